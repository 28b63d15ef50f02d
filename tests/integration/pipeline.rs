//! The whole pipeline through the CLI: stages (`--until`), trajectories that
//! `afford check` accepts and edited ones it rejects, CSV output, a user
//! robot named by path in a scenario, and the pipeline benchmark report.

use std::path::Path;

use serde_json::Value;

use crate::util::{afford, afford_with_path, assert_contains_all, repo, scratch_dir};

/// Plans `scenario` to a JSON file in `dir` and returns its path and content.
fn plan_to_file(scenario: &Path, dir: &Path) -> (std::path::PathBuf, Value) {
    let out = dir.join("plan.json");
    afford_with_path(
        &["plan"],
        scenario,
        &["-o", out.to_str().expect("UTF-8 path")],
    )
    .assert_code(0);
    let value = serde_json::from_str(&std::fs::read_to_string(&out).expect("plan written"))
        .expect("plan is JSON");
    (out, value)
}

fn write_json(path: &Path, value: &Value) {
    std::fs::write(path, serde_json::to_string(value).expect("serialise"))
        .expect("write edited plan");
}

#[test]
fn every_stage_adds_its_part_of_the_plan() {
    let expect = [
        (
            "grid",
            vec!["actions", "cells", "path_px"],
            vec!["waypoints", "joint_path", "trajectory"],
        ),
        (
            "waypoints",
            vec!["waypoints"],
            vec!["joint_path", "trajectory"],
        ),
        (
            "joints",
            vec!["waypoints", "arm", "joint_names", "joint_path"],
            vec!["trajectory"],
        ),
        (
            "trajectory",
            vec!["arm", "joint_names", "trajectory"],
            vec![],
        ),
    ];
    for (stage, present, absent) in expect {
        let plan = afford(&["plan", "--until", stage]).assert_code(0).json();
        let first = &plan["subgoals"][0];
        for key in present {
            assert!(!first[key].is_null(), "--until {stage}: '{key}' missing");
        }
        for key in absent {
            assert!(first[key].is_null(), "--until {stage}: '{key}' present");
        }
    }
}

#[test]
fn the_default_trajectory_is_ros_shaped_and_starts_and_ends_at_rest() {
    let plan = afford(&["plan"]).assert_code(0).json();
    for sub in plan["subgoals"].as_array().expect("sub-goals") {
        let names = sub["joint_names"].as_array().expect("joint names").len();
        let points = sub["trajectory"]["points"].as_array().expect("points");
        for end in [&points[0], points.last().expect("last point")] {
            assert_eq!(end["positions"].as_array().expect("positions").len(), names);
            assert!(
                end["velocities"]
                    .as_array()
                    .expect("velocities")
                    .iter()
                    .all(|v| v.as_f64().expect("number").abs() < 1e-9)
            );
        }
        let commands: Vec<&str> = sub["trajectory"]["gripper"]
            .as_array()
            .expect("gripper")
            .iter()
            .map(|e| e["command"].as_str().expect("command"))
            .collect();
        assert_eq!(commands, ["close", "open"]);
        let dt = points[1]["time_from_start"].as_f64().expect("time")
            - points[0]["time_from_start"].as_f64().expect("time");
        assert!((dt - 0.01).abs() < 1e-9, "100 Hz by default, got dt = {dt}");
    }
}

#[test]
fn check_accepts_a_planned_trajectory_and_rejects_a_velocity_edit() {
    let dir = scratch_dir("check-velocity");
    let scenario = repo().join("examples/hand-on-route.yaml");
    let (path, mut plan) = plan_to_file(&scenario, &dir);
    afford_with_path(&["check"], &scenario, &[path.to_str().expect("UTF-8")]).assert_code(0);

    plan["subgoals"][0]["trajectory"]["points"][40]["velocities"][1] = Value::from(5.0);
    let edited = dir.join("edited.json");
    write_json(&edited, &plan);
    let run = afford_with_path(&["check"], &scenario, &[edited.to_str().expect("UTF-8")]);
    run.assert_code(1).assert_no_panic();
    assert_contains_all(
        "stderr",
        &run.stderr,
        &["velocity", "joint_a2", "5.0000 rad/s", "limit 1.4835"],
    );
}

