//! Loading robots: built-in names, a user robot from a URDF path (as a
//! scenario's `robot.model` gives it), and clear errors for malformed files.

use std::path::{Path, PathBuf};

use afford_kinematics::{
    IkSettings, IkTarget, KinematicsError, RobotModel, Shape, Vec3, builtin_robots,
};
use rand::SeedableRng;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

#[test]
fn builtin_robots_are_listed_with_arms_dof_and_reach() {
    let robots = builtin_robots().unwrap();
    let names: Vec<&str> = robots.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["kuka_iiwa14", "care_o_bot4"]);
    assert_eq!(robots[0].dof, 7);
    assert_eq!(robots[0].arms.len(), 1);
    assert_eq!(robots[0].arms[0].dof, 7);
    assert_eq!(robots[1].dof, 16);
    let arms: Vec<(&str, usize)> = robots[1]
        .arms
        .iter()
        .map(|a| (a.name.as_str(), a.dof))
        .collect();
    assert_eq!(arms, [("right", 9), ("left", 9)]);
    for r in &robots {
        for a in &r.arms {
            assert!(
                a.reach > 0.8 && a.reach < 2.5,
                "{} {} reach {}",
                r.name,
                a.name,
                a.reach
            );
        }
    }
}

#[test]
fn builtin_models_carry_planning_data() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    assert_eq!(m.joints()[3].acceleration, 11.36);
    assert!((m.joints()[6].upper - 3.05433).abs() < 1e-9);
    assert_eq!(m.gripper().max_opening, 0.08);
    assert_eq!(m.gripper().fingers, ["gripper_link#1"]);
    assert_eq!(m.gripper().closing_time, 0.5);
    let a = m.link_index("link_1").unwrap();
    let b = m.link_index("link_2").unwrap();
    assert!(m.skips_self_collision(a, b));
    assert!(!m.skips_self_collision(
        m.link_index("link_1").unwrap(),
        m.link_index("link_7").unwrap()
    ));
    let l7 = &m.links()[m.link_index("link_7").unwrap()];
    assert!(matches!(l7.colliders[0].shape, Shape::Sphere { radius } if radius == 0.053));
    // Home is within limits and the TCP points down.
    let tcp = m.arms()[0].fk(&m.arms()[0].home);
    assert!((tcp.rotation * Vec3::z() + Vec3::z()).norm() < 1e-4);
    assert!((tcp.translation.vector - Vec3::new(0.51, 0.0, -0.15)).norm() < 1e-4);

    let c = RobotModel::builtin("care_o_bot4").unwrap();
    let right = c.arm("right").unwrap();
    assert_eq!(right.joint_names[0], "torso_2_joint");
    assert!(c.arm("middle").is_err());
    let parked = c.parked_except(c.home(), "right");
    let left_1 = c.joint_index("arm_left_1_joint").unwrap();
    assert_eq!(parked[left_1], -0.9599);
}

#[test]
fn user_robot_loads_from_a_urdf_path_given_in_a_scenario() {
    // A scenario would say `robot: {model: six_dof.urdf}` relative to its folder.
    let m = RobotModel::load("six_dof.urdf", &fixtures()).unwrap();
    assert_eq!(m.name(), "six_dof");
    assert_eq!(m.dof(), 6);
    assert_eq!(
        m.joints()[0].acceleration,
        5.0,
        "URDF 1.2 acceleration attribute used"
    );
    // The description path works too, and so does a built-in name through `load`.
    let m2 = RobotModel::load("six_dof.yaml", &fixtures()).unwrap();
    assert_eq!(
        m2.arms()[0].joint_names,
        ["j1", "j2", "j3", "j4", "j5", "j6"]
    );
    assert_eq!(
        RobotModel::load("kuka_iiwa14", &fixtures()).unwrap().name(),
        "kuka_iiwa14"
    );
    // And it solves IK.
    let arm = &m.arms()[0];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let t = IkTarget::TopDown {
        position: Vec3::new(0.45, 0.1, 0.1),
        yaw: None,
    };
    let s = arm
        .solve_ik(&t, None, &IkSettings::default(), &mut rng)
        .unwrap();
    assert!(s.position_error < 1e-4 && arm.within_limits(&s.q, 0.0));
}

