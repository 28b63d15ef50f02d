//! Changes of the speed override (slow down, stop, resume) that keep the
//! joints' jerk limits. Under the time warp `q(t) = p(s(t))`, `ṡ = σ`,
//!
//! ```text
//! q⃛ = p''' σ³ + 3 p'' σ σ̇ + p' σ̈
//! ```
//!
//! so a change of `σ` needs `σ̇` continuous (else the accelerations jump)
//! and `σ̈` bounded. A ramp over a duration `T` is, from a settled speed,
//! a trapezoidal `σ̇` ([`Shape::Trapezoid`]), or from any state the quintic
//! from `(σ₀, σ̇₀, 0)` to `(σ*, 0, 0)` (`σ̇₀` that of the ramp under way),
//! read at the plan's samples (`s(t) = ∫σ` solved for each sample's plan
//! time) and executed with the intervals of the `execute` module. A stop
//! ends exactly on a plan sample: its `T` solves `L = T (σ₀/2 + σ̇₀ T/10)`
//! for the plan time `L` to that sample. Candidates are tried soonest
//! settled first, each started after 0 or more samples of the speed under
//! way (the plan's own acceleration or jerk may sit at the limit where `σ`
//! cannot leave 1), up to riding the plan to its own rest at its end,
//! and the first whose executed samples pass the check's rules —
//! [`Interval::passes`] and the jerk as six times the third divided
//! difference of positions and times over four samples, with the samples
//! before the cursor and, after a stop, two at rest — is taken. At a plan
//! sample where the plan itself rests `σ` may jump (the arm does not move).
//! If none passes, the first that passes without the jerk, else the
//! gentlest: a stop is never skipped.

use crate::timing::{JointLimits, TrajectoryPoint};
use crate::trajectory::TimedMotion;

use super::brake::{self, Braking};
use super::interval::{Interval, LIMIT_SHARE};
use super::state::{Cursor, Ramp};

/// Shortest ramp tried, s.
const FIRST_DURATION_S: f64 = 0.02;
/// Each ramp tried lasts this much longer than the one before.
const DURATION_RATIO: f64 = 1.12;
/// Ramps tried (the longest ≈ 4 s).
const DURATIONS: i32 = 48;

/// The shape of a ramp over `u = t/T ∈ [0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shape {
    /// `σ(u) = Σ c_i u^i` from `(σ₀, σ̇₀, 0)` to `(σ*, 0, 0)`.
    Quintic,
    /// From `σ̇₀ = 0` only: `σ̇` a trapezoid (up over [`EDGE`] of `T`,
    /// level, down over `EDGE`), `σ̈` piecewise constant — a flatter
    /// deceleration than the quintic's for the same peak.
    Trapezoid,
}

/// Share of a trapezoidal ramp over which `σ̇` rises (and falls).
const EDGE: f64 = 0.25;

/// One ramp: `σ(t)` over `t ∈ [0, T]`.
struct Profile {
    shape: Shape,
    c: [f64; 6],
    sigma: f64,
    delta: f64,
    duration: f64,
}

impl Profile {
    /// `None` for a trapezoid that would start with `σ̇₀ ≠ 0`.
    fn new(shape: Shape, sigma: f64, rate: f64, target: f64, duration: f64) -> Option<Self> {
        if shape == Shape::Trapezoid && rate != 0.0 {
            return None;
        }
        let m = rate * duration;
        let (d, v) = (target - sigma - m, -m);
        Some(Self {
            shape,
            c: [
                sigma,
                m,
                0.0,
                10.0 * d - 4.0 * v,
                7.0 * v - 15.0 * d,
                6.0 * d - 3.0 * v,
            ],
            sigma,
            delta: target - sigma,
            duration,
        })
    }

    fn sigma(&self, u: f64) -> f64 {
        match self.shape {
            Shape::Quintic => self.c.iter().rev().fold(0.0, |acc, c| acc * u + c),
            Shape::Trapezoid => self.sigma + self.delta * trapezoid(u)[1],
        }
    }

