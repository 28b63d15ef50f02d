//! `afford.robots()` and `afford.load_robot()`: the built-in robots and a
//! user's robot description, loaded by the rules of a scenario's
//! `robot.model` (a built-in name, a description `.yaml`, or a `.urdf`
//! with its `.yaml` beside it; a relative path from `base_dir`).

use std::path::PathBuf;

use afford::kinematics::{BUILTIN_ROBOTS, RobotModel, RobotSummary};
use pyo3::prelude::*;

use crate::bridge;
use crate::errors::{self, Bad};

/// A robot: `name`, `dof` (the whole robot's), `arms` (each `name`, `dof`,
/// `joints`, `tool_link`, `reach` in m), `joints` (each movable joint with
/// its kind and limits: position, velocity, acceleration, jerk, effort)
/// and `source` (`built-in` or the description file). `to_dict()` is the
/// entry `afford robots --json` prints.
#[pyclass(module = "afford", frozen)]
pub struct Robot {
    summary: RobotSummary,
    joints: Vec<afford::kinematics::Joint>,
    #[pyo3(get)]
    source: String,
}

impl Robot {
    fn of(model: &RobotModel) -> Self {
        Self {
            summary: RobotSummary::of(model),
            joints: model.joints().to_vec(),
            source: model.source().to_string(),
        }
    }
}

#[pymethods]
impl Robot {
    #[getter]
    fn name(&self) -> String {
        self.summary.name.clone()
    }
    /// Degrees of freedom of the whole robot.
    #[getter]
    fn dof(&self) -> usize {
        self.summary.dof
    }
    /// The movable joints' names, in the robot's joint order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.joints.iter().map(|j| j.name.clone()).collect()
    }
    /// Each movable joint with its kind and limits (an unbounded
    /// position limit is `None`).
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.joints)
    }
    /// Each arm: `name`, `dof`, `joints`, `tool_link`, `reach` (m).
    #[getter]
    fn arms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.summary.arms)
    }
    /// The robot as `afford robots --json` lists it.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        bridge::serialised(py, &self.summary)
    }
    fn __repr__(&self) -> String {
        format!(
            "Robot(name={:?}, dof={}, arms={:?})",
            self.summary.name,
            self.summary.dof,
            self.summary
                .arms
                .iter()
                .map(|a| a.name.as_str())
                .collect::<Vec<_>>()
        )
    }
}

/// The robots built into afford (`kuka_iiwa14`, `care_o_bot4`), as
/// `afford robots` lists them.
#[pyfunction]
pub fn robots(py: Python<'_>) -> PyResult<Vec<Robot>> {
    let models = errors::compute(py, || {
        BUILTIN_ROBOTS
            .iter()
            .map(|n| RobotModel::builtin(n))
            .collect::<Result<Vec<_>, _>>()
    })?;
    let models = models.map_err(errors::internal)?;
    Ok(models.iter().map(Robot::of).collect())
}

/// Loads a robot by the rules of a scenario's `robot.model`: a built-in
/// name, a robot description `.yaml`, or a `.urdf` with its `.yaml` beside
/// it; a relative path starts at `base_dir` (default: the current
/// directory). Raises `afford.BadInput` naming the file and what is wrong.
#[pyfunction]
#[pyo3(signature = (model, base_dir = None))]
pub fn load_robot(py: Python<'_>, model: String, base_dir: Option<PathBuf>) -> PyResult<Robot> {
    let base = base_dir.unwrap_or_else(|| PathBuf::from("."));
    let loaded = errors::compute(py, || RobotModel::load(&model, &base))?;
    let model = loaded.map_err(|e| Bad::field("", "robot.model", e.to_string()).into_err(py))?;
    Ok(Robot::of(&model))
}
