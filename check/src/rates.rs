//! Joint positions, velocities and accelerations of one sub-goal, recomputed
//! from the positions and times alone and checked against the limits, then
//! the file's own velocity and acceleration fields checked against the limits
//! and against the recomputed values, then rest where the arm must rest.
//!
//! Finite differences, interval `i` from sample `i` to `i + 1`,
//! `dt_i = t_(i+1) - t_i`:
//! - mean velocity `v_i = (q_(i+1) - q_i) / dt_i`;
//! - acceleration at sample `i`: `a_i = (v_i - v_(i-1)) / ((dt_(i-1) + dt_i) / 2)`,
//!   twice the second divided difference: for motion whose acceleration
//!   stays within `A` it is a weighted mean of the acceleration, so within `A`;
//! - at the two ends the arm starts and ends at rest (velocity 0), so
//!   `a_0 = v_0 / (dt_0 / 2)` and `a_N = -v_(N-1) / (dt_(N-1) / 2)`: a
//!   trajectory that ends moving needs more than its limit to stop.
//!
//! Consistency of the file's fields: a joint within its acceleration limit
//! `A` has `|v(t_i) - v_i| <= A dt_i / 2` (and the same over the interval
//! before), and its velocity changes by at most `A dt_i` over an interval;
//! its stated acceleration differs from `a_i` by at most `A` (both lie in
//! `[-A, A]`, and `a_i` averages the acceleration around sample `i`).
//! Position limits do not apply to continuous joints.

use std::collections::BTreeMap;

use afford_kinematics::{Joint, JointKind};

use crate::file::Sample;
use crate::report::{ViolationClass, ViolationData};

/// Positions may pass a limit by this much (rad or m): rounding only.
pub const POSITION_TOLERANCE: f64 = 1e-9;
/// Velocities and accelerations may exceed a limit by this fraction.
pub const RATE_TOLERANCE: f64 = 1e-6;
/// Largest velocity or acceleration that counts as zero, and largest
/// position change that counts as none, where the arm must rest.
pub const REST_TOLERANCE: f64 = 1e-9;

/// Which check a finding comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Check {
    Position,
    MeanVelocity,
    FieldVelocity,
    VelocityConsistency,
    FiniteAcceleration,
    VelocityStep,
    FieldAcceleration,
    AccelerationConsistency,
    /// The first or last step too fast to start from or stop at rest.
    StartsMoving,
    EndsMoving,
    /// Velocity or acceleration fields not 0 at the first or last sample.
    StartFields,
    EndFields,
    /// Keyed by the event's index instead of a joint.
    RestEvent,
}

impl Check {
    fn class(self) -> ViolationClass {
        match self {
            Self::Position => ViolationClass::Position,
            Self::MeanVelocity | Self::FieldVelocity | Self::VelocityConsistency => {
                ViolationClass::Velocity
            }
            Self::FiniteAcceleration
            | Self::VelocityStep
            | Self::FieldAcceleration
            | Self::AccelerationConsistency => ViolationClass::Acceleration,
            Self::StartsMoving
            | Self::EndsMoving
            | Self::StartFields
            | Self::EndFields
            | Self::RestEvent => ViolationClass::Rest,
        }
    }
}

/// The worst case of one check on one joint.
#[derive(Debug, Clone)]
struct Worst {
    /// How far beyond what is allowed (ratio or excess, larger = worse).
    badness: f64,
    message: String,
    count: usize,
}

/// Collects the worst case per (check, joint).
#[derive(Default)]
struct Tally(BTreeMap<(Check, usize), Worst>);

impl Tally {
    fn add(&mut self, check: Check, joint: usize, badness: f64, message: impl FnOnce() -> String) {
        let slot = self.0.entry((check, joint)).or_insert(Worst {
            badness: f64::NEG_INFINITY,
            message: String::new(),
            count: 0,
        });
        slot.count += 1;
        if badness > slot.badness {
            slot.badness = badness;
            slot.message = message();
        }
    }
}

/// The arm's joints as the checks need them.
pub(crate) struct ArmJoints<'a> {
    pub joints: Vec<&'a Joint>,
}

