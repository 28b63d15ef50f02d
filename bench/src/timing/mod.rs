//! `afford bench timing`: the timing stage on seeded random smooth 7-joint
//! paths with KUKA LBR iiwa 14-like limits, 200 path segments, then on the
//! real paths of every example ([`examples`]).

pub mod examples;

use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use afford_planner::plan::PlanOptions;
use afford_planner::timing::{JointLimits, TimingSettings, time_parameterize};
use examples::measure_examples;

/// iiwa 14 R820 joint velocity limits, rad/s.
pub const IIWA_VELOCITY: [f64; 7] = [1.48, 1.48, 1.75, 1.31, 2.27, 2.36, 2.36];
/// iiwa-like joint acceleration limits, rad/s².
pub const IIWA_ACCELERATION: [f64; 7] = [8.57, 8.57, 8.74, 11.36, 12.23, 15.72, 15.72];

/// The iiwa-like velocity and acceleration limits as [`JointLimits`]; no
/// position limits (the random walks of [`random_smooth_path`] may leave
/// the iiwa's range, and positions do not enter the timing program).
pub fn iiwa_limits() -> JointLimits {
    JointLimits {
        lower: vec![f64::NEG_INFINITY; 7],
        upper: vec![f64::INFINITY; 7],
        velocity: IIWA_VELOCITY.to_vec(),
        acceleration: IIWA_ACCELERATION.to_vec(),
        jerk: Vec::new(),
    }
}

/// A smooth random joint path: `waypoints` configurations of `joints`
/// joints, a random walk with momentum (steps up to ~0.4 rad per joint).
pub fn random_smooth_path(rng: &mut impl Rng, joints: usize, waypoints: usize) -> Vec<Vec<f64>> {
    let mut q: Vec<f64> = (0..joints).map(|_| rng.random_range(-1.0..1.0)).collect();
    let mut step: Vec<f64> = (0..joints).map(|_| rng.random_range(-0.3..0.3)).collect();
    let mut path = vec![q.clone()];
    for _ in 1..waypoints {
        for j in 0..joints {
            step[j] = (0.6 * step[j] + rng.random_range(-0.25..0.25)).clamp(-0.4, 0.4);
            q[j] += step[j];
        }
        path.push(q.clone());
    }
    path
}

/// Benchmark set-up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TimingBenchSettings {
    /// Different random paths, 20.
    pub paths: usize,
    /// Timed solves per path, 5.
    pub repeats: usize,
    /// Waypoints per path, 12.
    pub waypoints: usize,
    /// Seed of the path generator, 1.
    pub seed: u64,
}

impl Default for TimingBenchSettings {
    fn default() -> Self {
        Self {
            paths: 20,
            repeats: 5,
            waypoints: 12,
            seed: 1,
        }
    }
}

/// `afford bench timing --json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimingBenchReport {
    /// Median wall time of the whole stage (spline, program, Clarabel,
    /// sampling at 100 Hz, sample check) with 200 segments, milliseconds.
    pub median_ms_200: f64,
    /// 90th percentile of the same, milliseconds.
    pub p90_ms_200: f64,
    /// Median solve time of the program (the two passes, or Clarabel's
    /// own time), milliseconds.
    pub median_solve_ms_200: f64,
    /// Median interior-point iterations (0 where the two passes solved the LP).
    pub median_iterations: f64,
    /// Median trajectory duration, seconds.
    pub median_duration_s: f64,
    /// Solves that ended `Solved` / all solves.
    pub solved: usize,
    pub runs: usize,
    pub joints: usize,
    pub segments: usize,
    /// Largest moving time of an example sub-goal over the converged
    /// time-optimal one on the same path and limits (see
    /// [`examples`]).
    pub max_ratio_to_optimal_examples: f64,
    /// Largest moving time of an example sub-goal over the converged
    /// optimum plus the least time any jerk-limited timing must add
    /// ([`jerk_floor`](afford_planner::timing::jerk_floor)): bounds the ratio to the
    /// jerk-limited optimum from above.
    pub max_ratio_to_jerk_floor: f64,
    /// Example sub-goals within 3 % of the converged optimum without jerk
    /// limits (`ratio_to_optimal`), and within 3 % of it plus the jerk
    /// floor (`ratio_to_jerk_floor`).
    pub within_3_percent: usize,
    pub within_3_percent_of_jerk_floor: usize,
    /// The same timed without the jerk limits (the discretisation's share).
    pub max_ratio_without_jerk: f64,
    /// Largest cost of the jerk limit on one example sub-goal, seconds.
    pub max_jerk_cost_s: f64,
    /// Median wall time of the timing stage per example sub-goal, ms.
    pub median_ms_examples: f64,
    /// Most direction reversals of one joint within one example sub-goal.
    pub max_velocity_reversals: usize,
    /// Largest jerk between samples over the joint's jerk limit, any example.
    pub max_jerk_ratio: f64,
    /// Example sub-goals measured.
    pub example_subgoals: usize,
}

