//! `afford plan`: scenario file → discrete plan.

use std::path::{Path, PathBuf};

use afford_kinematics::RobotModel;
use afford_planner::plan::UnsolvedSubgoal;
use afford_planner::scenario::{self, Scenario, bounds};
use afford_planner::timing::TimingSettings;
use afford_planner::{Plan, PlanError, PlanOptions, plan};

use super::output::{emit, note, render, render_csv};
use super::{ExitKind, Failure, OutputFormat, PlanArgs};

pub fn run(args: &PlanArgs) -> Result<(), Failure> {
    bounds::check_rate(args.rate)
        .map_err(|problem| Failure::new(ExitKind::BadInput, format!("--rate: {problem}")))?;
    let mut scenario = load(args.scenario.as_deref())?;
    let robot = load_robot(&scenario, args.scenario.as_deref())?;
    if scenario.name.is_none() {
        scenario.name = Some(source_name(args));
    }
    let options = PlanOptions {
        seed: args.seed,
        until: args.until.into(),
        base_dir: base_dir(args.scenario.as_deref()),
        timing: TimingSettings {
            rate_hz: args.rate,
            ..TimingSettings::default()
        },
        ..PlanOptions::default()
    };
    let plan = match plan(&scenario, &options) {
        Ok(plan) => plan,
        // Nothing planned: the plan is still written (no sub-goals, every
        // `unsolved` entry with its typed `refusal`), so a program reads
        // why without parsing stderr, and the picture shows each failure.
        Err(PlanError::Unsolvable { unsolved, .. }) => {
            nothing_planned(&scenario, &options, unsolved)
        }
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

/// The plan of a scenario none of whose sub-goals could be planned.
fn nothing_planned(
    scenario: &Scenario,
    options: &PlanOptions,
    unsolved: Vec<UnsolvedSubgoal>,
) -> Plan {
    Plan {
        scenario: scenario.name.clone().unwrap_or_default(),
        seed: options.seed,
        until: options.until,
        start_state: None,
        skipped: Vec::new(),
        subgoals: Vec::new(),
        unsolved,
        timings: Default::default(),
    }
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
pub fn load_robot(scenario: &Scenario, path: Option<&Path>) -> Result<RobotModel, Failure> {
    RobotModel::load(&scenario.robot.model, &base_dir(path)).map_err(|e| {
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

fn source_name(args: &PlanArgs) -> String {
    match &args.scenario {
        Some(path) => path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        ),
        None => scenario::DEFAULT_SCENARIO_NAME.to_string(),
    }
}
