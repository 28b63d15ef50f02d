//! The dense collision check of one phase of a sub-goal: the motion, linear
//! in joint space between samples, is cut into configurations so that no
//! point of any body moves more than [`STEP`] between two checked ones
//! (by the motion bound of [`crate::bodies`]), and at each of them every
//! pair is measured with parry: robot bodies and the held object against
//! the obstacles with their margins, and against each other.
//!
//! Only motion the arm can make is cut so: an interval in which some joint
//! moves faster than its velocity limit (a `velocity` violation already,
//! [`crate::rates`]) is checked at its two samples alone. The work of an
//! interval is then bounded by the velocity limits, not by the values in the
//! file: a single sample at 100 rad on the Care-O-bot's torso asked for
//! some 3 × 10⁵ configurations (minutes of parry queries) before.
//!
//! A pair is skipped at a checked configuration only when it provably keeps
//! its margin there: after a measurement with slack `d - margin`, the pair
//! cannot lose that slack before the two bodies' accumulated motion bounds
//! have grown by it. Every finding is kept per (class, body, other) with its
//! first and its worst configuration.

use std::collections::BTreeMap;

use parry3d::math::Pose as PPose;

use crate::bodies::Body;
use crate::chain::{Kinematics, to_parry};
use crate::rates::RATE_TOLERANCE;
use crate::report::{ViolationClass, ViolationData};
use crate::scene::{Obstacle, Role, signed_distance};

/// Largest motion of any body point between two checked configurations, m.
pub const STEP: f64 = 1e-3;
/// Contacts shallower than this count as touching, not penetrating, m
/// (an object resting on the table at the grasp has distance 0 up to
/// rounding).
pub const CONTACT_TOLERANCE: f64 = 1e-6;
/// Most configurations one sub-goal may need; a motion that needs more is
/// reported as too long to check rather than checked for minutes.
pub const MAX_CONFIGURATIONS: usize = 2_000_000;

/// The other member of a checked pair.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Other {
    Obstacle(usize),
    Body(usize),
}

/// A pair to check, with its margin.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair {
    pub body: usize,
    pub other: Other,
    pub margin: f64,
}

/// One phase of a sub-goal: who is checked against what, along which samples.
pub(crate) struct Phase<'a> {
    pub kin: &'a Kinematics,
    /// Robot bodies, then the held object when there is one.
    pub bodies: &'a [Body],
    pub obstacles: &'a [Obstacle],
    pub pairs: Vec<Pair>,
    /// The whole robot's configuration; `arm` joints are replaced by the samples.
    pub rest: &'a [f64],
    /// Robot joint index of each arm joint.
    pub arm: &'a [usize],
    /// Velocity limit of each arm joint, rad/s or m/s.
    pub speeds: &'a [f64],
    /// Arm positions and times of the phase's samples, in order.
    pub positions: &'a [&'a [f64]],
    pub times: &'a [f64],
    /// Sample index of `positions[0]` in the sub-goal (for messages).
    pub first_sample: usize,
}

/// A finding: one (class, body, other) with its first and worst configuration.
#[derive(Debug, Clone)]
pub(crate) struct Finding {
    pub margin: f64,
    pub first: (f64, usize),
    pub worst: (f64, f64, usize),
    pub count: usize,
}

pub(crate) type Findings = BTreeMap<(ViolationClass, String, String), Finding>;

