//! Time-parameterisation (planner::timing): limits, rest, optimality against
//! closed forms, the hand-proximity rule, bad input, determinism.

use afford_planner::timing::bench::{iiwa_limits, random_smooth_path};
use afford_planner::timing::{
    Hand, JointLimits, JointTrajectory, Program, Proximity, SeparationSettings, Timing,
    TimingError, TimingSettings, TimingStatus, time_parameterize,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn solved(timing: &Timing) -> &JointTrajectory {
    assert_eq!(timing.status, TimingStatus::Solved, "{:?}", timing.stats);
    timing.trajectory.as_ref().expect("solved means sampled")
}

/// Independent check of every sample (does not trust the stage's own check).
fn assert_within(trajectory: &JointTrajectory, limits: &JointLimits, scale: f64) {
    for p in &trajectory.points {
        for j in 0..limits.velocity.len() {
            assert!(p.velocities[j].abs() <= limits.velocity[j] * scale * (1.0 + 1e-6));
            assert!(
                p.accelerations[j].abs() <= limits.acceleration[j] * scale * scale * (1.0 + 1e-6)
            );
        }
    }
}

fn single_joint(distance: f64, v: f64, a: f64) -> f64 {
    let limits = JointLimits {
        lower: vec![-10.0; 1],
        upper: vec![10.0; 1],
        velocity: vec![v],
        acceleration: vec![a],
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
fn random_paths_stay_within_limits_and_rest_at_both_ends() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let limits = iiwa_limits();
    for _ in 0..5 {
        let path = random_smooth_path(&mut rng, 7, 10);
        let timing = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
        let trajectory = solved(&timing);
        assert_within(trajectory, &limits, 1.0);
        let (first, last) = (&trajectory.points[0], trajectory.points.last().unwrap());
        assert_eq!(first.time_from_start, 0.0);
        assert!(
            first
                .velocities
                .iter()
                .chain(&last.velocities)
                .all(|v| v.abs() < 1e-9)
        );
        for (q, w) in first.positions.iter().zip(&path[0]) {
            assert!((q - w).abs() < 1e-9);
        }
        for (q, w) in last.positions.iter().zip(path.last().unwrap()) {
            assert!((q - w).abs() < 1e-9);
        }
        // 100 Hz: consecutive samples 10 ms apart (the last may be closer).
        for w in trajectory.points.windows(2) {
            let dt = w[1].time_from_start - w[0].time_from_start;
            assert!(dt > 0.0 && dt <= 0.01 + 1e-12);
        }
    }
}

/// The LP's greatest profile and the SOCP's exact-time optimum coincide.
#[test]
fn greatest_profile_lp_equals_exact_time_socp() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let limits = iiwa_limits();
    for _ in 0..4 {
        let path = random_smooth_path(&mut rng, 7, 10);
        let lp = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
        let socp = time_parameterize(
            &path,
            &limits,
            None,
            &TimingSettings {
                program: Program::ExactTime,
                ..TimingSettings::default()
            },
        )
        .unwrap();
        let (t_lp, t_socp) = (solved(&lp).duration(), solved(&socp).duration());
        assert!(
            (t_lp - t_socp).abs() / t_socp < 1e-5,
            "LP {t_lp} SOCP {t_socp}"
        );
    }
    let (path, limits, proximity) = planar_case();
    let settings = TimingSettings {
        program: Program::ExactTime,
        ..TimingSettings::default()
    };
    let socp = time_parameterize(&path, &limits, Some(&proximity), &settings).unwrap();
    let lp =
        time_parameterize(&path, &limits, Some(&proximity), &TimingSettings::default()).unwrap();
    let (t_lp, t_socp) = (solved(&lp).duration(), solved(&socp).duration());
    assert!(
        (t_lp - t_socp).abs() / t_socp < 1e-5,
        "LP {t_lp} SOCP {t_socp}"
    );
}

#[test]
fn speed_scale_slows_uniformly() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let path = random_smooth_path(&mut rng, 7, 8);
    let limits = iiwa_limits();
    let full = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
    let half = time_parameterize(
        &path,
        &limits,
        None,
        &TimingSettings {
            speed_scale: 0.5,
            ..TimingSettings::default()
        },
    )
    .unwrap();
    assert_within(solved(&half), &limits, 0.5);
    let ratio = half.duration().unwrap() / full.duration().unwrap();
    assert!((ratio - 2.0).abs() < 1e-3, "ratio {ratio}");
}

