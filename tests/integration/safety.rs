//! The safety campaign (`afford bench safety`) at a small size: generated
//! scenes are valid and executable and cover what the campaign promises
//! (both robots, tall and wide pieces, several goals, hands, sensitive
//! colours, several sub-goals); the runner's counts add up, name every
//! class and repeat for the same seed; the CLI prints the documented JSON.

use afford::kinematics::RobotModel;
use afford::planner::instruction::subgoals;
use afford::planner::scenario::{Format, parse};
use afford::planner::{Plan, Scenario};
use afford_bench::safety::{Finding, SafetyConfig, VIOLATION_CLASSES, run_campaign};
use afford_bench::scenes::{ROBOTS, robot_of, scene};

use crate::util::afford;

/// Metres of a pixel length in `s` (the generator's calibrations are
/// axis-aligned with equal scales).
fn metres(s: &Scenario, pixels: f64) -> f64 {
    pixels * s.metres_per_pixel()[0]
}

#[test]
fn campaign_scenes_are_valid_executable_and_repeatable() {
    for k in 0..80 {
        let s = scene(1, k);
        let text = serde_json::to_string(&s).expect("a scene serialises");
        let read = parse(&text, Format::Json, "scene").unwrap_or_else(|e| panic!("scene {k}: {e}"));
        assert_eq!(read, s, "scene {k} does not read back as itself");
        assert_eq!(s.robot.model, robot_of(k));
        let goals = subgoals(&s, 1).unwrap_or_else(|e| panic!("scene {k}: {e}"));
        assert!(!goals.is_empty(), "scene {k}: no sub-goal");
        assert_eq!(s, scene(1, k), "scene {k} differs between two draws");
    }
    assert_ne!(
        scene(1, 0),
        scene(2, 0),
        "the seed does not change the scene"
    );
}

#[test]
fn campaign_scenes_cover_tall_wide_pieces_goals_hands_and_long_instructions() {
    let scenes: Vec<Scenario> = (0..200).map(|k| scene(1, k)).collect();
    let any = |what: &str, f: &dyn Fn(&Scenario) -> bool| {
        assert!(scenes.iter().any(f), "no scene has {what}");
    };
    for robot in ROBOTS {
        any(robot, &|s| s.robot.model == robot);
    }
    any("a piece taller than 0.15 m", &|s| {
        s.objects.iter().any(|o| o.height > 0.15)
    });
    any("a piece wider than the gripper on both sides", &|s| {
        s.objects
            .iter()
            .any(|o| metres(s, o.bbox.w.min(o.bbox.l)) > 0.08)
    });
    any("a piece wide on one side only", &|s| {
        s.objects.iter().any(|o| {
            let (w, l) = (metres(s, o.bbox.w), metres(s, o.bbox.l));
            w.max(l) > 0.08 && w.min(l) < 0.05
        })
    });
    any("three goals", &|s| s.goals.len() == 3);
    any("one goal", &|s| s.goals.len() == 1);
    any("two hands", &|s| s.hands.len() == 2);
    any("no hand", &|s| s.hands.is_empty());
    any("a sensitive colour", &|s| !s.sensitive.is_empty());
    any("four or more sub-goals", &|s| {
        subgoals(s, 1).is_ok_and(|g| g.len() >= 4)
    });
    any("sub-goals into two goals", &|s| {
        subgoals(s, 1).is_ok_and(|g| g.iter().any(|x| x.goal != g[0].goal))
    });
}

/// A checker that asserts what every emitted plan must satisfy whatever its
/// quality (one trajectory per sub-goal, one value per joint, times from 0
/// strictly increasing) and reports a sub-goal whose last sample still moves.
fn structural_check(_: &Scenario, robot: &RobotModel, plan: &Plan) -> Vec<Finding> {
    let mut found = Vec::new();
    for (k, sub) in plan.subgoals.iter().enumerate() {
        let motion = sub.trajectory.as_ref().expect("a trajectory per sub-goal");
        let names = sub.joint_names.as_ref().expect("joint names");
        let arm = robot
            .arm(sub.arm.as_deref().expect("arm"))
            .expect("known arm");
        assert_eq!(names, &arm.joint_names);
        assert_eq!(motion.points[0].time_from_start, 0.0);
        for pair in motion.points.windows(2) {
            assert!(pair[1].time_from_start > pair[0].time_from_start);
        }
        for p in &motion.points {
            assert_eq!(p.positions.len(), names.len());
        }
        let last = motion.points.last().expect("points");
        if last.velocities.iter().any(|v| v.abs() > 1e-9) {
            found.push(Finding {
                class: "rest".into(),
                subgoal: Some(k),
                message: "ends moving".into(),
            });
        }
    }
    found
}

