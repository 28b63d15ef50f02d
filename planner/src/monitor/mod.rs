//! The valid-policy detector (the paper's third module, section IV.C;
//! experiments 2, 4 and 5) and the execution it steers.
//!
//! [`Monitor::observe`] takes each camera observation at its execution
//! time and decides ([`Verdict`]): it re-simulates the remaining discrete
//! policy of every sub-goal ahead on the newest state grid ([`policy`]: a
//! negative reward anywhere ahead is a trigger), re-checks the remaining
//! trajectory geometrically when a change comes near it ([`route`]), applies
//! speed-and-separation monitoring to the hands ([`separation`]) and looks
//! for new work for an "all" instruction ([`work`]). Changes that touch
//! none of these never trigger. The monitor also executes what it decides
//! ([`execute`]): the trajectory is followed under a speed override, so a
//! stop is a timed braking along the path within the joint limits, a
//! replan starts from where the robot came to rest (holding or not,
//! [`crate::Planner::plan_from`]) and everything already done is kept.
//! Between observations [`Monitor::advance`] steps at the controller rate;
//! the executed timeline is [`Monitor::executed`], the decisions
//! [`Monitor::events`].

pub mod belief;
pub mod brake;
mod decide;
pub mod detection;
mod drive;
pub mod execute;
mod interval;
pub mod policy;
mod ramp;
mod replan;
pub mod route;
pub mod separation;
mod state;
pub mod timeline;
pub mod track;
mod verdict;
pub mod work;

use std::time::Instant;

use afford_collision::RobotGeometry;
use afford_kinematics::RobotModel;
use serde::Serialize;

pub use verdict::{Event, Reason, Verdict};

use crate::clearance::gripper_reach;
use crate::error::PlanError;
use crate::instruction::SubGoal;
use crate::plan::{HeldObject, JointState, Plan, PlanOptions};
use crate::scenario::{Hand, MotionPhase, Observation, PixelBox, Scenario};
use crate::trajectory::TimedMotion;
use belief::{Change, Placed};
use detection::HandMemory;
use execute::Cursor;
use track::Track;

/// Longest wait for a hand to clear the way before the monitor aborts, s.
pub const MAX_WAIT_S: f64 = 60.0;

/// One executed sub-goal: the motion as it really ran (stops, waits and
/// replanned pieces included), times from `start_time`, in the shape of a
/// planned sub-goal so the independent check reads it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExecutedSubgoal {
    pub object: String,
    pub goal: String,
    pub arm: String,
    pub joint_names: Vec<String>,
    /// Execution time when the sub-goal began, s.
    pub start_time: f64,
    pub trajectory: TimedMotion,
    /// What the independent check of this sub-goal is run against (not
    /// serialised): the goals as believed when it ended, its object where
    /// the gripper took it from, and the other objects and the hands that
    /// stayed where they were from its start to its end. An element that
    /// came or moved meanwhile was checked by the monitor against the
    /// motion still ahead when it came ([`route`]), not against the motion
    /// already done, which it never met.
    #[serde(skip)]
    pub scene: Option<Scenario>,
    /// The scene believed when the sub-goal began (not serialised).
    #[serde(skip)]
    pub scene_at_start: Option<Scenario>,
    /// The scene believed after each change while the sub-goal ran, with
    /// its time from `start_time`, s (not serialised): what the physical
    /// replay of the sub-goal puts in the world when.
    #[serde(skip)]
    pub changes: Vec<(f64, Scenario)>,
    /// The execution stopped for good before the sub-goal's end (an abort):
    /// the robot braked to rest on its path and stays there. Serialised
    /// only when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub cut_short: bool,
}

/// How the execution stands.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    Running,
    /// Every sub-goal done.
    Completed,
    /// Stopped for good, with the reason.
    Aborted(Reason),
}

/// Where a released piece and its goal were when the gripper opened
/// (name, box each).
#[derive(Debug, Clone)]
struct ReleasedAt {
    object: (String, PixelBox),
    goal: (String, PixelBox),
}

/// A replan waiting to take over.
#[derive(Debug, Clone)]
enum Pending {
    /// Once the robot has braked to rest.
    AtRest(Plan),
    /// When the sub-goal under way ends.
    AtEnd(Plan),
}