    /// `σ̇`, 1/s.
    fn rate(&self, u: f64) -> f64 {
        let d = match self.shape {
            Shape::Quintic => (1..6)
                .rev()
                .fold(0.0, |acc, i| acc * u + i as f64 * self.c[i]),
            Shape::Trapezoid => self.delta * trapezoid(u)[2],
        };
        d / self.duration
    }

    /// Plan time covered by `u`, s.
    fn distance(&self, u: f64) -> f64 {
        let integral = match self.shape {
            Shape::Quintic => {
                u * (0..6)
                    .rev()
                    .fold(0.0, |acc, i| acc * u + self.c[i] / (i + 1) as f64)
            }
            Shape::Trapezoid => self.sigma * u + self.delta * trapezoid(u)[0],
        };
        self.duration * integral
    }

    /// The `u` at which plan time `x` has been covered (`σ ≥ 0`).
    fn reach(&self, x: f64, from: f64) -> f64 {
        let (mut lo, mut hi) = (from, 1.0);
        for _ in 0..48 {
            let mid = 0.5 * (lo + hi);
            match self.distance(mid) < x {
                true => lo = mid,
                false => hi = mid,
            }
        }
        0.5 * (lo + hi)
    }
}

/// The unit trapezoidal step `g` from 0 to 1 at `u`: `[∫₀ᵘ g, g, g']`.
fn trapezoid(u: f64) -> [f64; 3] {
    let (r, p) = (EDGE, 1.0 / (1.0 - EDGE));
    let rise = |u: f64| [p * u.powi(3) / (6.0 * r), p * u * u / (2.0 * r), p * u / r];
    let top = rise(r);
    if u <= r {
        rise(u)
    } else if u <= 1.0 - r {
        let x = u - r;
        [top[0] + top[1] * x + 0.5 * p * x * x, top[1] + p * x, p]
    } else {
        let (x, w) = (1.0 - 2.0 * r, u - (1.0 - r));
        let level = [top[0] + top[1] * x + 0.5 * p * x * x, top[1] + p * x];
        let y = r - w;
        [
            level[0] + w - p * (r.powi(3) - y.powi(3)) / (6.0 * r),
            1.0 - p * y * y / (2.0 * r),
            p * y / r,
        ]
    }
}

/// The ramp from `cursor` to the speed `target`. A stop (`target` 0)
/// with `braking` given ends within its stopping distance
/// ([`Braking::allowed`]): the first jerk-bounded candidate that does, else
/// the hardest stop the joints allow ([`brake::hard`]).
pub fn plan(
    motion: &TimedMotion,
    limits: &JointLimits,
    cursor: &Cursor,
    target: f64,
    dt: f64,
    braking: Option<&Braking>,
) -> Ramp {
    let k = cursor.index;
    let going = |i: usize| cursor.ramp().map_or(cursor.sigma, |r| r.sigma(i));
    if at_rest(&motion.points[k]) {
        let jump = Ramp {
            target,
            first: k,
            sigmas: vec![target],
            rates: vec![0.0],
        };
        if passes(motion, limits, cursor, &jump, dt, true) {
            return jump;
        }
    }
    let braking = braking.filter(|_| target <= 0.0);
    let allowed = braking.map(|b| (b, b.allowed(motion, k, going(k))));
    let within = |ramp: &Ramp| {
        allowed.is_none_or(|(b, distance)| {
            b.travel(k, ramp.first + ramp.sigmas.len() - 1) <= distance + 1e-6
        })
    };
    let (mut without_jerk, mut gentlest) = (None, None);
    for (delay, duration, shape) in candidates(cursor, motion.points.len(), going(k), dt) {
        let Some(ramp) = candidate(motion, cursor, target, (delay, duration, shape)) else {
            continue;
        };
        if !within(&ramp) {
            continue;
        }
        if passes(motion, limits, cursor, &ramp, dt, true) {
            return ramp;
        }
        if without_jerk.is_none() && passes(motion, limits, cursor, &ramp, dt, false) {
            without_jerk = Some(ramp.clone());
        }
        if delay == 0 {
            gentlest = Some(ramp);
        }
    }
    let hard = braking
        .and_then(|_| brake::hard(motion, limits, cursor, dt))
        .filter(|r| passes(motion, limits, cursor, r, dt, false));
    hard.or(without_jerk).or(gentlest).unwrap_or_else(|| Ramp {
        target,
        first: k,
        sigmas: vec![going(k), going(k + 1)],
        rates: vec![0.0; 2],
    })
}

