//! Lifting a grid plan to 3-D tool waypoints in the robot base frame.
//!
//! Every cell maps to the table plane through the scenario's `pixel_to_base`
//! and `table_z`. One sub-goal becomes: travel at carry height from the
//! gripper's position to the target, descend to the approach height, then to
//! the grasp height, close, lift, travel to the cell next to the goal, the
//! GOAL macro over the box wall (through the entry cell to the drop cell),
//! descend into the box, open, retreat to carry height. The tool points down
//! throughout; its yaw puts the fingers across the object's shorter side.
//!
//! Heights (metres above the table top, TCP = the grasp point):
//! - grasp: half the object's height (the fingers close on its middle), but
//!   no lower than `min_grasp_height` and the fingertips `tip_clearance` off
//!   the table, and high enough that every tool collider outside the
//!   fingers' grasp region (the palm) stays `obstacle_margin` (plus
//!   `palm_clearance`) above its top ([`GripperReach`], measured on the robot's colliders). The
//!   sub-goal is refused, naming the object's height and the finger length,
//!   when the fingertips then reach neither the object's middle nor
//!   `min_grip_depth` below its top;
//! - approach: grasp + `approach_clearance`;
//! - carry: tallest thing on the table (objects, goal walls, hands) + the
//!   held object's height + `carry_clearance`, so the held object's bottom
//!   clears everything by at least `carry_clearance`;
//! - release: the object's bottom `release_clearance` above the box's wall
//!   top (or above the pieces already in the box that the open fingers
//!   pass over, plus their margin: [`crate::place::Release::floor`]),
//!   exactly over its resting spot ([`crate::place`]). DROP opens the
//!   gripper over the box, as in the paper: the fingers never enter it, so a
//!   box narrower than the open gripper still works.
//!
//! Opening: the fingers close across the object's narrower side (metres);
//! that width plus `opening_clearance` must not exceed the gripper's
//! `max_opening`, else the sub-goal is refused naming both widths.

use serde::{Deserialize, Serialize};

use crate::error::Refusal;
use crate::grid::Cell;
use crate::scenario::{Object, Scenario};
use crate::smooth::smooth_path;
use crate::task::{Action, GridTask};

/// Heights and clearances of the lifted motion, metres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LiftSettings {
    /// Above the grasp height where the vertical approach starts.
    pub approach_clearance: f64,
    /// Minimum gap between the held object's bottom and anything below it while travelling.
    pub carry_clearance: f64,
    /// Gap between the object's bottom and the box's wall top at release.
    pub release_clearance: f64,
    /// Lowest TCP height above the table for a grasp.
    pub min_grasp_height: f64,
    /// Longest straight step between consecutive waypoints; longer segments
    /// (the vertical moves, the carry over the wall) are cut into equal steps.
    pub max_step: f64,
    /// Lowest gap between the fingertips and the table at the grasp.
    pub tip_clearance: f64,
    /// Gap kept between the palm and the target's safety perimeter at the
    /// grasp (above the collision check's 0.1 mm tolerance).
    pub palm_clearance: f64,
    /// Shortest acceptable grip: how far below the object's top the
    /// fingertips must reach when they cannot reach its middle.
    pub min_grip_depth: f64,
    /// Total free play the open fingers need around the object (both sides).
    pub opening_clearance: f64,
}

impl Default for LiftSettings {
    fn default() -> Self {
        Self {
            approach_clearance: 0.10,
            carry_clearance: 0.05,
            release_clearance: 0.01,
            min_grasp_height: 0.02,
            max_step: 0.01,
            tip_clearance: 0.005,
            palm_clearance: 0.003,
            min_grip_depth: 0.01,
            opening_clearance: 0.01,
        }
    }
}

/// The gripper as lifting sees it, measured with the tool pointing down:
/// metres along the tool's approach axis, over every arm (the lowest palm,
/// the farthest fingertips).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GripperReach {
    /// Height above the TCP of the lowest point of any tool collider
    /// outside the grasp region (negative: it reaches below the TCP).
    pub palm_above_tcp: f64,
    /// How far the grasp region's colliders reach below the TCP.
    pub tips_below_tcp: f64,
    /// The robot description's `gripper.max_opening`.
    pub max_opening: f64,
    /// The robot description's `gripper.finger_length`.
    pub finger_length: f64,
    /// Half-widths of the grasp region's colliders about the TCP, metres:
    /// `[along the tool's x (the object's longer side), across the grasp
    /// axis (the tool's y)]`, each the farthest reach to either side, the
    /// second at least half the opening. What is lowered over a release
    /// spot is at least this wide.
    pub finger_half_extent: [f64; 2],
}

