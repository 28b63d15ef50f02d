//! The physical replay: every example plan of both
//! robots passes it; a trajectory edited to sweep the fingers through a
//! piece moves that piece and is flagged; a gripper that opens above the
//! goal lands the piece inside it, one that opens mid-carry does not; two
//! replays of one plan give the same report, byte for byte; `afford check
//! --physics` reports the class `physics` and exits 1. Each replay's wall
//! time is printed (`--nocapture`), not asserted.

use std::path::Path;
use std::time::Instant;

use afford::check::physics::check_physics;
use afford::check::{PlanFile, ViolationClass};
use afford::collision::replay::ReplayReport;
use afford::kinematics::RobotModel;
use afford::planner::scenario::{self, Scenario};
use afford::planner::{PlanOptions, plan};

use crate::util::{afford_with_path, fixture, repo, scratch_dir};

/// The scenario at `path`, its robot and its plan (seed 1) as a plan file;
/// `None` when nothing was planned.
fn planned(path: &Path) -> Option<(Scenario, RobotModel, PlanFile)> {
    let s = scenario::load(path).expect("the scenario loads");
    let robot = RobotModel::load(&s.robot.model, path.parent().expect("directory"))
        .expect("the robot loads");
    let options = PlanOptions {
        seed: 1,
        ..PlanOptions::default()
    };
    let p = plan(&s, &options).ok()?;
    let file = PlanFile::from(&p);
    (!file.subgoals.is_empty()).then_some((s, robot, file))
}

/// Replays `plan`; prints the time it took.
fn replayed(name: &str, s: &Scenario, robot: &RobotModel, plan: &PlanFile) -> ReplayReport {
    let started = Instant::now();
    let (report, _) = check_physics(s, robot, plan);
    let report = report.unwrap_or_else(|| panic!("{name}: the plan could not be replayed"));
    eprintln!(
        "physics replay ({name}): {} sub-goals, {} steps, {:.0} ms",
        plan.subgoals.len(),
        report.steps,
        started.elapsed().as_secs_f64() * 1e3
    );
    report
}

