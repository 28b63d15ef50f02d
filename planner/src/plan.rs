//! The planning pipeline, a straight run of named, timed stages: instruction
//! → sub-goals → per sub-goal a state grid → Contextual Q-learning → a
//! verified grid plan → tool waypoints, with the scene
//! updated after each sub-goal as the camera would see it (the object in its
//! goal, the gripper where it released). A sub-goal that cannot be solved is
//! reported by name with the reason while the others still plan.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use afford_collision::RobotGeometry;
use afford_kinematics::{PathSettings, RobotModel};

use serde::{Deserialize, Serialize};

use crate::clearance::{ArmMotion, FreeMoves, Leg, PathHit, check_motion, gripper_reach};
use crate::cql::{ContextualQLearner, LearnedPlan};
use crate::error::PlanError;
use crate::grid::{Cell, CellCode, GridRequest, StateGrid};
use crate::instruction::{Interpretation, SubGoal, work};
use crate::lift::{GripperReach, LiftSettings, LiftedMotion, Phase, grasp_pose, lift};
use crate::motion::{IK_STARTS, IkStart, solve_motions};
use crate::oracle;
use crate::scenario::Scenario;
use crate::start::{self, FirstSubgoal, StartState};
use crate::task::{Action, GridTask};
use crate::timing::TimingSettings;
use crate::trajectory::{TimedMotion, TimingRequest, time_motion};
use crate::transit::{TransitError, TransitSettings, joint_steps, plan_transit};
use afford_kinematics::{Arm, ArmChoice};

/// Where the pipeline stops. Later stages need the earlier ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Sub-goals, state grids and CQL plans.
    Grid,
    /// Plus tool waypoints in the robot base frame.
    Waypoints,
    /// Plus the arm choice and its collision-checked joint path.
    Joints,
    /// Plus the timed joint trajectory, checked again as sampled.
    Trajectory,
}

/// How to run the pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Seed of every random choice; same scenario + seed ⇒ same plan.
    pub seed: u64,
    /// The last stage to run.
    pub until: Stage,
    pub lift: LiftSettings,
    pub ik: PathSettings,
    pub timing: TimingSettings,
    /// The transit planner's budget ([`crate::transit`]).
    pub transit: TransitSettings,
    /// How often a sub-goal is re-learnt with the cells blocked where the
    /// arm collided, before giving up.
    pub max_replans: usize,
    /// Folder that relative paths in the scenario (a user robot) start from.
    pub base_dir: PathBuf,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            seed: 1,
            until: Stage::Trajectory,
            lift: LiftSettings::default(),
            ik: PathSettings::default(),
            timing: TimingSettings::default(),
            transit: TransitSettings::default(),
            max_replans: 5,
            base_dir: PathBuf::from("."),
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
    /// The whole robot's joint state at t = 0, where the first sub-goal's
    /// trajectory starts (stage `joints` and later).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_state: Option<JointState>,
    /// Pieces the instruction names that already rest in their goal and
    /// are left where they are, one sentence each.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<String>,
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
    /// Pixel `[u, v]` where the object is released and rests: its spot in
    /// the goal box, inside the drop cell ([`crate::place`]).
    pub release_px: [f64; 2],
    pub training_steps: usize,
    /// Shortest possible plan length (BFS oracle), for comparison.
    pub optimal_length: usize,
    /// Grid geometry: size `[n, m]`, cell size `[w, l]` px, origin `[u, v]` px.
    pub grid: GridInfo,
    /// Tool waypoints (stage `waypoints` and later).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub waypoints: Option<LiftedMotion>,
    /// The arm that moves (stage `joints` and later).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arm: Option<String>,
    /// The moving arm's joints, in the order of every joint vector below.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joint_names: Option<Vec<String>>,
    /// The arm's configuration at the start and at every tool waypoint.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joint_path: Option<Vec<Vec<f64>>>,
    /// The timed trajectory and gripper commands (stage `trajectory`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trajectory: Option<TimedMotion>,
}

