//! Continuous joints: no position limits are invented,
//! IK, path IK, random configurations and the arm-choice cost stay finite
//! and correct when a joint's range is the whole real line.

use std::path::{Path, PathBuf};

use afford_kinematics::{
    IkSettings, IkTarget, JointKind, PathSettings, RobotModel, Vec3, choose_arm,
    random_configuration,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

fn robot() -> RobotModel {
    RobotModel::load("continuous.yaml", &fixtures()).expect("continuous robot loads")
}

#[test]
fn continuous_joint_has_no_invented_limits() {
    let m = robot();
    let continuous: Vec<&str> = m
        .joints()
        .iter()
        .filter(|j| j.kind == JointKind::Continuous)
        .map(|j| j.name.as_str())
        .collect();
    assert_eq!(continuous, ["j1", "j6"]);
    for j in m.joints() {
        let bounded = j.kind != JointKind::Continuous;
        assert_eq!(j.is_bounded(), bounded, "{}", j.name);
        if !bounded {
            assert_eq!((j.lower, j.upper), (f64::NEG_INFINITY, f64::INFINITY));
            assert_eq!(j.mid(), 0.0);
            // Any finite value is inside, 7 rad and far beyond included.
            for q in [7.0, -7.0, 100.0, 2.0 * std::f64::consts::PI + 0.1] {
                assert!(j.within(q, 0.0), "{} at {q}", j.name);
            }
        }
    }
    let arm = &m.arms()[0];
    assert!(arm.within_limits(&[7.0, 0.6, 1.2, 0.0, 1.3, -9.0], 0.0));
    assert!(arm.mid_range().iter().all(|v| v.is_finite()));
    assert!(arm.reach.is_finite() && arm.reach > 0.5);
    // The JSON of a model shows no limit at all for a continuous joint.
    let json = serde_json::to_value(&m.joints()[0]).expect("serialise");
    assert!(json["lower"].is_null() && json["upper"].is_null(), "{json}");
}

#[test]
fn random_configurations_of_a_continuous_joint_stay_within_a_turn_of_home() {
    let m = robot();
    let arm = &m.arms()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut spread = [f64::INFINITY, f64::NEG_INFINITY];
    for _ in 0..500 {
        let q = random_configuration(arm, &mut rng);
        assert!(q.iter().all(|v| v.is_finite()));
        assert!(arm.within_limits(&q, 0.0));
        let d = q[0] - arm.home[0];
        assert!(d.abs() <= std::f64::consts::PI, "{d}");
        spread = [spread[0].min(d), spread[1].max(d)];
    }
    // The draw covers the whole turn, not a sliver of it.
    assert!(spread[0] < -2.5 && spread[1] > 2.5, "{spread:?}");
}

#[test]
fn continuous_joint_at_7_rad_seeds_ik_and_stays_on_its_turn() {
    let m = robot();
    let arm = &m.arms()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    // The home posture with the base turned by 7 rad and the flange by -7 rad.
    let seed = [7.0, 0.6, 1.2, 0.0, 1.3, -7.0];
    let here = arm.fk(&seed).translation.vector;
    let target = IkTarget::TopDown {
        position: here + Vec3::new(0.02, 0.03, 0.01),
        yaw: None,
    };
    let s = arm
        .solve_ik(&target, Some(&seed), &IkSettings::default(), &mut rng)
        .expect("IK from a 7 rad seed");
    assert!(s.position_error < 1e-4);
    assert!(s.q.iter().all(|v| v.is_finite()));
    // Seeded IK stays next to the seed instead of wrapping to [-2pi, 2pi].
    assert!((s.q[0] - 7.0).abs() < 0.3, "{:?}", s.q);
    assert!((s.q[5] + 7.0).abs() < 0.5, "{:?}", s.q);

    // A short straight path from there, and the arm-choice cost, are finite.
    let targets: Vec<IkTarget> = (0..20)
        .map(|k| IkTarget::TopDown {
            position: here + Vec3::new(0.0, 0.005 * k as f64, 0.0),
            yaw: None,
        })
        .collect();
    let mut current = m.home().to_vec();
    arm.insert(&mut current, &seed);
    let choice = choose_arm(&m, &targets, &current, &PathSettings::default(), &mut rng)
        .expect("valid request")
        .expect("reachable path");
    assert!(choice.cost.is_finite(), "{}", choice.cost);
    assert!((choice.path.waypoints[0][0] - 7.0).abs() < 0.3);
}

#[test]
fn continuous_joint_ik_from_home_reaches_targets_behind_the_robot() {
    // Without limits the base may turn any way: a target behind the robot
    // (outside j1's former +-1.5 rad) is reachable.
    let m = robot();
    let arm = &m.arms()[0];
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let target = IkTarget::TopDown {
        position: Vec3::new(-0.45, 0.05, 0.1),
        yaw: None,
    };
    let s = arm
        .solve_ik(&target, None, &IkSettings::default(), &mut rng)
        .expect("reachable behind the robot");
    assert!(s.position_error < 1e-4 && s.q.iter().all(|v| v.is_finite()));
}
