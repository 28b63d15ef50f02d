//! # afford-bench
//!
//! Benchmarks behind `afford bench`: seeded scene generation and the CQL
//! experiment that reproduces the paper's Table 1 (CQL against QL, measured
//! against the BFS oracle), the whole pipeline stage by stage, the timing
//! stage on random and example paths, and the
//! safety campaign (random scenes for both robots, planned and re-checked),
//! the transit campaign (Care-O-bot sub-goals alone against chained) and
//! the planned routes against the shortest any-angle paths.
//!
//! Built over the planner's public API (`afford-planner`), with the
//! independent check's feasibility probe (`afford-check`) for the safety
//! campaign's refusals; neither depends on this crate.

pub mod adversary;
pub mod cql;
pub mod free_poses;
pub mod generator;
pub mod monitor;
pub mod pipeline;
pub mod planning_time;
pub mod refusal;
pub mod routes;
pub mod safety;
pub mod scenes;
pub mod structural;
pub mod timing;
pub mod transits;
pub mod visibility;

/// Median of a sample (mean of the two middle values); 0 when empty.
pub fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

/// Arithmetic mean; 0 when empty.
pub fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}