impl Phase<'_> {
    /// Number of configurations the phase needs (before any work).
    pub(crate) fn configurations(&self) -> usize {
        let mut dq = vec![0.0; self.rest.len()];
        (0..self.positions.len().saturating_sub(1))
            .map(|i| self.substeps(i, &mut dq))
            .sum::<usize>()
            + 1
    }

    /// Configurations checked from sample `i` up to (not including) sample
    /// `i + 1`; `dq` is left holding the interval's joint motion. One (the
    /// sample itself) when the arm cannot make the motion in its time.
    fn substeps(&self, i: usize, dq: &mut [f64]) -> usize {
        let (a, b) = (self.positions[i], self.positions[i + 1]);
        let dt = self.times[i + 1] - self.times[i];
        for (k, &j) in self.arm.iter().enumerate() {
            dq[j] = b[k] - a[k];
        }
        let too_fast = (self.arm.iter().zip(self.speeds))
            .any(|(&j, &vmax)| dq[j].abs() > vmax * (1.0 + RATE_TOLERANCE) * dt);
        if too_fast {
            return 1;
        }
        let bound = self
            .bodies
            .iter()
            .map(|body| body.travel(dq))
            .fold(0.0, f64::max);
        ((bound / STEP).ceil() as usize).max(1)
    }

    /// Runs the phase, adding what it finds to `findings`.
    pub(crate) fn run(&self, findings: &mut Findings) {
        let mut travelled = vec![0.0; self.bodies.len()];
        let mut resume = vec![0.0; self.pairs.len()];
        let mut q = self.rest.to_vec();
        let mut dq = vec![0.0; self.rest.len()];
        for i in 0..self.positions.len() {
            let (a, t0) = (self.positions[i], self.times[i]);
            let Some((&b, &t1)) = self.positions.get(i + 1).zip(self.times.get(i + 1)) else {
                self.set(&mut q, a, a, 0.0);
                self.measure(
                    &q,
                    (t0, self.first_sample + i),
                    &travelled,
                    &mut resume,
                    findings,
                );
                break;
            };
            let n = self.substeps(i, &mut dq);
            for s in 0..n {
                let f = s as f64 / n as f64;
                self.set(&mut q, a, b, f);
                let at = (
                    t0 + f * (t1 - t0),
                    self.first_sample + i + usize::from(2 * s >= n),
                );
                self.measure(&q, at, &travelled, &mut resume, findings);
                for (t, body) in travelled.iter_mut().zip(self.bodies) {
                    *t += body.travel(&dq) / n as f64;
                }
            }
        }
    }

    fn set(&self, q: &mut [f64], a: &[f64], b: &[f64], f: f64) {
        for (k, &j) in self.arm.iter().enumerate() {
            q[j] = a[k] + f * (b[k] - a[k]);
        }
    }

    /// Measures every pair that is due at configuration `q`.
    fn measure(
        &self,
        q: &[f64],
        (t, sample): (f64, usize),
        travelled: &[f64],
        resume: &mut [f64],
        findings: &mut Findings,
    ) {
        let motion = |p: &Pair| {
            travelled[p.body]
                + match p.other {
                    Other::Obstacle(_) => 0.0,
                    Other::Body(b) => travelled[b],
                }
        };
        if !self
            .pairs
            .iter()
            .zip(resume.iter())
            .any(|(p, &r)| motion(p) >= r)
        {
            return;
        }
        let links = self.kin.link_poses(q);
        let poses: Vec<PPose> = self
            .bodies
            .iter()
            .map(|b| to_parry(&(links[b.link] * b.pose_link_shape)))
            .collect();
        for (p, r) in self.pairs.iter().zip(resume.iter_mut()) {
            let moved = motion(p);
            if moved < *r {
                continue;
            }
            let body = &self.bodies[p.body];
            let (d, other, role) = match p.other {
                Other::Obstacle(o) => {
                    let obstacle = &self.obstacles[o];
                    let d = obstacle
                        .parts
                        .iter()
                        .map(|(pose, shape)| {
                            signed_distance(&poses[p.body], &body.shape, pose, shape)
                        })
                        .fold(f64::INFINITY, f64::min);
                    (d, &obstacle.name, Some(obstacle.role))
                }
                Other::Body(b) => {
                    let d = signed_distance(
                        &poses[p.body],
                        &body.shape,
                        &poses[b],
                        &self.bodies[b].shape,
                    );
                    (d, &self.bodies[b].name, None)
                }
            };
            *r = moved + (d - p.margin).max(0.0);
            let class = match role {
                Some(Role::Target) if d < p.margin => ViolationClass::TargetTouched,
                Some(Role::Obstacle | Role::Released) if d < -CONTACT_TOLERANCE => {
                    ViolationClass::Penetration
                }
                Some(Role::Obstacle) if d < p.margin - CONTACT_TOLERANCE => ViolationClass::Margin,
                None if d < -CONTACT_TOLERANCE => ViolationClass::SelfCollision,
                _ => continue,
            };
            let key = (class, body.name.clone(), other.clone());
            let finding = findings.entry(key).or_insert(Finding {
                margin: p.margin,
                first: (t, sample),
                worst: (d, t, sample),
                count: 0,
            });
            finding.count += 1;
            if d < finding.worst.0 {
                finding.worst = (d, t, sample);
            }
        }
    }
}

