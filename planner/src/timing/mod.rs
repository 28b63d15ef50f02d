//! # Time-parameterisation: a joint path in, a time-optimal trajectory out
//!
//! One arm's joint path from IK (waypoints `q_0 … q_{W−1}`, rad) becomes a
//! C1 path `q(s)` with chord-length knots: the joint polyline with each
//! corner rounded by a quadratic Bézier blend ([`spline`]), which never
//! leaves the range of its waypoints (so never a position limit they
//! respect) and stays within [`TimingSettings::max_tool_deviation_m`] of
//! the planned tool path ([`deviation`]). It is cut into `N` segments
//! ([`grid`]), timed by one convex program ([`topp`]: an LP solved exactly
//! in two passes over the segments, or an SOCP solved with Clarabel)
//! and sampled at the controller rate ([`sample`]). Stages, in
//! [`time_parameterize_tool`]: blended path → grid → separation caps → rows
//! → LP/SOCP → sampling → check of every sample.
//!
//! ## The convex program
//!
//! With `b(s) = ṡ²` (1/s²) and `a(s) = s̈` (1/s²), `s` in rad of joint-space
//! chord length, joint velocity and acceleration are `q̇ = q'(s)√b` and
//! `q̈ = q''(s) b + q'(s) a`. The time-optimal problem over a fixed path
//! (Bobrow 1985; Verscheure et al., IEEE TAC 2009; Lipp & Boyd 2014) is
//!
//! ```text
//! minimise    T = ∫₀ᴸ ds / √b(s)
//! subject to  q'_j(s)² b(s) ≤ v_j²                        (velocity, rad/s)
//!             |q''_j(s) b(s) + q'_j(s) a(s)| ≤ A_j         (acceleration, rad/s²)
//!             ‖p'(s)‖² b(s) ≤ v_tool(s)²                    (tool speed near hands, m/s)
//!             b'(s) = 2 a(s),  b(0) = b(L) = 0             (start and end at rest)
//! ```
//!
//! Discretised with `a` constant per segment (`b_{i+1} = b_i + 2a_iΔs_i`) the
//! time is exactly `Σ 2Δs_i/(√b_i + √b_{i+1})` and the program becomes the
//! SOCP
//!
//! ```text
//! minimise    Σ_i 2Δs_i d_i
//! subject to  α_r b_i + β_r b_{i+1} ≤ 1     (pruned Bernstein rows, see grid)
//!             c_i² ≤ b_i                     ‖(2c_i, b_i − 1)‖₂ ≤ b_i + 1
//!             d_i (c_i + c_{i+1}) ≥ 1        ‖(2, d_i − c_i − c_{i+1})‖₂ ≤ d_i + c_i + c_{i+1}
//! ```
//!
//! with `b_0 = b_N = c_0 = c_N = 0`: `3N − 2` variables, `2N − 1` cones of
//! dimension 3, a few linear rows per segment. The rows bound each
//! constraint's **Bernstein coefficients** on each segment, which bounds the
//! constraint on the whole segment, not just at grid points; that, and a
//! relative margin of [`TimingSettings::limit_margin`] on every limit, is why
//! every sample at any rate is within the limits. Each sample is still
//! checked ([`sample::verify`]: positions, velocities, accelerations, the
//! tool's distance from the planned tool path; [`tool_speed`]: near hands
//! the tool's speed, of the interpolant and of the real tool by forward
//! kinematics, the caps lowered and the path timed again where it is over)
//! and a violation is a status, never a trajectory.
//!
//! Speed scale `k ∈ (0, 1]` multiplies velocity limits by `k` and
//! acceleration limits by `k²`: the result is the time-optimal trajectory
//! slowed uniformly by `1/k`. A jerk bound is not convex in `(a, b)`; the
//! optional [`TimingSettings::smoothing_weight`] `w` adds `w Σ (a_{i+1} − a_i)²`
//! (s⁻⁴ · w in seconds) to the time instead.
//!
//! ## Near people
//!
//! With tool positions per waypoint (robot base frame, m) and hands, the tool
//! speed is capped on each segment by the speed-and-separation rule of
//! [`separation`] (ISO/TS 15066, ISO 13855, ISO 10218-1; defaults in
//! [`SeparationSettings`]). The tool path `p(s)` is the same blended
//! construction on the tool positions, with the joint path's knots and radii.
//!
//! ```
//! use afford_planner::timing::{JointLimits, TimingSettings, time_parameterize};
//! let path = vec![vec![0.0, 0.0], vec![0.5, -0.2], vec![1.0, 0.3]];
//! let limits = JointLimits {
//!     lower: vec![-3.0, -3.0],
//!     upper: vec![3.0, 3.0],
//!     velocity: vec![1.0, 1.0],
//!     acceleration: vec![5.0, 5.0],
//!     jerk: vec![250.0, 250.0],
//! };
//! let timing = time_parameterize(&path, &limits, None, &TimingSettings::default()).unwrap();
//! let trajectory = timing.trajectory.expect("solved");
//! assert!(trajectory.points.last().unwrap().velocities.iter().all(|v| v.abs() < 1e-9));
//! ```

pub mod deviation;
pub mod grid;
pub mod jerk;
pub mod jerk_floor;
pub mod profile;
pub mod ramp;
pub mod sample;
pub mod separation;
pub mod spline;
pub mod taut;
pub mod tool_speed;
pub mod topp;
pub mod trajectory;

mod finish;
mod outcome;
mod refine;
mod run;
mod settings;

pub use deviation::ToolFk;
pub use outcome::{MAX_SAMPLES, SeparationSummary, SolveStats, Timing, TimingError, TimingStatus};
pub use run::{time_parameterize, time_parameterize_tool};
pub use sample::{JointTrajectory, LimitKind, LimitViolation, SpeedProfile, TrajectoryPoint};
pub use separation::{Hand, SeparationSettings};
pub use settings::{JointLimits, Proximity, TimingSettings};
pub use topp::{Program, SolverOutcome};
