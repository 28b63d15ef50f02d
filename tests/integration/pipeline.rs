//! The whole pipeline through the CLI: stages (`--until`), ROS-shaped
//! trajectories, CSV output, a user robot named by path in a scenario, and
//! the pipeline benchmark report (`afford check` has tests/integration/check.rs).

use std::path::Path;

use serde_json::Value;

use crate::util::{afford, afford_with_path, assert_contains_all, plan_to_file, repo, scratch_dir};

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
    copy_fixture_robot("six_dof", &dir);
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
    // The task's trajectory time: three gripper closes and opens of 0.5 s
    // each separate the moving time from the total.
    let moving = report["task_duration_s"].as_f64().expect("moving time");
    let total = report["task_total_s"].as_f64().expect("total time");
    assert!(
        moving > 0.0 && (total - moving - 3.0).abs() < 1e-9,
        "{moving} {total}"
    );
    let per_subgoal: f64 = report["subgoal_durations_s"]
        .as_array()
        .expect("per sub-goal")
        .iter()
        .map(|d| d["moving"].as_f64().expect("moving"))
        .sum();
    assert!((per_subgoal - moving).abs() < 1e-9);
}

#[test]
fn routes_bench_reports_ratios_to_the_oracle() {
    let report = afford(&["bench", "routes", "--scenarios", "6", "--json"])
        .assert_code(0)
        .json();
    assert_eq!(report["scenes"].as_u64(), Some(6));
    let subgoals = report["subgoals"].as_u64().expect("sub-goals");
    assert!(subgoals > 0, "{report}");
    let mean = report["mean_path_over_shortest"].as_f64().expect("mean");
    let max = report["max_path_over_shortest"].as_f64().expect("max");
    assert!((1.0 - 1e-9..=max).contains(&mean), "{mean} {max}");
    afford(&["bench", "routes", "--scenarios", "0"]).assert_code(2);
}

// ---- The robot's state at t = 0 ----

/// The whole robot's state as a name -> position map.
fn state_map(state: &Value) -> std::collections::BTreeMap<String, f64> {
    let names = state["joint_names"].as_array().expect("joint_names");
    let positions = state["positions"].as_array().expect("positions");
    assert_eq!(names.len(), positions.len());
    names
        .iter()
        .zip(positions)
        .map(|(n, p)| {
            (
                n.as_str().expect("name").to_string(),
                p.as_f64().expect("position"),
            )
        })
        .collect()
}

fn positions(point: &Value) -> Vec<f64> {
    point["positions"]
        .as_array()
        .expect("positions")
        .iter()
        .map(|v| v.as_f64().expect("number"))
        .collect()
}

/// Sub-goal 0's first sample is the plan's start state and every sub-goal
/// starts exactly (bit for bit) where the robot was after the previous one.
fn assert_chained_from_start_state(what: &str, plan: &Value) {
    let mut robot = state_map(&plan["start_state"]);
    let subgoals = plan["subgoals"].as_array().expect("subgoals");
    assert!(!subgoals.is_empty(), "{what}: no sub-goal");
    for (k, sub) in subgoals.iter().enumerate() {
        let names: Vec<&str> = sub["joint_names"]
            .as_array()
            .expect("joint_names")
            .iter()
            .map(|n| n.as_str().expect("name"))
            .collect();
        let points = sub["trajectory"]["points"].as_array().expect("points");
        let first = positions(&points[0]);
        for (name, q) in names.iter().zip(&first) {
            assert_eq!(
                *q, robot[*name],
                "{what}: sub-goal {k} starts with {name} = {q}, the robot is at {}",
                robot[*name]
            );
        }
        let last = positions(points.last().expect("a sample"));
        for (name, q) in names.iter().zip(last) {
            robot.insert(name.to_string(), q);
        }
    }
}

/// The `robot.joints` of a scenario file, by name.
fn scenario_joints(path: &Path) -> std::collections::BTreeMap<String, f64> {
    let scenario = afford::planner::scenario::load(path).expect("scenario loads");
    scenario.robot.joints.expect("robot.joints")
}

#[test]
fn start_state_first_sample_is_the_given_joint_state() {
    for example in ["joint-state-start.yaml", "cob4-joint-state-start.yaml"] {
        let path = repo().join("examples").join(example);
        let plan = afford_with_path(&["plan"], &path, &[])
            .assert_code(0)
            .json();
        assert_eq!(
            state_map(&plan["start_state"]),
            scenario_joints(&path),
            "{example}: start_state is not robot.joints"
        );
        assert_chained_from_start_state(example, &plan);
    }
}

