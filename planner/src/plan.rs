//! The planning pipeline, a straight run of named, timed stages: instruction
//! → sub-goals → per sub-goal a state grid → Contextual Q-learning → a
//! verified grid plan → tool waypoints, with the scene
//! updated after each sub-goal as the camera would see it (the object in its
//! goal, the gripper where it released). A sub-goal that cannot be solved is
//! reported by name with the reason while the others still plan.
//!
//! Here: the entry points. The options and outputs are in `types`, the
//! world carried between sub-goals in `world`, the sub-goal chain in
//! `chain`, one attempt at a sub-goal in `attempt`, the arm's motion and the
//! transits in `arm`.

use afford_collision::RobotGeometry;
use afford_kinematics::RobotModel;

use crate::clearance::gripper_reach;
use crate::error::PlanError;
pub use crate::error::UnsolvedSubgoal;
use crate::instruction::{Interpretation, SubGoal, work};
use crate::scenario::Scenario;
use crate::start::{self, FirstSubgoal, StartState};
use world::World;

mod arm;
mod attempt;
mod chain;
mod types;
mod world;

use types::timed;
pub use types::{
    GridInfo, HeldObject, JointState, MAX_REPLANS, MidExecution, Plan, PlanOptions, Planner, Stage,
    StageTimings, SubgoalPlan,
};
pub use world::subgoal_seed;

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
        start::check_stated_joints(scenario, &self.options.base_dir, &self.options.packages)?;
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
                subgoal_times: Vec::new(),
            });
        };
        let spec = &scenario.robot;
        let needs_robot =
            options.until >= Stage::Waypoints || spec.start.is_none() || spec.joints.is_some();
        let robot = match needs_robot {
            true => Some(
                RobotModel::load_with(&spec.model, &options.base_dir, &options.packages)
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
                subgoal_times: plan.timings.per_subgoal,
            });
        }
        Ok(plan)
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
        let robot = RobotModel::load_with(
            &scenario.robot.model,
            &self.options.base_dir,
            &self.options.packages,
        )
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
}

/// Plans `scenario` with `options`: `Planner::new(options).plan(scenario)`.
pub fn plan(scenario: &Scenario, options: &PlanOptions) -> Result<Plan, PlanError> {
    Planner::new(options.clone()).plan(scenario)
}