/// The (delay, duration) pairs to try, soonest settled first (`delay`
/// samples at speed `sigma`, then `duration`): delays grow by half up to
/// the plan's end, none from rest.
fn candidates(cursor: &Cursor, samples: usize, sigma: f64, dt: f64) -> Vec<(usize, f64, Shape)> {
    let left = samples.saturating_sub(cursor.index + 1);
    let mut delays = vec![0];
    if sigma > 0.0 {
        while delays[delays.len() - 1] < left {
            let d = delays[delays.len() - 1];
            delays.push((d + 1).max(d * 3 / 2).min(left));
        }
    }
    let durations = |d: usize| match d < left {
        true => 0..DURATIONS,
        false => 0..1,
    };
    let mut out: Vec<(usize, f64, Shape)> = delays
        .iter()
        .flat_map(|&d| durations(d).map(move |i| (d, FIRST_DURATION_S * DURATION_RATIO.powi(i))))
        .flat_map(|(d, t)| [(d, t, Shape::Trapezoid), (d, t, Shape::Quintic)])
        .collect();
    let cost = |&(d, t, _): &(usize, f64, Shape)| d as f64 * dt / sigma.max(1e-3) + t;
    out.sort_by(|a, b| cost(a).total_cmp(&cost(b)));
    out
}

/// The plan rests at the sample: no joint moves or accelerates.
fn at_rest(p: &TrajectoryPoint) -> bool {
    p.velocities
        .iter()
        .chain(&p.accelerations)
        .all(|v| v.abs() <= 1e-9)
}

/// `delay` more samples of the speed under way, then the ramp of
/// `shape` and `duration` to `target`; `None` when it would leave `[0, 1]`, halt
/// before its end or cannot start before the plan ends.
fn candidate(
    motion: &TimedMotion,
    cursor: &Cursor,
    target: f64,
    (delay, duration, shape): (usize, f64, Shape),
) -> Option<Ramp> {
    let points = &motion.points;
    let (k, n) = (cursor.index, points.len());
    let k0 = (k + delay).min(n - 1);
    let going = |i: usize| match cursor.ramp() {
        Some(r) => (r.sigma(i), r.rate(i)),
        None => (cursor.sigma, 0.0),
    };
    let (mut sigmas, mut rates): (Vec<f64>, Vec<f64>) = (k..=k0).map(going).unzip();
    if k0 + 1 >= n {
        // On at the speed under way to the plan's end, where it rests.
        return Some(Ramp {
            target,
            first: k,
            sigmas,
            rates,
        });
    }
    let (sigma, rate) = going(k0);
    let start = points[k0].time_from_start;
    let profile = match target > 0.0 {
        true => Profile::new(shape, sigma, rate, target, duration)?,
        false => {
            let length = duration * (0.5 * sigma + 0.1 * rate * duration);
            if length <= 0.0 {
                return None;
            }
            // The stop sample: the first at or past that plan time.
            let m = points
                .partition_point(|p| p.time_from_start - start < length - 1e-12)
                .clamp(k0 + 1, n - 1);
            let length = points[m].time_from_start - start;
            let root = 0.25 * sigma * sigma + 0.4 * rate * length;
            if root < 0.0 {
                return None;
            }
            let duration = 2.0 * length / (0.5 * sigma + root.sqrt());
            Profile::new(shape, sigma, rate, 0.0, duration)?
        }
    };
    let total = profile.distance(1.0);
    let mut u = 0.0;
    for p in &points[k0 + 1..] {
        let x = p.time_from_start - start;
        if x >= total - 1e-12 {
            if target <= 0.0 {
                sigmas.push(0.0);
                rates.push(0.0);
            }
            break;
        }
        u = profile.reach(x, u);
        let s = profile.sigma(u);
        if !(1e-9..=1.0 + 1e-12).contains(&s) {
            return None;
        }
        sigmas.push(s.min(1.0));
        rates.push(profile.rate(u));
    }
    Some(Ramp {
        target,
        first: k,
        sigmas,
        rates,
    })
}

