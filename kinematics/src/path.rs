//! Cartesian path IK: a list of tool targets becomes a continuous joint path.
//! Every waypoint is solved from the previous one (seeded, no restarts, so the
//! branch never flips); a step that fails or jumps is retried through
//! interpolated sub-targets; the first waypoint may try several starting
//! branches. A failure names the first waypoint no branch could reach.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::error::{IkFailure, KinematicsError};
use crate::ik::{IkSettings, IkTarget};
use crate::math::{Pose, Real};
use crate::model::Arm;

/// Path IK parameters. Defaults are written once, in `Default`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PathSettings {
    /// Single-waypoint IK settings.
    pub ik: IkSettings,
    /// Largest joint change (rad or m) accepted between consecutive waypoints.
    pub max_joint_step: Real,
    /// Interpolated sub-targets tried when a step fails or jumps.
    pub subdivisions: usize,
    /// Starting solutions tried for the first waypoint (different branches).
    pub start_attempts: usize,
}

impl Default for PathSettings {
    fn default() -> Self {
        Self {
            ik: IkSettings::default(),
            max_joint_step: 0.3,
            subdivisions: 4,
            start_attempts: 4,
        }
    }
}

impl PathSettings {
    pub fn validate(&self) -> Result<(), KinematicsError> {
        self.ik.validate()?;
        if !(self.max_joint_step.is_finite() && self.max_joint_step > 0.0) {
            return Err(KinematicsError::Settings {
                field: "max_joint_step",
                problem: "must be positive".into(),
            });
        }
        if self.start_attempts == 0 {
            return Err(KinematicsError::Settings {
                field: "start_attempts",
                problem: "must be at least 1".into(),
            });
        }
        Ok(())
    }
}

/// A continuous joint path of one arm, one configuration per waypoint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointPath {
    pub waypoints: Vec<Vec<Real>>,
    /// Largest single-joint change between consecutive waypoints.
    pub max_step: Real,
    /// Sum of Euclidean joint-space distances between consecutive waypoints.
    pub length: Real,
}

/// The first waypoint no branch could reach, and why.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[error("waypoint {index} of {count} is unreachable: {reason}")]
pub struct PathFailure {
    /// Index of the first unreachable waypoint.
    pub index: usize,
    pub count: usize,
    pub reason: IkFailure,
}

