//! The tool's speed near hands, sample by sample, against the
//! speed-and-separation caps of [`separation`](super::separation).
//!
//! Two measures. The program bounds the speed `‖p'(s)‖ ṡ` of the tool-space
//! interpolant `p(s)` (the blended tool positions) on each grid segment;
//! every sample's interpolant speed is checked against the caps the
//! program kept. The real tool follows forward kinematics of the joints,
//! which bends away from the interpolant between waypoints: on a profile
//! that sits on a crawl cap its speed was up to 3 % above the
//! interpolant's (0.0505 m/s against a 0.05 m/s cap, two Care-O-bot
//! scenes of the safety campaign). With the arm's forward kinematics `fk`
//! every sample interval `[t_k, t_{k+1}]` is measured on the real tool:
//!
//! ```text
//! mean speed      ‖fk(q_{k+1}) − fk(q_k)‖ / (t_{k+1} − t_k)      (what the independent check measures)
//! instantaneous   ‖fk(q + h q̇) − fk(q − h q̇)‖ / 2h   at both samples   (J(q) q̇, central difference)
//! ```
//!
//! against the smaller of the rule's cap at the nearer of the two real tool
//! positions' hand distances and the rule's caps of the grid segments the
//! interval's path stretch spans. Every interval over its cap is an
//! [`Excess`]; the timing lowers the caps on its stretch and times again.

use super::deviation::ToolPathCheck;
use super::jerk::Filtered;
use super::sample::{JointTrajectory, LimitKind, LimitViolation, SpeedProfile};
use super::separation::{Hand, SeparationSettings, nearest_hand_distance};
use super::spline::PiecewiseCubic;

/// Step of the central difference along `q̇`, seconds (the joints move
/// `h q̇`, about a milliradian: the truncation error is ~1e-6 of the speed).
const FK_STEP_S: f64 = 1e-3;

/// The caps near hands and what measures the tool against them.
pub struct ToolSpeedCheck<'a> {
    /// The tool-space interpolant (the joint path's knots and radii), m.
    pub tool: &'a PiecewiseCubic,
    /// Cap on the interpolant's speed on each grid segment, m/s (the
    /// program's, below the rule's by the margins).
    pub kept: &'a [f64],
    /// The rule's cap on each grid segment, m/s.
    pub limits: &'a [f64],
    /// The hands and the rule, for the real tool's own distances.
    pub hands: &'a [Hand],
    pub rule: &'a SeparationSettings,
    /// Forward kinematics of the samples; `None` measures the interpolant only.
    pub real: Option<&'a ToolPathCheck<'a>>,
}

/// A sample interval where the tool is faster than its cap.
#[derive(Debug, Clone, PartialEq)]
pub struct Excess {
    /// First sample of the interval.
    pub sample: usize,
    /// The stretch of path parameter whose caps to lower: the one the
    /// samples depend on (`[s(t − τ), s(t)]` with the jerk filter's width
    /// `τ`), for the real tool from sample `k − 1` to `k + 2`.
    pub stretch: (f64, f64),
    /// Measured speed and its cap, m/s.
    pub speed: f64,
    pub limit: f64,
    /// The interpolant's speed there, m/s: `speed` is the real tool's
    /// (or this one's) at this interpolant speed, so the caps on the
    /// stretch must bring this down by `limit / speed`.
    pub interpolant: f64,
}

impl Excess {
    /// As a [`LimitViolation`] of the tool speed.
    pub fn violation(&self) -> LimitViolation {
        LimitViolation {
            kind: LimitKind::ToolSpeed,
            sample: self.sample,
            joint: 0,
            value: self.speed,
            limit: self.limit,
        }
    }
}

