//! Helpers of the timing tests, shared by the planner's timing tests and
//! the benchmark crate's (`bench/tests/timing.rs`, which includes this file):
//! the status check, an independent check of every sample against the
//! velocity and acceleration limits, a planar case past a hand, the sampled
//! jerk, and loading and planning a scenario.
#![allow(dead_code)]

use afford_planner::timing::{
    Hand, JointLimits, JointTrajectory, Proximity, SeparationSettings, Timing, TimingStatus,
};
use afford_planner::{Plan, PlanOptions, Scenario};

pub fn solved(timing: &Timing) -> &JointTrajectory {
    assert_eq!(timing.status, TimingStatus::Solved, "{:?}", timing.stats);
    timing.trajectory.as_ref().expect("solved means sampled")
}

/// Independent check of every sample (does not trust the stage's own check).
pub fn assert_within(trajectory: &JointTrajectory, limits: &JointLimits, scale: f64) {
    for p in &trajectory.points {
        for j in 0..limits.velocity.len() {
            assert!(p.velocities[j].abs() <= limits.velocity[j] * scale * (1.0 + 1e-6));
            assert!(
                p.accelerations[j].abs() <= limits.acceleration[j] * scale * scale * (1.0 + 1e-6)
            );
        }
    }
}

/// Two joints whose tool is at (q0, q1, 0.3) m: a 1.2 m straight line past a
/// hand at (0.6, 0.25, 0.3).
pub fn planar_case() -> (Vec<Vec<f64>>, JointLimits, Proximity) {
    let path: Vec<Vec<f64>> = (0..=12).map(|k| vec![0.1 * k as f64, 0.0]).collect();
    let tool_positions = path.iter().map(|q| [q[0], q[1], 0.3]).collect();
    let limits = JointLimits {
        lower: vec![-10.0; 2],
        upper: vec![10.0; 2],
        velocity: vec![1.5, 1.5],
        acceleration: vec![4.0, 4.0],
        jerk: Vec::new(),
    };
    let proximity = Proximity {
        tool_positions,
        hands: vec![Hand {
            centre: [0.6, 0.25, 0.3],
            radius: 0.05,
        }],
        rule: SeparationSettings::default(),
    };
    (path, limits, proximity)
}

pub fn load(path: &str) -> Scenario {
    afford_planner::scenario::load(std::path::Path::new(path)).unwrap()
}

pub fn plan(scenario: &Scenario, options: &PlanOptions) -> Plan {
    afford_planner::plan(scenario, options).unwrap()
}

/// Six times the third divided difference of each joint's positions over
/// four consecutive samples, the arm at rest before and after (written
/// here, not taken from the planner): the largest over the limit.
pub fn sampled_jerk_ratio(trajectory: &JointTrajectory, jerk: &[f64]) -> f64 {
    let p = &trajectory.points;
    let (n, h0, h1) = (
        p.len(),
        p[1].time_from_start - p[0].time_from_start,
        p[p.len() - 1].time_from_start - p[p.len() - 2].time_from_start,
    );
    let t0 = p[0].time_from_start;
    let tn = p[n - 1].time_from_start;
    let mut times = vec![t0 - 2.0 * h0, t0 - h0];
    times.extend(p.iter().map(|x| x.time_from_start));
    times.extend([tn + h1, tn + 2.0 * h1]);
    let q = |k: usize, j: usize| p[k.clamp(2, n + 1) - 2].positions[j];
    let mut worst: f64 = 0.0;
    for (j, limit) in jerk.iter().enumerate() {
        for k in 0..times.len() - 3 {
            let w = &times[k..k + 4];
            let value: f64 = (0..4)
                .map(|i| {
                    let d: f64 = (0..4).filter(|&m| m != i).map(|m| w[i] - w[m]).product();
                    q(k + i, j) / d
                })
                .sum::<f64>()
                * 6.0;
            worst = worst.max(value.abs() / limit);
        }
    }
    worst
}
