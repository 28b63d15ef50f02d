//! The gripper of a draft: which joints are fingers, the opening their
//! limits give, the finger colliders, and the tool's approach axis from the
//! gripper's geometry (from the wrist to the fingers' centroid; without
//! fingers from the wrist to the tool, else the last joint's axis).

use std::collections::{BTreeMap, BTreeSet};

use super::{APPROACH_TOLERANCE_RAD, DraftArm, fk, round};
use crate::description::{DEFAULT_GRIPPER_TIME, Gripper};
use crate::math::{Real, Vec3};
use crate::model::JointKind;
use crate::urdf::Tree;

/// Names that mark a finger joint.
const FINGER_WORDS: [&str; 5] = ["finger", "gripper", "jaw", "knuckle", "claw"];

/// Movable joints that belong to a gripper: mimic joints, their leaders,
/// and joints named like fingers.
pub(super) fn finger_joints(tree: &Tree) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for j in tree.links.iter().filter_map(|l| l.joint.as_ref()) {
        if j.kind == JointKind::Fixed {
            continue;
        }
        let n = j.name.to_ascii_lowercase();
        if FINGER_WORDS.iter().any(|w| n.contains(w)) {
            out.insert(j.name.clone());
        }
        if let Some(r) = &j.resolved {
            out.insert(j.name.clone());
            out.insert(r.root.clone());
        }
    }
    out
}

