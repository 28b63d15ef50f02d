//! `afford plan`: scenario file → discrete plan.

use std::path::{Path, PathBuf};

use afford::plan_json::{plan_or_refusals, source_name, to_json};
use afford_kinematics::{PackagePaths, RobotModel};
use afford_planner::scenario::{self, Scenario, bounds};
use afford_planner::timing::TimingSettings;
use afford_planner::{Plan, PlanError, PlanOptions};

use super::output::{emit, note, render, render_csv};
use super::{ExitKind, Failure, OutputFormat, PlanArgs};

pub fn run(args: &PlanArgs) -> Result<(), Failure> {
    bounds::check_rate(args.rate)
        .map_err(|problem| Failure::new(ExitKind::BadInput, format!("--rate: {problem}")))?;
    let mut scenario = load(args.scenario.as_deref())?;
    let robot = load_robot(&scenario, args.scenario.as_deref(), &args.packages.paths())?;
    if scenario.name.is_none() {
        scenario.name = Some(source_name(args.scenario.as_deref()));
    }
    let options = PlanOptions {
        seed: args.seed,
        until: args.until.into(),
        base_dir: base_dir(args.scenario.as_deref()),
        packages: args.packages.paths(),
        timing: TimingSettings {
            rate_hz: args.rate,
            ..TimingSettings::default()
        },
        ..PlanOptions::default()
    };
    // Nothing planned: the plan is still written (no sub-goals, every
    // `unsolved` entry with its typed `refusal`), so a program reads why
    // without parsing stderr, and the picture shows each failure.
    let plan = match plan_or_refusals(&scenario, &options) {
        Ok(plan) => plan,
        Err(e) => {
            return Err(match e {
                PlanError::Scenario(_) | PlanError::Robot(_) | PlanError::Options { .. } => {
                    Failure::new(ExitKind::BadInput, e.to_string())
                }
                PlanError::RobotState { .. } => {
                    Failure::new(ExitKind::BadInput, format!("{}: {e}", scenario_file(args)))
                }
                _ => Failure::new(ExitKind::CouldNotPlan, e.to_string()),
            });
        }
    };
    let text = match format(args) {
        OutputFormat::Csv if plan.subgoals.is_empty() => String::new(),
        OutputFormat::Csv => render_csv(&plan)?,
        OutputFormat::Summary => super::summary::summary(&plan),
        OutputFormat::Json => to_json(&plan).map_err(|e| {
            Failure::new(
                ExitKind::CouldNotPlan,
                format!("cannot serialise the result: {e}"),
            )
        })?,
        format => render(&plan, format)?,
    };
    // The picture first: when it cannot be written, no plan is left behind
    // by a run that exits 2.
    if let Some(svg) = &args.svg {
        draw(&scenario, &plan, &robot, svg)?;
    }
    emit(&text, args.output.as_deref())?;
    for skipped in &plan.skipped {
        note(format_args!("afford: left where it is: {skipped}"));
    }
    if plan.unsolved.is_empty() {
        return Ok(());
    }
    let reasons: Vec<String> = plan
        .unsolved
        .iter()
        .map(|u| {
            format!(
                "{} → {}: {} [{}]",
                u.object,
                u.goal,
                u.reason,
                u.refusal.kind()
            )
        })
        .collect();
    let some = match plan.subgoals.is_empty() {
        true => "no sub-goal could be planned",
        false => "some sub-goals could not be planned",
    };
    Err(Failure::new(
        ExitKind::CouldNotPlan,
        format!("{some}:\n  - {}", reasons.join("\n  - ")),
    ))
}

/// Writes the picture of `plan` to `svg`.
fn draw(scenario: &Scenario, plan: &Plan, robot: &RobotModel, svg: &Path) -> Result<(), Failure> {
    let picture = afford::picture::plan_svg(scenario, plan, Some(robot))
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
    emit(&picture, Some(svg))
}

/// `--format`, else the summary for a person at a terminal and JSON for a
/// program (stdout piped or redirected, or `-o FILE`).
fn format(args: &PlanArgs) -> OutputFormat {
    use std::io::IsTerminal;
    match args.format {
        Some(format) => format,
        None if args.output.is_none() && std::io::stdout().is_terminal() => OutputFormat::Summary,
        None => OutputFormat::Json,
    }
}

/// The folder a scenario's relative paths start from: the file's folder
/// (the library's rule, [`scenario::base_dir`]); the current directory for
/// the built-in scenario.
pub fn base_dir(scenario: Option<&Path>) -> PathBuf {
    scenario.map_or_else(|| PathBuf::from("."), scenario::base_dir)
}

/// The scenario's robot (`robot.model`), loaded as `plan` would: an unknown
/// model or a broken description is bad input, named by field.
pub fn load_robot(
    scenario: &Scenario,
    path: Option<&Path>,
    packages: &PackagePaths,
) -> Result<RobotModel, Failure> {
    RobotModel::load_with(&scenario.robot.model, &base_dir(path), packages).map_err(|e| {
        let file = path.map_or_else(
            || scenario::DEFAULT_SCENARIO_NAME.to_string(),
            |p| p.display().to_string(),
        );
        Failure::new(ExitKind::BadInput, format!("{file}: robot.model: {e}"))
    })
}

/// The scenario from the file argument, or the embedded default.
pub fn load(path: Option<&Path>) -> Result<Scenario, Failure> {
    let loaded = match path {
        Some(path) => scenario::load(path),
        None => scenario::default_scenario(),
    };
    loaded.map_err(|e| Failure::new(ExitKind::BadInput, e.to_string()))
}

/// The scenario file as the user named it, for error messages.
fn scenario_file(args: &PlanArgs) -> String {
    args.scenario.as_ref().map_or_else(
        || scenario::DEFAULT_SCENARIO_NAME.to_string(),
        |p| p.display().to_string(),
    )
}