fn message(e: KinematicsError) -> String {
    e.to_string()
}

const DESC: &str = "afford_robot: 1\nname: t\nurdf: t.urdf\narms:\n  - {name: arm, root: base, tool: tip, joints: [j1]}\nacceleration_limits: {j1: 1.0}\n";

const ACM: &str = "allowed_collisions:\n  samples: 100\n  seed: 1\n  clearance: 0.03\n  pairs:\n";

fn urdf_with(joint: &str) -> String {
    format!("<robot name=\"t\"><link name=\"base\"/><link name=\"tip\"/>{joint}</robot>")
}

fn load_texts(desc: &str, urdf: &str) -> Result<RobotModel, KinematicsError> {
    RobotModel::from_texts(
        desc,
        Path::new("user/t.yaml"),
        urdf,
        Path::new("user/t.urdf"),
    )
}

#[test]
fn malformed_urdf_errors_name_file_and_element() {
    let good_joint = "<joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"tip\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" velocity=\"1\"/></joint>";
    assert!(load_texts(DESC, &urdf_with(good_joint)).is_ok());

    let truncated = &urdf_with(good_joint)[..60];
    let e = message(load_texts(DESC, truncated).unwrap_err());
    assert!(
        e.contains("user/t.urdf") && e.contains("malformed URDF"),
        "{e}"
    );

    let missing_parent = good_joint.replace("parent link=\"base\"", "parent link=\"bse\"");
    let e = message(load_texts(DESC, &urdf_with(&missing_parent)).unwrap_err());
    assert!(
        e.contains("user/t.urdf") && e.contains("joint 'j1'") && e.contains("'bse'"),
        "{e}"
    );

    let no_limit = good_joint.replace("<limit lower=\"-1\" upper=\"1\" velocity=\"1\"/>", "");
    let e = load_texts(DESC, &urdf_with(&no_limit)).unwrap_err();
    let text = message(e);
    assert!(
        text.contains("user/t.urdf") && text.contains("joint 'j1'"),
        "{text}"
    );

    let zero_axis = good_joint.replace("0 0 1", "0 0 0");
    let e = message(load_texts(DESC, &urdf_with(&zero_axis)).unwrap_err());
    assert!(e.contains("joint 'j1'") && e.contains("axis"), "{e}");

    let mesh = "<robot name=\"t\"><link name=\"base\"><collision><geometry><mesh filename=\"a.stl\"/></geometry></collision></link></robot>";
    let e = message(load_texts(DESC, mesh).unwrap_err());
    assert!(e.contains("link 'base'") && e.contains("mesh"), "{e}");

    let two_roots = "<robot name=\"t\"><link name=\"base\"/><link name=\"tip\"/></robot>";
    let e = message(load_texts(DESC, two_roots).unwrap_err());
    assert!(e.contains("root link"), "{e}");
}

