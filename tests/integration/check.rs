//! `afford check`, the independent gate: it accepts a plan that keeps every
//! rule and rejects edited trajectories (and the same trajectory against
//! edited scenes), one per fault kind, naming the violation's
//! class. Each check's wall time is printed (`--nocapture`), not asserted.
//!
//! The reference plan is `afford plan` of tests/fixtures/check/iiwa-one-piece.yaml
//! with the accelerations at the first, last and gripper-event samples set
//! to 0: the planner leaves the acceleration of the piece that ends there
//! (the gripper's dwell); everything else is as planned.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

use serde_json::{Value, json};

use crate::util::{
    afford, afford_with_path, assert_contains_all, fixture, nudge, repo, scratch_dir,
};

fn scene() -> PathBuf {
    fixture("check/iiwa-one-piece.yaml")
}

/// The reference plan (planned once per test run).
fn reference() -> Value {
    static PLAN: OnceLock<Value> = OnceLock::new();
    PLAN.get_or_init(|| {
        let mut plan = afford_with_path(&["plan"], &scene(), &[])
            .assert_code(0)
            .json();
        for sub in plan["subgoals"].as_array_mut().expect("sub-goals") {
            let times: Vec<f64> = sub["trajectory"]["gripper"]
                .as_array()
                .expect("gripper events")
                .iter()
                .flat_map(|e| [e["start"].as_f64(), e["end"].as_f64()])
                .map(|t| t.expect("event time"))
                .collect();
            let points = sub["trajectory"]["points"].as_array_mut().expect("points");
            let last = points.len() - 1;
            for (i, p) in points.iter_mut().enumerate() {
                let t = p["time_from_start"].as_f64().expect("time");
                if i == 0 || i == last || times.iter().any(|e| (e - t).abs() < 1e-9) {
                    let n = p["accelerations"].as_array().expect("accelerations").len();
                    p["accelerations"] = json!(vec![0.0; n]);
                }
            }
        }
        plan
    })
    .clone()
}

/// What one `afford check --json` run found.
struct Checked {
    code: Option<i32>,
    /// (class, sub-goal, message) per violation.
    violations: Vec<(String, Option<u64>, String)>,
    stderr: String,
}

impl Checked {
    /// Asserts exit 1 with a violation of `class` whose message holds every needle.
    #[track_caller]
    fn rejects(&self, class: &str, needles: &[&str]) {
        assert_eq!(self.code, Some(1), "expected exit 1: {}", self.stderr);
        let found = self
            .violations
            .iter()
            .find(|(c, _, m)| c == class && needles.iter().all(|n| m.contains(n)));
        assert!(
            found.is_some(),
            "no '{class}' violation naming {needles:?} among:\n{}",
            self.lines()
        );
    }

    fn lines(&self) -> String {
        self.violations
            .iter()
            .map(|(c, k, m)| format!("  {c} {k:?}: {m}\n"))
            .collect()
    }
}