#[test]
fn campaign_counts_add_up_name_every_class_and_repeat() {
    let config = SafetyConfig {
        scenarios: 6,
        seed: 1,
    };
    let mut calls = Vec::new();
    let report = run_campaign(&config, |k| calls.push(k), structural_check).expect("robots load");
    assert_eq!(calls, (1..=6).collect::<Vec<_>>());
    let t = &report.total;
    assert_eq!(t.scenarios, 6);
    assert_eq!(t.planned + t.partly_planned + t.refused, 6);
    for class in VIOLATION_CLASSES {
        assert!(t.violations.contains_key(class), "class {class} missing");
    }
    assert_eq!(report.robots.len(), 2);
    for robot in ROBOTS {
        let r = &report.robots[robot];
        assert_eq!(r.scenarios, 3, "{robot}");
        assert_eq!(r.planned + r.partly_planned + r.refused, 3, "{robot}");
    }
    let sum = |f: fn(&afford_bench::safety::Tally) -> usize| -> usize {
        report.robots.values().map(f).sum()
    };
    assert_eq!(sum(|r| r.trajectories), t.trajectories);
    assert_eq!(
        sum(|r| r.refusals.values().sum()),
        t.refusals.values().sum::<usize>()
    );
    for (kind, c) in &t.refusals_with_free_poses {
        assert_eq!(c.refusals, t.refusals[kind], "{kind}");
        assert!(
            c.with_free_poses <= c.probed && c.probed <= c.refusals,
            "{kind}"
        );
    }
    assert!(t.trajectories > 0, "nothing planned in 6 scenes");
    let refused_subgoals: usize = t.refusals.values().sum();
    assert!(
        t.refused == 0 || refused_subgoals >= t.refused,
        "a refused scene without a refusal reason"
    );
    // Every sub-goal and scene has its planning time.
    let times = &report.planning_time["total"];
    assert_eq!(times.scene.count, t.scenarios);
    assert!(times.subgoal.count >= t.trajectories);
    assert!(
        times.subgoal.median_s <= times.subgoal.p99_s && times.subgoal.p99_s <= times.subgoal.max_s
    );
    // The same seed gives the same report, wall-clock times aside.
    let mut again = run_campaign(&config, |_| {}, structural_check).expect("robots load");
    again.planning_time.clone_from(&report.planning_time);
    assert_eq!(report, again, "same seed, different report");
}

#[test]
fn bench_safety_json_has_the_documented_keys() {
    let run = afford(&[
        "bench",
        "safety",
        "--scenarios",
        "2",
        "--seed",
        "1",
        "--json",
    ]);
    run.assert_code(0);
    let v = run.json();
    for key in [
        "scenarios",
        "planned",
        "partly_planned",
        "refused",
        "violations",
        "refusals",
        "refusals_with_free_poses",
        "robots",
        "planning_time",
    ] {
        assert!(v.get(key).is_some(), "key {key} missing: {v}");
    }
    assert_eq!(v["scenarios"], 2);
    for class in VIOLATION_CLASSES {
        assert!(v["violations"][class].is_u64(), "class {class}: {v}");
    }
    for robot in ROBOTS {
        assert_eq!(v["robots"][robot]["scenarios"], 1, "{robot}: {v}");
    }
    // Every refusal kind, with its refusals counted as `refusals` counts them.
    for (kind, n) in v["refusals"].as_object().expect("refusals") {
        let counts = &v["refusals_with_free_poses"][kind];
        assert_eq!(&counts["refusals"], n, "{kind}: {v}");
        assert!(counts["with_free_poses"].as_u64() <= counts["probed"].as_u64());
    }
    afford(&["bench", "safety", "--scenarios", "0"]).assert_code(2);
}
