//! # afford-planner
//!
//! From a scenario (what the overhead camera and the microphone deliver) to a
//! discrete, verified grid plan, after Munguia-Galeano et al., "Affordance-Based
//! Human–Robot Interaction With Reinforcement Learning" (IEEE Access 2023):
//!
//! | stage | module | paper |
//! |---|---|---|
//! | scenario file | [`scenario`] | semantic set O, eq. (4) |
//! | sub-goals | [`instruction`] | Algorithm 1 |
//! | state grid | [`grid`] | Algorithm 2 |
//! | task (MDP) | [`task`] | actions, eq. (5) |
//! | affordances, initial Q | [`affordance`] | eq. (7)–(9) |
//! | learning | [`cql`] | eq. (10)–(11), Algorithm 3 |
//! | oracle | [`oracle`] | — (BFS, for measurement) |
//! | the robot's state at t = 0 | [`start`] | — |
//! | lifting to 3-D, placement | [`lift`], [`smooth`], [`place`] | spline interpolation, Alg. 3 |
//! | arm choice, IK | [`motion`] (over `afford-kinematics`) | — |
//! | collision check, replanning | [`geometry`], [`clearance`] (over `afford-collision`) | safety perimeters |
//! | time-parameterisation | [`timing`], [`trajectory`] (Clarabel) | — |
//! | pipeline | [`plan`] | Fig. 2 |
//!
//! ```
//! let scenario = afford_planner::scenario::default_scenario().unwrap();
//! let options = afford_planner::PlanOptions::default();
//! let plan = afford_planner::plan(&scenario, &options).unwrap();
//! assert!(plan.unsolved.is_empty());
//! assert_eq!(plan.subgoals[0].actions.last().unwrap().name(), "DROP");
//! ```

pub mod affordance;
pub mod bench;
pub mod clearance;
pub mod cql;
pub mod error;
pub mod geometry;
pub mod grid;
pub mod instruction;
pub mod lift;
pub mod motion;
pub mod oracle;
pub mod place;
pub mod plan;
pub mod scenario;
pub mod smooth;
pub mod start;
pub mod task;
pub mod timing;
pub mod trajectory;

pub use cql::{ContextualQLearner, LearnedPlan, LearnerSettings, QLearner};
pub use error::{FieldIssue, InstructionError, PlanError, ScenarioError};
pub use grid::{CellCode, StateGrid};
pub use plan::{JointState, Plan, PlanOptions, Planner, Stage, plan};
pub use scenario::Scenario;
pub use task::{Action, GridTask};