/// Runs `afford check --json` on `plan` against `scenario`; prints its time.
fn check(name: &str, scenario: &Path, plan: &Value) -> Checked {
    let dir = scratch_dir(&format!("check-{name}"));
    let path = dir.join("plan.json");
    std::fs::write(&path, serde_json::to_string(plan).expect("serialise")).expect("write plan");
    let started = Instant::now();
    let run = afford(&[
        "check",
        scenario.to_str().expect("UTF-8"),
        path.to_str().expect("UTF-8"),
        "--json",
    ]);
    eprintln!(
        "afford check ({name}): {:.0} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    run.assert_no_panic();
    let violations = match run.code {
        Some(0) | Some(1) => run.json()["violations"]
            .as_array()
            .expect("violations")
            .iter()
            .map(|v| {
                (
                    v["class"].as_str().expect("class").to_string(),
                    v["subgoal"].as_u64(),
                    v["message"].as_str().expect("message").to_string(),
                )
            })
            .collect(),
        _ => Vec::new(),
    };
    Checked {
        code: run.code,
        violations,
        stderr: run.stderr,
    }
}

/// The reference scene with `from` replaced by `to`, written for test `name`.
fn scene_with(name: &str, from: &str, to: &str) -> PathBuf {
    let text = std::fs::read_to_string(scene()).expect("scene");
    assert!(text.contains(from), "the scene has no '{from}'");
    let path = scratch_dir(&format!("scene-{name}")).join("scene.yaml");
    std::fs::write(&path, text.replace(from, to)).expect("write scene");
    path
}

fn points(plan: &mut Value) -> &mut Vec<Value> {
    plan["subgoals"][0]["trajectory"]["points"]
        .as_array_mut()
        .expect("points")
}

fn time(plan: &Value, i: usize) -> f64 {
    plan["subgoals"][0]["trajectory"]["points"][i]["time_from_start"]
        .as_f64()
        .expect("time")
}

/// Index of the sample at the close event.
fn close_sample(plan: &Value) -> usize {
    let t = plan["subgoals"][0]["trajectory"]["gripper"][0]["start"]
        .as_f64()
        .expect("close");
    (0..)
        .find(|&i| (time(plan, i) - t).abs() < 1e-9)
        .expect("sample at close")
}

#[test]
fn check_accepts_the_reference_plan() {
    let c = check("reference", &scene(), &reference());
    assert_eq!(c.code, Some(0), "{}{}", c.lines(), c.stderr);
}

#[test]
fn check_accepts_a_yaml_plan_and_prints_one_line_per_violation() {
    let dir = scratch_dir("check-yaml");
    let yaml = dir.join("plan.yaml");
    afford_with_path(
        &["plan"],
        &scene(),
        &["--format", "yaml", "-o", yaml.to_str().expect("UTF-8")],
    )
    .assert_code(0);
    let run = afford_with_path(&["check"], &scene(), &[yaml.to_str().expect("UTF-8")]);
    run.assert_no_panic();
    // As planned today the plan only misses rest (accelerations at its ends).
    for line in run.stdout.lines() {
        assert!(line.starts_with("rest sub-goal 0: "), "{line}");
    }
}

#[test]
fn check_rejects_a_position_beyond_a_limit_between_waypoints() {
    let mut plan = reference();
    for p in &mut points(&mut plan)[30..33] {
        p["positions"][3] = json!(-2.12);
    }
    check("position", &scene(), &plan)
        .rejects("position", &["joint_a4", "-2.1200", "lower limit -2.0944"]);
}

#[test]
fn check_rejects_halved_times_by_the_accelerations_they_imply() {
    let mut plan = reference();
    for p in points(&mut plan) {
        p["time_from_start"] = json!(p["time_from_start"].as_f64().expect("time") / 2.0);
    }
    for e in plan["subgoals"][0]["trajectory"]["gripper"]
        .as_array_mut()
        .expect("events")
    {
        for key in ["start", "end"] {
            e[key] = json!(e[key].as_f64().expect("time") / 2.0);
        }
    }
    check("halved", &scene(), &plan)
        .rejects("acceleration", &["recomputed from positions and times"]);
}

/// A 1 mrad bump of joint_a2 at one sample: positions and times alone show
/// a jerk of about 3 δ / h³ = 3,000 rad/s³ against its 428.5 rad/s³ limit.
#[test]
fn check_rejects_a_jerk_from_a_position_bump_naming_the_joint_and_time() {
    let mut plan = reference();
    nudge(&mut points(&mut plan)[40]["positions"][1], 1e-3);
    let c = check("jerk-bump", &scene(), &plan);
    c.rejects("jerk", &["joint_a2", "limit 428.5 rad/s³"]);
    let (_, _, message) = c
        .violations
        .iter()
        .find(|(class, _, m)| class == "jerk" && m.contains("joint_a2"))
        .expect("a jerk violation of joint_a2");
    let windows = [(39, 40), (38, 39), (40, 41), (37, 38), (41, 42)];
    assert!(
        windows.iter().any(|&(a, b)| message.contains(&format!(
            "around t = {:.3} s",
            0.5 * (time(&plan, a) + time(&plan, b))
        ))),
        "the worst window is not next to sample 40: {message}"
    );
}

#[test]
fn check_rejects_a_velocity_step_of_140_rad_s2() {
    let mut plan = reference();
    let v = &mut points(&mut plan)[40]["velocities"][1];
    *v = json!(v.as_f64().expect("velocity") + 1.4);
    check("velocity-step", &scene(), &plan)
        .rejects("acceleration", &["joint_a2", "velocities field changes by"]);
}

#[test]
fn check_accepts_a_planned_trajectory_and_rejects_a_velocity_edit() {
    let mut plan = reference();
    points(&mut plan)[40]["velocities"][1] = json!(5.0);
    check("velocity", &scene(), &plan)
        .rejects("velocity", &["joint_a2", "5.0000 rad/s", "limit 1.4835"]);
}

#[test]
fn check_rejects_a_trajectory_that_ends_moving() {
    let mut plan = reference();
    let n = points(&mut plan).len();
    points(&mut plan).truncate(n - 15);
    let last = points(&mut plan).last_mut().expect("last");
    last["velocities"] = json!(vec![0.0; 7]);
    last["accelerations"] = json!(vec![0.0; 7]);
    check("ends-moving", &scene(), &plan).rejects("rest", &["moving at its end"]);
}

#[test]
fn check_rejects_a_negative_time() {
    let mut plan = reference();
    points(&mut plan)[5]["time_from_start"] = json!(-0.5);
    check("negative-time", &scene(), &plan)
        .rejects("format", &["points[5].time_from_start", "-0.5"]);
}

#[test]
fn check_rejects_an_empty_plan() {
    let mut plan = reference();
    plan["subgoals"] = json!([]);
    check("empty", &scene(), &plan).rejects("format", &["no sub-goals"]);
}

#[test]
fn check_rejects_a_position_of_1e6_fast_naming_the_field() {
    let mut plan = reference();
    points(&mut plan)[3]["positions"][2] = json!(1e6);
    let started = Instant::now();
    check("1e6", &scene(), &plan)
        .rejects("format", &["points[3].positions[2]", "joint_a3", "1000000"]);
    eprintln!(
        "1e6 position rejected in {:.0} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
}

#[test]
fn check_rejects_open_before_close() {
    let mut plan = reference();
    let events = plan["subgoals"][0]["trajectory"]["gripper"]
        .as_array_mut()
        .expect("events");
    events.swap(0, 1);
    check("open-before-close", &scene(), &plan)
        .rejects("gripper_events", &["[\"open\", \"close\"]"]);
}

#[test]
fn check_rejects_a_missing_open_event() {
    let mut plan = reference();
    plan["subgoals"][0]["trajectory"]["gripper"]
        .as_array_mut()
        .expect("events")
        .pop();
    check("open-missing", &scene(), &plan).rejects("gripper_events", &["[\"close\"]"]);
}

#[test]
fn check_rejects_a_gripper_event_while_the_arm_moves() {
    let mut plan = reference();
    let t = time(&plan, close_sample(&plan) - 20);
    let close = &mut plan["subgoals"][0]["trajectory"]["gripper"][0];
    close["start"] = json!(t);
    close["end"] = json!(t);
    check("event-moving", &scene(), &plan).rejects("rest", &["gripper event 0"]);
}

#[test]
fn check_rejects_a_start_that_is_not_where_the_robot_is() {
    let mut plan = reference();
    nudge(&mut plan["start_state"]["positions"][0], 0.3);
    let c = check("start", &scene(), &plan);
    c.rejects("start", &["no arm's tool points down over robot.start"]);
    c.rejects("start", &["joint_a1", "away from start_state"]);
}

#[test]
fn check_rejects_a_trajectory_that_jumps() {
    let mut plan = reference();
    nudge(&mut points(&mut plan)[0]["positions"][0], 0.3);
    let c = check("jump", &scene(), &plan);
    c.rejects("start", &["joint_a1", "0.300000 away"]);
    c.rejects("velocity", &["joint_a1", "recomputed"]);
}

#[test]
fn check_rejects_an_arm_folded_into_itself() {
    let mut plan = reference();
    let folded = json!([0.0, 1.6, 0.0, -2.0, 0.0, 2.0, 0.0]);
    let n = points(&mut plan).len();
    for p in &mut points(&mut plan)[n - 30..n - 20] {
        p["positions"] = folded.clone();
    }
    check("self-collision", &scene(), &plan)
        .rejects("self_collision", &["gripper_link", "base_link"]);
}

#[test]
fn check_rejects_the_palm_in_a_tall_target() {
    let tall = scene_with(
        "tall-target",
        "box: [100, 80, 40, 40], height: 0.03",
        "box: [100, 80, 40, 40], height: 0.15",
    );
    check("tall-target", &tall, &reference())
        .rejects("target_touched", &["blue-square-1", "before the grasp"]);
}

#[test]
fn check_rejects_a_release_outside_the_goal() {
    let moved = scene_with(
        "goal-moved",
        "name: left box, box: [20, 300, 120, 120]",
        "name: left box, box: [80, 300, 120, 120]",
    );
    check("placement", &moved, &reference()).rejects(
        "placement",
        &["blue-square-1", "beyond an inner wall of the left box"],
    );
}

#[test]
fn check_rejects_an_object_wider_than_the_gripper() {
    let wide = scene_with(
        "wide-object",
        "box: [100, 80, 40, 40], height: 0.03",
        "box: [20, 0, 200, 200], height: 0.03",
    );
    check("too-wide", &wide, &reference()).rejects(
        "gripper_opening",
        &["blue-square-1", "0.1250 m wide", "opens 0.0800 m"],
    );
}

#[test]
fn check_rejects_a_trajectory_through_a_hand_perimeter() {
    let plan = reference();
    let cells = plan["subgoals"][0]["path_px"].as_array().expect("path");
    let mid = &cells[cells.len() / 2];
    let (u, v) = (mid[0].as_f64().expect("u"), mid[1].as_f64().expect("v"));
    let hand = format!(
        "hands:\n  - {{name: intruding-hand, box: [{}, {}, 30, 30], height: 0.06}}\ninstruction:",
        u - 15.0,
        v - 15.0
    );
    let with_hand = scene_with("hand-perimeter", "instruction:", &hand);
    check("hand-perimeter", &with_hand, &plan)
        .rejects("margin", &["intruding-hand", "inside its 100.0 mm margin"]);
}

#[test]
fn check_rejects_a_tool_too_fast_near_a_hand() {
    let hand =
        "hands:\n  - {name: watching-hand, box: [300, 225, 30, 30], height: 0.05}\ninstruction:";
    let with_hand = scene_with("tool-speed", "instruction:", hand);
    check("tool-speed", &with_hand, &reference())
        .rejects("tool_speed", &["watching-hand", "speed-and-separation cap"]);
}

#[test]
fn check_refuses_an_unreadable_plan_naming_the_field() {
    let dir = scratch_dir("check-unreadable");
    let path = dir.join("plan.json");
    let values = vec!["\"j\""; 200].join(",");
    std::fs::write(&path, format!("{{\"subgoals\": [{{\"object\": \"o\", \"goal\": \"g\", \"arm\": \"arm\", \"joint_names\": [{values}]}}]}}"))
        .expect("write");
    let run = afford_with_path(&["check"], &scene(), &[path.to_str().expect("UTF-8")]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        "stderr",
        &run.stderr,
        &["subgoals[0].joint_names", "more than 128 entries"],
    );
}

/// Every plan `afford plan` emits for the examples of both robots passes
/// (the scenario files directly in examples/; examples/monitor/ is run by
/// the monitor tests).
#[test]
fn check_accepts_every_example_plan_of_both_robots() {
    let mut rejected = Vec::new();
    for entry in std::fs::read_dir(repo().join("examples")).expect("examples") {
        let scenario = entry.expect("entry").path();
        let name = scenario
            .file_stem()
            .expect("stem")
            .to_string_lossy()
            .to_string();
        let run = afford_with_path(&["plan"], &scenario, &[]);
        if run.code == Some(2) || run.stdout.is_empty() || run.json()["subgoals"] == json!([]) {
            continue;
        }
        let c = check(&name, &scenario, &run.json());
        if c.code != Some(0) {
            rejected.push(format!("{name}:\n{}", c.lines()));
        }
    }
    assert!(rejected.is_empty(), "{}", rejected.join("\n"));
}
