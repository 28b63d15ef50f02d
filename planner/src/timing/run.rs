//! The timing stage as one pure function: inputs, settings, errors, status.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::deviation::{ToolFk, ToolPathCheck, narrow_radii};
use super::grid::{self, PathGrid};
use super::sample::{self, JointTrajectory, LimitKind, LimitViolation, SpeedProfile};
use super::separation::{Hand, SeparationSettings, nearest_hand_distance};
use super::spline::{PiecewiseCubic, chord_knots, widest_radii};
use super::taut;
use super::tool_speed::{self, Excess, ToolSpeedCheck};
use super::topp::{self, ProfileSolution, Program, ProgramSettings, SegmentRows, SolverOutcome};
use super::{jerk, ramp};

/// Per-joint limits of one arm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointLimits {
    /// Lower position limit of each joint, rad (m for a prismatic joint);
    /// `-inf` for a continuous joint.
    pub lower: Vec<f64>,
    /// Upper position limit, rad (m); `+inf` for a continuous joint.
    pub upper: Vec<f64>,
    /// `v_j`, rad/s (> 0).
    pub velocity: Vec<f64>,
    /// `A_j`, rad/s² (> 0).
    pub acceleration: Vec<f64>,
    /// `J_j`, rad/s³ (> 0), one per joint, or empty for no jerk limit. With
    /// them the time-optimal trajectory is averaged over the shortest
    /// window that keeps every joint's jerk within its limit ([`jerk`](super::jerk)).
    #[serde(default)]
    pub jerk: Vec<f64>,
}

/// Where the tool goes and where the hands are, for the separation rule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Proximity {
    /// Tool-centre position at each joint waypoint (forward kinematics of
    /// the waypoint), robot base frame, metres.
    pub tool_positions: Vec<[f64; 3]>,
    /// Hands seen by the camera.
    pub hands: Vec<Hand>,
    /// The speed-and-separation rule.
    #[serde(default)]
    pub rule: SeparationSettings,
}

/// Settings of the timing stage. Every default is written here once.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TimingSettings {
    /// Number of path segments `N` (grid points `N + 1`), 300: measured
    /// against toppra on 10 seeded iiwa paths the duration is then at most
    /// 0.07 % above the time-optimal reference, on 18 pieces of two
    /// examples' real paths at most 1.11 % (docs/decisions.md).
    /// At least one segment per spline piece is used, so more waypoints than
    /// this give more.
    pub path_points: usize,
    /// Refinement rounds after the first solve, 1: each cuts the segments
    /// where a constraint binds and the profile leaves room under the limits
    /// (see `refine_looseness`) and solves again (docs/decisions.md: the
    /// bound segments are where the per-segment bounds cost time).
    pub refine_rounds: u32,
    /// Refinement stops once a round gains less than this fraction of the
    /// duration, 1e-3.
    pub refine_tolerance: f64,
    /// A bound segment is cut where, at some point of it, the profile uses
    /// less than `1 − refine_looseness` of every limit (measured on the
    /// path, not on the rows' Bernstein coefficients: see
    /// [`grid::joint_utilisation`]), into about `gap / refine_looseness`
    /// parts (2 to 8), 2e-3. 0 cuts every bound segment whose rows may be
    /// first-order conservative into 4 (one of the reference's solves).
    pub refine_looseness: f64,
    /// Tool budget, metres, for pulling the joints taut ([`taut`](super::taut)),
    /// 0.0015: each smoothed waypoint's tool within this of the planned tool
    /// path (the corner blends add up to half of `max_tool_deviation_m`).
    /// 0 keeps the waypoints as they are. Used when the arm's forward
    /// kinematics is given.
    pub taut_tool_budget_m: f64,
    /// Controller sampling rate, Hz, 100.
    pub rate_hz: f64,
    /// Global speed scale `k ∈ (0, 1]`, 1: velocity limits × k, acceleration × k².
    pub speed_scale: f64,
    /// `w ≥ 0` of the smoothing term `w Σ (a_{i+1} − a_i)²`, 0 (pure minimum
    /// time). `w > 0` selects the SOCP form.
    pub smoothing_weight: f64,
    /// Relative margin taken off every limit inside the program, 1e-6.
    pub limit_margin: f64,
    /// Relative tolerance of the sample check, 1e-6.
    pub tolerance: f64,
    /// The convex program: the LP for the greatest profile (default) or the
    /// SOCP with the exact time objective; same optimum (see [`topp`](super::topp)).
    pub program: Program,
    /// Clarabel's iteration limit (the SOCP, or an LP off the lattice), 100.
    pub max_iterations: u32,
    /// Clarabel's duality-gap tolerance (absolute and relative), 1e-7.
    pub solver_tolerance: f64,
    /// Largest distance, metres, of any sample's tool from the planned tool
    /// path (the tool path of the joint polyline the collision stage
    /// checked), 0.005. Corner blends are sized for half of it; checked on
    /// every sample when the arm's forward kinematics is given.
    pub max_tool_deviation_m: f64,
    /// Relative margin taken off every tool-speed cap near a hand inside
    /// the program, 0.02. The program bounds the speed of the tool-space
    /// interpolant; the tool really follows forward kinematics of the joint
    /// path, measured up to 3 % faster where a profile sits on a crawl cap.
    /// With the arm's forward kinematics every sample's real tool speed is
    /// checked against the rule's cap and the caps are lowered where it is
    /// over ([`tool_speed`](super::tool_speed)); the margin makes that rare.
    pub tool_speed_margin: f64,
    /// With jerk limits, rounds of timing the path again below the
    /// time-optimal profile with its peaks rounded, so that the path
    /// acceleration falls at a jerk-limited rate where it switches
    /// ([`ramp`](super::ramp)), 1 (a second round gains nothing on the
    /// examples); the rounded profile is kept when it and its narrowest
    /// filter end sooner than the time-optimal one with its own. 0: the
    /// filter alone.
    pub jerk_ramp_rounds: u32,
}

