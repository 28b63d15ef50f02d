//! `afford`, the Python module: afford's library operations — reading
//! scenarios, planning, the independent check, the valid-policy detector
//! online, the robots — on Python data and numpy arrays. Bad input raises
//! `afford.BadInput`, a defect `afford.InternalError`; a Rust panic never
//! reaches the interpreter ([`errors`]). The GIL is released while afford
//! computes.

use pyo3::prelude::*;

mod arrays;
mod bridge;
mod check;
mod errors;
mod execution;
mod joints;
mod monitor;
mod plan;
mod record;
mod robots;
mod scenario;

/// Panics inside afford's panic guard: what a defect of afford looks like
/// from Python (`afford.InternalError`), for the tests.
#[pyfunction]
fn _panic(py: Python<'_>, message: String) -> PyResult<()> {
    errors::compute(py, move || panic!("{message}"))
}

#[pymodule]
fn _afford(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("BadInput", py.get_type::<errors::BadInput>())?;
    m.add("InternalError", py.get_type::<errors::InternalError>())?;
    m.add_class::<scenario::Scenario>()?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_class::<plan::Plan>()?;
    m.add_class::<plan::Subgoal>()?;
    m.add_class::<plan::Unsolved>()?;
    m.add_class::<plan::GripperEvent>()?;
    m.add_class::<record::Refusal>()?;
    m.add_class::<record::Reason>()?;
    m.add_function(wrap_pyfunction!(check::check, m)?)?;
    m.add_class::<check::Report>()?;
    m.add_class::<check::Violation>()?;
    m.add_class::<monitor::Monitor>()?;
    m.add_class::<execution::Verdict>()?;
    m.add_class::<execution::Event>()?;
    m.add_class::<execution::Executed>()?;
    m.add_class::<execution::Setpoints>()?;
    m.add_function(wrap_pyfunction!(robots::robots, m)?)?;
    m.add_function(wrap_pyfunction!(robots::load_robot, m)?)?;
    m.add_class::<robots::Robot>()?;
    m.add(
        "CAMERA_PERIOD_S",
        afford::planner::monitor::timeline::CAMERA_PERIOD_S,
    )?;
    m.add(
        "MAX_EXECUTION_TIME_S",
        afford::planner::scenario::bounds::MAX_EXECUTION_TIME_S,
    )?;
    m.add_function(wrap_pyfunction!(_panic, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
