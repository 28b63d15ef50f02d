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

use super::ramp::{self, Ramp};

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
    /// The last executed samples, this one last (at most three): plan
    /// index and time on [`Self::clock`]. Missing ones were at rest.
    past: Vec<(usize, f64)>,
    /// Execution time since the cursor was placed, s.
    clock: f64,
    /// The speed change under way, if any.
    ramp: Option<Ramp>,
}

impl Cursor {
    pub const START: Cursor = Cursor {
        index: 0,
        s: 0.0,
        sigma: 1.0,
        last: None,
        past: Vec::new(),
        clock: 0.0,
        ramp: None,
    };

    /// At plan sample `index` (time `s`), at rest or resting.
    pub fn at(index: usize, s: f64, sigma: f64) -> Self {
        Self {
            index,
            s,
            sigma,
            ..Self::START
        }
    }

    /// The last three executed samples (plan index, time), oldest first;
    /// samples before the first known one at rest a period `dt` apart.
    pub(super) fn history(&self, dt: f64) -> [(usize, f64); 3] {
        let known = match self.past.len() {
            0 => vec![(self.index, self.clock)],
            n => self.past[n.saturating_sub(3)..].to_vec(),
        };
        let first = known[0];
        let mut out = [first; 3];
        let pad = 3 - known.len();
        for (i, slot) in out.iter_mut().enumerate() {
            *slot = match i < pad {
                true => (first.0, first.1 - dt * (pad - i) as f64),
                false => known[i - pad],
            };
        }
        out
    }

    pub(super) fn last(&self) -> Option<&(Vec<f64>, f64)> {
        self.last.as_ref()
    }

    pub(super) fn ramp(&self) -> Option<&Ramp> {
        self.ramp.as_ref()
    }

    /// The cursor after one executed sample at plan index `index`.
    fn moved(&self, index: usize, s: f64, sigma: f64, last: (Vec<f64>, f64)) -> Cursor {
        let clock = self.clock + last.1;
        let mut past = self.past.clone();
        past.push((index, clock));
        if past.len() > 3 {
            past.remove(0);
        }
        let ramp = self
            .ramp
            .clone()
            .filter(|r| !(r.ended(index) && sigma == r.target));
        Cursor {
            index,
            s,
            sigma,
            last: Some(last),
            past,
            clock,
            ramp,
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
/// at rest with the command 0, one controller period `dt` of rest. A new
/// command starts a ramp ([`ramp::plan`]) from where the cursor is.
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
        cursor.ramp = Some(ramp::plan(motion, limits, &cursor, target, dt));
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

/// One interval between two plan samples, entered at speed `sigma_a` and
/// left at `sigma_b`.
pub(super) struct Interval<'a> {
    pub a: &'a TrajectoryPoint,
    pub b: &'a TrajectoryPoint,
    pub sigma_a: f64,
    pub sigma_b: f64,
}

impl Interval<'_> {
    fn h(&self) -> f64 {
        (self.b.time_from_start - self.a.time_from_start).max(1e-12)
    }

    pub fn duration(&self) -> f64 {
        2.0 * self.h() / (self.sigma_a + self.sigma_b).max(1e-12)
    }

    /// `σ̇` over the interval, 1/s.
    fn sigma_rate(&self) -> f64 {
        (self.sigma_b.powi(2) - self.sigma_a.powi(2)) / (2.0 * self.h())
    }

    pub fn means(&self, duration: f64) -> Vec<f64> {
        self.a
            .positions
            .iter()
            .zip(&self.b.positions)
            .map(|(p, q)| (q - p) / duration)
            .collect()
    }

    /// The independent check's discrete acceleration rules on this
    /// interval, every joint: the acceleration field, the velocity step,
    /// velocities against the mean of positions and the acceleration
    /// recomputed from the means of this and the `last` interval. Each is
    /// within [`LIMIT_SHARE`] of the joint's limit or no larger than the
    /// plan's own value there (`before`: the plan sample before `a`).
    pub fn passes(
        &self,
        limits: &JointLimits,
        before: Option<&TrajectoryPoint>,
        last: Option<&(Vec<f64>, f64)>,
    ) -> bool {
        let (a, b, h) = (self.a, self.b, self.h());
        let d = self.duration();
        let sddot = self.sigma_rate();
        let x = self.sigma_b * self.sigma_b;
        (0..a.positions.len()).all(|j| {
            let share = LIMIT_SHARE * limits.acceleration[j];
            let within = |value: f64, own: f64| value.abs() <= share.max(own.abs() * (1.0 + 1e-9));
            let (va, vb) = (
                a.velocities[j] * self.sigma_a,
                b.velocities[j] * self.sigma_b,
            );
            let step = b.positions[j] - a.positions[j];
            let (mean, own_mean) = (step / d, step / h);
            let field = b.accelerations[j] * x + b.velocities[j] * sddot;
            let recomputed = last.is_none_or(|(m, dl)| {
                let own = before.map_or(0.0, |p| {
                    let hp = (a.time_from_start - p.time_from_start).max(1e-12);
                    (own_mean - (a.positions[j] - p.positions[j]) / hp) / (0.5 * (hp + h))
                });
                within((mean - m[j]) / (0.5 * (dl + d)), own)
            });
            within(field, b.accelerations[j])
                && within((vb - va) / d, (b.velocities[j] - a.velocities[j]) / h)
                && within(
                    2.0 * (va - mean) / d,
                    2.0 * (a.velocities[j] - own_mean) / h,
                )
                && within(
                    2.0 * (vb - mean) / d,
                    2.0 * (b.velocities[j] - own_mean) / h,
                )
                && recomputed
        })
    }
}
