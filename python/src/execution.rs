//! What the monitor reports, as Python objects: its `Verdict` on one
//! observation, the `Event` log, the `Executed` timeline (one entry per
//! sub-goal begun, in the shape of a planned sub-goal) and the
//! `Setpoints` a controller tracks until the next call.

use afford::planner::monitor::{Event as RustEvent, ExecutedSubgoal, Verdict as RustVerdict};
use afford::planner::timing::TrajectoryPoint;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{self, Samples};
use crate::bridge;
use crate::joints;
use crate::plan::GripperEvent;
use crate::record::Reason;

/// A reason as a record (`None` for the verdicts without one).
fn reason(
    py: Python<'_>,
    r: Option<&afford::planner::monitor::Reason>,
) -> PyResult<Option<Py<Reason>>> {
    r.map(|r| Py::new(py, Reason::new(py, r)?)).transpose()
}

/// The monitor's decision on one observation: `kind` (`continue`, `slow`,
/// `stop`, `wait`, `replan`, `new_work`, `abort`), `reason` (typed, for
/// `wait`, `replan` and `abort`) with `message` its words, `scale` (the
/// speed scale of `slow`), `subgoals` (the `(object, goal)` pairs of
/// `new_work`).
#[pyclass(module = "afford", frozen)]
pub struct Verdict {
    #[pyo3(get)]
    kind: &'static str,
    #[pyo3(get)]
    reason: Option<Py<Reason>>,
    #[pyo3(get)]
    message: Option<String>,
    #[pyo3(get)]
    scale: Option<f64>,
    #[pyo3(get)]
    subgoals: Vec<(String, String)>,
}

impl Verdict {
    pub fn new(py: Python<'_>, v: &RustVerdict) -> PyResult<Self> {
        let subgoals = match v {
            RustVerdict::NewWork { subgoals } => subgoals
                .iter()
                .map(|g| (g.object.clone(), g.goal.clone()))
                .collect(),
            _ => Vec::new(),
        };
        Ok(Self {
            kind: v.name(),
            reason: reason(py, v.reason())?,
            message: v.reason().map(ToString::to_string),
            scale: match v {
                RustVerdict::Slow { scale } => Some(*scale),
                _ => None,
            },
            subgoals,
        })
    }
}

#[pymethods]
impl Verdict {
    fn __repr__(&self) -> String {
        match (&self.message, self.scale) {
            (Some(m), _) => format!("Verdict(kind={:?}, message={m:?})", self.kind),
            (None, Some(s)) => format!("Verdict(kind={:?}, scale={s})", self.kind),
            _ => format!("Verdict(kind={:?})", self.kind),
        }
    }
}

/// One entry of the event log: `time` (execution clock, s), `changes` in
/// the scene ("hand hand-1 appeared"), `verdict` (its kind), `brakes`, `reason`,
/// `message`, `scale`, `subgoals` ("object → goal" of new work), and the
/// wall-clock `decision_us` and `replan_ms`. `to_dict()` is the event as
/// `afford run` writes it (without the wall-clock times).
#[pyclass(module = "afford", frozen)]
pub struct Event {
    inner: RustEvent,
    #[pyo3(get)]
    reason: Option<Py<Reason>>,
}

impl Event {
    pub fn new(py: Python<'_>, e: &RustEvent) -> PyResult<Self> {
        Ok(Self {
            inner: e.clone(),
            reason: reason(py, e.reason.as_ref())?,
        })
    }
}

#[pymethods]
impl Event {
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time
    }
    #[getter]
    fn changes(&self) -> Vec<String> {
        self.inner.changes.clone()
    }
    #[getter]
    fn verdict(&self) -> &'static str {
        self.inner.verdict
    }
    /// True when the verdict brakes the robot to rest now.
    #[getter]
    fn brakes(&self) -> bool {
        self.inner.brakes
    }
    #[getter]
    fn message(&self) -> Option<String> {
        self.inner.message.clone()
    }
    #[getter]
    fn scale(&self) -> Option<f64> {
        self.inner.scale
    }
    #[getter]
    fn subgoals(&self) -> Vec<String> {
        self.inner.subgoals.clone()
    }
    /// Wall-clock time of the decision, µs (differs from run to run).
    #[getter]
    fn decision_us(&self) -> f64 {
        self.inner.decision_us
    }
    /// Wall-clock time of the replan, ms (differs from run to run).
    #[getter]
    fn replan_ms(&self) -> Option<f64> {
        self.inner.replan_ms
    }
    /// The event as `afford run` writes it (no wall-clock times).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner)
    }
    fn __repr__(&self) -> String {
        format!(
            "Event(time={}, verdict={:?}, changes={:?})",
            self.inner.time, self.inner.verdict, self.inner.changes
        )
    }
}

