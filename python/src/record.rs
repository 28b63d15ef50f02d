//! Typed records: a refusal of a sub-goal and a reason of the monitor are
//! each one kind (`record.kind`, the snake_case name afford's JSON gives)
//! with that kind's own fields, read as attributes (`refusal.goal`,
//! `reason.hand`); `to_dict()` is the record's JSON form.

use pyo3::exceptions::PyAttributeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::bridge;

/// A record's kind and fields from its JSON form (`{"kind": ..., ...}`).
fn fields<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<(String, Bound<'py, PyDict>)> {
    let data = bridge::serialised(py, value)?;
    let dict = data
        .cast_into::<PyDict>()
        .map_err(|e| crate::errors::internal(e.to_string()))?;
    let kind: String = match dict.get_item("kind")? {
        Some(k) => k.extract()?,
        None => String::new(),
    };
    Ok((kind, dict))
}

macro_rules! record {
    ($name:ident, $doc:literal) => {
        #[doc = $doc]
        #[pyclass(module = "afford", frozen)]
        pub struct $name {
            /// The kind, snake_case as in afford's JSON.
            #[pyo3(get)]
            pub kind: String,
            fields: Py<PyDict>,
        }

        impl $name {
            pub fn new<T: serde::Serialize>(py: Python<'_>, value: &T) -> PyResult<Self> {
                let (kind, dict) = fields(py, value)?;
                Ok(Self {
                    kind,
                    fields: dict.unbind(),
                })
            }
        }

        #[pymethods]
        impl $name {
            fn __getattr__(&self, py: Python<'_>, name: &str) -> PyResult<Py<PyAny>> {
                match self.fields.bind(py).get_item(name)? {
                    Some(v) => Ok(v.unbind()),
                    None => Err(PyAttributeError::new_err(format!(
                        "a `{}` {} has no field `{name}`",
                        self.kind,
                        stringify!($name)
                    ))),
                }
            }

            /// The field names of this kind (`kind` included).
            fn fields(&self, py: Python<'_>) -> PyResult<Vec<String>> {
                self.fields.bind(py).keys().extract()
            }

            /// The record as afford's JSON has it.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                self.fields.bind(py).copy()
            }

            fn __eq__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
                match other.cast::<$name>() {
                    Ok(o) => self.fields.bind(py).eq(o.get().fields.bind(py)),
                    Err(_) => Ok(false),
                }
            }

            fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
                let mut parts = Vec::new();
                for (k, v) in self.fields.bind(py).iter() {
                    parts.push(format!("{}={}", k.str()?, v.repr()?));
                }
                Ok(format!("{}({})", stringify!($name), parts.join(", ")))
            }
        }
    };
}

record!(
    Refusal,
    "Why one sub-goal could not be planned: `kind` (`goal_full`, `no_route`, ...) and that\n\
     kind's fields as attributes (`refusal.goal`, `refusal.blocked_cells`); `message` is the\n\
     sentence a person reads. `fields()` lists them, `to_dict()` is the JSON form."
);
record!(
    Reason,
    "Why the monitor waits, replans or aborts: `kind` (`hand_on_route`, `goal_moved`,\n\
     `target_moved`, `blocked`, `target_gone`, `goal_gone`, `waited_too_long`, `no_plan`) and\n\
     that kind's fields as attributes (`reason.hand`, `reason.subgoal`)."
);
