//! Cartesian path IK and arm choice: straight lines solve continuously, a path
//! leaving the workspace names its first unreachable waypoint, and the
//! Care-O-bot 4 picks the arm on the target's side of the table.

use afford_kinematics::{
    IkFailure, IkTarget, PathSettings, RobotModel, Vec3, choose_arm, max_joint_step, top_down_pose,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const IIWA_TABLE_Z: f64 = -0.40;
const COB_TABLE_Z: f64 = 0.75;

fn line(a: Vec3, b: Vec3, n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| a.lerp(&b, i as f64 / (n - 1) as f64))
        .collect()
}

fn check_continuous(robot: &str, arm_name: &str, targets: &[IkTarget], start: Option<&[f64]>) {
    let m = RobotModel::builtin(robot).unwrap();
    let arm = m.arm(arm_name).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let path = arm
        .solve_path(targets, start, &PathSettings::default(), &mut rng)
        .unwrap_or_else(|e| panic!("{robot}/{arm_name}: {e}"));
    assert_eq!(path.waypoints.len(), targets.len());
    let mut largest = 0.0f64;
    for (k, (q, t)) in path.waypoints.iter().zip(targets).enumerate() {
        let (dp, dr) = t.error(&arm.fk(q));
        assert!(
            dp <= 1e-4 && dr <= 1e-3,
            "{robot}/{arm_name} waypoint {k}: {dp} m, {dr} rad"
        );
        assert!(arm.within_limits(q, 0.0));
        if k > 0 {
            largest = largest.max(max_joint_step(&path.waypoints[k - 1], q));
        }
    }
    assert!(
        largest <= 0.05,
        "{robot}/{arm_name}: largest joint step {largest} rad"
    );
    assert!((path.max_step - largest).abs() < 1e-12);
}

#[test]
fn iiwa_straight_line_of_100_waypoints_is_continuous() {
    let z = IIWA_TABLE_Z + 0.10;
    let pts = line(Vec3::new(0.15, -0.25, z), Vec3::new(0.50, 0.25, z), 100);
    let top_down: Vec<IkTarget> = pts
        .iter()
        .map(|&p| IkTarget::TopDown {
            position: p,
            yaw: Some(0.3),
        })
        .collect();
    check_continuous("kuka_iiwa14", "arm", &top_down, None);
    let free_yaw: Vec<IkTarget> = pts
        .iter()
        .map(|&p| IkTarget::TopDown {
            position: p,
            yaw: None,
        })
        .collect();
    check_continuous("kuka_iiwa14", "arm", &free_yaw, None);
    // 6-D: a tilted tool carried along a vertical line.
    let rot = top_down_pose(Vec3::zeros(), 0.0).rotation
        * afford_kinematics::Rotation::from_euler_angles(0.3, -0.2, 0.0);
    let six_d: Vec<IkTarget> = line(Vec3::new(0.45, 0.1, -0.30), Vec3::new(0.45, 0.1, 0.10), 100)
        .into_iter()
        .map(|p| IkTarget::Pose(afford_kinematics::Pose::from_parts(p.into(), rot)))
        .collect();
    check_continuous("kuka_iiwa14", "arm", &six_d, None);
}

#[test]
fn care_o_bot4_straight_lines_are_continuous_for_both_arms() {
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let z = COB_TABLE_Z + 0.10;
    for (arm, sign) in [("right", -1.0), ("left", 1.0)] {
        let pts = line(
            Vec3::new(0.45, sign * 0.35, z),
            Vec3::new(0.75, sign * 0.05, z),
            100,
        );
        let targets: Vec<IkTarget> = pts
            .iter()
            .map(|&p| IkTarget::TopDown {
                position: p,
                yaw: None,
            })
            .collect();
        let home = m.arm(arm).unwrap().home.clone();
        check_continuous("care_o_bot4", arm, &targets, Some(&home));
    }
}

