//! What the planner is given and what it returns: the stage to stop at
//! ([`Stage`]), the options ([`PlanOptions`], every default written once),
//! the plan of a whole instruction ([`Plan`]) and of each sub-goal
//! ([`SubgoalPlan`]), the state it may start from mid-execution, and the
//! time spent in each stage ([`StageTimings`]).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use afford_kinematics::PathSettings;

use serde::{Deserialize, Serialize};

use crate::error::{FieldIssue, PlanError, Refusal, UnsolvedSubgoal};
use crate::grid::Obstacles;
use crate::instruction::SubGoal;
use crate::lift::{LiftSettings, LiftedMotion};
use crate::scenario::PixelBox;
use crate::task::Action;
use crate::timing::TimingSettings;
use crate::trajectory::TimedMotion;
use crate::transit::TransitSettings;

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
    /// Most arm motions (an arm's IK path, its transits and their collision
    /// check) a sub-goal may try over all its passes before its last
    /// collision is the refusal: the bound on a refusal's time.
    pub max_arm_motions: usize,
    /// Folder that a relative `robot.model` path starts from. The rule, the
    /// same in the library and the CLI: a scenario read from a file resolves
    /// it against the file's folder ([`PlanOptions::for_scenario_file`],
    /// what `afford` does); a scenario built in code against `base_dir`,
    /// by default the current directory.
    pub base_dir: PathBuf,
    /// Where `package://` collision meshes of a robot description are
    /// looked for (the caller's folders, then `ROS_PACKAGE_PATH`, …; see
    /// [`afford_kinematics::PackagePaths`]).
    pub packages: afford_kinematics::PackagePaths,
}

/// Most re-plans a sub-goal may take ([`PlanOptions::max_replans`]).
pub const MAX_REPLANS: usize = 64;

/// Largest [`PlanOptions::max_arm_motions`].
pub const MAX_ARM_MOTIONS: usize = 256;

/// Largest clearance or step of [`LiftSettings`], m.
pub(super) const MAX_LIFT_LENGTH_M: f64 = 1.0;

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
        if !(1..=MAX_ARM_MOTIONS).contains(&self.max_arm_motions) {
            issues.push(FieldIssue::new(
                "max_arm_motions",
                format!(
                    "must be between 1 and {MAX_ARM_MOTIONS}, got {}",
                    self.max_arm_motions
                ),
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
            max_arm_motions: 20,
            base_dir: PathBuf::from("."),
            packages: afford_kinematics::PackagePaths::new(Vec::new()),
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
    /// Wall time of each sub-goal, in the instruction's order: every
    /// attempt at it (a re-plan after a rewind included), success or
    /// refusal.
    pub per_subgoal: Vec<Duration>,
}

/// Runs `f` and adds its wall time to `slot`.
pub(super) fn timed<T>(slot: &mut Duration, f: impl FnOnce() -> T) -> T {
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
