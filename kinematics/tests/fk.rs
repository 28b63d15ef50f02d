//! Forward kinematics against the reference poses of the robot facts sheets
//! (numbers carried here): within 1 mm and 0.1 degree.

use afford_kinematics::{Pose, RobotModel, Rotation, Vec3};
use nalgebra::Quaternion;

const POS_TOL: f64 = 1e-3;
const ROT_TOL: f64 = 0.1 * std::f64::consts::PI / 180.0;

fn quat(wxyz: [f64; 4]) -> Rotation {
    Rotation::from_quaternion(Quaternion::new(wxyz[0], wxyz[1], wxyz[2], wxyz[3]))
}

fn assert_pose(what: &str, got: &Pose, pos: [f64; 3], wxyz: [f64; 4]) {
    let dp = (got.translation.vector - Vec3::from(pos)).norm();
    let dr = got.rotation.angle_to(&quat(wxyz));
    assert!(
        dp <= POS_TOL && dr <= ROT_TOL,
        "{what}: position off by {:.3} mm, rotation by {:.4} deg; got {:?} {:?}",
        dp * 1e3,
        dr.to_degrees(),
        got.translation.vector,
        got.rotation.quaternion()
    );
}

/// Facts sheet kuka_iiwa14 section 8: flange (tool0) in base_link.
#[test]
fn iiwa_flange_matches_reference_poses() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let pi = std::f64::consts::PI;
    let rows: [([f64; 7], [f64; 3], [f64; 4]); 4] = [
        ([0.0; 7], [0.0, 0.0, 1.306], [1.0, 0.0, 0.0, 0.0]),
        (
            [0.0, pi / 4.0, 0.0, -pi / 2.0, 0.0, pi / 4.0, 0.0],
            [0.57983, 0.0, 0.24814],
            [0.0, 0.0, 1.0, 0.0],
        ),
        (
            [0.5, -0.4, 0.3, 1.2, -0.7, 0.9, 1.1],
            [-0.44635, -0.45397, 0.82293],
            [0.60756, 0.21793, -0.36050, 0.67336],
        ),
        (
            [-1.2, 1.0, 0.8, -1.3, 2.0, -1.1, -2.5],
            [0.46432, -0.49384, 0.30146],
            [0.04617, 0.37928, 0.90647, -0.17979],
        ),
    ];
    for (q, pos, wxyz) in rows {
        let pose = m.link_pose(&q, "tool0").unwrap();
        assert_pose(&format!("iiwa tool0 at {q:?}"), &pose, pos, wxyz);
        // The arm chain's tool is the TCP, 0.15 beyond the flange along its z axis.
        let tcp = m.arms()[0].fk(&q);
        let expect = pose * nalgebra::Translation3::new(0.0, 0.0, 0.15);
        assert!((tcp.translation.vector - expect.translation.vector).norm() < 1e-12);
    }
    // Intermediate frames at q = (0, pi/4, 0, -pi/2, 0, pi/4, 0): elbow and wrist centre.
    let q = [0.0, pi / 4.0, 0.0, -pi / 2.0, 0.0, pi / 4.0, 0.0];
    let elbow = m.link_pose(&q, "link_4").unwrap().translation.vector;
    let wrist = m.link_pose(&q, "link_6").unwrap().translation.vector;
    assert!(
        (elbow - Vec3::new(0.2970, 0.0, 0.6570)).norm() < POS_TOL,
        "elbow {elbow:?}"
    );
    assert!(
        (wrist - Vec3::new(0.5798, 0.0, 0.3741)).norm() < POS_TOL,
        "wrist {wrist:?}"
    );
}

fn cob_config(m: &RobotModel, side: &str, torso: [f64; 2], arm: [f64; 7]) -> Vec<f64> {
    let mut q = vec![0.0; m.dof()];
    q[m.joint_index("torso_2_joint").unwrap()] = torso[0];
    q[m.joint_index("torso_3_joint").unwrap()] = torso[1];
    for (i, v) in arm.iter().enumerate() {
        q[m.joint_index(&format!("arm_{side}_{}_joint", i + 1))
            .unwrap()] = *v;
    }
    q
}

