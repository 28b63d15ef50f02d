//! Jerk limits: the time-optimal trajectory averaged over a moving window
//! of `τ` seconds (a FIR filter in time, after Biagiotti & Melchiorri,
//! "FIR filters for online trajectory planning with time- and
//! frequency-domain specifications", Control Eng. Practice 2012).
//!
//! The timed path `q(t)`, `t ∈ [0, T]`, rests at both ends and keeps
//! `|q̈_j| ≤ A_j` everywhere (the program bounds whole segments), but its
//! acceleration jumps wherever the path acceleration switches. Held at its
//! end values outside `[0, T]`, it becomes
//!
//! ```text
//! q̃(t) = (1/τ) ∫_{t−τ}^{t} q(u) du,        t ∈ [0, T + τ]
//! q̃̇(t) = (q(t) − q(t−τ)) / τ,   q̃̈(t) = (q̇(t) − q̇(t−τ)) / τ,   q̃⃛(t) = (q̈(t) − q̈(t−τ)) / τ
//! ```
//!
//! An average keeps every convex bound, so positions, velocities and
//! accelerations stay within the limits the unfiltered trajectory keeps,
//! the ends stay at rest, and the jerk is at most `2A_j/τ` — within the
//! jerk limit `J_j` for `τ ≥ 2A_j/J_j` whatever the profile. The motion
//! lasts `τ` longer and cuts the path's corners by `O(A τ²)` (below a
//! millimetre of tool at the defaults; the tool-path check of every sample
//! still applies). [`filter_width`] takes the smallest `τ` of a few
//! candidates up to that bound whose jerk `|q̈(t) − q̈(t−τ)|/τ` stays within
//! the limits on a dense set of times; the sampled trajectory's jerk is
//! then checked ([`sample_jerk`], third divided differences of positions
//! and times, as the independent check recomputes it) and a failure falls
//! back to the bound.
//!
//! Positions are exact: on each grid segment `s(t)` is quadratic and the
//! path cubic, so `q(t)` is a polynomial of degree ≤ 6 and the 4-point
//! Gauss–Legendre rule integrates it exactly.

use super::profile::SpeedProfile;
use super::spline::PiecewiseCubic;

/// Gauss–Legendre nodes and weights on `[0, 1]`, 4 points (exact to degree 7).
const GAUSS: [(f64, f64); 4] = [
    (0.069_431_844_202_973_7, 0.173_927_422_568_726_9),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_1),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_1),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_9),
];

/// Candidate widths tried, as fractions of the bound `max_j 2A_j/J_j`.
const CANDIDATES: usize = 32;

/// The timed path averaged over `τ` seconds.
pub struct Filtered<'a> {
    path: &'a PiecewiseCubic,
    profile: &'a SpeedProfile,
    tau: f64,
    /// `∫_0^{t_i} q_j du` at every grid time, `integral[i * dim + j]`.
    integral: Vec<f64>,
    /// The path at `s = 0` and `s = L`.
    ends: (Vec<f64>, Vec<f64>),
}

/// Position, velocity and acceleration of every joint at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub q: Vec<f64>,
    pub dq: Vec<f64>,
    pub ddq: Vec<f64>,
}

impl State {
    fn zeros(dim: usize) -> Self {
        Self {
            q: vec![0.0; dim],
            dq: vec![0.0; dim],
            ddq: vec![0.0; dim],
        }
    }
}

impl<'a> Filtered<'a> {
    /// The timed path `profile` on `path`, averaged over `tau ≥ 0` seconds
    /// (`tau = 0`: the timed path itself).
    pub fn new(path: &'a PiecewiseCubic, profile: &'a SpeedProfile, tau: f64) -> Self {
        let dim = path.dim();
        let mut this = Self {
            path,
            profile,
            tau,
            integral: Vec::new(),
            ends: (vec![0.0; dim], vec![0.0; dim]),
        };
        let mut scratch = State::zeros(dim);
        this.raw(0.0, &mut scratch);
        this.ends.0 = scratch.q.clone();
        this.raw(profile.duration(), &mut scratch);
        this.ends.1 = scratch.q.clone();
        if tau > 0.0 {
            let segments = profile.t.len() - 1;
            let mut integral = vec![0.0; (segments + 1) * dim];
            let mut part = vec![0.0; dim];
            for i in 0..segments {
                this.segment_integral(i, profile.t[i + 1], &mut part, &mut scratch);
                for j in 0..dim {
                    integral[(i + 1) * dim + j] = integral[i * dim + j] + part[j];
                }
            }
            this.integral = integral;
        }
        this
    }

    /// The filter's width `τ`, seconds.
    pub fn tau(&self) -> f64 {
        self.tau
    }

