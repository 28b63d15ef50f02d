//! `afford.plan` and what it returns: the plan of every sub-goal (its
//! trajectory as numpy arrays, its gripper events, a JointTrajectory
//! dict), the sub-goals that could not be planned with their typed
//! refusals, and the plan's JSON as `afford plan` writes it.

use afford::planner::timing::TimingSettings;
use afford::planner::trajectory::{GripperCommand, GripperEvent as RustGripperEvent};
use afford::planner::{PlanOptions, Stage, plan::SubgoalPlan, scenario::bounds};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{self, Samples};
use crate::bridge;
use crate::errors::{self, Bad};
use crate::joints;
use crate::record::Refusal;
use crate::scenario::Scenario;

/// Plans every sub-goal of the scenario's instruction: sub-goals, state
/// grids, Contextual Q-learning, tool waypoints, the arm's collision-checked
/// joint path and its timed trajectory (`until` stops after `"grid"`,
/// `"waypoints"` or `"joints"`). The same scenario and seed give the same
/// plan, byte for byte (`plan.to_json()` is what `afford plan --seed SEED
/// --rate RATE_HZ` writes). The GIL is released while planning.
///
/// A sub-goal that cannot be planned is data, not an exception: it is in
/// `plan.unsolved` with its typed `refusal`, and the others still plan.
/// Raises `afford.BadInput` for bad input (an option out of range, an
/// instruction that cannot be carried out, a robot that cannot be loaded
/// or a joint state that does not fit it) and `afford.InternalError` for a
/// defect of afford.
///
///     >>> scenario = afford.Scenario.from_file("examples/sort-blue-squares.yaml")
///     >>> plan = afford.plan(scenario, seed=1, rate_hz=100)
///     >>> s = plan.subgoals[0]
///     >>> s.object, s.goal, s.positions.shape   # (samples, joints), in s.joint_names order
///     ('blue-square-1', 'left box', (354, 7))
#[pyfunction]
#[pyo3(signature = (scenario, seed = 1, rate_hz = 100.0, until = None))]
pub fn plan(
    py: Python<'_>,
    scenario: &Bound<'_, Scenario>,
    seed: u64,
    rate_hz: f64,
    until: Option<&str>,
) -> PyResult<Plan> {
    let s = scenario.get();
    let mut options = options(seed, rate_hz, until).map_err(|b| b.into_err(py))?;
    options.base_dir = s.base_dir.clone();
    let planned = errors::compute(py, || {
        afford::plan_json::plan_or_refusals(&s.inner, &options)
    })?;
    let inner = planned.map_err(|e| errors::plan(py, &e, &s.file))?;
    errors::guard(|| Plan::new(py, inner, options))
}

/// The plan options of `afford.plan`'s arguments.
fn options(seed: u64, rate_hz: f64, until: Option<&str>) -> Result<PlanOptions, Bad> {
    bounds::check_rate(rate_hz).map_err(|m| Bad::field("", "rate_hz", m))?;
    let until = match until.unwrap_or("trajectory") {
        "grid" => Stage::Grid,
        "waypoints" => Stage::Waypoints,
        "joints" => Stage::Joints,
        "trajectory" => Stage::Trajectory,
        other => {
            return Err(Bad::field(
                "",
                "until",
                format!("`{other}` is no stage: grid, waypoints, joints or trajectory"),
            ));
        }
    };
    Ok(PlanOptions {
        seed,
        until,
        timing: TimingSettings {
            rate_hz,
            ..TimingSettings::default()
        },
        ..PlanOptions::default()
    })
}

/// The plan of a whole instruction: `subgoals` in execution order,
/// `unsolved` (each with its typed `refusal`), `skipped` pieces already in
/// their goal; `to_json()` is the JSON `afford plan` writes, `to_dict()`
/// the same as Python data.
#[pyclass(module = "afford", frozen)]
pub struct Plan {
    pub inner: afford::planner::Plan,
    pub options: PlanOptions,
    /// The planned sub-goals.
    #[pyo3(get)]
    subgoals: Vec<Py<Subgoal>>,
    /// The sub-goals that could not be planned.
    #[pyo3(get)]
    unsolved: Vec<Py<Unsolved>>,
}