/// Largest absolute per-joint difference.
pub fn max_joint_step(a: &[Real], b: &[Real]) -> Real {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

fn distance(a: &[Real], b: &[Real]) -> Real {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<Real>()
        .sqrt()
}

/// Target a fraction `t` of the way from `a` to `b`.
fn interpolate(a: &IkTarget, b: &IkTarget, t: Real) -> IkTarget {
    match (a, b) {
        (IkTarget::Pose(pa), IkTarget::Pose(pb)) => {
            let p = pa.translation.vector.lerp(&pb.translation.vector, t);
            let r = pa
                .rotation
                .try_slerp(&pb.rotation, t, 1e-9)
                .unwrap_or(pb.rotation);
            IkTarget::Pose(Pose::from_parts(p.into(), r))
        }
        (
            IkTarget::TopDown {
                position: pa,
                yaw: ya,
            },
            IkTarget::TopDown {
                position: pb,
                yaw: yb,
            },
        ) => IkTarget::TopDown {
            position: pa.lerp(pb, t),
            yaw: match (ya, yb) {
                (Some(x), Some(y)) => {
                    let d = (y - x + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                        - std::f64::consts::PI;
                    Some(x + d * t)
                }
                _ => *yb,
            },
        },
        _ => *b,
    }
}

impl Arm {
    /// Solves a Cartesian path. `start` (this arm's current joint values)
    /// seeds the first waypoint; without it, or if the seed fails, the first
    /// waypoint is solved with restarts. Consecutive waypoints never differ by
    /// more than `max_joint_step` per joint.
    pub fn solve_path(
        &self,
        targets: &[IkTarget],
        start: Option<&[Real]>,
        settings: &PathSettings,
        rng: &mut impl Rng,
    ) -> Result<JointPath, PathFailure> {
        self.solve_path_screened(targets, start, settings, rng, &mut |_| true)
    }

    /// [`Arm::solve_path`] that prefers a branch whose joint path (every
    /// waypoint, in order) passes `screen` (e.g. free of self-collision): a
    /// branch the screen rejects is left for the next start attempt, and
    /// only when no attempt passes is the first complete path returned (the
    /// caller's own checks then name what is wrong with it). The screen
    /// never makes a reachable path unreachable.
    pub fn solve_path_screened(
        &self,
        targets: &[IkTarget],
        start: Option<&[Real]>,
        settings: &PathSettings,
        rng: &mut impl Rng,
        screen: &mut dyn FnMut(&[Vec<Real>]) -> bool,
    ) -> Result<JointPath, PathFailure> {
        let count = targets.len();
        let fail = |index: usize, reason: IkFailure| PathFailure {
            index,
            count,
            reason,
        };
        if targets.is_empty() {
            return Ok(JointPath {
                waypoints: Vec::new(),
                max_step: 0.0,
                length: 0.0,
            });
        }
        let mut first_ik = settings.ik.clone();
        first_ik.restart_when_seeded = true;
        let mut furthest: Option<PathFailure> = None;
        let mut unscreened: Option<JointPath> = None;
        for attempt in 0..settings.start_attempts {
            // Attempt 0: from the given start (or home); later: fresh branches.
            let seed = if attempt == 0 { start } else { None };
            let q0 = match (attempt, seed) {
                (0, _) => self.solve_ik(&targets[0], seed, &first_ik, rng),
                _ => {
                    let random = crate::ik::random_configuration(self, rng);
                    self.solve_ik(&targets[0], Some(&random), &first_ik, rng)
                }
            };
            let q0 = match q0 {
                Ok(s) => s.q,
                Err(reason) => return Err(fail(0, reason)),
            };
            match self.follow(targets, q0, settings, rng) {
                Ok(path) if screen(&path.waypoints) => return Ok(path),
                Ok(path) => {
                    unscreened.get_or_insert(path);
                }
                Err((index, reason)) => {
                    if furthest.as_ref().is_none_or(|f| index > f.index) {
                        furthest = Some(fail(index, reason));
                    }
                    // Out of reach does not depend on the branch.
                    if matches!(
                        furthest.as_ref().map(|f| &f.reason),
                        Some(IkFailure::OutOfReach { .. })
                    ) {
                        break;
                    }
                }
            }
        }
        match unscreened {
            Some(path) => Ok(path),
            None => Err(furthest.expect("at least one start attempt")),
        }
    }

    fn follow(
        &self,
        targets: &[IkTarget],
        q0: Vec<Real>,
        settings: &PathSettings,
        rng: &mut impl Rng,
    ) -> Result<JointPath, (usize, IkFailure)> {
        let mut waypoints = Vec::with_capacity(targets.len());
        waypoints.push(q0);
        let (mut max_step, mut length) = (0.0f64, 0.0);
        for i in 1..targets.len() {
            let prev = waypoints[i - 1].clone();
            let q = match self.step(&targets[i - 1], &targets[i], &prev, settings, rng) {
                Ok(q) => q,
                Err(reason) => return Err((i, reason)),
            };
            max_step = max_step.max(max_joint_step(&prev, &q));
            length += distance(&prev, &q);
            waypoints.push(q);
        }
        Ok(JointPath {
            waypoints,
            max_step,
            length,
        })
    }

    /// One seeded step, retried through sub-targets when it fails or jumps.
    fn step(
        &self,
        from: &IkTarget,
        to: &IkTarget,
        prev: &[Real],
        settings: &PathSettings,
        rng: &mut impl Rng,
    ) -> Result<Vec<Real>, IkFailure> {
        let mut ik = settings.ik.clone();
        ik.restart_when_seeded = false;
        // The posture is the seed: stay close to the previous waypoint.
        let direct = self.solve_ik(to, Some(prev), &ik, rng);
        let direct_err = match direct {
            Ok(s) if max_joint_step(prev, &s.q) <= settings.max_joint_step => return Ok(s.q),
            Ok(s) => IkFailure::Discontinuous {
                step: max_joint_step(prev, &s.q),
            },
            Err(e) => e,
        };
        if matches!(direct_err, IkFailure::OutOfReach { .. }) || settings.subdivisions < 2 {
            return Err(direct_err);
        }
        let mut q = prev.to_vec();
        let n = settings.subdivisions;
        for k in 1..=n {
            let sub = interpolate(from, to, k as Real / n as Real);
            match self.solve_ik(&sub, Some(&q), &ik, rng) {
                Ok(s) => q = s.q,
                Err(_) => return Err(direct_err),
            }
        }
        let step = max_joint_step(prev, &q);
        if step > settings.max_joint_step {
            return Err(IkFailure::Discontinuous { step });
        }
        Ok(q)
    }
}
