//! The planning pipeline, a straight run of named, timed stages: instruction
//! → sub-goals → per sub-goal a state grid → Contextual Q-learning → a
//! verified grid plan → tool waypoints, with the scene
//! updated after each sub-goal as the camera would see it (the object in its
//! goal, the gripper where it released). A sub-goal that cannot be solved is
//! reported by name with the reason while the others still plan.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use afford_collision::{Collision, RobotGeometry};
use afford_kinematics::{PathSettings, RobotModel};

use serde::{Deserialize, Serialize};

use crate::clearance::{ArmMotion, PathHit, check_motion, gripper_reach};
use crate::cql::{ContextualQLearner, LearnedPlan};
use crate::error::{FieldIssue, HitPlace, PlanError, Refusal};
use crate::grid::{Cell, CellCode, GridRequest, StateGrid};
use crate::instruction::{Interpretation, SubGoal, work};
use crate::lift::{
    GripperReach, LiftRequest, LiftSettings, LiftedMotion, Phase, carry_height, grasp_pose, lift,
};
use crate::motion::solve_motion;
use crate::oracle;
use crate::scenario::{PixelBox, Scenario};
use crate::start::{self, FirstSubgoal, StartState};
use crate::task::{Action, GridTask};
use crate::timing::TimingSettings;
use crate::trajectory::{TimedMotion, TimingRequest, time_motion};

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
    /// How often a sub-goal is re-learnt with the cells blocked where the
    /// arm collided, before giving up.
    pub max_replans: usize,
    /// Folder that a relative `robot.model` path starts from. The rule, the
    /// same in the library and the CLI: a scenario read from a file resolves
    /// it against the file's folder ([`PlanOptions::for_scenario_file`],
    /// what `afford` does); a scenario built in code against `base_dir`,
    /// by default the current directory.
    pub base_dir: PathBuf,
}

/// Most re-plans a sub-goal may take ([`PlanOptions::max_replans`]).
pub const MAX_REPLANS: usize = 64;

/// Largest clearance or step of [`LiftSettings`], m.
const MAX_LIFT_LENGTH_M: f64 = 1.0;

impl PlanOptions {
    /// These options with `base_dir` set to the folder of the scenario file
    /// at `path` (the rule on [`PlanOptions::base_dir`]).
    pub fn for_scenario_file(self, path: &std::path::Path) -> Self {
        Self {
            base_dir: crate::scenario::base_dir(path),
            ..self
        }
    }

    /// Every problem with the options, each naming its field
    /// (`timing.rate_hz`, `lift.max_step`, …); [`Planner::plan`] runs it
    /// first. `Err` is [`PlanError::Options`].
    pub fn validate(&self) -> Result<(), PlanError> {
        let mut issues = Vec::new();
        if let Err(e) = crate::scenario::bounds::check_rate(self.timing.rate_hz) {
            issues.push(FieldIssue::new("timing.rate_hz", e));
        } else if let Err(e) = self.timing.validate() {
            issues.push(FieldIssue::new("timing", e.to_string()));
        }
        if let Err(e) = self.ik.validate() {
            issues.push(FieldIssue::new("ik", e.to_string()));
        }
        let l = &self.lift;
        for (field, value) in [
            ("approach_clearance", l.approach_clearance),
            ("carry_clearance", l.carry_clearance),
            ("release_clearance", l.release_clearance),
            ("min_grasp_height", l.min_grasp_height),
            ("max_step", l.max_step),
            ("tip_clearance", l.tip_clearance),
            ("palm_clearance", l.palm_clearance),
            ("min_grip_depth", l.min_grip_depth),
            ("opening_clearance", l.opening_clearance),
        ] {
            let positive = field != "max_step" || value > 0.0;
            if !(value.is_finite() && (0.0..=MAX_LIFT_LENGTH_M).contains(&value) && positive) {
                issues.push(FieldIssue::new(
                    format!("lift.{field}"),
                    format!(
                        "must be between 0 and {MAX_LIFT_LENGTH_M} m{}, got {value}",
                        if positive { "" } else { " and above 0" }
                    ),
                ));
            }
        }
        if self.max_replans > MAX_REPLANS {
            issues.push(FieldIssue::new(
                "max_replans",
                format!("must be at most {MAX_REPLANS}, got {}", self.max_replans),
            ));
        }
        match issues.is_empty() {
            true => Ok(()),
            false => Err(PlanError::Options { issues }),
        }
    }
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            seed: 1,
            until: Stage::Trajectory,
            lift: LiftSettings::default(),
            ik: PathSettings::default(),
            timing: TimingSettings::default(),
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

/// Where a replanned execution starts (the monitor's braking stop or the
/// end of a sub-goal): the whole robot's joint state, in
/// [`RobotModel::joints`] order, and the object the gripper holds, if any.
#[derive(Debug, Clone, PartialEq)]
pub struct MidExecution {
    pub joints: Vec<f64>,
    pub held: Option<HeldObject>,
}

/// An object in the gripper: its first sub-goal only carries it on.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldObject {
    /// The scenario object's name.
    pub object: String,
    /// Its box where it rested when the fingers closed, pixels: with
    /// `grasp` it fixes the object's pose in the gripper.
    pub grasped_box: PixelBox,
    /// The arm holding it.
    pub arm: String,
    /// That arm's configuration when the fingers closed.
    pub grasp: Vec<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridInfo {
    pub size: [usize; 2],
    pub cell_px: [f64; 2],
    pub origin_px: [f64; 2],
}

/// A sub-goal that could not be planned: `reason` is the message a person
/// reads, `refusal` the typed kind and data a program branches on (JSON
/// `{"kind": ..., ...fields, "message": ...}`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnsolvedSubgoal {
    pub object: String,
    pub goal: String,
    pub reason: String,
    #[serde(serialize_with = "crate::error::serialize_explained")]
    pub refusal: Refusal,
}

