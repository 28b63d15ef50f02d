//! What the timing stage gives back: a refusal of bad input
//! ([`TimingError`]), how the stage ended ([`TimingStatus`]), the solver's
//! and the separation rule's figures, and the timed result ([`Timing`]).

use serde::Serialize;

use super::sample::{JointTrajectory, LimitViolation, SpeedProfile};
use super::topp::SolverOutcome;

/// Most samples one timed path may hold (`duration × rate + 1`): 100 s at
/// 100 Hz, 10 s at 1 kHz. A longer path is refused with
/// [`TimingError::TooManySamples`] before any sample is allocated, so the
/// trajectory's memory is bounded whatever the limits and the rate
/// (README "Limits").
pub const MAX_SAMPLES: usize = 10_000;

/// Bad input to the timing stage.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TimingError {
    #[error("a joint path needs at least one waypoint")]
    NoWaypoints,
    #[error("waypoint {index} has {len} joints, expected {expected}")]
    WaypointLength {
        index: usize,
        len: usize,
        expected: usize,
    },
    #[error("{what} has {len} entries, expected {expected}")]
    SizeMismatch {
        what: &'static str,
        len: usize,
        expected: usize,
    },
    #[error("{what}[{index}] is not finite")]
    NonFinite { what: &'static str, index: usize },
    #[error("position limits of joint {joint} are [{lower}, {upper}], expected lower ≤ upper")]
    BadPositionLimits {
        joint: usize,
        lower: f64,
        upper: f64,
    },
    #[error("waypoint {index}: joint {joint} at {value} is outside its limits [{lower}, {upper}]")]
    WaypointOutsideLimits {
        index: usize,
        joint: usize,
        value: f64,
        lower: f64,
        upper: f64,
    },
    #[error("{what} limit of joint {joint} is {value}, expected finite and > 0")]
    BadLimit {
        what: &'static str,
        joint: usize,
        value: f64,
    },
    #[error("setting {field} = {value}, expected {expected}")]
    Setting {
        field: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error(
        "the motion would last {duration_s:.1} s, {samples:.0} samples at {rate_hz} Hz; \
         at most {max} samples are allowed (slow joint limits or crawling near a hand; \
         lower the rate or move the hand)",
        max = MAX_SAMPLES
    )]
    TooManySamples {
        duration_s: f64,
        rate_hz: f64,
        samples: f64,
    },
    #[error(
        "the path passes {distance_m:.3} m from a hand at s = {s:.4}, inside the protective \
         separation distance {required_m:.3} m, and min_tool_speed_m_s is 0"
    )]
    InsideProtectiveDistance {
        s: f64,
        distance_m: f64,
        required_m: f64,
    },
}

/// How the stage ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "status")]
#[non_exhaustive]
pub enum TimingStatus {
    /// Timed, sampled and every sample checked.
    Solved,
    /// Clarabel did not reach a usable solution.
    SolverStopped { outcome: SolverOutcome },
    /// A sample broke a limit; no trajectory is emitted.
    LimitViolated { violation: LimitViolation },
}

/// The status in words a user can act on (never the Debug form).
impl std::fmt::Display for TimingStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Solved => write!(f, "timed"),
            Self::SolverStopped { outcome } => write!(
                f,
                "no time-optimal motion was found along this path ({})",
                match outcome {
                    SolverOutcome::Infeasible =>
                        "the joint limits or a hand's speed limit leave no way to move along it",
                    SolverOutcome::LimitReached => "the timing program did not converge in time",
                    _ =>
                        "the timing program ran into numerical trouble; the path or the joint limits are extreme",
                }
            ),
            Self::LimitViolated { violation } => write!(
                f,
                "the sampled motion breaks a {} limit at sample {} ({:.4} > {:.4})",
                match violation.kind {
                    super::sample::LimitKind::Position => "joint position",
                    super::sample::LimitKind::ToolDeviation => "tool-path deviation",
                    super::sample::LimitKind::Velocity => "joint velocity",
                    super::sample::LimitKind::Acceleration => "joint acceleration",
                    super::sample::LimitKind::ToolSpeed => "tool speed",
                    super::sample::LimitKind::Jerk => "joint jerk",
                },
                violation.sample,
                violation.value.abs(),
                violation.limit
            ),
        }
    }
}

/// Solver figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolveStats {
    pub outcome: SolverOutcome,
    /// Clarabel's iterations; 0 when the two passes solved the LP.
    pub iterations: u32,
    /// Grid segments `N` actually used.
    pub segments: usize,
    /// Linear rows kept after pruning.
    pub linear_rows: usize,
    /// Solve time of the last program (the two passes or Clarabel), seconds.
    pub solve_time_s: f64,
    /// Refinement rounds run after the first solve.
    pub refinements: u32,
    /// Width of the jerk filter, seconds: the motion lasts this much
    /// longer than its profile (0 without jerk limits).
    pub jerk_filter_s: f64,
    /// How much longer the profile is than the time-optimal one, seconds,
    /// where its accelerations were lowered around switches for a narrower
    /// filter (0 when the time-optimal profile was kept).
    pub jerk_ramp_s: f64,
    /// Times the path was timed again with the hands' caps lowered where
    /// the tool was over one (0 without hands or when none was).
    pub tool_speed_rounds: u32,
    /// Whole stage (spline to checked samples), seconds.
    pub total_time_s: f64,
}

/// What the separation rule did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeparationSummary {
    /// Smallest tool–hand distance on the grid, metres.
    pub min_distance_m: f64,
    /// Smallest tool-speed cap on any segment, m/s.
    pub min_cap_m_s: f64,
    /// Segments capped at or below the reduced speed.
    pub reduced_segments: usize,
    /// Segments at the crawl floor (the formula asked for a stop).
    pub crawl_segments: usize,
}

/// The result of [`time_parameterize`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Timing {
    pub status: TimingStatus,
    /// The sampled trajectory: `Some` exactly when `status` is `Solved`.
    pub trajectory: Option<JointTrajectory>,
    /// The speed profile on the grid (present whenever Clarabel returned one).
    pub profile: Option<SpeedProfile>,
    pub stats: SolveStats,
    pub separation: Option<SeparationSummary>,
}

impl Timing {
    /// Duration of the trajectory, seconds, when solved.
    pub fn duration(&self) -> Option<f64> {
        self.trajectory.as_ref().map(JointTrajectory::duration)
    }
}
