//! Protective stops that end within the stopping distance the separation
//! rule assumes (ISO/TS 15066 §5.5.4.2.3): from a tool speed `v` the robot
//! may move `S = v·T_r + v²/(2·a_s)` — `T_r` the reaction time, `a_s` the
//! stopping deceleration of the scenario's `safety.separation` — before it
//! rests. The jerk-bounded ramps of [`super::ramp`] are taken when one ends
//! within `S`; where none does (the plan rides a joint's acceleration
//! limit, so braking along the path at the jerk limits takes too long) the
//! stop brakes as hard as the joints allow ([`hard`]): a category-2 stop
//! (IEC 60204-1 §9.2.2) along the planned path, `σ` at each plan sample the
//! smallest the independent check's velocity and acceleration rules let
//! through (within [`LIMIT_SHARE`] of every joint's acceleration limit),
//! jerk-bounded on every sample where that is possible. It never goes on at
//! the plan's speed.

use crate::timing::{JointLimits, SeparationSettings};
use crate::trajectory::TimedMotion;

use super::interval::{Interval, LIMIT_SHARE};
use super::ramp::jerk_within;
use super::state::{Cursor, Ramp};

/// What a stop must keep to: the tool's positions at the plan's samples
/// (base frame, m) and the separation settings its stopping distance comes
/// from.
#[derive(Clone, Copy)]
pub struct Braking<'a> {
    pub tool: &'a [[f64; 3]],
    pub separation: &'a SeparationSettings,
}

impl Braking<'_> {
    /// The stopping distance allowed from plan sample `k` at speed
    /// override `sigma`, m: the stopping term at the tool's speed there.
    pub fn allowed(&self, motion: &TimedMotion, k: usize, sigma: f64) -> f64 {
        stopping_term(self.separation, tool_speed(self.tool, motion, k) * sigma)
    }

    /// How far the tool moves along the plan from sample `from` to `to`, m.
    pub fn travel(&self, from: usize, to: usize) -> f64 {
        tool_travel(self.tool, from, to)
    }
}

/// The stopping term of the protective separation distance at tool speed
/// `v` (m/s): `v·T_r + v²/(2·a_s)`, m.
pub fn stopping_term(s: &SeparationSettings, v: f64) -> f64 {
    v * s.reaction_time_s + v * v / (2.0 * s.stop_deceleration_m_s2)
}

/// The planned tool speed at sample `k` (the next interval's), m/s.
fn tool_speed(tool: &[[f64; 3]], motion: &TimedMotion, k: usize) -> f64 {
    let points = &motion.points;
    let next = (k + 1).min(points.len() - 1);
    let h = points[next].time_from_start - points[k].time_from_start;
    match h > 0.0 {
        true => tool_travel(tool, k, next) / h,
        false => 0.0,
    }
}

/// Path length of the tool from sample `from` to sample `to`, m.
pub fn tool_travel(tool: &[[f64; 3]], from: usize, to: usize) -> f64 {
    let to = to.min(tool.len().saturating_sub(1));
    (from..to)
        .map(|i| {
            let (a, b) = (tool[i], tool[i + 1]);
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
        })
        .sum()
}

/// Steps of the search for each sample's speed, over `[0, 1]`.
const GRID: usize = 64;
/// Bisection rounds refining it.
const REFINE: usize = 10;

/// The hardest stop along the path from `cursor`: at each plan sample the
/// smallest `σ` that keeps the check's rules — the jerk too where some `σ`
/// does — until the robot rests on a sample. `None` when at some sample
/// no `σ` in `[0, 1]` keeps them.
pub fn hard(motion: &TimedMotion, limits: &JointLimits, cursor: &Cursor, dt: f64) -> Option<Ramp> {
    let points = &motion.points;
    let k = cursor.index;
    let (sigma, rate) = match cursor.ramp() {
        Some(r) => (r.sigma(k), r.rate(k)),
        None => (cursor.sigma, 0.0),
    };
    let mut ramp = Ramp {
        target: 0.0,
        first: k,
        sigmas: vec![sigma],
        rates: vec![rate],
    };
    let mut state = Executed {
        window: cursor.history(dt),
        last: cursor.last().cloned(),
    };
    let mut i = k;
    while i + 1 < points.len() && *ramp.sigmas.last()? > 0.0 {
        let sa = *ramp.sigmas.last()?;
        let step = Step {
            motion,
            limits,
            i,
            sa,
            dt,
        };
        let (sb, next) = step
            .slowest(&state, true)
            .or_else(|| step.slowest(&state, false))?;
        let h = points[i + 1].time_from_start - points[i].time_from_start;
        ramp.sigmas.push(sb);
        ramp.rates.push((sb * sb - sa * sa) / (2.0 * h.max(1e-12)));
        state = next;
        i += 1;
    }
    Some(ramp)
}

