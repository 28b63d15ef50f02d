//! Per-body exemptions (`PathOptions::exempt`): the fingers may close on the
//! target while the palm and the links keep its margin. The fast check and
//! the dense reference agree, and an unknown body name is an error.

use afford_collision::{
    BoxKind, DenseSettings, PathOptions, RobotGeometry, Scene, SceneBox, SceneSpec, dense_tool_path,
};
use afford_kinematics::{RobotModel, top_down_pose};
use nalgebra::Vector3;

const TABLE_Z: f64 = -0.2;

/// A tall (0.088 m) target under a top-down tool that descends to half its
/// height: the iiwa's palm (30 mm above the TCP) enters it by about 14 mm.
fn descent() -> (RobotGeometry, Scene, Vec<afford_kinematics::Pose>) {
    let model = RobotModel::builtin("kuka_iiwa14").unwrap();
    let geometry = RobotGeometry::new(&model).unwrap();
    let scene = Scene::from_spec(&SceneSpec {
        table_z: TABLE_Z,
        table: None,
        boxes: vec![SceneBox {
            name: "tall".into(),
            kind: BoxKind::Object,
            centre: [0.5, -0.2],
            size: [0.04, 0.04, 0.088],
            yaw: 0.0,
            margin: 0.02,
            round: false,
        }],
    })
    .unwrap();
    let path = [0.25, 0.044]
        .map(|h| top_down_pose(Vector3::new(0.5, -0.2, TABLE_Z + h), 0.0))
        .to_vec();
    (geometry, scene, path)
}

fn exempting(bodies: &[&str]) -> PathOptions {
    PathOptions {
        exempt: bodies
            .iter()
            .map(|b| (b.to_string(), "tall".to_string()))
            .collect(),
        ..PathOptions::default()
    }
}

#[test]
fn exempt_fingers_still_see_the_palm_enter_the_target() {
    let (geometry, scene, path) = descent();
    let opts = exempting(&["gripper_link#1"]);
    let verdict = geometry.check_tool_path(&scene, &path, &opts).unwrap();
    let hit = verdict.first().expect("the palm enters the tall target");
    assert_eq!(
        (hit.body.as_str(), hit.other.as_str()),
        ("gripper_link#0", "tall")
    );
    assert!(hit.penetration > 0.010, "{hit}");
    let dense =
        dense_tool_path(&geometry, &scene, &path, &opts, &DenseSettings::default()).unwrap();
    assert!(dense.collides(), "the dense reference agrees");
    assert_eq!(dense.first_hit.unwrap().1, "gripper_link#0");
}

#[test]
fn exempt_pair_leaves_other_obstacles_and_bodies_checked() {
    let (geometry, scene, path) = descent();
    let both = exempting(&["gripper_link#0", "gripper_link#1"]);
    assert!(
        geometry
            .check_tool_path(&scene, &path, &both)
            .unwrap()
            .is_free()
    );
    let dense =
        dense_tool_path(&geometry, &scene, &path, &both, &DenseSettings::default()).unwrap();
    assert!(!dense.collides());
    // An exemption for another obstacle's name leaves this one checked.
    let other = PathOptions {
        exempt: vec![("gripper_link#0".into(), "elsewhere".into())],
        ..PathOptions::default()
    };
    assert!(
        !geometry
            .check_tool_path(&scene, &path, &other)
            .unwrap()
            .is_free()
    );
}

#[test]
fn exempt_with_unknown_body_is_an_error_naming_it() {
    let (geometry, scene, path) = descent();
    let err = geometry
        .check_tool_path(&scene, &path, &exempting(&["gripper_link#7"]))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("exempt[0]") && err.contains("gripper_link#7"),
        "{err}"
    );
}

#[test]
fn tool_body_extents_measure_palm_and_fingertips() {
    let (geometry, _, _) = descent();
    let extents = geometry.tool_body_extents("arm").unwrap();
    let reach = |name: &str| extents.iter().find(|(n, _)| n == name).unwrap().1[1];
    // Palm capsule bottom 0.12 m beyond the flange, TCP 0.15: 30 mm above it.
    assert!((reach("gripper_link#0") + 0.030).abs() < 1e-9);
    // Finger box to 0.165 m: 15 mm beyond the TCP.
    assert!((reach("gripper_link#1") - 0.015).abs() < 1e-9);
}