impl Default for TimingSettings {
    fn default() -> Self {
        Self {
            path_points: 300,
            refine_rounds: 1,
            refine_tolerance: 1e-3,
            refine_looseness: 2e-3,
            taut_tool_budget_m: 0.0015,
            rate_hz: 100.0,
            speed_scale: 1.0,
            smoothing_weight: 0.0,
            limit_margin: 1e-6,
            tolerance: 1e-6,
            program: Program::GreatestProfile,
            max_iterations: 100,
            solver_tolerance: 1e-7,
            max_tool_deviation_m: 0.005,
            tool_speed_margin: 0.02,
            jerk_ramp_rounds: 1,
        }
    }
}

impl TimingSettings {
    /// Checks every field is finite and in range.
    pub fn validate(&self) -> Result<(), TimingError> {
        let checks: [(&'static str, f64, bool, &'static str); 11] = [
            (
                "taut_tool_budget_m",
                self.taut_tool_budget_m,
                self.taut_tool_budget_m >= 0.0,
                "≥ 0",
            ),
            (
                "refine_tolerance",
                self.refine_tolerance,
                self.refine_tolerance >= 0.0,
                "≥ 0",
            ),
            (
                "refine_looseness",
                self.refine_looseness,
                (0.0..1.0).contains(&self.refine_looseness),
                "in [0, 1)",
            ),
            ("rate_hz", self.rate_hz, self.rate_hz > 0.0, "> 0"),
            (
                "speed_scale",
                self.speed_scale,
                self.speed_scale > 0.0 && self.speed_scale <= 1.0,
                "in (0, 1]",
            ),
            (
                "smoothing_weight",
                self.smoothing_weight,
                self.smoothing_weight >= 0.0,
                "≥ 0",
            ),
            (
                "limit_margin",
                self.limit_margin,
                (0.0..0.5).contains(&self.limit_margin),
                "in [0, 0.5)",
            ),
            ("tolerance", self.tolerance, self.tolerance >= 0.0, "≥ 0"),
            (
                "max_tool_deviation_m",
                self.max_tool_deviation_m,
                self.max_tool_deviation_m > 0.0,
                "> 0",
            ),
            (
                "tool_speed_margin",
                self.tool_speed_margin,
                (0.0..0.5).contains(&self.tool_speed_margin),
                "in [0, 0.5)",
            ),
            (
                "solver_tolerance",
                self.solver_tolerance,
                self.solver_tolerance > 0.0 && self.solver_tolerance < 1.0,
                "in (0, 1)",
            ),
        ];
        for (field, value, ok, expected) in checks {
            if !(value.is_finite() && ok) {
                return Err(TimingError::Setting {
                    field,
                    value,
                    expected,
                });
            }
        }
        if self.path_points < 2 {
            return Err(TimingError::Setting {
                field: "path_points",
                value: self.path_points as f64,
                expected: "≥ 2",
            });
        }
        if self.max_iterations == 0 {
            return Err(TimingError::Setting {
                field: "max_iterations",
                value: 0.0,
                expected: "≥ 1",
            });
        }
        Ok(())
    }
}

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

/// Times a joint path without the arm's forward kinematics: as
/// [`time_parameterize_tool`] with the corners blended at their widest and
/// no tool-path check.
pub fn time_parameterize(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    proximity: Option<&Proximity>,
    settings: &TimingSettings,
) -> Result<Timing, TimingError> {
    time_parameterize_tool(waypoints, limits, proximity, None, settings)
}

/// Times one arm's joint path: blended path → grid → separation caps →
/// rows → LP (two passes) or SOCP (Clarabel) → sampling → check of every sample (positions,
/// velocities, accelerations, tool speed near hands, and with `fk` the
/// tool's distance from the planned tool path). `Err` only for bad input
/// (a waypoint outside the position limits included); a solver that stops
/// early or a sample outside a limit is a [`TimingStatus`]. Consecutive
/// identical waypoints are merged; a path of one configuration gives a
/// one-sample trajectory at rest.
pub fn time_parameterize_tool(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    proximity: Option<&Proximity>,
    fk: Option<ToolFk>,
    settings: &TimingSettings,
) -> Result<Timing, TimingError> {
    let started = Instant::now();
    settings.validate()?;
    validate_input(waypoints, limits, proximity)?;

    // Merge repeated waypoints (zero chord) with their tool positions.
    let mut keep: Vec<usize> = vec![0];
    for k in 1..waypoints.len() {
        let last = &waypoints[*keep.last().expect("non-empty")];
        if waypoints[k] != *last {
            keep.push(k);
        }
    }
    if keep.len() == 1 {
        return Ok(at_rest(&waypoints[0], started));
    }
    let points: Vec<&[f64]> = keep.iter().map(|&k| waypoints[k].as_slice()).collect();
    let tool_points: Option<Vec<[f64; 3]>> = proximity
        .filter(|p| !p.hands.is_empty())
        .map(|p| keep.iter().map(|&k| p.tool_positions[k]).collect());
    let planned = fk.map(|fk| ToolPathCheck::new(&points, fk, settings.max_tool_deviation_m));
    let taut = match (fk, &planned) {
        (Some(fk), Some(planned)) if settings.taut_tool_budget_m > 0.0 => taut::pull_taut(
            &points,
            &chord_knots(&points),
            (&limits.lower, &limits.upper),
            fk,
            planned,
            settings.taut_tool_budget_m,
        )
        .filter(|q| q.windows(2).all(|w| w[0] != w[1])),
        _ => None,
    };
    let path = Path {
        points: &points,
        tool_points: tool_points.as_deref(),
        planned: planned.as_ref(),
    };
    // The joints pulled taut, else (no budget, or a sample off the planned
    // tool path or beyond a limit) the waypoints as they are.
    if let Some(taut) = &taut {
        let taut_points: Vec<&[f64]> = taut.iter().map(Vec::as_slice).collect();
        let taut_tools: Option<Vec<[f64; 3]>> = tool_points
            .as_ref()
            .zip(fk)
            .map(|(_, fk)| taut.iter().map(|q| fk(q)).collect());
        let timing = time_path(
            &Path {
                points: &taut_points,
                tool_points: taut_tools.as_deref(),
                planned: planned.as_ref(),
            },
            limits,
            proximity,
            fk,
            settings,
            started,
        )?;
        if timing.status == TimingStatus::Solved {
            return Ok(timing);
        }
    }
    time_path(&path, limits, proximity, fk, settings, started)
}

