//! Size bounds of a user robot (`afford_kinematics::bounds`): each absurd
//! size in the URDF or the description is refused at load time, naming the
//! element, instead of reaching forward kinematics or parry (whose
//! penetration solver panicked on a 1e308 m shape).

use std::path::{Path, PathBuf};

use afford_kinematics::{RobotModel, bounds};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

fn texts() -> (String, String) {
    let read = |f: &str| std::fs::read_to_string(fixtures().join(f)).unwrap();
    (read("six_dof.yaml"), read("six_dof.urdf"))
}

/// Loads the six-DOF fixture with one replacement in the URDF or the
/// description and returns the error message.
fn refused(in_urdf: bool, from: &str, to: &str) -> String {
    let (mut description, mut urdf) = texts();
    let text = if in_urdf { &mut urdf } else { &mut description };
    assert!(text.contains(from), "fixture lacks {from}");
    *text = text.replacen(from, to, 1);
    match RobotModel::from_texts(
        &description,
        Path::new("six_dof.yaml"),
        &urdf,
        Path::new("six_dof.urdf"),
    ) {
        Ok(_) => panic!("loaded with {to}"),
        Err(e) => e.to_string(),
    }
}

fn assert_names(message: &str, needles: &[&str]) {
    for n in needles {
        assert!(message.contains(n), "{n:?} missing from: {message}");
    }
}

#[test]
fn the_unchanged_fixture_loads() {
    let (description, urdf) = texts();
    RobotModel::from_texts(
        &description,
        Path::new("six_dof.yaml"),
        &urdf,
        Path::new("six_dof.urdf"),
    )
    .unwrap();
}

#[test]
fn user_robot_with_a_1e308_m_shape_is_refused() {
    let m = refused(
        true,
        r#"<sphere radius="0.08"/>"#,
        r#"<sphere radius="1e308"/>"#,
    );
    assert_names(&m, &["six_dof.urdf", "link 'shoulder'", "between", "10 m"]);
}

#[test]
fn user_robot_with_a_1e_300_m_shape_is_refused() {
    let m = refused(
        true,
        r#"<box size="0.06 0.06 0.06"/>"#,
        r#"<box size="0.06 1e-300 0.06"/>"#,
    );
    assert_names(&m, &["link 'wrist_2'", "geometry sizes"]);
}

#[test]
fn joint_origin_a_million_metres_away_is_refused() {
    let m = refused(
        true,
        r#"<origin xyz="0 0 0.35"/>"#,
        r#"<origin xyz="0 0 1e6"/>"#,
    );
    assert_names(&m, &["joint 'j3'", "<origin xyz>", "10 m"]);
}

#[test]
fn collision_origin_rpy_of_1e300_rad_is_refused() {
    let m = refused(
        true,
        r#"<origin xyz="0 0 0.1"/>"#,
        r#"<origin xyz="0 0 0.1" rpy="0 1e300 0"/>"#,
    );
    assert_names(&m, &["link 'base'", "<origin rpy>"]);
}

#[test]
fn revolute_limit_of_1e308_rad_is_refused() {
    let m = refused(
        true,
        r#"<limit lower="-1.5" upper="1.5""#,
        r#"<limit lower="-1e308" upper="1.5""#,
    );
    assert_names(&m, &["joint 'j1'", "<limit lower>", "-1e308"]);
}

#[test]
fn joint_velocity_of_1e_9_rad_s_is_refused() {
    let m = refused(
        true,
        r#"velocity="2.0" effort="50" acceleration="5""#,
        r#"velocity="1e-9" effort="50" acceleration="5""#,
    );
    assert_names(&m, &["joint 'j1'", "<limit velocity>", "0.001"]);
}

#[test]
fn acceleration_limit_of_1e12_is_refused() {
    let m = refused(
        false,
        "acceleration_limits: {j2: 5.0",
        "acceleration_limits: {j2: 1e12",
    );
    assert_names(&m, &["six_dof.yaml", "acceleration_limits.j2", "10000"]);
}

#[test]
fn gripper_opening_of_a_kilometre_is_refused() {
    let m = refused(false, "max_opening: 0.06", "max_opening: 1000.0");
    assert_names(&m, &["gripper.max_opening", "between 0 and 1"]);
}

#[test]
fn more_links_than_the_bound_are_refused() {
    let extra: String = (0..=bounds::MAX_LINKS)
        .map(|i| format!("<link name=\"extra_{i}\"/>"))
        .collect();
    let m = refused(
        true,
        "<link name=\"tcp\"/>",
        &format!("<link name=\"tcp\"/>{extra}"),
    );
    assert_names(&m, &["<robot>", "<link>", "at most 512"]);
}

#[test]
fn robot_file_larger_than_the_bound_is_refused_unparsed() {
    let padding = " ".repeat(bounds::MAX_FILE_BYTES as usize);
    let m = refused(true, "<robot ", &format!("{padding}<robot "));
    assert_names(&m, &["six_dof.urdf", "larger than"]);
    let m = refused(
        false,
        "afford_robot: 1",
        &format!("afford_robot: 1\n#{padding}"),
    );
    assert_names(&m, &["six_dof.yaml", "larger than"]);
}

/// Loads the six-DOF fixture with replacements in the URDF and the description.
fn loaded(urdf_edit: (&str, &str), description_edit: (&str, &str)) -> RobotModel {
    let (description, urdf) = texts();
    assert!(urdf.contains(urdf_edit.0) && description.contains(description_edit.0));
    RobotModel::from_texts(
        &description.replacen(description_edit.0, description_edit.1, 1),
        Path::new("six_dof.yaml"),
        &urdf.replacen(urdf_edit.0, urdf_edit.1, 1),
        Path::new("six_dof.urdf"),
    )
    .unwrap()
}

/// A joint's jerk limit comes from the description's `jerk_limits`, else
/// the URDF 1.2 `<limit jerk>`, else the documented default ramp.
#[test]
fn jerk_limit_from_description_then_urdf_then_default() {
    let limit = r#"effort="50" acceleration="5"/>"#;
    let with_jerk = r#"effort="50" acceleration="5" jerk="300"/>"#;
    let section = "acceleration_limits:";
    let m = loaded((limit, with_jerk), (section, section));
    assert_eq!(m.joints()[0].jerk, 300.0);
    let m = loaded(
        (limit, with_jerk),
        (section, "jerk_limits: {j1: 120.0}\nacceleration_limits:"),
    );
    assert_eq!(m.joints()[0].jerk, 120.0);
    let m = loaded((limit, limit), (section, section));
    let j = &m.joints()[1];
    assert_eq!(
        j.jerk,
        j.acceleration / afford_kinematics::DEFAULT_JERK_RAMP_S
    );
}

#[test]
fn jerk_limit_of_1e12_is_refused() {
    let m = refused(
        false,
        "acceleration_limits:",
        "jerk_limits: {j2: 1e12}\nacceleration_limits:",
    );
    assert_names(&m, &["six_dof.yaml", "jerk_limits.j2"]);
}
