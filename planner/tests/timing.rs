//! Time-parameterisation (planner::timing): limits, rest, optimality against
//! closed forms, the hand-proximity rule, bad input, determinism.

mod timing_support;

use afford_kinematics::RobotModel;
use afford_planner::timing::deviation::point_segment_distance;
use afford_planner::timing::{
    Hand, JointLimits, JointTrajectory, Proximity, SeparationSettings, TimingError, TimingSettings,
    TimingStatus, time_parameterize, time_parameterize_tool,
};
use afford_planner::trajectory::{GripperCommand, GripperState};
use afford_planner::{Plan, PlanOptions};
use timing_support::{assert_within, load, plan, planar_case, sampled_jerk_ratio, solved};

fn single_joint(distance: f64, v: f64, a: f64) -> f64 {
    let limits = JointLimits {
        lower: vec![-10.0; 1],
        upper: vec![10.0; 1],
        velocity: vec![v],
        acceleration: vec![a],
        jerk: Vec::new(),
    };
    let timing = time_parameterize(
        &[vec![0.0], vec![distance]],
        &limits,
        None,
        &TimingSettings::default(),
    )
    .unwrap();
    let trajectory = solved(&timing);
    assert_within(trajectory, &limits, 1.0);
    trajectory.duration()
}

#[test]
fn trapezoid_matches_closed_form() {
    // D ≥ v²/A: accelerate, cruise, brake: T = D/v + v/A.
    let (d, v, a) = (2.0, 1.0, 2.0);
    let t = single_joint(d, v, a);
    let exact = d / v + v / a;
    assert!((t - exact).abs() / exact < 0.01, "T = {t}, exact {exact}");
}

#[test]
fn bang_bang_matches_closed_form() {
    // D < v²/A: accelerate then brake, never reaching v: T = 2√(D/A).
    let (d, v, a) = (0.2, 1.0, 2.0);
    let t = single_joint(d, v, a);
    let exact = 2.0 * (d / a).sqrt();
    assert!((t - exact).abs() / exact < 0.01, "T = {t}, exact {exact}");
}

#[test]
fn hand_proximity_slows_the_tool_to_reduced_speed() {
    let (path, limits, proximity) = planar_case();
    let rule = &proximity.rule;
    let hand = proximity.hands[0];
    let timing =
        time_parameterize(&path, &limits, Some(&proximity), &TimingSettings::default()).unwrap();
    let trajectory = solved(&timing);
    let summary = timing.separation.as_ref().unwrap();
    assert!(summary.reduced_segments > 0 && summary.crawl_segments > 0);
    let mut fastest_near = 0.0_f64;
    let mut fastest_far = 0.0_f64;
    for p in &trajectory.points {
        let speed = p.velocities[0].hypot(p.velocities[1]);
        let d = hand.distance([p.positions[0], p.positions[1], 0.3]);
        if d <= rule.reduced_speed_distance_m {
            fastest_near = fastest_near.max(speed);
            // The formula's cap (or the crawl floor) holds at every sample.
            assert!(
                speed <= rule.tool_speed_cap(d) * (1.0 + 1e-6) + 1e-9,
                "{speed} at {d}"
            );
        } else {
            fastest_far = fastest_far.max(speed);
        }
    }
    assert!(fastest_near <= 0.25 * (1.0 + 1e-6), "{fastest_near}");
    // Without the hand the same path is faster.
    let free = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
    assert!(free.duration().unwrap() < timing.duration().unwrap());
    let free_top = solved(&free)
        .points
        .iter()
        .map(|p| p.velocities[0].hypot(p.velocities[1]))
        .fold(0.0, f64::max);
    assert!(free_top > 0.25);
}