/// The joint path to time and the tool path it must keep to.
struct Path<'a> {
    /// Joint waypoints (consecutive ones distinct).
    points: &'a [&'a [f64]],
    /// The tool at each waypoint when hands are near, metres.
    tool_points: Option<&'a [[f64; 3]]>,
    /// The planned tool path (the collision-checked joint polyline's).
    planned: Option<&'a ToolPathCheck<'a>>,
}

/// Blended path → grid → program → jerk filter → samples → checks.
fn time_path(
    path: &Path,
    limits: &JointLimits,
    proximity: Option<&Proximity>,
    fk: Option<ToolFk>,
    settings: &TimingSettings,
    started: Instant,
) -> Result<Timing, TimingError> {
    let points = path.points;
    let knots = chord_knots(points);
    let mut radii = widest_radii(&knots);
    if let Some(fk) = fk {
        narrow_radii(
            points,
            &knots,
            &mut radii,
            fk,
            0.5 * settings.max_tool_deviation_m,
        );
    }
    let spline = PiecewiseCubic::blended(points, &knots, &radii);

    // Limits inside the program: scaled, with the margin taken off.
    let k = settings.speed_scale;
    let shrink = 1.0 - settings.limit_margin;
    let program = ProgramLimits {
        vel_sq: limits
            .velocity
            .iter()
            .map(|v| (v * k * shrink).powi(2))
            .collect(),
        acc: limits
            .acceleration
            .iter()
            .map(|a| a * k * k * shrink)
            .collect(),
        tool_shrink: shrink * (1.0 - settings.tool_speed_margin),
    };
    let tool_spline = path.tool_points.map(|tools| {
        let tools: Vec<&[f64]> = tools.iter().map(|p| p.as_slice()).collect();
        PiecewiseCubic::blended(&tools, &knots, &radii)
    });
    let tool = tool_spline.as_ref().zip(proximity);

    let inputs = Inputs {
        spline: &spline,
        program: &program,
        tool,
        tool_spline: tool_spline.as_ref(),
        limits,
        settings,
        points,
        planned: path.planned,
        started,
    };
    // Where the tool is over a hand's cap at some sample (the jerk filter
    // mixing the speeds of a stretch of path, or the real tool faster than
    // the interpolant the program bounds), the caps there are lowered and
    // the path is timed again: first, with the filter, every cap to the
    // smallest within the distance the filter spans; then each over-cap
    // stretch's caps by its measured excess. A trajectory still over after
    // `TOOL_SPEED_ROUNDS` is a `LimitViolated` status, never emitted.
    let mut shape = CapShape::default();
    let mut round = 0;
    loop {
        let solved = solve_refined(&inputs, &shape)?;
        let (mut timing, excess) = finish(&inputs, ramp_at_switches(&inputs, solved))?;
        timing.stats.tool_speed_rounds = round;
        let over = matches!(
            timing.status,
            TimingStatus::LimitViolated {
                violation: LimitViolation {
                    kind: LimitKind::ToolSpeed,
                    ..
                },
            }
        );
        if !over || excess.is_empty() || round == TOOL_SPEED_ROUNDS {
            return Ok(timing);
        }
        match &timing.profile {
            Some(profile) if timing.stats.jerk_filter_s > 0.0 && shape.window.is_none() => {
                shape.window = Some(FilterWindow {
                    s: profile.s.clone(),
                    t: profile.t.clone(),
                    tau: WINDOW_SLACK * timing.stats.jerk_filter_s,
                });
            }
            _ => shape.lower(&excess, program.tool_shrink),
        }
        round += 1;
    }
}

/// Most times a path is timed again with its caps lowered where the tool
/// was over a hand's cap (see [`time_path`]).
const TOOL_SPEED_ROUNDS: u32 = 4;

/// A lowered cap lands this fraction below the measured excess.
const LOWER_SLACK: f64 = 2e-3;

/// A cut never takes the interpolant's cap below this share of the limit:
/// a real tool more than twice as fast as the interpolant is a path whose
/// forward kinematics and tool positions disagree, not a timing to slow
/// down without end (the rounds then end in a `LimitViolated` status).
const LOWEST_CUT: f64 = 0.5;

/// The filter's window is taken this much wider than the width it had
/// when the caps are lowered for it (the path timed again may filter wider).
const WINDOW_SLACK: f64 = 1.25;

/// How the hands' caps are lowered below the rule's.
#[derive(Debug, Default)]
struct CapShape {
    /// Each segment's cap to the smallest over the stretch of path the jerk
    /// filter mixes into its samples; none before the first filter.
    window: Option<FilterWindow>,
    /// At most this cap, m/s, on the segments the stretch `[s_lo, s_hi]`
    /// touches.
    cuts: Vec<((f64, f64), f64)>,
}

impl CapShape {
    /// Lowers each excess's stretch to the interpolant speed at which the
    /// tool meets its limit: the interpolant's speed there times
    /// `limit / speed`, at least [`LOWEST_CUT`] of the limit, as a cap
    /// before the program's `tool_shrink`.
    fn lower(&mut self, excess: &[Excess], tool_shrink: f64) {
        self.cuts.extend(excess.iter().map(|e| {
            let meets = e.interpolant * e.limit / e.speed * (1.0 - LOWER_SLACK);
            (e.stretch, meets.max(LOWEST_CUT * e.limit) / tool_shrink)
        }));
    }

