//! `afford bench pipeline`: the whole pipeline on one scenario, repeated,
//! with the time of every stage per sub-goal and the planned task's
//! trajectory time (moving, and with the gripper rests).

use serde::Serialize;

use super::median;
use afford_planner::error::PlanError;
use afford_planner::plan::{Plan, PlanOptions, Planner, StageTimings};
use afford_planner::scenario::Scenario;

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
    /// The arm's moving time over the whole task, seconds: every sub-goal's
    /// trajectory without the rests while the gripper closes and opens.
    pub task_duration_s: f64,
    /// The whole task's trajectory time with the gripper rests, seconds.
    pub task_total_s: f64,
    /// Per planned sub-goal, in order.
    pub subgoal_durations_s: Vec<SubgoalDuration>,
}

/// One sub-goal's trajectory time, seconds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubgoalDuration {
    pub object: String,
    /// Without the gripper rests.
    pub moving: f64,
    /// With them.
    pub total: f64,
}

/// The trajectory times of a plan's sub-goals (those with a trajectory).
pub fn durations(plan: &Plan) -> Vec<SubgoalDuration> {
    plan.subgoals
        .iter()
        .filter_map(|s| {
            let t = s.trajectory.as_ref()?;
            let total = t.points.last().map_or(0.0, |p| p.time_from_start);
            let resting: f64 = t.gripper.iter().map(|g| g.end - g.start).sum();
            Some(SubgoalDuration {
                object: s.object.clone(),
                moving: total - resting,
                total,
            })
        })
        .collect()
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
    let mut subgoal_durations_s = Vec::new();
    for k in 0..runs {
        let started = std::time::Instant::now();
        let plan = planner.plan(scenario)?;
        if k == 0 {
            // Same scenario and seed: every run plans the same trajectories.
            subgoal_durations_s = durations(&plan);
        }
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
        task_duration_s: subgoal_durations_s.iter().map(|d| d.moving).sum(),
        task_total_s: subgoal_durations_s.iter().map(|d| d.total).sum(),
        subgoal_durations_s,
    })
}
