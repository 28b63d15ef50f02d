//! The module's two exceptions and how afford's errors become them: bad
//! input of any kind is `afford.BadInput` (with the `file`, `field` and
//! `message` of its first issue and every issue in `issues`, the fields
//! named as a scenario file's are); a defect of afford, a Rust panic
//! included, is `afford.InternalError`. A panic is caught where it
//! happens ([`compute`], [`guard`]) and never unwinds into the interpreter.

use std::panic::{AssertUnwindSafe, catch_unwind};

use afford::planner::FieldIssue;
use afford::planner::error::{PlanError, ScenarioError};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyList;

pyo3::create_exception!(
    afford,
    BadInput,
    PyValueError,
    "Bad input: a scenario, an option or an observation afford cannot use.\n\n\
     `str(e)` is the whole message, as the `afford` command prints it; `e.file` names the\n\
     file (or `<dict>`), `e.field` the first field at fault (`objects[2].box`, empty for\n\
     the document as a whole) and `e.message` what is wrong with it; `e.issues` lists\n\
     every `(field, message)`."
);
pyo3::create_exception!(
    afford,
    InternalError,
    PyRuntimeError,
    "A defect of afford (never of the input): please report it with the input that\n\
     caused it. A Rust panic inside afford arrives as this exception."
);

/// A bad input: its file, its issues by field, and the whole message.
pub struct Bad {
    pub file: String,
    pub issues: Vec<FieldIssue>,
    pub text: String,
}

impl Bad {
    /// One issue of one field.
    pub fn field(file: &str, field: &str, message: impl Into<String>) -> Self {
        let issue = FieldIssue::new(field, message);
        let text = match file.is_empty() {
            true => issue.to_string(),
            false => format!("{file}: {issue}"),
        };
        Self {
            file: file.to_string(),
            issues: vec![issue],
            text,
        }
    }

    /// The `afford.BadInput` exception.
    pub fn into_err(self, py: Python<'_>) -> PyErr {
        let err = BadInput::new_err(self.text.clone());
        let value = err.value(py);
        let first = self.issues.first();
        let pairs: Vec<(String, String)> = self
            .issues
            .iter()
            .map(|i| (i.field.clone(), i.message.clone()))
            .collect();
        let set = || -> PyResult<()> {
            value.setattr("file", &self.file)?;
            value.setattr("field", first.map_or("", |i| i.field.as_str()))?;
            value.setattr(
                "message",
                first.map_or(self.text.as_str(), |i| i.message.as_str()),
            )?;
            value.setattr("issues", PyList::new(py, pairs)?)?;
            Ok(())
        };
        match set() {
            Ok(()) => err,
            Err(e) => e,
        }
    }
}

/// A scenario that cannot be read, parsed or validated. A parse error of
/// text afford wrote itself (`from_dict`) has no line worth naming:
/// `located` false leaves it out.
pub fn scenario(e: &ScenarioError, located: bool) -> Bad {
    match e {
        ScenarioError::Parse { file, issue, .. } if !located => Bad {
            file: file.clone(),
            issues: vec![issue.clone()],
            text: format!("{file}: {issue}"),
        },
        ScenarioError::Parse { file, issue, .. } => Bad {
            file: file.clone(),
            issues: vec![issue.clone()],
            text: e.to_string(),
        },
        ScenarioError::Invalid { file, issues } => Bad {
            file: file.clone(),
            issues: issues.clone(),
            text: e.to_string(),
        },
        ScenarioError::Io { file, message } => Bad {
            file: file.clone(),
            issues: vec![FieldIssue::new("", message.clone())],
            text: e.to_string(),
        },
        ScenarioError::Extension { file } => Bad {
            file: file.clone(),
            issues: vec![FieldIssue::new(
                "",
                "the file name must end in .yaml, .yml or .json",
            )],
            text: e.to_string(),
        },
        other => Bad {
            file: String::new(),
            issues: vec![FieldIssue::new("", other.to_string())],
            text: other.to_string(),
        },
    }
}

/// A planning error: bad input (`BadInput`) or a defect (`InternalError`).
/// `Unsolvable` never comes here: a plan reports it as data.
pub fn plan(py: Python<'_>, e: &PlanError, file: &str) -> PyErr {
    let issues = |issues: &[FieldIssue]| Bad {
        file: file.to_string(),
        issues: issues.to_vec(),
        text: format!("{file}: {e}"),
    };
    let bad = match e {
        PlanError::Scenario(s) => scenario(s, true),
        PlanError::Instruction(i) => Bad::field(file, "instruction", i.to_string()),
        PlanError::Robot(message) => Bad::field(file, "robot.model", message.clone()),
        PlanError::RobotState { issues: found, .. } | PlanError::Options { issues: found } => {
            issues(found)
        }
        other => return InternalError::new_err(other.to_string()),
    };
    bad.into_err(py)
}

/// An `InternalError` naming what failed.
pub fn internal(what: impl std::fmt::Display) -> PyErr {
    InternalError::new_err(format!(
        "afford failed internally (a defect of afford): {what}"
    ))
}

/// The text of a panic's payload.
fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    match (
        payload.downcast_ref::<&str>(),
        payload.downcast_ref::<String>(),
    ) {
        (Some(s), _) => s.to_string(),
        (_, Some(s)) => s.clone(),
        _ => "a panic without a message".to_string(),
    }
}

/// Runs `f` without the GIL (other Python threads run meanwhile); a panic
/// in it becomes `InternalError`.
pub fn compute<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|payload| internal(panic_text(payload.as_ref())))
}

/// Runs `f` with the GIL held; a panic in it becomes `InternalError`.
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f))
        .unwrap_or_else(|payload| Err(internal(panic_text(payload.as_ref()))))
}