/// Every sample interval over its cap by more than the relative
/// `tolerance`, in sample order: the interpolant's speed at each sample
/// against the kept caps, and with [`ToolSpeedCheck::real`] the real
/// tool's (`tools[k]` = fk of sample `k`, metres) against the rule's.
pub fn excess(
    trajectory: &JointTrajectory,
    profile: &SpeedProfile,
    motion: &Filtered,
    check: &ToolSpeedCheck,
    tools: Option<&[[f64; 3]]>,
    tolerance: f64,
) -> Vec<Excess> {
    let points = &trajectory.points;
    let tau = motion.tau();
    let stretch = |k: usize| {
        let t = points[k].time_from_start;
        (motion.s_at(t - tau), motion.s_at(t))
    };
    let last = points.len() - 1;
    // Per sample: the real tool's position, instantaneous speed and
    // nearest hand distance.
    let real: Option<Vec<RealSample>> = check.real.zip(tools).map(|(fk, tools)| {
        points
            .iter()
            .zip(tools)
            .map(|(p, &x)| RealSample {
                x,
                speed: instantaneous_speed(fk, &p.positions, &p.velocities),
                hand_m: nearest_hand_distance(check.hands, x),
            })
            .collect()
    });
    let mut found = Vec::new();
    for k in 0..points.len() {
        let (s_lo, s_hi) = stretch(k);
        let t = points[k].time_from_start;
        let (speed, limit) = interpolant_speed(profile, motion, check, t, (s_lo, s_hi));
        let mut worst = (speed > limit * (1.0 + tolerance)).then_some(Excess {
            sample: k,
            stretch: (s_lo, s_hi),
            speed,
            limit,
            interpolant: speed,
        });
        if let (Some(real), true) = (&real, k < last) {
            let (a, b) = (&real[k], &real[k + 1]);
            let elapsed = points[k + 1].time_from_start - points[k].time_from_start;
            let speed = (distance(a.x, b.x) / elapsed).max(a.speed).max(b.speed);
            let span = (s_lo, stretch(k + 1).1);
            let limit = check
                .rule
                .tool_speed_cap(a.hand_m.min(b.hand_m))
                .min(spanned_min(check.limits, &profile.s, span));
            if speed > limit * (1.0 + tolerance)
                && worst
                    .as_ref()
                    .is_none_or(|w| speed / limit > w.speed / w.limit)
            {
                // The caps are lowered a sample either side too: the next
                // timing's samples fall elsewhere on the path.
                let padded = (stretch(k.saturating_sub(1)).0, stretch((k + 2).min(last)).1);
                let interpolant = distance(at(check.tool, span.0), at(check.tool, span.1));
                worst = Some(Excess {
                    sample: k,
                    stretch: padded,
                    speed,
                    limit,
                    interpolant: interpolant / (elapsed + tau),
                });
            }
        }
        found.extend(worst);
    }
    found
}

/// The real tool at one sample.
struct RealSample {
    /// Position, metres.
    x: [f64; 3],
    /// Instantaneous speed `‖J(q) q̇‖`, m/s.
    speed: f64,
    /// Distance to the nearest hand, metres.
    hand_m: f64,
}

/// `‖J(q) q̇‖` by a central difference of the forward kinematics along `q̇`, m/s.
fn instantaneous_speed(fk: &ToolPathCheck, q: &[f64], q_dot: &[f64]) -> f64 {
    let step = |sign: f64| -> Vec<f64> {
        q.iter()
            .zip(q_dot)
            .map(|(q, v)| q + sign * FK_STEP_S * v)
            .collect()
    };
    distance(fk.fk_of(&step(1.0)), fk.fk_of(&step(-1.0))) / (2.0 * FK_STEP_S)
}

/// The interpolant's speed at time `t` and its cap, m/s. Unfiltered: the
/// tool path's speed against its segment's cap. Filtered: the mean tool
/// velocity over the window `[t − τ, t]` (what averaging the joints gives,
/// to first order) against the smallest cap of the segments the window
/// spans.
fn interpolant_speed(
    profile: &SpeedProfile,
    motion: &Filtered,
    check: &ToolSpeedCheck,
    t: f64,
    (s_lo, s_hi): (f64, f64),
) -> (f64, f64) {
    let (tool, caps) = (check.tool, check.kept);
    let (mut x, mut dx, mut ddx) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    let tau = motion.tau();
    if tau <= 0.0 {
        let (s, s_dot, _, segment) = profile.state_at(t);
        tool.eval(s, &mut x, &mut dx, &mut ddx);
        let speed = dx.iter().map(|d| d * d).sum::<f64>().sqrt() * s_dot;
        return (speed, caps[segment]);
    }
    let speed = distance(at(tool, s_hi), at(tool, s_lo)) / tau;
    (speed, spanned_min(caps, &profile.s, (s_lo, s_hi)))
}

/// The smallest of `caps` (one per segment of `grid`) over the segments
/// that `[s_lo, s_hi]` touches.
fn spanned_min(caps: &[f64], grid: &[f64], (s_lo, s_hi): (f64, f64)) -> f64 {
    let segment = |s: f64| (grid.partition_point(|&g| g <= s).max(1) - 1).min(caps.len() - 1);
    caps[segment(s_lo)..=segment(s_hi)]
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt()
}

/// The point of `path` at `s`.
fn at(path: &PiecewiseCubic, s: f64) -> [f64; 3] {
    let (mut x, mut dx, mut ddx) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    path.eval(s, &mut x, &mut dx, &mut ddx);
    x
}
