//! The collision stage: an arm's joint path checked against the scene with
//! the collision crate's continuous checks (every arm link, the gripper, the
//! held object, the other arm; safety perimeters as margins). Used twice:
//! on the IK path, where a hit can send the grid back to CQL, and on the
//! sampled trajectory, the independent check before anything leaves afford.
//!
//! The path is checked in three parts, split where the gripper closes and
//! opens: up to the grasp the target is an obstacle with its margin for
//! every body but the fingers' grasp region ([`grasp_region`]), so the palm
//! and the links never come near it; while holding it rides with the
//! gripper as an attachment; after the release it stays where it was put,
//! under the open gripper, and is left out. The held box's bottom
//! [`SUPPORT_GAP`] is left out of the check only until the tool has risen
//! twice that above the grasp (it rests on the table when the fingers
//! close); from there on the whole box is checked.

use afford_collision::{Attachment, Collision, PathOptions, RobotGeometry, Scene};
use afford_kinematics::RobotModel;

use crate::geometry::{object_box, scene_spec};
use crate::lift::GripperReach;
use crate::scenario::{PixelBox, Scenario};

/// Height of the held object's bottom slice that may touch its support, m.
pub const SUPPORT_GAP: f64 = 0.002;

/// One arm's motion for one sub-goal.
pub struct ArmMotion<'a> {
    pub scenario: &'a Scenario,
    pub target: usize,
    pub goal: usize,
    pub arm: &'a str,
    /// The whole robot's configuration; the arm's joints are replaced by the path.
    pub rest: &'a [f64],
    /// The arm's configurations, in order; linear in between.
    pub path: &'a [Vec<f64>],
    /// Path indices where the gripper closes and opens.
    pub grasp_at: usize,
    pub release_at: usize,
    /// An object already held when the path starts (a replan while
    /// carrying): its box where it was grasped and the arm's configuration
    /// then, which fix its pose in the gripper. `grasp_at` is then 0.
    pub held: Option<(PixelBox, &'a [f64])>,
}

/// A hit on the path: the path index nearest to it and what hit what.
#[derive(Debug, Clone, PartialEq)]
pub struct PathHit {
    pub index: usize,
    pub collision: Collision,
}

/// Checks the motion; `Ok(None)` when it is free with every margin kept.
/// `Err` when the check cannot run (a robot or scene the collision crate
/// rejects).
pub fn check_motion(
    robot: &RobotModel,
    geometry: &RobotGeometry,
    m: &ArmMotion,
) -> Result<Option<PathHit>, String> {
    let spec = scene_spec(m.scenario, m.target, m.goal);
    let scene = Scene::from_spec(&spec).map_err(|e| e.to_string())?;
    let object = &m.scenario.objects[m.target];
    let arm = robot.arm(m.arm).map_err(|e| e.to_string())?;
    let (grasped_box, grasp) = m
        .held
        .unwrap_or((object.bbox, m.path[m.grasp_at].as_slice()));
    let full = object_box(m.scenario, object, grasped_box, object.height, 0.0);
    let grasp_pose = arm.fk(grasp);
    let mut resting = full.clone();
    resting.size[2] -= SUPPORT_GAP;
    // The table, or the floor of the goal box it was picked from.
    let support_z = spec.table_z + m.scenario.support_under(grasped_box);
    let on_table = Attachment::grasped(&resting, support_z + SUPPORT_GAP, &grasp_pose);
    let held = Attachment::grasped(&full, support_z, &grasp_pose);
    // The support slice is left out only until the object has left the table.
    let lift_z = grasp_pose.translation.vector.z + 2.0 * SUPPORT_GAP;
    let lifted = match m.held {
        Some(_) => m.grasp_at,
        None => (m.grasp_at..m.release_at)
            .find(|&k| arm.fk(&m.path[k]).translation.vector.z >= lift_z)
            .unwrap_or(m.release_at),
    };
    let options = PathOptions {
        arm: Some(m.arm.to_string()),
        ..PathOptions::default()
    };
    let parts = [
        (
            0,
            m.grasp_at,
            leg_options(robot, geometry, m.arm, &object.name, Leg::BeforeGrasp)?,
        ),
        (
            m.grasp_at,
            lifted,
            PathOptions {
                attached: Some(on_table),
                ..options.clone()
            },
        ),
        (
            lifted,
            m.release_at,
            PathOptions {
                attached: Some(held),
                ..options
            },
        ),
        (
            m.release_at,
            m.path.len() - 1,
            leg_options(robot, geometry, m.arm, &object.name, Leg::AfterRelease)?,
        ),
    ];
    first_hit(geometry, &scene, m, parts)
}