/// Runs the benchmark (single-threaded, deterministic inputs).
pub fn timing_benchmark(bench: &TimingBenchSettings) -> TimingBenchReport {
    let mut rng = ChaCha8Rng::seed_from_u64(bench.seed);
    let limits = iiwa_limits();
    let settings = TimingSettings {
        path_points: 200,
        ..TimingSettings::default()
    };
    let (mut total, mut solve, mut iterations, mut durations) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut solved = 0;
    for _ in 0..bench.paths {
        let path = random_smooth_path(&mut rng, 7, bench.waypoints.max(2));
        for _ in 0..bench.repeats {
            let start = Instant::now();
            let timing = time_parameterize(&path, &limits, None, &settings)
                .expect("generated paths are valid input");
            total.push(start.elapsed().as_secs_f64() * 1e3);
            solve.push(timing.stats.solve_time_s * 1e3);
            iterations.push(f64::from(timing.stats.iterations));
            if let Some(d) = timing.duration() {
                solved += 1;
                durations.push(d);
            }
        }
    }
    let runs = total.len();
    let examples = measure_examples(&PlanOptions::default());
    let mut example_ms: Vec<f64> = examples.iter().map(|f| f.timing_ms).collect();
    TimingBenchReport {
        median_ms_200: quantile(&mut total, 0.5),
        p90_ms_200: quantile(&mut total, 0.9),
        median_solve_ms_200: quantile(&mut solve, 0.5),
        median_iterations: quantile(&mut iterations, 0.5),
        median_duration_s: quantile(&mut durations, 0.5),
        solved,
        runs,
        joints: 7,
        segments: settings.path_points,
        max_ratio_to_optimal_examples: examples
            .iter()
            .map(|f| f.ratio_to_optimal)
            .fold(f64::NAN, f64::max),
        max_ratio_to_jerk_floor: examples
            .iter()
            .map(|f| f.ratio_to_jerk_floor)
            .fold(f64::NAN, f64::max),
        within_3_percent: examples
            .iter()
            .filter(|f| f.ratio_to_optimal <= 1.03)
            .count(),
        within_3_percent_of_jerk_floor: examples
            .iter()
            .filter(|f| f.ratio_to_jerk_floor <= 1.03)
            .count(),
        max_ratio_without_jerk: examples
            .iter()
            .map(|f| f.ratio_without_jerk)
            .fold(f64::NAN, f64::max),
        max_jerk_cost_s: examples
            .iter()
            .map(|f| f.jerk_cost_s)
            .fold(f64::NAN, f64::max),
        median_ms_examples: quantile(&mut example_ms, 0.5),
        max_velocity_reversals: examples
            .iter()
            .map(|f| f.max_velocity_reversals)
            .max()
            .unwrap_or(0),
        max_jerk_ratio: examples
            .iter()
            .map(|f| f.jerk_ratio)
            .fold(f64::NAN, f64::max),
        example_subgoals: examples.len(),
    }
}

fn quantile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    values[((values.len() - 1) as f64 * q).round() as usize]
}
