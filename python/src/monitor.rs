//! `afford.Monitor`: the valid-policy detector online, driven by the
//! caller's own camera loop. `observe(t, objects=, goals=, hands=)` is
//! `Monitor::observe` at execution time `t` (the lists replace the
//! scene's, as an observation of a scenario's timeline does; none given: a
//! camera frame that saw the same scene), validated by the scenario
//! file's rules first; `advance(dt)` is `Monitor::advance` and returns the
//! setpoints executed meanwhile. Driven as `afford run` drives it
//! (`afford_planner::monitor::timeline::play`), it gives `afford run`'s
//! events and executed samples.

use afford::kinematics::RobotModel;
use afford::planner::monitor::{self as rust, Reason as RustReason, Status, timeline};
use afford::planner::scenario::bounds::MAX_EXECUTION_TIME_S;
use afford::planner::scenario::{self, Observation};
use afford::planner::timing::TrajectoryPoint;
use afford::planner::trajectory::GripperEvent as RustGripperEvent;
use pyo3::prelude::*;

use crate::bridge;
use crate::errors::{self, Bad};
use crate::execution::{Event, Executed, Setpoints, Verdict};
use crate::plan::{GripperEvent, Plan};
use crate::record::Reason;
use crate::scenario::Scenario;

/// The name errors give an observation from Python.
const OBSERVATION: &str = "<observation>";

/// Follows a plan (stage `trajectory`) of `scenario` from t = 0 and decides
/// on each camera observation, as `afford run` does with a scenario's
/// timeline: `continue`, `slow`, `stop`, `wait`, `replan`, `new_work` or
/// `abort`. A stop is a timed braking along the planned path within the
/// joint limits; a replan starts where the robot came to rest.
///
/// Drive it from the camera loop: `verdict = monitor.observe(t, hands=[...])`
/// at each frame (execution time `t`), then `setpoints =
/// monitor.advance(dt)` for the joint states to send until the next
/// frame. `monitor.executed` is the executed timeline, `monitor.events`
/// the decisions; `monitor.status` is `running` until `completed` or
/// `aborted`.
#[pyclass(module = "afford")]
pub struct Monitor {
    inner: rust::Monitor,
    robot: RobotModel,
    base_dir: std::path::PathBuf,
    file: String,
    sent: Sent,
}

#[pymethods]
impl Monitor {
    /// A monitor following `plan` (from `afford.plan(scenario, ...)`, stage
    /// `trajectory`) in `scenario`. Raises `afford.BadInput` when the plan
    /// has no timed sub-goal.
    #[new]
    fn new(
        py: Python<'_>,
        scenario: &Bound<'_, Scenario>,
        plan: &Bound<'_, Plan>,
    ) -> PyResult<Self> {
        let (s, p) = (scenario.get(), plan.get());
        let mut options = p.options.clone();
        options.base_dir = s.base_dir.clone();
        let made = errors::compute(py, || {
            let robot =
                RobotModel::load(&s.inner.robot.model, &s.base_dir).map_err(|e| e.to_string())?;
            let monitor = rust::Monitor::new(p.inner.clone(), &s.inner, &options)
                .map_err(|e| e.to_string())?;
            Ok::<_, String>((monitor, robot))
        })?;
        let (inner, robot) = made.map_err(|m| Bad::field(&s.file, "plan", m).into_err(py))?;
        Ok(Self {
            inner,
            robot,
            base_dir: s.base_dir.clone(),
            file: s.file.clone(),
            sent: Sent {
                entry: 0,
                points: 0,
                events: 0,
                time: f64::NEG_INFINITY,
            },
        })
    }

