//! The whole pipeline through the CLI: stages (`--until`), ROS-shaped
//! trajectories, CSV output, a user robot named by path in a scenario, and
//! the pipeline benchmark report (`afford check` has tests/integration/check.rs).

use crate::util::{afford, afford_with_path, repo, scratch_dir};

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