/// What the robot is doing on the way to a waypoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Where the gripper is when the sub-goal starts (at carry height).
    Start,
    /// Travelling empty at carry height.
    Travel,
    /// Down to the approach height over the target.
    Approach,
    /// Down to the grasp height; the gripper closes here.
    Grasp,
    /// Up to carry height with the object.
    Lift,
    /// Travelling with the object at carry height.
    Carry,
    /// The GOAL macro: over the box wall to above the drop point.
    OverWall,
    /// Down into the box; the gripper opens here.
    Release,
    /// Back up to carry height, empty.
    Retreat,
}

/// One tool waypoint: position (base frame, metres), tool yaw (rad, tool x
/// axis in the horizontal plane; the tool's z axis points down), the phase of
/// the segment that ends here and whether the gripper holds the object on
/// arrival. The gripper closes at the last `grasp` waypoint and opens at the
/// last `release` waypoint.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToolWaypoint {
    pub position: [f64; 3],
    pub yaw: f64,
    pub phase: Phase,
    pub holding: bool,
}

/// The lifted motion of one sub-goal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiftedMotion {
    pub waypoints: Vec<ToolWaypoint>,
    /// Carry height above the table top, metres.
    pub carry_height: f64,
}

impl LiftedMotion {
    /// Indices into the joint path — 0 is the robot's configuration before
    /// the first waypoint, `k + 1` is waypoint `k` — where the gripper
    /// closes (last `grasp` waypoint) and opens (last `release` waypoint).
    pub fn gripper_switches(&self) -> (usize, usize) {
        let last = |phase: Phase| {
            self.waypoints
                .iter()
                .rposition(|w| w.phase == phase)
                .map_or(0, |k| k + 1)
        };
        (last(Phase::Grasp), last(Phase::Release))
    }

    /// The waypoint and phase of joint-path index `index` (`None` for 0).
    pub fn waypoint_of(&self, index: usize) -> Option<(usize, Phase)> {
        let k = index.checked_sub(1)?;
        self.waypoints.get(k).map(|w| (k, w.phase))
    }
}