/// The valid-policy detector and the execution it steers.
pub struct Monitor {
    options: PlanOptions,
    robot: RobotModel,
    geometry: RobotGeometry,
    opening: [f64; 2],
    dt: f64,
    scene: Scenario,
    plan: Plan,
    tracks: Vec<Track>,
    /// The scene the plan under way was made for (boxes within the
    /// detection tolerance of theirs here did not move).
    reference: Scenario,
    /// Target boxes the plan's grids were cut for.
    planned_boxes: Vec<PixelBox>,
    current: usize,
    cursor: Cursor,
    command: f64,
    clock: f64,
    /// The whole robot at the start of the sub-goal under way.
    joints: Vec<f64>,
    placed: Vec<Placed>,
    /// The piece of the sub-goal under way is placed (its gripper opened).
    placed_current: bool,
    /// Its box and its goal's box when it was released.
    released_at: Option<ReleasedAt>,
    done: Vec<String>,
    new_work: Vec<SubGoal>,
    held: Option<HeldObject>,
    pending: Option<Pending>,
    /// Trigger of the scene as last evaluated (re-evaluated on a change,
    /// a new plan or a new sub-goal).
    trigger: Option<Option<Verdict>>,
    /// Scene changes not yet evaluated.
    changes: Vec<Change>,
    /// The hands the detector lists and those it dropped within the hold.
    hands: HandMemory,
    waiting_since: Option<f64>,
    /// An abort under way: the robot brakes, then stops for good.
    aborting: Option<Reason>,
    status: Status,
    executed: Vec<ExecutedSubgoal>,
    events: Vec<Event>,
    /// Every hand list the detector delivered, with its time: the raw
    /// input an outside check measures the executed motion against.
    sightings: Vec<(f64, Vec<Hand>)>,
    last: &'static str,
}

impl Monitor {
    /// Follows `plan` (stage `trajectory`, as planned for `scenario` with
    /// `options`), from t = 0. `Err` when the robot cannot be loaded or the
    /// plan has no timed sub-goal.
    pub fn new(plan: Plan, scenario: &Scenario, options: &PlanOptions) -> Result<Self, PlanError> {
        let robot =
            RobotModel::load_with(&scenario.robot.model, &options.base_dir, &options.packages)
                .map_err(|e| PlanError::Robot(e.to_string()))?;
        let geometry = RobotGeometry::new(&robot).map_err(|e| PlanError::Robot(e.to_string()))?;
        let opening = gripper_reach(&robot, &geometry)
            .map_err(PlanError::Robot)?
            .finger_half_extent;
        let joints = plan
            .start_state
            .as_ref()
            .map(|s| s.positions.clone())
            .ok_or_else(|| PlanError::Robot("the plan has no start state".into()))?;
        if plan.subgoals.iter().any(|g| g.trajectory.is_none()) || plan.subgoals.is_empty() {
            return Err(PlanError::Robot(
                "the monitor follows timed plans (stage trajectory)".into(),
            ));
        }
        let mut monitor = Self {
            options: options.clone(),
            robot,
            geometry,
            opening,
            dt: 1.0 / options.timing.rate_hz,
            scene: scenario.clone(),
            reference: scenario.clone(),
            plan: Plan {
                subgoals: Vec::new(),
                ..plan.clone()
            },
            tracks: Vec::new(),
            planned_boxes: Vec::new(),
            current: 0,
            cursor: Cursor::START,
            command: 1.0,
            clock: 0.0,
            joints,
            placed: Vec::new(),
            placed_current: false,
            released_at: None,
            done: Vec::new(),
            new_work: Vec::new(),
            held: None,
            pending: None,
            trigger: None,
            changes: Vec::new(),
            hands: HandMemory::default(),
            waiting_since: None,
            aborting: None,
            status: Status::Running,
            executed: Vec::new(),
            events: Vec::new(),
            sightings: vec![(0.0, scenario.hands.clone())],
            last: "continue",
        };
        let hold = scenario.safety.detection.hand_hold_s;
        monitor.hands.update(Some(&scenario.hands), 0.0, hold);
        monitor.adopt(plan);
        monitor.cursor = Cursor::START;
        Ok(monitor)
    }

    /// Every hand list the detector delivered, `(time, hands)` in order,
    /// the scenario's own hands at 0: what was seen, not what the monitor
    /// believed (an outside check's input).
    pub fn sightings(&self) -> &[(f64, Vec<Hand>)] {
        &self.sightings
    }

    /// The execution clock, s.
    pub fn clock(&self) -> f64 {
        self.clock
    }

    pub fn status(&self) -> &Status {
        &self.status
    }

