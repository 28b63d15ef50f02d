//! `afford bench cql`: CQL and plain QL on seeded scenes, measured against the
//! BFS oracle, summarised like the paper's Table 1; and the export of the
//! same scenes' MDPs (`afford export-mdp --generated`) for the deep-RL rows.

use std::time::Instant;

use serde::Serialize;

use super::{generator, mean, median};
use afford_planner::cql::{ContextualQLearner, LearnedPlan, LearnerSettings, QLearner};
use afford_planner::export::{ExportMeta, LearnerRun, LearnerStats, MdpExport};
use afford_planner::grid::{GridRequest, StateGrid};
use afford_planner::oracle;
use afford_planner::scenario::Scenario;
use afford_planner::task::GridTask;

/// Benchmark parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct CqlBenchConfig {
    pub scenarios: usize,
    pub seed: u64,
    pub settings: LearnerSettings,
}

impl Default for CqlBenchConfig {
    fn default() -> Self {
        Self {
            scenarios: 100,
            seed: 1,
            settings: LearnerSettings::default(),
        }
    }
}

/// One learner's row of the table.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct LearnerSummary {
    /// Share of solvable scenes whose greedy plan completes the task.
    pub success_rate: f64,
    pub mean_steps: f64,
    pub median_steps: f64,
    pub mean_ms: f64,
    pub median_ms: f64,
    /// Mean over solved scenes of plan length / optimal length.
    pub mean_length_over_optimal: f64,
}

/// The whole table.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CqlBenchReport {
    pub scenarios: usize,
    /// Scenes the BFS oracle can solve; rates are over these.
    pub solvable: usize,
    /// CQL with afford's schedule ([`LearnerSettings::default`]).
    pub cql: LearnerSummary,
    /// Plain QL with the same settings.
    pub ql: LearnerSummary,
    /// CQL with the authors' literal schedule ([`LearnerSettings::paper`]).
    pub cql_paper: LearnerSummary,
    /// Plain QL with the authors' literal schedule.
    pub ql_paper: LearnerSummary,
    /// Grid sizes seen, cells: smallest and largest n·m.
    pub cells_min: usize,
    pub cells_max: usize,
}

/// One learner's raw results.
#[derive(Default)]
struct Samples {
    solved: usize,
    steps: Vec<f64>,
    ms: Vec<f64>,
    ratio: Vec<f64>,
}

impl Samples {
    fn record(&mut self, plan: &LearnedPlan, ms: f64, optimal: usize) {
        self.steps.push(plan.training_steps as f64);
        self.ms.push(ms);
        if plan.solved {
            self.solved += 1;
            self.ratio.push(plan.actions.len() as f64 / optimal as f64);
        }
    }

    fn summary(&self, solvable: usize) -> LearnerSummary {
        LearnerSummary {
            success_rate: if solvable == 0 {
                0.0
            } else {
                self.solved as f64 / solvable as f64
            },
            mean_steps: mean(&self.steps),
            median_steps: median(&self.steps),
            mean_ms: mean(&self.ms),
            median_ms: median(&self.ms),
            mean_length_over_optimal: mean(&self.ratio),
        }
    }
}

/// Runs the benchmark; `progress` is called after each scene.
pub fn run(config: &CqlBenchConfig, mut progress: impl FnMut(usize)) -> CqlBenchReport {
    let learners = [
        Learner::Contextual(ContextualQLearner::new(config.settings.clone())),
        Learner::Plain(QLearner::new(config.settings.clone())),
        Learner::Contextual(ContextualQLearner::new(LearnerSettings::paper())),
        Learner::Plain(QLearner::new(LearnerSettings::paper())),
    ];
    let mut samples: [Samples; 4] = Default::default();
    let mut report = CqlBenchReport {
        scenarios: config.scenarios,
        cells_min: usize::MAX,
        ..Default::default()
    };
    for index in 0..config.scenarios {
        let (_, grid) = generated_grid(config.seed, index);
        report.cells_min = report.cells_min.min(grid.len());
        report.cells_max = report.cells_max.max(grid.len());
        let task = GridTask::new(grid.clone());
        if let Some(optimal) = oracle::optimal_length(&task) {
            report.solvable += 1;
            let seed = learner_seed(config.seed, index);
            for (learner, sample) in learners.iter().zip(&mut samples) {
                let (plan, ms) = timed(|| learner.learn(&GridTask::new(grid.clone()), seed));
                sample.record(&plan, ms, optimal);
            }
        }
        progress(index + 1);
    }
    [report.cql, report.ql, report.cql_paper, report.ql_paper] =
        samples.map(|s| s.summary(report.solvable));
    report
}

