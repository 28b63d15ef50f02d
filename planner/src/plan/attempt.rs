//! One sub-goal through the stages (grid → Contextual Q-learning → verified
//! grid plan → tool waypoints → arm motion), tried again with a cell
//! blocked or the tool turned when the arm's motion collides, and the
//! reason in a user's terms when the grid has no plan.

use super::arm::{ArmMotionOutcome, PlannedPath, Replan, carry_on, collides, drop_leading_close};
use super::types::{GridInfo, PlanOptions, Planner, Stage, StageTimings, SubgoalPlan, timed};
use super::world::{Pass, Refused, World, room};
use crate::clearance::{ArmMotion, SelfClearance, check_motion};
use crate::cql::{ContextualQLearner, LearnedPlan};
use crate::error::{HitPlace, Refusal};
use crate::grid::{Cell, CellCode, GridRequest, StateGrid};
use crate::instruction::SubGoal;
use crate::lift::{LiftRequest, grasp_pose, lift};
use crate::motion::{IK_START, solve_motions};
use crate::place::Room;
use crate::route_grid::routable_task;
use crate::scenario::Scenario;
use crate::task::GridTask;
use crate::trajectory::{TimingRequest, time_motion};

impl Planner {
    /// One sub-goal through the stages: grid → CQL → lift → IK. `Err` is the
    /// reason it cannot be planned.
    pub(super) fn plan_subgoal(
        &self,
        pass: Pass,
        timings: &mut StageTimings,
    ) -> Result<SubgoalPlan, Refused> {
        let (world, request) = (pass.world, pass.request);
        let mut retry = Retry::default();
        loop {
            let hit = match self.attempt(&pass, &mut retry, timings)? {
                Attempt::Planned(done) => return Ok(*done),
                Attempt::Collides(hit) => hit,
            };
            if retry.arm_motions >= self.options.max_arm_motions {
                return Err(Refused::motion(hit.refusal));
            }
            let cell = hit
                .replannable_cell
                .filter(|_| retry.blocked.len() < self.options.max_replans);
            match cell {
                // The route's carry height came first: a collision is met
                // with the full height before any cell is blocked.
                _ if hit.lowered && !retry.full_height => retry.full_height = true,
                Some(cell) if !retry.blocked.contains(&cell) => retry.blocked.push(cell),
                _ if hit.at_grasp
                    && retry.turn + 1 < grasp_turns(world, request, &self.options) =>
                {
                    retry.turn += 1
                }
                _ => return Err(Refused::motion(hit.refusal)),
            }
        }
    }