impl UnsolvedSubgoal {
    pub fn new(goal: &SubGoal, refusal: Refusal) -> Self {
        Self {
            object: goal.object.clone(),
            goal: goal.goal.clone(),
            reason: refusal.to_string(),
            refusal,
        }
    }
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
    /// The tool's height above the table when it points down over
    /// `gripper_px` (metres), `None` otherwise ([`start::tool_height_over`]).
    gripper_height: Option<f64>,
    robot: Option<RobotModel>,
    geometry: Option<RobotGeometry>,
    /// The gripper's reach and opening (stage `waypoints` and later).
    gripper: Option<GripperReach>,
    joints: Vec<f64>,
    /// The object in the gripper when planning starts mid-execution; only
    /// the first sub-goal carries it ([`Planner::plan_from`]).
    held: Option<HeldObject>,
}

impl Planner {
    pub fn new(options: PlanOptions) -> Self {
        Self { options }
    }

    /// Plans every sub-goal of `scenario`'s instruction, stage by stage up to
    /// `options.until`. `Err` when the input is bad (instruction not
    /// executable, robot cannot be loaded, options or scenario invalid —
    /// the same errors a scenario file gets) or no sub-goal could be planned;
    /// otherwise unsolvable sub-goals are listed in [`Plan::unsolved`].
    pub fn plan(&self, scenario: &Scenario) -> Result<Plan, PlanError> {
        let options = &self.options;
        options.validate()?;
        // A scenario built in code has not been through the file checks:
        // every size bound holds before any work starts.
        scenario.validate()?;
        let mut timings = StageTimings::default();
        let Interpretation {
            subgoals: goals,
            skipped,
        } = timed(&mut timings.subgoals, || work(scenario, options.seed))?;
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
            Some(r) => Some(self.start_state(scenario, r, &goals[0])?),
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
        let gripper_height = robot
            .as_ref()
            .and_then(|r| start::tool_height_over(scenario, r, &joints, gripper_px));
        let mut world = World {
            scene: scenario.clone(),
            gripper_px,
            gripper_height,
            robot,
            geometry,
            gripper,
            joints,
            held: None,
        };
        let mut plan = Plan {
            scenario: scenario.name.clone().unwrap_or_default(),
            seed: options.seed,
            until: options.until,
            start_state,
            skipped,
            subgoals: Vec::new(),
            unsolved: Vec::new(),
            timings: StageTimings::default(),
        };
        self.plan_goals(&mut world, &goals, &mut plan, &mut timings);
        plan.timings = timings;
        if plan.subgoals.is_empty() {
            let reasons = plan
                .unsolved
                .iter()
                .map(|u| format!("{} → {}: {}", u.object, u.goal, u.reason))
                .collect();
            return Err(PlanError::Unsolvable {
                reasons,
                unsolved: plan.unsolved,
            });
        }
        Ok(plan)
    }

