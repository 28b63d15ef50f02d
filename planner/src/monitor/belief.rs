//! The scene the monitor believes in: the planning scene, changed by each
//! observation, except where the robot knows better — an object it has
//! placed stays where it put it (moving with its goal when the goal moves)
//! and the object in its gripper is in its gripper, whatever the
//! observation lists for them (a camera sees a held piece badly). Also the
//! difference between two scenes, as typed changes, for the event log and
//! for the relevance tests.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::scenario::{Object, Observation, PixelBox, Scenario};

/// An object the robot put in a goal: its box relative to the goal's
/// top-left corner, pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct Placed {
    pub object: Object,
    pub goal: String,
    pub offset: [f64; 2],
}

/// One difference between two scenes.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "change", rename_all = "snake_case")]
pub enum Change {
    Appeared { kind: ElementKind, name: String },
    Moved { kind: ElementKind, name: String },
    Left { kind: ElementKind, name: String },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementKind {
    Object,
    Goal,
    Hand,
}

impl std::fmt::Display for Change {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (kind, name, what) = match self {
            Change::Appeared { kind, name } => (kind, name, "appeared"),
            Change::Moved { kind, name } => (kind, name, "moved"),
            Change::Left { kind, name } => (kind, name, "left"),
        };
        let kind = match kind {
            ElementKind::Object => "object",
            ElementKind::Goal => "goal",
            ElementKind::Hand => "hand",
        };
        write!(f, "{kind} {name} {what}")
    }
}

impl Change {
    pub fn name(&self) -> &str {
        match self {
            Change::Appeared { name, .. }
            | Change::Moved { name, .. }
            | Change::Left { name, .. } => name,
        }
    }
}

/// `scene` after `observation`, with the robot's own knowledge of the
/// objects it `placed` and the one it `holds` (name, its box) kept.
pub fn observe(
    scene: &Scenario,
    observation: &Observation,
    placed: &[Placed],
    holds: Option<(&str, PixelBox)>,
) -> Scenario {
    let mut next = scene.observed(observation);
    for p in placed {
        let Some(goal) = next.goals.iter().find(|g| g.name == p.goal) else {
            continue;
        };
        let mut object = p.object.clone();
        object.bbox.u = goal.bbox.u + p.offset[0];
        object.bbox.v = goal.bbox.v + p.offset[1];
        keep(&mut next.objects, object);
    }
    if let Some((name, bbox)) = holds
        && let Some(o) = scene.objects.iter().find(|o| o.name == name)
    {
        keep(&mut next.objects, Object { bbox, ..o.clone() });
    }
    next
}

/// Replaces the object of the same name, or appends it.
fn keep(objects: &mut Vec<Object>, object: Object) {
    match objects.iter_mut().find(|o| o.name == object.name) {
        Some(o) => *o = object,
        None => objects.push(object),
    }
}

/// What differs from `before` to `after`, objects, goals, then hands, each
/// by name in order.
pub fn changes(before: &Scenario, after: &Scenario) -> Vec<Change> {
    let mut out = Vec::new();
    let lists = [
        (
            ElementKind::Object,
            boxes(before.objects.iter().map(|o| (&o.name, o.bbox, o.height))),
            boxes(after.objects.iter().map(|o| (&o.name, o.bbox, o.height))),
        ),
        (
            ElementKind::Goal,
            boxes(before.goals.iter().map(|g| (&g.name, g.bbox, g.height))),
            boxes(after.goals.iter().map(|g| (&g.name, g.bbox, g.height))),
        ),
        (
            ElementKind::Hand,
            boxes(before.hands.iter().map(|h| (&h.name, h.bbox, h.height))),
            boxes(after.hands.iter().map(|h| (&h.name, h.bbox, h.height))),
        ),
    ];
    for (kind, old, new) in lists {
        for (name, b) in &new {
            let name = name.clone();
            match old.get(&name) {
                None => out.push(Change::Appeared { kind, name }),
                Some(a) if a != b => out.push(Change::Moved { kind, name }),
                Some(_) => {}
            }
        }
        for name in old.keys().filter(|n| !new.contains_key(*n)) {
            out.push(Change::Left {
                kind,
                name: name.clone(),
            });
        }
    }
    out
}

type Boxes = BTreeMap<String, ([f64; 4], f64)>;

fn boxes<'a>(items: impl Iterator<Item = (&'a String, PixelBox, f64)>) -> Boxes {
    items
        .map(|(n, b, h)| (n.clone(), (<[f64; 4]>::from(b), h)))
        .collect()
}
