//! # afford-planner
//!
//! From a scenario (what the overhead camera and the microphone deliver) to a
//! discrete, verified grid plan, after Munguia-Galeano et al., "Affordance-Based
//! Human–Robot Interaction With Reinforcement Learning" (IEEE Access 2023):
//!
//! | stage | folder | module | paper |
//! |---|---|---|---|
//! | scenario file | | [`scenario`] | semantic set O, eq. (4) |
//! | sub-goals | | [`instruction`] | Algorithm 1 |
//! | state grid | [`discrete`] | [`grid`] | Algorithm 2 |
//! | task (MDP) | [`discrete`] | [`task`] | actions, eq. (5) |
//! | affordances, initial Q | [`discrete`] | [`affordance`] | eq. (7)–(9) |
//! | learning | [`discrete`] | [`cql`] | eq. (10)–(11), Algorithm 3 |
//! | oracle | [`discrete`] | [`oracle`] | — (BFS, for measurement) |
//! | MDP export | [`discrete`] | [`export`] | — (for the deep-RL baselines) |
//! | the robot's state at t = 0 | [`motion`] | [`start`] | — |
//! | lifting to 3-D, placement | [`motion`] | [`lift`], [`smooth`], [`place`] | spline interpolation, Alg. 3 |
//! | arm choice, IK | [`motion`] | [`motion`] (over `afford-kinematics`) | — |
//! | collision check, replanning | [`motion`] | [`geometry`], [`clearance`] (over `afford-collision`) | safety perimeters |
//! | time-parameterisation | [`timing`] | [`timing`], [`trajectory`] (Clarabel) | — |
//! | pipeline | | [`plan`] | Fig. 2 |
//!
//! ```
//! let scenario = afford_planner::scenario::default_scenario().unwrap();
//! let options = afford_planner::PlanOptions::default();
//! let plan = afford_planner::plan(&scenario, &options).unwrap();
//! assert!(plan.unsolved.is_empty());
//! assert_eq!(plan.subgoals[0].actions.last().unwrap().name(), "DROP");
//! ```

pub mod discrete;
pub mod error;
pub mod instruction;
pub mod monitor;
pub mod motion;
pub mod plan;
pub mod scenario;
pub mod timing;

// The stages keep their short paths (`afford_planner::grid`, …): the folders
// group them by pipeline stage, the names stay what users already import.
pub use discrete::{affordance, cql, export, grid, oracle, route_grid, task};
pub use motion::{clearance, geometry, lift, place, smooth, start, transit};
pub use timing::trajectory;

pub use cql::{ContextualQLearner, LearnedPlan, LearnerSettings, QLearner};
pub use error::{FieldIssue, InstructionError, PlanError, ScenarioError};
pub use grid::{CellCode, StateGrid};
pub use plan::{HeldObject, JointState, MidExecution, Plan, PlanOptions, Planner, Stage, plan};
pub use scenario::Scenario;
pub use task::{Action, GridTask};