    /// Applies the cuts to `caps`, one per segment of `grid`.
    fn cut(&self, grid: &PathGrid, caps: &mut [f64]) {
        for &(stretch, most) in &self.cuts {
            for cap in &mut caps[touched(grid, stretch)] {
                *cap = cap.min(most);
            }
        }
    }

    /// `grid` with each segment a cut touches split into parts about as
    /// long as the cut's stretch (at most [`MOST_PARTS`]), so that a cut
    /// slows no more of the path than it must.
    fn split(&self, grid: PathGrid) -> PathGrid {
        if self.cuts.is_empty() {
            return grid;
        }
        let mut parts = vec![1; grid.segments()];
        for &((lo, hi), _) in &self.cuts {
            for i in touched(&grid, (lo, hi)) {
                let wanted = (grid.step(i) / (hi - lo).max(f64::MIN_POSITIVE)).ceil();
                parts[i] = parts[i].max(wanted.min(MOST_PARTS as f64) as usize);
            }
        }
        grid.split(|i| parts[i])
    }
}

/// Where the jerk filter mixes speeds: a sample at time `t` averages the
/// path over `[t − τ, t]`, so every sample that averages a point of the
/// stretch `[lo, hi]` averages only path the profile crosses within `τ`
/// before `lo` or after `hi`. Read on the profile timed before the caps
/// are lowered: lowered caps only lower the time-optimal profile, so the
/// stretch found covers the one the slower motion mixes, with
/// [`WINDOW_SLACK`] for a wider filter. Where the motion timed again is
/// still over a cap (a rounded peak moved, say), the samples' check finds
/// it and the cuts of [`CapShape::lower`] follow, as before.
#[derive(Debug)]
struct FilterWindow {
    /// The earlier profile's grid points and their times (s, seconds).
    s: Vec<f64>,
    t: Vec<f64>,
    /// The window, seconds.
    tau: f64,
}

impl FilterWindow {
    /// The path the filter mixes into samples on `[lo, hi]`, whole
    /// segments of the earlier profile's grid outward.
    fn stretch(&self, lo: f64, hi: f64) -> (f64, f64) {
        let last = self.s.len() - 1;
        let at_or_before =
            |values: &[f64], x: f64| values.partition_point(|&v| v <= x).saturating_sub(1);
        let at_or_after = |values: &[f64], x: f64| values.partition_point(|&v| v < x).min(last);
        let t_lo = self.t[at_or_before(&self.s, lo)] - self.tau;
        let t_hi = self.t[at_or_after(&self.s, hi)] + self.tau;
        (
            self.s[at_or_before(&self.t, t_lo)],
            self.s[at_or_after(&self.t, t_hi)],
        )
    }
}

/// The segments of `grid` that the stretch `[lo, hi]` touches.
fn touched(grid: &PathGrid, (lo, hi): (f64, f64)) -> std::ops::Range<usize> {
    let from = grid.s.partition_point(|&s| s < lo).saturating_sub(1);
    let to = grid.s.partition_point(|&s| s <= hi).min(grid.segments());
    from..to.max(from)
}

/// What [`solve_refined`] and [`finish`] share.
struct Inputs<'a> {
    spline: &'a PiecewiseCubic,
    program: &'a ProgramLimits,
    tool: Option<(&'a PiecewiseCubic, &'a Proximity)>,
    tool_spline: Option<&'a PiecewiseCubic>,
    limits: &'a JointLimits,
    settings: &'a TimingSettings,
    points: &'a [&'a [f64]],
    planned: Option<&'a ToolPathCheck<'a>>,
    started: Instant,
}

/// The program on the first grid, then refined where a constraint binds
/// (`settings.refine_rounds`); the hands' caps lowered as `shape` says.
/// Also the rounds run.
fn solve_refined(inputs: &Inputs, shape: &CapShape) -> Result<(Solved, u32), TimingError> {
    let Inputs {
        spline,
        program,
        tool,
        settings,
        ..
    } = *inputs;
    let mut solved = solve_on_grid(
        spline,
        shape.split(PathGrid::new(spline, settings.path_points)),
        program,
        tool,
        settings,
        shape,
    )?;
    let mut rounds = 0;
    let most = settings.path_points.max(solved.grid.segments()) * MAX_REFINED_GROWTH;
    while rounds < settings.refine_rounds && solved.usable() && solved.grid.segments() < most {
        let parts = solved.refinable(inputs);
        if parts.iter().all(|&p| p <= 1) {
            break;
        }
        let finer = solved.grid.split(|i| parts[i]);
        let next = solve_on_grid(spline, finer, program, tool, settings, shape)?;
        rounds += 1;
        if !next.usable() {
            break;
        }
        let (before, after) = (solved.duration(), next.duration());
        solved = next;
        if before - after <= settings.refine_tolerance * before {
            break;
        }
    }
    Ok((solved, rounds))
}

