//! From the speed profile to a joint trajectory sampled at the controller
//! rate, and the check of every sample against the limits.
//!
//! On segment `i` the path acceleration is constant, so with
//! `ṡ_i = √b_i`: `Δt_i = 2Δs_i/(ṡ_i + ṡ_{i+1})`, `s̈ = (ṡ_{i+1} − ṡ_i)/Δt_i`,
//! `s(τ) = s_i + ṡ_i τ + s̈ τ²/2`. Joint values follow by the chain rule:
//! `q̇ = q'(s) ṡ`, `q̈ = q''(s) ṡ² + q'(s) s̈`.

use serde::{Deserialize, Serialize};

use super::deviation::ToolPathCheck;
use super::jerk::{Filtered, State, sample_jerk};
pub use super::profile::SpeedProfile;
use super::spline::PiecewiseCubic;

/// One sample, the shape of ROS `trajectory_msgs/JointTrajectoryPoint`
/// (rad, rad/s, rad/s², seconds from the start).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryPoint {
    pub positions: Vec<f64>,
    pub velocities: Vec<f64>,
    pub accelerations: Vec<f64>,
    pub time_from_start: f64,
}

/// A timed joint trajectory, the shape of ROS `trajectory_msgs/JointTrajectory`
/// without `joint_names` (the caller knows the arm and adds them).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointTrajectory {
    pub points: Vec<TrajectoryPoint>,
}

impl JointTrajectory {
    /// `time_from_start` of the last point, 0 for an empty trajectory.
    pub fn duration(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.time_from_start)
    }
}

/// Samples at `rate_hz`, from 0 to the duration inclusive. The first and
/// last samples are exactly at rest on `ends` (the first and last
/// waypoints): positions the waypoints, velocities and accelerations 0,
/// times exactly 0 and the duration. Every step lasts at most one period
/// and the last at least half of one: a regular sample closer than half a
/// period to the end moves back to half a period before it, since rates a
/// controller or checker derives from positions over a microsecond step
/// are rounding noise.
pub fn sample(motion: &Filtered, rate_hz: f64, ends: (&[f64], &[f64])) -> JointTrajectory {
    let duration = motion.duration();
    let dim = ends.0.len();
    let period = 1.0 / rate_hz;
    let count = (duration * rate_hz - 1e-9).ceil().max(0.0) as usize;
    let last_regular = (count.max(1) - 1) as f64 * period;
    let before_end = match count >= 2 && duration - last_regular < period / 2.0 {
        true => duration - period / 2.0,
        false => last_regular,
    };
    let mut points = Vec::with_capacity(count + 1);
    let mut state = State {
        q: vec![0.0; dim],
        dq: vec![0.0; dim],
        ddq: vec![0.0; dim],
    };
    let mut scratch = (state.clone(), state.clone());
    for k in 0..=count {
        let t = match count - k {
            0 => duration,
            1 => before_end,
            _ => k as f64 * period,
        };
        motion.state(t, &mut state, &mut scratch);
        points.push(TrajectoryPoint {
            positions: state.q.clone(),
            velocities: state.dq.clone(),
            accelerations: state.ddq.clone(),
            time_from_start: t,
        });
    }
    for (point, at) in [(0, ends.0), (count, ends.1)] {
        let p = &mut points[point];
        p.positions.copy_from_slice(at);
        p.velocities.fill(0.0);
        p.accelerations.fill(0.0);
    }
    JointTrajectory { points }
}

/// Which quantity broke its limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LimitKind {
    Position,
    Velocity,
    Acceleration,
    ToolSpeed,
    /// The tool's distance from the planned tool path, metres.
    ToolDeviation,
    /// Jerk, rad/s³ (m/s³), from the samples' positions and times.
    Jerk,
}

/// The first sample found outside its limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitViolation {
    pub kind: LimitKind,
    /// Sample index.
    pub sample: usize,
    /// Joint index (0 for the tool speed).
    pub joint: usize,
    pub value: f64,
    pub limit: f64,
}

