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

use super::detection::moved_beyond;

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

/// What the robot knows better than the camera while it observes.
pub struct Known<'a> {
    /// The objects it put in goals.
    pub placed: &'a [Placed],
    /// The object in its gripper (name, the box it was grasped from).
    pub holds: Option<(&'a str, PixelBox)>,
    /// The scene its plan was made for: a box seen within the detection
    /// tolerance of its box there is that box ([`super::detection`]).
    pub reference: &'a Scenario,
    /// The open fingers' half-width, m (for each piece's grasp slack).
    pub half_opening: f64,
}

/// `scene` after `observation`, detector noise taken out, with the robot's
/// own knowledge of the objects it placed and the one it holds kept.
pub fn observe(scene: &Scenario, observation: &Observation, known: &Known) -> Scenario {
    let mut next = scene.observed(observation);
    denoise(&mut next, known.reference, known.half_opening);
    let (placed, holds) = (known.placed, known.holds);
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

/// Boxes within the detection tolerance of their box in `reference` (the
/// same name) are put back there: jitter is not a move. An object's
/// tolerance is at most half its grasp's slack (`half_opening` less half
/// its narrower side).
fn denoise(next: &mut Scenario, reference: &Scenario, half_opening: f64) {
    let [mu, mv] = next.metres_per_pixel();
    let setting = next.safety.detection.position_tolerance_m;
    for o in &mut next.objects {
        let Some(r) = reference.objects.iter().find(|r| r.name == o.name) else {
            continue;
        };
        let slack = half_opening - 0.5 * (r.bbox.w * mu).min(r.bbox.l * mv);
        let tolerance = setting.min(0.5 * slack.max(0.0));
        if !moved_beyond([mu, mv], o.bbox, r.bbox, tolerance) && o.height == r.height {
            o.bbox = r.bbox;
        }
    }
    for g in &mut next.goals {
        if let Some(r) = reference.goals.iter().find(|r| r.name == g.name)
            && !moved_beyond([mu, mv], g.bbox, r.bbox, setting)
            && g.height == r.height
        {
            g.bbox = r.bbox;
        }
    }
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