    /// One pass through the stages with `blocked` cells added to the grid:
    /// grid → CQL → lift → IK → collision check.
    pub(super) fn attempt(
        &self,
        pass: &Pass,
        retry: &mut Retry,
        timings: &mut StageTimings,
    ) -> Result<Attempt, Refused> {
        let (world, goal, request, seed) = (pass.world, pass.goal, pass.request, pass.seed);
        let (options, scene, blocked) = (&self.options, &world.scene, &retry.blocked);
        if let Some(gripper) = &world.gripper {
            grasp_pose(
                scene,
                &scene.objects[request.object],
                gripper,
                &options.lift,
            )
            .map_err(Refused::early)?;
        }
        let (task, optimal) = timed(&mut timings.grid, || {
            routable_task(scene, request, room(world, pass.later), blocked)
        });
        let learner = ContextualQLearner::new(scene.learner.clone());
        let learned = timed(&mut timings.cql, || learner.learn(&task, seed));
        let Some(optimal) = optimal else {
            return Err(match blocked.is_empty() {
                true => Refused::early(why_unsolvable(scene, request, room(world, pass.later))),
                false => Refused::motion(Refusal::NoRoute {
                    object: scene.objects[request.object].name.clone(),
                    goal: scene.goals[request.goal].name.clone(),
                    blocked_cells: blocked.len(),
                }),
            });
        };
        if !learned.solved {
            return Err(Refused::early(Refusal::LearnerBudget {
                training_steps: learned.training_steps,
            }));
        }
        let room_for = pass.later.iter().map(|&j| scene.objects[j].name.clone());
        let mut done = subgoal_plan(goal, &task, &learned, optimal, room_for.collect());
        if options.until < Stage::Waypoints {
            return Ok(Attempt::Planned(Box::new(done)));
        }
        let Some(gripper) = &world.gripper else {
            return Err(Refused::early(Refusal::internal(
                "lift",
                "the robot is needed to lift the plan",
            )));
        };
        let lift_request = LiftRequest {
            object: request.object,
            goal: request.goal,
            actions: &learned.actions,
            cells: &learned.cells,
            start_px: world.gripper_px,
            start_height: world.gripper_height,
            full_height: retry.full_height,
        };
        let mut motion = timed(&mut timings.lift, || {
            lift(scene, &task, &lift_request, gripper, &options.lift)
        })
        .map_err(Refused::early)?;
        let turn = f64::from(GRASP_TURNS[retry.turn]) * std::f64::consts::FRAC_PI_2;
        if turn != 0.0 {
            motion.waypoints.iter_mut().for_each(|w| w.yaw += turn);
        }
        let held = world.held.as_ref().filter(|h| h.object == goal.object);
        if held.is_some() {
            carry_on(&mut motion);
        }
        let (Some(robot), Some(geometry), true) = (
            &world.robot,
            &world.geometry,
            options.until >= Stage::Joints,
        ) else {
            done.waypoints = Some(motion);
            return Ok(Attempt::Planned(Box::new(done)));
        };
        // The arms that reach, cheapest first, their IK started where they
        // are: the first whose whole motion is free moves ([`IK_START`]). A
        // collision goes back to the grid when no arm is free; else the
        // transits not found are the refusal.
        let mut first_hit: Option<Replan> = None;
        let mut no_transit = Vec::new();
        let mut free = None;
        let screen = SelfClearance::new(geometry, &world.joints)
            .map_err(|e| Refused::motion(Refusal::internal("collision", e)))?;
        let solved = timed(&mut timings.ik, || {
            let (joints, ik) = (&world.joints, &options.ik);
            solve_motions(robot, &motion, joints, ik, seed, IK_START, Some(&screen))
        });
        let choices = match solved {
            Ok(choices) => choices,
            Err(refusal) => {
                let replan = Replan::out_of_reach(refusal, scene, &task, &motion);
                return replan
                    .map(|r| Attempt::Collides(Box::new(r)))
                    .map_err(Refused::motion);
            }
        };
        for choice in choices {
            if retry.arm_motions >= options.max_arm_motions {
                break;
            }
            retry.arm_motions += 1;
            let arm = &robot.arms()[choice.arm_index];
            let outcome =
                self.arm_motion(pass, robot, geometry, arm, &choice, &task, &motion, timings)?;
            match outcome {
                ArmMotionOutcome::Free(path) => {
                    free = Some((choice, arm, path));
                    break;
                }
                ArmMotionOutcome::Collides(hit) => merge_hit(&mut first_hit, *hit),
                ArmMotionOutcome::NoTransit(failure) => no_transit.push(failure),
            }
        }
        let Some((choice, arm, planned)) = free else {
            return match first_hit {
                Some(hit) => Ok(Attempt::Collides(Box::new(hit))),
                None => Err(Refused::motion(Refusal::NoTransit { arms: no_transit })),
            };
        };
        let PlannedPath {
            joint_path,
            grasp_at,
            release_at,
            motion,
        } = planned;
        if options.until >= Stage::Trajectory {
            let request = TimingRequest {
                scenario: scene,
                robot,
                arm,
                path: &joint_path,
                switches: (grasp_at, release_at),
                separation: &scene.safety.separation,
                settings: &options.timing,
            };
            let mut timed_motion =
                timed(&mut timings.timing, || time_motion(&request)).map_err(Refused::motion)?;
            if held.is_some() {
                drop_leading_close(&mut timed_motion);
            }
            let (grasp_at, release_at) = timed_motion.gripper_samples();
            let positions: Vec<Vec<f64>> = timed_motion
                .points
                .iter()
                .map(|p| p.positions.clone())
                .collect();
            let verify = ArmMotion {
                scenario: scene,
                target: pass.request.object,
                goal: pass.request.goal,
                arm: &arm.name,
                rest: &world.joints,
                path: &positions,
                grasp_at,
                release_at,
                held: held.map(|h| (h.grasped_box, h.grasp.as_slice())),
            };
            if let Some(hit) = timed(&mut timings.collision, || {
                check_motion(robot, geometry, &verify)
            })
            .map_err(|e| Refused::motion(Refusal::internal("collision", e)))?
            {
                let time_s = timed_motion.points[hit.index].time_from_start;
                return Err(Refused::motion(collides(
                    &arm.name,
                    &hit.collision,
                    HitPlace::Trajectory { time_s },
                )));
            }
            done.trajectory = Some(timed_motion);
        }
        done.arm = Some(choice.arm.clone());
        done.joint_names = Some(arm.joint_names.clone());
        done.joint_path = Some(joint_path);
        done.waypoints = Some(motion);
        Ok(Attempt::Planned(Box::new(done)))
    }
}