/// A joint state of the whole robot, in the shape of ROS
/// `sensor_msgs/JointState` (positions only): rad for revolute and
/// continuous joints, m for prismatic ones, in the robot's joint order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointState {
    pub joint_names: Vec<String>,
    pub positions: Vec<f64>,
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
    pub ik: Duration,
    pub collision: Duration,
    /// Transit planning (its edge checks included).
    pub transit: Duration,
    pub timing: Duration,
}

/// Runs `f` and adds its wall time to `slot`.
fn timed<T>(slot: &mut Duration, f: impl FnOnce() -> T) -> T {
    let t = Instant::now();
    let value = f();
    *slot += t.elapsed();
    value
}

/// The planner: runs the pipeline on scenarios with fixed options.
#[derive(Debug, Clone, Default)]
pub struct Planner {
    pub options: PlanOptions,
}

/// What carries over from one sub-goal to the next: the scene as the camera
/// would see it and the robot's configuration.
struct World {
    scene: Scenario,
    gripper_px: [f64; 2],
    robot: Option<RobotModel>,
    geometry: Option<RobotGeometry>,
    /// The gripper's reach and opening (stage `waypoints` and later).
    gripper: Option<GripperReach>,
    joints: Vec<f64>,
}

impl Planner {
    pub fn new(options: PlanOptions) -> Self {
        Self { options }
    }

    /// Plans every sub-goal of `scenario`'s instruction, stage by stage up to
    /// `options.until`. `Err` when the input is bad (instruction not
    /// executable, robot cannot be loaded) or no sub-goal could be planned;
    /// otherwise unsolvable sub-goals are listed in [`Plan::unsolved`].
    pub fn plan(&self, scenario: &Scenario) -> Result<Plan, PlanError> {
        // A scenario built in code has not been through the file checks:
        // every size bound holds before any work starts.
        crate::scenario::check(scenario, scenario.name.as_deref().unwrap_or("scenario"))?;
        let mut timings = StageTimings::default();
        let Interpretation {
            subgoals: goals,
            skipped,
        } = timed(&mut timings.subgoals, || work(scenario, self.options.seed))?;
        let mut plan = self.plan_goals(scenario, &goals, timings)?;
        plan.skipped = skipped;
        Ok(plan)
    }