    /// The scene the monitor believes in now.
    pub fn scene(&self) -> &Scenario {
        &self.scene
    }

    /// The executed timeline so far, one entry per sub-goal begun.
    pub fn executed(&self) -> &[ExecutedSubgoal] {
        &self.executed
    }

    /// The decisions so far.
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    /// The whole robot's joint state at t = 0.
    pub fn start_state(&self) -> Option<&JointState> {
        self.plan.start_state.as_ref()
    }

    /// Where execution is: the sub-goal under way (0-based, in execution
    /// order), its phase and how far through it.
    pub fn position(&self) -> (usize, MotionPhase, f64) {
        let motion = self.motion();
        let (phase, fraction) = self.tracks[self.current].phase(self.cursor.s, motion.duration());
        (self.executed.len().saturating_sub(1), phase, fraction)
    }

    /// The controller period, s.
    pub fn period(&self) -> f64 {
        self.dt
    }

    /// Stops for good: the robot brakes to rest along its path.
    pub fn abort(&mut self, reason: Reason) {
        let verdict = Verdict::Abort { reason };
        self.act(&verdict);
        self.log(&verdict, &[], 0.0, None);
        while self.status == Status::Running {
            self.tick();
        }
    }

    /// Steps the execution at the controller rate until `t`. A hand the
    /// detector dropped stops counting when its hold ends, between
    /// observations too: the scene changes then and is decided on.
    pub fn advance(&mut self, t: f64) {
        while self.status == Status::Running && self.clock + 0.5 * self.dt < t {
            let hold = self.scene.safety.detection.hand_hold_s;
            if self
                .hands
                .next_expiry(hold)
                .is_some_and(|e| self.clock + 1e-9 >= e)
            {
                self.decide_on(&Observation::default());
            }
            if self.status == Status::Running {
                self.tick();
            }
        }
    }

    /// Takes `observation` at execution time `t` (the execution first runs
    /// on to `t`) and decides. An observation that lists nothing is a camera
    /// frame that saw the same scene: only the separation rule and the
    /// waiting are evaluated again.
    pub fn observe(&mut self, observation: &Observation, t: f64) -> Verdict {
        self.advance(t);
        self.decide_on(observation)
    }

    /// Takes `observation` now and decides.
    fn decide_on(&mut self, observation: &Observation) -> Verdict {
        let started = Instant::now();
        if self.status != Status::Running {
            return Verdict::Continue;
        }
        if let Some(hands) = &observation.hands {
            self.sightings.push((self.clock, hands.clone()));
        }
        let observation = self.with_held_hands(observation);
        let changes = match observation.is_unchanged() {
            true => Vec::new(),
            false => self.take(&observation),
        };
        let (verdict, replan_ms) = self.decide();
        let decision_us = started.elapsed().as_secs_f64() * 1e6;
        let decision_us = decision_us - replan_ms.unwrap_or(0.0) * 1e3;
        self.act(&verdict);
        self.log(&verdict, &changes, decision_us, replan_ms);
        verdict
    }

    /// `observation` with the hands to believe in ([`HandMemory`]): those
    /// listed, and those dropped within the hold time. Unchanged when the
    /// believed hands are those of the scene.
    fn with_held_hands(&mut self, observation: &Observation) -> Observation {
        let hold = self.scene.safety.detection.hand_hold_s;
        let believed = self
            .hands
            .update(observation.hands.as_deref(), self.clock, hold);
        let mut out = observation.clone();
        out.hands = match (&observation.hands, believed == self.scene.hands) {
            (None, true) => None,
            _ => Some(believed),
        };
        out
    }

    /// Applies an observation to the believed scene; the changes in words.
    fn take(&mut self, observation: &Observation) -> Vec<String> {
        let held = self.holds().map(|(n, b)| (n.to_string(), b));
        let known = belief::Known {
            placed: &self.placed,
            holds: held.as_ref().map(|(n, b)| (n.as_str(), *b)),
            reference: &self.reference,
            half_opening: self.opening[1],
        };
        let next = belief::observe(&self.scene, observation, &known);
        let changes = belief::changes(&self.scene, &next);
        if !changes.is_empty() {
            if let Some(e) = self.executed.last_mut() {
                e.changes.push((self.clock - e.start_time, next.clone()));
            }
            self.scene = next;
            self.trigger = None;
            self.changes.extend(changes.iter().cloned());
        }
        changes.iter().map(Change::to_string).collect()
    }
}
