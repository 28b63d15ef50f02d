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
//!   hands, grown by their margins and the footprint) plus the held
//!   object's height plus `carry_clearance`, so the held object's bottom
//!   clears everything under it by at least `carry_clearance`; never below
//!   the approach or release height. [`carry_height`] (the tallest thing
//!   on the whole table) is the fallback after a collision;
//! - the turns over the target: the travel's last stretch descends from the
//!   carry height to the approach height on a quarter ellipse, arriving
//!   vertically, and the carry's first stretch rises the same way after the
//!   lift, instead of right angles (near stops of the arm), where no
//!   segment of the stretch needs more than the approach height by the
//!   carry rule (`eased`); never on the fallback. Where the tool's reach
//!   from the base falls toward the target, the stretch is that whole
//!   fall, up to five drops long, so the height falls while the reach does
//!   (no joint turning at the foot of the vertical move);
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

/// Lifts a solved grid plan: the CQL cells pulled taut into an any-angle
/// route ([`crate::motion::route`]), smoothed ([`smooth_route`]), at the
/// carry height the route needs, with eased turns over the target
/// (`eased`). `Err` is why the gripper cannot take the object (too wide
/// for its opening, too tall for a grip that keeps the palm clear).
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
    // From the tool itself to the next cell: the start cell's centre is
    // where the grid rounds the tool to, not a place to go (and is inside a
    // perimeter when the tool starts in one).
    let mut to_target = vec![request.start_px];
    to_target.extend(centres(&cells[usize::from(grasp_at > 0)..=grasp_at]));
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
    let metres = scenario.metres_per_pixel();
    let under = Under::of(scenario, grid, object, goal);
    let need = |a, b| under.tallest(a, b) + held.height + settings.carry_clearance;
    let carry_height = match request.full_height {
        true => carry_height(scenario, object, settings),
        false => [&travel, &carry]
            .iter()
            .flat_map(|leg| needs(leg, &need))
            .fold(0.0, f64::max),
    }
    .max(approach)
    .max(release);
    // Over the target the tool turns between the route and the vertical
    // moves on a quarter ellipse instead of a corner, where nothing under
    // that stretch needs more than the approach height (not on the
    // full-height fallback).
    let base_of = |p: [f64; 2]| scenario.pixel_to_base(p);
    let ease = |leg: &[[f64; 2]], at_end: bool| match request.full_height {
        true => leg.iter().map(|&p| (p, carry_height)).collect(),
        false => eased(
            leg,
            metres,
            &need,
            &base_of,
            [approach, carry_height],
            at_end,
        ),
    };
    let (travel, carry) = (ease(&travel, true), ease(&carry, false));
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
    let mut along = 0.0;
    for pair in travel.windows(2) {
        let ((from, _), (to, z)) = (pair[0], pair[1]);
        along += planar_distance(from, to, metres);
        // Down along the route at 45° when the tool starts higher.
        out.push(point(to, z.max(start_height - along), Phase::Travel, false));
    }
    let target_px = grid.centre(grid.target);
    // At the approach height already (nothing under the route needs more,
    // or the eased turn ends there): no second waypoint at the same place.
    let over_target = point(target_px, approach, Phase::Approach, false);
    if out
        .last()
        .is_none_or(|w| distance3(w.position, over_target.position) > 1e-9)
    {
        out.push(over_target);
    }
    out.push(point(target_px, grasp, Phase::Grasp, false));
    out.push(point(target_px, carry[0].1, Phase::Lift, true));
    let goal_box = scenario.goals[goal].bbox;
    let mut over = false;
    for &(p, z) in carry.iter().skip(1) {
        over |= goal_box.contains(p);
        let phase = if over { Phase::OverWall } else { Phase::Carry };
        out.push(point(p, z, phase, true));
    }
    out.push(point(drop_px, release, Phase::Release, true));
    out.push(point(drop_px, carry_height, Phase::Retreat, false));
    let eased = travel
        .iter()
        .chain(&carry)
        .any(|&(_, z)| z < carry_height - 1e-9);
    Ok(LiftedMotion {
        waypoints: densify(&out, settings.max_step),
        carry_height,
        eased,
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

/// TCP height above the table at the grasp (see the module doc; over a
/// goal box's floor for a piece resting in one), or why no
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
        // Heights so far are above the piece's bottom: a piece resting in
        // a goal box stands on its floor.
        return Ok(grasp + s.support_under(held.bbox));
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

/// What a footprint (a cell-sized square) passes over on the way: objects
/// other than the held one and goal walls grown by the margins the grid
/// paints them with (the sub-goal's own goal by none), hands by
/// `hand_margin`, each grown again by half the footprint, with their
/// heights above the table (metres).
struct Under(Vec<(PixelBox, f64)>);

impl Under {
    fn of(s: &Scenario, grid: &StateGrid, object: usize, goal: usize) -> Self {
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
        Self(objects.chain(goals).chain(hands).collect())
    }

    /// Height of the tallest thing the footprint passes over from `a` to
    /// `b` (pixels; touching counts), 0 when none.
    fn tallest(&self, a: [f64; 2], b: [f64; 2]) -> f64 {
        self.0
            .iter()
            .filter(|(b_, _)| {
                // Touching counts: the box grown by a micro-pixel.
                let lo = [b_.u - 1e-6, b_.v - 1e-6];
                let hi = [b_.u + b_.w + 1e-6, b_.v + b_.l + 1e-6];
                crosses_open_box(a, b, lo, hi)
            })
            .fold(0.0, |t: f64, (_, h)| t.max(*h))
    }
}

/// The need of every segment of a leg (of its one point when it has one).
fn needs(leg: &[[f64; 2]], need: &dyn Fn([f64; 2], [f64; 2]) -> f64) -> Vec<f64> {
    match leg.len() {
        1 => vec![need(leg[0], leg[0])],
        _ => leg.windows(2).map(|w| need(w[0], w[1])).collect(),
    }
}

/// Samples of the quarter ellipse that eases a turn between the route and
/// a vertical move, from the route's end.
const EASE_SAMPLES: usize = 16;

/// Longest horizontal span of an eased turn, in drops (`high − low`).
const MAX_EASE_SPAN: f64 = 5.0;

/// Rises of the reach from the base (metres) smaller than this do not
/// end a stretch on which it falls toward the target.
const REACH_NOISE: f64 = 1e-4;

/// The leg's points (pixels) with their heights (metres above the table):
/// at `high` = `heights[1]`, except that over the stretch nearest the
/// target (the leg's end when `at_end`, else its start) the height follows
/// a quarter ellipse down to `low` = `heights[0]` at the target, arriving
/// vertically. Its horizontal span is the drop `high − low`, or, where
/// the tool's reach from the robot base (`base_of`: pixels to base-frame
/// metres) falls toward the target, the leg's whole last stretch on which
/// it falls, at most [`MAX_EASE_SPAN`] drops (the whole leg when shorter):
/// the height then falls while the reach does, so a joint that the falling
/// reach moves against the descent (the iiwa's shoulder on a leg passing
/// the base tangentially into the target) is carried past that turn by
/// the descent instead of turning at the foot of it and again on the
/// vertical line. A reach that rises into the target moves such joints
/// the descent's way already.
/// The ellipse is used only when no segment of that stretch needs more
/// than `low` (`need`, metres): everything on it is at least as high as
/// its need; when the long stretch is not clear, the drop's length is
/// tried. The stretch is resampled so the curve has `EASE_SAMPLES` points.
fn eased(
    leg: &[[f64; 2]],
    metres: [f64; 2],
    need: &dyn Fn([f64; 2], [f64; 2]) -> f64,
    base_of: &dyn Fn([f64; 2]) -> [f64; 2],
    [low, high]: [f64; 2],
    at_end: bool,
) -> Vec<([f64; 2], f64)> {
    let mut points: Vec<[f64; 2]> = leg.to_vec();
    if at_end {
        points.reverse();
    }
    // Arc length from the target (the first point now), metres.
    let mut s = vec![0.0; points.len()];
    for i in 1..points.len() {
        s[i] = s[i - 1] + planar_distance(points[i - 1], points[i], metres);
    }
    let length = s.last().copied().unwrap_or(0.0);
    let drop = high - low;
    let falling = falling_stretch(&points, &s, base_of);
    let needs = needs(&points, need);
    let clear = |reach: f64| {
        needs
            .iter()
            .zip(&s)
            .all(|(n, &from)| from >= reach || *n <= low)
    };
    let reach = [falling.clamp(drop, MAX_EASE_SPAN * drop), drop]
        .map(|r| r.min(length))
        .into_iter()
        .find(|&r| r > 1e-6 && clear(r));
    let mut out: Vec<([f64; 2], f64)> = match reach {
        Some(reach) if high > low => {
            let at = |d: f64| {
                let k = s.partition_point(|&x| x < d).clamp(1, points.len() - 1);
                let t = ((d - s[k - 1]) / (s[k] - s[k - 1]).max(1e-12)).clamp(0.0, 1.0);
                [0, 1].map(|c| points[k - 1][c] + t * (points[k][c] - points[k - 1][c]))
            };
            let curve = (0..=EASE_SAMPLES).map(|i| {
                let phi = i as f64 / EASE_SAMPLES as f64 * std::f64::consts::FRAC_PI_2;
                (at(reach * (1.0 - phi.cos())), low + drop * phi.sin())
            });
            let rest = points
                .iter()
                .zip(&s)
                .filter(|&(_, &d)| d > reach + 1e-9)
                .map(|(&p, _)| (p, high));
            curve.chain(rest).collect()
        }
        _ => points.iter().map(|&p| (p, high)).collect(),
    };
    if at_end {
        out.reverse();
    }
    out
}

/// Arc length (metres, `s`) from the first point (the target) over which
/// the reach from the base (the norm of `base_of`, pixels to base-frame
/// metres, an affine map) grows, i.e. falls toward the target; rises of at
/// most [`REACH_NOISE`] are ignored. On a straight segment the reach is
/// least at the foot of the perpendicular from the base, the one place
/// inside it where the reach can turn.
fn falling_stretch(points: &[[f64; 2]], s: &[f64], base_of: &dyn Fn([f64; 2]) -> [f64; 2]) -> f64 {
    let reach = |p: [f64; 2]| {
        let [x, y] = base_of(p);
        x.hypot(y)
    };
    let mut samples = points
        .first()
        .map(|&p| (0.0, reach(p)))
        .into_iter()
        .collect::<Vec<_>>();
    for k in 1..points.len() {
        let (a, b) = (base_of(points[k - 1]), base_of(points[k]));
        let d = [b[0] - a[0], b[1] - a[1]];
        let t = -(a[0] * d[0] + a[1] * d[1]) / (d[0] * d[0] + d[1] * d[1]).max(1e-18);
        if t > 0.0 && t < 1.0 {
            let foot = [a[0] + t * d[0], a[1] + t * d[1]];
            samples.push((s[k - 1] + t * (s[k] - s[k - 1]), foot[0].hypot(foot[1])));
        }
        samples.push((s[k], reach(points[k])));
    }
    let Some(&(_, first)) = samples.first() else {
        return 0.0;
    };
    let (mut extreme, mut at) = (first, 0.0);
    for &(from, r) in &samples[1..] {
        let change = r - extreme;
        if change.abs() <= REACH_NOISE {
            continue;
        }
        if change < 0.0 {
            return at;
        }
        (extreme, at) = (r, from);
    }
    s.last().copied().unwrap_or(0.0)
}

/// Horizontal distance (metres) between two pixels, `metres` per pixel
/// along u and v.
fn planar_distance(a: [f64; 2], b: [f64; 2], [mu, mv]: [f64; 2]) -> f64 {
    ((b[0] - a[0]) * mu).hypot((b[1] - a[1]) * mv)
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
    Ok(longer_side_yaw(s, held))
}

/// Tool yaw (rad, base frame) that lays the tool's x axis along the
/// object's longer side (along u on a tie), as [`grasp_yaw`] without the
/// opening check.
pub fn longer_side_yaw(s: &Scenario, held: &Object) -> f64 {
    let [mu, mv] = s.metres_per_pixel();
    let m = &s.camera.pixel_to_base;
    let (dx, dy) = if held.bbox.w * mu >= held.bbox.l * mv {
        (m[0][0], m[1][0])
    } else {
        (m[0][1], m[1][1])
    };
    dy.atan2(dx)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MM: [f64; 2] = [0.001, 0.001];

    /// Base frame (metres) with the base 0.5 m beside the test legs'
    /// x = 140 px: the reach rises over their last 60 mm to their end at
    /// x = 200 px, so the turn is eased over one drop.
    const BESIDE: fn([f64; 2]) -> [f64; 2] = |p| [(p[0] - 140.0) * 0.001, (p[1] + 500.0) * 0.001];

    /// The turn over the target is a quarter ellipse: it ends at the low
    /// height going straight down, never dips below what the stretch needs,
    /// and reaches the route's height one drop's length before the target.
    #[test]
    fn lift_eases_the_turn_over_the_target_where_nothing_under_needs_more() {
        let leg = [[0.0, 0.0], [100.0, 0.0], [200.0, 0.0]];
        let eased = eased(&leg, MM, &|_, _| 0.08, &BESIDE, [0.12, 0.18], true);
        let (last, before) = (eased[eased.len() - 1], eased[eased.len() - 2]);
        assert_eq!(last, ([200.0, 0.0], 0.12));
        // Arriving vertically: the last step is mostly down.
        assert!(before.1 - last.1 > 5.0 * (last.0[0] - before.0[0]) * 0.001);
        // Flat until 60 mm before the target, then only going down.
        for w in eased.windows(2) {
            assert!(w[1].1 <= w[0].1 + 1e-12 && w[0].1 >= 0.12 - 1e-12);
            if w[1].0[0] <= 140.0 {
                assert!((w[1].1 - 0.18).abs() < 1e-9, "{w:?}");
            }
        }
    }

    /// Something under the last stretch that needs more than the low height
    /// keeps the corner: flat at the route's height up to the target.
    #[test]
    fn lift_keeps_the_corner_where_something_under_needs_the_height() {
        let leg = [[0.0, 0.0], [100.0, 0.0], [200.0, 0.0]];
        let need = |a: [f64; 2], _: [f64; 2]| if a[0] >= 100.0 { 0.15 } else { 0.08 };
        let eased = eased(&leg, MM, &need, &BESIDE, [0.12, 0.18], true);
        assert!(eased.iter().all(|&(_, z)| (z - 0.18).abs() < 1e-12));
        // The other end eases the same way when it is the target's.
        let from_start = eased_heights(&leg, [0.12, 0.18]);
        assert_eq!(from_start.first(), Some(&0.12));
    }

    /// A leg passing the base tangentially, its reach from the base least
    /// over the target (falling all the way to it): the descent spans five
    /// drops (300 mm) of it, so the height falls wherever the reach does
    /// and a joint that both move (the iiwa's shoulder) does not turn where
    /// the leg meets the vertical move. Eased over one drop (60 mm) only,
    /// the reach fell at the carry height first.
    #[test]
    fn lift_descends_over_the_whole_stretch_where_the_reach_falls_toward_the_target() {
        let leg: Vec<[f64; 2]> = (0..=80).map(|k| [5.0 * k as f64, 0.0]).collect();
        let beside = |p: [f64; 2]| [(p[0] - 400.0) * 0.001, 0.5];
        let eased = eased(&leg, MM, &|_, _| 0.08, &beside, [0.12, 0.18], true);
        for &(p, z) in &eased {
            if p[0] >= 105.0 {
                assert!(z < 0.18 - 1e-9, "flat at {p:?} where the reach falls");
            } else if p[0] <= 100.0 {
                assert!((z - 0.18).abs() < 1e-12, "{p:?} {z}");
            }
        }
        // Still arriving vertically at the approach height.
        let (last, before) = (eased[eased.len() - 1], eased[eased.len() - 2]);
        assert_eq!(last, ([400.0, 0.0], 0.12));
        assert!(before.1 - last.1 > 2.0 * (last.0[0] - before.0[0]) * 0.001);
    }

    fn eased_heights(leg: &[[f64; 2]], heights: [f64; 2]) -> Vec<f64> {
        eased(leg, MM, &|_, _| 0.0, &BESIDE, heights, false)
            .into_iter()
            .map(|(_, z)| z)
            .collect()
    }
}
