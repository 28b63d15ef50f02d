//! # afford-check
//!
//! An independent gate for afford plans: reads a plan file (bounded, JSON or
//! YAML) and re-checks everything a robot would execute against the
//! scenario, sharing no code path with the planner's own checks. It uses
//! afford-planner only for data types and scenario loading and
//! afford-kinematics only for the robot description; forward kinematics is
//! k's (from the URDF via urdf-rs 0.9), collisions are parry3d's on a scene
//! rebuilt here from the scenario's pixel boxes. The physical replay
//! ([`physics`], `--physics`) is a different test, not a second opinion on
//! the planner's geometry: it runs afford-collision's rapier3d replay on
//! this crate's reading of the scene.
//!
//! | what | module | class |
//! |---|---|---|
//! | reading the file, its bounds | [`file`](read_plan) | — |
//! | names, sizes, values, times, gripper events | `format` | `format`, `gripper_events` |
//! | the start state by the scenario's rule | `start` | `start`, `continuity` |
//! | positions, velocities, accelerations, rest | `rates` | `position`, `velocity`, `acceleration`, `rest` |
//! | tool speed near hands (ISO/TS 15066) | `tool_speed` | `tool_speed` |
//! | dense collision check (1 mm steps) | `dense`, `bodies`, `scene`, `chain` | `penetration`, `margin`, `self_collision`, `target_touched` |
//! | grasp width, release | `placement` | `gripper_opening`, `placement` |
//! | physical replay (rapier3d, `--physics`) | [`physics`] | `physics` |
//! | an executed run's seen hands: contacts, perimeter entries | [`check_hands`], [`presence`] | — |
//! | an executed run's stops against the stopping term | [`stops`] | — |
//! | whether a refused sub-goal has free poses (IK and collisions of its own) | [`probe`] | — |
//!
//! ```
//! let scenario = afford_planner::scenario::default_scenario().unwrap();
//! let robot = afford_kinematics::RobotModel::builtin("kuka_iiwa14").unwrap();
//! let plan = afford_check::read_plan(r#"{"subgoals": []}"#).unwrap();
//! let report = afford_check::check_plan(&scenario, &robot, &plan);
//! assert_eq!(report.violations[0].class, afford_check::ViolationClass::Format);
//! ```
//!
//! A plan straight from the planner, in memory:
//!
//! ```
//! let scenario = afford_planner::scenario::default_scenario().unwrap();
//! let options = afford_planner::PlanOptions::default();
//! let plan = afford_planner::plan(&scenario, &options).unwrap();
//! let report = afford_check::check(&scenario, &plan, &options.base_dir).unwrap();
//! assert!(report.passed(), "{:?}", report.violations);
//! ```

mod bodies;
mod chain;
mod check;
mod dense;
mod file;
mod format;
mod hands;
mod jerk;
pub mod physics;
mod placement;
pub mod probe;
mod rates;
mod report;
mod scene;
mod start;
mod stops;
mod tool_speed;

pub use check::{check, check_plan};
pub use dense::{CONTACT_TOLERANCE, MAX_CONFIGURATIONS, STEP};
pub use file::{
    MAX_GRIPPER_EVENTS, MAX_JOINTS, MAX_PLAN_BYTES, MAX_SAMPLES, MAX_SUBGOALS, PlanFile,
    PlanFileError, Sample, StartState, SubgoalFile, TrajectoryFile, read_plan,
};
pub use format::{EVENT_TIME_TOLERANCE, MAX_ABS_POSITION, MAX_ABS_RATE, MAX_TIME};
pub use hands::{HandReport, Presence, check_hands, presence};
pub use placement::PLACEMENT_TOLERANCE;
pub use probe::{FreePoses, Probe, ProbeError, ProbeSettings};
pub use rates::{POSITION_TOLERANCE, RATE_TOLERANCE, REST_TOLERANCE};
pub use report::{Report, Violation, ViolationClass, ViolationData};
pub use scene::{GOAL_WALL, TABLE_THICKNESS};
pub use start::{START_TILT, START_TOLERANCE, scenario_joint_issues};
pub use stops::{Stop, stops};
pub use tool_speed::TOOL_SPEED_TOLERANCE;