/// Lifts a solved grid plan. `object` and `goal` index the scenario; `cells`
/// is the plan's visited cells ([`crate::LearnedPlan::cells`]) and `actions`
/// its actions. `Err` is why the gripper cannot take the object (too wide
/// for its opening, too tall for a grip that keeps the palm clear).
#[allow(clippy::too_many_arguments)]
pub fn lift(
    scenario: &Scenario,
    task: &GridTask,
    object: usize,
    goal: usize,
    actions: &[Action],
    cells: &[Cell],
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<LiftedMotion, Refusal> {
    let grid = &task.grid;
    let held = &scenario.objects[object];
    let table = scenario.camera.table_z;
    let carry_height = carry_height(scenario, object, settings);
    let (yaw, grasp) = grasp_pose(scenario, held, gripper, settings)?;
    let grasp_at = actions
        .iter()
        .position(|&a| a == Action::Grasp)
        .unwrap_or(0);
    let goal_at = actions
        .iter()
        .position(|&a| a == Action::Goal)
        .unwrap_or(actions.len());
    let to_target = &cells[..=grasp_at];
    let to_goal = &cells[grasp_at + 1..=goal_at];
    let at = |p: [f64; 2], h: f64| {
        let [x, y] = scenario.pixel_to_base(p);
        [x, y, table + h]
    };
    let point = |p: [f64; 2], h: f64, phase: Phase, holding: bool| ToolWaypoint {
        position: at(p, h),
        yaw,
        phase,
        holding,
    };
    let mut out = Vec::new();
    let travel = |out: &mut Vec<ToolWaypoint>, leg: &[Cell], phase: Phase, holding: bool| {
        out.extend(
            smooth_path(grid, leg)
                .into_iter()
                .skip(1)
                .map(|p| point(p, carry_height, phase, holding)),
        );
    };
    let start_px = grid.centre(cells[0]);
    out.push(point(start_px, carry_height, Phase::Start, false));
    travel(&mut out, to_target, Phase::Travel, false);
    let target_px = grid.centre(grid.target);
    out.push(point(
        target_px,
        grasp + settings.approach_clearance,
        Phase::Approach,
        false,
    ));
    out.push(point(target_px, grasp, Phase::Grasp, false));
    out.push(point(target_px, carry_height, Phase::Lift, true));
    travel(&mut out, to_goal, Phase::Carry, true);
    let near = cells[goal_at];
    let drop = grid.drop.unwrap_or(near);
    if let Some(entry) = task.goal_entry(near).filter(|&e| e != drop) {
        out.push(point(
            grid.centre(entry),
            carry_height,
            Phase::OverWall,
            true,
        ));
    }
    let (drop_px, floor) = match grid.release {
        Ok(r) => (r.spot, r.floor),
        Err(_) => (grid.centre(drop), 0.0),
    };
    let floor = floor.max(scenario.goals[goal].height);
    out.push(point(drop_px, carry_height, Phase::OverWall, true));
    out.push(point(
        drop_px,
        floor + grasp + settings.release_clearance,
        Phase::Release,
        true,
    ));
    out.push(point(drop_px, carry_height, Phase::Retreat, false));
    Ok(LiftedMotion {
        waypoints: densify(&out, settings.max_step),
        carry_height,
    })
}

/// The grasp's tool yaw and TCP height above the table ([`grasp_yaw`],
/// [`grasp_height`]), or why the gripper cannot take the object.
pub fn grasp_pose(
    s: &Scenario,
    held: &Object,
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<(f64, f64), Refusal> {
    Ok((
        grasp_yaw(s, held, gripper, settings)?,
        grasp_height(s, held, gripper, settings)?,
    ))
}

/// TCP height above the table at the grasp (see the module doc), or why no
/// height keeps the palm clear of the object while the fingers still hold it.
pub fn grasp_height(
    s: &Scenario,
    held: &Object,
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<f64, Refusal> {
    let h = held.height;
    let margin = s.safety.obstacle_margin;
    let grasp = (h / 2.0)
        .max(settings.min_grasp_height)
        .max(gripper.tips_below_tcp + settings.tip_clearance)
        .max(h + margin + settings.palm_clearance - gripper.palm_above_tcp);
    let tips = grasp - gripper.tips_below_tcp;
    let depth = h - tips;
    // 1 nm: a grip of exactly `min_grip_depth` passes despite rounding.
    if tips <= h / 2.0 || depth >= settings.min_grip_depth - 1e-9 {
        return Ok(grasp);
    }
    Err(Refusal::TooTallForFingers {
        object: held.name.clone(),
        height_m: h,
        palm_gap_m: margin,
        finger_length_m: gripper.finger_length,
        grip_depth_m: depth.max(0.0),
        min_grip_depth_m: settings.min_grip_depth,
    })
}

/// Carry height (metres above the table top) of a sub-goal that moves
/// `object`: the tallest other thing on the table + the object's height +
/// `carry_clearance`.
pub fn carry_height(scenario: &Scenario, object: usize, settings: &LiftSettings) -> f64 {
    tallest(scenario, object) + scenario.objects[object].height + settings.carry_clearance
}

/// Cuts every segment longer than `max_step` into equal steps; inserted
/// waypoints take the phase and holding state of the segment's end.
fn densify(waypoints: &[ToolWaypoint], max_step: f64) -> Vec<ToolWaypoint> {
    let mut out: Vec<ToolWaypoint> = waypoints.first().copied().into_iter().collect();
    for pair in waypoints.windows(2) {
        let (a, b) = (pair[0].position, pair[1].position);
        let length = (0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt();
        let steps = (length / max_step).ceil().max(1.0) as usize;
        out.extend((1..=steps).map(|i| {
            let t = i as f64 / steps as f64;
            ToolWaypoint {
                position: [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k])),
                ..pair[1]
            }
        }));
    }
    out
}

/// Height above the table of the tallest object (other than the held one),
/// goal wall or hand.
fn tallest(s: &Scenario, held: usize) -> f64 {
    let objects = s
        .objects
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != held)
        .map(|(_, o)| o.height);
    objects
        .chain(s.goals.iter().map(|g| g.height))
        .chain(s.hands.iter().map(|h| h.height))
        .fold(0.0, f64::max)
}

/// Tool yaw that lays the tool's x axis along the object's longer side
/// (metres), so the fingers (closing along the tool's y axis) span its
/// narrower side; pixel axes are mapped through `pixel_to_base`. `Err` names
/// both widths when that side plus `opening_clearance` exceeds the
/// gripper's opening.
pub fn grasp_yaw(
    s: &Scenario,
    held: &Object,
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<f64, Refusal> {
    let [mu, mv] = s.metres_per_pixel();
    let (along_u, along_v) = (held.bbox.w * mu, held.bbox.l * mv);
    let across = along_u.min(along_v);
    if across + settings.opening_clearance > gripper.max_opening {
        return Err(Refusal::GripperTooNarrow {
            object: held.name.clone(),
            width_m: across,
            clearance_m: settings.opening_clearance,
            opening_m: gripper.max_opening,
        });
    }
    let m = &s.camera.pixel_to_base;
    let (dx, dy) = if along_u >= along_v {
        (m[0][0], m[1][0])
    } else {
        (m[0][1], m[1][1])
    };
    Ok(dy.atan2(dx))
}