#[test]
fn start_pixel_alone_hovers_without_detour_through_home() {
    use afford::kinematics::{RobotModel, Vec3};
    let path = repo().join("examples/sort-blue-squares.yaml");
    let scenario = afford::planner::scenario::load(&path).expect("loads");
    let plan = afford_with_path(&["plan"], &path, &[])
        .assert_code(0)
        .json();
    assert_chained_from_start_state("sort-blue-squares", &plan);
    let robot = RobotModel::builtin("kuka_iiwa14").expect("robot");
    let arm = &robot.arms()[0];
    let state = state_map(&plan["start_state"]);
    let start: Vec<f64> = robot.joints().iter().map(|j| state[&j.name]).collect();
    // The tool points down over robot.start at the first sub-goal's carry height.
    let tool = arm.fk(&arm.extract(&start));
    let [x, y] = scenario.pixel_to_base(scenario.robot.start.expect("start"));
    let carry = plan["subgoals"][0]["waypoints"]["carry_height"]
        .as_f64()
        .expect("carry height");
    let want = Vec3::new(x, y, scenario.camera.table_z + carry);
    assert!(
        (tool.translation.vector - want).norm() < 1e-4,
        "tool at {:?}, want {want:?}",
        tool.translation.vector
    );
    assert!((tool.rotation * Vec3::z() + Vec3::z()).norm() < 1e-3);
    // Sub-goal 0 never passes through home: it starts at the hover.
    let home = robot.home();
    let points = plan["subgoals"][0]["trajectory"]["points"]
        .as_array()
        .expect("points");
    let nearest_home = points
        .iter()
        .map(|p| {
            positions(p)
                .iter()
                .zip(home)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .fold(f64::INFINITY, f64::min);
    assert!(nearest_home > 0.05, "passes {nearest_home} rad from home");
}

/// A copy of the iiwa joint-state example with `robot` replaced.
fn scenario_with_robot(dir: &Path, robot: &str) -> std::path::PathBuf {
    let text =
        std::fs::read_to_string(repo().join("examples/joint-state-start.yaml")).expect("example");
    let start = text.find("robot:").expect("robot section");
    let end = start + text[start..].find("objects:").expect("objects section");
    let path = dir.join("scene.yaml");
    std::fs::write(
        &path,
        format!("{}{robot}\n{}", &text[..start], &text[end..]),
    )
    .expect("write scenario");
    path
}

const IIWA_JOINTS: &str =
    "joint_a1: 0.15, joint_a2: 1.1, joint_a3: 0.0, joint_a4: -1.45, joint_a5: 0.0, joint_a6: 0.6";

#[test]
fn start_state_and_start_pixel_disagreeing_is_bad_input() {
    let dir = scratch_dir("start-disagrees");
    // The joints put the tool near pixel (180, 100); (600, 400) is many cells away.
    let far = scenario_with_robot(
        &dir,
        &format!(
            "robot: {{model: kuka_iiwa14, start: [600, 400], joints: {{{IIWA_JOINTS}, joint_a7: 0.2}}}}"
        ),
    );
    for command in ["plan", "validate"] {
        let run = afford_with_path(&[command], &far, &[]);
        run.assert_code(2).assert_no_panic();
        assert_contains_all(
            command,
            &run.stderr,
            &[
                "scene.yaml",
                "robot.start",
                "robot.joints",
                "more than one grid cell",
            ],
        );
    }
    // Within one cell they agree: the grid starts at robot.start.
    let near = scenario_with_robot(
        &dir,
        &format!(
            "robot: {{model: kuka_iiwa14, start: [185, 105], joints: {{{IIWA_JOINTS}, joint_a7: 0.2}}}}"
        ),
    );
    let plan = afford_with_path(&["plan", "--until", "grid"], &near, &[])
        .assert_code(0)
        .json();
    let first = &plan["subgoals"][0]["path_px"][0];
    let cell = &plan["subgoals"][0]["grid"]["cell_px"];
    for (k, at) in [185.0, 105.0].into_iter().enumerate() {
        let half = cell[k].as_f64().expect("cell") / 2.0;
        let centre = first[k].as_f64().expect("pixel");
        assert!(
            (centre - at).abs() <= half,
            "grid starts at {first}, not at robot.start"
        );
    }
}

#[test]
fn start_state_naming_a_wrong_joint_set_or_value_is_bad_input() {
    let dir = scratch_dir("start-bad-joints");
    let cases = [
        // joint_a7 missing.
        (
            format!("{{{IIWA_JOINTS}}}"),
            "robot.joints.joint_a7",
            "missing",
        ),
        // A name the robot does not have.
        (
            format!("{{{IIWA_JOINTS}, joint_a7: 0.2, joint_a8: 0.0}}"),
            "robot.joints.joint_a8",
            "not a movable joint",
        ),
        // Outside joint_a7's limits (+-3.05 rad).
        (
            format!("{{{IIWA_JOINTS}, joint_a7: 7.0}}"),
            "robot.joints.joint_a7",
            "outside the joint limits",
        ),
    ];
    for (joints, field, what) in cases {
        let path = scenario_with_robot(
            &dir,
            &format!("robot: {{model: kuka_iiwa14, joints: {joints}}}"),
        );
        for command in ["plan", "validate"] {
            let run = afford_with_path(&[command], &path, &[]);
            run.assert_code(2).assert_no_panic();
            assert_contains_all(command, &run.stderr, &["scene.yaml", field, what]);
        }
    }
    // Not a number at all: caught while reading the scenario.
    let path = scenario_with_robot(
        &dir,
        &format!("robot: {{model: kuka_iiwa14, joints: {{{IIWA_JOINTS}, joint_a7: .nan}}}}"),
    );
    let run = afford_with_path(&["validate"], &path, &[]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all("nan", &run.stderr, &["robot.joints.joint_a7", "finite"]);
}

/// The continuous-joint fixture robot next to a scenario whose current state
/// has j6 at `j6` rad.
fn continuous_robot_scenario(dir: &Path, j6: &str) -> std::path::PathBuf {
    copy_fixture_robot("continuous", dir);
    let scenario = dir.join("scene.yaml");
    std::fs::write(
        &scenario,
        format!(
            "afford: 1\nname: continuous\ncamera: {{width: 640, height: 480, pixel_to_base: [[0.0, -0.0004, 0.55], [-0.0004, 0.0, 0.128]], table_z: 0.0}}\n\
             robot: {{model: continuous.yaml, joints: {{j1: 0.0, j2: 0.6, j3: 1.2, j4: 0.0, j5: 1.3, j6: {j6}}}}}\n\
             objects: [{{name: blue-square-1, color: blue, shape: square, box: [100, 100, 60, 60], height: 0.03}}]\n\
             goals: [{{name: box, box: [440, 300, 160, 160], height: 0.05}}]\n\
             instruction: put the blue square in the box\n"
        ),
    )
    .expect("write scenario");
    scenario
}

#[test]
fn continuous_joint_at_7_rad_is_accepted() {
    let dir = scratch_dir("continuous-7-rad");
    let scenario = continuous_robot_scenario(&dir, "7.0");
    let (plan_file, plan) = plan_to_file(&scenario, &dir);
    assert_eq!(state_map(&plan["start_state"])["j6"], 7.0);
    assert_chained_from_start_state("continuous", &plan);
    // The flange keeps its turn: no sample is wrapped into [-2 pi, 2 pi].
    let j6: Vec<f64> = plan["subgoals"]
        .as_array()
        .expect("subgoals")
        .iter()
        .flat_map(|s| {
            s["trajectory"]["points"]
                .as_array()
                .expect("points")
                .clone()
        })
        .map(|p| positions(&p)[5])
        .collect();
    assert!(
        j6.iter().all(|q| (q - 7.0).abs() < std::f64::consts::PI),
        "{j6:?}"
    );
    // `afford check` agrees with `plan`.
    afford_with_path(&["check"], &scenario, &[plan_file.to_str().expect("UTF-8")])
        .assert_code(0)
        .assert_no_panic();
    // A revolute joint at 7 rad is still outside its limits.
    let text = std::fs::read_to_string(&scenario).expect("scenario");
    std::fs::write(&scenario, text.replace("j2: 0.6", "j2: 7.0")).expect("edit");
    let run = afford_with_path(&["plan"], &scenario, &[]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        "revolute",
        &run.stderr,
        &["robot.joints.j2", "outside the joint limits"],
    );
}

#[test]
fn start_with_neither_joints_nor_pixel_rests_at_home() {
    let dir = scratch_dir("start-neither");
    let path = scenario_with_robot(&dir, "robot: {model: kuka_iiwa14}");
    let plan = afford_with_path(&["plan"], &path, &[])
        .assert_code(0)
        .json();
    let robot = afford::kinematics::RobotModel::builtin("kuka_iiwa14").expect("robot");
    let state = state_map(&plan["start_state"]);
    for (joint, home) in robot.joints().iter().zip(robot.home()) {
        assert_eq!(state[&joint.name], *home, "{}", joint.name);
    }
    assert_chained_from_start_state("neither", &plan);
}

/// Copies the kinematics test robot `name` (its URDF and description) into `dir`.
fn copy_fixture_robot(name: &str, dir: &Path) {
    for ext in ["urdf", "yaml"] {
        let file = format!("{name}.{ext}");
        std::fs::copy(
            repo().join("kinematics/tests/fixtures").join(&file),
            dir.join(&file),
        )
        .expect("copy robot");
    }
}
