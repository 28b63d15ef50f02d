//! Typed errors of the planner crate. Bad input (a scenario file, an
//! instruction) is an `Err`; a task the learner cannot solve is reported in
//! the plan's status, by sub-goal name, next to the sub-goals that planned.

use std::fmt;

use serde::Serialize;

mod refusal;

pub use refusal::{
    ArmFailure, Explained, HitPlace, Refusal, TransitFailure, phase_name, serialize_explained,
};

/// One problem with one field of a scenario, e.g. `objects[2].box`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldIssue {
    /// Path of the field, `objects[2].box`; empty for the document itself.
    pub field: String,
    pub message: String,
}

impl FieldIssue {
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for FieldIssue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.field, self.message)
        }
    }
}

/// A scenario file could not be read, parsed or validated.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    #[error("{file}: cannot read the file: {message}")]
    Io { file: String, message: String },
    #[error("{file}: unknown scenario format: the file name must end in .yaml, .yml or .json")]
    Extension { file: String },
    #[error("{file}{}: {issue}", location(*line, *column))]
    Parse {
        file: String,
        issue: FieldIssue,
        line: Option<u64>,
        column: Option<u64>,
    },
    #[error("{file}: invalid scenario:{}", issues.iter().map(|i| format!("\n  - {i}")).collect::<String>())]
    Invalid {
        file: String,
        issues: Vec<FieldIssue>,
    },
}

fn location(line: Option<u64>, column: Option<u64>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!(":{l}:{c}"),
        (Some(l), None) => format!(":{l}"),
        _ => String::new(),
    }
}

/// The instruction cannot be turned into sub-goals. Its message always starts
/// with "Not executable instruction".
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("Not executable instruction: {reason}")]
pub struct InstructionError {
    pub reason: String,
}

impl InstructionError {
    pub fn new(reason: impl Into<String>) -> Self {
        Self {
            reason: reason.into(),
        }
    }
}

/// Planning stopped before any sub-goal could be attempted.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Instruction(#[from] InstructionError),
    /// The scenario's robot could not be loaded.
    #[error("robot: {0}")]
    Robot(String),
    /// The scenario's robot state (`robot.joints`, `robot.start`) does not
    /// fit the robot: bad input, each issue names its field.
    #[error("the robot's state does not fit {robot}:{}", issues.iter().map(|i| format!("\n  - {i}")).collect::<String>())]
    RobotState {
        robot: String,
        issues: Vec<FieldIssue>,
    },
    /// The plan options are out of range; each issue names its field.
    #[error("invalid plan options:{}", issues.iter().map(|i| format!("\n  - {i}")).collect::<String>())]
    Options { issues: Vec<FieldIssue> },
    /// Every sub-goal failed; each reason is listed by sub-goal
    /// (`reasons[k]` is "object → goal: message" of `unsolved[k]`).
    #[error("no sub-goal could be planned:{}", reasons.iter().map(|r| format!("\n  - {r}")).collect::<String>())]
    Unsolvable {
        reasons: Vec<String>,
        unsolved: Vec<UnsolvedSubgoal>,
        /// Wall time spent on each sub-goal (as [`crate::plan::StageTimings::per_subgoal`]).
        subgoal_times: Vec<std::time::Duration>,
    },
}

/// A sub-goal that could not be planned: `reason` is the message a person
/// reads, `refusal` the typed kind and data a program branches on (JSON
/// `{"kind": ..., ...fields, "message": ...}`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnsolvedSubgoal {
    pub object: String,
    pub goal: String,
    pub reason: String,
    #[serde(serialize_with = "serialize_explained")]
    pub refusal: Refusal,
}