    /// `T + τ`, seconds.
    pub fn duration(&self) -> f64 {
        self.profile.duration() + self.tau
    }

    /// The unfiltered path parameter at time `t` (0 before the start, `L`
    /// after the end).
    pub fn s_at(&self, t: f64) -> f64 {
        self.path_state(t).0
    }

    /// `(s, ṡ, s̈)` of the unfiltered profile, at rest outside `[0, T]`.
    fn path_state(&self, t: f64) -> (f64, f64, f64) {
        if t <= 0.0 {
            (0.0, 0.0, 0.0)
        } else if t >= self.profile.duration() {
            (self.path.length(), 0.0, 0.0)
        } else {
            let (s, s_dot, s_ddot, _) = self.profile.state_at(t);
            (s, s_dot, s_ddot)
        }
    }

    /// The unfiltered state at `t`.
    fn raw(&self, t: f64, out: &mut State) {
        let (s, s_dot, s_ddot) = self.path_state(t);
        let State { q, dq, ddq } = out;
        self.path.eval(s, q, dq, ddq);
        for j in 0..q.len() {
            let (d1, d2) = (dq[j], ddq[j]);
            dq[j] = d1 * s_dot;
            ddq[j] = d2 * s_dot * s_dot + d1 * s_ddot;
        }
    }

    /// `∫_{t_i}^{t} q du` for `t` in grid segment `i` (exact, see the module docs).
    fn segment_integral(&self, i: usize, t: f64, out: &mut [f64], scratch: &mut State) {
        let t0 = self.profile.t[i];
        let h = t - t0;
        out.fill(0.0);
        for (x, w) in GAUSS {
            self.raw(t0 + x * h, scratch);
            for (o, q) in out.iter_mut().zip(&scratch.q) {
                *o += w * h * q;
            }
        }
    }

    /// `∫_0^t q du` of every joint (the path held at its ends outside `[0, T]`).
    fn antiderivative(&self, t: f64, out: &mut [f64], scratch: &mut State) {
        let dim = out.len();
        let duration = self.profile.duration();
        if t <= 0.0 {
            out.iter_mut()
                .zip(&self.ends.0)
                .for_each(|(o, q)| *o = q * t);
        } else if t >= duration {
            let last = &self.integral[(self.profile.t.len() - 1) * dim..];
            for ((o, integral), q) in out.iter_mut().zip(last).zip(&self.ends.1) {
                *o = integral + q * (t - duration);
            }
        } else {
            let i = (self.profile.t.partition_point(|&ti| ti <= t).max(1) - 1)
                .min(self.profile.t.len() - 2);
            self.segment_integral(i, t, out, scratch);
            for (o, integral) in out.iter_mut().zip(&self.integral[i * dim..]) {
                *o += integral;
            }
        }
    }

    /// The filtered state at `t ∈ [0, T + τ]`.
    pub fn state(&self, t: f64, out: &mut State, scratch: &mut (State, State)) {
        if self.tau <= 0.0 {
            self.raw(t, out);
            return;
        }
        let (now, before) = scratch;
        self.raw(t, now);
        self.raw(t - self.tau, before);
        let inv = 1.0 / self.tau;
        for j in 0..out.q.len() {
            out.dq[j] = (now.q[j] - before.q[j]) * inv;
            out.ddq[j] = (now.dq[j] - before.dq[j]) * inv;
        }
        // `before` is spent: its buffers hold the two antiderivatives.
        let State {
            q: upper,
            dq: lower,
            ..
        } = before;
        self.antiderivative(t, upper, now);
        self.antiderivative(t - self.tau, lower, now);
        for j in 0..out.q.len() {
            out.q[j] = (upper[j] - lower[j]) * inv;
        }
    }
}

/// The filter width: 0 without jerk limits; else the smallest of
/// [`CANDIDATES`] widths up to `max_j 2A_j/J_j` (`acceleration` as the
/// program bounded it, rad/s²; `jerk` in rad/s³) for which
/// `|q̈_j(t) − q̈_j(t−τ)| ≤ J_j τ` at every probe time — both sides of every
/// grid time, of every grid time shifted by `τ`, and every segment's middle.
pub fn filter_width(
    path: &PiecewiseCubic,
    profile: &SpeedProfile,
    acceleration: &[f64],
    jerk: &[f64],
) -> f64 {
    let bound = jerk_bound_width(acceleration, jerk).unwrap_or(0.0);
    filter_width_below(path, profile, acceleration, jerk, f64::INFINITY).unwrap_or(bound)
}