    /// Plans the given sub-goals of `scenario` in order, from the robot's
    /// state at t = 0, as [`Planner::plan`] does after reading the
    /// instruction (`timings` carries the time spent so far). `Err` as
    /// [`Planner::plan`]; no sub-goals is `Unsolvable`.
    pub fn plan_goals(
        &self,
        scenario: &Scenario,
        goals: &[SubGoal],
        mut timings: StageTimings,
    ) -> Result<Plan, PlanError> {
        let options = &self.options;
        let Some(first_goal) = goals.first() else {
            return Err(PlanError::Unsolvable {
                reasons: vec!["no sub-goals to plan".to_string()],
            });
        };
        let spec = &scenario.robot;
        let needs_robot =
            options.until >= Stage::Waypoints || spec.start.is_none() || spec.joints.is_some();
        let robot = match needs_robot {
            true => Some(
                RobotModel::load(&spec.model, &options.base_dir)
                    .map_err(|e| PlanError::Robot(e.to_string()))?,
            ),
            false => None,
        };
        let start = match &robot {
            Some(r) => Some(self.start_state(scenario, r, first_goal)?),
            None => None,
        };
        let geometry = match (&robot, options.until >= Stage::Waypoints) {
            (Some(r), true) => {
                Some(RobotGeometry::new(r).map_err(|e| PlanError::Robot(e.to_string()))?)
            }
            _ => None,
        };
        let start_state = match (&robot, &start, options.until >= Stage::Joints) {
            (Some(r), Some(s), true) => Some(JointState {
                joint_names: r.joints().iter().map(|j| j.name.clone()).collect(),
                positions: s.joints.clone(),
            }),
            _ => None,
        };
        let (joints, gripper_px) = match start {
            Some(s) => (s.joints, s.gripper_px),
            None => (Vec::new(), spec.start.unwrap_or_default()),
        };
        let gripper = match (&robot, &geometry) {
            (Some(r), Some(g)) => Some(gripper_reach(r, g).map_err(PlanError::Robot)?),
            _ => None,
        };
        let mut world = World {
            scene: scenario.clone(),
            gripper_px,
            robot,
            geometry,
            gripper,
            joints,
        };
        let (subgoals, unsolved) = self.plan_chain(&mut world, goals, &mut timings);
        let plan = Plan {
            scenario: scenario.name.clone().unwrap_or_default(),
            seed: options.seed,
            until: options.until,
            start_state,
            skipped: Vec::new(),
            subgoals,
            unsolved,
            timings,
        };
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

    /// The sub-goals one after another, the world updated after each. An
    /// arm stays where its sub-goal left it, except after the last sub-goal,
    /// where it returns to park (when it has a park posture). When a
    /// sub-goal's motion cannot be planned and the arm of the last planned
    /// sub-goal stayed out of park, that sub-goal is planned again with the
    /// arm returning to park, and the failed one is tried once more; if the
    /// parked version does not plan, the first outcome stands.
    fn plan_chain(
        &self,
        world: &mut World,
        goals: &[SubGoal],
        timings: &mut StageTimings,
    ) -> (Vec<SubgoalPlan>, Vec<UnsolvedSubgoal>) {
        let mut park = vec![false; goals.len()];
        if let Some(last) = park.last_mut() {
            *last = true;
        }
        let mut outcomes: Vec<Result<SubgoalPlan, String>> = Vec::new();
        let mut snapshots: Vec<Option<Snapshot>> = vec![None; goals.len()];
        // After a rewind to sub-goal j: the outcomes and the world as they
        // were, restored when j does not plan with its arm parking.
        let mut fallback: Option<Rewound> = None;
        while outcomes.len() < goals.len() {
            let k = outcomes.len();
            let goal = &goals[k];
            let request = request(&world.scene, goal, world.gripper_px);
            snapshots[k] = Some(world.snapshot());
            let seed = subgoal_seed(self.options.seed, k);
            let refused = match self.plan_subgoal(world, goal, request, seed, park[k], timings) {
                Ok(done) => {
                    world.advance(request, &done);
                    outcomes.push(Ok(done));
                    fallback = None;
                    continue;
                }
                Err(refused) => refused,
            };
            if let Some((j, saved, state)) = fallback.take() {
                park[j] = false;
                outcomes = saved;
                world.restore(state);
                continue;
            }
            let rewind = match refused.motion {
                true => self.rewind_to(world, &outcomes, &park),
                false => None,
            };
            let Some(j) = rewind else {
                outcomes.push(Err(refused.reason));
                continue;
            };
            let mut saved = outcomes.clone();
            saved.push(Err(refused.reason));
            fallback = Some((j, saved, world.snapshot()));
            park[j] = true;
            outcomes.truncate(j);
            if let Some(state) = snapshots[j].clone() {
                world.restore(state);
            }
        }
        let mut subgoals = Vec::new();
        let mut unsolved = Vec::new();
        for (goal, outcome) in goals.iter().zip(outcomes) {
            match outcome {
                Ok(done) => subgoals.push(done),
                Err(reason) => unsolved.push(UnsolvedSubgoal {
                    object: goal.object.clone(),
                    goal: goal.goal.clone(),
                    reason,
                }),
            }
        }
        (subgoals, unsolved)
    }

    /// The last planned sub-goal, when its arm stayed out of park (it has a
    /// park posture and is not at it): the one to plan again with the arm
    /// parking at its end.
    fn rewind_to(
        &self,
        world: &World,
        outcomes: &[Result<SubgoalPlan, String>],
        park: &[bool],
    ) -> Option<usize> {
        let robot = world.robot.as_ref()?;
        let j = outcomes.iter().rposition(|o| o.is_ok())?;
        let arm = outcomes[j].as_ref().ok()?.arm.as_ref()?;
        let arm = robot.arm(arm).ok()?;
        (!park[j] && !arm.park.is_empty() && !start::is_parked(arm, &world.joints)).then_some(j)
    }

    /// The robot's state at t = 0 ([`crate::start`]); the first sub-goal
    /// gives the grid cell and the carry height the rules use.
    fn start_state(
        &self,
        scenario: &Scenario,
        robot: &RobotModel,
        first: &SubGoal,
    ) -> Result<StartState, PlanError> {
        let object = scenario
            .object_index(&first.object)
            .expect("sub-goals name scenario objects");
        let first = FirstSubgoal::moving(scenario, object, &self.options.lift);
        start::resolve(scenario, robot, &first, &self.options.ik.ik).map_err(|issues| {
            PlanError::RobotState {
                robot: robot.name().to_string(),
                issues,
            }
        })
    }

    /// One sub-goal through the stages: grid → CQL → lift → IK. `Err` is the
    /// reason it cannot be planned. `park`: the arm returns to its park
    /// posture at the end (when it has one).
    fn plan_subgoal(
        &self,
        world: &World,
        goal: &SubGoal,
        request: GridRequest,
        seed: u64,
        park: bool,
        timings: &mut StageTimings,
    ) -> Result<SubgoalPlan, Refused> {
        let mut retry = Retry::default();
        loop {
            let pass = Pass {
                world,
                goal,
                request,
                seed,
                park,
            };
            let hit = match self.attempt(&pass, &retry, timings)? {
                Attempt::Planned(done) => return Ok(*done),
                Attempt::Collides(hit) => hit,
            };
            let cell = hit
                .replannable_cell
                .filter(|_| retry.blocked.len() < self.options.max_replans);
            match cell {
                Some(cell) if !retry.blocked.contains(&cell) => retry.blocked.push(cell),
                _ if hit.at_grasp && !retry.flipped => retry.flipped = true,
                _ => {
                    return Err(Refused::motion(format!(
                        "the motion collides: {}",
                        hit.message
                    )));
                }
            }
        }
    }

    /// One pass through the stages with `blocked` cells added to the grid:
    /// grid → CQL → lift → IK → collision check.
    fn attempt(
        &self,
        pass: &Pass,
        retry: &Retry,
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
        let task = timed(&mut timings.grid, || {
            let mut grid = StateGrid::build_placing(scene, request, opening(world));
            blocked.iter().for_each(|&cell| grid.block(cell));
            GridTask::new(grid)
        });
        let learner = ContextualQLearner::new(scene.learner.clone());
        let learned = timed(&mut timings.cql, || learner.learn(&task, seed));
        let Some(optimal) = oracle::optimal_length(&task) else {
            return Err(match blocked.is_empty() {
                true => Refused::early(why_unsolvable(scene, request, opening(world))),
                false => Refused::motion(format!(
                    "no route is left once {} cells the arm collides over are blocked",
                    blocked.len()
                )),
            });
        };
        if !learned.solved {
            return Err(Refused::early(format!(
                "the learner found no plan within {} training steps",
                learned.training_steps
            )));
        }
        let mut done = subgoal_plan(goal, &task, &learned, optimal);
        if options.until < Stage::Waypoints {
            return Ok(Attempt::Planned(Box::new(done)));
        }
        let Some(gripper) = &world.gripper else {
            return Err(Refused::early(
                "the robot is needed to lift the plan".to_string(),
            ));
        };
        let mut motion = timed(&mut timings.lift, || {
            lift(
                scene,
                &task,
                request.object,
                request.goal,
                &learned.actions,
                &learned.cells,
                gripper,
                &options.lift,
            )
        })
        .map_err(Refused::early)?;
        if retry.flipped {
            motion
                .waypoints
                .iter_mut()
                .for_each(|w| w.yaw += std::f64::consts::PI);
        }
        let (Some(robot), Some(geometry), true) = (
            &world.robot,
            &world.geometry,
            options.until >= Stage::Joints,
        ) else {
            done.waypoints = Some(motion);
            return Ok(Attempt::Planned(Box::new(done)));
        };
        // The arms that reach, cheapest first: the first whose whole motion
        // is free moves. When none is, the arms try again with their IK
        // started from their home posture, then from random postures
        // (other branches: an IK posture may fold into the body). A collision of
        // the cheapest goes back to the grid when no arm is free; transit
        // refusals are named with it.
        let mut first_hit: Option<Replan> = None;
        let mut no_transit = Vec::new();
        let mut free = None;
        for start in IK_STARTS {
            let choices = timed(&mut timings.ik, || {
                solve_motions(robot, &motion, &world.joints, &options.ik, seed, start)
            });
            let choices = match (choices, start) {
                (Ok(c), _) => c,
                (Err(e), IkStart::Current) => return Err(Refused::motion(e)),
                (Err(_), _) => continue,
            };
            for choice in choices {
                let arm = &robot.arms()[choice.arm_index];
                let outcome =
                    self.arm_motion(pass, robot, geometry, arm, &choice, &task, &motion, timings)?;
                match outcome {
                    ArmMotionOutcome::Free(path) => {
                        free = Some((choice, arm, path));
                        break;
                    }
                    ArmMotionOutcome::Collides(hit) => {
                        first_hit.get_or_insert(*hit);
                    }
                    ArmMotionOutcome::NoTransit(reason) => {
                        no_transit.push(format!("arm {}: {reason}", arm.name));
                    }
                }
            }
            if free.is_some() {
                break;
            }
        }
        let Some((choice, arm, planned)) = free else {
            return match first_hit {
                Some(mut hit) => {
                    no_transit
                        .iter()
                        .for_each(|r| hit.message.push_str(&format!("; {r}")));
                    Ok(Attempt::Collides(Box::new(hit)))
                }
                None => Err(Refused::motion(format!(
                    "no collision-free transit: {}",
                    no_transit.join("; ")
                ))),
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
            let timed_motion =
                timed(&mut timings.timing, || time_motion(&request)).map_err(Refused::motion)?;
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
            };
            if let Some(hit) = timed(&mut timings.collision, || {
                check_motion(robot, geometry, &verify)
            })
            .map_err(Refused::motion)?
            {
                let t = timed_motion.points[hit.index].time_from_start;
                return Err(Refused::motion(format!(
                    "the timed trajectory collides at t = {t:.3} s: {}",
                    hit.collision
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

    /// One arm's whole joint path for the sub-goal: the transit from where
    /// the arm is to its path, its IK path, and (when the pass parks) the
    /// transit back to park, each transit straight when free and else found
    /// by the transit planner ([`crate::transit`]); then the continuous
    /// check of the whole path. Leading travel waypoints whose configuration
    /// is not free (the start cell over an obstacle's perimeter, where a
    /// parked arm's gripper never is) are left out: the transit joins the
    /// tool path at the first free one.
    #[allow(clippy::too_many_arguments)]
    fn arm_motion(
        &self,
        pass: &Pass,
        robot: &RobotModel,
        geometry: &RobotGeometry,
        arm: &Arm,
        choice: &ArmChoice,
        task: &GridTask,
        motion: &LiftedMotion,
        timings: &mut StageTimings,
    ) -> Result<ArmMotionOutcome, Refused> {
        let (world, request) = (pass.world, pass.request);
        let scene = &world.scene;
        let moves = |leg| {
            FreeMoves::new(
                robot,
                geometry,
                scene,
                request.object,
                request.goal,
                &arm.name,
                &world.joints,
                leg,
            )
            .map_err(Refused::motion)
        };
        let before = moves(Leg::BeforeGrasp)?;
        let skip = timed(&mut timings.transit, || {
            leading_blocked(&before, motion, &choice.path.waypoints)
        })
        .map_err(Refused::motion)?;
        let motion = LiftedMotion {
            waypoints: motion.waypoints[skip..].to_vec(),
            ..motion.clone()
        };
        let waypoints = &choice.path.waypoints[skip..];
        let start = arm.extract(&world.joints);
        let first = waypoints.first().cloned().unwrap_or_else(|| start.clone());
        let stream = 2 * choice.arm_index;
        let mut lead =
            match self.transit(arm, &before, &start, &first, pass.seed, stream, timings)? {
                Ok(path) => path,
                Err(e) => {
                    return Ok(ArmMotionOutcome::NoTransit(format!(
                        "on the way to the first waypoint: {e}"
                    )));
                }
            };
        // The transit ends on the first waypoint, which the IK path starts with.
        lead.pop();
        // joint_path[lead.len() + 1 + k] is tool waypoint k.
        let offset = lead.len();
        let mut joint_path: Vec<Vec<f64>> = std::iter::once(start)
            .chain(lead)
            .chain(waypoints.iter().cloned())
            .collect();
        if pass.park && !arm.park.is_empty() {
            let after = moves(Leg::AfterRelease)?;
            let last = joint_path.last().cloned().unwrap_or_default();
            let parked = arm.extract(&start::parked_home(robot));
            match self.transit(arm, &after, &last, &parked, pass.seed, stream + 1, timings)? {
                Ok(path) => joint_path.extend(path),
                Err(e) => {
                    return Ok(ArmMotionOutcome::NoTransit(format!(
                        "returning to park: {e}"
                    )));
                }
            }
        }
        let (grasp_at, release_at) = motion.gripper_switches();
        let (grasp_at, release_at) = (grasp_at + offset, release_at + offset);
        let check = ArmMotion {
            scenario: scene,
            target: request.object,
            goal: request.goal,
            arm: &arm.name,
            rest: &world.joints,
            path: &joint_path,
            grasp_at,
            release_at,
        };
        if let Some(hit) = timed(&mut timings.collision, || {
            check_motion(robot, geometry, &check)
        })
        .map_err(Refused::motion)?
        {
            return Ok(ArmMotionOutcome::Collides(Box::new(Replan::of(
                hit, offset, scene, task, &motion,
            ))));
        }
        Ok(ArmMotionOutcome::Free(PlannedPath {
            joint_path,
            grasp_at,
            release_at,
            motion,
        }))
    }

    /// A transit of `arm` from `from` to `to` (excluded, included) under
    /// `moves`' edge test, with the random stream `stream` of the sub-goal's
    /// seed. An end that is not free gives the straight move, for the whole
    /// path's check to name the hit; the inner `Err` is why no transit
    /// exists within the budget, the outer one a check that cannot run.
    #[allow(clippy::too_many_arguments)]
    fn transit(
        &self,
        arm: &Arm,
        moves: &FreeMoves,
        from: &[f64],
        to: &[f64],
        seed: u64,
        stream: usize,
        timings: &mut StageTimings,
    ) -> Result<Result<Vec<Vec<f64>>, TransitError>, Refused> {
        let settings = &self.options.transit;
        let found = timed(&mut timings.transit, || {
            plan_transit(
                arm,
                from,
                to,
                &mut |a, b| moves.edge_free(a, b),
                settings,
                subgoal_seed(seed ^ TRANSIT_STREAM, stream),
            )
        });
        match found {
            Ok(t) => Ok(Ok(t.path)),
            Err(TransitError::StartCollides | TransitError::EndCollides) => {
                Ok(Ok(joint_steps(from, to, settings.max_step)))
            }
            Err(TransitError::Check(e)) => Err(Refused::motion(e)),
            Err(e) => Ok(Err(e)),
        }
    }
}

/// How many leading travel waypoints have a configuration that is not free
/// (at most all but the last travel waypoint).
fn leading_blocked(
    moves: &FreeMoves,
    motion: &LiftedMotion,
    path: &[Vec<f64>],
) -> Result<usize, String> {
    let travel = motion
        .waypoints
        .iter()
        .take_while(|w| w.phase == Phase::Travel)
        .count()
        .min(path.len());
    for (k, q) in path.iter().enumerate().take(travel.saturating_sub(1)) {
        if moves.edge_free(q, q)? {
            return Ok(k);
        }
    }
    Ok(travel.saturating_sub(1))
}

/// Offset of the transit planner's random streams from the learner's
/// (sub-goal seeds are SplitMix64 steps; this keeps the two apart).
const TRANSIT_STREAM: u64 = 0x7472_616e_7369_7473;

/// One sub-goal's inputs to a pass through the stages.
struct Pass<'a> {
    world: &'a World,
    goal: &'a SubGoal,
    request: GridRequest,
    seed: u64,
    /// The arm returns to park at the end.
    park: bool,
}

/// Why a sub-goal was not planned.
#[derive(Debug)]
struct Refused {
    reason: String,
    /// The arm's motion failed (joints or trajectory stage): another robot
    /// state (the previous arm parked) may plan it.
    motion: bool,
}

impl Refused {
    /// Refused before any arm moves (scene, grid, learner, lifting).
    fn early(reason: String) -> Self {
        Self {
            reason,
            motion: false,
        }
    }

    fn motion(reason: String) -> Self {
        Self {
            reason,
            motion: true,
        }
    }
}

/// A collision-checked joint path, where the gripper closes and opens, and
/// the tool waypoints it follows.
struct PlannedPath {
    joint_path: Vec<Vec<f64>>,
    grasp_at: usize,
    release_at: usize,
    motion: LiftedMotion,
}

/// How one arm's motion for a sub-goal turned out.
enum ArmMotionOutcome {
    Free(PlannedPath),
    Collides(Box<Replan>),
    /// No collision-free transit within the planner's budget.
    NoTransit(String),
}

/// What a sub-goal's next pass does differently after a collision.
#[derive(Debug, Default)]
struct Retry {
    /// Cells the arm collided over, blocked in the grid.
    blocked: Vec<Cell>,
    /// Grasp with the tool turned half a turn (a hand whose open finger
    /// sticks out to one side then has it on the other).
    flipped: bool,
}

/// The outcome of one pass through the stages.
enum Attempt {
    Planned(Box<SubgoalPlan>),
    Collides(Box<Replan>),
}

/// A collision the grid did not see, and the cell to block for the next pass.
struct Replan {
    /// The collision in words, with the waypoint and phase where it happens.
    message: String,
    /// The cell under the colliding waypoint, when it is a travel or carry
    /// waypoint over a cell that may be blocked (not the start, the target or
    /// the goal).
    replannable_cell: Option<Cell>,
    /// The hit is where the hand closes or opens on the object (approach,
    /// grasp, lift, release): turning the tool may avoid it.
    at_grasp: bool,
}

impl Replan {
    /// `offset`: joint-path configurations between the start and the first
    /// waypoint (the way out of park).
    fn of(
        hit: PathHit,
        offset: usize,
        scene: &Scenario,
        task: &GridTask,
        motion: &LiftedMotion,
    ) -> Self {
        let grid = &task.grid;
        let at = hit
            .index
            .checked_sub(offset)
            .and_then(|i| motion.waypoint_of(i));
        let message = match at {
            Some((k, phase)) => format!(
                "{} waypoint {k}: {}",
                format!("{phase:?}").to_lowercase(),
                hit.collision
            ),
            None if hit.index <= offset => {
                format!("on the way to the first waypoint: {}", hit.collision)
            }
            None => format!("returning to park: {}", hit.collision),
        };
        let cell = at
            .filter(|(_, phase)| matches!(phase, Phase::Travel | Phase::Carry))
            .map(|(k, _)| motion.waypoints[k].position)
            .map(|p| grid.cell_at(scene.base_to_pixel([p[0], p[1]])))
            .filter(|&cell| {
                cell != grid.start && cell != grid.target && grid.code(cell) == CellCode::Empty
            });
        let at_grasp = at.is_some_and(|(_, p)| {
            matches!(
                p,
                Phase::Approach | Phase::Grasp | Phase::Lift | Phase::Release
            )
        });
        Self {
            message,
            replannable_cell: cell,
            at_grasp,
        }
    }
}

/// The sub-goal a chain went back to, and the outcomes and world before.
type Rewound = (usize, Vec<Result<SubgoalPlan, String>>, Snapshot);

/// The part of the [`World`] a sub-goal changes, to plan it again.
#[derive(Clone)]
struct Snapshot {
    scene: Scenario,
    gripper_px: [f64; 2],
    joints: Vec<f64>,
}

impl World {
    fn snapshot(&self) -> Snapshot {
        Snapshot {
            scene: self.scene.clone(),
            gripper_px: self.gripper_px,
            joints: self.joints.clone(),
        }
    }

    fn restore(&mut self, state: Snapshot) {
        self.scene = state.scene;
        self.gripper_px = state.gripper_px;
        self.joints = state.joints;
    }

    /// The scene after a planned sub-goal: the object rests on its spot in
    /// the goal box, the gripper is over it, the arm where its path ended
    /// (other arms stay where they are: the collision check sees them there).
    fn advance(&mut self, request: GridRequest, done: &SubgoalPlan) {
        self.gripper_px = done.release_px;
        let object = &mut self.scene.objects[request.object];
        object.bbox = object.bbox.centred_at(self.gripper_px);
        let (Some(robot), Some(arm), Some(path)) = (&self.robot, &done.arm, &done.joint_path)
        else {
            return;
        };
        // Where the robot really stops: the last trajectory sample (the next
        // sub-goal starts there exactly), or the path's end before timing.
        let last = match &done.trajectory {
            Some(t) => t.points.last().map(|p| &p.positions),
            None => path.last(),
        };
        if let (Ok(arm), Some(last)) = (robot.arm(arm), last) {
            arm.insert(&mut self.joints, last);
        }
    }
}

/// Plans `scenario` with `options`: `Planner::new(options).plan(scenario)`.
pub fn plan(scenario: &Scenario, options: &PlanOptions) -> Result<Plan, PlanError> {
    Planner::new(options.clone()).plan(scenario)
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
        release_px: grid
            .release
            .unwrap_or_else(|_| grid.centre(*learned.cells.last().unwrap_or(&grid.start))),
        training_steps: learned.training_steps,
        optimal_length,
        grid: GridInfo {
            size: [grid.rows, grid.cols],
            cell_px: grid.cell_size,
            origin_px: grid.origin,
        },
        waypoints: None,
        arm: None,
        joint_names: None,
        joint_path: None,
        trajectory: None,
    }
}

/// The half-widths a release spot leaves room for: the grasp region's
/// colliders about the TCP, at least the open fingers (m, see
/// [`GripperReach::finger_half_extent`]), once the robot is known.
fn opening(world: &World) -> Option<[f64; 2]> {
    world.gripper.map(|g| g.finger_half_extent)
}

/// Why the oracle finds no plan, in words a user can act on.
fn why_unsolvable(scene: &Scenario, request: GridRequest, opening: Option<[f64; 2]>) -> String {
    let grid = StateGrid::build_placing(scene, request, opening);
    let object = &scene.objects[request.object].name;
    let goal = &scene.goals[request.goal].name;
    if grid.code(grid.target) == CellCode::Hand {
        return format!("a hand covers {object}");
    }
    if grid.code(grid.start) == CellCode::Hand {
        return "a hand's perimeter covers the gripper: wait for the hand to move".to_string();
    }
    if let Err(no_spot) = grid.release {
        return no_spot.reason(scene, request.object, request.goal);
    }
    let without_hands = Scenario {
        hands: Vec::new(),
        ..scene.clone()
    };
    let grid = StateGrid::build_placing(&without_hands, request, opening);
    if oracle::optimal_length(&GridTask::new(grid)).is_some() {
        return "hand blocks every route".to_string();
    }
    format!("no free route from the gripper to {object} and on to the {goal}")
}
