//! The grid MDP of one sub-goal as data (`afford export-mdp`), for learners
//! outside afford (the stable-baselines comparison in `bench/rl-baselines/`).
//!
//! Everything is produced by the code the learners use: the transition
//! table by [`GridTask::step`], the rewards by [`LearnerSettings::reward`],
//! the episode length by [`LearnerSettings::episode_length`], the optimum by
//! the BFS oracle and the plan by [`ContextualQLearner`]. Nothing here
//! re-states a rule. The format is documented in `docs/mdp-export.md`.
//!
//! States are indexed `(row · cols + col) · 2 + holding`; actions in the
//! order of [`Action::ALL`]. `next[s][a]` is the next state, [`REFUSED`]
//! when the scene does not afford `a` in `s` (the agent stays, reward
//! `reward_refused`: plain QL's rule) or [`DONE`] for the terminal DROP.
//! The affordance mask ζ(s, a) is `next[s][a] != REFUSED`.

use serde::{Deserialize, Serialize};

use crate::cql::{ContextualQLearner, LearnedPlan, LearnerSettings};
use crate::error::InstructionError;
use crate::grid::{GridRequest, StateGrid};
use crate::instruction::subgoals;
use crate::oracle;
use crate::scenario::Scenario;
use crate::scenario::bounds::MAX_GRID_CELLS;
use crate::task::{Action, GridTask, Outcome};

/// Version of the export format; bumped on any change a reader must know.
pub const FORMAT_VERSION: u32 = 1;
/// `next` entry of an action the scene does not afford: the agent stays.
pub const REFUSED: i64 = -1;
/// `next` entry of the terminal DROP over the drop cell.
pub const DONE: i64 = -2;
/// Most states an export holds: two per cell of the largest grid a
/// scenario may ask for ([`MAX_GRID_CELLS`]).
pub const MAX_STATES: usize = 2 * MAX_GRID_CELLS;

/// One sub-goal's grid MDP as afford's learner sees it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MdpExport {
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// Scene name (`bench-SEED-INDEX` for generated scenes).
    pub name: String,
    /// The object moved and the goal it goes to.
    pub object: String,
    pub goal: String,
    /// Seed of afford's learner for `cql_plan` (and `learners`).
    pub seed: u64,
    /// n rows (along v) and m columns (along u).
    pub rows: usize,
    pub cols: usize,
    /// The state matrix, row by row, in the paper's codes: 0 empty,
    /// 0.1 target, 0.2 obstacle, 0.3 goal, 0.4 hand.
    pub grid: Vec<Vec<f64>>,
    /// Cells `[row, col]`: the gripper's start, the target, and the drop
    /// cell the GOAL macro carries to (`null` when the goal is full).
    pub start: [usize; 2],
    pub target: [usize; 2],
    pub drop: Option<[usize; 2]>,
    /// Action names in index order: UP, DOWN, LEFT, RIGHT, GRASP, DROP, GOAL.
    pub actions: Vec<Action>,
    /// Index of the start state (`holding` false).
    pub start_state: usize,
    /// `next[s][a]`: next state index, [`REFUSED`] or [`DONE`].
    pub next: Vec<[i64; Action::COUNT]>,
    /// `reward[s][a]`: the reward of taking `a` in `s`.
    pub reward: Vec<[f64; Action::COUNT]>,
    /// γ of afford's learner.
    pub discount: f64,
    /// Steps after which afford's learner restarts an episode.
    pub episode_steps: usize,
    /// Length of the shortest plan (actions, DROP included); `null` when
    /// the task cannot be solved.
    pub optimal_length: Option<usize>,
    /// afford's CQL plan for this MDP (settings of the scene, `seed`).
    pub cql_plan: ExportedPlan,
    /// Training statistics of afford's learners, when asked for
    /// (`--learner-stats`); times vary run to run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub learners: Option<LearnerStats>,
}

/// A learner's greedy plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExportedPlan {
    pub actions: Vec<Action>,
    /// The plan ends with DROP over the drop cell, afforded actions only.
    pub solved: bool,
    /// Environment steps spent training.
    pub training_steps: usize,
    /// Training stopped on a stable greedy plan, not on the step budget.
    pub converged: bool,
}

impl From<&LearnedPlan> for ExportedPlan {
    fn from(plan: &LearnedPlan) -> Self {
        Self {
            actions: plan.actions.clone(),
            solved: plan.solved,
            training_steps: plan.training_steps,
            converged: plan.converged,
        }
    }
}

/// One training run of an afford learner with its cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnerRun {
    pub plan: ExportedPlan,
    /// Wall time, milliseconds (building the task's tables included).
    pub wall_ms: f64,
    /// CPU time of the training thread, milliseconds; `null` where the
    /// system does not tell (measured on Linux only).
    pub cpu_ms: Option<f64>,
}

