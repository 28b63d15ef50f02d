//! What lifting is given and what it gives back: the heights and
//! clearances ([`LiftSettings`], every default written once), the
//! gripper's reach and opening ([`GripperReach`]), the request
//! ([`LiftRequest`]) and the tool waypoints by phase ([`LiftedMotion`]).

use serde::{Deserialize, Serialize};

use crate::grid::Cell;
use crate::task::Action;

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
    /// Some travel or carry waypoint is below the carry height (an eased
    /// turn over the target): the full-height fallback differs from it.
    #[serde(skip)]
    pub eased: bool,
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

/// What [`lift`] lifts: the solved grid plan of one sub-goal and where the
/// tool is when it starts.
#[derive(Debug, Clone, Copy)]
pub struct LiftRequest<'a> {
    /// Index of the moved object in the scenario.
    pub object: usize,
    /// Index of the goal in the scenario.
    pub goal: usize,
    /// The plan's actions ([`crate::LearnedPlan::actions`]).
    pub actions: &'a [Action],
    /// The plan's visited cells ([`crate::LearnedPlan::cells`]).
    pub cells: &'a [Cell],
    /// Where the tool is, pixel (u, v): the route starts here.
    pub start_px: [f64; 2],
    /// The tool's height above the table when it points down over
    /// `start_px` (metres); `None`: not known, the route starts at the
    /// carry height.
    pub start_height: Option<f64>,
    /// Carry at the full height ([`carry_height`]: the tallest thing on the
    /// whole table) instead of what the route passes over.
    pub full_height: bool,
}
