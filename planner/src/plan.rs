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

use crate::clearance::{ArmMotion, FreeMoves, Leg, PathHit, check_motion, gripper_reach};
use crate::cql::{ContextualQLearner, LearnedPlan};
use crate::error::{FieldIssue, HitPlace, PlanError, Refusal, TransitFailure};
use crate::grid::{Cell, CellCode, GridRequest, Obstacles, StateGrid};
use crate::instruction::{Interpretation, SubGoal, work};
use crate::lift::{
    GripperReach, LiftRequest, LiftSettings, LiftedMotion, Phase, carry_height, grasp_pose, lift,
};
use crate::motion::{IK_STARTS, IkStart, solve_motions};
use crate::place::Room;
use crate::route_grid::routable_task;
use crate::scenario::{PixelBox, Scenario};
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
    /// The objects released into the same goal later in the chain that the
    /// spot leaves room for ([`Room::later`]); not serialised (the monitor
    /// chooses the same spot with them).
    #[serde(skip)]
    pub room_for: Vec<String>,
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
    /// What the grid painted as obstacles: left out for the paper's grid
    /// (every other object and goal), `sensitive` when the route passes
    /// over the rest ([`crate::discrete::route_grid`]).
    #[serde(skip_serializing_if = "Obstacles::is_all")]
    pub obstacles: Obstacles,
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
        self.options.validate()?;
        // A scenario built in code has not been through the file checks:
        // every size bound holds before any work starts.
        scenario.validate()?;
        start::check_stated_joints(scenario, &self.options.base_dir)?;
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
        options.validate()?;
        let Some(first_goal) = goals.first() else {
            return Err(PlanError::Unsolvable {
                reasons: vec!["no sub-goals to plan".to_string()],
                unsolved: Vec::new(),
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
            return Err(PlanError::Unsolvable {
                reasons,
                unsolved: plan.unsolved,
            });
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
        let mut outcomes: Vec<Result<SubgoalPlan, Refusal>> = Vec::new();
        let mut snapshots: Vec<Option<Snapshot>> = vec![None; goals.len()];
        // After a rewind to sub-goal j: the outcomes and the world as they
        // were, restored when j does not plan with its arm parking.
        let mut fallback: Option<Rewound> = None;
        while outcomes.len() < goals.len() {
            let k = outcomes.len();
            let goal = &goals[k];
            let request = request(&world.scene, goal, world.gripper_px);
            snapshots[k] = Some(world.snapshot());
            let later = later_in_goal(&world.scene, goals, k);
            let pass = Pass {
                world,
                goal,
                request,
                seed: subgoal_seed(self.options.seed, k),
                park: park[k],
                later: &later,
            };
            let refused = match self.plan_subgoal(pass, timings) {
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
                outcomes.push(Err(*refused.reason));
                continue;
            };
            let mut saved = outcomes.clone();
            saved.push(Err(*refused.reason));
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
                Err(refusal) => unsolved.push(UnsolvedSubgoal::new(goal, refusal)),
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
        outcomes: &[Result<SubgoalPlan, Refusal>],
        park: &[bool],
    ) -> Option<usize> {
        let robot = world.robot.as_ref()?;
        let j = outcomes.iter().rposition(|o| o.is_ok())?;
        let arm = outcomes[j].as_ref().ok()?.arm.as_ref()?;
        let arm = robot.arm(arm).ok()?;
        (!park[j] && !arm.park.is_empty() && !start::is_parked(arm, &world.joints)).then_some(j)
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
        let start_state = Some(JointState {
            joint_names: robot.joints().iter().map(|j| j.name.clone()).collect(),
            positions: from.joints.clone(),
        });
        world.robot = Some(robot);
        let planner = Planner::new(PlanOptions {
            until: Stage::Trajectory,
            ..self.options.clone()
        });
        let mut timings = StageTimings::default();
        let (subgoals, unsolved) = planner.plan_chain(&mut world, goals, &mut timings);
        Ok(Plan {
            scenario: scenario.name.clone().unwrap_or_default(),
            seed: self.options.seed,
            until: Stage::Trajectory,
            start_state,
            skipped: Vec::new(),
            subgoals,
            unsolved,
            timings,
        })
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
    fn plan_subgoal(&self, pass: Pass, timings: &mut StageTimings) -> Result<SubgoalPlan, Refused> {
        let (world, request) = (pass.world, pass.request);
        let mut retry = Retry::default();
        loop {
            let hit = match self.attempt(&pass, &retry, timings)? {
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
                _ => return Err(Refused::motion(hit.refusal)),
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
        // The arms that reach, cheapest first: the first whose whole motion
        // is free moves. When none is, the arms try again with their IK
        // started from their home posture, then from random postures
        // (other branches: an IK posture may fold into the body). A collision of
        // the cheapest goes back to the grid when no arm is free; else the
        // transits not found are the refusal.
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
                    ArmMotionOutcome::NoTransit(failure) => no_transit.push(failure),
                }
            }
            if free.is_some() {
                break;
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
        let held = world.held.as_ref().filter(|h| h.object == pass.goal.object);
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
            .map_err(|e| Refused::motion(Refusal::internal("collision", e)))
        };
        // An object already in the hand is no obstacle to it.
        let before = moves(match held {
            Some(_) => Leg::AfterRelease,
            None => Leg::BeforeGrasp,
        })?;
        let skip = timed(&mut timings.transit, || {
            leading_blocked(&before, motion, &choice.path.waypoints)
        })
        .map_err(|e| Refused::motion(Refusal::internal("collision", e)))?;
        let motion = LiftedMotion {
            waypoints: motion.waypoints[skip..].to_vec(),
            ..motion.clone()
        };
        let start = arm.extract(&world.joints);
        let mut waypoints = choice.path.waypoints[skip..].to_vec();
        // The route starts where the tool is: a first waypoint whose IK lands
        // on the current configuration is that configuration exactly.
        if let Some(q) = waypoints.first_mut()
            && q.iter()
                .zip(&start)
                .all(|(a, b)| (a - b).abs() <= SAME_CONFIGURATION)
        {
            q.clone_from(&start);
        }
        let first = waypoints.first().cloned().unwrap_or_else(|| start.clone());
        let stream = 2 * choice.arm_index;
        let mut lead =
            match self.transit(arm, &before, &start, &first, pass.seed, stream, timings)? {
                Ok(path) => path,
                Err(e) => {
                    return Ok(ArmMotionOutcome::NoTransit(TransitFailure {
                        arm: arm.name.clone(),
                        place: HitPlace::ToFirstWaypoint,
                        reason: e.to_string(),
                    }));
                }
            };
        // The transit ends on the first waypoint, which the IK path starts with.
        lead.pop();
        // joint_path[lead.len() + 1 + k] is tool waypoint k.
        let offset = lead.len();
        let mut joint_path: Vec<Vec<f64>> = std::iter::once(start)
            .chain(lead)
            .chain(waypoints)
            .collect();
        if pass.park && !arm.park.is_empty() {
            let after = moves(Leg::AfterRelease)?;
            let last = joint_path.last().cloned().unwrap_or_default();
            let parked = arm.extract(&start::parked_home(robot));
            match self.transit(arm, &after, &last, &parked, pass.seed, stream + 1, timings)? {
                Ok(path) => joint_path.extend(path),
                Err(e) => {
                    return Ok(ArmMotionOutcome::NoTransit(TransitFailure {
                        arm: arm.name.clone(),
                        place: HitPlace::ReturningToPark,
                        reason: e.to_string(),
                    }));
                }
            }
        }
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
        .map_err(|e| Refused::motion(Refusal::internal("collision", e)))?
        {
            let mut replan = Replan::of(hit, offset, scene, task, &motion, &arm.name);
            replan.lowered = motion.eased
                || motion.carry_height
                    < carry_height(scene, request.object, &self.options.lift) - 1e-9;
            return Ok(ArmMotionOutcome::Collides(Box::new(replan)));
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
            Err(TransitError::Check(e)) => Err(Refused::motion(Refusal::internal("collision", e))),
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
#[derive(Clone, Copy)]
struct Pass<'a> {
    world: &'a World,
    goal: &'a SubGoal,
    request: GridRequest,
    seed: u64,
    /// The arm returns to park at the end (when it has a park posture).
    park: bool,
    /// The objects the chain releases into the same goal later
    /// ([`later_in_goal`]).
    later: &'a [usize],
}

/// Why a sub-goal was not planned.
#[derive(Debug)]
struct Refused {
    /// Boxed: a refusal is large and `Refused` is every stage's `Err`.
    reason: Box<Refusal>,
    /// The arm's motion failed (joints or trajectory stage): another robot
    /// state (the previous arm parked) may plan it.
    motion: bool,
}

impl Refused {
    /// Refused before any arm moves (scene, grid, learner, lifting).
    fn early(reason: Refusal) -> Self {
        Self {
            reason: Box::new(reason),
            motion: false,
        }
    }

    fn motion(reason: Refusal) -> Self {
        Self {
            reason: Box::new(reason),
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
    NoTransit(TransitFailure),
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
    /// The motion carried lower than the full height (the route's height)
    /// or eased its turns over the target: the full-height fallback differs.
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

/// The sub-goal a chain went back to, and the outcomes and world before.
type Rewound = (usize, Vec<Result<SubgoalPlan, Refusal>>, Snapshot);

/// The part of the [`World`] a sub-goal changes, to plan it again.
#[derive(Clone)]
struct Snapshot {
    scene: Scenario,
    gripper_px: [f64; 2],
    gripper_height: Option<f64>,
    joints: Vec<f64>,
    held: Option<HeldObject>,
}

impl World {
    fn snapshot(&self) -> Snapshot {
        Snapshot {
            scene: self.scene.clone(),
            gripper_px: self.gripper_px,
            gripper_height: self.gripper_height,
            joints: self.joints.clone(),
            held: self.held.clone(),
        }
    }

    fn restore(&mut self, state: Snapshot) {
        self.scene = state.scene;
        self.gripper_px = state.gripper_px;
        self.gripper_height = state.gripper_height;
        self.joints = state.joints;
        self.held = state.held;
    }

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

/// What a release spot leaves room for: the grasp region's colliders about
/// the TCP, at least the open fingers (m, see
/// [`GripperReach::finger_half_extent`]), once the robot is known, and the
/// chain's `later` pieces for the same goal.
fn room<'a>(world: &World, later: &'a [usize]) -> Room<'a> {
    Room {
        opening: world.gripper.map(|g| g.finger_half_extent),
        later,
    }
}

/// The objects of `goals[k + 1..]` bound for `goals[k]`'s goal, in order:
/// the pieces its release spot leaves room for ([`Room::later`]).
fn later_in_goal(scene: &Scenario, goals: &[SubGoal], k: usize) -> Vec<usize> {
    goals[k + 1..]
        .iter()
        .filter(|g| g.goal == goals[k].goal)
        .filter_map(|g| scene.object_index(&g.object))
        .collect()
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
fn why_unsolvable(scene: &Scenario, request: GridRequest, room: Room) -> Refusal {
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