/// afford's two learners on the same MDP, with the scene's settings and
/// with the authors' literal schedule ([`LearnerSettings::paper`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnerStats {
    pub cql: LearnerRun,
    pub ql: LearnerRun,
    pub cql_paper: LearnerRun,
    pub ql_paper: LearnerRun,
}

/// Who the MDP is for: scene name, object, goal and learner seed.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportMeta {
    pub name: String,
    pub object: String,
    pub goal: String,
    pub seed: u64,
}

impl MdpExport {
    /// The export of `task` with afford's CQL plan `plan` (learned with
    /// `settings` and `meta.seed`).
    pub fn of(
        meta: ExportMeta,
        task: &GridTask,
        settings: &LearnerSettings,
        plan: &LearnedPlan,
    ) -> Self {
        let grid = &task.grid;
        let cell = |(r, c): (usize, usize)| [r, c];
        let encode = |outcome| match outcome {
            Outcome::Moved(n) => task.state_index(n) as i64,
            Outcome::Refused => REFUSED,
            Outcome::Done => DONE,
        };
        let (mut next, mut reward) = (Vec::new(), Vec::new());
        for i in 0..task.state_count() {
            let outcomes = Action::ALL.map(|a| (a, task.step(task.state(i), a)));
            next.push(outcomes.map(|(_, o)| encode(o)));
            reward.push(outcomes.map(|(a, o)| settings.reward(a, o)));
        }
        Self {
            format_version: FORMAT_VERSION,
            name: meta.name,
            object: meta.object,
            goal: meta.goal,
            seed: meta.seed,
            rows: grid.rows,
            cols: grid.cols,
            grid: grid.matrix(),
            start: cell(grid.start),
            target: cell(grid.target),
            drop: grid.drop.map(cell),
            actions: Action::ALL.to_vec(),
            start_state: task.state_index(task.start()),
            next,
            reward,
            discount: settings.discount,
            episode_steps: settings.episode_length(task),
            optimal_length: oracle::optimal_length(task),
            cql_plan: plan.into(),
            learners: None,
        }
    }

    /// Follows `actions` from the start state through the exported table:
    /// `Some(steps)` when it ends with the terminal DROP, using afforded
    /// actions only, `None` otherwise. How a reader checks an export.
    pub fn replay(&self, actions: &[Action]) -> Option<usize> {
        let mut state = self.start_state;
        for (k, a) in actions.iter().enumerate() {
            match self.next.get(state)?[a.index()] {
                DONE => return (k + 1 == actions.len()).then_some(k + 1),
                REFUSED => return None,
                next => state = usize::try_from(next).ok()?,
            }
        }
        None
    }
}

/// One export per sub-goal of a scenario's instruction, each grid built on
/// the scene as it is now (as `afford validate` draws them) with the
/// gripper at pixel `gripper`; learner seed of sub-goal k as in
/// `afford plan` ([`crate::plan::subgoal_seed`]).
///
/// # Errors
/// The instruction cannot be executed (the message `afford plan` gives).
pub fn scenario_exports(
    scenario: &Scenario,
    gripper: [f64; 2],
    seed: u64,
    name: &str,
) -> Result<Vec<MdpExport>, InstructionError> {
    let goals = subgoals(scenario, seed)?;
    let learner = ContextualQLearner::new(scenario.learner.clone());
    Ok(goals
        .iter()
        .enumerate()
        .filter_map(|(k, g)| {
            let request = GridRequest {
                object: scenario.object_index(&g.object)?,
                goal: scenario.goal_index(&g.goal)?,
                gripper,
            };
            let task = GridTask::new(StateGrid::build(scenario, request));
            let meta = ExportMeta {
                name: format!("{name}-{k}"),
                object: g.object.clone(),
                goal: g.goal.clone(),
                seed: crate::plan::subgoal_seed(seed, k),
            };
            let plan = learner.learn(&task, meta.seed);
            Some(MdpExport::of(meta, &task, &scenario.learner, &plan))
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scenario file exports one MDP per sub-goal; the default scenario's
    /// plan replays in its export.
    #[test]
    fn scenario_exports_one_mdp_per_subgoal() {
        let scenario = crate::scenario::default_scenario().unwrap();
        let goals = subgoals(&scenario, 1).unwrap();
        let gripper = scenario.robot.start.unwrap_or_default();
        let exports = scenario_exports(&scenario, gripper, 1, "default").unwrap();
        assert_eq!(exports.len(), goals.len());
        let e = &exports[0];
        assert_eq!(e.name, "default-0");
        assert_eq!(e.object, goals[0].object);
        assert_eq!(
            e.replay(&e.cql_plan.actions),
            Some(e.cql_plan.actions.len())
        );
    }
}
