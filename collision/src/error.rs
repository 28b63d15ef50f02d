//! Errors of the collision crate: bad scene specs, bad paths, bad fixtures.
//! A collision found is an answer ([`crate::PathVerdict`]), never an error.

use std::path::PathBuf;

/// Misuse or bad input. Every variant names the field (and file) at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CollisionError {
    /// A scene spec field is out of range (non-finite, negative size, ...).
    #[error("scene: {field}: {problem}")]
    Scene { field: String, problem: String },
    /// A path is malformed (too short, wrong joint count, non-finite value).
    #[error("path: {field}: {problem}")]
    Path { field: String, problem: String },
    /// A setting is out of range (the field names the option).
    #[error("{field}: {problem}")]
    Settings { field: String, problem: String },
    /// The robot model could not be used.
    #[error("robot: {0}")]
    Kinematics(#[from] afford_kinematics::KinematicsError),
    /// A fixture file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A fixture file does not parse.
    #[error("{}: malformed fixture: {message}", file.display())]
    FixtureSyntax { file: PathBuf, message: String },
    /// A fixture field is inconsistent.
    #[error("{}: {field}: {problem}", file.display())]
    Fixture {
        file: PathBuf,
        field: String,
        problem: String,
    },
}

pub(crate) fn scene_err(field: impl Into<String>, problem: impl Into<String>) -> CollisionError {
    CollisionError::Scene {
        field: field.into(),
        problem: problem.into(),
    }
}

pub(crate) fn path_err(field: impl Into<String>, problem: impl Into<String>) -> CollisionError {
    CollisionError::Path {
        field: field.into(),
        problem: problem.into(),
    }
}