    /// Plans `goals` in order from `world`, each from where the one before
    /// ended; unsolvable ones go to `plan.unsolved`.
    fn plan_goals(
        &self,
        world: &mut World,
        goals: &[SubGoal],
        plan: &mut Plan,
        timings: &mut StageTimings,
    ) {
        for (k, goal) in goals.iter().enumerate() {
            let request = request(&world.scene, goal, world.gripper_px);
            match self.plan_subgoal(
                world,
                goal,
                request,
                subgoal_seed(self.options.seed, k),
                timings,
            ) {
                Ok(done) => {
                    world.advance(request, &done);
                    plan.subgoals.push(done);
                }
                Err(refusal) => plan.unsolved.push(UnsolvedSubgoal::new(goal, refusal)),
            }
        }
    }

    /// Plans `goals` (every stage) from a mid-execution state: the robot
    /// where it stopped, the grid starting under the tool of the arm that
    /// moved, and — when `from.held` names the first goal's object — that
    /// sub-goal only carries the object on from where it is (no travel, no
    /// grasp: its trajectory has no close command). `Err` as for
    /// [`Self::plan`]; `scenario` is the scene as the camera sees it now.
    pub fn plan_from(
        &self,
        scenario: &Scenario,
        goals: &[SubGoal],
        from: &MidExecution,
    ) -> Result<Plan, PlanError> {
        let robot = RobotModel::load(&scenario.robot.model, &self.options.base_dir)
            .map_err(|e| PlanError::Robot(e.to_string()))?;
        let geometry = RobotGeometry::new(&robot).map_err(|e| PlanError::Robot(e.to_string()))?;
        self.plan_from_loaded(scenario, &robot, &geometry, goals, from)
    }

    /// [`Self::plan_from`] with the scenario's robot already loaded (a
    /// monitor replanning keeps it).
    pub fn plan_from_loaded(
        &self,
        scenario: &Scenario,
        robot: &RobotModel,
        geometry: &RobotGeometry,
        goals: &[SubGoal],
        from: &MidExecution,
    ) -> Result<Plan, PlanError> {
        self.options.validate()?;
        crate::scenario::check(scenario, scenario.name.as_deref().unwrap_or("scenario"))?;
        let (robot, geometry) = (robot.clone(), geometry.clone());
        let gripper = gripper_reach(&robot, &geometry).map_err(PlanError::Robot)?;
        let arm = from.held.as_ref().map(|h| h.arm.as_str());
        let start = start::mid_execution(scenario, &robot, from.joints.clone(), arm);
        let mut scene = scenario.clone();
        let held = from
            .held
            .clone()
            .filter(|h| goals.first().is_some_and(|g| g.object == h.object));
        if let Some(object) = held.as_ref().and_then(|h| scene.object_index(&h.object)) {
            // The camera sees the held object under the gripper.
            let b = &mut scene.objects[object].bbox;
            *b = b.centred_at(start.gripper_px);
        }
        let gripper_height =
            start::tool_height_over(&scene, &robot, &start.joints, start.gripper_px);
        let mut world = World {
            scene,
            gripper_px: start.gripper_px,
            gripper_height,
            robot: None,
            geometry: Some(geometry),
            gripper: Some(gripper),
            joints: start.joints,
            held,
        };
        let mut plan = Plan {
            scenario: scenario.name.clone().unwrap_or_default(),
            seed: self.options.seed,
            until: Stage::Trajectory,
            start_state: Some(JointState {
                joint_names: robot.joints().iter().map(|j| j.name.clone()).collect(),
                positions: from.joints.clone(),
            }),
            skipped: Vec::new(),
            subgoals: Vec::new(),
            unsolved: Vec::new(),
            timings: StageTimings::default(),
        };
        world.robot = Some(robot);
        let planner = Planner::new(PlanOptions {
            until: Stage::Trajectory,
            ..self.options.clone()
        });
        let mut timings = StageTimings::default();
        planner.plan_goals(&mut world, goals, &mut plan, &mut timings);
        plan.timings = timings;
        Ok(plan)
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
    /// reason it cannot be planned.
    fn plan_subgoal(
        &self,
        world: &World,
        goal: &SubGoal,
        request: GridRequest,
        seed: u64,
        timings: &mut StageTimings,
    ) -> Result<SubgoalPlan, Refusal> {
        let mut retry = Retry::default();
        loop {
            let hit = match self.attempt(world, goal, request, &retry, seed, timings)? {
                Attempt::Planned(done) => return Ok(*done),
                Attempt::Collides(hit) => hit,
            };
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
                _ => return Err(hit.refusal),
            }
        }
    }