/// [`filter_width`] among the candidates narrower than `below` only:
/// `None` when none of them passes (a profile that cannot beat a width
/// already found is not scanned to the end). 0 without jerk limits.
pub fn filter_width_below(
    path: &PiecewiseCubic,
    profile: &SpeedProfile,
    acceleration: &[f64],
    jerk: &[f64],
    below: f64,
) -> Option<f64> {
    let Some(bound) = jerk_bound_width(acceleration, jerk) else {
        return Some(0.0);
    };
    let raw = Filtered::new(path, profile, 0.0);
    let dim = path.dim();
    let t = &profile.t;
    let nudge = 1e-9 * (1.0 + profile.duration());
    let mut probes: Vec<f64> = Vec::with_capacity(3 * t.len());
    for (i, &ti) in t.iter().enumerate() {
        probes.extend([ti - nudge, ti + nudge]);
        if let Some(&next) = t.get(i + 1) {
            probes.push(0.5 * (ti + next));
        }
    }
    let (mut a, mut b) = (State::zeros(dim), State::zeros(dim));
    let mut holds = |probe: usize, later: bool, tau: f64| {
        let time = if later {
            probes[probe] + tau
        } else {
            probes[probe]
        };
        raw.raw(time, &mut a);
        raw.raw(time - tau, &mut b);
        (0..dim).all(|j| (a.ddq[j] - b.ddq[j]).abs() <= jerk[j] * tau)
    };
    // A width fits when no probe breaks it, in whatever order they are
    // tried: the scan starts at the probe that broke the last width, which
    // nearly always breaks the next one too (a failing width then costs a
    // few evaluations, not a scan).
    let checks = 2 * probes.len();
    let mut start = 0;
    let widths = (1..CANDIDATES).map(|m| bound * m as f64 / CANDIDATES as f64);
    for tau in widths.take_while(|&tau| tau < below) {
        match (0..checks)
            .map(|k| (start + k) % checks)
            .find(|&c| !holds(c / 2, c % 2 == 1, tau))
        {
            Some(broke) => start = broke,
            None => return Some(tau),
        }
    }
    None
}

/// `max_j 2A_j/J_j`, the width that bounds every joint's jerk whatever the
/// profile; `None` without jerk limits.
pub fn jerk_bound_width(acceleration: &[f64], jerk: &[f64]) -> Option<f64> {
    (!jerk.is_empty()).then(|| {
        acceleration
            .iter()
            .zip(jerk)
            .map(|(a, j)| 2.0 * a / j)
            .fold(0.0, f64::max)
    })
}

/// The largest jerk of the samples over the limits: `(ratio, sample,
/// joint, jerk)` for the worst window, jerk as six times the third divided
/// difference of positions over four consecutive samples, with the arm at
/// rest for two more samples before the first and after the last (a step
/// apart). `times[k]` and `positions[k][j]` per sample.
pub fn sample_jerk(
    times: &[f64],
    positions: &[&[f64]],
    jerk: &[f64],
) -> Option<(f64, usize, usize, f64)> {
    let n = times.len();
    if n < 2 || jerk.is_empty() {
        return None;
    }
    let (first, last) = (times[1] - times[0], times[n - 1] - times[n - 2]);
    let mut padded_t = vec![times[0] - 2.0 * first, times[0] - first];
    padded_t.extend_from_slice(times);
    padded_t.extend([times[n - 1] + last, times[n - 1] + 2.0 * last]);
    let at = |k: usize, j: usize| positions[k.saturating_sub(2).min(n - 1)][j];
    let mut worst: Option<(f64, usize, usize, f64)> = None;
    for (j, limit) in jerk.iter().enumerate() {
        for k in 0..padded_t.len() - 3 {
            let value = third_difference(&padded_t[k..k + 4], |m| at(k + m, j));
            let ratio = value.abs() / limit;
            if worst.is_none_or(|w| ratio > w.0) {
                worst = Some((ratio, k.saturating_sub(2).min(n - 1), j, value));
            }
        }
    }
    worst
}

/// `6 f[t_0, t_1, t_2, t_3]`, the jerk a cubic through the four points has.
fn third_difference(t: &[f64], f: impl Fn(usize) -> f64) -> f64 {
    let d1: [f64; 3] = std::array::from_fn(|m| (f(m + 1) - f(m)) / (t[m + 1] - t[m]));
    let d2: [f64; 2] = std::array::from_fn(|m| (d1[m + 1] - d1[m]) / (t[m + 2] - t[m]));
    6.0 * (d2[1] - d2[0]) / (t[3] - t[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn third_difference_of_a_cubic_is_its_jerk() {
        let t = [0.0, 0.01, 0.02, 0.025];
        let cubic = |x: f64| 1.0 + 2.0 * x - 3.0 * x * x + 5.0 * x * x * x;
        let value = third_difference(&t, |m| cubic(t[m]));
        assert!((value - 30.0).abs() < 1e-6, "{value}");
    }
}