#[test]
fn path_leaving_the_workspace_reports_its_first_unreachable_waypoint() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let arm = &m.arms()[0];
    // Top-down along +x at 0.1 above the table: the wrist centre sits 0.276 above the
    // TCP and can be at most 0.82 from the shoulder (0, 0, 0.36).
    let z = IIWA_TABLE_Z + 0.10;
    let pts = line(Vec3::new(0.30, 0.0, z), Vec3::new(1.29, 0.0, z), 100);
    let shoulder = Vec3::new(0.0, 0.0, 0.36);
    let expected = pts
        .iter()
        .position(|p| (p + Vec3::new(0.0, 0.0, 0.276) - shoulder).norm() > 0.82)
        .unwrap();
    let targets: Vec<IkTarget> = pts
        .iter()
        .map(|&p| IkTarget::TopDown {
            position: p,
            yaw: Some(0.0),
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let err = arm
        .solve_path(&targets, None, &PathSettings::default(), &mut rng)
        .unwrap_err();
    assert_eq!(err.index, expected, "{err}");
    assert_eq!(err.count, 100);
    assert!(matches!(err.reason, IkFailure::OutOfReach { .. }), "{err}");
    // Everything before it is reachable on one continuous branch (joint steps
    // grow near the stretched-arm singularity, so only the path bound applies).
    let settings = PathSettings::default();
    let path = arm
        .solve_path(&targets[..expected], None, &settings, &mut rng)
        .unwrap();
    assert!(
        path.max_step <= settings.max_joint_step,
        "{}",
        path.max_step
    );
}

fn descend(x: f64, y: f64) -> Vec<IkTarget> {
    // Approach from 0.20 above the table down to the grasp height, then lift: the paper's motion.
    let top = Vec3::new(x, y, COB_TABLE_Z + 0.20);
    let grasp = Vec3::new(x, y, COB_TABLE_Z + 0.05);
    let mut pts = line(top, grasp, 10);
    pts.extend(line(grasp, top, 10));
    pts.into_iter()
        .map(|p| IkTarget::TopDown {
            position: p,
            yaw: None,
        })
        .collect()
}

/// Near and middle of the table (x <= 0.7 m). Further forward the left arm
/// also wins on the right side: the right arm would need a large torso turn
/// (see kinematics/DESIGN.md).
#[test]
fn care_o_bot4_uses_the_arm_on_the_targets_side() {
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let settings = PathSettings::default();
    for (x, y, expected) in [
        (0.45, 0.30, "left"),
        (0.60, 0.20, "left"),
        (0.70, 0.35, "left"),
        (0.45, -0.30, "right"),
        (0.60, -0.20, "right"),
        (0.70, -0.35, "right"),
    ] {
        let choice = choose_arm(&m, &descend(x, y), m.home(), &settings, &mut rng)
            .unwrap()
            .unwrap();
        assert_eq!(choice.arm, expected, "target ({x}, {y})");
        // The other arm is parked; the chosen arm's joints follow the path.
        let other = m.arms().iter().find(|a| a.name != expected).unwrap();
        for full in &choice.robot_path {
            for &(i, v) in &other.park {
                assert_eq!(full[i], v);
            }
        }
        let chosen = &m.arms()[choice.arm_index];
        assert_eq!(
            chosen.extract(&choice.robot_path[5]),
            choice.path.waypoints[5]
        );
    }
}

#[test]
fn arm_choice_reports_every_arms_failure() {
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let err = choose_arm(
        &m,
        &descend(2.5, 0.0),
        m.home(),
        &PathSettings::default(),
        &mut rng,
    )
    .unwrap()
    .unwrap_err();
    assert_eq!(err.failures.len(), 2);
    assert!(err.failures.iter().all(|(_, f)| f.index == 0));
    assert!(
        choose_arm(
            &m,
            &descend(0.5, 0.0),
            &[0.0; 3],
            &PathSettings::default(),
            &mut rng
        )
        .is_err()
    );
}

/// A screen that rejects the branch the unscreened solve takes (its elbow
/// joint's sign) makes the path IK return another branch; a screen that
/// rejects everything returns the unscreened path unchanged.
#[test]
fn screened_path_ik_leaves_a_rejected_branch_and_never_loses_a_reachable_path() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let arm = m.arm("arm").unwrap();
    let z = IIWA_TABLE_Z + 0.10;
    let targets: Vec<IkTarget> = line(Vec3::new(0.45, -0.1, z), Vec3::new(0.45, 0.1, z), 10)
        .into_iter()
        .map(|p| IkTarget::TopDown {
            position: p,
            yaw: Some(0.0),
        })
        .collect();
    let settings = PathSettings::default();
    let solve = |screen: &mut dyn FnMut(&[Vec<f64>]) -> bool| {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        arm.solve_path_screened(&targets, Some(&arm.home), &settings, &mut rng, screen)
            .unwrap()
    };
    let plain = solve(&mut |_| true);
    let sign = plain.waypoints[0][3].signum();
    let other = solve(&mut |path| path.iter().all(|q| q[3].signum() != sign));
    assert!(
        other.waypoints.iter().all(|q| q[3].signum() != sign),
        "{:?}",
        other.waypoints[0]
    );
    let rejected = solve(&mut |_| false);
    assert_eq!(rejected, plain);
}
