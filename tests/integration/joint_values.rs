//! Joint values. A bad `robot.joints` (a joint missing, a value outside its
//! limits) is bad input (exit 2, the field named) even when the instruction
//! cannot be executed either: it was reported as exit 1 (unplannable), the
//! joint state never read. And a plan with one Care-O-bot joint at 100 rad
//! kept `afford check` busy for minutes (the dense collision check cut the
//! 100 rad jump into millimetre steps): the jump is a `position` and a
//! `velocity` violation, checked at its samples only; a scenario joint
//! outside its limits is refused before the plan is read.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde_json::Value;

use crate::util::{afford, afford_with_path, assert_contains_all, repo, scratch_dir};

const UNEXECUTABLE: &str = "instruction: \"put the purple elephant next to the moon\"";

/// `example` with each (from, to) replaced, written for test `name`.
fn edited(name: &str, example: &str, edits: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(repo().join("examples").join(example)).expect("example");
    for (from, to) in edits {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(from))
            .map(str::to_string);
        let line = line.unwrap_or_else(|| panic!("{example} has no line starting {from:?}"));
        text = text.replace(&line, to);
    }
    let path = scratch_dir(&format!("joint-values-{name}")).join(example);
    std::fs::write(&path, text).expect("write");
    path
}

#[test]
fn a_bad_joint_state_is_bad_input_even_when_the_instruction_cannot_be_executed() {
    let cases = [
        (
            "cob4-joint-state-start.yaml",
            "torso_2_joint:",
            "    torso_2_joint: 100",
            "robot.joints.torso_2_joint",
        ),
        (
            "cob4-joint-state-start.yaml",
            "arm_left_3_joint:",
            "",
            "robot.joints.arm_left_3_joint",
        ),
        (
            "joint-state-start.yaml",
            "joints:",
            "  joints: {joint_a1: 0.15, joint_a2: 1.1, joint_a3: 0.0, joint_a4: -1.45, joint_a5: 0.0, joint_a6: 0.6, joint_a7: 9}",
            "robot.joints.joint_a7",
        ),
    ];
    for (k, (example, from, to, field)) in cases.into_iter().enumerate() {
        let path = edited(
            &format!("masked-{k}"),
            example,
            &[(from, to), ("instruction:", UNEXECUTABLE)],
        );
        for command in ["plan", "run", "validate"] {
            let run = afford_with_path(&[command], &path, &[]);
            run.assert_code(2).assert_no_panic();
            assert_contains_all(&run.command, &run.stderr, &[field]);
        }
    }
}

/// The example's plan with the torso at 100 rad at one sample.
fn plan_with_torso_at_100_rad(dir: &Path) -> (PathBuf, PathBuf) {
    let scenario = repo().join("examples/cob4-joint-state-start.yaml");
    let mut plan = afford_with_path(&["plan"], &scenario, &[])
        .assert_code(0)
        .json();
    let sub = &mut plan["subgoals"][0];
    let torso = (sub["joint_names"].as_array().expect("names"))
        .iter()
        .position(|n| n == "torso_2_joint")
        .expect("the torso is in the arm");
    sub["trajectory"]["points"][100]["positions"][torso] = Value::from(100.0);
    let path = dir.join("plan.json");
    std::fs::write(&path, serde_json::to_string(&plan).expect("JSON")).expect("write");
    (scenario, path)
}

#[test]
fn a_care_o_bot_plan_with_a_joint_at_100_rad_is_refused_without_checking_the_jump_densely() {
    let dir = scratch_dir("joint-values-100-rad");
    let (scenario, plan) = plan_with_torso_at_100_rad(&dir);
    let started = Instant::now();
    let run = afford(&[
        "check",
        scenario.to_str().expect("UTF-8"),
        plan.to_str().expect("UTF-8"),
        "--json",
    ]);
    eprintln!(
        "check of the 100 rad plan: {:.0} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    run.assert_code(1).assert_no_panic();
    let report = run.json();
    let violations = report["violations"].as_array().expect("violations");
    let classes: Vec<&str> = violations
        .iter()
        .filter_map(|v| v["class"].as_str())
        .collect();
    let position = violations
        .iter()
        .find(|v| v["class"] == "position")
        .expect("a position violation");
    let message = position["message"].as_str().expect("message");
    assert_contains_all(
        "position",
        message,
        &["torso_2_joint", "100.0000 rad", "sample 100"],
    );
    assert!(classes.contains(&"velocity"), "{classes:?}");
    // The jump is no motion to check for collisions: no finding along it
    // (the millimetre steps through it found 44).
    for class in ["penetration", "self_collision", "margin", "target_touched"] {
        assert!(
            !classes.contains(&class),
            "a {class} finding along the jump: {classes:?}"
        );
    }
}

#[test]
fn check_refuses_a_scenario_joint_outside_its_limits_naming_the_field() {
    let dir = scratch_dir("joint-values-check-scenario");
    let (_, plan) = plan_with_torso_at_100_rad(&dir);
    let scenario = edited(
        "check-scenario",
        "cob4-joint-state-start.yaml",
        &[("torso_2_joint:", "    torso_2_joint: 100")],
    );
    let run = afford_with_path(&["check"], &scenario, &[plan.to_str().expect("UTF-8")]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["robot.joints.torso_2_joint", "outside the joint limits"],
    );
}
