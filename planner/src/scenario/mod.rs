//! Scenarios: the data model of a scenario file, reading it (YAML or JSON)
//! and validating it, plus the built-in default scenario and the
//! observation timeline of an execution.

pub mod bounds;
mod load;
mod model;
mod names;
mod observation;
mod validate;

pub use afford_kinematics::open_regular;
pub use load::{Format, check, load, parse};
pub use model::*;
pub use observation::{MotionPhase, Observation, PlanPoint};
pub use validate::validate;

/// The embedded default scenario used when `afford plan` gets no file
/// (`examples/sort-blue-squares.yaml`).
pub const DEFAULT_SCENARIO: &str = include_str!("../../../examples/sort-blue-squares.yaml");
/// The name under which the default scenario is reported.
pub const DEFAULT_SCENARIO_NAME: &str = "<built-in>/sort-blue-squares.yaml";

/// The folder a scenario file's relative paths (`robot.model`) start
/// from: the file's own folder (`.` for a bare file name).
pub fn base_dir(path: &std::path::Path) -> std::path::PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    }
}

impl Scenario {
    /// Every check a scenario file goes through after parsing (ranges,
    /// names, boxes, calibration, size bounds); `Err` lists each issue by
    /// field, named after `name` (or "scenario"). [`crate::Planner::plan`]
    /// runs it, so a scenario built in code gets the errors a file gets.
    pub fn validate(&self) -> Result<(), crate::error::ScenarioError> {
        check(self, self.name.as_deref().unwrap_or("scenario"))
    }
}

/// Parses the embedded default scenario.
pub fn default_scenario() -> Result<Scenario, crate::error::ScenarioError> {
    parse(DEFAULT_SCENARIO, Format::Yaml, DEFAULT_SCENARIO_NAME)
}
