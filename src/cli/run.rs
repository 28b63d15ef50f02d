//! `afford run`: plans the scenario, then executes the plan against its
//! observation timeline with the valid-policy detector
//! ([`afford_planner::monitor`]) and writes the executed timeline (one
//! entry per sub-goal begun, in the shape of a plan, times from each
//! sub-goal's `start_time`), the event log and the physical replay of the
//! result ([`executed`]). Every executed sub-goal is re-checked by the
//! independent checker before anything is written (a violation: nothing
//! written, exit 1), then replayed physically (rapier3d): its report is
//! the output's `physics` field and a line on stderr.
//! Exit 0 completed with every replay passing; 1 aborted, or the executed
//! timeline failed the check or the physical replay (each reason on
//! stderr); 2 bad input.

use afford_planner::monitor::{Event, ExecutedSubgoal, Monitor, Reason, Status, timeline};
use afford_planner::scenario::bounds;
use afford_planner::timing::TimingSettings;
use afford_planner::{JointState, PlanError, PlanOptions, plan};
use serde::Serialize;

use super::executed::{self, PeopleCheck, RunReplay};
use super::output::{csv_header, csv_numbers, csv_text, emit, note, render};
use super::plan::{base_dir, load, load_robot};
use super::{ExitKind, Failure, OutputFormat, RunArgs};

/// What `afford run` writes.
#[derive(Serialize)]
struct RunOutput<'a> {
    scenario: String,
    seed: u64,
    /// `completed`, `aborted`, `replay_failed` or `touched_hand`
    /// ([`outcome`]).
    outcome: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<&'a Reason>,
    #[serde(skip_serializing_if = "Option::is_none")]
    start_state: Option<&'a JointState>,
    /// The executed timeline, one entry per sub-goal begun.
    subgoals: &'a [ExecutedSubgoal],
    events: Vec<EventOut<'a>>,
    /// The physical replay of every executed sub-goal (ended or cut short).
    physics: &'a RunReplay,
    /// The hand check and the stops, measured by afford-check.
    people: &'a PeopleCheck,
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
    let robot = load_robot(&scenario, args.scenario.as_deref(), &args.packages.paths())?;
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
        packages: args.packages.paths(),
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
    let delivered = timeline::play(&mut monitor, &scenario.observations);
    if delivered < scenario.observations.len() {
        note(format_args!(
            "afford run: observations[{delivered}..{}] never came due: the run ended first",
            scenario.observations.len()
        ));
    }
    let files =
        executed::files(&monitor, &robot).map_err(|e| Failure::new(ExitKind::CouldNotPlan, e))?;
    let violations = executed::check(&files, &robot);
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
    let replayed = executed::replay(&files, &robot);
    physics_summary(&replayed);
    let people = executed::people(&files, &monitor, &robot);
    let reason = match monitor.status() {
        Status::Aborted(reason) => Some(reason),
        _ => None,
    };
    let output = RunOutput {
        scenario: scenario.name.clone().unwrap_or_default(),
        seed: args.seed,
        outcome: outcome(reason.is_some(), &replayed, &people),
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
        physics: &replayed,
        people: &people,
    };
    let text = match args.format {
        OutputFormat::Csv => csv(&monitor),
        format => render(&output, format)?,
    };
    // The picture first: a picture that cannot be written leaves no run
    // file behind either.
    if let Some(svg) = &args.svg {
        let picture = super::run_svg::draw(
            monitor.scene(),
            monitor.executed(),
            monitor.events(),
            &robot,
        );
        emit(&picture, Some(svg))?;
    }
    emit(&text, args.output.as_deref())?;
    exit(reason, &replayed, &people)
}