/// The joint limits every sample is checked against (already scaled by the
/// speed scale), one entry per joint.
pub struct SampleLimits<'a> {
    /// Position limits, rad (m); infinite for a continuous joint (unchecked).
    pub lower: &'a [f64],
    pub upper: &'a [f64],
    pub velocity: &'a [f64],
    pub acceleration: &'a [f64],
    /// Jerk limits, rad/s³ (m/s³); empty: none.
    pub jerk: &'a [f64],
    /// Relative tolerance: a velocity or acceleration up to `limit (1 +
    /// tolerance)`, a position up to `tolerance · max(1, |limit|)` beyond.
    pub tolerance: f64,
}

/// The path the samples were taken on and its tool-side checks.
pub struct PathChecks<'a> {
    pub path: &'a PiecewiseCubic,
    /// The timed path as sampled (averaged over its filter's window).
    pub motion: &'a Filtered<'a>,
    /// The planned tool path and its tolerance, with the tool of every
    /// sample (its forward kinematics, metres).
    pub tool_path: Option<(&'a ToolPathCheck<'a>, &'a [[f64; 3]])>,
}

/// Every sample within the position limits, the velocity and acceleration
/// limits and the planned tool path's tolerance (when given), then the
/// jerk limits. `Err` names the first sample found outside, in this order.
/// (The tool's speed near hands: [`tool_speed`](super::tool_speed).)
pub fn verify(
    trajectory: &JointTrajectory,
    limits: &SampleLimits,
    checks: &PathChecks,
) -> Result<(), LimitViolation> {
    let tolerance = limits.tolerance;
    for (k, p) in trajectory.points.iter().enumerate() {
        for j in 0..limits.velocity.len() {
            let (q, lower, upper) = (p.positions[j], limits.lower[j], limits.upper[j]);
            let slack = |limit: f64| tolerance * limit.abs().max(1.0);
            let position = [
                (lower, q >= lower - slack(lower)),
                (upper, q <= upper + slack(upper)),
            ]
            .into_iter()
            .find(|(limit, ok)| limit.is_finite() && !ok)
            .map(|(limit, _)| (LimitKind::Position, q, limit));
            let rates = [
                (LimitKind::Velocity, p.velocities[j], limits.velocity[j]),
                (
                    LimitKind::Acceleration,
                    p.accelerations[j],
                    limits.acceleration[j],
                ),
            ];
            let broken = position
                .into_iter()
                .chain(rates.into_iter().filter(|c| !within(c.1, c.2, tolerance)))
                .next();
            if let Some((kind, value, limit)) = broken {
                return Err(LimitViolation {
                    kind,
                    sample: k,
                    joint: j,
                    value,
                    limit,
                });
            }
        }
        if let Some((planned, tools)) = checks.tool_path {
            // The path stretch the sample averages: [s(t − τ), s(t)].
            let t = p.time_from_start;
            let tau = checks.motion.tau();
            let (s_lo, s_hi) = (checks.motion.s_at(t - tau), checks.motion.s_at(t));
            let (first, last) = (checks.path.locate(s_lo).0, checks.path.locate(s_hi).0);
            let segments = (
                checks.path.segments_of(first).0,
                checks.path.segments_of(last).1,
            );
            let distance = planned.distance(tools[k], segments);
            if !within(distance, planned.tolerance_m, 0.0) {
                return Err(LimitViolation {
                    kind: LimitKind::ToolDeviation,
                    sample: k,
                    joint: 0,
                    value: distance,
                    limit: planned.tolerance_m,
                });
            }
        }
    }
    let times: Vec<f64> = trajectory
        .points
        .iter()
        .map(|p| p.time_from_start)
        .collect();
    let positions: Vec<&[f64]> = trajectory
        .points
        .iter()
        .map(|p| p.positions.as_slice())
        .collect();
    if let Some((ratio, sample, joint, value)) = sample_jerk(&times, &positions, limits.jerk)
        && ratio > 1.0 + tolerance
    {
        return Err(LimitViolation {
            kind: LimitKind::Jerk,
            sample,
            joint,
            value,
            limit: limits.jerk[joint],
        });
    }
    Ok(())
}

