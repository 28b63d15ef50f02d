//! The discrete planning pipeline: instruction → sub-goals → per sub-goal a
//! state grid → Contextual Q-learning → a verified grid plan, with the scene
//! updated after each sub-goal as the camera would see it (the object in its
//! goal, the gripper where it released). A sub-goal that cannot be solved is
//! reported by name with the reason while the others still plan.

use std::time::{Duration, Instant};

use serde::Serialize;

use crate::cql::{ContextualQLearner, LearnedPlan};
use crate::error::PlanError;
use crate::grid::{CellCode, GridRequest, StateGrid};
use crate::instruction::{SubGoal, subgoals};
use crate::oracle;
use crate::scenario::Scenario;
use crate::task::{Action, GridTask};

/// The discrete plan of a whole instruction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridPlan {
    /// Scenario name (or file name when it has none).
    pub scenario: String,
    pub seed: u64,
    /// Planned sub-goals, in execution order.
    pub subgoals: Vec<SubgoalPlan>,
    /// Sub-goals that could not be planned, with the reason.
    pub unsolved: Vec<UnsolvedSubgoal>,
    /// Wall-clock time per stage; not serialised, so output stays reproducible.
    #[serde(skip)]
    pub timings: StageTimings,
}

/// One planned sub-goal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SubgoalPlan {
    pub object: String,
    pub goal: String,
    pub actions: Vec<Action>,
    /// Visited cells `[row, col]`, start to drop (see [`LearnedPlan::cells`]).
    pub cells: Vec<[usize; 2]>,
    /// Pixel centre `[u, v]` of every visited cell.
    pub path_px: Vec<[f64; 2]>,
    pub training_steps: usize,
    /// Shortest possible plan length (BFS oracle), for comparison.
    pub optimal_length: usize,
    /// Grid geometry: size `[n, m]`, cell size `[w, l]` px, origin `[u, v]` px.
    pub grid: GridInfo,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridInfo {
    pub size: [usize; 2],
    pub cell_px: [f64; 2],
    pub origin_px: [f64; 2],
}

#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct UnsolvedSubgoal {
    pub object: String,
    pub goal: String,
    pub reason: String,
}

/// Time spent in each named stage.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StageTimings {
    pub subgoals: Duration,
    pub grid: Duration,
    pub cql: Duration,
}

/// Plans every sub-goal of `scenario`'s instruction. `Err` only when the
/// instruction itself is not executable or no sub-goal could be planned.
pub fn plan_grid(scenario: &Scenario, seed: u64) -> Result<GridPlan, PlanError> {
    let mut timings = StageTimings::default();
    let t = Instant::now();
    let goals = subgoals(scenario, seed)?;
    timings.subgoals = t.elapsed();
    let learner = ContextualQLearner::new(scenario.learner.clone());
    let mut scene = scenario.clone();
    let mut gripper = scenario.robot.start;
    let mut plan = GridPlan {
        scenario: scenario.name.clone().unwrap_or_default(),
        seed,
        subgoals: Vec::new(),
        unsolved: Vec::new(),
        timings: StageTimings::default(),
    };
    for (k, goal) in goals.iter().enumerate() {
        let request = request(&scene, goal, gripper);
        let t = Instant::now();
        let task = GridTask::new(StateGrid::build(&scene, request));
        timings.grid += t.elapsed();
        let t = Instant::now();
        let learned = learner.learn(&task, subgoal_seed(seed, k));
        timings.cql += t.elapsed();
        match oracle::optimal_length(&task) {
            Some(optimal) if learned.solved => {
                let done = subgoal_plan(goal, &task, &learned, optimal);
                gripper = *done.path_px.last().unwrap_or(&gripper);
                let object = &mut scene.objects[request.object];
                object.bbox = object.bbox.centred_at(gripper);
                plan.subgoals.push(done);
            }
            optimal => plan.unsolved.push(UnsolvedSubgoal {
                object: goal.object.clone(),
                goal: goal.goal.clone(),
                reason: match optimal {
                    None => why_unsolvable(&scene, request),
                    Some(_) => format!(
                        "the learner found no plan within {} training steps",
                        learned.training_steps
                    ),
                },
            }),
        }
    }
    plan.timings = timings;
    if plan.subgoals.is_empty() {
        let reasons = plan
            .unsolved
            .iter()
            .map(|u| format!("{} → {}: {}", u.object, u.goal, u.reason))
            .collect();
        return Err(PlanError::Unsolvable { reasons });
    }
    Ok(plan)
}

fn request(scene: &Scenario, goal: &SubGoal, gripper: [f64; 2]) -> GridRequest {
    GridRequest {
        object: scene
            .object_index(&goal.object)
            .expect("sub-goals name scenario objects"),
        goal: scene
            .goal_index(&goal.goal)
            .expect("sub-goals name scenario goals"),
        gripper,
    }
}

/// A seed per sub-goal derived from the plan's seed (SplitMix64 step), so a
/// sub-goal's plan does not depend on how much randomness earlier ones drew.
pub fn subgoal_seed(seed: u64, k: usize) -> u64 {
    let mut z = seed.wrapping_add((k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn subgoal_plan(
    goal: &SubGoal,
    task: &GridTask,
    learned: &LearnedPlan,
    optimal_length: usize,
) -> SubgoalPlan {
    let grid = &task.grid;
    SubgoalPlan {
        object: goal.object.clone(),
        goal: goal.goal.clone(),
        actions: learned.actions.clone(),
        cells: learned.cells.iter().map(|&(r, c)| [r, c]).collect(),
        path_px: learned.cells.iter().map(|&c| grid.centre(c)).collect(),
        training_steps: learned.training_steps,
        optimal_length,
        grid: GridInfo {
            size: [grid.rows, grid.cols],
            cell_px: grid.cell_size,
            origin_px: grid.origin,
        },
    }
}

/// Why the oracle finds no plan, in words a user can act on.
fn why_unsolvable(scene: &Scenario, request: GridRequest) -> String {
    let grid = StateGrid::build(scene, request);
    let object = &scene.objects[request.object].name;
    let goal = &scene.goals[request.goal].name;
    if grid.code(grid.target) == CellCode::Hand {
        return format!("a hand covers {object}");
    }
    if grid.code(grid.start) == CellCode::Hand {
        return "a hand's perimeter covers the gripper: wait for the hand to move".to_string();
    }
    if grid.drop.is_none() {
        return format!("safety perimeters cover the whole {goal}");
    }
    let without_hands = Scenario {
        hands: Vec::new(),
        ..scene.clone()
    };
    if oracle::optimal_length(&GridTask::new(StateGrid::build(&without_hands, request))).is_some() {
        return "hand blocks every route".to_string();
    }
    format!("no free route from the gripper to {object} and on to the {goal}")
}