/// Whether executing `ramp` from `cursor` keeps every rule on every
/// sample it touches: the ramp, three samples at its target after it, and
/// two controller periods at rest where it comes to rest (a stop, a
/// gripper event or the plan's end). `jerk` includes the jerk rule.
fn passes(
    motion: &TimedMotion,
    limits: &JointLimits,
    cursor: &Cursor,
    ramp: &Ramp,
    dt: f64,
    jerk: bool,
) -> bool {
    let points = &motion.points;
    let jerk = jerk && !limits.jerk.is_empty();
    let end = (cursor.index + ramp.sigmas.len() + 3).min(points.len() - 1);
    let mut window = cursor.history(dt);
    let mut last = cursor.last().cloned();
    let mut i = cursor.index;
    let mut rests = true;
    while i < end && !(i > cursor.index && gripper_starts(motion, i)) {
        let interval = Interval {
            a: &points[i],
            b: &points[i + 1],
            sigma_a: ramp.sigma(i),
            sigma_b: ramp.sigma(i + 1),
        };
        if interval.sigma_a + interval.sigma_b <= 0.0 {
            break;
        }
        let before = i.checked_sub(1).map(|p| &points[p]);
        if !interval.passes(limits, before, last.as_ref()) {
            return false;
        }
        let d = interval.duration();
        let next = (i + 1, window[2].1 + d);
        if jerk && !jerk_within(points, limits, [window[0], window[1], window[2], next]) {
            return false;
        }
        window = [window[1], window[2], next];
        last = Some((interval.means(d), d));
        i += 1;
        rests = ramp.sigma(i) <= 0.0;
    }
    if i == end && end < points.len() - 1 && !rests {
        return true;
    }
    // At rest on sample `i`: two controller periods.
    for _ in 0..2 {
        let next = (i, window[2].1 + dt);
        let stops = last.as_ref().is_none_or(|(m, dl)| {
            m.iter()
                .zip(&limits.acceleration)
                .all(|(m, a)| (m / (0.5 * (dl + dt))).abs() <= LIMIT_SHARE * a)
        });
        if !stops || (jerk && !jerk_within(points, limits, [window[0], window[1], window[2], next]))
        {
            return false;
        }
        window = [window[1], window[2], next];
        last = Some((vec![0.0; limits.acceleration.len()], dt));
    }
    true
}

/// A gripper event starts at sample `i` (the arm rests through it).
fn gripper_starts(motion: &TimedMotion, i: usize) -> bool {
    let s = motion.points[i].time_from_start;
    motion
        .gripper
        .iter()
        .any(|e| (e.start - s).abs() < 1e-9 && e.end > e.start)
}

/// Every joint's jerk over four executed samples (plan index, time) —
/// six times the third divided difference, as the independent check
/// recomputes it — within its limit.
pub fn jerk_within(
    points: &[TrajectoryPoint],
    limits: &JointLimits,
    window: [(usize, f64); 4],
) -> bool {
    limits.jerk.iter().enumerate().all(|(j, limit)| {
        let base = points[window[0].0].positions[j];
        let jerk: f64 = (0..4)
            .map(|i| {
                let denominator: f64 = (0..4)
                    .filter(|&m| m != i)
                    .map(|m| window[i].1 - window[m].1)
                    .product();
                (points[window[i].0].positions[j] - base) / denominator
            })
            .sum();
        (6.0 * jerk).abs() <= *limit
    })
}
