//! `afford check`: the independent gate (crate `afford-check`) over a plan
//! file and its scenario. Exit 0 when the plan passes, 1 with violations
//! (one line each on stdout: class, sub-goal, message), 2 when the scenario,
//! the robot or the plan file cannot be read (a plan file that is no
//! regular file, a FIFO, is refused unread) or `robot.joints` does not fit
//! the robot, 3 when the verdict cannot be written. `--physics` adds the physical
//! replay (rapier3d) after the other checks: class `physics`, its time and
//! what it found in a line on stderr.

use std::io::Read;
use std::path::Path;

use afford_check::{MAX_PLAN_BYTES, PlanFile, check_plan, read_plan};
use afford_collision::replay::ReplayReport;
use afford_kinematics::RobotModel;
use serde::Serialize;

use super::output::{emit, note};
use super::plan::{load, load_robot};
use super::{CheckArgs, ExitKind, Failure};

/// `--json` output: the verdict and every violation.
#[derive(Serialize)]
struct JsonReport<'a> {
    passed: bool,
    violations: &'a [afford_check::Violation],
    /// The physical replay's full report (`--physics` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    physics: Option<&'a ReplayReport>,
}

pub fn run(args: &CheckArgs) -> Result<(), Failure> {
    let scenario = load(Some(&args.scenario))?;
    let robot = load_robot(&scenario, Some(&args.scenario), &args.packages.paths())?;
    joints_fit(&args.scenario, &scenario, &robot)?;
    let plan = read_plan_file(&args.plan)?;
    let mut report = check_plan(&scenario, &robot, &plan);
    let replayed = match args.physics {
        true => physics(&scenario, &robot, &plan, &mut report),
        false => None,
    };
    let text = match args.json {
        true => {
            let json = JsonReport {
                passed: report.passed(),
                violations: &report.violations,
                physics: replayed.as_ref(),
            };
            let mut text = serde_json::to_string_pretty(&json)
                .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
            text.push('\n');
            text
        }
        false => report.violations.iter().map(|v| format!("{v}\n")).collect(),
    };
    emit(&text, None)?;
    let name = args.plan.display();
    match report.violations.len() {
        0 => {
            if !args.json {
                note(format_args!(
                    "{name}: {} sub-goal(s) pass every check",
                    plan.subgoals.len()
                ));
            }
            Ok(())
        }
        n => Err(Failure::new(
            ExitKind::CouldNotPlan,
            format!("{name}: {n} violation(s)"),
        )),
    }
}

/// The scenario's `robot.joints` fit the robot by the gate's own reading
/// ([`afford_check::scenario_joint_issues`]): else bad input (exit 2), each
/// field named, before any plan is read.
fn joints_fit(
    path: &Path,
    scenario: &afford_planner::Scenario,
    robot: &RobotModel,
) -> Result<(), Failure> {
    let issues = afford_check::scenario_joint_issues(scenario, robot);
    if issues.is_empty() {
        return Ok(());
    }
    let lines: Vec<String> = issues
        .iter()
        .map(|(field, message)| format!("\n  - {field}: {message}"))
        .collect();
    Err(Failure::new(
        ExitKind::BadInput,
        format!(
            "{}: the robot's state does not fit {}:{}",
            path.display(),
            robot.name(),
            lines.concat()
        ),
    ))
}

/// Runs the physical replay, adds its violations to `report` and returns
/// its report (`None` when the plan could not be turned into motions).
fn physics(
    scenario: &afford_planner::Scenario,
    robot: &RobotModel,
    plan: &PlanFile,
    report: &mut afford_check::Report,
) -> Option<ReplayReport> {
    let started = std::time::Instant::now();
    let (replayed, found) = afford_check::physics::check_physics(scenario, robot, plan);
    // A plan that could not be turned into motions replays nothing: its
    // `physics` violation says why, no "0 steps, 0 of 0 pieces" line.
    if let Some(r) = replayed.as_ref().filter(|r| r.steps > 0) {
        let moved = r.pieces.iter().filter(|p| p.moved).count();
        let inside = r.targets.iter().filter(|t| t.in_goal).count();
        note(format_args!(
            "physics: {} steps of {} ms in {:.0} ms: {inside} of {} pieces in their goal, {moved} other piece(s) moved, {} contact(s)",
            r.steps,
            r.step * 1e3,
            started.elapsed().as_secs_f64() * 1e3,
            r.targets.len(),
            r.contacts.len()
        ));
    }
    report.violations.extend(found.violations);
    replayed
}

/// Reads at most [`MAX_PLAN_BYTES`] (+1 to tell a larger file) and parses it.
fn read_plan_file(path: &Path) -> Result<PlanFile, Failure> {
    let bad = |m: String| Failure::new(ExitKind::BadInput, format!("{}: {m}", path.display()));
    let file = afford_planner::scenario::open_regular(path)
        .map_err(|e| bad(format!("cannot read the file: {e}")))?;
    let mut bytes = Vec::new();
    file.take(MAX_PLAN_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| bad(format!("cannot read the file: {e}")))?;
    if bytes.len() > MAX_PLAN_BYTES {
        return Err(bad(format!(
            "more than the {MAX_PLAN_BYTES} bytes a plan file may have"
        )));
    }
    let text = String::from_utf8(bytes).map_err(|_| bad("is not UTF-8 text".into()))?;
    if is_run_output(&text) {
        return Err(bad(RUN_OUTPUT.into()));
    }
    read_plan(&text).map_err(|e| bad(e.to_string()))
}

/// Why the output of `afford run` is not checked here.
const RUN_OUTPUT: &str = "this is the output of `afford run` (it has `outcome` and `events`), not a plan: the scene changed while it ran, so checking it against the scenario's first scene would report false violations. `afford run` checks its own executed timeline against the scene as it changed (the independent check, the hand check and the physical replay: its `people` and `physics` fields, exit 1 when one fails); run `afford run SCENARIO` again to re-check it";

/// A JSON or YAML document whose top level has `outcome` and `events`: what
/// `afford run` writes.
fn is_run_output(text: &str) -> bool {
    let keys = |v: &serde_json::Value| v.get("outcome").is_some() && v.get("events").is_some();
    match serde_json::from_str::<serde_json::Value>(text) {
        Ok(v) => keys(&v),
        Err(_) => serde_saphyr::from_str::<serde_json::Value>(text).is_ok_and(|v| keys(&v)),
    }
}
