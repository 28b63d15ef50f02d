//! The JSON data model between Python and afford. Python dicts, lists,
//! strings, numbers, booleans and None (tuples as lists; numpy arrays and
//! scalars through their `tolist()`) become JSON text, which afford's
//! scenario reader then parses and validates exactly as it reads a JSON
//! file; afford's serialisable results come back as the same
//! Python values `json.loads` would make of their JSON. Input is bounded
//! (nesting, values) before anything is parsed.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Number, Value};

use crate::errors::Bad;

/// Deepest nesting read from Python (a scenario nests five deep).
pub const MAX_DEPTH: usize = 32;
/// Most values read from Python in one call (lists, dicts and scalars).
pub const MAX_VALUES: usize = 1 << 20;

/// Writes `obj` as JSON text, keys in the dict's order; `file` names it
/// in errors, which name the value's path as a scenario file's errors do
/// (`objects[2].box`).
pub fn json_text(obj: &Bound<'_, PyAny>, file: &str) -> Result<String, Bad> {
    let mut writer = Writer {
        out: String::new(),
        path: String::new(),
        budget: MAX_VALUES,
        file,
    };
    writer.write(obj, 0)?;
    Ok(writer.out)
}

struct Writer<'a> {
    out: String,
    path: String,
    budget: usize,
    file: &'a str,
}

impl Writer<'_> {
    fn bad(&self, message: impl Into<String>) -> Bad {
        Bad::field(self.file, &self.path, message)
    }

    fn write(&mut self, obj: &Bound<'_, PyAny>, depth: usize) -> Result<(), Bad> {
        if depth > MAX_DEPTH {
            return Err(self.bad(format!("nested more than {MAX_DEPTH} deep")));
        }
        if self.budget == 0 {
            return Err(self.bad(format!("more than {MAX_VALUES} values")));
        }
        self.budget -= 1;
        if obj.is_none() {
            self.out.push_str("null");
        } else if let Ok(b) = obj.cast::<PyBool>() {
            self.out
                .push_str(if b.is_true() { "true" } else { "false" });
        } else if let Ok(i) = obj.cast::<PyInt>() {
            let text = match (i.extract::<u64>(), i.extract::<i64>()) {
                (Ok(v), _) => v.to_string(),
                (_, Ok(v)) => v.to_string(),
                _ => return Err(self.bad("a whole number too large for afford")),
            };
            self.out.push_str(&text);
        } else if let Ok(f) = obj.cast::<PyFloat>() {
            let v = f.value();
            let number = Number::from_f64(v)
                .ok_or_else(|| self.bad(format!("must be a finite number, got {v}")))?;
            self.out.push_str(&number.to_string());
        } else if let Ok(s) = obj.cast::<PyString>() {
            let text = s.to_cow().map_err(|e| self.bad(e.to_string()))?;
            self.string(&text);
        } else if let Ok(d) = obj.cast::<PyDict>() {
            self.dict(d, depth)?;
        } else if obj.cast::<PyList>().is_ok() || obj.cast::<PyTuple>().is_ok() {
            self.list(obj, depth)?;
        } else {
            self.other(obj, depth)?;
        }
        Ok(())
    }

    fn string(&mut self, text: &str) {
        self.out
            .push_str(&Value::String(text.to_string()).to_string());
    }

    fn dict(&mut self, d: &Bound<'_, PyDict>, depth: usize) -> Result<(), Bad> {
        self.out.push('{');
        for (k, (key, value)) in d.iter().enumerate() {
            let key = key
                .cast::<PyString>()
                .map_err(|_| self.bad(format!("keys must be strings, got a {}", type_name(&key))))?
                .to_cow()
                .map_err(|e| self.bad(e.to_string()))?
                .into_owned();
            if k > 0 {
                self.out.push(',');
            }
            self.string(&key);
            self.out.push(':');
            let len = self.path.len();
            if !self.path.is_empty() {
                self.path.push('.');
            }
            self.path.push_str(&key);
            self.write(&value, depth + 1)?;
            self.path.truncate(len);
        }
        self.out.push('}');
        Ok(())
    }

    fn list(&mut self, obj: &Bound<'_, PyAny>, depth: usize) -> Result<(), Bad> {
        self.out.push('[');
        let items = obj.try_iter().map_err(|e| self.bad(e.to_string()))?;
        for (k, item) in items.enumerate() {
            let item = item.map_err(|e| self.bad(e.to_string()))?;
            if k > 0 {
                self.out.push(',');
            }
            let len = self.path.len();
            self.path.push_str(&format!("[{k}]"));
            self.write(&item, depth + 1)?;
            self.path.truncate(len);
        }
        self.out.push(']');
        Ok(())
    }

    /// numpy arrays and scalars through their `tolist()`; anything else
    /// is refused.
    fn other(&mut self, obj: &Bound<'_, PyAny>, depth: usize) -> Result<(), Bad> {
        if let Ok(tolist) = obj.getattr("tolist") {
            let plain = tolist.call0().map_err(|e| self.bad(e.to_string()))?;
            if !plain.is(obj) {
                return self.write(&plain, depth + 1);
            }
        }
        Err(self.bad(format!(
            "a {} is not afford data (dicts, lists, strings, numbers, booleans, None)",
            type_name(obj)
        )))
    }
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "value".to_string(), |n| n.to_string())
}

/// A JSON value as the Python value `json.loads` makes of it.
pub fn to_py<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.into_pyobject(py)?.into_any(),
            (_, Some(i), _) => i.into_pyobject(py)?.into_any(),
            (_, _, Some(f)) => PyFloat::new(py, f).into_any(),
            _ => return Err(PyTypeError::new_err("a number afford cannot represent")),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, to_py(py, v)?)?;
            }
            dict.into_any()
        }
    })
}

/// A serialisable afford value as Python data (its JSON form).
pub fn serialised<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let json = serde_json::to_value(value).map_err(crate::errors::internal)?;
    to_py(py, &json)
}
