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
    use crate::bench::cql::generated_export;

    /// The format reads back to the same value (serde, JSON).
    #[test]
    fn mdp_export_round_trips_through_json() {
        let export = generated_export(1, 0, true);
        let text = serde_json::to_string(&export).unwrap();
        let back: MdpExport = serde_json::from_str(&text).unwrap();
        assert_eq!(back, export);
        assert_eq!(back.format_version, FORMAT_VERSION);
    }

    /// A reader must know the version: a file without it is refused, as is
    /// a field the format does not have.
    #[test]
    fn mdp_export_refuses_missing_version_and_unknown_fields() {
        let export = generated_export(1, 1, false);
        let mut value = serde_json::to_value(&export).unwrap();
        value.as_object_mut().unwrap().remove("format_version");
        assert!(serde_json::from_value::<MdpExport>(value.clone()).is_err());
        value["format_version"] = 1.into();
        value["surprise"] = 1.into();
        assert!(serde_json::from_value::<MdpExport>(value).is_err());
    }

    /// Tables are one row per state, and the state count stays within the
    /// bound the scenario limits imply; every next state is on the table.
    #[test]
    fn mdp_export_tables_are_bounded_and_consistent() {
        for index in 0..10 {
            let e = generated_export(1, index, false);
            let states = e.rows * e.cols * 2;
            assert!(states <= MAX_STATES, "{}: {states} states", e.name);
            assert_eq!(e.next.len(), states);
            assert_eq!(e.reward.len(), states);
            assert_eq!(e.grid.len(), e.rows);
            assert!(e.grid.iter().all(|row| row.len() == e.cols));
            let on_table = |n: i64| n == REFUSED || n == DONE || (0..states as i64).contains(&n);
            assert!(e.next.iter().flatten().all(|&n| on_table(n)), "{}", e.name);
        }
    }

    /// afford's own CQL plan, replayed through the exported transitions,
    /// reaches DROP in exactly its length; a plan cut short does not.
    #[test]
    fn exported_cql_plan_replays_to_drop() {
        let mut solved = 0;
        for index in 0..20 {
            let e = generated_export(1, index, false);
            if !e.cql_plan.solved {
                assert_eq!(
                    e.optimal_length, None,
                    "{}: CQL failed a solvable MDP",
                    e.name
                );
                continue;
            }
            solved += 1;
            let plan = &e.cql_plan.actions;
            assert_eq!(e.replay(plan), Some(plan.len()), "{}", e.name);
            assert!(plan.len() >= e.optimal_length.unwrap());
            assert_eq!(e.replay(&plan[..plan.len() - 1]), None, "{}", e.name);
        }
        // Most generated scenes leave no resting spot in the goal (see
        // `afford bench cql`: 36 of seed 1's first 100 are solvable).
        assert!(solved >= 5, "only {solved} of 20 scenes solved");
    }

    /// The exported rewards and terminal are the learner's: the last step
    /// of a solved plan earns `reward_drop`, GOAL earns `reward_goal`, a
    /// refused action `reward_refused`.
    #[test]
    fn exported_rewards_follow_the_learner_settings() {
        let settings = LearnerSettings::default();
        let e = (0..20)
            .map(|index| generated_export(1, index, false))
            .find(|e| e.cql_plan.solved)
            .unwrap();
        let mut state = e.start_state;
        for a in &e.cql_plan.actions {
            let (next, r) = (e.next[state][a.index()], e.reward[state][a.index()]);
            let expected = match (next, a) {
                (DONE, _) => settings.reward_drop,
                (_, Action::Goal) => settings.reward_goal,
                (_, Action::Grasp) => settings.reward_grasp,
                _ => settings.reward_move,
            };
            assert_eq!(r, expected);
            if next >= 0 {
                state = next as usize;
            }
        }
        let refused = e.next.iter().flatten().zip(e.reward.iter().flatten());
        assert!(
            refused
                .filter(|&(&n, _)| n == REFUSED)
                .all(|(_, &r)| r == settings.reward_refused)
        );
    }

    /// Learner statistics are there only when asked for, and the CQL run
    /// they report is the exported plan.
    #[test]
    fn learner_stats_describe_the_exported_plan() {
        assert!(generated_export(1, 3, false).learners.is_none());
        let e = generated_export(1, 3, true);
        let stats = e.learners.as_ref().unwrap();
        assert_eq!(stats.cql.plan, e.cql_plan);
        assert!(stats.cql.wall_ms >= 0.0 && stats.ql.wall_ms >= 0.0);
    }

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