/// Facts sheet care_o_bot4 section 9: frames in base_link.
#[test]
#[allow(clippy::approx_constant)] // CR's named poses, numbers exactly as written there
fn care_o_bot4_frames_match_reference_poses() {
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let side_pose = [0.9599, 1.6581, -1.0472, -1.6581, -1.0472, -0.6981, 1.07];
    let neg = side_pose.map(|v| -v);
    let folded = [0.9599, 1.5708, -0.12, 1.0, 1.38, 0.75, -1.36];
    let r1 = [0.3, -0.5, 0.4, 1.2, -0.6, 0.8, 0.2];
    let l1 = [-0.7, 0.9, -0.3, -1.4, 0.5, -1.0, 0.6];
    #[allow(clippy::type_complexity)]
    let rows: [(&str, [f64; 2], [f64; 7], &str, [f64; 3], [f64; 4]); 13] = [
        (
            "right",
            [0.0, 0.0],
            [0.0; 7],
            "arm_right_7_link",
            [0.0, -0.99666, 1.00640],
            [0.70705, 0.70717, 0.0, 0.0],
        ),
        (
            "right",
            [0.0, 0.0],
            [0.0; 7],
            "gripper_right_base_link",
            [0.0, -1.07146, 1.00639],
            [0.0, 0.0, -0.70717, 0.70705],
        ),
        (
            "right",
            [0.0, 0.0],
            [0.0; 7],
            "gripper_right_grasp_link",
            [0.0, -1.18146, 1.00637],
            [0.50004, -0.49996, 0.50004, -0.49996],
        ),
        (
            "left",
            [0.0, 0.0],
            [0.0; 7],
            "arm_left_7_link",
            [0.0, 0.99674, 1.00640],
            [0.0, 0.0, 0.70717, 0.70705],
        ),
        (
            "left",
            [0.0, 0.0],
            [0.0; 7],
            "gripper_left_base_link",
            [0.0, 1.07154, 1.00639],
            [0.70705, -0.70717, 0.0, 0.0],
        ),
        (
            "right",
            [0.0, 0.0],
            side_pose,
            "arm_right_7_link",
            [-0.04074, -0.35526, 0.49923],
            [0.02777, -0.77431, -0.02958, -0.63150],
        ),
        (
            "right",
            [0.0, 0.0],
            side_pose,
            "gripper_right_base_link",
            [0.03229, -0.34925, 0.48420],
            [0.63150, -0.02958, 0.77431, 0.02777],
        ),
        (
            "left",
            [0.0, 0.0],
            neg,
            "gripper_left_base_link",
            [0.03229, 0.34932, 0.48420],
            [0.02777, 0.77431, -0.02958, 0.63150],
        ),
        (
            "right",
            [0.0, 0.0],
            folded,
            "gripper_right_base_link",
            [-0.35398, 0.06199, 0.47758],
            [0.30757, -0.79474, -0.39078, -0.34796],
        ),
        (
            "right",
            [-1.0, 0.5],
            r1,
            "arm_right_7_link",
            [-0.15043, -0.87425, 0.82658],
            [0.35568, 0.49687, -0.38519, -0.69155],
        ),
        (
            "right",
            [-1.0, 0.5],
            r1,
            "gripper_right_base_link",
            [-0.22233, -0.86083, 0.84225],
            [0.69155, -0.38518, -0.49687, 0.35568],
        ),
        (
            "left",
            [-1.0, 0.5],
            l1,
            "arm_left_7_link",
            [0.66646, 0.55863, 0.94792],
            [0.59382, -0.01477, -0.71233, -0.37382],
        ),
        (
            "left",
            [-1.0, 0.5],
            l1,
            "gripper_left_base_link",
            [0.60400, 0.59978, 0.94677],
            [0.37382, -0.71233, 0.01477, 0.59382],
        ),
    ];
    for (side, torso, arm, link, pos, wxyz) in rows {
        let q = cob_config(&m, side, torso, arm);
        let pose = m.link_pose(&q, link).unwrap();
        assert_pose(
            &format!("cob4 {link} torso {torso:?} arm {arm:?}"),
            &pose,
            pos,
            wxyz,
        );
        // link_poses and link_pose agree.
        let all = m.link_poses(&q).unwrap();
        let i = m.link_index(link).unwrap();
        assert!((all[i].translation.vector - pose.translation.vector).norm() < 1e-12);
    }
}

/// Facts sheet care_o_bot4 section 9, arm alone (arm_base_link -> arm_7_link).
#[test]
fn care_o_bot4_arm_alone_matches_reference_poses() {
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let rows: [([f64; 7], [f64; 3], [f64; 4]); 3] = [
        ([0.0; 7], [0.0, 0.0, 0.98270], [1.0, 0.0, 0.0, 0.0]),
        (
            [0.5, -0.8, 0.3, 1.1, -0.4, 0.9, -0.6],
            [0.25309, 0.04865, 0.82326],
            [0.81669, 0.35211, -0.40925, -0.20384],
        ),
        (
            [1.2, 1.0, -1.5, -2.0, 2.0, -1.5, 1.5],
            [0.15577, -0.34676, 0.42460],
            [0.68859, -0.13036, 0.03569, -0.71244],
        ),
    ];
    for side in ["right", "left"] {
        for (arm, pos, wxyz) in rows {
            let q = cob_config(&m, side, [0.3, -0.2], arm);
            let base = m.link_pose(&q, &format!("arm_{side}_base_link")).unwrap();
            let tip = m.link_pose(&q, &format!("arm_{side}_7_link")).unwrap();
            assert_pose(
                &format!("cob4 {side} arm alone {arm:?}"),
                &(base.inverse() * tip),
                pos,
                wxyz,
            );
        }
    }
}

/// The arm chains (torso folded in) agree with the tree FK on the grasp point.
#[test]
fn arm_chains_agree_with_tree_fk() {
    for name in afford_kinematics::BUILTIN_ROBOTS {
        let m = RobotModel::builtin(name).unwrap();
        for arm in m.arms() {
            let mut q = m.home().to_vec();
            for (k, &i) in arm.joint_indices.iter().enumerate() {
                q[i] = 0.3 * (k as f64 + 1.0).sin();
            }
            let tree = m.link_pose(&q, &arm.tool_link).unwrap();
            let chain = arm.fk(&arm.extract(&q));
            assert!((tree.translation.vector - chain.translation.vector).norm() < 1e-12);
            assert!(tree.rotation.angle_to(&chain.rotation) < 1e-12);
        }
    }
}