    /// Takes the camera's observation at execution time `t` (s; the
    /// execution first runs on to `t`) and decides. `objects`, `goals`,
    /// `hands` are lists in the scenario format that replace the scene's
    /// (`hands=[]`: the hands left); none given is a frame that saw the
    /// same scene. Returns the `Verdict`. Raises `afford.BadInput` for an
    /// observation a scenario file's timeline could not hold.
    #[pyo3(signature = (t, objects = None, goals = None, hands = None))]
    fn observe(
        &mut self,
        py: Python<'_>,
        t: f64,
        objects: Option<&Bound<'_, PyAny>>,
        goals: Option<&Bound<'_, PyAny>>,
        hands: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Verdict> {
        check_time("t", t).map_err(|b| b.into_err(py))?;
        let observation = self.observation(
            t,
            [("objects", objects), ("goals", goals), ("hands", hands)],
        );
        let observation = observation.map_err(|b| b.into_err(py))?;
        let inner = &mut self.inner;
        let verdict = errors::compute(py, || inner.observe(&observation, t))?;
        errors::guard(|| Verdict::new(py, &verdict))
    }

    /// Steps the execution at the controller rate for `dt` seconds (or up
    /// to the execution time `until`) and returns the `Setpoints` executed
    /// meanwhile: what the controller tracks until the next call.
    #[pyo3(signature = (dt = None, *, until = None))]
    fn advance(
        &mut self,
        py: Python<'_>,
        dt: Option<f64>,
        until: Option<f64>,
    ) -> PyResult<Setpoints> {
        let start = self.inner.clock();
        let target = match (dt, until) {
            (Some(dt), None) if dt.is_finite() && dt >= 0.0 => start + dt,
            (None, Some(until)) => until,
            (Some(dt), None) => {
                return Err(
                    Bad::field("", "dt", format!("must be a finite time ≥ 0 s, got {dt}"))
                        .into_err(py),
                );
            }
            _ => return Err(Bad::field("", "dt", "give one of `dt` and `until`").into_err(py)),
        };
        check_time("until", target).map_err(|b| b.into_err(py))?;
        let inner = &mut self.inner;
        errors::compute(py, || inner.advance(target))?;
        errors::guard(|| self.setpoints(py, start))
    }

    /// True when an entry of a scenario's `observations:` timeline (a dict
    /// with `at` or `when`) has fallen due: its time has come, or execution
    /// has reached its plan point (`afford run`'s rule).
    fn due(&self, py: Python<'_>, observation: &Bound<'_, PyAny>) -> PyResult<bool> {
        let text = bridge::json_text(observation, OBSERVATION).map_err(|b| b.into_err(py))?;
        let o: Observation = parse(&text).map_err(|b| b.into_err(py))?;
        Ok(timeline::due(&self.inner, &o))
    }

    /// Stops for good (reason `no_plan` with `message`): the robot brakes to
    /// rest along its path. Returns the `Setpoints` of the braking (with
    /// any not yet handed out by `advance`).
    fn abort(&mut self, py: Python<'_>, message: String) -> PyResult<Setpoints> {
        let start = self.inner.clock();
        let inner = &mut self.inner;
        errors::compute(py, || inner.abort(RustReason::NoPlan { message }))?;
        errors::guard(|| self.setpoints(py, start))
    }

    /// The execution clock, s.
    #[getter]
    fn clock(&self) -> f64 {
        self.inner.clock()
    }

    /// The controller period, s.
    #[getter]
    fn period(&self) -> f64 {
        self.inner.period()
    }

    /// `running`, `completed` or `aborted`.
    #[getter]
    fn status(&self) -> &'static str {
        match self.inner.status() {
            Status::Running => "running",
            Status::Completed => "completed",
            Status::Aborted(_) => "aborted",
        }
    }

    /// Why the run was aborted (`None` unless `status == "aborted"`).
    #[getter]
    fn reason(&self, py: Python<'_>) -> PyResult<Option<Reason>> {
        match self.inner.status() {
            Status::Aborted(r) => Ok(Some(Reason::new(py, r)?)),
            _ => Ok(None),
        }
    }

    /// Where execution is: `(subgoal, phase, fraction)` — the sub-goal
    /// under way (0-based, execution order), its phase (`travel`, `grasp`,
    /// `carry`, `release`, `retreat`) and how far through it (0–1).
    #[getter]
    fn position(&self, py: Python<'_>) -> PyResult<(usize, String, f64)> {
        let (k, phase, fraction) = self.inner.position();
        Ok((k, bridge::serialised(py, &phase)?.extract()?, fraction))
    }

    /// The executed timeline so far, one `Executed` per sub-goal begun.
    #[getter]
    fn executed(&self, py: Python<'_>) -> PyResult<Vec<Executed>> {
        self.inner
            .executed()
            .iter()
            .map(|e| Executed::new(py, e))
            .collect()
    }

    /// The decisions so far, one `Event` each.
    #[getter]
    fn events(&self, py: Python<'_>) -> PyResult<Vec<Event>> {
        self.inner
            .events()
            .iter()
            .map(|e| Event::new(py, e))
            .collect()
    }

    /// The whole robot's joint state at t = 0 (`{"joint_names", "positions"}`).
    #[getter]
    fn start_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner.start_state())
    }

    /// The scene the monitor believes in now.
    #[getter]
    fn scene(&self) -> Scenario {
        Scenario::new(
            self.inner.scene().clone(),
            self.base_dir.clone(),
            self.file.clone(),
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "Monitor(status={:?}, clock={}, executed={}, events={})",
            self.status(),
            self.inner.clock(),
            self.inner.executed().len(),
            self.inner.events().len()
        )
    }
}

