//! Arm choice for robots with several arms: every arm tries the whole
//! Cartesian path; the one that reaches every waypoint at the lowest cost
//! works, the others park.
//!
//! cost = |q_first - q_now| + path length (joint space, Euclidean)
//!        + limit_weight * mean over waypoints of mean_j ((q_j - mid_j) / half_range_j)^2
//!
//! A continuous joint has no limits to keep away from: its term is 0.

use rand::Rng;
use serde::Serialize;

use crate::error::KinematicsError;
use crate::ik::IkTarget;
use crate::math::Real;
use crate::model::{Arm, RobotModel};
use crate::path::{JointPath, PathFailure, PathSettings};

/// Weight of the distance-to-limits term in the arm-choice cost.
pub const LIMIT_WEIGHT: Real = 0.5;

/// The chosen arm and its path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArmChoice {
    pub arm: String,
    /// Index into [`RobotModel::arms`].
    pub arm_index: usize,
    pub cost: Real,
    /// The arm's own joint path.
    pub path: JointPath,
    /// Whole-robot configurations along the path: the chosen arm's values,
    /// every other arm at its park posture, remaining joints as in `current`.
    pub robot_path: Vec<Vec<Real>>,
}

/// No arm reaches every waypoint; each arm's first failure.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[error("no arm reaches every waypoint: {}", .failures.iter().map(|(a, f)| format!("{a}: {f}")).collect::<Vec<_>>().join("; "))]
pub struct NoArmReaches {
    pub failures: Vec<(String, PathFailure)>,
}

/// Arm-choice cost of a solved path (see the module docs).
pub fn path_cost(arm: &Arm, current: &[Real], path: &JointPath) -> Real {
    let Some(first) = path.waypoints.first() else {
        return 0.0;
    };
    let approach: Real = first
        .iter()
        .zip(current)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<Real>()
        .sqrt();
    let limits: Real = path
        .waypoints
        .iter()
        .map(|q| {
            q.iter()
                .zip(arm.lower.iter().zip(&arm.upper))
                .filter(|&(_, (lo, hi))| lo.is_finite() && hi.is_finite())
                .map(|(&v, (&lo, &hi))| {
                    let half = 0.5 * (hi - lo);
                    ((v - 0.5 * (hi + lo)) / half).powi(2)
                })
                .sum::<Real>()
                / arm.dof() as Real
        })
        .sum::<Real>()
        / path.waypoints.len() as Real;
    approach + path.length + LIMIT_WEIGHT * limits
}

/// Picks the arm that reaches every target with the lowest cost, starting
/// from the robot configuration `current`.
pub fn choose_arm(
    model: &RobotModel,
    targets: &[IkTarget],
    current: &[Real],
    settings: &PathSettings,
    rng: &mut impl Rng,
) -> Result<Result<ArmChoice, NoArmReaches>, KinematicsError> {
    if current.len() != model.dof() {
        return Err(KinematicsError::ConfigSize {
            what: "current robot configuration",
            expected: model.dof(),
            got: current.len(),
        });
    }
    settings.validate()?;
    let mut best: Option<ArmChoice> = None;
    let mut failures = Vec::new();
    for (arm_index, arm) in model.arms().iter().enumerate() {
        let now = arm.extract(current);
        match arm.solve_path(targets, Some(&now), settings, rng) {
            Ok(path) => {
                let cost = path_cost(arm, &now, &path);
                if best.as_ref().is_none_or(|b| cost < b.cost) {
                    let parked = model.parked_except(current, &arm.name);
                    let robot_path = path
                        .waypoints
                        .iter()
                        .map(|q| {
                            let mut full = parked.clone();
                            arm.insert(&mut full, q);
                            full
                        })
                        .collect();
                    best = Some(ArmChoice {
                        arm: arm.name.clone(),
                        arm_index,
                        cost,
                        path,
                        robot_path,
                    });
                }
            }
            Err(f) => failures.push((arm.name.clone(), f)),
        }
    }
    Ok(best.ok_or(NoArmReaches { failures }))
}
