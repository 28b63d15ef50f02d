//! Lifting a grid plan to 3-D tool waypoints in the robot base frame.
//!
//! Every cell maps to the table plane through the scenario's `pixel_to_base`
//! and `table_z`. One sub-goal becomes: travel at carry height from where
//! the tool is (no detour through the start cell's centre) to the target,
//! descend to the approach height, then to the grasp height, close, lift,
//! carry to the resting spot in the goal, descend into the box, open,
//! retreat to carry height. Both horizontal legs are the CQL cell path
//! pulled taut into an any-angle route in the same homotopy class
//! ([`crate::motion::route`]), then smoothed ([`crate::smooth`]). The tool
//! points down throughout; its yaw puts the fingers across the object's
//! shorter side. A tool that starts lower than the carry height rises
//! first; one that starts higher descends along the route at 45°.
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
//! - carry: the tallest thing the route passes over (objects, goal walls,
//!   hands, grown by their margins and the footprint; [`route_carry_height`])
//!   plus the held object's height plus `carry_clearance`, so the held
//!   object's bottom clears everything under it by at least
//!   `carry_clearance`; never below the approach or release height. [`carry_height`] (the tallest
//!   thing on the whole table) is the fallback after a collision;
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
use crate::grid::{Cell, StateGrid};
use crate::motion::route::{crosses_open_box, taut};
use crate::scenario::{Object, PixelBox, Scenario};
use crate::smooth::smooth_route;
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

