//! Executing a sub-goal's timed trajectory under a speed override
//! `σ ∈ [0, 1]`: the robot goes through the plan's own samples — the
//! positions that were collision-checked — with each interval between two
//! samples stretched by the speed: an interval of plan time `h` entered at
//! speed `σ_k` and left at `σ_{k+1}` lasts `2h / (σ_k + σ_{k+1})`, and
//!
//! ```text
//! q̇_k = q'_k σ_k        q̈_k = q''_k σ_k² + q'_k σ̇,   σ̇ = (σ_{k+1}² − σ_k²) / 2h
//! ```
//!
//! with `q'`, `q''` the plan's velocities and accelerations (the discrete
//! time-optimal parameterisation with `b = σ²`, as in [`crate::timing`]).
//! Each interval's `σ_{k+1}` is the value nearest the commanded speed that
//! keeps both samples within the joint velocity and acceleration limits
//! and passes the discrete rules the independent check applies to a
//! trajectory (velocity steps, velocities consistent with positions,
//! accelerations recomputed from positions), each with [`LIMIT_SHARE`];
//! going on at the same speed is always allowed (the plan passed them at
//! full speed). A stop is `σ* = 0`: the robot brakes along its path to rest
//! on one of the plan's samples — a timed stop, never a jump — and rests
//! there, a sample every controller period, until it resumes.

use crate::timing::{JointLimits, TrajectoryPoint};
use crate::trajectory::TimedMotion;

/// Share of each velocity and acceleration limit the override may use.
pub const LIMIT_SHARE: f64 = 0.999;

/// Where execution is along one sub-goal's planned trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct Cursor {
    /// The plan sample the robot is at.
    pub index: usize,
    /// Its plan time, seconds from the start of the sub-goal's trajectory.
    pub s: f64,
    /// Speed override `σ = ṡ`, 0 (at rest) to 1 (as planned).
    pub sigma: f64,
    /// Mean joint velocities over the last executed interval and its
    /// duration (for the acceleration recomputed from positions).
    last: Option<(Vec<f64>, f64)>,
}

impl Cursor {
    pub const START: Cursor = Cursor {
        index: 0,
        s: 0.0,
        sigma: 1.0,
        last: None,
    };

    /// At plan sample `index` (time `s`), at rest or resting.
    pub fn at(index: usize, s: f64, sigma: f64) -> Self {
        Self {
            index,
            s,
            sigma,
            last: None,
        }
    }
}

/// One executed interval: the new cursor, the sample reached and how long
/// it took, s.
pub struct Step {
    pub cursor: Cursor,
    pub point: TrajectoryPoint,
    pub duration: f64,
}

/// The planned position at plan time `s` (the sample at or before it).
pub fn planned_position(points: &[TrajectoryPoint], s: f64) -> Vec<f64> {
    let k = points
        .partition_point(|p| p.time_from_start <= s + 1e-9)
        .saturating_sub(1);
    points[k].positions.clone()
}

/// One interval from `cursor` toward the commanded speed `target` (0–1);
/// at rest with the command 0, one controller period `dt` of rest.
pub fn step(
    motion: &TimedMotion,
    limits: &JointLimits,
    cursor: &Cursor,
    target: f64,
    dt: f64,
) -> Step {
    let points = &motion.points;
    let k = cursor.index.min(points.len() - 1);
    let target = target.clamp(0.0, 1.0);
    if k + 1 >= points.len() || (cursor.sigma <= 0.0 && target <= 0.0) {
        return rest(&points[k], cursor, dt);
    }
    let interval = Interval {
        a: &points[k],
        b: &points[k + 1],
        limits,
        sigma: cursor.sigma,
        last: cursor.last.as_ref(),
    };
    let x = interval.choose(target * target);
    let sigma = x.sqrt();
    let duration = interval.duration(sigma);
    let sddot = (x - cursor.sigma * cursor.sigma) / (2.0 * interval.h());
    let b = interval.b;
    let point = TrajectoryPoint {
        positions: b.positions.clone(),
        velocities: b.velocities.iter().map(|v| v * sigma).collect(),
        accelerations: b
            .accelerations
            .iter()
            .zip(&b.velocities)
            .map(|(a, v)| a * x + v * sddot)
            .collect(),
        time_from_start: b.time_from_start,
    };
    Step {
        cursor: Cursor {
            index: k + 1,
            s: b.time_from_start,
            sigma,
            last: Some((interval.means(duration), duration)),
        },
        point,
        duration,
    }
}