    /// One pass through the stages with `blocked` cells added to the grid:
    /// grid → CQL → lift → IK → collision check.
    fn attempt(
        &self,
        world: &World,
        goal: &SubGoal,
        request: GridRequest,
        retry: &Retry,
        seed: u64,
        timings: &mut StageTimings,
    ) -> Result<Attempt, Refusal> {
        let (options, scene, blocked) = (&self.options, &world.scene, &retry.blocked);
        if let Some(gripper) = &world.gripper {
            grasp_pose(
                scene,
                &scene.objects[request.object],
                gripper,
                &options.lift,
            )?;
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
                true => why_unsolvable(scene, request, opening(world)),
                false => Refusal::NoRoute {
                    object: scene.objects[request.object].name.clone(),
                    goal: scene.goals[request.goal].name.clone(),
                    blocked_cells: blocked.len(),
                },
            });
        };
        if !learned.solved {
            return Err(Refusal::LearnerBudget {
                training_steps: learned.training_steps,
            });
        }
        let mut done = subgoal_plan(goal, &task, &learned, optimal);
        if options.until < Stage::Waypoints {
            return Ok(Attempt::Planned(Box::new(done)));
        }
        let Some(gripper) = &world.gripper else {
            return Err(Refusal::internal(
                "lift",
                "the robot is needed to lift the plan",
            ));
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
        })?;
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
        let choice = timed(&mut timings.ik, || {
            solve_motion(robot, &motion, &world.joints, &options.ik, seed)
        })?;
        let arm = &robot.arms()[choice.arm_index];
        let start = arm.extract(&world.joints);
        let mut choice = choice;
        // The route starts where the tool is: a first waypoint whose IK lands
        // on the current configuration is that configuration exactly.
        if let Some(q) = choice.path.waypoints.first_mut()
            && q.iter()
                .zip(&start)
                .all(|(a, b)| (a - b).abs() <= SAME_CONFIGURATION)
        {
            q.clone_from(&start);
        }
        let first = choice
            .path
            .waypoints
            .first()
            .cloned()
            .unwrap_or_else(|| start.clone());
        let lead = match start::is_parked(arm, &world.joints) {
            true => leave_park(arm, &start, &first),
            false => approach(&start, &first),
        };
        // joint_path[lead.len() + 1 + k] is tool waypoint k.
        let offset = lead.len();
        let mut joint_path: Vec<Vec<f64>> = std::iter::once(start.clone())
            .chain(lead)
            .chain(choice.path.waypoints)
            .collect();
        joint_path.extend(return_to_park(arm, &world.joints, &joint_path));
        let (grasp_at, release_at) = motion.gripper_switches();
        // An object already held is held from the start.
        let grasp_at = held.map_or(grasp_at + offset, |_| 0);
        let release_at = release_at + offset;
        let check = ArmMotion {
            scenario: scene,
            target: request.object,
            goal: request.goal,
            arm: &arm.name,
            rest: &world.joints,
            path: &joint_path,
            grasp_at,
            release_at,
            held: held.map(|h| (h.grasped_box, h.grasp.as_slice())),
        };
        if let Some(hit) = timed(&mut timings.collision, || {
            check_motion(robot, geometry, &check)
        })
        .map_err(|e| Refusal::internal("collision", e))?
        {
            let mut replan = Replan::of(hit, offset, scene, &task, &motion, &arm.name);
            replan.lowered =
                motion.carry_height < carry_height(scene, request.object, &options.lift) - 1e-9;
            return Ok(Attempt::Collides(Box::new(replan)));
        }
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
            let mut timed_motion = timed(&mut timings.timing, || time_motion(&request))?;
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
                path: &positions,
                grasp_at,
                release_at,
                ..check
            };
            if let Some(hit) = timed(&mut timings.collision, || {
                check_motion(robot, geometry, &verify)
            })
            .map_err(|e| Refusal::internal("collision", e))?
            {
                let time_s = timed_motion.points[hit.index].time_from_start;
                return Err(collides(
                    &arm.name,
                    &hit.collision,
                    HitPlace::Trajectory { time_s },
                ));
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

/// What a sub-goal's next pass does differently after a collision.
#[derive(Debug, Default)]
struct Retry {
    /// Cells the arm collided over, blocked in the grid.
    blocked: Vec<Cell>,
    /// Index into [`GRASP_TURNS`]: how the tool is turned about its axis at
    /// every waypoint of the pass.
    turn: usize,
    /// Carry at the full height (the tallest thing on the table), not the
    /// height the route needs.
    full_height: bool,
}

/// Quarter turns of the tool tried in order after a hit where the hand
/// closes or opens: none, half a turn (a hand whose open finger sticks out
/// to one side then has it on the other), then the fingers across the
/// object's longer side both ways (open fingers that straddle a neighbour
/// or a box wall then lie along it), when that side fits the opening
/// ([`grasp_turns`]). The held object keeps its orientation on the table.
const GRASP_TURNS: [u8; 4] = [0, 2, 1, 3];

/// How many of [`GRASP_TURNS`] the object allows: all four when its longer
/// side plus the opening clearance fits the gripper's opening, else the
/// first two.
fn grasp_turns(world: &World, request: GridRequest, options: &PlanOptions) -> usize {
    let [mu, mv] = world.scene.metres_per_pixel();
    let b = world.scene.objects[request.object].bbox;
    let longer = (b.w * mu).max(b.l * mv);
    match world.gripper {
        Some(g) if longer + options.lift.opening_clearance <= g.max_opening => GRASP_TURNS.len(),
        _ => 2,
    }
}

/// The outcome of one pass through the stages.
enum Attempt {
    Planned(Box<SubgoalPlan>),
    Collides(Box<Replan>),
}

/// A collision the grid did not see, and the cell to block for the next pass.
struct Replan {
    /// The collision with the waypoint and phase where it happens.
    refusal: Refusal,
    /// The cell under the colliding waypoint, when it is a travel or carry
    /// waypoint over a cell that may be blocked (not the start, the target or
    /// the goal).
    replannable_cell: Option<Cell>,
    /// The hit is where the hand closes or opens on the object (approach,
    /// grasp, lift, release): turning the tool may avoid it.
    at_grasp: bool,
    /// The motion carried lower than the full height (the route's height).
    lowered: bool,
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
        arm: &str,
    ) -> Self {
        let grid = &task.grid;
        let at = hit
            .index
            .checked_sub(offset)
            .and_then(|i| motion.waypoint_of(i));
        let place = match at {
            Some((waypoint, phase)) => HitPlace::Waypoint { phase, waypoint },
            None if hit.index <= offset => HitPlace::ToFirstWaypoint,
            None => HitPlace::ReturningToPark,
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
            refusal: collides(arm, &hit.collision, place),
            replannable_cell: cell,
            at_grasp,
            lowered: false,
        }
    }
}