/// One executed sub-goal: the motion as it really ran (stops, waits and
/// replanned pieces included): `object`, `goal`, `arm`, `joint_names`,
/// `start_time` (execution clock, s), `positions`, `velocities`,
/// `accelerations` `(samples, joints)` and `time_from_start` `(samples,)`
/// from `start_time`, `gripper` events, `cut_short` (an abort stopped it
/// for good). `to_dict()` is its entry in `afford run`'s `subgoals`.
#[pyclass(module = "afford", frozen)]
pub struct Executed {
    inner: ExecutedSubgoal,
    #[pyo3(get)]
    positions: Py<PyAny>,
    #[pyo3(get)]
    velocities: Py<PyAny>,
    #[pyo3(get)]
    accelerations: Py<PyAny>,
    #[pyo3(get)]
    time_from_start: Py<PyAny>,
    #[pyo3(get)]
    gripper: Vec<Py<GripperEvent>>,
}

impl Executed {
    pub fn new(py: Python<'_>, e: &ExecutedSubgoal) -> PyResult<Self> {
        let Samples {
            positions,
            velocities,
            accelerations,
            time,
        } = arrays::samples(py, &e.trajectory.points, e.joint_names.len(), 0.0)?;
        Ok(Self {
            inner: e.clone(),
            positions,
            velocities,
            accelerations,
            time_from_start: time,
            gripper: GripperEvent::all(py, &e.trajectory.gripper, 0.0)?,
        })
    }
}

#[pymethods]
impl Executed {
    #[getter]
    fn object(&self) -> String {
        self.inner.object.clone()
    }
    #[getter]
    fn goal(&self) -> String {
        self.inner.goal.clone()
    }
    #[getter]
    fn arm(&self) -> String {
        self.inner.arm.clone()
    }
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names.clone()
    }
    #[getter]
    fn start_time(&self) -> f64 {
        self.inner.start_time
    }
    #[getter]
    fn cut_short(&self) -> bool {
        self.inner.cut_short
    }
    /// The executed motion as a `trajectory_msgs/JointTrajectory`-shaped dict.
    fn to_joint_trajectory<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        joints::joint_trajectory(
            py,
            &self.inner.joint_names,
            &self.inner.trajectory.points,
            0.0,
        )
    }
    /// The entry as in `afford run`'s `subgoals`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner)
    }
    fn __repr__(&self) -> String {
        format!(
            "Executed(object={:?}, arm={:?}, start_time={}, samples={})",
            self.inner.object,
            self.inner.arm,
            self.inner.start_time,
            self.inner.trajectory.points.len()
        )
    }
}

/// What the controller tracks until the next call: the whole robot's
/// joint states (`joint_names` in the robot's order; the arm at rest
/// holds its position) at each controller period executed since the last
/// call, `time` on the execution clock (s), from `start` (the clock before
/// the call) to `end`; `gripper` the commands sent meanwhile (times on the
/// execution clock). Empty when nothing moved (the run ended).
#[pyclass(module = "afford", frozen)]
pub struct Setpoints {
    points: Vec<TrajectoryPoint>,
    #[pyo3(get)]
    joint_names: Vec<String>,
    #[pyo3(get)]
    positions: Py<PyAny>,
    #[pyo3(get)]
    velocities: Py<PyAny>,
    #[pyo3(get)]
    accelerations: Py<PyAny>,
    #[pyo3(get)]
    time: Py<PyAny>,
    #[pyo3(get)]
    start: f64,
    #[pyo3(get)]
    end: f64,
    #[pyo3(get)]
    gripper: Vec<Py<GripperEvent>>,
}

impl Setpoints {
    /// `points` are whole-robot samples, their `time_from_start` the
    /// execution clock.
    pub fn new(
        py: Python<'_>,
        joint_names: Vec<String>,
        points: Vec<TrajectoryPoint>,
        (start, end): (f64, f64),
        gripper: Vec<Py<GripperEvent>>,
    ) -> PyResult<Self> {
        let Samples {
            positions,
            velocities,
            accelerations,
            time,
        } = arrays::samples(py, &points, joint_names.len(), 0.0)?;
        Ok(Self {
            points,
            joint_names,
            positions,
            velocities,
            accelerations,
            time,
            start,
            end,
            gripper,
        })
    }
}

#[pymethods]
impl Setpoints {
    /// The setpoints as a `trajectory_msgs/JointTrajectory`-shaped dict,
    /// `time_from_start` from `start`.
    fn to_joint_trajectory<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        joints::joint_trajectory(py, &self.joint_names, &self.points, self.start)
    }
    fn __len__(&self) -> usize {
        self.points.len()
    }
    fn __repr__(&self) -> String {
        format!(
            "Setpoints(start={}, end={}, samples={})",
            self.start,
            self.end,
            self.points.len()
        )
    }
}
