//! What the monitor decides, why, and the event log entry of a decision.

use serde::Serialize;

use crate::instruction::SubGoal;
use crate::plan::Plan;

/// The monitor's decision for one observation.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Nothing that matters changed: go on as planned.
    Continue,
    /// Speed and separation: go on at `scale` (0–1) of the planned speed.
    Slow { scale: f64 },
    /// Speed and separation: a protective stop; the robot brakes along its
    /// path and resumes when the hand is back outside the perimeter.
    Stop,
    /// A hand blocks the remaining way: brake, ask the person to move and
    /// resume the same plan when the way is clear.
    Wait { reason: Reason },
    /// The plan no longer fits the scene: `plan` does the rest, from where
    /// the robot comes to rest (braking now for the sub-goal under way, or
    /// at its end when a later sub-goal is affected).
    Replan { plan: Box<Plan>, reason: Reason },
    /// The instruction asked for all pieces of a kind and new ones came:
    /// they are done after the plan in hand.
    NewWork { subgoals: Vec<SubGoal> },
    /// Nothing can be done: the robot brakes to rest and stops.
    Abort { reason: Reason },
}

impl Verdict {
    /// The verdict's name as in the event log.
    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Continue => "continue",
            Verdict::Slow { .. } => "slow",
            Verdict::Stop => "stop",
            Verdict::Wait { .. } => "wait",
            Verdict::Replan { .. } => "replan",
            Verdict::NewWork { .. } => "new_work",
            Verdict::Abort { .. } => "abort",
        }
    }

    /// The reason, for the verdicts that have one.
    pub fn reason(&self) -> Option<&Reason> {
        match self {
            Verdict::Wait { reason }
            | Verdict::Replan { reason, .. }
            | Verdict::Abort { reason } => Some(reason),
            _ => None,
        }
    }
}

/// Why the monitor waits, replans or aborts.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Reason {
    /// The remaining policy enters a hand's cell, or the remaining motion
    /// comes within a hand's perimeter.
    HandOnRoute { hand: String, subgoal: usize },
    /// The target is not where the plan grasps it.
    TargetMoved { object: String, subgoal: usize },
    /// The goal is not where the plan drops the object.
    GoalMoved { goal: String, subgoal: usize },
    /// Something new is on the remaining route.
    Blocked { by: String, subgoal: usize },
    /// The target left the scene.
    TargetGone { object: String },
    /// The goal left the scene.
    GoalGone { goal: String },
    /// A hand kept the way blocked longer than the monitor waits.
    WaitedTooLong { hand: String, seconds: f64 },
    /// Replanning found no plan.
    NoPlan { message: String },
}

impl std::fmt::Display for Reason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Reason::HandOnRoute { hand, subgoal } => write!(
                f,
                "{hand} is on the remaining route of sub-goal {subgoal}: please move your hand"
            ),
            Reason::TargetMoved { object, subgoal } => {
                write!(f, "{object} moved (sub-goal {subgoal})")
            }
            Reason::GoalMoved { goal, subgoal } => write!(
                f,
                "{goal} moved: the drop of sub-goal {subgoal} would miss it"
            ),
            Reason::Blocked { by, subgoal } => {
                write!(f, "{by} blocks the remaining route of sub-goal {subgoal}")
            }
            Reason::TargetGone { object } => write!(f, "{object} is no longer on the table"),
            Reason::GoalGone { goal } => write!(f, "{goal} is no longer on the table"),
            Reason::WaitedTooLong { hand, seconds } => {
                write!(f, "{hand} kept the way blocked for {seconds:.0} s")
            }
            Reason::NoPlan { message } => write!(f, "no plan from here: {message}"),
        }
    }
}

/// One entry of the event log: a decision that changed what the robot does,
/// or a change of the scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Event {
    /// Execution time, s.
    pub time: f64,
    /// What changed in the scene (empty: a decision on an unchanged scene,
    /// e.g. the robot reached a hand that was already there).
    pub changes: Vec<String>,
    /// The verdict's name ([`Verdict::name`]).
    pub verdict: &'static str,
    /// The verdict brakes the robot to rest now (a stop, a wait, an abort,
    /// a replan from where the robot stops); serialised only when true.
    /// A replan from the end of the sub-goal under way does not brake.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub brakes: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<Reason>,
    /// The reason in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// `Slow`: the speed scale.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// `NewWork`: the new sub-goals, "object → goal".
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub subgoals: Vec<String>,
    /// Wall-clock time of the decision, µs (not deterministic; left out of
    /// serialised output unless asked for).
    #[serde(skip)]
    pub decision_us: f64,
    /// Wall-clock time of the replan, ms (ditto).
    #[serde(skip)]
    pub replan_ms: Option<f64>,
}