impl Plan {
    pub fn new(
        py: Python<'_>,
        inner: afford::planner::Plan,
        options: PlanOptions,
    ) -> PyResult<Self> {
        let subgoals = inner
            .subgoals
            .iter()
            .map(|s| Py::new(py, Subgoal::new(py, s)?))
            .collect::<PyResult<_>>()?;
        let unsolved = inner
            .unsolved
            .iter()
            .map(|u| {
                let refusal = Py::new(py, Refusal::new(py, &u.refusal.explained())?)?;
                Py::new(
                    py,
                    Unsolved {
                        object: u.object.clone(),
                        goal: u.goal.clone(),
                        reason: u.reason.clone(),
                        refusal,
                    },
                )
            })
            .collect::<PyResult<_>>()?;
        Ok(Self {
            inner,
            options,
            subgoals,
            unsolved,
        })
    }
}

#[pymethods]
impl Plan {
    /// The scenario's name.
    #[getter]
    fn scenario(&self) -> String {
        self.inner.scenario.clone()
    }

    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed
    }

    /// The controller rate of the trajectories, Hz.
    #[getter]
    fn rate_hz(&self) -> f64 {
        self.options.timing.rate_hz
    }

    /// The last stage that ran: `grid`, `waypoints`, `joints` or `trajectory`.
    #[getter]
    fn until(&self, py: Python<'_>) -> PyResult<String> {
        bridge::serialised(py, &self.inner.until)?.extract()
    }

    /// Pieces the instruction names that already rest in their goal, one
    /// sentence each.
    #[getter]
    fn skipped(&self) -> Vec<String> {
        self.inner.skipped.clone()
    }

    /// The whole robot's joint state at t = 0 (`{"joint_names",
    /// "positions"}`), where the first trajectory starts; `None` before
    /// stage `joints`.
    #[getter]
    fn start_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner.start_state)
    }

    /// Wall-clock seconds of each stage, summed over sub-goals (not
    /// reproducible; not in `to_json()`).
    #[getter]
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let t = &self.inner.timings;
        let out = PyDict::new(py);
        for (name, d) in [
            ("subgoals", t.subgoals),
            ("grid", t.grid),
            ("cql", t.cql),
            ("lift", t.lift),
            ("ik", t.ik),
            ("collision", t.collision),
            ("transit", t.transit),
            ("timing", t.timing),
        ] {
            out.set_item(name, d.as_secs_f64())?;
        }
        Ok(out)
    }

    /// The plan's JSON text, byte for byte what `afford plan` writes.
    fn to_json(&self) -> PyResult<String> {
        afford::plan_json::to_json(&self.inner).map_err(errors::internal)
    }

    /// The plan as Python data: `json.loads(plan.to_json())`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner)
    }

    fn __repr__(&self) -> String {
        format!(
            "Plan(scenario={:?}, subgoals={}, unsolved={})",
            self.inner.scenario,
            self.inner.subgoals.len(),
            self.inner.unsolved.len()
        )
    }
}

/// One planned sub-goal: `object` to `goal` by `arm`; its trajectory
/// (stage `trajectory`) as `positions`, `velocities`, `accelerations` of
/// shape `(samples, joints)` in the order of `joint_names`, and
/// `time_from_start` of shape `(samples,)`; `gripper` its commands.
/// Earlier stages leave what they do not compute `None`.
#[pyclass(module = "afford", frozen)]
pub struct Subgoal {
    inner: SubgoalPlan,
    #[pyo3(get)]
    object: String,
    #[pyo3(get)]
    goal: String,
    #[pyo3(get)]
    arm: Option<String>,
    #[pyo3(get)]
    joint_names: Option<Vec<String>>,
    #[pyo3(get)]
    positions: Option<Py<PyAny>>,
    #[pyo3(get)]
    velocities: Option<Py<PyAny>>,
    #[pyo3(get)]
    accelerations: Option<Py<PyAny>>,
    #[pyo3(get)]
    time_from_start: Option<Py<PyAny>>,
    /// The gripper commands, in order.
    #[pyo3(get)]
    gripper: Vec<Py<GripperEvent>>,
}

