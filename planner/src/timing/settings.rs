//! What the timing stage is given besides the path: each joint's limits
//! ([`JointLimits`]), where the tool and the hands are ([`Proximity`]) and
//! the stage's settings ([`TimingSettings`]), every default written once.

use serde::{Deserialize, Serialize};

use super::outcome::TimingError;
use super::separation::{Hand, SeparationSettings};
use super::topp::Program;

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