/// What the run came to, worst first: `touched_hand` when the physical
/// replay or the hand check found a robot body or the held piece touching
/// a seen hand (nothing that touched a person is a success),
/// `entered_perimeter` when a body came into a seen hand's perimeter from
/// outside, `stop_beyond_term` when a stop travelled past the stopping
/// term, `replay_failed` for any other finding of the replay, `aborted`
/// when the monitor stopped for good, else `completed`.
fn outcome(aborted: bool, replayed: &RunReplay, people: &PeopleCheck) -> &'static str {
    let touched = replayed
        .subgoals
        .iter()
        .filter_map(|s| s.report.as_ref())
        .flat_map(|r| &r.contacts)
        .any(|c| c.kind == afford_collision::replay::BodyKind::Hand);
    if touched || !people.hand_contacts.is_empty() {
        "touched_hand"
    } else if !people.perimeter_entries.is_empty() {
        "entered_perimeter"
    } else if people.largest_stop_ratio > 1.0 {
        "stop_beyond_term"
    } else if !replayed.passed {
        "replay_failed"
    } else if aborted {
        "aborted"
    } else {
        "completed"
    }
}

/// Exit 1 when the run was aborted or its physical replay failed (both
/// reasons on stderr), else 0.
fn exit(
    aborted: Option<&Reason>,
    replayed: &RunReplay,
    people: &PeopleCheck,
) -> Result<(), Failure> {
    let mut reasons: Vec<String> = aborted
        .map(|r| format!("aborted: {r}"))
        .into_iter()
        .collect();
    if !replayed.passed {
        reasons.push(format!(
            "the executed run fails the physical replay:\n  {}",
            replayed.failures().join("\n  ")
        ));
    }
    let near: Vec<&String> = people
        .hand_contacts
        .iter()
        .chain(&people.perimeter_entries)
        .collect();
    if !near.is_empty() {
        let lines: Vec<&str> = near.iter().map(|s| s.as_str()).collect();
        reasons.push(format!(
            "the executed run comes too near a seen hand:\n  {}",
            lines.join("\n  ")
        ));
    }
    if people.largest_stop_ratio > 1.0 {
        reasons.push(format!(
            "a stop travelled {:.2} times its stopping term",
            people.largest_stop_ratio
        ));
    }
    match reasons.is_empty() {
        true => Ok(()),
        false => Err(Failure::new(ExitKind::CouldNotPlan, reasons.join("\n"))),
    }
}

/// One line on stderr: how many executed sub-goals the physical replay
/// passed, where the targets came to rest, what else moved or was touched.
fn physics_summary(replayed: &RunReplay) {
    let reports = || replayed.subgoals.iter().filter_map(|s| s.report.as_ref());
    let passed = replayed.subgoals.iter().filter(|s| s.passed).count();
    let in_goal = reports()
        .flat_map(|r| &r.targets)
        .filter(|t| t.goal.is_some() && t.in_goal)
        .count();
    let moved = reports()
        .flat_map(|r| &r.pieces)
        .filter(|p| p.moved)
        .count();
    let contacts: usize = reports().map(|r| r.contacts.len()).sum();
    note(format_args!(
        "  physical replay: {passed} of {} executed sub-goal(s) pass; {in_goal} piece(s) at rest in their goal, {moved} other piece(s) moved, {contacts} contact(s)",
        replayed.subgoals.len()
    ));
}