/// The program bounds the speed of the tool-space interpolant (chords
/// between the waypoints' tools); the real tool follows forward kinematics.
/// Here the tool swings on a 0.2 m arc round a hand, waypoints 1 rad apart:
/// the arc is 4 % longer than its chords, more than `tool_speed_margin`,
/// so a profile on the 0.05 m/s crawl cap moved the real tool at about
/// 0.051 m/s (Care-O-bot scenes 703 and 811 of the safety campaign: 0.0505
/// and 0.0502). Every sample interval's real tool speed (forward
/// kinematics of the samples, as the independent check measures it) must
/// be within the rule's cap, with and without the jerk filter.
#[test]
fn tool_speed_near_hands_measured_by_forward_kinematics() {
    let radius = 0.2;
    let fk = move |q: &[f64]| [radius * q[0].cos(), radius * q[0].sin(), 0.3 + 0.1 * q[1]];
    let path: Vec<Vec<f64>> = (0..=3).map(|k| vec![k as f64, 0.0]).collect();
    let hand = Hand {
        centre: [0.0, 0.0, 0.3],
        radius: 0.05,
    };
    let proximity = Proximity {
        tool_positions: path.iter().map(|q| fk(q)).collect(),
        hands: vec![hand],
        rule: SeparationSettings::default(),
    };
    let rule = &proximity.rule;
    for jerk in [Vec::new(), vec![50.0, 50.0]] {
        let limits = JointLimits {
            lower: vec![-10.0; 2],
            upper: vec![10.0; 2],
            velocity: vec![1.5, 1.5],
            acceleration: vec![4.0, 4.0],
            jerk,
        };
        let timing = time_parameterize_tool(
            &path,
            &limits,
            Some(&proximity),
            Some(&fk),
            &TimingSettings::default(),
        )
        .unwrap();
        let trajectory = solved(&timing);
        let mut fastest = 0.0_f64;
        for w in trajectory.points.windows(2) {
            let (a, b) = (fk(&w[0].positions), fk(&w[1].positions));
            let speed =
                point_segment_distance(a, b, b) / (w[1].time_from_start - w[0].time_from_start);
            let cap = rule.tool_speed_cap(hand.distance(a).min(hand.distance(b)));
            assert!(
                speed <= cap * (1.0 + 1e-6),
                "the real tool at {speed} m/s against a cap of {cap} m/s, t = {} s",
                w[0].time_from_start
            );
            fastest = fastest.max(speed / cap);
        }
        // Within the cap, not far below it: the caps were lowered where the
        // real tool was over, not everywhere.
        assert!(fastest > 0.99, "at most {fastest} of the cap");
        assert!(timing.stats.tool_speed_rounds >= 1, "{:?}", timing.stats);
    }
}

/// Lowering the caps where the real tool is over is bounded: a tool that
/// no timing keeps within the cap (forward kinematics that jumps 5 cm
/// between two samples next to a hand) is a `LimitViolated` status after
/// the last round, never a trajectory.
#[test]
fn tool_speed_over_the_cap_after_every_round_is_refused() {
    let (path, limits, mut proximity) = planar_case();
    let fk = |q: &[f64]| {
        let jump = if q[0] > 0.55 { 0.05 } else { 0.0 };
        [q[0] + jump, q[1], 0.3]
    };
    proximity.tool_positions = path.iter().map(|q| fk(q)).collect();
    let settings = TimingSettings {
        max_tool_deviation_m: 0.1,
        ..TimingSettings::default()
    };
    let timing =
        time_parameterize_tool(&path, &limits, Some(&proximity), Some(&fk), &settings).unwrap();
    assert!(timing.trajectory.is_none());
    assert!(
        matches!(&timing.status, TimingStatus::LimitViolated { violation } if violation.kind == afford_planner::timing::LimitKind::ToolSpeed),
        "{:?}",
        timing.status
    );
    assert_eq!(timing.stats.tool_speed_rounds, 4, "{:?}", timing.stats);
}

