//! A lower bound on what jerk limits must cost on a path, from the
//! converged time-optimal trajectory without them.
//!
//! Every feasible path-velocity profile lies below the time-optimal one
//! under the velocity, acceleration and tool-speed limits (the feasible
//! profiles have a greatest element: Bobrow 1985; Pham, IEEE T-RO 2018), so
//! a jerk-limited motion through the path point `P` takes at least the
//! optimum's time *after* `P`, and the optimum takes at most the time the
//! reference (a feasible, converged solution) takes *to* `P`. A
//! jerk-limited motion starts at rest with zero acceleration, so joint `j`
//! moves at most `J_j t³/6` in its first `t` seconds and reaches `P`, where
//! that joint has moved `δ_j`, no earlier than `(6δ_j/J_j)^{1/3}`. Hence
//!
//! ```text
//! T_jerk ≥ T_opt + max over P, j of [ (6 δ_j(P) / J_j)^{1/3} − t_ref(P) ]
//! ```
//!
//! and the same backwards from the rest at the end, with `P` in the first
//! half of the reference's time at the start and in the second at the end
//! (the two stretches do not overlap). For one joint accelerating at `A`
//! from rest the bracket peaks at `(4/9) A/J`: `(8/9) A/J` a rest-to-rest
//! piece, against `A/J` for the jerk-limited optimum of a single joint.
//! The maximum is taken over the reference's samples, so a coarser sampling
//! only weakens the bound.

use super::sample::JointTrajectory;

/// The floor of one rest-to-rest piece, seconds: the most the bracket of
/// the module docs reaches from its first rest and from its last, summed.
/// `reference` is the converged time-optimal trajectory of the piece
/// without jerk limits (at rest at both ends, positions in rad or m, times
/// in s); `jerk[j]` is joint `j`'s jerk limit (rad/s³ or m/s³). A joint
/// with no finite positive limit bounds nothing; an empty reference gives 0.
pub fn piece_jerk_floor(reference: &JointTrajectory, jerk: &[f64]) -> f64 {
    let points = &reference.points;
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return 0.0;
    };
    let half = 0.5 * (first.time_from_start + last.time_from_start);
    let from_start = ramp_floor(
        points.iter().take_while(|p| p.time_from_start <= half),
        first,
        jerk,
    );
    let to_end = ramp_floor(
        points
            .iter()
            .rev()
            .take_while(|p| p.time_from_start >= half),
        last,
        jerk,
    );
    from_start + to_end
}

/// `max(0, max over samples and joints of (6δ_j/J_j)^{1/3} − t)`, with `δ_j`
/// and `t` measured from the rest sample `rest`.
fn ramp_floor<'a>(
    samples: impl Iterator<Item = &'a super::TrajectoryPoint>,
    rest: &super::TrajectoryPoint,
    jerk: &[f64],
) -> f64 {
    let mut floor = 0.0_f64;
    for p in samples {
        let t = (p.time_from_start - rest.time_from_start).abs();
        for ((q, q0), &limit) in p.positions.iter().zip(&rest.positions).zip(jerk) {
            if limit.is_finite() && limit > 0.0 {
                let reach = (6.0 * (q - q0).abs() / limit).cbrt();
                floor = floor.max(reach - t);
            }
        }
    }
    floor
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::timing::TrajectoryPoint;

    /// One joint moving `d` rest to rest at full acceleration `a` and back
    /// (the acceleration-limited optimum), sampled at `rate` Hz.
    fn bang_bang(d: f64, a: f64, rate: f64) -> JointTrajectory {
        let total = 2.0 * (d / a).sqrt();
        let samples = (total * rate).ceil() as usize;
        let points = (0..=samples)
            .map(|k| {
                let t = (k as f64 / rate).min(total);
                let q = if t <= total / 2.0 {
                    0.5 * a * t * t
                } else {
                    d - 0.5 * a * (total - t) * (total - t)
                };
                TrajectoryPoint {
                    positions: vec![q],
                    velocities: vec![0.0],
                    accelerations: vec![0.0],
                    time_from_start: t,
                }
            })
            .collect();
        JointTrajectory { points }
    }

    /// The jerk-limited optimum of the same move lasts `A/J +
    /// √((A/J)² + 4d/A)` (a symmetric S-curve without cruise), `A/J` or
    /// more beyond the bang-bang profile's `√(4d/A)`: the floor stays below
    /// that and reaches the `(8/9) A/J` of the module docs.
    #[test]
    fn floor_of_a_bang_bang_move_is_eight_ninths_of_a_over_j_and_below_the_s_curve() {
        let (d, a, j) = (0.4, 10.0, 500.0);
        let floor = piece_jerk_floor(&bang_bang(d, a, 20_000.0), &[j]);
        let ramp = a / j;
        let s_curve_cost = ramp + (ramp * ramp + 4.0 * d / a).sqrt() - (4.0 * d / a).sqrt();
        assert!(floor <= s_curve_cost, "{floor} > {s_curve_cost}");
        assert!(
            (floor - 8.0 / 9.0 * ramp).abs() < 1e-3 * ramp,
            "{floor} against {}",
            8.0 / 9.0 * ramp
        );
    }

    /// Coarse samples only weaken the bound; no jerk limit, no floor.
    #[test]
    fn floor_shrinks_with_coarse_samples_and_vanishes_without_a_limit() {
        let fine = piece_jerk_floor(&bang_bang(0.4, 10.0, 20_000.0), &[500.0]);
        let coarse = piece_jerk_floor(&bang_bang(0.4, 10.0, 100.0), &[500.0]);
        assert!(coarse <= fine + 1e-12 && coarse > 0.5 * fine);
        assert_eq!(
            piece_jerk_floor(&bang_bang(0.4, 10.0, 100.0), &[f64::INFINITY]),
            0.0
        );
    }
}
