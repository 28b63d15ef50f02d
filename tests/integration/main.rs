//! afford's integration tests: one test binary (ripgrep's layout) with a
//! module per topic. Fixtures live in tests/fixtures/.

mod cases;
mod check;
mod cli;
mod cql_properties;
mod examples;
mod instructions;
mod pipeline;
mod safety;
mod scenario_errors;
mod transits;
mod util;
