//! Direction reversals of the joints on the examples' sub-goals (at most
//! 4 per joint per sub-goal; a reversal is a sign change of a
//! joint's velocity beyond [`REVERSAL_THRESHOLD`]): where they are, and
//! regression tests for their sources.

use std::collections::BTreeMap;

use afford_bench::timing::examples::{EXAMPLES, REVERSAL_THRESHOLD, velocity_reversals};
use afford_planner::lift::LiftedMotion;
use afford_planner::plan::{PlanOptions, SubgoalPlan, plan};
use afford_planner::scenario::{Format, parse};
use afford_planner::trajectory::TimedMotion;

/// The phase of every trajectory sample: the nearest joint-path waypoint
/// (searched forward from the last one matched), named by its tool
/// waypoint's phase, `Lead`/`Park` on the transits before and after.
fn sample_phases(sub: &SubgoalPlan, lifted: &LiftedMotion) -> Vec<String> {
    let (t, path) = (
        sub.trajectory.as_ref().unwrap(),
        sub.joint_path.as_ref().unwrap(),
    );
    let distance = |a: &[f64], b: &[f64]| -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>()
    };
    // The lead transit's length: where the gripper closes on the path less
    // the grasp's waypoint index.
    let (taken, _) = t.gripper_samples();
    let grasp = path
        .iter()
        .position(|q| *q == t.points[taken].positions)
        .unwrap_or(0);
    let lead = grasp.saturating_sub(lifted.gripper_switches().0);
    let end = lead + lifted.waypoints.len();
    let mut at = 0usize;
    t.points
        .iter()
        .map(|p| {
            let window = at.saturating_sub(3)..(at + 60).min(path.len());
            at = window
                .min_by(|&a, &b| {
                    distance(&path[a], &p.positions).total_cmp(&distance(&path[b], &p.positions))
                })
                .unwrap_or(at);
            match at {
                0 => "Here".to_string(),
                i if i <= lead => "Lead".to_string(),
                i if i > end => "Park".to_string(),
                i => format!(
                    "{:?}",
                    lifted.waypoint_of(i - lead).map(|(_, ph)| ph).unwrap()
                ),
            }
        })
        .collect()
}

/// Per example sub-goal the most reversals of a joint, and for every joint
/// with more than 4 each reversal's phase and the joint's excursion since
/// its previous turn, mrad; then every joint's reversals by phase and
/// excursion (< 5, 5–20, ≥ 20 mrad). Not run by default:
/// `cargo test --release -p afford-bench --test reversals -- --ignored --nocapture diagnose_example_reversals`.
#[test]
#[ignore = "measurement: prints where the reversals are"]
fn diagnose_example_reversals() {
    let options = PlanOptions::default();
    let (mut over, mut total) = (0, 0);
    let mut by_phase: BTreeMap<String, [usize; 3]> = BTreeMap::new();
    for (name, text) in EXAMPLES {
        let Ok(scenario) = parse(text, Format::Yaml, name) else {
            continue;
        };
        let Ok(planned) = plan(&scenario, &options) else {
            continue;
        };
        for (k, sub) in planned.subgoals.iter().enumerate() {
            let (Some(t), Some(lifted), Some(names)) = (
                sub.trajectory.as_ref(),
                sub.waypoints.as_ref(),
                sub.joint_names.as_ref(),
            ) else {
                continue;
            };
            let phases = sample_phases(sub, lifted);
            let mut worst = 0;
            for (j, joint) in names.iter().enumerate() {
                let (mut last, mut extreme) = (0.0_f64, t.points[0].positions[j]);
                let mut turns = Vec::new();
                for (s, p) in t.points.iter().enumerate() {
                    let v = p.velocities[j];
                    if v.abs() <= REVERSAL_THRESHOLD {
                        continue;
                    }
                    if last != 0.0 && v.signum() != last {
                        let q = p.positions[j];
                        let excursion = 1e3 * (q - extreme).abs();
                        turns.push(format!("{}:{excursion:.0}", phases[s]));
                        let bucket = usize::from(excursion >= 5.0) + usize::from(excursion >= 20.0);
                        by_phase.entry(phases[s].clone()).or_default()[bucket] += 1;
                        extreme = q;
                    }
                    last = v.signum();
                }
                worst = worst.max(turns.len());
                if turns.len() > 4 {
                    println!("{name}[{k}] {joint} {}: {}", turns.len(), turns.join(" "));
                }
            }
            println!("{name}[{k}] worst {worst}");
            over += usize::from(worst > 4);
            total += 1;
        }
    }
    println!("sub-goals over 4: {over} of {total}");
    for (phase, [small, middle, large]) in by_phase {
        println!("{phase:>10}: < 5 mrad {small:>4}, 5-20 {middle:>4}, >= 20 {large:>4}");
    }
}

/// The timed trajectory and joint names of the first sub-goal of the
/// scenario `text` (YAML, named `file` in errors), planned with defaults.
fn first_subgoal(text: &str, file: &str) -> (TimedMotion, Vec<String>) {
    let scenario = parse(text, Format::Yaml, file).unwrap();
    let mut planned = plan(&scenario, &PlanOptions::default()).unwrap();
    let sub = planned.subgoals.swap_remove(0);
    (sub.trajectory.unwrap(), sub.joint_names.unwrap())
}

/// The iiwa's base joint barely moves on the vertical moves of
/// `examples/monitor/hand-approaching.yaml` (±6 mrad, the arm not planar);
/// with every joint's tube narrowed wherever any waypoint's tool strayed,
/// those few mrad came out as a fifth reversal of `joint_a1`.
#[test]
fn taut_joints_turn_at_most_four_times_on_the_hand_approaching_example() {
    let (t, names) = first_subgoal(
        include_str!("../../examples/monitor/hand-approaching.yaml"),
        "hand-approaching.yaml",
    );
    for (j, joint) in names.iter().enumerate() {
        let turns = velocity_reversals(&t, j);
        assert!(turns <= 4, "{joint} reverses {turns} times");
    }
}

/// On `examples/sensitive-yellow.yaml` the travel passes the base
/// tangentially: the tool's reach from the base falls by 7 mm over the
/// last 12 cm before the target, at the carry height, and `joint_a2`
/// (the shoulder, which the reach and the descent both move) turned there
/// and again where the lift met the carry (8 turns). The eased descent now
/// spans that stretch: the height falls wherever the reach does.
#[test]
fn ease_spans_the_falling_reach_so_the_shoulder_turns_at_most_four_times_on_sensitive_yellow() {
    let (t, names) = first_subgoal(
        include_str!("../../examples/sensitive-yellow.yaml"),
        "sensitive-yellow.yaml",
    );
    let shoulder = names.iter().position(|n| n == "joint_a2").unwrap();
    let turns = velocity_reversals(&t, shoulder);
    assert!(turns <= 4, "joint_a2 reverses {turns} times");
}
