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

use crate::error::Refusal;
use crate::grid::Cell;
use crate::motion::route::taut;
use crate::scenario::Scenario;
use crate::smooth::smooth_route;
use crate::task::{Action, GridTask};

mod ease;
mod height;
mod settings;

use ease::{eased, needs, planar_distance};
use height::Under;
pub use height::{carry_height, grasp_height, grasp_pose, grasp_yaw, longer_side_yaw};
pub use settings::{GripperReach, LiftRequest, LiftSettings, LiftedMotion, Phase, ToolWaypoint};

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
