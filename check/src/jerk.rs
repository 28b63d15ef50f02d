//! Joint jerk of one sub-goal, recomputed from the positions and times
//! alone and checked against each joint's jerk limit (the robot
//! description's `jerk_limits`, else URDF 1.2 `<limit jerk>`, else the
//! documented default; `afford_kinematics::Joint::jerk`).
//!
//! For four consecutive samples `t_0 < t_1 < t_2 < t_3` the jerk is six
//! times the third divided difference,
//!
//! ```text
//! j = 6 Σ_i q_i / Π_{k≠i} (t_i − t_k)
//! ```
//!
//! the jerk of the cubic through the four points. For motion whose
//! acceleration is continuous with its jerk within `J` it is a weighted mean
//! of the jerk over `[t_0, t_3]` (the Peano kernel of a divided difference
//! is a non-negative B-spline of unit integral), so within `J` at any
//! sampling; an acceleration that jumps between two samples shows as
//! `Δa / (t_3 − t_0)` times a factor of order one. The arm rests before
//! the first sample and after the last (it starts and ends at rest), so two
//! samples at rest, a step apart, are added at each end: a trajectory that
//! starts or stops with a step of acceleration is caught too.

use afford_kinematics::JointKind;

use crate::file::Sample;
use crate::rates::{ArmJoints, RATE_TOLERANCE};
use crate::report::{ViolationClass, ViolationData};

/// Every joint whose recomputed jerk exceeds its limit: one finding per
/// joint, at its worst window, with the number of windows over the limit.
/// Expects a well-formed trajectory (times strictly increasing).
pub(crate) fn check(
    arm: &ArmJoints,
    points: &[Sample],
) -> Vec<(ViolationClass, String, ViolationData)> {
    let n = points.len();
    if n < 2 {
        return Vec::new();
    }
    // Sample times with two rest samples before and after; `source(k)` is
    // the real sample whose positions the padded sample `k` holds.
    let (first, last) = (
        points[1].time_from_start - points[0].time_from_start,
        points[n - 1].time_from_start - points[n - 2].time_from_start,
    );
    let start = points[0].time_from_start;
    let end = points[n - 1].time_from_start;
    let mut times = vec![start - 2.0 * first, start - first];
    times.extend(points.iter().map(|p| p.time_from_start));
    times.extend([end + last, end + 2.0 * last]);
    let source = |k: usize| k.clamp(2, n + 1) - 2;
    let mut found = Vec::new();
    for (j, joint) in arm.joints.iter().enumerate() {
        let limit = joint.jerk;
        let mut worst: Option<(f64, usize)> = None;
        let mut cases = 0;
        for k in 0..times.len() - 3 {
            let window = &times[k..k + 4];
            let jerk: f64 = 6.0
                * (0..4)
                    .map(|i| {
                        let denominator: f64 = (0..4)
                            .filter(|&m| m != i)
                            .map(|m| window[i] - window[m])
                            .product();
                        points[source(k + i)].positions[j] / denominator
                    })
                    .sum::<f64>();
            if jerk.abs() > limit * (1.0 + RATE_TOLERANCE) {
                cases += 1;
                if worst.is_none_or(|(w, _)| jerk.abs() > w.abs()) {
                    worst = Some((jerk, k));
                }
            }
        }
        let Some((jerk, k)) = worst else {
            continue;
        };
        let (from, to) = (source(k), source(k + 3));
        let time = 0.5 * (times[k + 1] + times[k + 2]);
        let unit = match joint.kind {
            JointKind::Prismatic => "m",
            _ => "rad",
        };
        let more = match cases {
            1 => String::new(),
            n => format!(" ({n} cases in all)"),
        };
        found.push((
            ViolationClass::Jerk,
            format!(
                "{} jerks at {jerk:.1} {unit}/s³ around t = {time:.3} s (samples {from}-{to}), limit {limit:.1} {unit}/s³ (recomputed from positions and times){more}",
                joint.name
            ),
            ViolationData {
                joint: Some(joint.name.clone()),
                time_s: Some(time),
                sample: Some(from),
                cases: Some(cases),
                ..ViolationData::default()
            },
        ));
    }
    found
}

#[cfg(test)]
mod tests {
    use afford_kinematics::Joint;

    use super::*;
    use crate::file::one_joint_samples;

    fn joint() -> Joint {
        Joint {
            name: "j".into(),
            kind: JointKind::Revolute,
            lower: -10.0,
            upper: 10.0,
            velocity: 10.0,
            acceleration: 10.0,
            jerk: 100.0,
            effort: 1.0,
        }
    }

    /// A rest-to-rest move whose jerk is ±90 rad/s³ (the smoothest
    /// polynomial, `q = d (10u³ − 15u⁴ + 6u⁵)`, peak jerk `60 d / T³`)
    /// passes at any sampling; the same positions in half the time have
    /// eight times the jerk.
    #[test]
    fn jerk_is_recomputed_from_positions_and_times() {
        let (d, duration) = (1.5, 1.0);
        let q = |t: f64| {
            let u = t / duration;
            d * (10.0 * u.powi(3) - 15.0 * u.powi(4) + 6.0 * u.powi(5))
        };
        let times: Vec<f64> = (0..=100).map(|i| i as f64 * 0.01).chain([1.0]).collect();
        let mut times = times;
        times.dedup();
        let j = joint();
        let arm = ArmJoints { joints: vec![&j] };
        let found = check(&arm, &one_joint_samples(q, &times));
        assert!(found.is_empty(), "{found:?}");
        let fast: Vec<f64> = times.iter().map(|t| t / 2.0).collect();
        let found = check(&arm, &one_joint_samples(|t| q(2.0 * t), &fast));
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].0, ViolationClass::Jerk);
        assert!(found[0].1.starts_with("j jerks at"), "{}", found[0].1);
    }
}
