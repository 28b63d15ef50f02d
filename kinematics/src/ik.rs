//! Inverse kinematics of one arm: damped least squares (Levenberg-Marquardt)
//! with hard joint limits and a posture task in the null space.
//!
//! Each iteration, with `e` the weighted task error (position, and rotation
//! scaled by `orientation_length`), `J` the matching Jacobian rows and
//! `z = k (q_posture - q)` the posture step:
//!
//! ```text
//! lambda = damping + |e|^2 / 2                       (Sugihara's LM damping)
//! dq     = z + J^T (J J^T + lambda I)^-1 (e - J z)
//! q      = clamp(q + dq)  -- joints that hit a limit are frozen and the step re-solved
//! ```
//!
//! A continuous joint's limits are -inf/+inf, so it is never clamped or frozen.
//!
//! Top-down grasps with free yaw drop the rotation about the tool axis from the
//! task (5-D), so that freedom joins the null space. Unseeded solves start at
//! home, then at random in-limit configurations drawn from the caller's RNG;
//! seeded solves start at the seed and, by default, never restart (branch stays).
//! Failures are diagnosed (out of reach, joint limit, singular, not converged).

use nalgebra::{Matrix6, Matrix6xX, Vector6};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::chain::MAX_DOF;
use crate::error::{IkFailure, KinematicsError};
use crate::math::{Pose, Real, Vec3, direction_error, rotation_error, top_down_rotation};
use crate::model::Arm;

/// What the tool must reach, in the robot base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IkTarget {
    /// Full 6-D tool pose.
    Pose(Pose),
    /// Tool at `position`, approach axis (+z) straight down; yaw (rotation of
    /// the tool x axis about the vertical) fixed, or free when `None`.
    TopDown { position: Vec3, yaw: Option<Real> },
}

impl IkTarget {
    /// Target tool position.
    pub fn position(&self) -> Vec3 {
        match self {
            IkTarget::Pose(p) => p.translation.vector,
            IkTarget::TopDown { position, .. } => *position,
        }
    }

    /// Position error (m) and rotation error (rad) of a tool pose against the
    /// target. With free yaw the rotation error is the tilt of the tool axis.
    pub fn error(&self, pose: &Pose) -> (Real, Real) {
        let dp = (self.position() - pose.translation.vector).norm();
        let dr = match self {
            IkTarget::Pose(p) => pose.rotation.angle_to(&p.rotation),
            IkTarget::TopDown { yaw: Some(y), .. } => {
                pose.rotation.angle_to(&top_down_rotation(*y))
            }
            IkTarget::TopDown { yaw: None, .. } => {
                let z = pose.rotation * Vec3::z();
                direction_error(&z, &-Vec3::z()).norm()
            }
        };
        (dp, dr)
    }

    fn is_finite(&self) -> bool {
        match self {
            IkTarget::Pose(p) => {
                p.translation.vector.iter().all(|v| v.is_finite())
                    && p.rotation.coords.iter().all(|v| v.is_finite())
            }
            IkTarget::TopDown { position, yaw } => {
                position.iter().all(|v| v.is_finite()) && yaw.is_none_or(|y| y.is_finite())
            }
        }
    }
}

/// IK parameters. Defaults are written once, in `Default`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IkSettings {
    /// Converged when the tool is this close (m).
    pub position_tolerance: Real,
    /// ... and this well aligned (rad).
    pub rotation_tolerance: Real,
    /// Iterations per attempt.
    pub max_iterations: usize,
    /// Random restarts after the first attempt (unseeded solves).
    pub restarts: usize,
    /// Whether a seeded solve may restart elsewhere (may change branch).
    pub restart_when_seeded: bool,
    /// Posture (null-space) gain per iteration of the redundancy phase, 0..1.
    pub posture_gain: Real,
    /// Iterations of the redundancy phase after convergence (0 = off).
    pub posture_iterations: usize,
    /// Constant part of the LM damping (m^2).
    pub damping: Real,
    /// Largest joint change per iteration (rad or m).
    pub max_step: Real,
    /// Length (m) that turns rotation errors (rad) into distances.
    pub orientation_length: Real,
}

impl Default for IkSettings {
    fn default() -> Self {
        Self {
            position_tolerance: 1e-5,
            rotation_tolerance: 1e-4,
            max_iterations: 80,
            restarts: 40,
            restart_when_seeded: false,
            posture_gain: 0.3,
            posture_iterations: 15,
            damping: 1e-5,
            max_step: 0.4,
            orientation_length: 0.2,
        }
    }
}