impl Monitor {
    /// The observation at `t` of the lists given, validated as an entry of
    /// a scenario file's timeline is against the scene believed now.
    fn observation<const N: usize>(
        &self,
        t: f64,
        lists: [(&str, Option<&Bound<'_, PyAny>>); N],
    ) -> Result<Observation, Bad> {
        let mut text = format!(
            "{{\"at\":{}",
            serde_json::Number::from_f64(t).map_or("0".into(), |n| n.to_string())
        );
        for (name, list) in lists {
            if let Some(list) = list {
                let json = bridge::json_text(list, OBSERVATION).map_err(|b| prefixed(b, name))?;
                text.push_str(&format!(",\"{name}\":{json}"));
            }
        }
        text.push('}');
        let observation: Observation = parse(&text)?;
        if observation.is_unchanged() {
            return Ok(observation);
        }
        let mut scene = self.inner.scene().clone();
        scene.observations = vec![observation.clone()];
        scenario::check(&scene, OBSERVATION).map_err(|e| {
            let mut bad = errors::scenario(&e, true);
            for issue in &mut bad.issues {
                issue.field = issue
                    .field
                    .trim_start_matches("observations[0].")
                    .to_string();
            }
            bad.text = bad.text.replace("observations[0].", "");
            bad
        })?;
        Ok(observation)
    }

    /// The whole-robot samples executed since the last call, and the
    /// gripper commands sent meanwhile.
    fn setpoints(&mut self, py: Python<'_>, start: f64) -> PyResult<Setpoints> {
        let state = self.inner.start_state();
        let names = state.map(|s| s.joint_names.clone()).unwrap_or_default();
        let mut whole = state.map(|s| s.positions.clone()).unwrap_or_default();
        let mut sent = self.sent;
        if sent.entry >= self.inner.executed().len() {
            // The entry under way was dropped (an abort before it moved).
            sent.points = 0;
            sent.events = 0;
        }
        let mut points = Vec::new();
        let mut gripper: Vec<RustGripperEvent> = Vec::new();
        for (k, e) in self.inner.executed().iter().enumerate() {
            let arm = self.robot.arm(&e.arm).map_err(errors::internal)?;
            if k >= sent.entry {
                let (from, events) = match k == sent.entry {
                    true => (sent.points, sent.events),
                    false => (0, 0),
                };
                let samples = &e.trajectory.points;
                for p in &samples[from.min(samples.len())..] {
                    let t = e.start_time + p.time_from_start;
                    // A sub-goal's first sample is where the one before ended.
                    if t > sent.time + 1e-9 {
                        points.push(whole_point(arm, &whole, p, t));
                        sent.time = t;
                    }
                }
                let commands = &e.trajectory.gripper;
                gripper.extend(commands[events.min(commands.len())..].iter().map(|g| {
                    RustGripperEvent {
                        start: e.start_time + g.start,
                        end: e.start_time + g.end,
                        ..*g
                    }
                }));
                (sent.entry, sent.points, sent.events) = (k, samples.len(), commands.len());
            }
            if let Some(end) = e.trajectory.points.last() {
                arm.insert(&mut whole, &end.positions);
            }
        }
        self.sent = sent;
        let gripper = GripperEvent::all(py, &gripper, 0.0)?;
        Setpoints::new(py, names, points, (start, self.inner.clock()), gripper)
    }
}

/// Setpoints handed out so far: up to executed entry `entry`, its first
/// `points` samples and `events` gripper commands; `time` the execution
/// time of the last sample.
#[derive(Debug, Clone, Copy)]
struct Sent {
    entry: usize,
    points: usize,
    events: usize,
    time: f64,
}

/// The whole robot at an arm's sample `p`: `whole` with the arm's joints
/// set (the other joints rest), its time the execution clock `t`.
fn whole_point(
    arm: &afford::kinematics::Arm,
    whole: &[f64],
    p: &TrajectoryPoint,
    t: f64,
) -> TrajectoryPoint {
    let mut point = TrajectoryPoint {
        positions: whole.to_vec(),
        velocities: vec![0.0; whole.len()],
        accelerations: vec![0.0; whole.len()],
        time_from_start: t,
    };
    arm.insert(&mut point.positions, &p.positions);
    arm.insert(&mut point.velocities, &p.velocities);
    arm.insert(&mut point.accelerations, &p.accelerations);
    point
}

/// An execution time afford can run to.
fn check_time(field: &str, t: f64) -> Result<(), Bad> {
    match t.is_finite() && (0.0..=MAX_EXECUTION_TIME_S).contains(&t) {
        true => Ok(()),
        false => Err(Bad::field(
            "",
            field,
            format!("must be an execution time between 0 and {MAX_EXECUTION_TIME_S} s, got {t}"),
        )),
    }
}

/// An error of one of `observe`'s lists, named by the list.
fn prefixed(mut bad: Bad, list: &str) -> Bad {
    for issue in &mut bad.issues {
        issue.field = match issue.field.is_empty() {
            true => list.to_string(),
            false => format!("{list}{}", issue.field),
        };
    }
    let first = bad
        .issues
        .first()
        .map(ToString::to_string)
        .unwrap_or_default();
    bad.text = format!("{OBSERVATION}: {first}");
    bad
}

/// Observation text (afford's own, with the caller's lists) parsed, its
/// errors named by field.
fn parse(text: &str) -> Result<Observation, Bad> {
    let mut de = serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = e.path().to_string();
        let message = e.into_inner().to_string();
        let message = message
            .split(" at line ")
            .next()
            .unwrap_or_default()
            .to_string();
        Bad::field(OBSERVATION, if field == "." { "" } else { &field }, message)
    })
}
