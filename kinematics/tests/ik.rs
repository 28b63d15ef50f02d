//! IK per arm: random reachable poses, top-down grasps over the recommended
//! table regions, seeded solves, and typed failure reasons.

use afford_kinematics::{
    IkFailure, IkSettings, IkTarget, RobotModel, Vec3, bench_arm, random_configuration,
    random_reachable_poses,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Recommended placements (robots/README.md): table height in the base frame
/// and the table region (x range, y range) the camera sees.
const IIWA_TABLE_Z: f64 = -0.40;
const IIWA_REGION: ([f64; 2], [f64; 2]) = ([0.36, 0.66], [-0.20, 0.20]);
const COB_TABLE_Z: f64 = 0.75;
const COB_REGION: ([f64; 2], [f64; 2]) = ([0.40, 1.00], [-0.40, 0.40]);
const GRASP_HEIGHT: f64 = 0.05;

#[test]
fn random_reachable_poses_solve_for_every_arm() {
    const POSES: usize = 2000;
    for name in afford_kinematics::BUILTIN_ROBOTS {
        let m = RobotModel::builtin(name).unwrap();
        for arm in m.arms() {
            let targets = random_reachable_poses(arm, POSES, 11);
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let settings = IkSettings::default();
            let mut ok = 0;
            for t in &targets {
                match arm.solve_ik(&IkTarget::Pose(*t), None, &settings, &mut rng) {
                    Ok(s) => {
                        let pose = arm.fk(&s.q);
                        let dp = (pose.translation.vector - t.translation.vector).norm();
                        let dr = pose.rotation.angle_to(&t.rotation);
                        assert!(
                            dp <= 1e-4 && dr <= 1e-3,
                            "{name}/{}: returned a wrong solution",
                            arm.name
                        );
                        assert!(
                            arm.within_limits(&s.q, 0.0),
                            "{name}/{}: limits violated",
                            arm.name
                        );
                        ok += 1;
                    }
                    Err(IkFailure::InvalidRequest { reason }) => panic!("{reason}"),
                    Err(_) => {}
                }
            }
            let rate = ok as f64 / POSES as f64;
            assert!(rate >= 0.995, "{name}/{}: success {rate}", arm.name);
        }
    }
}

fn grid(region: ([f64; 2], [f64; 2]), step: f64) -> Vec<(f64, f64)> {
    let n = |r: [f64; 2]| ((r[1] - r[0]) / step).round() as usize;
    let mut out = Vec::new();
    for i in 0..=n(region.0) {
        for j in 0..=n(region.1) {
            out.push((region.0[0] + i as f64 * step, region.1[0] + j as f64 * step));
        }
    }
    out
}

#[test]
fn iiwa_reaches_its_camera_region_top_down_at_grasp_approach_and_carry_height() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let arm = &m.arms()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    // Grasp, approach and carry heights of the paper.
    for (k, (x, y)) in grid(IIWA_REGION, 0.05).into_iter().enumerate() {
        let height = [GRASP_HEIGHT, 0.20, 0.25][k % 3];
        let position = Vec3::new(x, y, IIWA_TABLE_Z + height);
        for yaw in [None, Some(0.0), Some(1.2)] {
            let t = IkTarget::TopDown { position, yaw };
            let s = arm
                .solve_ik(&t, None, &IkSettings::default(), &mut rng)
                .unwrap_or_else(|e| panic!("({x:.2}, {y:.2}) yaw {yaw:?}: {e}"));
            let (dp, dr) = t.error(&arm.fk(&s.q));
            assert!(dp <= 1e-4 && dr <= 1e-3);
        }
    }
}

#[test]
fn care_o_bot4_reaches_its_table_region_top_down_with_the_nearer_arm() {
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for (x, y) in grid(COB_REGION, 0.1) {
        let arm = m.arm(if y >= 0.0 { "left" } else { "right" }).unwrap();
        let t = IkTarget::TopDown {
            position: Vec3::new(x, y, COB_TABLE_Z + GRASP_HEIGHT),
            yaw: None,
        };
        let s = arm
            .solve_ik(&t, None, &IkSettings::default(), &mut rng)
            .unwrap_or_else(|e| panic!("{} arm at ({x:.2}, {y:.2}): {e}", arm.name));
        assert!(arm.within_limits(&s.q, 0.0));
    }
}