fn unit(j: &Joint) -> &'static str {
    match j.kind {
        JointKind::Prismatic => "m",
        _ => "rad",
    }
}

/// Every position, velocity, acceleration and rest finding of one
/// sub-goal. `events` are the gripper events' `[start, end]` windows.
/// Expects a well-formed trajectory (see [`crate::format`]).
pub(crate) fn check(
    arm: &ArmJoints,
    points: &[Sample],
    events: &[(f64, f64)],
) -> Vec<(ViolationClass, String, ViolationData)> {
    let mut tally = Tally::default();
    positions(arm, points, &mut tally);
    for (j, joint) in arm.joints.iter().enumerate() {
        rates(j, joint, points, &mut tally);
        rest(j, joint, points, events, &mut tally);
    }
    tally
        .0
        .into_iter()
        .map(|((check, j), w)| {
            let more = match w.count {
                1 => String::new(),
                n => format!(" ({n} cases in all)"),
            };
            let data = ViolationData {
                // RestEvent is keyed by the gripper event, not a joint.
                joint: (check != Check::RestEvent)
                    .then(|| arm.joints.get(j).map(|joint| joint.name.clone()))
                    .flatten(),
                cases: Some(w.count),
                ..ViolationData::default()
            };
            (check.class(), format!("{}{more}", w.message), data)
        })
        .collect()
}

fn positions(arm: &ArmJoints, points: &[Sample], tally: &mut Tally) {
    for (i, p) in points.iter().enumerate() {
        for (j, joint) in arm.joints.iter().enumerate() {
            if joint.kind == JointKind::Continuous {
                continue;
            }
            let q = p.positions[j];
            let (side, limit, excess) = if q < joint.lower {
                ("lower", joint.lower, joint.lower - q)
            } else {
                ("upper", joint.upper, q - joint.upper)
            };
            if excess > POSITION_TOLERANCE {
                tally.add(Check::Position, j, excess, || {
                    format!(
                        "{} is at {q:.4} {u} at t = {:.3} s (sample {i}), beyond its {side} limit {limit:.4} {u}",
                        joint.name,
                        p.time_from_start,
                        u = unit(joint)
                    )
                });
            }
        }
    }
}

