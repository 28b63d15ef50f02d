//! Trajectory samples as numpy arrays: positions, velocities and
//! accelerations of shape `(samples, joints)`, times of shape `(samples,)`.
//! Each array is made by numpy itself over the samples' float64 bytes
//! (`numpy.frombuffer` on a bytearray: writable, one copy), so the module
//! needs numpy only at run time.

use afford::planner::timing::TrajectoryPoint;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyByteArray;

/// The four arrays of a run of samples.
pub struct Samples {
    pub positions: Py<PyAny>,
    pub velocities: Py<PyAny>,
    pub accelerations: Py<PyAny>,
    pub time: Py<PyAny>,
}

/// `numpy.frombuffer`, imported once.
fn frombuffer(py: Python<'_>) -> PyResult<&Bound<'_, PyAny>> {
    static FROMBUFFER: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    FROMBUFFER
        .get_or_try_init(py, || {
            Ok::<_, PyErr>(py.import("numpy")?.getattr("frombuffer")?.unbind())
        })
        .map(|f| f.bind(py))
}

/// A float64 numpy array of `values` in the given shape.
pub fn array(py: Python<'_>, values: &[f64], shape: &[usize]) -> PyResult<Py<PyAny>> {
    let buffer = PyByteArray::new_with(py, values.len() * 8, |bytes| {
        for (chunk, v) in bytes.chunks_exact_mut(8).zip(values) {
            chunk.copy_from_slice(&v.to_ne_bytes());
        }
        Ok(())
    })?;
    let flat = frombuffer(py)?.call1((buffer, "float64"))?;
    Ok(flat.call_method1("reshape", (shape.to_vec(),))?.unbind())
}

/// One `(samples, joints)` array of the values `pick` takes from each point.
fn matrix(
    py: Python<'_>,
    points: &[TrajectoryPoint],
    joints: usize,
    pick: impl Fn(&TrajectoryPoint) -> &[f64],
) -> PyResult<Py<PyAny>> {
    let mut flat = Vec::with_capacity(points.len() * joints);
    for p in points {
        let row = pick(p);
        if row.len() != joints {
            return Err(crate::errors::internal(format!(
                "a sample with {} values for {joints} joints",
                row.len()
            )));
        }
        flat.extend_from_slice(row);
    }
    array(py, &flat, &[points.len(), joints])
}

/// The arrays of `points`, each time less `t0`.
pub fn samples(
    py: Python<'_>,
    points: &[TrajectoryPoint],
    joints: usize,
    t0: f64,
) -> PyResult<Samples> {
    let time: Vec<f64> = points.iter().map(|p| p.time_from_start - t0).collect();
    Ok(Samples {
        positions: matrix(py, points, joints, |p| &p.positions)?,
        velocities: matrix(py, points, joints, |p| &p.velocities)?,
        accelerations: matrix(py, points, joints, |p| &p.accelerations)?,
        time: array(py, &time, &[points.len()])?,
    })
}
