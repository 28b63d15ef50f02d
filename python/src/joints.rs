//! The ROS 2 message shapes: a `sensor_msgs/JointState` in (`name`,
//! `position`: a dict or the message itself) and a
//! `trajectory_msgs/JointTrajectory` out (`joint_names`, `points[]` with
//! `positions`, `velocities`, `accelerations` and `time_from_start` as a
//! `builtin_interfaces/Duration`, `{sec, nanosec}`), so a ROS 2 node
//! converts either with a line or two.

use afford::check::MAX_JOINTS;
use afford::planner::timing::TrajectoryPoint;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyMapping};

use crate::errors::Bad;

/// The name errors give a joint state read from Python.
const FIELD: &str = "joint_state";

/// `name` and `position` of a JointState-shaped dict or message, as
/// (joint, position) pairs; each name once, every position finite.
pub fn read_joint_state(obj: &Bound<'_, PyAny>) -> Result<Vec<(String, f64)>, Bad> {
    let bad = |field: &str, message: String| Bad::field("", &format!("{FIELD}{field}"), message);
    let get = |key: &str| -> Result<Bound<'_, PyAny>, Bad> {
        let found = match obj.cast::<PyMapping>() {
            Ok(m) => m.get_item(key).ok(),
            Err(_) => obj.getattr(key).ok(),
        };
        found.ok_or_else(|| bad("", format!("a joint state needs `{key}` (and `name`, `position` as in sensor_msgs/JointState)")))
    };
    let names: Vec<String> = get("name")?
        .extract()
        .map_err(|_| bad(".name", "must be a list of joint names".into()))?;
    let positions: Vec<f64> = get("position")?
        .extract()
        .map_err(|_| bad(".position", "must be a list of numbers".into()))?;
    if names.len() > MAX_JOINTS {
        return Err(bad(
            ".name",
            format!("{} joints; a robot has at most {MAX_JOINTS}", names.len()),
        ));
    }
    if names.len() != positions.len() {
        return Err(bad(
            ".position",
            format!(
                "{} positions for {} names: give one per joint",
                positions.len(),
                names.len()
            ),
        ));
    }
    for (k, name) in names.iter().enumerate() {
        if names[..k].contains(name) {
            return Err(bad(
                &format!(".name[{k}]"),
                format!("`{name}` is named twice"),
            ));
        }
        if !positions[k].is_finite() {
            return Err(bad(
                &format!(".position[{k}]"),
                format!("must be a finite number, got {}", positions[k]),
            ));
        }
    }
    Ok(names.into_iter().zip(positions).collect())
}

/// A time in seconds as a `builtin_interfaces/Duration`: whole seconds and
/// the nanoseconds past them (0 ≤ nanosec < 10⁹).
pub fn duration(seconds: f64) -> (i64, u32) {
    let total = (seconds * 1e9).round() as i64;
    (
        total.div_euclid(1_000_000_000),
        total.rem_euclid(1_000_000_000) as u32,
    )
}

/// A `trajectory_msgs/JointTrajectory`-shaped dict of `points`, their times
/// less `t0` seconds.
pub fn joint_trajectory<'py>(
    py: Python<'py>,
    joint_names: &[String],
    points: &[TrajectoryPoint],
    t0: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("joint_names", PyList::new(py, joint_names)?)?;
    let list = PyList::empty(py);
    for p in points {
        let point = PyDict::new(py);
        point.set_item("positions", PyList::new(py, &p.positions)?)?;
        point.set_item("velocities", PyList::new(py, &p.velocities)?)?;
        point.set_item("accelerations", PyList::new(py, &p.accelerations)?)?;
        let (sec, nanosec) = duration(p.time_from_start - t0);
        let time = PyDict::new(py);
        time.set_item("sec", sec)?;
        time.set_item("nanosec", nanosec)?;
        point.set_item("time_from_start", time)?;
        list.append(point)?;
    }
    out.set_item("points", list)?;
    Ok(out)
}