/// Samples the solved profile through the jerk filter and checks every
/// sample; also every sample interval where the tool is over a hand's cap.
fn finish(
    inputs: &Inputs,
    Ramped {
        solved,
        rounds,
        narrow,
        ramp_s,
    }: Ramped,
) -> Result<(Timing, Vec<Excess>), TimingError> {
    let Inputs {
        spline,
        program,
        limits,
        settings,
        points,
        planned,
        started,
        ..
    } = *inputs;
    let k = settings.speed_scale;
    let Solved {
        grid,
        rows,
        solution,
        tool: tool_caps,
    } = solved;
    let n = grid.segments();
    let tool = inputs.tool_spline.zip(tool_caps);
    let mut stats = SolveStats {
        outcome: solution.outcome,
        iterations: solution.iterations,
        segments: n,
        linear_rows: rows.rows.len(),
        solve_time_s: solution.solve_time_s,
        refinements: rounds,
        jerk_filter_s: 0.0,
        jerk_ramp_s: ramp_s,
        tool_speed_rounds: 0,
        total_time_s: 0.0,
    };
    let separation = tool.as_ref().map(|(_, t)| t.summary.clone());
    if !usable(&solution) {
        stats.total_time_s = started.elapsed().as_secs_f64();
        let outcome = match solution.outcome {
            SolverOutcome::Solved | SolverOutcome::AlmostSolved => SolverOutcome::NumericalError,
            other => other,
        };
        let timing = Timing {
            status: TimingStatus::SolverStopped { outcome },
            trajectory: None,
            profile: None,
            stats,
            separation,
        };
        return Ok((timing, Vec::new()));
    }

    let profile = SpeedProfile::new(&grid, &solution.b);
    let velocity: Vec<f64> = limits.velocity.iter().map(|v| v * k).collect();
    let acceleration: Vec<f64> = limits.acceleration.iter().map(|a| a * k * k).collect();
    // The filter keeps the jerk within the limits less the program's margin,
    // so the samples stay strictly inside them whatever the rounding.
    let jerk_kept = jerk_kept(limits, settings);
    let widest = jerk::jerk_bound_width(&program.acc, &jerk_kept).unwrap_or(0.0);
    let samples = ((profile.duration() + widest) * settings.rate_hz).ceil() + 1.0;
    if !samples.is_finite() || samples > MAX_SAMPLES as f64 {
        return Err(TimingError::TooManySamples {
            duration_s: profile.duration() + widest,
            rate_hz: settings.rate_hz,
            samples,
        });
    }
    let ends = (points[0], points[points.len() - 1]);
    let sample_limits = sample::SampleLimits {
        lower: &limits.lower,
        upper: &limits.upper,
        velocity: &velocity,
        acceleration: &acceleration,
        jerk: &limits.jerk,
        tolerance: settings.tolerance,
    };
    // The narrowest filter found on the profile, then (should its samples
    // break a limit) the width that bounds every joint's jerk.
    let mut widths = vec![narrow];
    if widest > narrow {
        widths.push(widest);
    }
    // Every sample's interpolant speed within the caps the program kept
    // (`tool_speed_margin` below the rule's: the margin is for the real
    // tool's speed, not for the averaging), the real tool's within the
    // rule's.
    let kept_caps: Option<Vec<f64>> = tool
        .as_ref()
        .map(|(_, t)| t.limits.iter().map(|c| c * program.tool_shrink).collect());
    let speed_check = tool
        .as_ref()
        .zip(kept_caps.as_deref())
        .zip(inputs.tool)
        .map(|(((spline, caps), kept), (_, proximity))| ToolSpeedCheck {
            tool: spline,
            kept,
            limits: &caps.limits,
            hands: &proximity.hands,
            rule: &proximity.rule,
            real: planned,
        });
    let mut outcome = None;
    for tau in widths {
        let motion = jerk::Filtered::new(spline, &profile, tau);
        let trajectory = sample::sample(&motion, settings.rate_hz, ends);
        let tools: Option<Vec<[f64; 3]>> = planned.map(|planned| {
            trajectory
                .points
                .iter()
                .map(|p| planned.fk_of(&p.positions))
                .collect()
        });
        let excess = speed_check.as_ref().map_or_else(Vec::new, |c| {
            tool_speed::excess(
                &trajectory,
                &profile,
                &motion,
                c,
                tools.as_deref(),
                settings.tolerance,
            )
        });
        let check = match excess.first() {
            Some(over) => Err(over.violation()),
            None => sample::verify(
                &trajectory,
                &sample_limits,
                &sample::PathChecks {
                    path: spline,
                    motion: &motion,
                    tool_path: planned.zip(tools.as_deref()),
                },
            ),
        };
        stats.jerk_filter_s = tau;
        let passed = check.is_ok();
        outcome = Some((check, trajectory, excess));
        if passed {
            break;
        }
    }
    let (check, trajectory, excess) = outcome.expect("at least one filter width is tried");
    debug_assert_eq!(trajectory.points[0].positions.len(), limits.velocity.len());
    stats.total_time_s = started.elapsed().as_secs_f64();
    let (status, trajectory) = match check {
        Ok(()) => (TimingStatus::Solved, Some(trajectory)),
        Err(violation) => (TimingStatus::LimitViolated { violation }, None),
    };
    let timing = Timing {
        status,
        trajectory,
        profile: Some(profile),
        stats,
        separation,
    };
    Ok((timing, excess))
}

/// The jerk limits the filter keeps: the limits less the program's margin,
/// so the samples stay strictly inside them whatever the rounding.
fn jerk_kept(limits: &JointLimits, settings: &TimingSettings) -> Vec<f64> {
    limits
        .jerk
        .iter()
        .map(|j| j * (1.0 - settings.limit_margin))
        .collect()
}

/// A solved profile with the narrowest jerk filter found for it.
struct Ramped {
    solved: Solved,
    /// Refinement rounds run.
    rounds: u32,
    /// The narrowest filter width whose probes keep the jerk, seconds.
    narrow: f64,
    /// How much longer the profile is than the time-optimal one, seconds.
    ramp_s: f64,
}