/// A few lines on stderr: the outcome, then each event.
fn summary(monitor: &Monitor) {
    let done = monitor.executed().len();
    let t = monitor.clock();
    match monitor.status() {
        Status::Aborted(reason) => note(format_args!(
            "afford run: aborted at {t:.2} s after {done} sub-goal(s) begun: {reason}"
        )),
        _ => note(format_args!(
            "afford run: completed {done} sub-goal(s) in {t:.2} s"
        )),
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
        note(format_args!(
            "  {:7.2} s  {}{what}{changed} (decided in {:.0} µs{replan})",
            e.time, e.verdict, e.decision_us
        ));
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
    let mut out = csv_header(
        &["time", "subgoal", "object", "arm", "gripper", "event"],
        dof,
    );
    let mut events = monitor.events().iter().peekable();
    for (k, s) in monitor.executed().iter().enumerate() {
        for p in &s.trajectory.points {
            let time = s.start_time + p.time_from_start;
            let mut here = Vec::new();
            while let Some(e) = events.next_if(|e| e.time <= time + 1e-9) {
                here.push(e.verdict);
            }
            out.push_str(&format!(
                "{time},{k},{},{},{},{},{}\n",
                csv_text(&s.object),
                csv_text(&s.arm),
                s.trajectory.gripper_state(p.time_from_start).name(),
                here.join(" "),
                csv_numbers(p)
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use executed::SubgoalReplay;

    fn clear() -> PeopleCheck {
        PeopleCheck {
            passed: true,
            ..PeopleCheck::default()
        }
    }

    /// A run the hand check found in a hand's perimeter or whose stop ran
    /// past its term is not completed, even when the replay passed.
    #[test]
    fn a_run_near_a_hand_or_with_a_long_stop_is_not_reported_completed() {
        let entered = PeopleCheck {
            perimeter_entries: vec!["link_7 comes within 40 mm of hand-1".into()],
            ..clear()
        };
        assert_eq!(outcome(false, &replay(&[]), &entered), "entered_perimeter");
        let long = PeopleCheck {
            largest_stop_ratio: 1.3,
            ..clear()
        };
        assert_eq!(outcome(false, &replay(&[]), &long), "stop_beyond_term");
        assert!(exit(None, &replay(&[]), &long).is_err());
        let touched = PeopleCheck {
            hand_contacts: vec!["held piece inside hand-1".into()],
            ..entered
        };
        assert_eq!(outcome(false, &replay(&[]), &touched), "touched_hand");
    }

    fn replay(failures: &[&str]) -> RunReplay {
        RunReplay {
            passed: failures.is_empty(),
            subgoals: vec![SubgoalReplay {
                subgoal: 1,
                object: "blue-square-2".into(),
                passed: failures.is_empty(),
                failures: failures.iter().map(|f| f.to_string()).collect(),
                report: None,
            }],
        }
    }

    /// A completed run whose physical replay fails exits 1 with the finding
    /// and the sub-goal it happened in; one that passes exits 0.
    #[test]
    fn run_exit_is_1_when_the_physical_replay_of_the_executed_run_fails() {
        assert!(exit(None, &replay(&[]), &clear()).is_ok());
        let failed = exit(None, &replay(&["red-square-1 moved 7.0 mm"]), &clear()).unwrap_err();
        assert_eq!(failed.code, ExitKind::CouldNotPlan);
        assert!(
            failed.message.contains("fails the physical replay")
                && failed
                    .message
                    .contains("sub-goal 1 (blue-square-2): red-square-1 moved 7.0 mm"),
            "{}",
            failed.message
        );
    }

    /// Nothing that touched a person is reported as a success: a run whose
    /// replay found the held piece in a hand says so, whatever else.
    #[test]
    fn a_run_whose_replay_touched_a_hand_is_not_reported_completed() {
        let mut touched = replay(&["held blue-square-1 touches the hand hand-1"]);
        touched.subgoals[0].report = Some(afford_collision::replay::ReplayReport {
            step: 0.01,
            steps: 1,
            targets: Vec::new(),
            pieces: Vec::new(),
            contacts: vec![afford_collision::replay::LinkContact {
                link: "held blue-square-1".into(),
                body: "hand-1".into(),
                kind: afford_collision::replay::BodyKind::Hand,
                motion: 0,
                first: 3.8,
                last: 3.9,
                depth: 0.011,
            }],
            input_error: None,
        });
        assert_eq!(outcome(false, &touched, &clear()), "touched_hand");
        assert_eq!(outcome(true, &touched, &clear()), "touched_hand");
        assert_eq!(
            outcome(false, &replay(&["moved"]), &clear()),
            "replay_failed"
        );
        assert_eq!(outcome(true, &replay(&[]), &clear()), "aborted");
        assert_eq!(outcome(false, &replay(&[]), &clear()), "completed");
    }

    /// An aborted run whose replay also fails gives both reasons.
    #[test]
    fn run_exit_names_the_abort_and_the_replay_failure_together() {
        let reason = Reason::NoPlan {
            message: "no way round".into(),
        };
        let failed = exit(
            Some(&reason),
            &replay(&["blue-square-2 comes to rest outside"]),
            &clear(),
        )
        .unwrap_err();
        assert_eq!(failed.code, ExitKind::CouldNotPlan);
        assert!(
            failed.message.starts_with("aborted: "),
            "{}",
            failed.message
        );
        assert!(
            failed.message.contains("physical replay"),
            "{}",
            failed.message
        );
    }
}