fn rates(j: usize, joint: &Joint, points: &[Sample], tally: &mut Tally) {
    let (vmax, amax, u, name) = (joint.velocity, joint.acceleration, unit(joint), &joint.name);
    let over = |value: f64, limit: f64| value.abs() > limit * (1.0 + RATE_TOLERANCE);
    let n = points.len();
    let t = |i: usize| points[i].time_from_start;
    let dt = |i: usize| t(i + 1) - t(i);
    let mean = |i: usize| (points[i + 1].positions[j] - points[i].positions[j]) / dt(i);
    for i in 0..n - 1 {
        let v = mean(i);
        if over(v, vmax) {
            tally.add(Check::MeanVelocity, j, v.abs() / vmax, || {
                format!(
                    "{name} moves at {v:.4} {u}/s between t = {:.3} s and {:.3} s (samples {i}-{}), limit {vmax:.4} {u}/s (recomputed from positions and times)",
                    t(i),
                    t(i + 1),
                    i + 1
                )
            });
        }
        let step = (points[i + 1].velocities[j] - points[i].velocities[j]) / dt(i);
        if over(step, amax) {
            tally.add(Check::VelocityStep, j, step.abs() / amax, || {
                format!(
                    "{name}'s velocities field changes by {:.4} {u}/s between t = {:.3} s and {:.3} s (samples {i}-{}): {step:.2} {u}/s², limit {amax:.4} {u}/s²",
                    points[i + 1].velocities[j] - points[i].velocities[j],
                    t(i),
                    t(i + 1),
                    i + 1
                )
            });
        }
    }
    for (i, p) in points.iter().enumerate() {
        let (v, a) = (p.velocities[j], p.accelerations[j]);
        if over(v, vmax) {
            tally.add(Check::FieldVelocity, j, v.abs() / vmax, || {
                format!("{name}'s velocities field says {v:.4} {u}/s at t = {:.3} s (sample {i}), limit {vmax:.4} {u}/s", t(i))
            });
        }
        if over(a, amax) {
            tally.add(Check::FieldAcceleration, j, a.abs() / amax, || {
                format!("{name}'s accelerations field says {a:.4} {u}/s² at t = {:.3} s (sample {i}), limit {amax:.4} {u}/s²", t(i))
            });
        }
        let around = [i.checked_sub(1), (i + 1 < n).then_some(i)];
        for k in around.into_iter().flatten() {
            let (vm, allowed) = (
                mean(k),
                amax * dt(k) / 2.0 * (1.0 + RATE_TOLERANCE) + REST_TOLERANCE,
            );
            if (v - vm).abs() > allowed {
                tally.add(Check::VelocityConsistency, j, (v - vm).abs() / allowed, || {
                    format!(
                        "{name}'s velocities field says {v:.4} {u}/s at t = {:.3} s (sample {i}), but its positions move at {vm:.4} {u}/s between samples {k} and {}: within the acceleration limit they differ by at most {allowed:.4} {u}/s",
                        t(i),
                        k + 1
                    )
                });
            }
        }
        let before = if i == 0 { 0.0 } else { mean(i - 1) };
        let after = if i + 1 == n { 0.0 } else { mean(i) };
        let half =
            (if i == 0 { 0.0 } else { dt(i - 1) } + if i + 1 == n { 0.0 } else { dt(i) }) / 2.0;
        let afd = (after - before) / half;
        if (0 < i && i + 1 < n) && over(afd, amax) {
            tally.add(Check::FiniteAcceleration, j, afd.abs() / amax, || {
                format!(
                    "{name} accelerates at {afd:.2} {u}/s² at t = {:.3} s (sample {i}), limit {amax:.4} {u}/s² (recomputed from positions and times)",
                    t(i)
                )
            });
        }
        // The recomputed value averages a(t) over the samples' window, the
        // field is a(t_i): both lie in [-A, A], so they differ by up to 2A
        // where a time-optimal profile switches from +A to -A in the window.
        let allowed = 2.0 * amax * (1.0 + RATE_TOLERANCE) + REST_TOLERANCE;
        if (0 < i && i + 1 < n) && (a - afd).abs() > allowed {
            tally.add(Check::AccelerationConsistency, j, (a - afd).abs() / allowed, || {
                format!(
                    "{name}'s accelerations field says {a:.4} {u}/s² at t = {:.3} s (sample {i}), but its positions give {afd:.4} {u}/s²: they differ by more than twice the limit {amax:.4} {u}/s²",
                    t(i)
                )
            });
        }
    }
}