#[test]
fn physics_replay_passes_every_example_plan_of_both_robots() {
    let mut files: Vec<_> = std::fs::read_dir(repo().join("examples"))
        .expect("examples/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    let (mut replays, mut robots, mut failed) = (0, Vec::new(), Vec::new());
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let Some((s, robot, plan)) = planned(path) else {
            continue;
        };
        let report = replayed(&name, &s, &robot, &plan);
        assert_eq!(report.targets.len(), plan.subgoals.len(), "{name}");
        if !report.passed() {
            failed.push(format!("{name}: {:?}", report.failures()));
        }
        replays += 1;
        robots.push(robot.name().to_string());
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
    robots.sort();
    robots.dedup();
    assert!(replays >= 10, "only {replays} example plans replayed");
    assert_eq!(robots, ["care_o_bot4", "kuka_iiwa14"]);
}

/// tests/fixtures/check/iiwa-one-piece.yaml with red-square-1 moved next to
/// the target at the same distance from the robot's base (0.61 m), 0.15 rad
/// clockwise of it: a turn of joint a1 at the grasp sweeps the fingers
/// through it.
fn sweep_scene() -> Scenario {
    let mut s = scenario::load(&fixture("check/iiwa-one-piece.yaml")).expect("fixture");
    s.objects[1].bbox.u = 246.0;
    s.objects[1].bbox.v = 61.0;
    let polar = |i: usize| {
        let [x, y] = s.pixel_to_base(s.objects[i].bbox.centre());
        (x.hypot(y), y.atan2(x))
    };
    let ((r0, a0), (r1, a1)) = (polar(0), polar(1));
    assert!(
        (r0 - r1).abs() < 0.005 && (a0 - a1 - 0.15).abs() < 0.01,
        "{r0} {a0} {r1} {a1}"
    );
    s
}

/// Inserts, at the close event of sub-goal 0, a turn of `joint` out by
/// `amplitude` rad and back over `duration` s (raised cosine, 10 ms
/// samples); every later sample and gripper event moves `duration` later.
fn sweep_at_grasp(plan: &mut PlanFile, joint: &str, amplitude: f64, duration: f64) {
    let sub = &mut plan.subgoals[0];
    let j = sub
        .joint_names
        .iter()
        .position(|n| n == joint)
        .expect("joint");
    let t_close = sub.trajectory.gripper[0].start;
    let points = &mut sub.trajectory.points;
    let c = points
        .iter()
        .position(|p| (p.time_from_start - t_close).abs() < 1e-9)
        .expect("a sample at the close");
    for p in &mut points[c + 1..] {
        p.time_from_start += duration;
    }
    for e in &mut sub.trajectory.gripper {
        e.start += duration;
        e.end += duration;
    }
    let n = (duration / 0.01).round() as usize;
    let sweep: Vec<_> = (1..=n)
        .map(|i| {
            let s = i as f64 / n as f64;
            let mut p = points[c].clone();
            p.positions[j] += amplitude * 0.5 * (1.0 - (2.0 * std::f64::consts::PI * s).cos());
            p.time_from_start = t_close + s * duration;
            p
        })
        .collect();
    points.splice(c + 1..c + 1, sweep);
}

#[test]
fn physics_replay_flags_a_trajectory_swept_through_a_piece() {
    let s = sweep_scene();
    let robot = RobotModel::builtin("kuka_iiwa14").expect("robot");
    let p = plan(&s, &PlanOptions::default()).expect("plans");
    let mut file = PlanFile::from(&p);
    let clean = replayed("sweep scene as planned", &s, &robot, &file);
    assert!(clean.passed(), "{:?}", clean.failures());

    sweep_at_grasp(&mut file, "joint_a1", -0.3, 2.0);
    let swept = replayed("swept through red-square-1", &s, &robot, &file);
    let red = swept
        .pieces
        .iter()
        .find(|p| p.piece == "red-square-1")
        .expect("red-square-1 reported");
    assert!(red.moved && red.max_displacement > 0.005, "{red:?}");
    assert!(
        swept
            .contacts
            .iter()
            .any(|c| c.body == "red-square-1" && c.motion == 0 && c.link.starts_with("gripper")),
        "{:?}",
        swept.contacts
    );
    let (_, violations) = check_physics(&s, &robot, &file);
    assert!(
        violations
            .of(ViolationClass::Physics)
            .any(|v| v.message.contains("red-square-1 moved")),
        "{:?}",
        violations.violations
    );
}

#[test]
fn physics_replay_lands_a_piece_released_above_the_box_inside_and_flags_one_dropped_mid_carry() {
    let path = fixture("check/iiwa-one-piece.yaml");
    let (s, robot, mut file) = planned(&path).expect("the reference scene plans");
    let report = replayed("reference", &s, &robot, &file);
    let t = &report.targets[0];
    assert!(
        t.in_goal && t.beyond_inner_walls.is_some_and(|b| b < 0.0),
        "{t:?}"
    );
    assert!(report.passed(), "{:?}", report.failures());

    // Open the gripper halfway between the close and the open instead.
    let events = &mut file.subgoals[0].trajectory.gripper;
    let mid = 0.5 * (events[0].end + events[1].start);
    let points = &file.subgoals[0].trajectory.points;
    let at = points
        .iter()
        .map(|p| p.time_from_start)
        .min_by(|a, b| (a - mid).abs().total_cmp(&(b - mid).abs()))
        .expect("samples");
    let events = &mut file.subgoals[0].trajectory.gripper;
    events[1].start = at;
    events[1].end = at;
    let dropped = replayed("opened mid-carry", &s, &robot, &file);
    let t = &dropped.targets[0];
    assert!(!t.in_goal, "{t:?}");
    assert!(
        dropped
            .failures()
            .iter()
            .any(|(k, m)| *k == Some(0) && m.contains("blue-square-1") && m.contains("left box")),
        "{:?}",
        dropped.failures()
    );
}

#[test]
fn physics_replay_is_deterministic() {
    let s = sweep_scene();
    let robot = RobotModel::builtin("kuka_iiwa14").expect("robot");
    let p = plan(&s, &PlanOptions::default()).expect("plans");
    let mut file = PlanFile::from(&p);
    sweep_at_grasp(&mut file, "joint_a1", -0.3, 2.0);
    let first = replayed("determinism 1", &s, &robot, &file);
    let second = replayed("determinism 2", &s, &robot, &file);
    let json = |r: &ReplayReport| serde_json::to_string(r).expect("serialise");
    assert_eq!(json(&first), json(&second));
    assert!(!first.contacts.is_empty(), "the run compared has contacts");
}

#[test]
fn check_physics_cli_reports_the_physics_class_and_exits_1() {
    let s = sweep_scene();
    let dir = scratch_dir("check-physics");
    let scene = dir.join("scene.yaml");
    let text = std::fs::read_to_string(fixture("check/iiwa-one-piece.yaml")).expect("fixture");
    let moved = text.replace("box: [420, 120, 40, 40]", "box: [246, 61, 40, 40]");
    assert_ne!(moved, text);
    std::fs::write(&scene, moved).expect("write scene");
    let p = plan(&s, &PlanOptions::default()).expect("plans");
    let mut file = PlanFile::from(&p);
    let write = |file: &PlanFile| {
        let path = dir.join("plan.json");
        std::fs::write(&path, serde_json::to_string(file).expect("json")).expect("write plan");
        path
    };
    let run = |plan: &Path| {
        afford_with_path(
            &["check", scene.to_str().unwrap()],
            plan,
            &["--json", "--physics"],
        )
    };
    let clean = run(&write(&file));
    clean.assert_no_panic();
    let json = clean.json();
    assert!(
        json["physics"]["targets"][0]["in_goal"].as_bool() == Some(true),
        "{json}"
    );
    let physics = |v: &serde_json::Value| {
        v["violations"]
            .as_array()
            .expect("violations")
            .iter()
            .filter(|v| v["class"] == "physics")
            .count()
    };
    assert_eq!(physics(&json), 0, "{json}");

    sweep_at_grasp(&mut file, "joint_a1", -0.3, 2.0);
    let swept = run(&write(&file));
    swept.assert_code(1).assert_no_panic();
    assert!(physics(&swept.json()) > 0, "{}", swept.stdout);
}
