//! `afford run`: plans the scenario, then executes the plan against its
//! observation timeline with the valid-policy detector
//! ([`afford_planner::monitor`]) and writes the executed timeline (one
//! entry per sub-goal begun, in the shape of a plan, times from each
//! sub-goal's `start_time`) and the event log. Every executed sub-goal is
//! re-checked by the independent checker before anything is written.
//! Exit 0 completed, 1 aborted (the reason on stderr) or the executed
//! timeline failed the check, 2 bad input.

use afford_check::{ViolationClass, check_plan, read_plan};
use afford_kinematics::RobotModel;
use afford_planner::monitor::{Event, ExecutedSubgoal, Monitor, Reason, Status, timeline};
use afford_planner::scenario::{Scenario, bounds};
use afford_planner::timing::TimingSettings;
use afford_planner::{JointState, PlanError, PlanOptions, plan};
use serde::Serialize;

use super::output::{emit, render};
use super::plan::{base_dir, load, load_robot};
use super::{ExitKind, Failure, OutputFormat, RunArgs};

/// What `afford run` writes.
#[derive(Serialize)]
struct RunOutput<'a> {
    scenario: String,
    seed: u64,
    /// `completed` or `aborted`.
    outcome: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<&'a Reason>,
    #[serde(skip_serializing_if = "Option::is_none")]
    start_state: Option<&'a JointState>,
    /// The executed timeline, one entry per sub-goal begun.
    subgoals: &'a [ExecutedSubgoal],
    events: Vec<EventOut<'a>>,
}

/// An event, with the decision time only when `--timings` asks for it
/// (wall-clock: it differs from run to run).
#[derive(Serialize)]
struct EventOut<'a> {
    #[serde(flatten)]
    event: &'a Event,
    #[serde(skip_serializing_if = "Option::is_none")]
    decision_us: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    replan_ms: Option<f64>,
}

pub fn run(args: &RunArgs) -> Result<(), Failure> {
    bounds::check_rate(args.rate)
        .map_err(|problem| Failure::new(ExitKind::BadInput, format!("--rate: {problem}")))?;
    let mut scenario = load(args.scenario.as_deref())?;
    let robot = load_robot(&scenario, args.scenario.as_deref())?;
    if scenario.name.is_none() {
        scenario.name = Some(match &args.scenario {
            Some(p) => p
                .file_stem()
                .map_or_else(|| p.display().to_string(), |s| s.to_string_lossy().into()),
            None => afford_planner::scenario::DEFAULT_SCENARIO_NAME.to_string(),
        });
    }
    let options = PlanOptions {
        seed: args.seed,
        base_dir: base_dir(args.scenario.as_deref()),
        timing: TimingSettings {
            rate_hz: args.rate,
            ..TimingSettings::default()
        },
        ..PlanOptions::default()
    };
    let planned = plan(&scenario, &options).map_err(|e| match e {
        PlanError::Scenario(_) | PlanError::Robot(_) | PlanError::RobotState { .. } => {
            Failure::new(ExitKind::BadInput, e.to_string())
        }
        _ => Failure::new(ExitKind::CouldNotPlan, e.to_string()),
    })?;
    let mut monitor = Monitor::new(planned, &scenario, &options)
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
    timeline::play(&mut monitor, &scenario.observations);
    let violations = check_executed(&monitor, &robot)?;
    summary(&monitor);
    if !violations.is_empty() {
        return Err(Failure::new(
            ExitKind::CouldNotPlan,
            format!(
                "the executed timeline fails the independent check; nothing written:\n  {}",
                violations.join("\n  ")
            ),
        ));
    }
    let reason = match monitor.status() {
        Status::Aborted(reason) => Some(reason),
        _ => None,
    };
    let output = RunOutput {
        scenario: scenario.name.clone().unwrap_or_default(),
        seed: args.seed,
        outcome: if reason.is_some() {
            "aborted"
        } else {
            "completed"
        },
        reason,
        start_state: monitor.start_state(),
        subgoals: monitor.executed(),
        events: monitor
            .events()
            .iter()
            .map(|event| EventOut {
                event,
                decision_us: args.timings.then_some(event.decision_us),
                replan_ms: event.replan_ms.filter(|_| args.timings),
            })
            .collect(),
    };
    let text = match args.format {
        OutputFormat::Csv => csv(&monitor),
        format => render(&output, format)?,
    };
    emit(&text, args.output.as_deref())?;
    if let Some(svg) = &args.svg {
        let picture = super::run_svg::draw(
            monitor.scene(),
            monitor.executed(),
            monitor.events(),
            &robot,
        );
        emit(&picture, Some(svg))?;
    }
    match reason {
        Some(reason) => Err(Failure::new(
            ExitKind::CouldNotPlan,
            format!("aborted: {reason}"),
        )),
        None => Ok(()),
    }
}

