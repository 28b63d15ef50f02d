//! Mimic joints: a gripper whose right finger mirrors the left one (and a
//! knuckle following the right finger) loads with the followers outside the
//! configuration, and forward kinematics poses them from their leader;
//! broken relations are typed errors.

use std::path::{Path, PathBuf};

use afford_kinematics::{KinematicsError, MimicProblem, RobotModel, Vec3};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

fn gripper() -> RobotModel {
    RobotModel::load("mimic_gripper.yaml", &fixtures()).expect("the mimic gripper loads")
}

fn origin(m: &RobotModel, q: &[f64], link: &str) -> Vec3 {
    m.link_pose(q, link).unwrap().translation.vector
}

#[test]
fn mimic_joints_are_not_planning_joints() {
    let m = gripper();
    let names: Vec<&str> = m.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["lift", "finger_left_joint"]);
    assert_eq!(m.dof(), 2);
    let mimics: Vec<(&str, &str, usize)> = m
        .mimic_joints()
        .iter()
        .map(|j| (j.name.as_str(), j.leader.as_str(), j.joint))
        .collect();
    assert_eq!(
        mimics,
        [
            ("finger_right_joint", "finger_left_joint", 1),
            ("knuckle_joint", "finger_right_joint", 1)
        ]
    );
    let knuckle = &m.mimic_joints()[1];
    assert_eq!(
        (knuckle.mimic.multiplier, knuckle.mimic.offset),
        (10.0, 0.1)
    );
}

#[test]
fn the_mimic_fingers_forward_kinematics_follows_the_leader() {
    let m = gripper();
    for opening in [0.0, 0.013, 0.04] {
        for lift in [-0.7, 0.0, 0.4] {
            let q = [lift, opening];
            let palm = m.link_pose(&q, "palm").unwrap();
            // In the palm frame: left at +y, right mirrored at -y.
            let local = |link: &str| {
                palm.inverse_transform_vector(&(origin(&m, &q, link) - palm.translation.vector))
            };
            let (left, right) = (local("finger_left"), local("finger_right"));
            assert!((left.y - (0.005 + opening)).abs() < 1e-12, "{left:?}");
            assert!((right.y + (0.005 + opening)).abs() < 1e-12, "{right:?}");
            assert!((right.z - left.z).abs() < 1e-12);
            // The knuckle turns about x by 10 * opening + 0.1.
            let turn = palm.rotation.inverse() * m.link_pose(&q, "knuckle").unwrap().rotation;
            let expected = 10.0 * opening + 0.1;
            assert!(
                (turn.angle() - expected).abs() < 1e-12,
                "{} vs {expected}",
                turn.angle()
            );
            // Every link pose agrees with the one-link walk.
            let all = m.link_poses(&q).unwrap();
            for (link, pose) in m.links().iter().zip(&all) {
                let one = m.link_pose(&q, &link.name).unwrap();
                assert!((one.translation.vector - pose.translation.vector).norm() < 1e-12);
            }
        }
    }
}

/// Loads the gripper with `edit` applied to its URDF text.
fn edited(edit: impl Fn(&str) -> String) -> Result<RobotModel, KinematicsError> {
    let dir = fixtures();
    let yaml = std::fs::read_to_string(dir.join("mimic_gripper.yaml")).unwrap();
    let urdf = std::fs::read_to_string(dir.join("mimic_gripper.urdf")).unwrap();
    RobotModel::from_texts(
        &yaml,
        Path::new("mimic_gripper.yaml"),
        &edit(&urdf),
        Path::new("mimic_gripper.urdf"),
    )
}

fn mimic_problem(edit: impl Fn(&str) -> String) -> (String, MimicProblem) {
    match edited(edit) {
        Err(KinematicsError::Mimic { joint, problem, .. }) => (joint, problem),
        other => panic!("not a mimic error: {other:?}"),
    }
}

#[test]
fn a_mimic_cycle_is_refused() {
    let (joint, problem) = mimic_problem(|u| {
        u.replace(
            r#"<limit lower="0" upper="0.04" velocity="0.1" effort="20" acceleration="1"/>
  </joint>"#,
            r#"<limit lower="0" upper="0.04" velocity="0.1" effort="20" acceleration="1"/>
    <mimic joint="knuckle_joint"/>
  </joint>"#,
        )
    });
    assert_eq!(joint, "finger_left_joint");
    let MimicProblem::Cycle { joints } = problem else {
        panic!("not a cycle: {problem:?}");
    };
    assert_eq!(
        joints,
        [
            "finger_left_joint",
            "knuckle_joint",
            "finger_right_joint",
            "finger_left_joint"
        ]
    );
}

#[test]
fn a_joint_mimicking_itself_is_a_cycle() {
    let (_, problem) = mimic_problem(|u| {
        u.replace(
            r#"mimic joint="finger_right_joint""#,
            r#"mimic joint="knuckle_joint""#,
        )
    });
    assert!(
        matches!(problem, MimicProblem::Cycle { ref joints } if joints.len() == 2),
        "{problem:?}"
    );
}

#[test]
fn a_mimic_leader_must_exist_and_move() {
    let (joint, problem) = mimic_problem(|u| {
        u.replace(
            r#"mimic joint="finger_left_joint""#,
            r#"mimic joint="thumb""#,
        )
    });
    assert_eq!(joint, "finger_right_joint");
    assert_eq!(
        problem,
        MimicProblem::UnknownLeader {
            leader: "thumb".into()
        }
    );
    let (_, problem) = mimic_problem(|u| {
        u.replace(
            r#"mimic joint="finger_left_joint""#,
            r#"mimic joint="palm_tcp""#,
        )
    });
    assert_eq!(
        problem,
        MimicProblem::FixedLeader {
            leader: "palm_tcp".into()
        }
    );
    let (_, problem) = mimic_problem(|u| u.replace(r#"multiplier="10""#, r#"multiplier="1e9""#));
    assert!(
        matches!(problem, MimicProblem::BadValue { .. }),
        "{problem:?}"
    );
}

/// The load error of the mimic gripper with `from` replaced by `to` in its
/// description.
fn description_refusal(from: &str, to: &str) -> String {
    let yaml = std::fs::read_to_string(fixtures().join("mimic_gripper.yaml")).unwrap();
    let urdf = std::fs::read_to_string(fixtures().join("mimic_gripper.urdf")).unwrap();
    RobotModel::from_texts(
        &yaml.replace(from, to),
        Path::new("mimic_gripper.yaml"),
        &urdf,
        Path::new("mimic_gripper.urdf"),
    )
    .unwrap_err()
    .to_string()
}

#[test]
fn a_mimic_joint_is_not_a_joint_of_the_description() {
    let message = description_refusal("{finger_left_joint: 0.02}", "{finger_right_joint: 0.02}");
    assert!(
        message.contains("home.finger_right_joint") && message.contains("mimic"),
        "{message}"
    );
}

#[test]
fn an_arm_through_a_mimic_joint_is_refused() {
    let message = description_refusal("tool: tcp", "tool: knuckle");
    assert!(
        message.contains("mimic joint 'finger_right_joint'"),
        "{message}"
    );
}