/// One controller period at rest on the sample.
fn rest(p: &TrajectoryPoint, cursor: &Cursor, dt: f64) -> Step {
    let zeros = vec![0.0; p.positions.len()];
    Step {
        cursor: Cursor {
            sigma: 0.0,
            last: Some((zeros.clone(), dt)),
            ..cursor.clone()
        },
        point: TrajectoryPoint {
            positions: p.positions.clone(),
            velocities: zeros.clone(),
            accelerations: zeros,
            time_from_start: p.time_from_start,
        },
        duration: dt,
    }
}

/// Where braking from `cursor` brings the arm to rest: the same steps as
/// [`step`] with the command 0, at most `max_steps` intervals.
pub fn stopping_point(
    motion: &TimedMotion,
    limits: &JointLimits,
    cursor: &Cursor,
    dt: f64,
    max_steps: usize,
) -> Cursor {
    let mut cursor = cursor.clone();
    for _ in 0..max_steps {
        if cursor.sigma <= 0.0 || cursor.index + 1 >= motion.points.len() {
            break;
        }
        cursor = step(motion, limits, &cursor, 0.0, dt).cursor;
    }
    cursor
}

/// One interval between two plan samples, entered at speed `sigma`.
struct Interval<'a> {
    a: &'a TrajectoryPoint,
    b: &'a TrajectoryPoint,
    limits: &'a JointLimits,
    sigma: f64,
    last: Option<&'a (Vec<f64>, f64)>,
}

impl Interval<'_> {
    fn h(&self) -> f64 {
        (self.b.time_from_start - self.a.time_from_start).max(1e-12)
    }

    fn duration(&self, sigma: f64) -> f64 {
        2.0 * self.h() / (self.sigma + sigma).max(1e-12)
    }

    fn means(&self, duration: f64) -> Vec<f64> {
        self.a
            .positions
            .iter()
            .zip(&self.b.positions)
            .map(|(p, q)| (q - p) / duration)
            .collect()
    }

    /// The exit speed² nearest `wanted` that passes [`Self::passes`]:
    /// bisection between it and the speed² held constant.
    fn choose(&self, wanted: f64) -> f64 {
        let fastest = self
            .b
            .velocities
            .iter()
            .zip(&self.limits.velocity)
            .filter(|(v, _)| v.abs() > 1e-12)
            .map(|(v, limit)| (LIMIT_SHARE * limit / v.abs()).powi(2))
            .fold(1.0, f64::min);
        let held = (self.sigma * self.sigma).min(fastest);
        let wanted = wanted.min(fastest);
        // Resuming from rest must move: never hold 0.
        let held = if held <= 0.0 { wanted.min(1e-6) } else { held };
        if self.passes(wanted) {
            return wanted;
        }
        let (mut good, mut bad) = (held, wanted);
        for _ in 0..30 {
            let mid = 0.5 * (good + bad);
            match self.passes(mid) {
                true => good = mid,
                false => bad = mid,
            }
        }
        good
    }

    /// The discrete rules at exit speed² `x`, every joint.
    fn passes(&self, x: f64) -> bool {
        let sigma = x.sqrt();
        let d = self.duration(sigma);
        let sddot = (x - self.sigma * self.sigma) / (2.0 * self.h());
        let (a, b) = (self.a, self.b);
        (0..a.positions.len()).all(|j| {
            let (vmax, amax) = (
                LIMIT_SHARE * self.limits.velocity[j],
                LIMIT_SHARE * self.limits.acceleration[j],
            );
            let (va, vb) = (a.velocities[j] * self.sigma, b.velocities[j] * sigma);
            let mean = (b.positions[j] - a.positions[j]) / d;
            let field = b.accelerations[j] * x + b.velocities[j] * sddot;
            let recomputed = self
                .last
                .is_none_or(|(m, dl)| ((mean - m[j]) / (0.5 * (dl + d))).abs() <= amax);
            vb.abs() <= vmax
                && field.abs() <= amax
                && ((vb - va) / d).abs() <= amax
                && (va - mean).abs() <= amax * d / 2.0
                && (vb - mean).abs() <= amax * d / 2.0
                && recomputed
        })
    }
}