#[test]
fn malformed_description_errors_name_file_and_element() {
    let urdf = urdf_with(
        "<joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"tip\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" velocity=\"1\"/></joint>",
    );
    let cases: [(&str, &[&str]); 12] = [
        (
            &DESC.replace("joints: [j1]", "joints: [j9]"),
            &["user/t.yaml", "arms[0].joints[0]", "'j9'"],
        ),
        (
            &DESC.replace("tool: tip", "tool: tipp"),
            &["user/t.yaml", "arms[0].tool", "'tipp'"],
        ),
        (
            &DESC.replace("joints: [j1]", "joints: 5"),
            &["user/t.yaml", "malformed robot description"],
        ),
        (&format!("{DESC}colour: red\n"), &["user/t.yaml", "colour"]),
        (
            &format!("{DESC}home: {{j1: 2.0}}\n"),
            &["user/t.yaml", "home.j1", "outside"],
        ),
        (
            &DESC.replace("afford_robot: 1", "afford_robot: 7"),
            &["user/t.yaml", "afford_robot"],
        ),
        (
            &format!("{DESC}self_collision_skip: [[base, tip]]\n"),
            &[
                "self_collision_skip",
                "allowed_collisions",
                "afford robots acm",
            ],
        ),
        (
            &format!("{DESC}{ACM}    - {{pair: [base, nowhere], reason: never}}\n"),
            &["allowed_collisions.pairs[0]", "'nowhere'"],
        ),
        (
            &format!("{DESC}{ACM}    - {{pair: [base, tip], reason: adjacent}}\n"),
            &["allowed_collisions.pairs[0]", "not adjacent"],
        ),
        (
            &format!(
                "{DESC}{}",
                ACM.replace("samples: 100", "samples: 0")
                    .replace("pairs:\n", "pairs: []\n")
            ),
            &["allowed_collisions.samples"],
        ),
        (
            &format!("{DESC}gripper: {{fingers: [tip#3]}}\n"),
            &["gripper.fingers[0]", "'tip#3'", "names no collider"],
        ),
        (
            &format!("{DESC}gripper: {{closing_time: -1.0}}\n"),
            &["gripper.closing_time", "-1"],
        ),
    ];
    for (desc, needles) in cases {
        let e = message(load_texts(desc, &urdf).unwrap_err());
        for n in needles {
            assert!(e.contains(n), "error '{e}' should mention '{n}'");
        }
    }
    let no_acc = DESC.replace("acceleration_limits: {j1: 1.0}\n", "");
    let e = message(load_texts(&no_acc, &urdf).unwrap_err());
    assert!(e.contains("acceleration_limits.j1"), "{e}");
}

#[test]
fn missing_files_and_unknown_names_are_errors_not_panics() {
    let e = message(RobotModel::load("no_such_robot", &fixtures()).unwrap_err());
    assert!(
        e.contains("kuka_iiwa14") && e.contains("care_o_bot4"),
        "{e}"
    );
    let e = message(RobotModel::load("missing/robot.yaml", &fixtures()).unwrap_err());
    assert!(e.contains("missing/robot.yaml"), "{e}");
    let e = message(RobotModel::load("lonely.urdf", &fixtures()).unwrap_err());
    assert!(e.contains("lonely.yaml"), "{e}");
}

#[test]
fn description_without_allowed_collisions_skips_only_adjacent_links() {
    // six_dof.yaml has no `allowed_collisions`: the safe default skips the
    // links joined by a joint (wrist_1 has no geometry, so forearm and
    // wrist_2 meet through it) and checks every other pair.
    let m = RobotModel::load("six_dof.yaml", &fixtures()).unwrap();
    assert!(m.allowed_collisions().is_none());
    let names: Vec<(&str, &str)> = m
        .self_collision_skip()
        .iter()
        .map(|&(a, b)| (m.links()[a].name.as_str(), m.links()[b].name.as_str()))
        .collect();
    assert_eq!(
        names,
        [
            ("base", "shoulder"),
            ("shoulder", "upper_arm"),
            ("upper_arm", "forearm"),
            ("forearm", "wrist_2"),
        ]
    );
    assert_eq!(m.self_collision_skip(), m.adjacent_link_pairs());
}

#[test]
fn self_collision_pairs_from_geometry_not_hand_list() {
    // The Care-O-bot's old hand list skipped arm link 3 against the torso as
    // "cannot meet"; the stored matrix (derived from geometry) checks it.
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let acm = m
        .allowed_collisions()
        .expect("built-in robots store their matrix");
    assert!(acm.samples >= 10_000 && acm.clearance >= 0.01);
    for side in ["right", "left"] {
        for link in ["arm_{side}_3_link", "arm_{side}_4_link"] {
            let link = link.replace("{side}", side);
            let (a, b) = (
                m.link_index("torso_3_link").unwrap(),
                m.link_index(&link).unwrap(),
            );
            assert!(
                !m.skips_self_collision(a, b),
                "torso_3_link vs {link} skipped"
            );
        }
    }
}