/// The time-optimal profile with its narrowest jerk filter, or (with jerk
/// limits and `settings.jerk_ramp_rounds > 0`) the same lattice rows with
/// `b ≤ g`, `g` the time-optimal profile with its peaks rounded
/// ([`ramp::rounded_peaks`], each round at the last profile's speeds),
/// whichever ends sooner with its own narrowest filter. Every one keeps
/// every limit the lattice rows bound; the samples of the one kept are
/// checked as every profile's are.
fn ramp_at_switches(inputs: &Inputs, (solved, rounds): (Solved, u32)) -> Ramped {
    let Inputs {
        spline,
        program,
        limits,
        settings,
        ..
    } = *inputs;
    let kept = jerk_kept(limits, settings);
    let profile = |solved: &Solved| SpeedProfile::new(&solved.grid, &solved.solution.b);
    let plain = match solved.usable() {
        true => jerk::filter_width(spline, &profile(&solved), &program.acc, &kept),
        false => 0.0,
    };
    if settings.jerk_ramp_rounds == 0 || plain == 0.0 {
        return Ramped {
            solved,
            rounds,
            narrow: plain,
            ramp_s: 0.0,
        };
    }
    let optimal = solved.duration();
    let program_settings = ProgramSettings {
        program: settings.program,
        smoothing_weight: settings.smoothing_weight,
        max_iterations: settings.max_iterations,
        tolerance: settings.solver_tolerance,
    };
    let mut speeds = solved.solution.b.clone();
    let mut ramped: Option<Ramped> = None;
    for _ in 0..settings.jerk_ramp_rounds {
        let rounded = ramp::rounded_peaks(
            spline,
            &solved.grid,
            &solved.solution.b,
            &speeds,
            &kept,
            RAMP_SHARE,
        );
        let rows = capped_rows(&solved.rows, &rounded);
        let solution = topp::solve_profile(&solved.grid, &rows, &program_settings);
        if !usable(&solution) {
            break;
        }
        let candidate = Solved {
            grid: solved.grid.clone(),
            rows,
            solution,
            tool: solved.tool.clone(),
        };
        let ramp_s = candidate.duration() - optimal;
        speeds.clone_from(&candidate.solution.b);
        let so_far = ramped.as_ref().map_or(plain, |r| r.ramp_s + r.narrow);
        // Only a width that makes the candidate end sooner is searched for.
        let narrower = jerk::filter_width_below(
            spline,
            &profile(&candidate),
            &program.acc,
            &kept,
            so_far - ramp_s,
        );
        if let Some(narrow) = narrower {
            ramped = Some(Ramped {
                solved: candidate,
                rounds,
                narrow,
                ramp_s,
            });
        }
    }
    ramped.unwrap_or(Ramped {
        solved,
        rounds,
        narrow: plain,
        ramp_s: 0.0,
    })
}

/// The share of each joint's jerk limit the path acceleration's fall may
/// use at a rounded peak: the rest is for the grid's steps (the fall is a
/// staircase of one step a segment), taken up by the filter.
const RAMP_SHARE: f64 = 0.75;

/// `rows` with `b_i ≤ cap_i` added at every inner grid point `i`.
fn capped_rows(rows: &SegmentRows, cap: &[f64]) -> SegmentRows {
    let n = rows.offsets.len() - 1;
    let mut capped = SegmentRows {
        offsets: Vec::with_capacity(n + 1),
        rows: Vec::with_capacity(rows.rows.len() + n),
    };
    capped.offsets.push(0);
    for (i, (range, most)) in rows.offsets.windows(2).zip(cap).enumerate() {
        capped
            .rows
            .extend_from_slice(&rows.rows[range[0]..range[1]]);
        if i > 0 {
            capped.rows.push((1.0 / most, 0.0));
        }
        capped.offsets.push(capped.rows.len());
    }
    capped
}

fn validate_input(
    waypoints: &[Vec<f64>],
    limits: &JointLimits,
    proximity: Option<&Proximity>,
) -> Result<(), TimingError> {
    let joints = limits.velocity.len();
    if waypoints.is_empty() {
        return Err(TimingError::NoWaypoints);
    }
    if joints == 0 {
        return Err(TimingError::SizeMismatch {
            what: "velocity limits",
            len: 0,
            expected: waypoints[0].len().max(1),
        });
    }
    for (what, len) in [
        ("acceleration limits", limits.acceleration.len()),
        ("lower position limits", limits.lower.len()),
        ("upper position limits", limits.upper.len()),
    ] {
        if len != joints {
            return Err(TimingError::SizeMismatch {
                what,
                len,
                expected: joints,
            });
        }
    }
    for (joint, (&lower, &upper)) in limits.lower.iter().zip(&limits.upper).enumerate() {
        if !(lower <= upper && lower < f64::INFINITY && upper > f64::NEG_INFINITY) {
            return Err(TimingError::BadPositionLimits {
                joint,
                lower,
                upper,
            });
        }
    }
    if !limits.jerk.is_empty() && limits.jerk.len() != joints {
        return Err(TimingError::SizeMismatch {
            what: "jerk limits",
            len: limits.jerk.len(),
            expected: joints,
        });
    }
    for (what, values) in [
        ("velocity", &limits.velocity),
        ("acceleration", &limits.acceleration),
        ("jerk", &limits.jerk),
    ] {
        for (joint, &value) in values.iter().enumerate() {
            if !(value.is_finite() && value > 0.0) {
                return Err(TimingError::BadLimit { what, joint, value });
            }
        }
    }
    for (index, w) in waypoints.iter().enumerate() {
        if w.len() != joints {
            return Err(TimingError::WaypointLength {
                index,
                len: w.len(),
                expected: joints,
            });
        }
        if !w.iter().all(|x| x.is_finite()) {
            return Err(TimingError::NonFinite {
                what: "waypoints",
                index,
            });
        }
        let outside = (0..joints).find(|&j| !(limits.lower[j]..=limits.upper[j]).contains(&w[j]));
        if let Some(joint) = outside {
            return Err(TimingError::WaypointOutsideLimits {
                index,
                joint,
                value: w[joint],
                lower: limits.lower[joint],
                upper: limits.upper[joint],
            });
        }
    }
    if let Some(p) = proximity {
        p.rule.validate()?;
        if p.tool_positions.len() != waypoints.len() {
            return Err(TimingError::SizeMismatch {
                what: "tool positions",
                len: p.tool_positions.len(),
                expected: waypoints.len(),
            });
        }
        for (index, t) in p.tool_positions.iter().enumerate() {
            if !t.iter().all(|x| x.is_finite()) {
                return Err(TimingError::NonFinite {
                    what: "tool_positions",
                    index,
                });
            }
        }
        for (index, h) in p.hands.iter().enumerate() {
            if !(h.centre.iter().all(|x| x.is_finite()) && h.radius.is_finite() && h.radius >= 0.0)
            {
                return Err(TimingError::NonFinite {
                    what: "hands",
                    index,
                });
            }
        }
    }
    Ok(())
}