/// The executed samples the rules look back on.
#[derive(Clone)]
struct Executed {
    window: [(usize, f64); 3],
    last: Option<(Vec<f64>, f64)>,
}

/// One interval of a hard stop: from plan sample `i` at speed `sa`.
struct Step<'a> {
    motion: &'a TimedMotion,
    limits: &'a JointLimits,
    i: usize,
    sa: f64,
    dt: f64,
}

impl Step<'_> {
    /// The smallest `σ_b` the rules (with the jerk or without) let
    /// through, and the executed state after it.
    fn slowest(&self, state: &Executed, jerk: bool) -> Option<(f64, Executed)> {
        if let Some(next) = self.passes(state, 0.0, jerk) {
            return Some((0.0, next));
        }
        let first = (1..=GRID).find_map(|j| {
            let sb = j as f64 / GRID as f64;
            self.passes(state, sb, jerk).map(|n| (sb, n))
        })?;
        let (mut lo, mut best) = (first.0 - 1.0 / GRID as f64, first);
        for _ in 0..REFINE {
            let mid = 0.5 * (lo + best.0);
            match self.passes(state, mid, jerk) {
                Some(n) => best = (mid, n),
                None => lo = mid,
            }
        }
        Some(best)
    }

    /// The executed state after the interval to `σ_b = sb` when it keeps
    /// the rules; when it comes to rest, two controller periods at rest
    /// must keep them too.
    fn passes(&self, state: &Executed, sb: f64, jerk: bool) -> Option<Executed> {
        let points = &self.motion.points;
        let jerk = jerk && !self.limits.jerk.is_empty();
        let interval = Interval {
            a: &points[self.i],
            b: &points[self.i + 1],
            sigma_a: self.sa,
            sigma_b: sb,
        };
        if self.sa + sb <= 0.0 {
            return None;
        }
        let before = self.i.checked_sub(1).map(|p| &points[p]);
        if !interval.passes(self.limits, before, state.last.as_ref()) {
            return None;
        }
        let d = interval.duration();
        let mut next = advance(
            state,
            (self.i + 1, state.window[2].1 + d),
            interval.means(d),
        );
        if jerk && !self.jerk_ok(state, next.window[2]) {
            return None;
        }
        if sb > 0.0 {
            return Some(next);
        }
        let zeros = vec![0.0; self.limits.acceleration.len()];
        let after = next.clone();
        for _ in 0..2 {
            let (m, dl) = next.last.clone()?;
            let stops = m
                .iter()
                .zip(&self.limits.acceleration)
                .all(|(m, a)| (m / (0.5 * (dl + self.dt))).abs() <= LIMIT_SHARE * a);
            let at_rest = (self.i + 1, next.window[2].1 + self.dt);
            if !stops || (jerk && !self.jerk_ok(&next, at_rest)) {
                return None;
            }
            next = Executed {
                window: [next.window[1], next.window[2], at_rest],
                last: Some((zeros.clone(), self.dt)),
            };
        }
        Some(after)
    }

    fn jerk_ok(&self, state: &Executed, next: (usize, f64)) -> bool {
        let w = state.window;
        jerk_within(&self.motion.points, self.limits, [w[0], w[1], w[2], next])
    }
}

/// The state after one more executed sample `next` with mean velocities
/// `means` over its interval.
fn advance(state: &Executed, next: (usize, f64), means: Vec<f64>) -> Executed {
    let w = state.window;
    Executed {
        window: [w[1], w[2], next],
        last: Some((means, next.1 - w[2].1)),
    }
}