/// At rest at both ends and during every gripper event. One finding per
/// end and per event (the worst joint named, the count of joints).
fn rest(j: usize, joint: &Joint, points: &[Sample], events: &[(f64, f64)], tally: &mut Tally) {
    let (amax, u, name) = (joint.acceleration, unit(joint), &joint.name);
    let n = points.len();
    let stated = |p: &Sample| p.velocities[j].abs().max(p.accelerations[j].abs());
    let ends = [
        (Check::StartsMoving, Check::StartFields, 0, 0, "start"),
        (Check::EndsMoving, Check::EndFields, n - 1, n - 2, "end"),
    ];
    for (moving, fields, i, k, word) in ends {
        let p = &points[i];
        let dt = points[k + 1].time_from_start - points[k].time_from_start;
        let vm = (points[k + 1].positions[j] - points[k].positions[j]) / dt;
        let needed = vm.abs() / (dt / 2.0);
        if needed > amax * (1.0 + RATE_TOLERANCE) {
            tally.add(moving, 0, needed / amax, || {
                format!(
                    "the arm is moving at its {word}: {name}'s {} step (t = {:.3} s, sample {i}) moves at {vm:.4} {u}/s, which {} rest within the step needs {needed:.2} {u}/s², limit {amax:.4} {u}/s²",
                    if i == 0 { "first" } else { "last" },
                    p.time_from_start,
                    if i == 0 { "from" } else { "to" }
                )
            });
        }
        if stated(p) > REST_TOLERANCE {
            tally.add(fields, 0, stated(p), || {
                format!(
                    "the arm is not at rest at its {word} (t = {:.3} s, sample {i}): {name}'s velocity is {:.4} {u}/s and acceleration {:.4} {u}/s², both must be 0",
                    p.time_from_start, p.velocities[j], p.accelerations[j]
                )
            });
        }
    }
    for (e, &(start, end)) in events.iter().enumerate() {
        let inside = (0..n).filter(|&i| {
            let t = points[i].time_from_start;
            t >= start - REST_TOLERANCE && t <= end + REST_TOLERANCE
        });
        let mut q0 = None;
        for i in inside {
            let p = &points[i];
            let moved = (p.positions[j] - *q0.get_or_insert(p.positions[j])).abs();
            if stated(p) > REST_TOLERANCE || moved > REST_TOLERANCE {
                tally.add(Check::RestEvent, e, moved.max(stated(p)), || {
                    format!(
                        "the arm is not at rest during gripper event {e} [{start:.3} s, {end:.3} s]: at t = {:.3} s (sample {i}) {name} has moved {moved:.6} {u}, velocity {:.4} {u}/s, acceleration {:.4} {u}/s² (all must be 0)",
                        p.time_from_start, p.velocities[j], p.accelerations[j]
                    )
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::file::one_joint_samples;

    fn joint(kind: JointKind) -> Joint {
        Joint {
            name: "j".into(),
            kind,
            lower: -2.0 * std::f64::consts::PI,
            upper: 2.0 * std::f64::consts::PI,
            velocity: 1.0,
            acceleration: 2.0,
            jerk: 100.0,
            effort: 1.0,
        }
    }

    fn still_at(q: f64, times: &[f64]) -> Vec<Sample> {
        one_joint_samples(|_| q, times)
    }

    #[test]
    fn a_continuous_joint_at_7_rad_has_no_position_limit() {
        let samples = still_at(7.0, &[0.0, 0.5, 1.0]);
        let continuous = joint(JointKind::Continuous);
        let found = check(
            &ArmJoints {
                joints: vec![&continuous],
            },
            &samples,
            &[],
        );
        assert!(found.is_empty(), "{found:?}");
        let revolute = joint(JointKind::Revolute);
        let found = check(
            &ArmJoints {
                joints: vec![&revolute],
            },
            &samples,
            &[],
        );
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].0, ViolationClass::Position);
        assert!(
            found[0].1.contains("beyond its upper limit 6.2832"),
            "{}",
            found[0].1
        );
    }

    /// A bang-bang move within the limits passes; the same positions in half
    /// the time need four times the acceleration.
    #[test]
    fn accelerations_are_recomputed_from_positions_and_times() {
        let j = joint(JointKind::Revolute);
        let (a, dt, n) = (2.0, 0.01, 100);
        let times: Vec<f64> = (0..=n).map(|i| i as f64 * dt).collect();
        let half = n as f64 * dt / 2.0;
        let samples: Vec<Sample> = times
            .iter()
            .map(|&t| {
                let (q, v, acc) = match t <= half {
                    true => (a * t * t / 2.0, a * t, a),
                    false => {
                        let r = 2.0 * half - t;
                        (a * half * half - a * r * r / 2.0, a * r, -a)
                    }
                };
                let ends = t == 0.0 || (t - 2.0 * half).abs() < 1e-12;
                Sample {
                    positions: vec![q],
                    velocities: vec![v],
                    accelerations: vec![if ends { 0.0 } else { acc }],
                    time_from_start: t,
                }
            })
            .collect();
        let arm = ArmJoints { joints: vec![&j] };
        assert!(
            check(&arm, &samples, &[]).is_empty(),
            "{:?}",
            check(&arm, &samples, &[])
        );
        let halved: Vec<Sample> = samples
            .iter()
            .map(|s| Sample {
                time_from_start: s.time_from_start / 2.0,
                ..s.clone()
            })
            .collect();
        let found = check(&arm, &halved, &[]);
        assert!(
            found
                .iter()
                .any(|(c, m, _)| *c == ViolationClass::Acceleration && m.contains("recomputed")),
            "{found:?}"
        );
    }
}