/// `|value| ≤ limit (1 + tolerance)`; false for NaN.
fn within(value: f64, limit: f64, tolerance: f64) -> bool {
    value.abs() <= limit * (1.0 + tolerance)
}

#[cfg(test)]
mod tests {
    use super::super::grid::PathGrid;
    use super::super::spline::{chord_knots, widest_radii};
    use super::*;

    /// A trajectory of two joints timed on a blended path, its profile, and
    /// the path; the second joint is continuous (infinite limits).
    fn timed() -> (JointTrajectory, PiecewiseCubic, SpeedProfile) {
        let points: Vec<&[f64]> = vec![&[0.0, 0.0], &[0.5, 7.0], &[1.0, 7.5]];
        let knots = chord_knots(&points);
        let path = PiecewiseCubic::blended(&points, &knots, &widest_radii(&knots));
        let grid = PathGrid::new(&path, 50);
        let mut b = vec![0.04; grid.s.len()];
        b[0] = 0.0;
        *b.last_mut().unwrap() = 0.0;
        let profile = SpeedProfile::new(&grid, &b);
        let trajectory = sample(
            &Filtered::new(&path, &profile, 0.0),
            100.0,
            (points[0], points[2]),
        );
        (trajectory, path, profile)
    }

    fn check(
        trajectory: &JointTrajectory,
        path: &PiecewiseCubic,
        profile: &SpeedProfile,
    ) -> Result<(), LimitViolation> {
        let limits = SampleLimits {
            lower: &[-1.0, f64::NEG_INFINITY],
            upper: &[1.0, f64::INFINITY],
            velocity: &[10.0, 10.0],
            acceleration: &[100.0, 100.0],
            jerk: &[],
            tolerance: 1e-6,
        };
        let motion = Filtered::new(path, profile, 0.0);
        let checks = PathChecks {
            path,
            motion: &motion,
            tool_path: None,
        };
        verify(trajectory, &limits, &checks)
    }

    #[test]
    fn sample_steps_at_most_a_period_the_last_at_least_half() {
        let (_, path, profile) = timed();
        let duration = profile.duration();
        // A rate whose grid puts a regular sample 1e-4 periods before the end.
        let periods = (duration * 100.0).floor() + 1e-4;
        let rate = periods / duration;
        let ends: (&[f64], &[f64]) = (&[0.0, 0.0], &[1.0, 7.5]);
        let trajectory = sample(&Filtered::new(&path, &profile, 0.0), rate, ends);
        let times: Vec<f64> = trajectory
            .points
            .iter()
            .map(|p| p.time_from_start)
            .collect();
        let last = times[times.len() - 1] - times[times.len() - 2];
        assert!(
            last >= 0.5 / rate - 1e-12,
            "last step {last} s at {rate} Hz"
        );
        assert_eq!(*times.last().unwrap(), duration);
        let period = 1.0 / rate;
        assert!(
            times
                .windows(2)
                .all(|w| w[1] > w[0] && w[1] - w[0] <= period + 1e-12)
        );
    }

    #[test]
    fn a_sample_past_a_position_limit_is_a_violation() {
        let (mut trajectory, path, profile) = timed();
        assert_eq!(check(&trajectory, &path, &profile), Ok(()));
        trajectory.points[3].positions[0] = 1.001;
        let violation = check(&trajectory, &path, &profile).unwrap_err();
        assert_eq!(
            (
                violation.kind,
                violation.sample,
                violation.joint,
                violation.limit
            ),
            (LimitKind::Position, 3, 0, 1.0)
        );
    }

    #[test]
    fn a_continuous_joint_is_not_limited() {
        let (mut trajectory, path, profile) = timed();
        trajectory.points[3].positions[1] = 1e6;
        assert_eq!(check(&trajectory, &path, &profile), Ok(()));
    }
}