#[test]
fn zero_crawl_speed_refuses_a_path_inside_the_protective_distance() {
    let (path, limits, mut proximity) = planar_case();
    proximity.rule.min_tool_speed_m_s = 0.0;
    let err = time_parameterize(&path, &limits, Some(&proximity), &TimingSettings::default())
        .unwrap_err();
    assert!(
        matches!(err, TimingError::InsideProtectiveDistance { .. }),
        "{err}"
    );
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let ok_limits = JointLimits {
        lower: vec![-10.0; 2],
        upper: vec![10.0; 2],
        velocity: vec![1.0, 1.0],
        acceleration: vec![1.0, 1.0],
        jerk: Vec::new(),
    };
    let path = vec![vec![0.0, 0.0], vec![1.0, 1.0]];
    let settings = TimingSettings::default();
    let run = |path: &[Vec<f64>], limits: &JointLimits, settings: &TimingSettings| {
        time_parameterize(path, limits, None, settings)
    };
    assert!(matches!(
        run(&[], &ok_limits, &settings),
        Err(TimingError::NoWaypoints)
    ));
    assert!(matches!(
        run(&[vec![0.0, 0.0], vec![1.0]], &ok_limits, &settings),
        Err(TimingError::WaypointLength { index: 1, .. })
    ));
    assert!(matches!(
        run(
            &[vec![0.0, f64::NAN], vec![1.0, 1.0]],
            &ok_limits,
            &settings
        ),
        Err(TimingError::NonFinite { index: 0, .. })
    ));
    let zero = JointLimits {
        lower: vec![-10.0; 2],
        upper: vec![10.0; 2],
        velocity: vec![1.0, 0.0],
        acceleration: vec![1.0, 1.0],
        jerk: Vec::new(),
    };
    assert!(matches!(
        run(&path, &zero, &settings),
        Err(TimingError::BadLimit { joint: 1, .. })
    ));
    let short = JointLimits {
        lower: vec![-10.0; 2],
        upper: vec![10.0; 2],
        velocity: vec![1.0, 1.0],
        acceleration: vec![1.0],
        jerk: Vec::new(),
    };
    assert!(matches!(
        run(&path, &short, &settings),
        Err(TimingError::SizeMismatch { .. })
    ));
    assert!(matches!(
        run(&[vec![0.0, 0.0], vec![10.5, 1.0]], &ok_limits, &settings),
        Err(TimingError::WaypointOutsideLimits {
            index: 1,
            joint: 0,
            ..
        })
    ));
    let crossed = JointLimits {
        lower: vec![-1.0, 1.0],
        upper: vec![1.0, -1.0],
        ..ok_limits.clone()
    };
    assert!(matches!(
        run(&path, &crossed, &settings),
        Err(TimingError::BadPositionLimits { joint: 1, .. })
    ));
    for bad in [
        TimingSettings {
            speed_scale: 0.0,
            ..TimingSettings::default()
        },
        TimingSettings {
            speed_scale: 1.5,
            ..TimingSettings::default()
        },
        TimingSettings {
            rate_hz: f64::INFINITY,
            ..TimingSettings::default()
        },
        TimingSettings {
            path_points: 1,
            ..TimingSettings::default()
        },
    ] {
        assert!(matches!(
            run(&path, &ok_limits, &bad),
            Err(TimingError::Setting { .. })
        ));
    }
    let proximity = Proximity {
        tool_positions: vec![[0.0; 3]],
        hands: vec![],
        rule: SeparationSettings::default(),
    };
    assert!(matches!(
        time_parameterize(&path, &ok_limits, Some(&proximity), &settings),
        Err(TimingError::SizeMismatch { .. })
    ));
}

#[test]
fn repeated_waypoints_merge_and_a_single_configuration_is_at_rest() {
    let limits = JointLimits {
        lower: vec![-10.0; 1],
        upper: vec![10.0; 1],
        velocity: vec![1.0],
        acceleration: vec![1.0],
        jerk: Vec::new(),
    };
    let still = time_parameterize(
        &[vec![0.3], vec![0.3]],
        &limits,
        None,
        &TimingSettings::default(),
    )
    .unwrap();
    assert_eq!(solved(&still).points.len(), 1);
    let repeated = time_parameterize(
        &[vec![0.0], vec![0.0], vec![1.0], vec![1.0]],
        &limits,
        None,
        &TimingSettings::default(),
    )
    .unwrap();
    assert_within(solved(&repeated), &limits, 1.0);
}