/// Keeps the first hit of a pass as its refusal, and what any of its hits
/// allows the next pass: a cell to block under the first hit over one, a
/// turn of the tool when any arm hit where the hand closes or opens.
fn merge_hit(first: &mut Option<Replan>, hit: Replan) {
    match first {
        None => *first = Some(hit),
        Some(kept) => {
            kept.replannable_cell = kept.replannable_cell.or(hit.replannable_cell);
            kept.at_grasp |= hit.at_grasp;
        }
    }
}

/// What a sub-goal's next pass does differently after a collision.
#[derive(Debug, Default)]
pub(super) struct Retry {
    /// Cells the arm collided over, blocked in the grid.
    pub(super) blocked: Vec<Cell>,
    /// Index into [`GRASP_TURNS`]: how the tool is turned about its axis at
    /// every waypoint of the pass.
    pub(super) turn: usize,
    /// Carry at the full height (the tallest thing on the table), not the
    /// height the route needs.
    pub(super) full_height: bool,
    /// Arm motions tried so far, every pass counted
    /// ([`PlanOptions::max_arm_motions`]).
    pub(super) arm_motions: usize,
}

/// The outcome of one pass through the stages.
pub(super) enum Attempt {
    Planned(Box<SubgoalPlan>),
    Collides(Box<Replan>),
}

/// Quarter turns of the tool tried in order after a hit where the hand
/// closes or opens: none, half a turn (a hand whose open finger sticks out
/// to one side then has it on the other), then the fingers across the
/// object's longer side both ways (open fingers that straddle a neighbour
/// or a box wall then lie along it), when that side fits the opening
/// ([`grasp_turns`]). The held object keeps its orientation on the table.
pub(super) const GRASP_TURNS: [u8; 4] = [0, 2, 1, 3];

/// How many of [`GRASP_TURNS`] the object allows: all four when its longer
/// side plus the opening clearance fits the gripper's opening, else the
/// first two.
pub(super) fn grasp_turns(world: &World, request: GridRequest, options: &PlanOptions) -> usize {
    let [mu, mv] = world.scene.metres_per_pixel();
    let b = world.scene.objects[request.object].bbox;
    let longer = (b.w * mu).max(b.l * mv);
    match world.gripper {
        Some(g) if longer + options.lift.opening_clearance <= g.max_opening => GRASP_TURNS.len(),
        _ => 2,
    }
}

pub(super) fn subgoal_plan(
    goal: &SubGoal,
    task: &GridTask,
    learned: &LearnedPlan,
    optimal_length: usize,
    room_for: Vec<String>,
) -> SubgoalPlan {
    let grid = &task.grid;
    SubgoalPlan {
        object: goal.object.clone(),
        goal: goal.goal.clone(),
        actions: learned.actions.clone(),
        cells: learned.cells.iter().map(|&(r, c)| [r, c]).collect(),
        path_px: learned.cells.iter().map(|&c| grid.centre(c)).collect(),
        release_px: grid
            .release
            .map(|r| r.spot)
            .unwrap_or_else(|_| grid.centre(*learned.cells.last().unwrap_or(&grid.start))),
        room_for,
        training_steps: learned.training_steps,
        optimal_length,
        grid: GridInfo {
            size: [grid.rows, grid.cols],
            cell_px: grid.cell_size,
            origin_px: grid.origin,
            obstacles: grid.obstacles,
        },
        waypoints: None,
        arm: None,
        joint_names: None,
        joint_path: None,
        trajectory: None,
    }
}

/// Why the oracle finds no plan, in terms a user can act on.
pub(super) fn why_unsolvable(scene: &Scenario, request: GridRequest, room: Room) -> Refusal {
    let grid = StateGrid::build_placing(scene, request, room);
    let object = scene.objects[request.object].name.clone();
    let goal = scene.goals[request.goal].name.clone();
    if grid.code(grid.target) == CellCode::Hand {
        return Refusal::HandCoversTarget { object };
    }
    if grid.code(grid.start) == CellCode::Hand {
        return Refusal::HandCoversGripper;
    }
    if let Err(no_spot) = grid.release {
        return no_spot.reason(scene, request.object, request.goal);
    }
    let without_hands = Scenario {
        hands: Vec::new(),
        ..scene.clone()
    };
    if routable_task(&without_hands, request, room, &[])
        .1
        .is_some()
    {
        return Refusal::HandBlocksRoute { object, goal };
    }
    Refusal::NoRoute {
        object,
        goal,
        blocked_cells: 0,
    }
}