#[test]
fn smoothing_weight_still_within_limits_and_not_faster() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let path = random_smooth_path(&mut rng, 7, 8);
    let limits = iiwa_limits();
    let optimal = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
    let smooth = time_parameterize(
        &path,
        &limits,
        None,
        &TimingSettings {
            smoothing_weight: 1e-4,
            ..TimingSettings::default()
        },
    )
    .unwrap();
    assert_within(solved(&smooth), &limits, 1.0);
    assert!(smooth.duration().unwrap() >= optimal.duration().unwrap() * (1.0 - 1e-6));
}

/// Two joints whose tool is at (q0, q1, 0.3) m: a 1.2 m straight line past a
/// hand at (0.6, 0.25, 0.3).
fn planar_case() -> (Vec<Vec<f64>>, JointLimits, Proximity) {
    let path: Vec<Vec<f64>> = (0..=12).map(|k| vec![0.1 * k as f64, 0.0]).collect();
    let tool_positions = path.iter().map(|q| [q[0], q[1], 0.3]).collect();
    let limits = JointLimits {
        lower: vec![-10.0; 2],
        upper: vec![10.0; 2],
        velocity: vec![1.5, 1.5],
        acceleration: vec![4.0, 4.0],
    };
    let proximity = Proximity {
        tool_positions,
        hands: vec![Hand {
            centre: [0.6, 0.25, 0.3],
            radius: 0.05,
        }],
        rule: SeparationSettings::default(),
    };
    (path, limits, proximity)
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
    };
    assert!(matches!(
        run(&path, &short, &settings),
        Err(TimingError::SizeMismatch { .. })
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
fn same_input_same_trajectory() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let path = random_smooth_path(&mut rng, 7, 10);
    let a = time_parameterize(&path, &iiwa_limits(), None, &TimingSettings::default()).unwrap();
    let b = time_parameterize(&path, &iiwa_limits(), None, &TimingSettings::default()).unwrap();
    assert_eq!(a.trajectory, b.trajectory);
    assert_eq!(a.profile, b.profile);
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

/// Writes a JSON case for `scripts/toppra_reference.py` (not run by default):
/// `AFFORD_TIMING_CASE=/tmp/case.json cargo test --release -p afford-planner
/// --test timing -- --ignored export_reference_case`.
#[test]
#[ignore = "writes a file for the toppra comparison script"]
fn export_reference_case() {
    let out = std::env::var("AFFORD_TIMING_CASE").unwrap_or("timing_case.json".into());
    let limits = iiwa_limits();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut cases = Vec::new();
    for _ in 0..10 {
        let path = random_smooth_path(&mut rng, 7, 12);
        let mut durations = serde_json::Map::new();
        for n in [100, 200, 300, 400, 1000] {
            let settings = TimingSettings {
                path_points: n,
                ..TimingSettings::default()
            };
            let timing = time_parameterize(&path, &limits, None, &settings).unwrap();
            durations.insert(n.to_string(), serde_json::json!(timing.duration().unwrap()));
        }
        cases.push(serde_json::json!({
            "waypoints": path,
            "velocity_limits": limits.velocity,
            "acceleration_limits": limits.acceleration,
            "spline": "natural cubic, chord-length knots",
            "afford_duration_s": durations,
        }));
    }
    let doc = serde_json::json!({"cases": cases});
    std::fs::write(&out, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    eprintln!("wrote {out}");
}

/// Prints the `afford bench timing --json` report (not run by default).
#[test]
#[ignore = "benchmark: run with --release -- --ignored --nocapture"]
fn print_bench_report() {
    let report = afford_planner::timing::timing_benchmark(&Default::default());
    println!("{}", serde_json::to_string(&report).unwrap());
}

/// Tool positions of the samples against the planned tool path (the
/// polyline through the forward kinematics of the joint waypoints), and the
/// largest step outside the joint position limits, on every example and
/// fixture case (not run by default):
/// `cargo test --release -p afford-planner --test timing -- --ignored --nocapture measure_examples`.
#[test]
#[ignore = "measurement: prints per-scenario figures"]
fn measure_examples() {
    use afford_kinematics::RobotModel;
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
