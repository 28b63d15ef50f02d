//! The planning pipeline, a straight run of named, timed stages: instruction
//! → sub-goals → per sub-goal a state grid → Contextual Q-learning → a
//! verified grid plan → tool waypoints, with the scene
//! updated after each sub-goal as the camera would see it (the object in its
//! goal, the gripper where it released). A sub-goal that cannot be solved is
//! reported by name with the reason while the others still plan.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::cql::{ContextualQLearner, LearnedPlan};
use crate::error::PlanError;
use crate::grid::{CellCode, GridRequest, StateGrid};
use crate::instruction::{SubGoal, subgoals};
use crate::lift::{LiftSettings, LiftedMotion, lift};
use crate::oracle;
use crate::scenario::Scenario;
use crate::task::{Action, GridTask};

/// Where the pipeline stops. Later stages need the earlier ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Sub-goals, state grids and CQL plans.
    Grid,
    /// Plus tool waypoints in the robot base frame.
    Waypoints,
}

/// How to run the pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Seed of every random choice; same scenario + seed ⇒ same plan.
    pub seed: u64,
    /// The last stage to run.
    pub until: Stage,
    pub lift: LiftSettings,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            seed: 1,
            until: Stage::Waypoints,
            lift: LiftSettings::default(),
        }
    }
}

/// The plan of a whole instruction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    /// Scenario name (or file name when it has none).
    pub scenario: String,
    pub seed: u64,
    /// The last stage that ran.
    pub until: Stage,
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
    /// Tool waypoints (stage `waypoints` and later).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub waypoints: Option<LiftedMotion>,
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

/// Time spent in each named stage, summed over sub-goals.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StageTimings {
    pub subgoals: Duration,
    pub grid: Duration,
    pub cql: Duration,
    pub lift: Duration,
}

/// Runs `f` and adds its wall time to `slot`.
fn timed<T>(slot: &mut Duration, f: impl FnOnce() -> T) -> T {
    let t = Instant::now();
    let value = f();
    *slot += t.elapsed();
    value
}

/// Plans every sub-goal of `scenario`'s instruction, stage by stage up to
/// `options.until`. `Err` only when the instruction itself is not executable
/// or no sub-goal could be planned; otherwise unsolvable sub-goals are listed
/// in [`Plan::unsolved`].
pub fn plan(scenario: &Scenario, options: &PlanOptions) -> Result<Plan, PlanError> {
    let mut timings = StageTimings::default();
    let goals = timed(&mut timings.subgoals, || subgoals(scenario, options.seed))?;
    let mut scene = scenario.clone();
    let mut gripper = scenario.robot.start;
    let mut plan = Plan {
        scenario: scenario.name.clone().unwrap_or_default(),
        seed: options.seed,
        until: options.until,
        subgoals: Vec::new(),
        unsolved: Vec::new(),
        timings: StageTimings::default(),
    };
    for (k, goal) in goals.iter().enumerate() {
        let request = request(&scene, goal, gripper);
        match plan_subgoal(
            &scene,
            goal,
            request,
            subgoal_seed(options.seed, k),
            options,
            &mut timings,
        ) {
            Ok(done) => {
                gripper = *done.path_px.last().unwrap_or(&gripper);
                let object = &mut scene.objects[request.object];
                object.bbox = object.bbox.centred_at(gripper);
                plan.subgoals.push(done);
            }
            Err(reason) => plan.unsolved.push(UnsolvedSubgoal {
                object: goal.object.clone(),
                goal: goal.goal.clone(),
                reason,
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

/// One sub-goal through the stages: grid → CQL → lift. `Err` is the reason
/// it cannot be planned.
fn plan_subgoal(
    scene: &Scenario,
    goal: &SubGoal,
    request: GridRequest,
    seed: u64,
    options: &PlanOptions,
    timings: &mut StageTimings,
) -> Result<SubgoalPlan, String> {
    let task = timed(&mut timings.grid, || {
        GridTask::new(StateGrid::build(scene, request))
    });
    let learner = ContextualQLearner::new(scene.learner.clone());
    let learned = timed(&mut timings.cql, || learner.learn(&task, seed));
    let optimal = oracle::optimal_length(&task).ok_or_else(|| why_unsolvable(scene, request))?;
    if !learned.solved {
        return Err(format!(
            "the learner found no plan within {} training steps",
            learned.training_steps
        ));
    }
    let mut done = subgoal_plan(goal, &task, &learned, optimal);
    if options.until >= Stage::Waypoints {
        done.waypoints = Some(timed(&mut timings.lift, || {
            lift(
                scene,
                &task,
                request.object,
                &learned.actions,
                &learned.cells,
                &options.lift,
            )
        }));
    }
    Ok(done)
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
        waypoints: None,
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