#[test]
fn check_rejects_a_trajectory_through_a_hand_perimeter() {
    let dir = scratch_dir("check-hand");
    let scenario = repo().join("examples/sort-blue-squares.yaml");
    let (path, plan) = plan_to_file(&scenario, &dir);
    // The same trajectories against the scene with a hand resting right under
    // the middle of the first carry: the edit puts the route through its perimeter.
    let cells = plan["subgoals"][0]["path_px"].as_array().expect("path");
    let mid = &cells[cells.len() / 2];
    let (u, v) = (mid[0].as_f64().expect("u"), mid[1].as_f64().expect("v"));
    let text = std::fs::read_to_string(&scenario).expect("scenario");
    let with_hand = text.replace(
        "instruction:",
        &format!("hands:\n  - {{name: intruding-hand, box: [{}, {}, 30, 30], height: 0.06}}\ninstruction:", u - 15.0, v - 15.0),
    );
    let edited = dir.join("with-hand.yaml");
    std::fs::write(&edited, with_hand).expect("write scenario");
    let run = afford_with_path(&["check"], &edited, &[path.to_str().expect("UTF-8")]);
    run.assert_code(1).assert_no_panic();
    assert_contains_all(
        "stderr",
        &run.stderr,
        &[
            "collision",
            "intruding-hand",
            "Perimeter",
            "margin 100.0 mm",
        ],
    );
}

#[test]
fn check_rejects_a_trajectory_that_jumps() {
    let dir = scratch_dir("check-jump");
    let scenario = repo().join("examples/hand-on-route.yaml");
    let (_, mut plan) = plan_to_file(&scenario, &dir);
    let q = &mut plan["subgoals"][0]["trajectory"]["points"][0]["positions"][0];
    *q = Value::from(q.as_f64().expect("position") + 0.3);
    let edited = dir.join("jump.json");
    write_json(&edited, &plan);
    let run = afford_with_path(&["check"], &scenario, &[edited.to_str().expect("UTF-8")]);
    run.assert_code(1);
    assert_contains_all("stderr", &run.stderr, &["continuity", "0.3", "velocity"]);
}

#[test]
fn csv_has_one_row_per_sample() {
    let csv = afford(&["plan", "--format", "csv"])
        .assert_code(0)
        .stdout
        .clone();
    let plan = afford(&["plan"]).assert_code(0).json();
    let samples: usize = plan["subgoals"]
        .as_array()
        .expect("sub-goals")
        .iter()
        .map(|s| s["trajectory"]["points"].as_array().expect("points").len())
        .sum();
    let mut lines = csv.lines();
    let header = lines.next().expect("header");
    assert!(
        header.starts_with("subgoal,object,arm,time_from_start,gripper,q1,"),
        "{header}"
    );
    assert_eq!(lines.count(), samples);
    assert!(csv.contains(",closed,") && csv.contains(",open,"));
    afford(&["plan", "--format", "csv", "--until", "grid"]).assert_code(2);
}

#[test]
fn a_user_robot_named_in_the_scenario_plans() {
    let dir = scratch_dir("user-robot");
    for file in ["six_dof.urdf", "six_dof.yaml"] {
        std::fs::copy(
            repo().join("kinematics/tests/fixtures").join(file),
            dir.join(file),
        )
        .expect("copy robot");
    }
    let scenario = dir.join("scene.yaml");
    std::fs::write(
        &scenario,
        "afford: 1\nname: user-robot\ncamera: {width: 640, height: 480, pixel_to_base: [[0.0, -0.0004, 0.55], [-0.0004, 0.0, 0.128]], table_z: 0.0}\n\
         robot: {model: six_dof.yaml, start: [320, 240]}\n\
         objects: [{name: blue-square-1, color: blue, shape: square, box: [100, 100, 60, 60], height: 0.03}]\n\
         goals: [{name: box, box: [440, 300, 160, 160], height: 0.05}]\n\
         instruction: put the blue square in the box\n",
    )
    .expect("write scenario");
    let plan = afford_with_path(&["plan"], &scenario, &[])
        .assert_code(0)
        .json();
    let names: Vec<&str> = plan["subgoals"][0]["joint_names"]
        .as_array()
        .expect("names")
        .iter()
        .map(|n| n.as_str().expect("name"))
        .collect();
    assert_eq!(names, ["j1", "j2", "j3", "j4", "j5", "j6"]);

    std::fs::write(
        dir.join("six_dof.yaml"),
        "afford_robot: 1\nname: broken\nurdf: six_dof.urdf\narms: []\n",
    )
    .expect("break");
    let run = afford_with_path(&["plan"], &scenario, &[]);
    run.assert_code(2).assert_no_panic();
    assert!(run.stderr.contains("six_dof.yaml"), "{}", run.stderr);
}

#[test]
fn pipeline_bench_reports_every_stage() {
    let report = afford(&["bench", "pipeline", "--runs", "2", "--json"])
        .assert_code(0)
        .json();
    assert_eq!(report["subgoals"].as_u64(), Some(3));
    assert!(report["median_ms_per_subgoal"].as_f64().expect("median") > 0.0);
    for stage in ["cql", "lift", "ik", "collision", "timing"] {
        assert!(
            report["stages_ms"][stage].as_f64().expect("stage time") > 0.0,
            "{stage}"
        );
    }
}