impl World {
    /// The scene after a planned sub-goal: the object rests on its spot in
    /// the goal box, the gripper is over it, the arm where its path ended
    /// (other arms stay where they are: the collision check sees them there).
    fn advance(&mut self, request: GridRequest, done: &SubgoalPlan) {
        self.held = None;
        self.gripper_px = done.release_px;
        self.gripper_height = None;
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
        self.gripper_height =
            start::tool_height_over(&self.scene, robot, &self.joints, self.gripper_px);
    }
}

/// Largest joint difference (rad or m) at which a solved configuration is
/// taken as the current one (IK converges to about 1e-9).
const SAME_CONFIGURATION: f64 = 1e-6;

/// The arm's way back to its park posture after its last waypoint, through
/// its home posture, in joint steps of at most 0.05 rad; empty for an arm
/// without a park posture.
fn return_to_park(arm: &afford_kinematics::Arm, rest: &[f64], path: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let Some(last) = path.last().filter(|_| !arm.park.is_empty()) else {
        return Vec::new();
    };
    let mut full = rest.to_vec();
    for &(i, v) in &arm.park {
        full[i] = v;
    }
    let park = arm.extract(&full);
    let mut out = joint_steps(last, &arm.home);
    out.extend(joint_steps(&arm.home, &park));
    out
}

