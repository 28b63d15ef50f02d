//! Any-angle routes: the lifted route starts where the tool is, is shorter
//! than the grid's staircase, carries no higher than what it passes over
//! needs, and turns onto the vertical moves without a corner (against the
//! independent oracle's shortest paths: `bench/tests/routes.rs`).

use afford_planner::lift::Phase;
use afford_planner::scenario::{Object, default_scenario};
use afford_planner::{Plan, PlanOptions, Scenario, Stage};

fn plan_waypoints(scenario: &Scenario) -> Plan {
    let options = PlanOptions {
        until: Stage::Waypoints,
        ..PlanOptions::default()
    };
    afford_planner::plan(scenario, &options).expect("plans")
}

fn planar_length(points: impl Iterator<Item = [f64; 2]>) -> f64 {
    let points: Vec<[f64; 2]> = points.collect();
    points
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

#[test]
fn route_starts_where_the_tool_is_and_beats_the_staircase() {
    let scenario = default_scenario().expect("default scenario");
    let plan = plan_waypoints(&scenario);
    let mut start = scenario.robot.start.expect("start pixel");
    for (k, done) in plan.subgoals.iter().enumerate() {
        let motion = done.waypoints.as_ref().expect("waypoints");
        let first = motion.waypoints[0];
        assert_eq!(first.phase, Phase::Start);
        let [x, y] = scenario.pixel_to_base(start);
        assert!(
            (first.position[0] - x).hypot(first.position[1] - y) < 1e-9,
            "sub-goal {k} starts at {:?}, the tool is at ({x}, {y})",
            first.position
        );
        // The route (horizontal, metres) against the cell centres it was
        // pulled from, from the same start.
        let route = planar_length(
            motion
                .waypoints
                .iter()
                .map(|w| [w.position[0], w.position[1]]),
        );
        let staircase = planar_length(
            std::iter::once(start)
                .chain(done.path_px.iter().copied())
                .chain(std::iter::once(done.release_px))
                .map(|p| scenario.pixel_to_base(p)),
        );
        assert!(
            route < staircase - 0.01 || route < staircase * 0.99,
            "sub-goal {k}: route {route:.3} m, staircase {staircase:.3} m"
        );
        start = done.release_px;
    }
}

#[test]
fn carry_height_ignores_a_tall_piece_off_the_route() {
    let mut scenario = default_scenario().expect("default scenario");
    let before = plan_waypoints(&scenario);
    // A 0.2 m tall piece in the far corner, away from every route.
    scenario.objects.push(Object {
        name: "tall-red-circle".to_string(),
        color: "red".to_string(),
        shape: "circle".to_string(),
        bbox: [560.0, 20.0, 40.0, 40.0].into(),
        height: 0.2,
    });
    let after = plan_waypoints(&scenario);
    for (a, b) in before.subgoals.iter().zip(&after.subgoals) {
        let carry = |p: &afford_planner::plan::SubgoalPlan| {
            p.waypoints.as_ref().expect("waypoints").carry_height
        };
        // The left box's 0.10 m wall is on every route: 0.10 + 0.03 + 0.05.
        assert!((carry(a) - 0.18).abs() < 1e-9, "{}", carry(a));
        assert!(
            (carry(b) - carry(a)).abs() < 1e-9,
            "{} vs {}",
            carry(b),
            carry(a)
        );
    }
    assert_eq!(before.subgoals.len(), after.subgoals.len());
}

/// Largest turn (degrees) between consecutive non-zero 3-D segments of
/// `points`.
fn sharpest_turn(points: &[[f64; 3]]) -> f64 {
    let steps: Vec<[f64; 3]> = points
        .windows(2)
        .map(|w| [0, 1, 2].map(|k| w[1][k] - w[0][k]))
        .filter(|d| d.iter().map(|x| x * x).sum::<f64>() > 1e-12)
        .collect();
    steps
        .windows(2)
        .map(|w| {
            let dot: f64 = (0..3).map(|k| w[0][k] * w[1][k]).sum();
            let norm = |d: &[f64; 3]| d.iter().map(|x| x * x).sum::<f64>().sqrt();
            (dot / (norm(&w[0]) * norm(&w[1])))
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees()
        })
        .fold(0.0, f64::max)
}

/// The tool turns from the route down onto the target, and from the lift
/// into the carry, on a curve instead of a right angle (each right angle
/// was a near stop; nothing under those stretches needs the carry height
/// in the default scenario).
#[test]
fn route_turns_onto_the_vertical_moves_without_a_corner() {
    let scenario = default_scenario().expect("default scenario");
    let plan = plan_waypoints(&scenario);
    for (k, done) in plan.subgoals.iter().enumerate() {
        let motion = done.waypoints.as_ref().expect("waypoints");
        let stretch = |phases: &[Phase]| -> Vec<[f64; 3]> {
            motion
                .waypoints
                .iter()
                .filter(|w| phases.contains(&w.phase))
                .map(|w| w.position)
                .collect()
        };
        let down = stretch(&[Phase::Travel, Phase::Approach, Phase::Grasp]);
        let up = stretch(&[Phase::Lift, Phase::Carry]);
        let (d, u) = (sharpest_turn(&down), sharpest_turn(&up));
        eprintln!("sub-goal {k}: sharpest turn down {d:.1}°, up {u:.1}°");
        assert!(d < 45.0 && u < 45.0, "sub-goal {k}: {d:.1}°, {u:.1}°");
        // An eased motion says so: a collision on it is retried with the
        // full-height motion (right-angle turns) before any cell is blocked.
        assert!(motion.eased, "sub-goal {k}");
    }
}
