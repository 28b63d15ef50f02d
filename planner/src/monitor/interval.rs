//! One executed interval between two plan samples under the speed
//! override, `σ_a` at the first and `σ_b` at the second: how long it lasts
//! (`2h / (σ_a + σ_b)`), its mean velocities, and the independent check's
//! discrete acceleration rules on it ([`Interval::passes`]).

use crate::timing::{JointLimits, TrajectoryPoint};

/// Share of each velocity and acceleration limit the override may use.
pub const LIMIT_SHARE: f64 = 0.999;

/// One interval between two plan samples, entered at speed `sigma_a` and
/// left at `sigma_b`.
pub struct Interval<'a> {
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
    pub fn sigma_rate(&self) -> f64 {
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