impl Subgoal {
    fn new(py: Python<'_>, s: &SubgoalPlan) -> PyResult<Self> {
        let joints = s.joint_names.as_ref().map_or(0, Vec::len);
        let samples = match &s.trajectory {
            Some(t) => Some(arrays::samples(py, &t.points, joints, 0.0)?),
            None => None,
        };
        let gripper = match &s.trajectory {
            Some(t) => GripperEvent::all(py, &t.gripper, 0.0)?,
            None => Vec::new(),
        };
        let (positions, velocities, accelerations, time_from_start) = match samples {
            Some(Samples {
                positions,
                velocities,
                accelerations,
                time,
            }) => (
                Some(positions),
                Some(velocities),
                Some(accelerations),
                Some(time),
            ),
            None => (None, None, None, None),
        };
        Ok(Self {
            inner: s.clone(),
            object: s.object.clone(),
            goal: s.goal.clone(),
            arm: s.arm.clone(),
            joint_names: s.joint_names.clone(),
            positions,
            velocities,
            accelerations,
            time_from_start,
            gripper,
        })
    }
}

#[pymethods]
impl Subgoal {
    /// The grid actions of the learnt policy (`UP`, `LEFT`, ..., `DROP`).
    #[getter]
    fn actions(&self) -> Vec<&'static str> {
        self.inner.actions.iter().map(|a| a.name()).collect()
    }

    /// The trajectory as a `trajectory_msgs/JointTrajectory`-shaped dict:
    /// `joint_names`, `points[]` with `positions`, `velocities`,
    /// `accelerations` and `time_from_start` as `{"sec", "nanosec"}`.
    /// `None` before stage `trajectory`.
    fn to_joint_trajectory<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        match (&self.inner.trajectory, &self.inner.joint_names) {
            (Some(t), Some(names)) => {
                Ok(Some(joints::joint_trajectory(py, names, &t.points, 0.0)?))
            }
            _ => Ok(None),
        }
    }

    /// The sub-goal as in the plan's JSON.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner)
    }

    fn __repr__(&self) -> String {
        let samples = self.inner.trajectory.as_ref().map_or(0, |t| t.points.len());
        format!(
            "Subgoal(object={:?}, goal={:?}, arm={:?}, samples={samples})",
            self.object, self.goal, self.arm
        )
    }
}

/// A sub-goal that could not be planned: `reason` in words, `refusal` typed.
#[pyclass(module = "afford", frozen)]
pub struct Unsolved {
    #[pyo3(get)]
    object: String,
    #[pyo3(get)]
    goal: String,
    /// The sentence a person reads.
    #[pyo3(get)]
    reason: String,
    /// The typed refusal: `refusal.kind` and that kind's fields.
    #[pyo3(get)]
    refusal: Py<Refusal>,
}

#[pymethods]
impl Unsolved {
    fn __repr__(&self) -> String {
        format!(
            "Unsolved(object={:?}, goal={:?}, kind={:?})",
            self.object,
            self.goal,
            self.refusal.get().kind
        )
    }
}

/// A gripper command: `command` (`close` or `open`) sent at `start`, done
/// at `end`, seconds from the start of its sub-goal (the arm rests between).
#[pyclass(module = "afford", frozen)]
pub struct GripperEvent {
    #[pyo3(get)]
    command: &'static str,
    #[pyo3(get)]
    start: f64,
    #[pyo3(get)]
    end: f64,
}

impl GripperEvent {
    /// Every event of a motion, times less `t0`.
    pub fn all(py: Python<'_>, events: &[RustGripperEvent], t0: f64) -> PyResult<Vec<Py<Self>>> {
        events
            .iter()
            .map(|e| {
                let command = match e.command {
                    GripperCommand::Close => "close",
                    GripperCommand::Open => "open",
                };
                Py::new(
                    py,
                    Self {
                        command,
                        start: e.start - t0,
                        end: e.end - t0,
                    },
                )
            })
            .collect()
    }
}

#[pymethods]
impl GripperEvent {
    fn __repr__(&self) -> String {
        format!(
            "GripperEvent(command={:?}, start={}, end={})",
            self.command, self.start, self.end
        )
    }
}