impl IkSettings {
    /// Checks every field; names the first bad one.
    pub fn validate(&self) -> Result<(), KinematicsError> {
        let bad = |field: &'static str, problem: &str| {
            Err(KinematicsError::Settings {
                field,
                problem: problem.to_string(),
            })
        };
        let pos = |v: Real| v.is_finite() && v > 0.0;
        if !pos(self.position_tolerance) {
            return bad("position_tolerance", "must be positive");
        }
        if !pos(self.rotation_tolerance) {
            return bad("rotation_tolerance", "must be positive");
        }
        if self.max_iterations == 0 {
            return bad("max_iterations", "must be at least 1");
        }
        if !(self.posture_gain.is_finite() && (0.0..1.0).contains(&self.posture_gain)) {
            return bad("posture_gain", "must lie in [0, 1)");
        }
        if !pos(self.damping) {
            return bad("damping", "must be positive");
        }
        if !pos(self.max_step) {
            return bad("max_step", "must be positive");
        }
        if !pos(self.orientation_length) {
            return bad("orientation_length", "must be positive");
        }
        Ok(())
    }
}

/// A solved configuration of one arm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IkSolution {
    /// Arm joint values, base to tool; inside the limits.
    pub q: Vec<Real>,
    pub position_error: Real,
    pub rotation_error: Real,
    /// Iterations over all attempts.
    pub iterations: usize,
    /// Attempts used (1 = first start converged).
    pub attempts: usize,
}

/// How one attempt is run.
#[derive(Clone, Copy)]
struct Mode {
    limits: bool,
    position_only: bool,
}

struct Attempt {
    q: Vec<Real>,
    converged: bool,
    cost: Real,
    iterations: usize,
}

struct Solver<'a> {
    arm: &'a Arm,
    target: IkTarget,
    s: &'a IkSettings,
    jac: Matrix6xX<Real>,
    /// Target rotation for 6-D modes.
    rotation: Option<crate::math::Rotation>,
}

impl<'a> Solver<'a> {
    fn new(arm: &'a Arm, target: IkTarget, s: &'a IkSettings) -> Self {
        let rotation = match target {
            IkTarget::Pose(p) => Some(p.rotation),
            IkTarget::TopDown { yaw: Some(y), .. } => Some(top_down_rotation(y)),
            IkTarget::TopDown { yaw: None, .. } => None,
        };
        Self {
            arm,
            target,
            s,
            jac: Matrix6xX::zeros(arm.dof()),
            rotation,
        }
    }

    /// Weighted error, position and rotation errors, and the tool axis when
    /// the rotation about it is free. Fills `self.jac` (weighted rows).
    fn linearise(&mut self, q: &[Real], mode: Mode) -> (Vector6<Real>, Real, Real, Option<Vec3>) {
        let pose = self.arm.chain.fk_jacobian(q, &mut self.jac);
        let ep = self.target.position() - pose.translation.vector;
        let (er, free_axis) = match self.rotation {
            Some(r) => (rotation_error(&pose.rotation, &r), None),
            None => {
                let a = pose.rotation * Vec3::z();
                (direction_error(&a, &-Vec3::z()), Some(a))
            }
        };
        let l = self.s.orientation_length;
        if mode.position_only {
            for mut col in self.jac.column_iter_mut() {
                col[3] = 0.0;
                col[4] = 0.0;
                col[5] = 0.0;
            }
        } else {
            for mut col in self.jac.column_iter_mut() {
                let mut w = Vec3::new(col[3], col[4], col[5]);
                if let Some(a) = free_axis {
                    w -= a * a.dot(&w);
                }
                col[3] = l * w.x;
                col[4] = l * w.y;
                col[5] = l * w.z;
            }
        }
        let er_w = if mode.position_only {
            Vec3::zeros()
        } else {
            er * l
        };
        let e = Vector6::new(ep.x, ep.y, ep.z, er_w.x, er_w.y, er_w.z);
        (e, ep.norm(), er.norm(), free_axis)
    }

    fn converged(&self, ep: Real, er: Real, mode: Mode) -> bool {
        ep < self.s.position_tolerance && (mode.position_only || er < self.s.rotation_tolerance)
    }

    fn run(&mut self, start: &[Real], posture: &[Real], mode: Mode) -> Attempt {
        let mut a = self.converge(start, posture, 0.0, mode, self.s.max_iterations);
        if a.converged && self.s.posture_gain > 0.0 && self.s.posture_iterations > 0 {
            // Redundancy resolution: slide along the solution set towards the posture.
            let refined = self.converge(
                &a.q,
                posture,
                self.s.posture_gain,
                mode,
                self.s.posture_iterations,
            );
            let polished = self.converge(&refined.q, posture, 0.0, mode, 10);
            if polished.converged {
                a.q = polished.q;
                a.cost = polished.cost;
                a.iterations += refined.iterations + polished.iterations;
            }
        }
        a
    }

