//! `afford bench pipeline`: the whole pipeline on one scenario, repeated,
//! with the time of every stage per sub-goal.

use serde::Serialize;

use super::median;
use crate::error::PlanError;
use crate::plan::{PlanOptions, Planner, StageTimings};
use crate::scenario::Scenario;

/// Median milliseconds per sub-goal of each stage.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StageMedians {
    pub subgoals: f64,
    pub grid: f64,
    pub cql: f64,
    pub lift: f64,
    pub ik: f64,
    pub collision: f64,
    pub timing: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PipelineBenchReport {
    pub scenario: String,
    pub runs: usize,
    pub subgoals: usize,
    /// Median over runs of the whole plan's wall time divided by its sub-goals.
    pub median_ms_per_subgoal: f64,
    pub stages_ms: StageMedians,
}

/// Plans `scenario` `runs` times with `options`; `progress` is called after each run.
pub fn run(
    scenario: &Scenario,
    options: &PlanOptions,
    runs: usize,
    mut progress: impl FnMut(usize),
) -> Result<PipelineBenchReport, PlanError> {
    let planner = Planner::new(options.clone());
    let mut per_run: Vec<(f64, StageTimings, usize)> = Vec::with_capacity(runs);
    for k in 0..runs {
        let started = std::time::Instant::now();
        let plan = planner.plan(scenario)?;
        let n = plan.subgoals.len().max(1);
        per_run.push((
            started.elapsed().as_secs_f64() * 1e3 / n as f64,
            plan.timings,
            n,
        ));
        progress(k + 1);
    }
    let per_subgoal = |f: fn(&StageTimings) -> std::time::Duration| {
        let values: Vec<f64> = per_run
            .iter()
            .map(|(_, t, n)| f(t).as_secs_f64() * 1e3 / *n as f64)
            .collect();
        median(&values)
    };
    Ok(PipelineBenchReport {
        scenario: scenario.name.clone().unwrap_or_default(),
        runs,
        subgoals: per_run.first().map_or(0, |r| r.2),
        median_ms_per_subgoal: median(&per_run.iter().map(|r| r.0).collect::<Vec<_>>()),
        stages_ms: StageMedians {
            subgoals: per_subgoal(|t| t.subgoals),
            grid: per_subgoal(|t| t.grid),
            cql: per_subgoal(|t| t.cql),
            lift: per_subgoal(|t| t.lift),
            ik: per_subgoal(|t| t.ik),
            collision: per_subgoal(|t| t.collision),
            timing: per_subgoal(|t| t.timing),
        },
    })
}
