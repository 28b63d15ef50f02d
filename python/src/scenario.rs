//! `afford.Scenario`: a scenario read from a file, from Python data (the
//! scenario format as dicts and lists, validated with a file's errors) or
//! the built-in default, with the folder its relative robot paths start
//! from (the library's rule: the file's folder; for data, `base_dir`,
//! by default the current directory).

use std::path::PathBuf;

use afford::planner::scenario::{self, Format};
use pyo3::prelude::*;

use crate::bridge;
use crate::errors;
use crate::joints;

/// The name errors give to a scenario read from Python data.
pub const DICT_FILE: &str = "<dict>";

/// A scenario: what the overhead camera and the microphone deliver, and
/// the robot. Read with `Scenario.from_file(path)`, `Scenario.from_dict(d)`
/// or `Scenario.default()`; `to_dict()` gives the scenario format back.
#[pyclass(module = "afford", frozen)]
pub struct Scenario {
    pub inner: scenario::Scenario,
    /// Where relative robot paths start.
    pub base_dir: PathBuf,
    /// The file it was read from, for error messages (`<dict>` for data).
    pub file: String,
}

impl Scenario {
    pub fn new(inner: scenario::Scenario, base_dir: PathBuf, file: String) -> Self {
        Self {
            inner,
            base_dir,
            file,
        }
    }
}

#[pymethods]
impl Scenario {
    /// Reads and validates a scenario file (`.yaml`, `.yml` or `.json`). A
    /// scenario without a `name` is named after the file's stem, as
    /// `afford plan` names it; relative robot paths start at the file's
    /// folder. Raises `afford.BadInput` naming the file, the field and what
    /// is wrong.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        errors::guard(|| {
            let mut inner =
                scenario::load(&path).map_err(|e| errors::scenario(&e, true).into_err(py))?;
            if inner.name.is_none() {
                inner.name = Some(afford::plan_json::source_name(Some(&path)));
            }
            Ok(Self::new(
                inner,
                scenario::base_dir(&path),
                path.display().to_string(),
            ))
        })
    }

    /// A scenario from Python data in the scenario format (the dicts and
    /// lists `yaml.safe_load` or `json.load` make of a scenario file),
    /// parsed and validated as a JSON file is: the same `afford.BadInput`
    /// (`field`, `message`) as the file, named `<dict>`. Relative robot
    /// paths start at `base_dir` (default: the current directory).
    #[staticmethod]
    #[pyo3(signature = (data, base_dir = None))]
    fn from_dict(
        py: Python<'_>,
        data: &Bound<'_, PyAny>,
        base_dir: Option<PathBuf>,
    ) -> PyResult<Self> {
        errors::guard(|| {
            let text = bridge::json_text(data, DICT_FILE).map_err(|b| b.into_err(py))?;
            let inner = scenario::parse(&text, Format::Json, DICT_FILE)
                .map_err(|e| errors::scenario(&e, false).into_err(py))?;
            let base_dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
            Ok(Self::new(inner, base_dir, DICT_FILE.to_string()))
        })
    }

    /// The built-in default scenario (`examples/sort-blue-squares.yaml`):
    /// what `afford plan` plans without a file.
    #[staticmethod]
    fn default(py: Python<'_>) -> PyResult<Self> {
        errors::guard(|| {
            let inner = scenario::default_scenario()
                .map_err(|e| errors::scenario(&e, true).into_err(py))?;
            Ok(Self::new(
                inner,
                PathBuf::from("."),
                scenario::DEFAULT_SCENARIO_NAME.to_string(),
            ))
        })
    }

    /// The scenario in the scenario format, as Python data
    /// (`Scenario.from_dict(s.to_dict())` reads it back).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner)
    }

    /// This scenario with the robot's current joint state (`robot.joints`)
    /// from a `sensor_msgs/JointState`-shaped input: a dict (or a message)
    /// with `name` and `position`, every movable joint of the robot named.
    /// `robot.start` is dropped: the state is given in joints.
    fn with_joint_state(&self, py: Python<'_>, joint_state: &Bound<'_, PyAny>) -> PyResult<Self> {
        errors::guard(|| {
            let state = joints::read_joint_state(joint_state).map_err(|b| b.into_err(py))?;
            let mut inner = self.inner.clone();
            inner.robot.joints = Some(state.into_iter().collect());
            inner.robot.start = None;
            let file = self.file.clone();
            scenario::check(&inner, &file).map_err(|e| errors::scenario(&e, true).into_err(py))?;
            Ok(Self::new(inner, self.base_dir.clone(), file))
        })
    }

    /// The scenario's name (`None` when it has none).
    #[getter]
    fn name(&self) -> Option<String> {
        self.inner.name.clone()
    }

    /// The spoken instruction.
    #[getter]
    fn instruction(&self) -> String {
        self.inner.instruction.clone()
    }

    /// `robot.model`: a built-in name or a robot description path.
    #[getter]
    fn robot(&self) -> String {
        self.inner.robot.model.clone()
    }

    /// The folder relative robot paths start from.
    #[getter]
    fn base_dir(&self) -> PathBuf {
        self.base_dir.clone()
    }

    /// The observation timeline (`observations:`), as Python data.
    #[getter]
    fn observations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.inner.observations)
    }

    fn __repr__(&self) -> String {
        format!(
            "Scenario(name={:?}, robot={:?}, instruction={:?})",
            self.inner.name.as_deref().unwrap_or(""),
            self.inner.robot.model,
            self.inner.instruction
        )
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Scenario>()
            .is_ok_and(|o| o.get().inner == self.inner && o.get().base_dir == self.base_dir)
    }
}
