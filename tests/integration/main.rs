//! afford's integration tests: one test binary (ripgrep's layout) with a
//! module per topic. Fixtures live in tests/fixtures/.

mod api;
mod bad_input;
mod cases;
mod check;
mod cli;
mod cql_properties;
mod doc_links;
mod examples;
mod export_mdp;
mod false_refusals;
mod features;
mod hand_check;
mod instructions;
mod joint_values;
mod monitor;
mod monitor_people;
mod names;
mod packing;
mod physics;
mod pipeline;
mod plan_output;
mod refusals;
mod robots_init;
mod safety;
mod scenario_errors;
mod streams;
mod toy_robot;
mod transits;
mod util;