    /// The LM iteration; with `gain > 0` it keeps going until the posture step
    /// is small (or `max_iterations`), otherwise it stops at convergence.
    fn converge(
        &mut self,
        start: &[Real],
        posture: &[Real],
        gain: Real,
        mode: Mode,
        max_iterations: usize,
    ) -> Attempt {
        let n = self.arm.dof();
        let (lo, hi) = (&self.arm.lower, &self.arm.upper);
        let mut q = [0.0; MAX_DOF];
        q[..n].copy_from_slice(start);
        if mode.limits {
            for i in 0..n {
                q[i] = q[i].clamp(lo[i], hi[i]);
            }
        }
        let mut best_cost = Real::INFINITY;
        let mut since_best = 0;
        for it in 0..max_iterations {
            let (e, ep, er, free_axis) = self.linearise(&q[..n], mode);
            let cost = e.norm();
            let posture_done =
                gain == 0.0 || (0..n).all(|i| (gain * (posture[i] - q[i])).abs() < 1e-4);
            if self.converged(ep, er, mode) && posture_done {
                return Attempt {
                    q: q[..n].to_vec(),
                    converged: true,
                    cost,
                    iterations: it,
                };
            }
            if gain > 0.0 {
                // Posture phase: no stall test.
            } else if cost < best_cost * 0.999 {
                best_cost = cost;
                since_best = 0;
            } else {
                since_best += 1;
                if since_best > 12 {
                    return Attempt {
                        q: q[..n].to_vec(),
                        converged: false,
                        cost,
                        iterations: it,
                    };
                }
            }
            let lambda = self.s.damping + 0.5 * cost * cost;
            let mut free = [true; MAX_DOF];
            let mut dq = [0.0; MAX_DOF];
            // Clamping loop: frozen joints keep their clamped step, the rest re-solve.
            for _pass in 0..3 {
                let mut z = [0.0; MAX_DOF];
                let mut r = e;
                for i in 0..n {
                    z[i] = if free[i] {
                        gain * (posture[i] - q[i])
                    } else {
                        dq[i]
                    };
                    let col = self.jac.column(i);
                    r -= col * z[i];
                }
                let mut a = Matrix6::<Real>::identity() * lambda;
                for i in (0..n).filter(|&i| free[i]) {
                    let col = self.jac.column(i);
                    a += col * col.transpose();
                }
                if let Some(ax) = free_axis {
                    // The free rotation about the tool axis has no Jacobian rows: pin it.
                    let l2 = self.s.orientation_length * self.s.orientation_length;
                    for (r_, c_) in [
                        (0, 0),
                        (0, 1),
                        (0, 2),
                        (1, 0),
                        (1, 1),
                        (1, 2),
                        (2, 0),
                        (2, 1),
                        (2, 2),
                    ] {
                        a[(3 + r_, 3 + c_)] += l2 * ax[r_] * ax[c_];
                    }
                }
                let y = match a.cholesky() {
                    Some(c) => c.solve(&r),
                    None => Vector6::zeros(),
                };
                for i in 0..n {
                    dq[i] = if free[i] {
                        z[i] + self.jac.column(i).dot(&y)
                    } else {
                        z[i]
                    };
                }
                // Trust region on the joint step.
                let biggest = dq[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
                if biggest > self.s.max_step {
                    let k = self.s.max_step / biggest;
                    dq[..n].iter_mut().for_each(|v| *v *= k);
                }
                if !mode.limits {
                    break;
                }
                let mut newly_frozen = false;
                for i in 0..n {
                    let t = q[i] + dq[i];
                    if free[i] && (t < lo[i] || t > hi[i]) {
                        dq[i] = t.clamp(lo[i], hi[i]) - q[i];
                        free[i] = false;
                        newly_frozen = true;
                    }
                }
                if !newly_frozen {
                    break;
                }
            }
            for i in 0..n {
                q[i] += dq[i];
                if mode.limits {
                    q[i] = q[i].clamp(lo[i], hi[i]);
                }
            }
        }
        let (e, ep, er, _) = self.linearise(&q[..n], mode);
        Attempt {
            q: q[..n].to_vec(),
            converged: self.converged(ep, er, mode),
            cost: e.norm(),
            iterations: max_iterations,
        }
    }
}

/// A random in-limit configuration of the arm, uniform over each joint's
/// range. A continuous joint (no limits) is drawn within +-pi of its home
/// value: one full turn, every orientation of the joint once.
pub fn random_configuration(arm: &Arm, rng: &mut impl Rng) -> Vec<Real> {
    arm.lower
        .iter()
        .zip(&arm.upper)
        .zip(&arm.home)
        .map(
            |((&lo, &hi), &home)| match lo.is_finite() && hi.is_finite() {
                true => rng.random_range(lo..=hi),
                false => home + rng.random_range(-std::f64::consts::PI..=std::f64::consts::PI),
            },
        )
        .collect()
}

impl Arm {
    /// Solves IK for `target`. With a seed, starts there and stays on its
    /// branch (no restarts unless `restart_when_seeded`); without one, starts
    /// at home and restarts from random configurations drawn from `rng`.
    /// Returned joint values are always within the limits and meet the
    /// tolerances; otherwise the failure says why.
    pub fn solve_ik(
        &self,
        target: &IkTarget,
        seed: Option<&[Real]>,
        settings: &IkSettings,
        rng: &mut impl Rng,
    ) -> Result<IkSolution, IkFailure> {
        if !target.is_finite() {
            return Err(IkFailure::InvalidRequest {
                reason: "target holds a non-finite number",
            });
        }
        if let Some(s) = seed
            && (s.len() != self.dof() || s.iter().any(|v| !v.is_finite()))
        {
            return Err(IkFailure::InvalidRequest {
                reason: "seed must hold one finite value per arm joint",
            });
        }
        let distance = (target.position() - self.reach_centre()).norm();
        if distance > self.reach {
            return Err(IkFailure::OutOfReach {
                position_error: distance - self.reach,
            });
        }
        let mut solver = Solver::new(self, *target, settings);
        let limited = Mode {
            limits: true,
            position_only: false,
        };
        let (first, posture): (Vec<Real>, Vec<Real>) = match seed {
            Some(s) => (s.to_vec(), s.to_vec()),
            None => (self.home.clone(), self.home.clone()),
        };
        let restarts = if seed.is_some() && !settings.restart_when_seeded {
            0
        } else {
            settings.restarts
        };
        let mut iterations = 0;
        let mut best: Option<Attempt> = None;
        for attempt in 0..=restarts {
            let start = if attempt == 0 {
                first.clone()
            } else if attempt == 1 && seed.is_some() {
                self.home.clone()
            } else {
                random_configuration(self, rng)
            };
            let result = solver.run(&start, &posture, limited);
            iterations += result.iterations;
            if result.converged {
                let pose = self.fk(&result.q);
                let (position_error, rotation_error) = target.error(&pose);
                debug_assert!(self.within_limits(&result.q, 0.0));
                return Ok(IkSolution {
                    q: result.q,
                    position_error,
                    rotation_error,
                    iterations,
                    attempts: attempt + 1,
                });
            }
            if best.as_ref().is_none_or(|b| result.cost < b.cost) {
                best = Some(result);
            }
        }
        let best = best.expect("at least one attempt ran");
        Err(diagnose(&mut solver, &best, restarts + 1))
    }
}

/// Why the attempts failed. Relax the joint limits and solve again from the
/// best attempt and from home: if that fails too, the target is out of reach;
/// if it succeeds outside the limits, a joint limit is in the way; if it
/// succeeds inside them, the limited solver was stuck (singular or not converged).
fn diagnose(solver: &mut Solver<'_>, best: &Attempt, attempts: usize) -> IkFailure {
    let arm = solver.arm;
    let unlimited_mode = Mode {
        limits: false,
        position_only: false,
    };
    let mut closest: Option<Attempt> = None;
    for start in [best.q.clone(), arm.home.clone()] {
        let a = solver.run(&start, &start, unlimited_mode);
        if a.converged {
            closest = Some(a);
            break;
        }
        if closest.as_ref().is_none_or(|c| a.cost < c.cost) {
            closest = Some(a);
        }
    }
    let unlimited = closest.expect("two relaxed attempts ran");
    if !unlimited.converged {
        let (_, ep, _, _) = solver.linearise(&unlimited.q, unlimited_mode);
        return IkFailure::OutOfReach { position_error: ep };
    }
    let outside = |k: usize| (arm.lower[k] - unlimited.q[k]).max(unlimited.q[k] - arm.upper[k]);
    let worst = (0..arm.dof())
        .max_by(|&i, &j| outside(i).total_cmp(&outside(j)))
        .unwrap_or(0);
    if outside(worst) > 0.0 {
        return IkFailure::JointLimit {
            joint: arm.joint_names[worst].clone(),
        };
    }
    let limited = Mode {
        limits: true,
        position_only: false,
    };
    let (_, ep, er, _) = solver.linearise(&best.q, limited);
    let sigma_min = solver.jac.clone().svd(false, false).singular_values.min();
    if sigma_min < 1e-3 {
        return IkFailure::Singular { sigma_min };
    }
    IkFailure::NotConverged {
        attempts,
        position_error: ep,
        rotation_error: er,
    }
}
