//! The independent hand check of an executed motion (afford-check's
//! `check_hands`, `presence`, `stops`) on a planned sub-goal: it must find
//! a hand put where the gripper goes, leave one far away alone, and
//! measure a trajectory that never stops as no stop at all.

use afford_check::{PlanFile, Presence, check_hands, presence, stops};
use afford_kinematics::RobotModel;
use afford_planner::scenario::{Hand, PixelBox, Scenario, default_scenario};
use afford_planner::{PlanOptions, plan};

/// The default scene's first sub-goal, alone, as a plan file.
fn first_subgoal() -> (Scenario, RobotModel, PlanFile) {
    let scenario = default_scenario().unwrap();
    let planned = plan(&scenario, &PlanOptions::default()).unwrap();
    let mut file = PlanFile::from(&planned);
    file.subgoals.truncate(1);
    let robot = RobotModel::builtin(&scenario.robot.model).unwrap();
    (scenario, robot, file)
}

fn hand_at(bbox: PixelBox) -> Vec<Presence> {
    let hand = Hand {
        name: "hand-1".into(),
        bbox,
        height: 0.1,
    };
    presence(&[(0.0, vec![hand])], 0.5)
}

#[test]
fn a_hand_over_the_target_is_found_by_the_hand_check() {
    let (scenario, robot, file) = first_subgoal();
    let target = scenario
        .objects
        .iter()
        .find(|o| o.name == file.subgoals[0].object)
        .unwrap();
    let report = check_hands(&scenario, &robot, &file, 0.0, &hand_at(target.bbox));
    assert!(!report.contacts.is_empty(), "{report:?}");
    assert!(
        report.contacts.iter().any(|c| c.contains("hand-1")),
        "{report:?}"
    );
}

#[test]
fn a_hand_in_the_far_corner_is_left_alone_by_the_hand_check() {
    let (scenario, robot, file) = first_subgoal();
    // The top-right corner: 0.3 m from the first target and the route.
    let corner = PixelBox {
        u: 620.0,
        v: 0.0,
        w: 20.0,
        l: 20.0,
    };
    let report = check_hands(&scenario, &robot, &file, 0.0, &hand_at(corner));
    assert!(report.passed(), "{report:?}");
}

#[test]
fn a_planned_motion_that_never_brakes_measures_its_whole_way_as_the_stop() {
    let (scenario, robot, file) = first_subgoal();
    let points = &file.subgoals[0].trajectory.points;
    let end = points[points.len() - 1].time_from_start;
    let times: Vec<f64> = (1..10).map(|k| end * k as f64 / 10.0).collect();
    let found = stops(&scenario, &robot, &file, 0.0, &times);
    assert_eq!(found.len(), times.len());
    // Somewhere the plan rides on fast to its next rest: far beyond the
    // stopping term of its speed, which a real stop would keep.
    let worst = found.iter().map(|s| s.ratio()).fold(0.0, f64::max);
    assert!(worst > 1.5, "{found:?}");
}

/// `afford check` is for plans: a run's output (its scene changed while it
/// ran) is refused with the reason and where a run is checked instead,
/// not checked against the first scene into false violations.
#[test]
fn afford_check_refuses_a_run_output_naming_what_checks_it() {
    let dir = crate::util::scratch_dir("check-run-output");
    let out = dir.join("run.json");
    let scenario = "examples/monitor/hand-in-the-way.yaml";
    crate::util::afford(&["run", scenario, "-o", &out.to_string_lossy()]).assert_code(0);
    let checked = crate::util::afford(&["check", scenario, &out.to_string_lossy()]);
    checked.assert_code(2);
    crate::util::assert_contains_all(
        "afford check of a run",
        &checked.stderr,
        &["run.json", "output of `afford run`", "people"],
    );
}
