//! `afford check`: the independent gate (crate `afford-check`) over a plan
//! file and its scenario. Exit 0 when the plan passes, 1 with violations
//! (one line each on stdout: class, sub-goal, message), 2 when the scenario,
//! the robot or the plan file cannot be read.

use std::io::Read;
use std::path::Path;

use afford_check::{MAX_PLAN_BYTES, PlanFile, check_plan, read_plan};
use afford_kinematics::RobotModel;
use serde::Serialize;

use super::output::emit;
use super::plan::{base_dir, load};
use super::{CheckArgs, ExitKind, Failure};

/// `--json` output: the verdict and every violation.
#[derive(Serialize)]
struct JsonReport<'a> {
    passed: bool,
    violations: &'a [afford_check::Violation],
}

pub fn run(args: &CheckArgs) -> Result<(), Failure> {
    let scenario = load(Some(&args.scenario))?;
    let robot = RobotModel::load(&scenario.robot.model, &base_dir(Some(&args.scenario)))
        .map_err(|e| Failure::new(ExitKind::BadInput, format!("robot: {e}")))?;
    let plan = read_plan_file(&args.plan)?;
    let report = check_plan(&scenario, &robot, &plan);
    let text = match args.json {
        true => {
            let json = JsonReport {
                passed: report.passed(),
                violations: &report.violations,
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
                eprintln!("{name}: {} sub-goals pass every check", plan.subgoals.len());
            }
            Ok(())
        }
        n => Err(Failure::new(
            ExitKind::CouldNotPlan,
            format!("{name}: {n} violation(s)"),
        )),
    }
}

/// Reads at most [`MAX_PLAN_BYTES`] (+1 to tell a larger file) and parses it.
fn read_plan_file(path: &Path) -> Result<PlanFile, Failure> {
    let bad = |m: String| Failure::new(ExitKind::BadInput, format!("{}: {m}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| bad(format!("cannot read the file: {e}")))?;
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
    read_plan(&text).map_err(|e| bad(e.to_string()))
}
