//! The observation timeline of a scenario (format 1, optional): what the
//! overhead camera sees while the plan executes. Each entry happens at an
//! execution time (`at`, seconds) or at a point of the plan (`when`: a
//! sub-goal, a phase of its motion and a fraction of that phase, so a
//! scripted example keeps its meaning when trajectories get faster), and
//! replaces the element lists it names (`objects`, `goals`, `hands`);
//! elements not listed stay as they were.

use serde::{Deserialize, Serialize};

use super::{Goal, Hand, Object, Scenario};

/// One camera observation during execution.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Observation {
    /// Execution time, seconds from the start of the run (≥ 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<f64>,
    /// Or the point of the plan where it happens.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub when: Option<PlanPoint>,
    /// Every object on the table now, replacing the list.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub objects: Option<Vec<Object>>,
    /// Every goal now, replacing the list.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goals: Option<Vec<Goal>>,
    /// Every hand now, replacing the list (`[]`: the hands left).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hands: Option<Vec<Hand>>,
}

/// A point of the executed plan: sub-goal `subgoal` (0-based, in execution
/// order), `fraction` (0–1) of the way through its `phase`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanPoint {
    pub subgoal: usize,
    pub phase: MotionPhase,
    #[serde(default)]
    pub fraction: f64,
}

/// The phases of one sub-goal's timed motion, split by its gripper events,
/// in the order they happen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionPhase {
    /// From the start to the gripper's close command.
    Travel,
    /// While the gripper closes.
    Grasp,
    /// From closed to the open command: the object is held.
    Carry,
    /// While the gripper opens.
    Release,
    /// From open to the end of the sub-goal.
    Retreat,
}

impl Observation {
    /// True when the entry changes nothing (a camera frame that saw the
    /// same scene).
    pub fn is_unchanged(&self) -> bool {
        self.objects.is_none() && self.goals.is_none() && self.hands.is_none()
    }
}

impl Scenario {
    /// The scene after `observation`: its listed element lists replace these.
    pub fn observed(&self, observation: &Observation) -> Scenario {
        let mut scene = self.clone();
        scene.apply(observation);
        scene
    }

    /// Replaces the element lists `observation` lists, in place.
    pub fn apply(&mut self, observation: &Observation) {
        if let Some(objects) = &observation.objects {
            self.objects = objects.clone();
        }
        if let Some(goals) = &observation.goals {
            self.goals = goals.clone();
        }
        if let Some(hands) = &observation.hands {
            self.hands = hands.clone();
        }
    }
}
