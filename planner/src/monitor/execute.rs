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
//! A change of speed follows a jerk-limited ramp (`ramp.rs`): the
//! sequence of `σ_k` from a smooth `σ(t)`, checked sample by sample with
//! the independent check's discrete rules — velocity steps, velocities
//! consistent with positions, accelerations recomputed from positions
//! (each within [`LIMIT_SHARE`] of its limit, or no worse than the plan's
//! own value there) and the jerk as six times the third divided difference
//! of positions and times over four samples — and lengthened until it
//! passes. A stop is `σ* = 0`: the robot brakes along its path to rest on
//! one of the plan's samples — a timed stop, never a jump — and rests
//! there, a sample every controller period, until it resumes.

use crate::timing::{JointLimits, TrajectoryPoint};
use crate::trajectory::TimedMotion;

use super::brake::Braking;
use super::interval::Interval;
pub use super::interval::LIMIT_SHARE;
use super::ramp;
pub use super::state::Cursor;

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
/// at rest with the command 0, one controller period `dt` of rest. A new
/// command starts a ramp ([`ramp::plan`]) from where the cursor is.
pub fn step(
    motion: &TimedMotion,
    limits: &JointLimits,
    cursor: &Cursor,
    target: f64,
    dt: f64,
    braking: Option<&Braking>,
) -> Step {
    let points = &motion.points;
    let k = cursor.index.min(points.len() - 1);
    let target = target.clamp(0.0, 1.0);
    if k + 1 >= points.len() {
        return rest(&points[k], cursor, dt);
    }
    let mut cursor = Cursor {
        index: k,
        ..cursor.clone()
    };
    let settled = match &cursor.ramp {
        Some(r) => r.target == target,
        None => cursor.sigma == target,
    };
    if !settled {
        cursor.ramp = Some(ramp::plan(motion, limits, &cursor, target, dt, braking));
    }
    let (sa, sb) = match &cursor.ramp {
        Some(r) => (r.sigma(k), r.sigma(k + 1)),
        None => (cursor.sigma, cursor.sigma),
    };
    if sa + sb <= 0.0 {
        return rest(&points[k], &cursor, dt);
    }
    let interval = Interval {
        a: &points[k],
        b: &points[k + 1],
        sigma_a: sa,
        sigma_b: sb,
    };
    let duration = interval.duration();
    let sddot = interval.sigma_rate();
    let b = interval.b;
    let point = TrajectoryPoint {
        positions: b.positions.clone(),
        velocities: b.velocities.iter().map(|v| v * sb).collect(),
        accelerations: b
            .accelerations
            .iter()
            .zip(&b.velocities)
            .map(|(a, v)| a * sb * sb + v * sddot)
            .collect(),
        time_from_start: b.time_from_start,
    };
    Step {
        cursor: cursor.moved(
            k + 1,
            b.time_from_start,
            sb,
            (interval.means(duration), duration),
        ),
        point,
        duration,
    }
}

/// One controller period at rest on the sample.
fn rest(p: &TrajectoryPoint, cursor: &Cursor, dt: f64) -> Step {
    let zeros = vec![0.0; p.positions.len()];
    let mut cursor = cursor.moved(cursor.index, cursor.s, 0.0, (zeros.clone(), dt));
    cursor.ramp = None;
    Step {
        cursor,
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
/// [`step`] with the command 0 (the same ramp), at most `max_steps`
/// intervals.
pub fn stopping_point(
    motion: &TimedMotion,
    limits: &JointLimits,
    cursor: &Cursor,
    dt: f64,
    max_steps: usize,
    braking: Option<&Braking>,
) -> Cursor {
    let mut cursor = cursor.clone();
    for _ in 0..max_steps {
        if cursor.sigma <= 0.0 || cursor.index + 1 >= motion.points.len() {
            break;
        }
        cursor = step(motion, limits, &cursor, 0.0, dt, braking).cursor;
    }
    cursor
}