#[test]
fn seeded_solves_stay_on_the_seed_branch() {
    for name in afford_kinematics::BUILTIN_ROBOTS {
        let m = RobotModel::builtin(name).unwrap();
        for arm in m.arms() {
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            for _ in 0..200 {
                let q = random_configuration(arm, &mut rng);
                // Keep away from the limits so the nudge stays inside.
                let q: Vec<f64> = q
                    .iter()
                    .zip(arm.lower.iter().zip(&arm.upper))
                    .map(|(&v, (&lo, &hi))| v.clamp(lo + 0.1, hi - 0.1))
                    .collect();
                let nudged: Vec<f64> = q.iter().map(|v| v + 0.02).collect();
                let target = IkTarget::Pose(arm.fk(&nudged));
                let s = arm
                    .solve_ik(&target, Some(&q), &IkSettings::default(), &mut rng)
                    .unwrap();
                let step = afford_kinematics::max_joint_step(&q, &s.q);
                assert!(
                    step < 0.1,
                    "{name}/{}: seeded solve jumped {step} rad",
                    arm.name
                );
                assert_eq!(s.attempts, 1);
            }
        }
    }
}

#[test]
fn redundancy_resolves_towards_home() {
    // A target near home's tool pose is solved close to home, not anywhere on the self-motion.
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let arm = &m.arms()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut pose = arm.fk(&arm.home);
    pose.translation.vector += Vec3::new(-0.05, 0.1, 0.05);
    let s = arm
        .solve_ik(
            &IkTarget::Pose(pose),
            None,
            &IkSettings::default(),
            &mut rng,
        )
        .unwrap();
    let d = afford_kinematics::max_joint_step(&arm.home, &s.q);
    assert!(d < 0.5, "solution {d} rad from home");
}

#[test]
fn failures_are_typed_and_never_a_configuration() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let arm = &m.arms()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let s = IkSettings::default();
    // Far away: caught by the reach bound.
    let far = IkTarget::TopDown {
        position: Vec3::new(3.0, 0.0, 0.0),
        yaw: None,
    };
    assert!(matches!(
        arm.solve_ik(&far, None, &s, &mut rng),
        Err(IkFailure::OutOfReach { .. })
    ));
    // Inside the crude bound (1.456 m) but beyond shoulder + 0.82 + 0.276.
    let beyond = IkTarget::Pose(afford_kinematics::pose_from_xyz_rpy(
        [1.25, 0.0, 0.36],
        [0.0, std::f64::consts::FRAC_PI_2, 0.0],
    ));
    assert!(matches!(
        arm.solve_ik(&beyond, None, &s, &mut rng),
        Err(IkFailure::OutOfReach { .. })
    ));
    // Bad requests.
    let nan = IkTarget::TopDown {
        position: Vec3::new(f64::NAN, 0.0, 0.0),
        yaw: None,
    };
    assert!(matches!(
        arm.solve_ik(&nan, None, &s, &mut rng),
        Err(IkFailure::InvalidRequest { .. })
    ));
    let near = IkTarget::TopDown {
        position: Vec3::new(0.4, 0.0, 0.0),
        yaw: None,
    };
    assert!(matches!(
        arm.solve_ik(&near, Some(&[0.0; 3]), &s, &mut rng),
        Err(IkFailure::InvalidRequest { .. })
    ));

    // A user arm whose base joint cannot turn round: a target behind it needs a joint past its limit.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let user = RobotModel::load("six_dof.urdf", &dir).unwrap();
    let arm = &user.arms()[0];
    let behind = IkTarget::TopDown {
        position: Vec3::new(-0.45, 0.0, 0.2),
        yaw: None,
    };
    match arm.solve_ik(&behind, None, &s, &mut rng) {
        Err(IkFailure::JointLimit { joint }) => assert!(joint == "j1" || joint == "j2", "{joint}"),
        other => panic!("expected a joint-limit failure, got {other:?}"),
    }
}

#[test]
fn bench_function_reports_both_solvers() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let b = bench_arm("kuka_iiwa14", &m.arms()[0], 50, 1);
    assert_eq!(b.poses, 50);
    assert!(b.success_rate >= 0.98 && b.median_us > 0.0 && b.k_median_us > 0.0);
    let json = serde_json::to_value(&b).unwrap();
    for key in [
        "robot",
        "arm",
        "success_rate",
        "median_us",
        "k_success_rate",
        "k_median_us",
    ] {
        assert!(json.get(key).is_some(), "{key}");
    }
}