/// The first hit of the path's parts `(from, to, options)`, in order, each
/// checked with its own options in `scene`.
fn first_hit(
    geometry: &RobotGeometry,
    scene: &Scene,
    m: &ArmMotion,
    parts: impl IntoIterator<Item = (usize, usize, PathOptions)>,
) -> Result<Option<PathHit>, String> {
    for (from, to, opts) in parts {
        let verdict = geometry
            .check_arm_path(scene, m.arm, m.rest, &m.path[from..=to], &opts)
            .map_err(|e| e.to_string())?;
        if let Some(hit) = verdict.first() {
            return Ok(Some(PathHit {
                index: from + hit.waypoint,
                collision: hit.clone(),
            }));
        }
    }
    Ok(None)
}

/// Checks a motion that starts after its release (the way out of a goal):
/// the whole path as the after-release leg of [`check_motion`], the target
/// resting where the scenario has it.
pub fn check_after_release(
    robot: &RobotModel,
    geometry: &RobotGeometry,
    m: &ArmMotion,
) -> Result<Option<PathHit>, String> {
    let spec = scene_spec(m.scenario, m.target, m.goal);
    let scene = Scene::from_spec(&spec).map_err(|e| e.to_string())?;
    let name = &m.scenario.objects[m.target].name;
    let options = leg_options(robot, geometry, m.arm, name, Leg::AfterRelease)?;
    first_hit(geometry, &scene, m, [(0, m.path.len() - 1, options)])
}

/// The parts of a sub-goal where the hand holds nothing: the arm's free moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Leg {
    /// Up to the grasp: the target is an obstacle with its margin for every
    /// body but the fingers' grasp region.
    BeforeGrasp,
    /// After the release: the target rests under the open gripper and is
    /// left out.
    AfterRelease,
}

/// The check options of a free leg of `arm`'s motion whose target is `object`.
fn leg_options(
    robot: &RobotModel,
    geometry: &RobotGeometry,
    arm: &str,
    object: &str,
    leg: Leg,
) -> Result<PathOptions, String> {
    let options = PathOptions {
        arm: Some(arm.to_string()),
        ..PathOptions::default()
    };
    Ok(match leg {
        Leg::BeforeGrasp => PathOptions {
            exempt: grasp_region(robot, geometry, arm)?
                .into_iter()
                .map(|f| (f, object.to_string()))
                .collect(),
            ..options
        },
        Leg::AfterRelease => PathOptions {
            ignore: vec![object.to_string()],
            ..options
        },
    })
}

/// `options` for a yes-or-no check: a hit is not scanned for its deepest
/// point.
fn verdict_only(options: PathOptions) -> PathOptions {
    PathOptions {
        settings: afford_collision::CheckSettings {
            describe: false,
            ..options.settings
        },
        ..options
    }
}

/// The edge test of an arm's free moves in one sub-goal (the transit
/// planner's validity test): the scene and options [`check_motion`] uses on
/// that leg, built once.
pub struct FreeMoves<'a> {
    geometry: &'a RobotGeometry,
    scene: Scene,
    arm: String,
    rest: Vec<f64>,
    options: PathOptions,
}

impl<'a> FreeMoves<'a> {
    /// `rest`: the whole robot's configuration (the moving arm's joints are
    /// replaced by the edge's). `Err` when the scene or robot is rejected.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        robot: &RobotModel,
        geometry: &'a RobotGeometry,
        scenario: &Scenario,
        target: usize,
        goal: usize,
        arm: &str,
        rest: &[f64],
        leg: Leg,
    ) -> Result<Self, String> {
        let spec = scene_spec(scenario, target, goal);
        let scene = Scene::from_spec(&spec).map_err(|e| e.to_string())?;
        let object = &scenario.objects[target].name;
        Ok(Self {
            geometry,
            scene,
            arm: arm.to_string(),
            rest: rest.to_vec(),
            options: verdict_only(leg_options(robot, geometry, arm, object, leg)?),
        })
    }

    /// Is the straight joint-space move of the arm from `a` to `b` free,
    /// every margin kept at every instant?
    pub fn edge_free(&self, a: &[f64], b: &[f64]) -> Result<bool, String> {
        self.geometry
            .check_arm_path(
                &self.scene,
                &self.arm,
                &self.rest,
                &[a.to_vec(), b.to_vec()],
                &self.options,
            )
            .map(|v| v.is_free())
            .map_err(|e| e.to_string())
    }
}