/// Scene `index` of the seeded series `seed` and its grid: the one object
/// into the one goal, the gripper at `robot.start`.
pub fn generated_grid(seed: u64, index: usize) -> (Scenario, StateGrid) {
    let scene = generator::scene(seed, index);
    let grid = first_grid(&scene);
    (scene, grid)
}

/// The grid of a generated scene (its one object into its one goal, the
/// gripper at `robot.start`, which the generator always gives).
pub fn first_grid(scene: &Scenario) -> StateGrid {
    let request = GridRequest {
        object: 0,
        goal: 0,
        gripper: scene
            .robot
            .start
            .expect("generated scenes give robot.start"),
    };
    StateGrid::build(scene, request)
}

/// The learners' seed on scene `index` of the series `seed`.
pub fn learner_seed(seed: u64, index: usize) -> u64 {
    seed.wrapping_add(index as u64)
}

/// The MDP export of generated scene `index` (`afford export-mdp
/// --generated`), with afford's CQL plan learned exactly as this benchmark
/// does; with `stats`, also the training steps and times of both learners
/// with the scene's settings and with the authors' schedule (the CQL run
/// measured is the one exported).
pub fn generated_export(seed: u64, index: usize, stats: bool) -> MdpExport {
    let (scene, grid) = generated_grid(seed, index);
    let meta = ExportMeta {
        name: scene.name.clone().unwrap_or_default(),
        object: scene.objects[0].name.clone(),
        goal: scene.goals[0].name.clone(),
        seed: learner_seed(seed, index),
    };
    let settings = &scene.learner;
    let cql = Learner::Contextual(ContextualQLearner::new(settings.clone()));
    let (plan, cql_run) = measured(&cql, &grid, meta.seed);
    let mut export = MdpExport::of(meta, &GridTask::new(grid.clone()), settings, &plan);
    if stats {
        let run = |learner: Learner| measured(&learner, &grid, export.seed).1;
        export.learners = Some(LearnerStats {
            cql: cql_run,
            ql: run(Learner::Plain(QLearner::new(settings.clone()))),
            cql_paper: run(Learner::Contextual(ContextualQLearner::new(
                LearnerSettings::paper(),
            ))),
            ql_paper: run(Learner::Plain(QLearner::new(LearnerSettings::paper()))),
        });
    }
    export
}

/// One training run on a fresh task built from `grid`, with its wall and
/// CPU time (the task's tables included, as in the benchmark).
fn measured(learner: &Learner, grid: &StateGrid, seed: u64) -> (LearnedPlan, LearnerRun) {
    let cpu = thread_cpu_ms();
    let (plan, wall_ms) = timed(|| learner.learn(&GridTask::new(grid.clone()), seed));
    let cpu_ms = cpu.zip(thread_cpu_ms()).map(|(a, b)| b - a);
    let run = LearnerRun {
        plan: (&plan).into(),
        wall_ms,
        cpu_ms,
    };
    (plan, run)
}

/// CPU time of the calling thread so far, milliseconds
/// (`CLOCK_THREAD_CPUTIME_ID`, Linux); `None` elsewhere.
fn thread_cpu_ms() -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
        Some(t.tv_sec as f64 * 1e3 + t.tv_nsec as f64 / 1e6)
    }
    #[cfg(not(target_os = "linux"))]
    None
}

enum Learner {
    Contextual(ContextualQLearner),
    Plain(QLearner),
}

impl Learner {
    fn learn(&self, task: &GridTask, seed: u64) -> LearnedPlan {
        match self {
            Learner::Contextual(l) => l.learn(task, seed),
            Learner::Plain(l) => l.learn(task, seed),
        }
    }
}

/// Runs `f`, returning its value and the wall time in milliseconds. The task
/// is built inside `f`, so the time covers affordances and the initial table.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let value = f();
    (value, t.elapsed().as_secs_f64() * 1e3)
}

impl CqlBenchReport {
    /// The table as text, like the paper's Table 1.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{} scenes ({} solvable by the BFS oracle), grids of {}..{} cells\n\n",
            self.scenarios, self.solvable, self.cells_min, self.cells_max
        );
        out.push_str("algorithm            success  mean steps  median steps  mean ms  median ms  length/optimal\n");
        let rows = [
            ("CQL", &self.cql),
            ("QL", &self.ql),
            ("CQL, paper schedule", &self.cql_paper),
            ("QL, paper schedule", &self.ql_paper),
        ];
        for (name, s) in rows {
            out.push_str(&format!(
                "{name:<19}  {:>6.1}%  {:>10.0}  {:>12.0}  {:>7.2}  {:>9.2}  {:>14.3}\n",
                s.success_rate * 100.0,
                s.mean_steps,
                s.median_steps,
                s.mean_ms,
                s.median_ms,
                s.mean_length_over_optimal
            ));
        }
        out
    }
}