#[test]
fn settings_deny_unknown_fields_and_fill_defaults() {
    let s: SeparationSettings = serde_json::from_str(r#"{"reduced_speed_m_s": 0.2}"#).unwrap();
    assert_eq!(s.reduced_speed_m_s, 0.2);
    assert_eq!(s.human_speed_m_s, 2.0);
    assert!(serde_json::from_str::<SeparationSettings>(r#"{"speed": 1}"#).is_err());
    assert!(serde_json::from_str::<TimingSettings>(r#"{"rate": 1}"#).is_err());
    let t: TimingSettings = serde_json::from_str(r#"{"rate_hz": 250}"#).unwrap();
    assert_eq!(t.path_points, 300);
}

/// Largest step of any sample outside its joint's position limits, rad
/// (negative: every sample inside by that much), with the joint's name.
fn position_excess(plan: &Plan, robot: &RobotModel) -> (f64, String) {
    let mut worst = (f64::NEG_INFINITY, String::new());
    for sub in &plan.subgoals {
        let (Some(t), Some(arm)) = (&sub.trajectory, &sub.arm) else {
            continue;
        };
        let arm = robot.arm(arm).unwrap();
        for p in &t.points {
            for (j, q) in p.positions.iter().enumerate() {
                let excess = (arm.lower[j] - q).max(q - arm.upper[j]);
                if excess > worst.0 {
                    worst = (excess, arm.joint_names[j].clone());
                }
            }
        }
    }
    worst
}

/// Largest distance, metres, of any sample's tool from the tool path of the
/// joint polyline the collision stage checked (an independent measurement:
/// every joint segment traced at 200 points, every sample against all of them).
fn tool_deviation(plan: &Plan, robot: &RobotModel) -> f64 {
    let mut worst: f64 = 0.0;
    for sub in &plan.subgoals {
        let (Some(t), Some(path), Some(arm)) = (&sub.trajectory, &sub.joint_path, &sub.arm) else {
            continue;
        };
        let arm = robot.arm(arm).unwrap();
        let fk = |q: &[f64]| -> [f64; 3] { arm.fk(q).translation.vector.into() };
        let traced: Vec<[f64; 3]> = path
            .windows(2)
            .flat_map(|w| {
                (0..=200).map(|m| {
                    let u = m as f64 / 200.0;
                    let q: Vec<f64> = w[0]
                        .iter()
                        .zip(&w[1])
                        .map(|(a, b)| a + u * (b - a))
                        .collect();
                    fk(&q)
                })
            })
            .collect();
        for p in &t.points {
            let tool = fk(&p.positions);
            let d = traced
                .windows(2)
                .map(|w| point_segment_distance(tool, w[0], w[1]))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    worst
}

/// The fixture's header: "plans (exit 0) with every trajectory sample inside
/// the joint position limits (iiwa joint_a4 >= -2.0944 rad), or refuses the
/// sub-goal with the joint named". A natural cubic spline through the joint
/// waypoints took joint_a4 to -2.1329 rad between waypoints inside the limits.
#[test]
fn limits_spline_overshoot_between_waypoints() {
    let scenario = load("../tests/fixtures/cases/limits-spline-overshoot-tall-object.yaml");
    let robot = RobotModel::builtin("kuka_iiwa14").unwrap();
    let plan = plan(&scenario, &PlanOptions::default());
    for unsolved in &plan.unsolved {
        assert!(unsolved.reason.contains("joint_a"), "{}", unsolved.reason);
    }
    assert!(plan.subgoals.iter().all(|s| s.trajectory.is_some()));
    let (excess, joint) = position_excess(&plan, &robot);
    assert!(excess <= 0.0, "{joint} is {excess} rad outside its limits");
}

/// The same kind on a bare joint path: joint 0 runs up to its upper limit
/// and stays there while joint 1 moves on. Every sample stays inside (a
/// natural cubic spline through these waypoints reaches 1.0085).
#[test]
fn joint_at_its_limit_at_a_corner_stays_inside() {
    let mut path: Vec<Vec<f64>> = (0..=10).map(|k| vec![0.1 * k as f64, 0.0]).collect();
    path.extend((1..=10).map(|k| vec![1.0, 0.1 * k as f64]));
    let limits = JointLimits {
        lower: vec![-1.0, -1.0],
        upper: vec![1.0, 1.0],
        velocity: vec![1.0, 1.0],
        acceleration: vec![4.0, 4.0],
        jerk: Vec::new(),
    };
    let timing = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
    let trajectory = solved(&timing);
    let highest = trajectory
        .points
        .iter()
        .map(|p| p.positions[0])
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(highest <= 1.0, "joint 0 reaches {highest}");
    assert!(highest > 1.0 - 1e-9, "the waypoint at the limit is reached");
}

/// A long joint segment beside 1 cm ones (the first move of a sub-goal):
/// the natural cubic spline swung the tool ~98 mm off the planned path.
/// Here the "arm" maps joints to the tool one to one (metres), so the tool
/// path is the joint polyline itself (a natural cubic spline through these
/// waypoints is 107 mm off it). Then the real first move of
/// sort-blue-squares, 104 mm off with the natural spline.
#[test]
fn tool_leaves_planned_path_on_long_first_segment() {
    let mut path = vec![vec![0.0, 0.0], vec![0.6, 0.2]];
    path.extend((1..=15).map(|k| vec![0.6 + 0.01 * k as f64, 0.2 - 0.01 * k as f64]));
    let limits = JointLimits {
        lower: vec![-2.0, -2.0],
        upper: vec![2.0, 2.0],
        velocity: vec![1.0, 1.0],
        acceleration: vec![4.0, 4.0],
        jerk: Vec::new(),
    };
    let fk = |q: &[f64]| [q[0], q[1], 0.0];
    let settings = TimingSettings::default();
    let timing = time_parameterize_tool(&path, &limits, None, Some(&fk), &settings).unwrap();
    let trajectory = solved(&timing);
    let worst = trajectory
        .points
        .iter()
        .map(|p| {
            path.windows(2)
                .map(|w| point_segment_distance(fk(&p.positions), fk(&w[0]), fk(&w[1])))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    assert!(
        worst <= settings.max_tool_deviation_m,
        "the tool is {worst} m off the planned path"
    );
    let robot = RobotModel::builtin("kuka_iiwa14").unwrap();
    let real = plan(
        &load("../examples/sort-blue-squares.yaml"),
        &PlanOptions::default(),
    );
    let deviation = tool_deviation(&real, &robot);
    assert!(
        deviation <= settings.max_tool_deviation_m,
        "sort-blue-squares: the tool is {deviation} m off the checked path"
    );
}

/// The per-sample check refuses a path whose blends cannot keep the tool
/// within the tolerance: a tolerance far below what any blend reaches is a
/// status, never a trajectory.
#[test]
fn tool_path_tolerance_is_checked_on_every_sample() {
    let path = vec![vec![0.0, 0.0], vec![0.5, 0.0], vec![0.5, 0.5]];
    let limits = JointLimits {
        lower: vec![-2.0, -2.0],
        upper: vec![2.0, 2.0],
        velocity: vec![1.0, 1.0],
        acceleration: vec![4.0, 4.0],
        jerk: Vec::new(),
    };
    // The tool moves 1000× the joints: a blend sized for the tolerance in
    // the linear estimate is checked, and passes.
    let fk = |q: &[f64]| [1000.0 * q[0], 1000.0 * q[1], 0.0];
    let settings = TimingSettings::default();
    let timing = time_parameterize_tool(&path, &limits, None, Some(&fk), &settings).unwrap();
    solved(&timing);
    // A forward kinematics that disagrees with itself between the blend
    // sizing and the check (a jump away from the corner) is caught.
    let jumpy = |q: &[f64]| {
        let off = if q[0] > 0.45 && q[0] < 0.5 && q[1] > 0.0 {
            0.1
        } else {
            0.0
        };
        [q[0] + off, q[1], 0.0]
    };
    let timing = time_parameterize_tool(&path, &limits, None, Some(&jumpy), &settings).unwrap();
    assert!(timing.trajectory.is_none());
    assert!(
        matches!(&timing.status, TimingStatus::LimitViolated { violation } if violation.kind == afford_planner::timing::LimitKind::ToolDeviation),
        "{:?}",
        timing.status
    );
}

/// Care-O-bot torso and wrist joints went 1-3 mrad past their limits with the
/// natural cubic spline (0.8 mrad on cob4-extra-pieces, 0.1 mrad on
/// cob4-here-pointing); now every sample stays inside the limits and the
/// tool within the tolerance of the checked path.
#[test]
fn cob_torso_and_wrist_stay_within_limits_between_waypoints() {
    let robot = RobotModel::builtin("care_o_bot4").unwrap();
    for file in [
        "../examples/cob4-extra-pieces.yaml",
        "../examples/cob4-here-pointing.yaml",
    ] {
        let options = PlanOptions::default();
        let plan = plan(&load(file), &options);
        assert!(plan.subgoals.len() >= 2, "{file}: {:?}", plan.unsolved);
        let (excess, joint) = position_excess(&plan, &robot);
        assert!(excess <= 0.0, "{file}: {joint} is {excess} rad outside");
        let deviation = tool_deviation(&plan, &robot);
        assert!(
            deviation <= options.timing.max_tool_deviation_m,
            "{file}: the tool is {deviation} m off the checked path"
        );
    }
}

/// A continuous joint (infinite limits) may sit anywhere, e.g. at 7 rad.
#[test]
fn continuous_joint_has_no_position_limit() {
    let limits = JointLimits {
        lower: vec![f64::NEG_INFINITY, -1.0],
        upper: vec![f64::INFINITY, 1.0],
        velocity: vec![1.0, 1.0],
        acceleration: vec![4.0, 4.0],
        jerk: Vec::new(),
    };
    let path = vec![vec![7.0, 0.0], vec![7.5, 0.5], vec![8.0, 0.5]];
    let timing = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
    let trajectory = solved(&timing);
    assert_eq!(trajectory.points.last().unwrap().positions, vec![8.0, 0.5]);
}

/// Every sub-goal: one close then one open, each taking the robot
/// description's time; samples exactly at each event's start and end; the
/// arm still (same positions, zero velocity and acceleration) on every
/// sample between; the trajectory starts at t = 0 and ends at rest.
fn assert_gripper_dwell(plan: &Plan, closing: f64, opening: f64) {
    for sub in &plan.subgoals {
        let t = sub.trajectory.as_ref().unwrap();
        let commands: Vec<GripperCommand> = t.gripper.iter().map(|e| e.command).collect();
        assert_eq!(commands, [GripperCommand::Close, GripperCommand::Open]);
        assert!(t.gripper[0].end <= t.gripper[1].start);
        for (event, time) in t.gripper.iter().zip([closing, opening]) {
            assert!((event.end - event.start - time).abs() < 1e-12, "{event:?}");
            let at = |time: f64| t.points.iter().position(|p| p.time_from_start == time);
            let (first, last) = (at(event.start).unwrap(), at(event.end).unwrap());
            assert!(last > first || time == 0.0);
            for p in &t.points[first..=last] {
                assert_eq!(p.positions, t.points[first].positions);
                assert!(
                    p.velocities
                        .iter()
                        .chain(&p.accelerations)
                        .all(|v| *v == 0.0)
                );
            }
        }
        let (start, end) = (&t.points[0], t.points.last().unwrap());
        assert_eq!(start.time_from_start, 0.0);
        for p in [start, end] {
            assert!(
                p.velocities
                    .iter()
                    .chain(&p.accelerations)
                    .all(|v| *v == 0.0)
            );
        }
        assert_eq!(
            &end.positions,
            sub.joint_path.as_ref().unwrap().last().unwrap()
        );
        let states: Vec<GripperState> = t
            .points
            .iter()
            .map(|p| t.gripper_state(p.time_from_start))
            .collect();
        let mut phases = states.clone();
        phases.dedup();
        let expected = [
            GripperState::Open,
            GripperState::Closing,
            GripperState::Closed,
            GripperState::Opening,
            GripperState::Open,
        ];
        assert_eq!(
            phases,
            expected
                .iter()
                .copied()
                .filter(|s| closing > 0.0 || *s != GripperState::Closing)
                .collect::<Vec<_>>()
        );
    }
}

#[test]
fn gripper_dwell_holds_the_arm_at_rest_for_the_closing_time() {
    let robot = RobotModel::builtin("kuka_iiwa14").unwrap();
    let gripper = robot.gripper();
    assert!(gripper.closing_time > 0.0 && gripper.opening_time > 0.0);
    let plan = plan(
        &load("../examples/sort-blue-squares.yaml"),
        &PlanOptions::default(),
    );
    assert!(!plan.subgoals.is_empty());
    assert_gripper_dwell(&plan, gripper.closing_time, gripper.opening_time);
}

/// The times come from the robot description: a copy of the iiwa with a
/// 0.8 s close and a 0.3 s open.
#[test]
fn gripper_dwell_follows_the_robot_descriptions_times() {
    let dir = std::env::temp_dir().join(format!("afford-gripper-time-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy("../robots/kuka_iiwa14.urdf", dir.join("kuka_iiwa14.urdf")).unwrap();
    let description = std::fs::read_to_string("../robots/kuka_iiwa14.yaml").unwrap();
    let changed = description
        .replace("closing_time: 0.5", "closing_time: 0.8")
        .replace("opening_time: 0.5", "opening_time: 0.3");
    assert_ne!(changed, description, "the description names both times");
    std::fs::write(dir.join("robot.yaml"), changed).unwrap();
    let mut scenario = load("../examples/sort-blue-squares.yaml");
    scenario.robot.model = "robot.yaml".into();
    let options = PlanOptions {
        base_dir: dir.clone(),
        ..PlanOptions::default()
    };
    let plan = plan(&scenario, &options);
    std::fs::remove_dir_all(&dir).ok();
    assert_gripper_dwell(&plan, 0.8, 0.3);
}

/// The collision check sees the object taken where the gripper has closed
/// and left where it starts to open: those samples' poses are the grasp and
/// release configurations of the joint path.
#[test]
fn gripper_samples_mark_where_the_object_is_taken_and_left() {
    let plan = plan(
        &load("../examples/sort-blue-squares.yaml"),
        &PlanOptions::default(),
    );
    for sub in &plan.subgoals {
        let t = sub.trajectory.as_ref().unwrap();
        let (taken, left) = t.gripper_samples();
        assert_eq!(t.points[taken].time_from_start, t.gripper[0].end);
        assert_eq!(t.points[left].time_from_start, t.gripper[1].start);
        let path = sub.joint_path.as_ref().unwrap();
        assert!(path.contains(&t.points[taken].positions));
        assert!(path.contains(&t.points[left].positions));
    }
}

/// Tool positions of the samples against the planned tool path (the
/// polyline through the forward kinematics of the joint waypoints), and the
/// largest step outside the joint position limits, on every example and
/// fixture case (not run by default):
/// `cargo test --release -p afford-planner --test timing -- --ignored --nocapture measure_examples`.
#[test]
#[ignore = "measurement: prints per-scenario figures"]
fn measure_examples() {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir("../examples")
        .unwrap()
        .chain(std::fs::read_dir("../tests/fixtures/cases").unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for file in files {
        let scenario = afford_planner::scenario::load(&file).unwrap();
        let Ok(plan) = afford_planner::plan(&scenario, &Default::default()) else {
            println!("{}: no plan", file.display());
            continue;
        };
        let robot = RobotModel::builtin(&scenario.robot.model).unwrap();
        for (k, sub) in plan.subgoals.iter().enumerate() {
            let (Some(t), Some(path), Some(arm)) = (&sub.trajectory, &sub.joint_path, &sub.arm)
            else {
                continue;
            };
            let arm = robot.arm(arm).unwrap();
            let fk = |q: &[f64]| -> [f64; 3] { arm.fk(q).translation.vector.into() };
            let poly: Vec<[f64; 3]> = path.iter().map(|q| fk(q)).collect();
            let deviation = |p: [f64; 3]| {
                poly.windows(2)
                    .map(|w| {
                        afford_planner::timing::deviation::point_segment_distance(p, w[0], w[1])
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let sampled = t
                .points
                .iter()
                .map(|p| deviation(fk(&p.positions)))
                .fold(0.0, f64::max);
            let mut linear: f64 = 0.0;
            for w in path.windows(2) {
                for m in 1..20 {
                    let u = m as f64 / 20.0;
                    let q: Vec<f64> = w[0]
                        .iter()
                        .zip(&w[1])
                        .map(|(a, b)| a + u * (b - a))
                        .collect();
                    linear = linear.max(deviation(fk(&q)));
                }
            }
            let over = t
                .points
                .iter()
                .flat_map(|p| {
                    p.positions
                        .iter()
                        .enumerate()
                        .map(|(j, q)| (arm.lower[j] - q).max(q - arm.upper[j]))
                })
                .fold(f64::NEG_INFINITY, f64::max);
            println!(
                "{} [{k}] duration {:.3} s, tool deviation {:.2} mm (joint-linear {:.2} mm), position excess {:.4} rad",
                file.file_name().unwrap().to_string_lossy(),
                t.duration(),
                1e3 * sampled,
                1e3 * linear,
                over
            );
        }
    }
}

/// Velocity sign changes of joint `j` beyond 1e-3 rad/s.
fn reversals(trajectory: &JointTrajectory, j: usize) -> usize {
    let signs: Vec<f64> = trajectory
        .points
        .iter()
        .map(|p| p.velocities[j])
        .filter(|v| v.abs() > 1e-3)
        .map(f64::signum)
        .collect();
    signs.windows(2).filter(|w| w[0] != w[1]).count()
}

/// Dense IK waypoints (every 1 cm of a 0.3 rad sweep) whose wrist swings
/// ±3 mrad every ten waypoints around a slow turn, the shape path IK gave
/// the examples' wrist joints: pulled taut within the tool budget the
/// wrist turns one way only; without it the timed wrist reverses at every
/// swing.
#[test]
fn timing_joint_reversals_from_ik_zigzag() {
    let path: Vec<Vec<f64>> = (0..=30)
        .map(|k| {
            let u = k as f64 / 30.0;
            let wiggle = 0.003 * (std::f64::consts::TAU * k as f64 / 10.0).sin();
            vec![0.3 * u, 0.5 - 0.1 * u, 0.02 * u + wiggle]
        })
        .collect();
    let fk = |q: &[f64]| -> [f64; 3] {
        let (a, b, c) = (q[0], q[0] + q[1], q[0] + q[1] + q[2]);
        [
            0.6 * a.cos() + 0.4 * b.cos() + 0.1 * c.cos(),
            0.6 * a.sin() + 0.4 * b.sin() + 0.1 * c.sin(),
            0.0,
        ]
    };
    let limits = JointLimits {
        lower: vec![-3.0; 3],
        upper: vec![3.0; 3],
        velocity: vec![1.5; 3],
        acceleration: vec![8.0; 3],
        jerk: vec![400.0; 3],
    };
    let time = |budget: f64| {
        let settings = TimingSettings {
            taut_tool_budget_m: budget,
            ..TimingSettings::default()
        };
        let timing = time_parameterize_tool(&path, &limits, None, Some(&fk), &settings).unwrap();
        solved(&timing).clone()
    };
    let taut = time(TimingSettings::default().taut_tool_budget_m);
    let raw = time(0.0);
    assert_eq!(reversals(&taut, 2), 0, "the wrist still reverses");
    assert!(reversals(&raw, 2) >= 5, "{} reversals", reversals(&raw, 2));
    assert!(sampled_jerk_ratio(&taut, &limits.jerk) <= 1.0 + 1e-6);
}

/// A short rest-to-rest move that never reaches its speed limit: the
/// time-optimal profile switches every joint's acceleration from +A to −A
/// at one point, which the filter alone smooths with a window of 2A/J.
/// With the profile's peak rounded the acceleration falls at the jerk
/// limit's rate instead and a window of about A/J (for the jumps at the
/// rests) is left: the motion ends sooner, every sample still within the
/// jerk, velocity and acceleration limits.
#[test]
fn jerk_limited_profile_ramps_the_acceleration_instead_of_filtering_the_whole_piece() {
    let path = vec![vec![0.0, 0.0], vec![0.12, 0.3], vec![0.25, 0.6]];
    let limits = JointLimits {
        lower: vec![-3.0; 2],
        upper: vec![3.0; 2],
        velocity: vec![10.0; 2],
        acceleration: vec![5.0; 2],
        jerk: vec![250.0; 2],
    };
    let time = |rounds: u32| {
        let settings = TimingSettings {
            jerk_ramp_rounds: rounds,
            ..TimingSettings::default()
        };
        time_parameterize(&path, &limits, None, &settings).unwrap()
    };
    let (filtered, ramped) = (time(0), time(1));
    let widest = 2.0 * 5.0 / 250.0;
    assert_eq!(filtered.stats.jerk_ramp_s, 0.0);
    assert!(
        (filtered.stats.jerk_filter_s - widest).abs() < 1e-9,
        "the filter alone needs its widest window, got {} s",
        filtered.stats.jerk_filter_s
    );
    let (before, after) = (solved(&filtered), solved(&ramped));
    assert!(
        ramped.stats.jerk_ramp_s > 0.0 && ramped.stats.jerk_filter_s <= 0.6 * widest,
        "rounded by {} s, filter {} s",
        ramped.stats.jerk_ramp_s,
        ramped.stats.jerk_filter_s
    );
    assert!(
        after.duration() < before.duration() - 0.25 * widest,
        "ramped {} s against filtered {} s",
        after.duration(),
        before.duration()
    );
    let ratio = sampled_jerk_ratio(after, &limits.jerk);
    assert!(ratio <= 1.0 + 1e-6, "jerk {ratio} × its limit");
    assert_within(after, &limits, 1.0);
}
