//! The IK measurement behind `afford bench ik`: for every built-in arm, random
//! reachable targets (FK of random in-limit configurations, fixed seed), our
//! solver and k's `JacobianIkSolver` side by side. Success = within 0.1 mm and
//! 0.001 rad with every joint inside its limits.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::error::KinematicsError;
use crate::ik::{IkSettings, IkTarget, random_configuration};
use crate::kchain::KBaseline;
use crate::math::{Pose, Real, pose_distance};
use crate::model::{Arm, RobotModel};

/// Success tolerance of the benchmark: position (m).
pub const BENCH_POSITION_TOLERANCE: Real = 1e-4;
/// Success tolerance of the benchmark: rotation (rad).
pub const BENCH_ROTATION_TOLERANCE: Real = 1e-3;
/// Random restarts granted to k's solver (as in the stack notes).
pub const K_RESTARTS: usize = 10;

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IkBenchReport {
    pub arms: Vec<ArmBench>,
}

/// One arm's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArmBench {
    pub robot: String,
    pub arm: String,
    pub poses: usize,
    pub success_rate: Real,
    pub median_us: Real,
    pub k_success_rate: Real,
    pub k_median_us: Real,
}

/// The benchmark's success criterion: `q` within the joint limits puts the
/// tool within [`BENCH_POSITION_TOLERANCE`] and [`BENCH_ROTATION_TOLERANCE`]
/// of `target`.
pub fn is_success(arm: &Arm, q: &[Real], target: &Pose) -> bool {
    let (dp, dr) = pose_distance(&arm.fk(q), target);
    arm.within_limits(q, 1e-12) && dp <= BENCH_POSITION_TOLERANCE && dr <= BENCH_ROTATION_TOLERANCE
}

fn median(mut v: Vec<Real>) -> Real {
    if v.is_empty() {
        return Real::NAN;
    }
    v.sort_by(Real::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Random reachable 6-D targets for an arm (FK of random in-limit configurations).
pub fn random_reachable_poses(arm: &Arm, count: usize, seed: u64) -> Vec<Pose> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| arm.fk(&random_configuration(arm, &mut rng)))
        .collect()
}

/// Measures one arm: `poses` targets from `seed`, unseeded solves.
pub fn bench_arm(robot: &str, arm: &Arm, poses: usize, seed: u64) -> ArmBench {
    let targets = random_reachable_poses(arm, poses, seed);
    let settings = IkSettings::default();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let (mut ok, mut times) = (0usize, Vec::with_capacity(poses));
    for t in &targets {
        let start = Instant::now();
        let r = arm.solve_ik(&IkTarget::Pose(*t), None, &settings, &mut rng);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        if r.is_ok_and(|s| is_success(arm, &s.q, t)) {
            ok += 1;
        }
    }
    let k = KBaseline::new(
        arm,
        BENCH_POSITION_TOLERANCE * 0.5,
        BENCH_ROTATION_TOLERANCE * 0.5,
        K_RESTARTS,
    );
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let (mut k_ok, mut k_times) = (0usize, Vec::with_capacity(poses));
    for t in &targets {
        let start = Instant::now();
        let r = k.solve(arm, t, &arm.home, &mut rng);
        k_times.push(start.elapsed().as_secs_f64() * 1e6);
        if r.is_some_and(|q| is_success(arm, &q, t)) {
            k_ok += 1;
        }
    }
    let rate = |n: usize| {
        if poses == 0 {
            Real::NAN
        } else {
            n as Real / poses as Real
        }
    };
    ArmBench {
        robot: robot.to_string(),
        arm: arm.name.clone(),
        poses,
        success_rate: rate(ok),
        median_us: median(times),
        k_success_rate: rate(k_ok),
        k_median_us: median(k_times),
    }
}

/// The IK benchmark over every built-in arm.
pub fn ik_benchmark(poses: usize, seed: u64) -> Result<IkBenchReport, KinematicsError> {
    let mut arms = Vec::new();
    for name in crate::builtin::NAMES {
        let model = RobotModel::builtin(name)?;
        for arm in model.arms() {
            arms.push(bench_arm(name, arm, poses, seed));
        }
    }
    Ok(IkBenchReport { arms })
}
