//! Scenarios: the data model of a scenario file, reading it (YAML or JSON)
//! and validating it, plus the built-in default scenario and the
//! observation timeline of an execution.

pub mod bounds;
mod load;
mod model;
mod observation;
mod validate;

pub use load::{Format, check, load, parse};
pub use model::*;
pub use observation::{MotionPhase, Observation, PlanPoint};
pub use validate::validate;

/// The embedded default scenario used when `afford plan` gets no file
/// (`examples/sort-blue-squares.yaml`).
pub const DEFAULT_SCENARIO: &str = include_str!("../../../examples/sort-blue-squares.yaml");
/// The name under which the default scenario is reported.
pub const DEFAULT_SCENARIO_NAME: &str = "<built-in>/sort-blue-squares.yaml";

/// Parses the embedded default scenario.
pub fn default_scenario() -> Result<Scenario, crate::error::ScenarioError> {
    parse(DEFAULT_SCENARIO, Format::Yaml, DEFAULT_SCENARIO_NAME)
}
