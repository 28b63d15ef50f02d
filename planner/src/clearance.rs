//! The collision stage: a sub-goal's joint path checked against the scene
//! with the collision crate's continuous checks (every arm link, the gripper,
//! the held object, the other arm; safety perimeters as margins).
//!
//! The path is checked in three parts, split where the gripper closes and
//! opens: up to the grasp the target is ignored (the fingers close on it);
//! while holding it rides with the gripper as an attachment; after the
//! release it stays where it was put, under the open gripper, and is not
//! part of the scene. The held box's bottom [`SUPPORT_GAP`] is left out of
//! the check: it rests on the table when the fingers close.

use afford_collision::{Attachment, BoxKind, Collision, PathOptions, RobotGeometry, Scene};
use afford_kinematics::RobotModel;

use crate::geometry::{scene_box, scene_spec};
use crate::lift::{Phase, ToolWaypoint};
use crate::scenario::Scenario;

/// Height of the held object's bottom slice that may touch its support, m.
pub const SUPPORT_GAP: f64 = 0.002;

/// A collision found on a sub-goal's path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathCollision {
    /// Index of the tool waypoint nearest the hit (`None`: the move from the
    /// robot's current configuration to the first waypoint).
    pub waypoint: Option<usize>,
    pub phase: Option<Phase>,
    pub collision: Collision,
}

impl std::fmt::Display for PathCollision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.waypoint, self.phase) {
            (Some(k), Some(phase)) => write!(f, "{phase:?} waypoint {k}: {}", self.collision),
            _ => write!(f, "on the way to the first waypoint: {}", self.collision),
        }
    }
}

/// What the check needs to know of one sub-goal.
pub struct SubgoalMotion<'a> {
    pub scenario: &'a Scenario,
    pub target: usize,
    pub goal: usize,
    pub arm: &'a str,
    /// The whole robot's configuration; the arm's joints are replaced by the path.
    pub rest: &'a [f64],
    /// The arm's configuration at the start and at every tool waypoint.
    pub joint_path: &'a [Vec<f64>],
    pub waypoints: &'a [ToolWaypoint],
}

/// Checks the motion; `Ok(None)` when it is free with every margin kept.
pub fn check_motion(
    robot: &RobotModel,
    geometry: &RobotGeometry,
    m: &SubgoalMotion,
) -> Result<Option<PathCollision>, String> {
    let spec = scene_spec(m.scenario, m.target, m.goal);
    let scene = Scene::from_spec(&spec).map_err(|e| e.to_string())?;
    let object = &m.scenario.objects[m.target];
    let target_name = object.name.clone();
    let last = |phase: Phase| {
        m.waypoints
            .iter()
            .rposition(|w| w.phase == phase)
            .map_or(0, |k| k + 1)
    };
    let (grasp, release) = (last(Phase::Grasp), last(Phase::Release));
    let arm = robot.arm(m.arm).map_err(|e| e.to_string())?;
    // The held box's lowest SUPPORT_GAP is not checked: it is the face that
    // rests on the table while the fingers close.
    let mut held = scene_box(
        m.scenario,
        &target_name,
        BoxKind::Object,
        object.bbox,
        object.height,
        0.0,
    );
    held.size[2] -= SUPPORT_GAP;
    let attached = Attachment::grasped(
        &held,
        spec.table_z + SUPPORT_GAP,
        &arm.fk(&m.joint_path[grasp]),
    );
    let parts = [
        (
            0,
            grasp,
            PathOptions {
                ignore: vec![target_name.clone()],
                ..options(m.arm)
            },
        ),
        (
            grasp,
            release,
            PathOptions {
                attached: Some(attached),
                ..options(m.arm)
            },
        ),
        (release, m.joint_path.len() - 1, options(m.arm)),
    ];
    for (from, to, opts) in parts {
        let verdict = geometry
            .check_arm_path(&scene, m.arm, m.rest, &m.joint_path[from..=to], &opts)
            .map_err(|e| e.to_string())?;
        if let Some(hit) = verdict.first() {
            let index = from + hit.waypoint;
            let waypoint = index.checked_sub(1);
            return Ok(Some(PathCollision {
                waypoint,
                phase: waypoint.and_then(|k| m.waypoints.get(k)).map(|w| w.phase),
                collision: hit.clone(),
            }));
        }
    }
    Ok(None)
}

fn options(arm: &str) -> PathOptions {
    PathOptions {
        arm: Some(arm.to_string()),
        ..PathOptions::default()
    }
}
