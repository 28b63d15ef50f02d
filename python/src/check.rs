//! `afford.check`: the independent gate (crate afford-check) over a plan
//! and its scenario, in memory, and optionally the physical replay
//! (rapier3d) — what `afford check [--physics]` does with files. The
//! violations come back typed: class, sub-goal, message and the data a
//! program acts on (joint, body, other, time, sample, distance, margin).

use afford::check::{
    PlanFile, Report as RustReport, Violation as RustViolation, check_plan, read_plan,
};
use afford::collision::replay::ReplayReport;
use afford::kinematics::RobotModel;
use pyo3::prelude::*;
use serde::Serialize;

use crate::bridge;
use crate::errors::{self, Bad};
use crate::plan::Plan;
use crate::scenario::Scenario;

/// The name errors give a plan read from Python data.
const PLAN_DICT: &str = "<plan dict>";

/// Re-checks `plan` against `scenario` with afford's independent checker
/// (its own kinematics and collision geometry, no code shared with the
/// planner): start state, continuity, joint limits and rest, gripper
/// events, tool speed near hands, gripper opening, dense collision checks
/// and placement; `physics=True` adds the physical replay (rapier3d). `plan`
/// is an `afford.Plan` or the plan's JSON as Python data (what `afford
/// plan` writes, `json.load`ed). Returns the `Report`; an empty
/// `report.violations` means it passed. The GIL is released meanwhile.
/// Raises `afford.BadInput` when the robot or the plan data cannot be read.
#[pyfunction]
#[pyo3(signature = (scenario, plan, physics = false))]
pub fn check(
    py: Python<'_>,
    scenario: &Bound<'_, Scenario>,
    plan: &Bound<'_, PyAny>,
    physics: bool,
) -> PyResult<Report> {
    let s = scenario.get();
    let file = plan_file(plan).map_err(|b| b.into_err(py))?;
    let robot = RobotModel::load(&s.inner.robot.model, &s.base_dir)
        .map_err(|e| Bad::field(&s.file, "robot.model", e.to_string()).into_err(py))?;
    let (report, replay) = errors::compute(py, || {
        let mut report = check_plan(&s.inner, &robot, &file);
        let replay = match physics {
            true => {
                let (replay, found) =
                    afford::check::physics::check_physics(&s.inner, &robot, &file);
                report.violations.extend(found.violations);
                replay
            }
            false => None,
        };
        (report, replay)
    })?;
    errors::guard(|| Report::new(py, report, replay))
}

/// The plan as the checker reads it: an `afford.Plan` directly, Python
/// data through the plan file reader (its bounds and errors).
fn plan_file(plan: &Bound<'_, PyAny>) -> Result<PlanFile, Bad> {
    if let Ok(p) = plan.cast::<Plan>() {
        return Ok(PlanFile::from(&p.get().inner));
    }
    let text = bridge::json_text(plan, PLAN_DICT)?;
    read_plan(&text).map_err(|e| Bad::field(PLAN_DICT, "", e.to_string()))
}

/// What the check found: `passed`, `violations`, and with `physics=True`
/// the replay's report (`physics`, as Python data). `to_dict()` is what
/// `afford check --json` prints.
#[pyclass(module = "afford", frozen)]
pub struct Report {
    inner: RustReport,
    replay: Option<ReplayReport>,
    /// Every violation, in the order found.
    #[pyo3(get)]
    violations: Vec<Py<Violation>>,
}

impl Report {
    fn new(py: Python<'_>, inner: RustReport, replay: Option<ReplayReport>) -> PyResult<Self> {
        let violations = inner
            .violations
            .iter()
            .map(|v| Py::new(py, Violation { inner: v.clone() }))
            .collect::<PyResult<_>>()?;
        Ok(Self {
            inner,
            replay,
            violations,
        })
    }
}

/// `afford check --json`'s output.
#[derive(Serialize)]
struct JsonReport<'a> {
    passed: bool,
    violations: &'a [RustViolation],
    #[serde(skip_serializing_if = "Option::is_none")]
    physics: Option<&'a ReplayReport>,
}

#[pymethods]
impl Report {
    /// True when nothing was found.
    #[getter]
    fn passed(&self) -> bool {
        self.inner.passed()
    }

    /// The physical replay's report (`physics=True`), as Python data.
    #[getter]
    fn physics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.replay)
    }

    /// The report as `afford check --json` prints it.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let json = JsonReport {
            passed: self.inner.passed(),
            violations: &self.inner.violations,
            physics: self.replay.as_ref(),
        };
        bridge::serialised(py, &json)
    }

    fn __bool__(&self) -> bool {
        self.inner.passed()
    }

    fn __repr__(&self) -> String {
        format!(
            "Report(passed={}, violations={})",
            self.inner.passed(),
            self.inner.violations.len()
        )
    }
}

/// One violation: `kind` (its class: `penetration`, `margin`, `velocity`,
/// `jerk`, `placement`, `physics`, ...), `subgoal` (`None`: the plan as a
/// whole), `message`, and where the class knows them `joint`, `body`,
/// `other`, `time_s`, `sample`, `distance_m`, `margin_m`, `cases` (else
/// `None`).
#[pyclass(module = "afford", frozen)]
pub struct Violation {
    inner: RustViolation,
}

#[pymethods]
impl Violation {
    /// The class, snake_case (`afford check`'s first column).
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.class.name()
    }
    #[getter]
    fn subgoal(&self) -> Option<usize> {
        self.inner.subgoal
    }
    #[getter]
    fn message(&self) -> String {
        self.inner.message.clone()
    }
    #[getter]
    fn joint(&self) -> Option<String> {
        self.inner.data.joint.clone()
    }
    /// The robot body: a link (`link#k` for its k-th collider) or `held:<object>`.
    #[getter]
    fn body(&self) -> Option<String> {
        self.inner.data.body.clone()
    }
    /// The obstacle, piece or other robot body.
    #[getter]
    fn other(&self) -> Option<String> {
        self.inner.data.other.clone()
    }
    /// Seconds from the start of the sub-goal's trajectory, at the worst case.
    #[getter]
    fn time_s(&self) -> Option<f64> {
        self.inner.data.time_s
    }
    #[getter]
    fn sample(&self) -> Option<usize> {
        self.inner.data.sample
    }
    /// Signed distance at the worst case, m (< 0: inside).
    #[getter]
    fn distance_m(&self) -> Option<f64> {
        self.inner.data.distance_m
    }
    /// The distance that had to be kept, m.
    #[getter]
    fn margin_m(&self) -> Option<f64> {
        self.inner.data.margin_m
    }
    /// How many cases this one violation stands for.
    #[getter]
    fn cases(&self) -> Option<usize> {
        self.inner.data.cases
    }
    /// The violation as `afford check --json` prints it.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner)
    }
    fn __str__(&self) -> String {
        self.inner.to_string()
    }
    fn __repr__(&self) -> String {
        format!(
            "Violation(kind={:?}, subgoal={:?}, message={:?})",
            self.inner.class.name(),
            self.inner.subgoal,
            self.inner.message
        )
    }
}