/// Each executed sub-goal through the independent check, against the scene
/// believed when it ended with its object where it was taken from, from
/// the robot's state when it began. Violations, one line each.
fn check_executed(monitor: &Monitor, robot: &RobotModel) -> Result<Vec<String>, Failure> {
    let mut lines = Vec::new();
    for (k, sub) in monitor.executed().iter().enumerate() {
        let Some(scene) = &sub.scene else {
            continue;
        };
        let start = whole_state(monitor, robot, k);
        let scene = Scenario {
            robot: afford_planner::scenario::RobotSpec {
                start: None,
                joints: Some(
                    start
                        .joint_names
                        .iter()
                        .cloned()
                        .zip(start.positions.iter().copied())
                        .collect(),
                ),
                ..scene.robot.clone()
            },
            observations: Vec::new(),
            ..scene.clone()
        };
        #[derive(Serialize)]
        struct One<'a> {
            start_state: &'a JointState,
            subgoals: [&'a ExecutedSubgoal; 1],
        }
        let text = serde_json::to_string(&One {
            start_state: &start,
            subgoals: [sub],
        })
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
        let file = read_plan(&text).map_err(|e| {
            Failure::new(
                ExitKind::CouldNotPlan,
                format!("executed sub-goal {k}: {e}"),
            )
        })?;
        let report = check_plan(&scene, robot, &file);
        // The jerk class judges plans: the monitor's speed override (slow
        // down, stop) does not bound jerk yet (issue 9 item 6 is the plans').
        lines.extend(
            report
                .violations
                .iter()
                .filter(|v| v.class != ViolationClass::Jerk)
                .map(|v| format!("executed sub-goal {k}: {v}")),
        );
    }
    Ok(lines)
}

/// The whole robot's state when executed sub-goal `k` began: the start
/// state with every earlier sub-goal's arm where it ended.
fn whole_state(monitor: &Monitor, robot: &RobotModel, k: usize) -> JointState {
    let mut state = monitor.start_state().cloned().unwrap_or(JointState {
        joint_names: Vec::new(),
        positions: Vec::new(),
    });
    for sub in &monitor.executed()[..k] {
        if let (Ok(arm), Some(last)) = (robot.arm(&sub.arm), sub.trajectory.points.last()) {
            arm.insert(&mut state.positions, &last.positions);
        }
    }
    state
}

/// A few lines on stderr: the outcome, then each event.
fn summary(monitor: &Monitor) {
    let done = monitor.executed().len();
    let t = monitor.clock();
    match monitor.status() {
        Status::Aborted(reason) => {
            eprintln!("afford run: aborted at {t:.2} s after {done} sub-goal(s) begun: {reason}")
        }
        _ => eprintln!("afford run: completed {done} sub-goal(s) in {t:.2} s"),
    }
    for e in monitor.events() {
        let what = match (&e.message, e.scale) {
            (Some(m), _) => format!(": {m}"),
            (None, Some(s)) => format!(" to {:.0} % speed", s * 100.0),
            _ if !e.subgoals.is_empty() => format!(": {}", e.subgoals.join(", ")),
            _ => String::new(),
        };
        let changed = match e.changes.is_empty() {
            true => String::new(),
            false => format!(" [{}]", e.changes.join("; ")),
        };
        let replan = e
            .replan_ms
            .map_or(String::new(), |ms| format!(", replanned in {ms:.1} ms"));
        eprintln!(
            "  {:7.2} s  {}{what}{changed} (decided in {:.0} µs{replan})",
            e.time, e.verdict, e.decision_us
        );
    }
}

/// The executed timeline as CSV: one row per sample, execution time first,
/// then as `afford plan --format csv`; the `event` column names the
/// verdicts decided at that sample.
fn csv(monitor: &Monitor) -> String {
    let dof = monitor
        .executed()
        .iter()
        .map(|s| s.joint_names.len())
        .max()
        .unwrap_or(0);
    let names = |prefix: char| (1..=dof).map(move |j| format!("{prefix}{j}"));
    let header: Vec<String> = ["time", "subgoal", "object", "arm", "gripper", "event"]
        .into_iter()
        .map(String::from)
        .chain(names('q'))
        .chain(names('v'))
        .chain(names('a'))
        .collect();
    let mut out = header.join(",") + "\n";
    let mut events = monitor.events().iter().peekable();
    for (k, s) in monitor.executed().iter().enumerate() {
        for p in &s.trajectory.points {
            let time = s.start_time + p.time_from_start;
            let mut here = Vec::new();
            while let Some(e) = events.next_if(|e| e.time <= time + 1e-9) {
                here.push(e.verdict);
            }
            let numbers: Vec<String> = p
                .positions
                .iter()
                .chain(&p.velocities)
                .chain(&p.accelerations)
                .map(|v| format!("{v}"))
                .collect();
            out.push_str(&format!(
                "{time},{k},{},{},{},{},{}\n",
                s.object,
                s.arm,
                s.trajectory.gripper_state(p.time_from_start).name(),
                here.join(" "),
                numbers.join(",")
            ));
        }
    }
    out
}