/// One line per finding: what, how deep, where first and where worst.
/// The typed data of a finding (see [`describe`] for its message).
pub(crate) fn data(
    (_, body, other): &(ViolationClass, String, String),
    f: &Finding,
) -> ViolationData {
    let (d, t, sample) = f.worst;
    ViolationData {
        body: Some(body.clone()),
        other: Some(other.clone()),
        time_s: Some(t),
        sample: Some(sample),
        distance_m: Some(d),
        margin_m: Some(f.margin),
        cases: Some(f.count),
        ..ViolationData::default()
    }
}

pub(crate) fn describe(
    (class, body, other): &(ViolationClass, String, String),
    f: &Finding,
) -> String {
    let (d, t, sample) = f.worst;
    let mm = |x: f64| x * 1e3;
    let what = match class {
        ViolationClass::Penetration => format!("{body} is {:.1} mm inside {other}", mm(-d)),
        ViolationClass::SelfCollision => format!("{body} is {:.1} mm inside {other}", mm(-d)),
        ViolationClass::Margin => format!(
            "{body} comes within {:.1} mm of {other}, inside its {:.1} mm margin",
            mm(d),
            mm(f.margin)
        ),
        _ if d < 0.0 => format!(
            "{body} is {:.1} mm inside the target {other} before the grasp (only the fingers may come within {:.1} mm)",
            mm(-d),
            mm(f.margin)
        ),
        _ => format!(
            "{body} comes within {:.1} mm of the target {other} before the grasp (only the fingers may come within {:.1} mm)",
            mm(d),
            mm(f.margin)
        ),
    };
    format!(
        "{what} at t = {t:.3} s (sample {sample}); first at t = {:.3} s (sample {}), {} checked configurations",
        f.first.0, f.first.1, f.count
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bodies::robot_bodies;
    use afford_kinematics::RobotModel;

    /// The configurations the Care-O-bot's right arm (torso included) needs
    /// for three samples 10 ms apart whose middle one has the torso at
    /// `torso` rad.
    fn configurations_through(torso: f64, dt: f64) -> usize {
        let model = RobotModel::builtin("care_o_bot4").unwrap();
        let kin = Kinematics::new(&model).unwrap();
        let bodies = robot_bodies(&model, &kin).unwrap();
        let arm = model.arm("right").unwrap();
        let rest = model.home().to_vec();
        let start: Vec<f64> = arm.joint_indices.iter().map(|&j| rest[j]).collect();
        let mut middle = start.clone();
        let torso_at = (arm.joint_names.iter())
            .position(|n| n == "torso_2_joint")
            .unwrap();
        middle[torso_at] = torso;
        let positions: [&[f64]; 3] = [&start, &middle, &start];
        let speeds: Vec<f64> = (arm.joint_indices.iter())
            .map(|&j| model.joints()[j].velocity)
            .collect();
        let phase = Phase {
            kin: &kin,
            bodies: &bodies,
            obstacles: &[],
            pairs: Vec::new(),
            rest: &rest,
            arm: &arm.joint_indices,
            speeds: &speeds,
            positions: &positions,
            times: &[0.0, dt, 2.0 * dt],
            first_sample: 0,
        };
        phase.configurations()
    }

    /// A torso sample at 100 rad 10 ms from its neighbours is a jump no arm
    /// makes: checked at its three samples, not cut into the ~3 × 10⁵
    /// millimetre steps its size asked for (minutes of parry queries).
    #[test]
    fn a_joint_jump_the_arm_cannot_make_is_checked_at_its_samples_only() {
        assert_eq!(configurations_through(100.0, 0.01), 3);
    }

    /// Motion within the velocity limits is still cut into millimetre steps:
    /// 0.5 rad of torso over 1 s (limit 1.4 rad/s) moves the arm's far end
    /// by decimetres.
    #[test]
    fn motion_within_the_velocity_limits_is_checked_at_millimetre_steps() {
        let n = configurations_through(0.5, 1.0);
        assert!(n > 200, "{n} configurations");
    }
}