/// Lifts a solved grid plan: the CQL cells pulled taut into an any-angle
/// route ([`crate::motion::route`]), smoothed ([`smooth_route`]), at the
/// carry height the route needs ([`route_carry_height`]). `Err` is why the
/// gripper cannot take the object (too wide for its opening, too tall for a
/// grip that keeps the palm clear).
pub fn lift(
    scenario: &Scenario,
    task: &GridTask,
    request: &LiftRequest,
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<LiftedMotion, Refusal> {
    let grid = &task.grid;
    let LiftRequest {
        object,
        goal,
        actions,
        cells,
        ..
    } = *request;
    let held = &scenario.objects[object];
    let table = scenario.camera.table_z;
    let (yaw, grasp) = grasp_pose(scenario, held, gripper, settings)?;
    let grasp_at = actions
        .iter()
        .position(|&a| a == Action::Grasp)
        .unwrap_or(0);
    let goal_at = actions
        .iter()
        .position(|&a| a == Action::Goal)
        .unwrap_or(actions.len());
    let centres = |leg: &[Cell]| leg.iter().map(|&c| grid.centre(c)).collect::<Vec<_>>();
    let mut to_target = vec![request.start_px];
    to_target.extend(centres(&cells[..=grasp_at]));
    let mut to_goal = centres(&cells[grasp_at..=goal_at]);
    let near = cells[goal_at];
    let drop = grid.drop.unwrap_or(near);
    if let Some(entry) = task.goal_entry(near).filter(|&e| e != drop) {
        to_goal.push(grid.centre(entry));
    }
    let (drop_px, floor) = match grid.release {
        Ok(r) => (r.spot, r.floor),
        Err(_) => (grid.centre(drop), 0.0),
    };
    to_goal.push(drop_px);
    let travel = smooth_route(grid, &taut(grid, &to_target));
    let carry = smooth_route(grid, &taut(grid, &to_goal));
    let approach = grasp + settings.approach_clearance;
    let release = floor.max(scenario.goals[goal].height) + grasp + settings.release_clearance;
    let carry_height = match request.full_height {
        true => carry_height(scenario, object, settings),
        false => route_carry_height(scenario, grid, object, goal, &[&travel, &carry], settings),
    }
    .max(approach)
    .max(release);
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
    let start_height = request.start_height.unwrap_or(carry_height);
    let mut out = vec![point(request.start_px, start_height, Phase::Start, false)];
    if start_height < carry_height - settings.max_step / 10.0 {
        out.push(point(request.start_px, carry_height, Phase::Travel, false));
    }
    let [mu, mv] = scenario.metres_per_pixel();
    let mut along = 0.0;
    for pair in travel.windows(2) {
        along += ((pair[1][0] - pair[0][0]) * mu).hypot((pair[1][1] - pair[0][1]) * mv);
        // Down to the carry height at 45° when the tool starts higher.
        let h = (start_height - along).max(carry_height);
        out.push(point(pair[1], h, Phase::Travel, false));
    }
    let target_px = grid.centre(grid.target);
    // At the approach height already (nothing under the route needs more):
    // no second waypoint at the same place.
    let over_target = point(target_px, approach, Phase::Approach, false);
    if out
        .last()
        .is_none_or(|w| distance3(w.position, over_target.position) > 1e-9)
    {
        out.push(over_target);
    }
    out.push(point(target_px, grasp, Phase::Grasp, false));
    out.push(point(target_px, carry_height, Phase::Lift, true));
    let goal_box = scenario.goals[goal].bbox;
    let mut over = false;
    for &p in carry.iter().skip(1) {
        over |= goal_box.contains(p);
        let phase = if over { Phase::OverWall } else { Phase::Carry };
        out.push(point(p, carry_height, phase, true));
    }
    out.push(point(drop_px, release, Phase::Release, true));
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
/// `object` when the route is not known: the tallest other thing on the
/// table + the object's height + `carry_clearance`.
pub fn carry_height(scenario: &Scenario, object: usize, settings: &LiftSettings) -> f64 {
    tallest(scenario, object) + scenario.objects[object].height + settings.carry_clearance
}

/// Carry height (metres above the table top) that the route needs: the
/// tallest thing the footprint (a cell-sized square, pixels) passes over
/// anywhere along `legs` (pixel polylines) — objects other than the held
/// one and goal walls grown by the margins the grid paints them with (the
/// sub-goal's own goal by none), hands by `hand_margin`, touching counts —
/// plus the object's height plus `carry_clearance` (just those two when the
/// route passes over nothing).
pub fn route_carry_height(
    scenario: &Scenario,
    grid: &StateGrid,
    object: usize,
    goal: usize,
    legs: &[&[[f64; 2]]],
    settings: &LiftSettings,
) -> f64 {
    let s = scenario;
    let [mu, mv] = s.metres_per_pixel();
    let grown = |b: PixelBox, margin: f64| {
        b.grown(
            margin / mu + grid.cell_size[0] / 2.0,
            margin / mv + grid.cell_size[1] / 2.0,
        )
    };
    let objects = s
        .objects
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != object)
        .map(|(_, o)| {
            let margin = match s.is_sensitive(o) {
                true => s.safety.sensitive_margin,
                false => s.safety.obstacle_margin,
            };
            (grown(o.bbox, margin), s.top_above_table(o))
        });
    let goals = s.goals.iter().enumerate().map(|(i, g)| {
        let margin = if i == goal {
            0.0
        } else {
            s.safety.obstacle_margin
        };
        (grown(g.bbox, margin), g.height)
    });
    let hands = s
        .hands
        .iter()
        .map(|h| (grown(h.bbox, s.safety.hand_margin), h.height));
    let passes_over = |b: &PixelBox| {
        // Touching counts: the box grown by a micro-pixel.
        let (lo, hi) = (
            [b.u - 1e-6, b.v - 1e-6],
            [b.u + b.w + 1e-6, b.v + b.l + 1e-6],
        );
        legs.iter().any(|leg| match leg.len() {
            1 => crosses_open_box(leg[0], leg[0], lo, hi),
            _ => leg.windows(2).any(|w| crosses_open_box(w[0], w[1], lo, hi)),
        })
    };
    let tallest = objects
        .chain(goals)
        .chain(hands)
        .filter(|(b, _)| passes_over(b))
        .fold(0.0, |t: f64, (_, h)| t.max(h));
    tallest + s.objects[object].height + settings.carry_clearance
}

fn distance3(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt()
}

/// Cuts every segment longer than `max_step` into equal steps; inserted
/// waypoints take the phase and holding state of the segment's end.
fn densify(waypoints: &[ToolWaypoint], max_step: f64) -> Vec<ToolWaypoint> {
    let mut out: Vec<ToolWaypoint> = waypoints.first().copied().into_iter().collect();
    for pair in waypoints.windows(2) {
        let (a, b) = (pair[0].position, pair[1].position);
        let length = distance3(a, b);
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
        .map(|(_, o)| s.top_above_table(o));
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
