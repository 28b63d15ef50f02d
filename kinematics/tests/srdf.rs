//! SRDF: `disable_collisions` pairs join the self-collision skip list,
//! `group_state`s become named postures, and whatever the URDF does not
//! have is an error naming the SRDF and the element.

use std::path::{Path, PathBuf};

use afford_kinematics::{KinematicsError, RobotModel};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// The mimic gripper described in a scratch folder with `srdf` as its SRDF.
fn with_srdf(test: &str, srdf: &str) -> Result<RobotModel, KinematicsError> {
    let dir = std::env::temp_dir().join(format!("afford-srdf-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let yaml = std::fs::read_to_string(fixtures().join("mimic_gripper.yaml")).unwrap();
    let urdf = fixtures().join("mimic_gripper.urdf");
    let yaml = yaml.replace(
        "urdf: mimic_gripper.urdf",
        &format!("urdf: {}\nsrdf: gripper.srdf", urdf.display()),
    );
    std::fs::write(dir.join("gripper.yaml"), yaml).unwrap();
    std::fs::write(dir.join("gripper.srdf"), srdf).unwrap();
    RobotModel::from_path(&dir.join("gripper.yaml"))
}

const SRDF: &str = r#"<?xml version="1.0"?>
<robot name="mimic_gripper">
  <group name="gripper"><joint name="finger_left_joint"/></group>
  <group_state name="open" group="gripper">
    <joint name="finger_left_joint" value="0.04"/>
    <joint name="finger_right_joint" value="0.04"/>
  </group_state>
  <group_state name="tilted" group="arm"><joint name="lift" value="-0.5"/></group_state>
  <disable_collisions link1="finger_left" link2="finger_right" reason="Never"/>
</robot>
"#;

#[test]
fn srdf_disabled_pairs_join_the_self_collision_skip() {
    let plain = RobotModel::load("mimic_gripper.yaml", &fixtures()).unwrap();
    let m = with_srdf("skip", SRDF).unwrap();
    let pair = |m: &RobotModel| {
        let (a, b) = (
            m.link_index("finger_left").unwrap(),
            m.link_index("finger_right").unwrap(),
        );
        m.skips_self_collision(a, b)
    };
    assert!(!pair(&plain) && pair(&m));
    assert_eq!(
        m.self_collision_skip().len(),
        plain.self_collision_skip().len() + 1
    );
}

#[test]
fn srdf_group_states_are_named_postures() {
    let m = with_srdf("postures", SRDF).unwrap();
    let names: Vec<(&str, &str)> = m
        .named_postures()
        .iter()
        .map(|p| (p.name.as_str(), p.group.as_str()))
        .collect();
    assert_eq!(names, [("open", "gripper"), ("tilted", "arm")]);
    // The mimic joint's value is its leader's business: only the leader is set.
    assert_eq!(m.named_postures()[0].values, [(1, 0.04)]);
    assert_eq!(m.posture("open").unwrap(), [m.home()[0], 0.04]);
    assert_eq!(m.posture("tilted").unwrap(), [-0.5, m.home()[1]]);
    assert!(m.posture("closed").is_none());
}

#[test]
fn srdf_errors_name_the_file_and_the_element() {
    let cases = [
        (
            SRDF.replace("link2=\"finger_right\"", "link2=\"thumb\""),
            "disable_collisions #1",
            "thumb",
        ),
        (
            SRDF.replace("value=\"-0.5\"", "value=\"2.5\""),
            "group_state 'tilted'",
            "outside its limits",
        ),
        (
            SRDF.replace("name=\"lift\"", "name=\"wrist\""),
            "group_state 'tilted'",
            "wrist",
        ),
        (
            SRDF.replace(
                "value=\"0.04\"/>\n    <joint",
                "value=\"0 1\"/>\n    <joint",
            ),
            "group_state 'open'",
            "one finite number",
        ),
        (SRDF.replace("</robot>", ""), "<robot>", ""),
    ];
    for (k, (text, element, detail)) in cases.iter().enumerate() {
        let e = with_srdf(&format!("error-{k}"), text).unwrap_err();
        let message = e.to_string();
        assert!(matches!(e, KinematicsError::Srdf { .. }), "{message}");
        assert!(
            message.contains("gripper.srdf")
                && message.contains(element)
                && message.contains(detail),
            "{message}"
        );
    }
}