/// The self-clearance screen of the path IK: does an arm's joint path (the
/// rest of the robot as in `rest`) keep [`SELF_CLEARANCE`] from the robot's
/// own bodies? It sees no scene: scene obstacles are the collision
/// stage's and the grid's, while an IK branch that folds an arm into the
/// body is the IK's to avoid ([`afford_kinematics::Arm::solve_path_screened`]).
pub struct SelfClearance<'a> {
    geometry: &'a RobotGeometry,
    scene: Scene,
    rest: Vec<f64>,
    settings: afford_collision::CheckSettings,
}

/// Room the path IK keeps between the robot's own bodies along its joint
/// path, m.
pub const SELF_CLEARANCE: f64 = 0.01;

impl<'a> SelfClearance<'a> {
    /// `Err` when the collision crate rejects the empty scene.
    pub fn new(geometry: &'a RobotGeometry, rest: &[f64]) -> Result<Self, String> {
        let spec = afford_collision::SceneSpec {
            table_z: 0.0,
            table: None,
            boxes: Vec::new(),
        };
        Ok(Self {
            geometry,
            scene: Scene::from_spec(&spec).map_err(|e| e.to_string())?,
            rest: rest.to_vec(),
            settings: afford_collision::CheckSettings {
                tolerance: SELF_CLEARANCE,
                describe: false,
                ..Default::default()
            },
        })
    }

    /// Whether `arm` along `path` (its joint path, checked continuously
    /// between the waypoints) keeps [`SELF_CLEARANCE`] from every other body
    /// of the robot (a path the check cannot take passes: the collision
    /// stage reports it). One continuous check of the whole path costs a
    /// fraction of one static check per waypoint: conservative advancement
    /// steps over the stretches where the arm is far from its body.
    pub fn admits(&self, arm: &str, path: &[Vec<f64>]) -> bool {
        let options = PathOptions {
            arm: Some(arm.to_string()),
            settings: self.settings,
            ..PathOptions::default()
        };
        self.geometry
            .check_arm_path(&self.scene, arm, &self.rest, path, &options)
            .map_or(true, |v| v.is_free())
    }
}

/// The colliders of `arm`'s gripper that may touch the target before they
/// close on it: the robot description's `gripper.fingers` rigid with the
/// arm's tool frame, or every collider rigid with it when the description
/// names none (a user robot without the field).
pub fn grasp_region(
    robot: &RobotModel,
    geometry: &RobotGeometry,
    arm: &str,
) -> Result<Vec<String>, String> {
    let tool: Vec<String> = geometry
        .tool_body_extents(arm)
        .map_err(|e| e.to_string())?
        .into_iter()
        .map(|(name, _)| name)
        .collect();
    let fingers: Vec<String> = tool
        .iter()
        .filter(|b| robot.gripper().fingers.contains(b))
        .cloned()
        .collect();
    Ok(if fingers.is_empty() { tool } else { fingers })
}

/// The gripper's reach along the approach axis over every arm (the lowest
/// palm, the farthest fingertips), measured on the colliders rigid with
/// each arm's tool frame; the opening and finger length from the robot
/// description.
pub fn gripper_reach(robot: &RobotModel, geometry: &RobotGeometry) -> Result<GripperReach, String> {
    let mut reach = GripperReach {
        palm_above_tcp: f64::INFINITY,
        tips_below_tcp: 0.0,
        max_opening: robot.gripper().max_opening,
        finger_length: robot.gripper().finger_length,
        finger_half_extent: [0.0, robot.gripper().max_opening / 2.0],
    };
    for arm in robot.arms() {
        let region = grasp_region(robot, geometry, &arm.name)?;
        let bounds = geometry
            .tool_body_bounds(&arm.name)
            .map_err(|e| e.to_string())?;
        for (name, [min, max]) in bounds {
            let below = max[2];
            match region.contains(&name) {
                true => {
                    reach.tips_below_tcp = reach.tips_below_tcp.max(below);
                    for k in 0..2 {
                        let side = min[k].abs().max(max[k].abs());
                        reach.finger_half_extent[k] = reach.finger_half_extent[k].max(side);
                    }
                }
                false => reach.palm_above_tcp = reach.palm_above_tcp.min(-below),
            }
        }
    }
    Ok(reach)
}