/// The gripper section, the finger joints' open values and the approach
/// axis in the tool frame.
pub(super) fn gripper(
    tree: &Tree,
    arm: &DraftArm,
    fingers: &BTreeSet<String>,
    guesses: &mut Vec<String>,
) -> (Gripper, BTreeMap<String, Real>, Option<Vec3>) {
    let link = |name: &str| tree.links.iter().position(|l| l.name == name);
    let joint_link = |name: &str| {
        (tree.links.iter()).position(|l| l.joint.as_ref().is_some_and(|j| j.name == name))
    };
    let (Some(tool), Some(wrist)) = (
        link(&arm.tool),
        arm.joints.last().and_then(|j| joint_link(j)),
    ) else {
        return (Gripper::default(), BTreeMap::new(), None);
    };
    let mut open = BTreeMap::new();
    for l in &tree.links {
        if let Some(j) = l.joint.as_ref().filter(|j| fingers.contains(&j.name))
            && j.resolved.is_none()
            && j.upper.is_finite()
        {
            open.insert(j.name.clone(), j.upper);
        }
    }
    let poses = fk::poses(tree, &open);
    let below_wrist = |mut l: usize| loop {
        if l == wrist {
            return true;
        }
        match tree.links[l].parent {
            Some(p) => l = p,
            None => return false,
        }
    };
    // Finger links: below a finger joint (and below the wrist).
    let finger_link = |l: usize| {
        let mut cur = Some(l);
        while let Some(c) = cur {
            if c == wrist {
                return false;
            }
            if tree.links[c]
                .joint
                .as_ref()
                .is_some_and(|j| fingers.contains(&j.name))
            {
                return true;
            }
            cur = tree.links[c].parent;
        }
        false
    };
    let finger_links: Vec<usize> = (0..tree.links.len())
        .filter(|&l| below_wrist(l) && finger_link(l) && !tree.links[l].colliders.is_empty())
        .collect();
    let mut points = Vec::new();
    let mut bodies = Vec::new();
    for &l in &finger_links {
        let name = &tree.links[l].name;
        let n = tree.links[l].colliders.len();
        bodies.extend((0..n).map(|k| match n {
            1 => name.clone(),
            _ => format!("{name}#{k}"),
        }));
        points.extend(
            fk::collider_points(tree, l)
                .into_iter()
                .map(|p| poses[l] * nalgebra::Point3::from(p))
                .map(|p| p.coords),
        );
    }
    let wrist_at = poses[wrist].translation.vector;
    let tool_pose = poses[tool];
    let (direction, from) = match centroid(&points).map(|c| c - wrist_at) {
        Some(d) if d.norm() > 0.01 => (d, "from the wrist to the fingers' centroid"),
        _ => {
            let d = tool_pose.translation.vector - wrist_at;
            let axis = tree.links[wrist]
                .joint
                .as_ref()
                .map_or(Vec3::z(), |j| j.axis);
            match d.norm() > 0.01 {
                true => (d, "from the wrist to the tool (no fingers found)"),
                false => (
                    poses[wrist].rotation * axis,
                    "the last joint's axis (no fingers found)",
                ),
            }
        }
    };
    let approach = (tool_pose.rotation.inverse() * direction).normalize();
    let angle = approach.z.clamp(-1.0, 1.0).acos();
    let shown = format!("({:.3}, {:.3}, {:.3})", approach.x, approach.y, approach.z);
    match angle <= APPROACH_TOLERANCE_RAD {
        true => guesses.push(format!(
            "arms[0].tool: '{}': approach axis {from} is {shown} in its frame, {:.0}° from its +z: +z taken as the approach",
            arm.tool,
            angle.to_degrees()
        )),
        false => guesses.push(format!(
            "arms[0].tool: '{}': approach axis {from} is {shown} in its frame, {:.0}° from its +z; afford's tool frame has +z = approach: add a fixed link to the URDF turned so (and at the grasp point) and name it in arms[0].tool",
            arm.tool,
            angle.to_degrees()
        )),
    }
    let d = tool_pose.rotation * approach;
    let along: Vec<Real> = points
        .iter()
        .map(|p| (p - tool_pose.translation.vector).dot(&d))
        .collect();
    let reach = along.iter().copied().fold(Real::NEG_INFINITY, Real::max);
    if reach > 0.02 {
        guesses.push(format!(
            "arms[0].tool: the fingertips reach {reach:.3} m beyond '{}' along the approach axis; afford's tool is the grasp point: add a fixed link between the fingertips and name it in arms[0].tool",
            arm.tool
        ));
    }
    let mut gripper = Gripper {
        fingers: bodies,
        ..Gripper::default()
    };
    match opening(tree, fingers) {
        Some(o) => {
            gripper.max_opening = round(o, 4);
            guesses.push(format!(
                "gripper.max_opening: {:.4} m from the finger joints' limits (the fingers open in home)",
                gripper.max_opening
            ));
        }
        None => guesses.push(format!(
            "gripper.max_opening: {} m (default: no prismatic finger joint with limits)",
            gripper.max_opening
        )),
    }
    let span = reach - along.iter().copied().fold(Real::INFINITY, Real::min);
    match span.is_finite() && span > 0.0 {
        true => {
            gripper.finger_length = round(span.min(0.2), 3);
            guesses.push(format!(
                "gripper.finger_length: {:.3} m, the finger colliders' extent along the approach axis",
                gripper.finger_length
            ));
        }
        false => guesses.push(format!(
            "gripper.finger_length: {} m (default: no finger colliders)",
            gripper.finger_length
        )),
    }
    if gripper.fingers.is_empty() {
        guesses.push("gripper.fingers: none found (no finger joints with collision geometry below the wrist)".into());
    }
    guesses.push(format!(
        "gripper.closing_time, opening_time: {DEFAULT_GRIPPER_TIME} s (default)"
    ));
    (gripper, open, Some(approach))
}

fn centroid(points: &[Vec3]) -> Option<Vec3> {
    (!points.is_empty()).then(|| points.iter().sum::<Vec3>() / points.len() as Real)
}

/// The widest opening the prismatic finger joints give: each leader's
/// travel times one plus its followers' |multiplier|s; the largest.
fn opening(tree: &Tree, fingers: &BTreeSet<String>) -> Option<Real> {
    let joints: Vec<_> = tree.links.iter().filter_map(|l| l.joint.as_ref()).collect();
    (joints.iter())
        .filter(|j| {
            j.kind == JointKind::Prismatic
                && j.resolved.is_none()
                && fingers.contains(&j.name)
                && j.lower.is_finite()
                && j.upper.is_finite()
        })
        .map(|j| {
            let followers: Real = (joints.iter())
                .filter_map(|f| {
                    f.resolved
                        .as_ref()
                        .filter(|r| r.root == j.name && f.kind == JointKind::Prismatic)
                })
                .map(|r| r.mimic.multiplier.abs())
                .sum();
            (j.upper - j.lower) * (1.0 + followers)
        })
        .filter(|o| *o > 0.0)
        .reduce(Real::max)
}