/// The way from a parked arm to its path's first configuration, through its
/// home posture (straight in joint space from park, the arm could sweep the
/// robot's body); empty for an arm without a park posture. An arm that is
/// not parked takes the straight [`approach`] instead.
fn leave_park(arm: &afford_kinematics::Arm, start: &[f64], first: &[f64]) -> Vec<Vec<f64>> {
    if arm.park.is_empty() {
        return Vec::new();
    }
    let mut out = joint_steps(start, &arm.home);
    out.extend(joint_steps(&arm.home, first));
    out.pop();
    out
}

/// The way of an arm that is not parked from where it is to its path's
/// first configuration: straight in joint space, in steps of at most
/// 0.05 rad (so the timing stage's interpolant sees evenly spaced points,
/// not one long segment beside 1 cm ones), the first configuration excluded.
fn approach(start: &[f64], first: &[f64]) -> Vec<Vec<f64>> {
    let mut out = joint_steps(start, first);
    out.pop();
    out
}

/// Configurations from `a` (excluded) to `b` (included), straight in joint
/// space, no joint moving more than 0.05 rad per step.
fn joint_steps(a: &[f64], b: &[f64]) -> Vec<Vec<f64>> {
    let largest = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let steps = (largest / 0.05).ceil() as usize;
    (1..=steps)
        .map(|k| {
            a.iter()
                .zip(b)
                .map(|(x, y)| x + k as f64 / steps as f64 * (y - x))
                .collect()
        })
        .collect()
}

/// The lifted motion of an object already in the gripper: everything up
/// to the lift (travel, approach, grasp, lift) is dropped, so the motion
/// starts with the carry.
fn carry_on(motion: &mut LiftedMotion) {
    let carry = motion
        .waypoints
        .iter()
        .position(|w| matches!(w.phase, Phase::Carry | Phase::OverWall))
        .unwrap_or(0);
    motion.waypoints.drain(..carry);
}

/// The trajectory of a motion that starts holding: the close command the
/// timing stage put at t = 0 (and the rest it waited for it) is dropped.
fn drop_leading_close(motion: &mut TimedMotion) {
    let Some(close) = motion
        .gripper
        .iter()
        .position(|e| e.command == crate::trajectory::GripperCommand::Close)
    else {
        return;
    };
    let shift = motion.gripper.remove(close).end;
    motion.points.retain(|p| p.time_from_start >= shift - 1e-9);
    for p in &mut motion.points {
        p.time_from_start = (p.time_from_start - shift).max(0.0);
    }
    for e in &mut motion.gripper {
        e.start -= shift;
        e.end -= shift;
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
            .map(|r| r.spot)
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

/// The refusal of a collision `hit` of `arm` at `place`.
fn collides(arm: &str, hit: &Collision, place: HitPlace) -> Refusal {
    Refusal::Collides {
        arm: arm.to_string(),
        body: hit.body.clone(),
        other: hit.other.clone(),
        hit: hit.kind,
        place,
        clearance_m: hit.clearance,
        penetration_m: hit.penetration,
        margin_m: hit.margin,
        depth_m: hit.margin_violation.max(0.0),
    }
}

/// Why the oracle finds no plan, in terms a user can act on.
fn why_unsolvable(scene: &Scenario, request: GridRequest, opening: Option<[f64; 2]>) -> Refusal {
    let grid = StateGrid::build_placing(scene, request, opening);
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
    let grid = StateGrid::build_placing(&without_hands, request, opening);
    if oracle::optimal_length(&GridTask::new(grid)).is_some() {
        return Refusal::HandBlocksRoute { object, goal };
    }
    Refusal::NoRoute {
        object,
        goal,
        blocked_cells: 0,
    }
}