/// The cap of every segment of `grid` (m/s), lowered as `shape` says, and
/// the summary. A segment's distance is the smaller end-point distance less
/// half its chord (a lower bound along a straight chord).
fn tool_caps(
    proximity: &Proximity,
    tool: &PiecewiseCubic,
    grid: &PathGrid,
    shape: &CapShape,
) -> Result<ToolCaps, TimingError> {
    let rule = &proximity.rule;
    let (mut x, mut dx, mut ddx) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    let positions: Vec<[f64; 3]> = grid
        .s
        .iter()
        .map(|&s| {
            tool.eval(s, &mut x, &mut dx, &mut ddx);
            x
        })
        .collect();
    let distance: Vec<f64> = positions
        .iter()
        .map(|&p| nearest_hand_distance(&proximity.hands, p))
        .collect();
    let mut summary = SeparationSummary {
        min_distance_m: distance.iter().copied().fold(f64::INFINITY, f64::min),
        min_cap_m_s: f64::INFINITY,
        reduced_segments: 0,
        crawl_segments: 0,
    };
    let mut caps = Vec::with_capacity(grid.segments());
    let mut rises = Vec::with_capacity(grid.segments());
    for i in 0..grid.segments() {
        let chord: f64 = (0..3)
            .map(|k| (positions[i + 1][k] - positions[i][k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let d = (distance[i].min(distance[i + 1]) - 0.5 * chord).max(0.0);
        let cap = rule.tool_speed_cap(d);
        if cap <= 0.0 {
            return Err(TimingError::InsideProtectiveDistance {
                s: grid.s[i],
                distance_m: d,
                required_m: rule.stop_distance(d),
            });
        }
        if cap <= rule.reduced_speed_m_s {
            summary.reduced_segments += 1;
        }
        if rule.formula_speed(d) <= rule.min_tool_speed_m_s {
            summary.crawl_segments += 1;
        }
        summary.min_cap_m_s = summary.min_cap_m_s.min(cap);
        caps.push(cap);
        // The distance anywhere on the segment is at most the farther end's
        // plus half the chord: a finer grid may raise the cap only below that.
        let farthest = distance[i].max(distance[i + 1]) + 0.5 * chord;
        rises.push(rule.tool_speed_cap(farthest) > cap);
    }
    let limits = caps.clone();
    if let Some(window) = &shape.window {
        for (i, cap) in caps.iter_mut().enumerate() {
            let mixed = touched(grid, window.stretch(grid.s[i], grid.s[i + 1]));
            *cap = limits[mixed].iter().copied().fold(*cap, f64::min);
        }
    }
    shape.cut(grid, &mut caps);
    Ok(ToolCaps {
        caps,
        limits,
        rises,
        summary,
    })
}

/// Segments an active segment is cut into at each refinement round
/// without a looseness (the reference's refinement).
const REFINE_PARTS: usize = 4;

/// Most segments a loose segment is cut into at one refinement round.
const MOST_PARTS: usize = 8;

/// Relative slack below which a row counts as active (binding).
const ACTIVE_SLACK: f64 = 1e-4;

/// Refinement stops once the grid has this many times the segments it
/// started with (bounds the work).
const MAX_REFINED_GROWTH: usize = 8;

/// The limits as the program uses them (scaled, margined).
struct ProgramLimits {
    /// `v_j²`, (rad/s)².
    vel_sq: Vec<f64>,
    /// `A_j`, rad/s².
    acc: Vec<f64>,
    /// Factor on every tool-speed cap.
    tool_shrink: f64,
}

/// One solve of the program on one grid.
struct Solved {
    grid: PathGrid,
    rows: SegmentRows,
    solution: ProfileSolution,
    /// Tool-speed caps near hands.
    tool: Option<ToolCaps>,
}

/// The tool-speed cap of every segment near hands.
#[derive(Clone)]
struct ToolCaps {
    /// Cap the program keeps, m/s.
    caps: Vec<f64>,
    /// The separation rule's cap of each segment, m/s (`caps` may be lower,
    /// see [`solve_refined`]).
    limits: Vec<f64>,
    /// A finer grid may raise the cap: the cap at the segment's largest
    /// possible hand distance is higher (the formula's graded part, or a
    /// clamped cap that the half-chord penalty moved off its plateau).
    rises: Vec<bool>,
    summary: SeparationSummary,
}

impl Solved {
    fn usable(&self) -> bool {
        usable(&self.solution)
    }

    /// The exact discretised time `Σ 2Δs_i/(√b_i + √b_{i+1})`, seconds.
    fn duration(&self) -> f64 {
        let b = &self.solution.b;
        (0..self.grid.segments())
            .map(|i| 2.0 * self.grid.step(i) / (b[i].max(0.0).sqrt() + b[i + 1].max(0.0).sqrt()))
            .sum()
    }

    /// Segments where a finer grid gains time: a row within
    /// [`ACTIVE_SLACK`] of its bound, and with `settings.refine_looseness > 0`
    /// some point of the segment where the profile uses less than
    /// `1 − refine_looseness` of every limit ([`Self::utilisation`]); with 0,
    /// every such segment whose binding rows may be conservative to first
    /// order in `Δs` — an acceleration row, a speed row of a joint turning
    /// round or of the tool ([`grid::speed_rows_loose`],
    /// [`grid::tool_speed_rows_loose`]), or a tool-speed cap a finer grid may
    /// raise ([`ToolCaps::rises`]).
    fn refinable(&self, inputs: &Inputs) -> Vec<usize> {
        let (spline, program) = (inputs.spline, inputs.program);
        let looseness = inputs.settings.refine_looseness;
        let b = &self.solution.b;
        (0..self.grid.segments())
            .map(|i| {
                let rows = &self.rows.rows[self.rows.offsets[i]..self.rows.offsets[i + 1]];
                let ends = (b[i], b[i + 1]);
                let active = rows
                    .iter()
                    .any(|(alpha, beta)| alpha * ends.0 + beta * ends.1 >= 1.0 - ACTIVE_SLACK);
                if !active {
                    return 1;
                }
                if looseness > 0.0 {
                    // The gap is first order in Δs: cut into enough parts
                    // to bring it to about the looseness.
                    let gap = 1.0 - self.utilisation(inputs, i);
                    return if gap > looseness {
                        ((gap / looseness).ceil() as usize).clamp(2, MOST_PARTS)
                    } else {
                        1
                    };
                }
                let loose = grid::acceleration_bound(
                    spline,
                    &self.grid,
                    i,
                    &program.acc,
                    ends,
                    ACTIVE_SLACK,
                ) || grid::speed_rows_loose(spline, &self.grid, i)
                    || self.tool.as_ref().is_some_and(|t| t.rises[i])
                    || inputs
                        .tool_spline
                        .is_some_and(|tool| grid::tool_speed_rows_loose(tool, &self.grid, i));
                if loose { REFINE_PARTS } else { 1 }
            })
            .collect()
    }

    /// The least share of the limits the profile uses at any point of
    /// segment `i` (at each point the largest share of any limit): the
    /// joints' ([`grid::joint_utilisation`]) and the tool's speed near hands
    /// against the separation rule's cap at that point (the program's cap
    /// where the jerk filter lowered it), as the program margins them.
    fn utilisation(&self, inputs: &Inputs, i: usize) -> f64 {
        let ends = (self.solution.b[i], self.solution.b[i + 1]);
        let program = inputs.program;
        let mut used = grid::joint_utilisation(
            inputs.spline,
            &self.grid,
            i,
            &program.vel_sq,
            &program.acc,
            ends,
        );
        if let (Some((tool, proximity)), Some(caps)) = (inputs.tool, self.tool.as_ref()) {
            let (mut x, mut dx, mut ddx) = ([0.0; 3], [0.0; 3], [0.0; 3]);
            let last = (used.len() - 1) as f64;
            for (k, used) in used.iter_mut().enumerate() {
                let t = k as f64 / last;
                tool.eval(
                    self.grid.s[i] + t * self.grid.step(i),
                    &mut x,
                    &mut dx,
                    &mut ddx,
                );
                let distance = nearest_hand_distance(&proximity.hands, x);
                let cap =
                    proximity.rule.tool_speed_cap(distance).min(caps.caps[i]) * program.tool_shrink;
                let b = ends.0 + t * (ends.1 - ends.0);
                *used = used.max(dx.iter().map(|v| v * v).sum::<f64>() * b / (cap * cap));
            }
        }
        used.into_iter().fold(f64::INFINITY, f64::min)
    }
}

fn usable(solution: &ProfileSolution) -> bool {
    let n = solution.b.len() - 1;
    matches!(
        solution.outcome,
        SolverOutcome::Solved | SolverOutcome::AlmostSolved
    ) && solution.b[1..n].iter().all(|b| b.is_finite() && *b > 0.0)
}

/// Rows of every segment of `grid` (with the tool-speed caps near hands),
/// then the program.
fn solve_on_grid(
    spline: &PiecewiseCubic,
    grid: PathGrid,
    limits: &ProgramLimits,
    tool: Option<(&PiecewiseCubic, &Proximity)>,
    settings: &TimingSettings,
    shape: &CapShape,
) -> Result<Solved, TimingError> {
    let caps = tool
        .map(|(tool, proximity)| tool_caps(proximity, tool, &grid, shape))
        .transpose()?;
    let caps_sq: Option<Vec<f64>> = caps.as_ref().map(|t| {
        t.caps
            .iter()
            .map(|c| (c * limits.tool_shrink).powi(2))
            .collect()
    });
    let rows = grid::program_rows(
        spline,
        &grid,
        &limits.vel_sq,
        &limits.acc,
        tool.zip(caps_sq.as_deref())
            .map(|((spline, _), caps_sq)| (spline, caps_sq)),
    );
    let solution = topp::solve_profile(
        &grid,
        &rows,
        &ProgramSettings {
            program: settings.program,
            smoothing_weight: settings.smoothing_weight,
            max_iterations: settings.max_iterations,
            tolerance: settings.solver_tolerance,
        },
    );
    Ok(Solved {
        grid,
        rows,
        solution,
        tool: caps,
    })
}

fn at_rest(q: &[f64], started: Instant) -> Timing {
    let dim = q.len();
    Timing {
        status: TimingStatus::Solved,
        trajectory: Some(JointTrajectory {
            points: vec![sample::TrajectoryPoint {
                positions: q.to_vec(),
                velocities: vec![0.0; dim],
                accelerations: vec![0.0; dim],
                time_from_start: 0.0,
            }],
        }),
        profile: None,
        stats: SolveStats {
            outcome: SolverOutcome::Solved,
            iterations: 0,
            segments: 0,
            linear_rows: 0,
            solve_time_s: 0.0,
            refinements: 0,
            jerk_filter_s: 0.0,
            jerk_ramp_s: 0.0,
            tool_speed_rounds: 0,
            total_time_s: started.elapsed().as_secs_f64(),
        },
        separation: None,
    }
}
