//! Why one sub-goal could not be planned ([`Refusal`]): one variant per
//! kind with its data, the message a person reads (`Display`) and the JSON
//! form with that message ([`Explained`]).

use std::fmt;

use afford_collision::HitKind;
use afford_kinematics::IkFailure;
use serde::Serialize;

use crate::lift::Phase;
use crate::timing::{SolverOutcome, TimingError, TimingStatus, sample::LimitKind};

/// Why one sub-goal could not be planned: one variant per kind, with the
/// data a robot stack branches on; `Display` is the message a person reads.
/// JSON: `{"kind": "goal_full", "goal": "left box", ...}` (see
/// [`Explained`] for the form with the message). Lengths are metres
/// (`_m`), times seconds (`_s`), angles radians (`_rad`); a place on the
/// motion is a [`HitPlace`].
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Refusal {
    /// A hand's safety perimeter covers the object to move.
    #[error("a hand covers {object}: wait for the hand to move")]
    HandCoversTarget { object: String },
    /// The robot, where it stands, is inside a hand's safety perimeter (or
    /// the hands cover every cell of the grid): no motion keeps the margin.
    #[error("a hand's perimeter covers the gripper: wait for the hand to move")]
    HandCoversGripper,
    /// Without the hands a route exists; with them none does.
    #[error("a hand blocks every route from the gripper to {object} and on to the {goal}")]
    HandBlocksRoute { object: String, goal: String },
    /// No free route through the grid. `blocked_cells`: cells blocked
    /// because the arm collided over them on earlier passes (0 when the
    /// scene itself leaves no route).
    #[error("{}", no_route(object, goal, *blocked_cells))]
    NoRoute {
        object: String,
        goal: String,
        blocked_cells: usize,
    },
    /// Every free spot in the goal lies under a safety perimeter.
    #[error("safety perimeters cover the whole {goal}")]
    PerimetersCoverGoal { goal: String },
    /// The pieces already in the goal leave no spot for this one.
    #[error("{goal} is full")]
    GoalFull { goal: String },
    /// The object's footprint is larger than the goal's inside.
    #[error(
        "{object} ({:.3} m x {:.3} m) does not fit inside the inner walls of the goal '{goal}' ({:.3} m x {:.3} m, {clearance_m} m clearance)",
        object_m[0], object_m[1], inner_m[0], inner_m[1]
    )]
    DoesNotFitGoal {
        object: String,
        goal: String,
        /// Footprint along the image's u and v axes.
        object_m: [f64; 2],
        /// Inside of the goal's walls along u and v.
        inner_m: [f64; 2],
        /// Kept from each wall.
        clearance_m: f64,
    },
    /// The object's narrower side plus the clearance exceeds the opening.
    #[error(
        "{object} is {width_m:.3} m wide across its narrower side ({:.3} m with {clearance_m:.3} m clearance); the gripper opens {opening_m:.3} m",
        width_m + clearance_m
    )]
    GripperTooNarrow {
        object: String,
        width_m: f64,
        clearance_m: f64,
        opening_m: f64,
    },
    /// With the palm clear of the top, the fingers hold too little of it.
    #[error(
        "{object} is {height_m:.3} m tall: with the palm {palm_gap_m:.3} m above its top the fingers ({finger_length_m:.3} m long) reach {:.1} mm below it, less than half its height or {:.1} mm",
        grip_depth_m * 1e3, min_grip_depth_m * 1e3
    )]
    TooTallForFingers {
        object: String,
        height_m: f64,
        palm_gap_m: f64,
        finger_length_m: f64,
        grip_depth_m: f64,
        min_grip_depth_m: f64,
    },
    /// Contextual Q-learning ran out of training steps (a route exists).
    #[error("the learner found no plan within {training_steps} training steps")]
    LearnerBudget { training_steps: usize },
    /// No arm reaches every tool waypoint; each arm's first failure.
    #[error("{}", arm_failures(arms))]
    Unreachable { arms: Vec<ArmFailure> },
    /// Every arm reaches every waypoint only with a joint beyond its limit.
    #[error("{}", arm_failures(arms))]
    JointLimit { arms: Vec<ArmFailure> },
    /// The motion hits something, or enters its safety perimeter, after
    /// every re-plan.
    #[error("{}", collision_message(self))]
    Collides {
        arm: String,
        /// Robot body: link name (`link#k` for its k-th collider) or `held:<object>`.
        body: String,
        /// Obstacle name, or the other robot body.
        other: String,
        hit: HitKind,
        place: HitPlace,
        /// Distance left to the real shape at the deepest point (0 when touching).
        clearance_m: f64,
        penetration_m: f64,
        /// The obstacle's safety perimeter (0 for the robot itself).
        margin_m: f64,
        /// How far inside the perimeter (≥ 0).
        depth_m: f64,
    },
    /// No arm found a collision-free transit (out of park, between
    /// sub-goals, back to park) within the transit planner's budget; each
    /// arm's failed transit, for every IK start tried.
    #[error("no collision-free transit: {}", transit_failures(arms))]
    NoTransit { arms: Vec<TransitFailure> },
    /// The time-optimal program found no motion along the joint path.
    #[error("timing failed: {}", TimingStatus::SolverStopped { outcome: *outcome })]
    TimingSolver { outcome: SolverOutcome },
    /// A sample of the timed motion breaks a limit; nothing is emitted.
    #[error("timing failed: the sampled motion breaks the {} limit{} at sample {sample} of the piece ({:.4} > {:.4})",
        quantity_name(*quantity),
        joint.as_deref().map(|j| format!(" of joint '{j}'")).unwrap_or_default(),
        value.abs(), limit)]
    TimingLimit {
        quantity: LimitKind,
        sample: usize,
        /// The joint, `None` for the tool speed or deviation.
        joint: Option<String>,
        value: f64,
        limit: f64,
    },
    /// The motion would take more samples than a trajectory may hold.
    #[error(
        "the motion would last {duration_s:.1} s, {samples:.0} samples at {rate_hz} Hz; at most {} samples are allowed (slow joint limits or crawling near a hand; lower the rate or move the hand)",
        crate::timing::MAX_SAMPLES
    )]
    TooSlow {
        duration_s: f64,
        rate_hz: f64,
        samples: f64,
    },
    /// The path passes a hand closer than the protective separation
    /// distance while the tool may not crawl (`min_tool_speed_m_s` = 0).
    #[error(
        "the path passes {distance_m:.3} m from a hand, inside the protective separation distance {required_m:.3} m, and min_tool_speed_m_s is 0"
    )]
    InsideProtectiveDistance { distance_m: f64, required_m: f64 },
    /// A stage could not run on what an earlier stage produced (a defect
    /// of afford, never of the input).
    #[error("internal error in the {stage} stage: {message}")]
    Internal { stage: String, message: String },
}

/// One arm's first unreachable tool waypoint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArmFailure {
    pub arm: String,
    /// Index of the tool waypoint.
    pub waypoint: usize,
    /// What the robot does on the way to it.
    pub phase: Option<Phase>,
    pub cause: IkFailure,
}

/// One arm's transit that the transit planner did not find.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransitFailure {
    pub arm: String,
    /// [`HitPlace::ToFirstWaypoint`] or [`HitPlace::ReturningToPark`].
    pub place: HitPlace,
    /// Why, in words (the search's budget).
    pub reason: String,
}

/// Where on a sub-goal's motion a collision is.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "during", rename_all = "snake_case")]
pub enum HitPlace {
    /// At or on the way to tool waypoint `waypoint` (see the plan's
    /// `waypoints`), in phase `phase`.
    Waypoint { phase: Phase, waypoint: usize },
    /// On the way from the arm's start to the first tool waypoint.
    ToFirstWaypoint,
    /// After the last waypoint, on the way back to the park posture.
    ReturningToPark,
    /// On the timed trajectory, `time_s` seconds into the sub-goal.
    Trajectory { time_s: f64 },
}

impl fmt::Display for HitPlace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Waypoint { phase, waypoint } => {
                write!(f, "at {} waypoint {waypoint}", phase_name(*phase))
            }
            Self::ToFirstWaypoint => write!(f, "on the way to the first waypoint"),
            Self::ReturningToPark => write!(f, "returning to the park posture"),
            Self::Trajectory { time_s } => write!(f, "{time_s:.3} s into the timed trajectory"),
        }
    }
}

/// A phase in words, `over wall` for `OverWall`.
pub fn phase_name(phase: Phase) -> &'static str {
    match phase {
        Phase::Start => "start",
        Phase::Travel => "travel",
        Phase::Approach => "approach",
        Phase::Grasp => "grasp",
        Phase::Lift => "lift",
        Phase::Carry => "carry",
        Phase::OverWall => "over-wall",
        Phase::Release => "release",
        Phase::Retreat => "retreat",
    }
}

impl Refusal {
    /// The snake_case kind, as in JSON.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::HandCoversTarget { .. } => "hand_covers_target",
            Self::HandCoversGripper => "hand_covers_gripper",
            Self::HandBlocksRoute { .. } => "hand_blocks_route",
            Self::NoRoute { .. } => "no_route",
            Self::PerimetersCoverGoal { .. } => "perimeters_cover_goal",
            Self::GoalFull { .. } => "goal_full",
            Self::DoesNotFitGoal { .. } => "does_not_fit_goal",
            Self::GripperTooNarrow { .. } => "gripper_too_narrow",
            Self::TooTallForFingers { .. } => "too_tall_for_fingers",
            Self::LearnerBudget { .. } => "learner_budget",
            Self::Unreachable { .. } => "unreachable",
            Self::JointLimit { .. } => "joint_limit",
            Self::Collides { .. } => "collides",
            Self::NoTransit { .. } => "no_transit",
            Self::TimingSolver { .. } => "timing_solver",
            Self::TimingLimit { .. } => "timing_limit",
            Self::TooSlow { .. } => "too_slow",
            Self::InsideProtectiveDistance { .. } => "inside_protective_distance",
            Self::Internal { .. } => "internal",
        }
    }

    /// Every kind [`Refusal::kind`] returns, in declaration order.
    pub const KINDS: [&'static str; 19] = [
        "hand_covers_target",
        "hand_covers_gripper",
        "hand_blocks_route",
        "no_route",
        "perimeters_cover_goal",
        "goal_full",
        "does_not_fit_goal",
        "gripper_too_narrow",
        "too_tall_for_fingers",
        "learner_budget",
        "unreachable",
        "joint_limit",
        "collides",
        "no_transit",
        "timing_solver",
        "timing_limit",
        "too_slow",
        "inside_protective_distance",
        "internal",
    ];

    /// The refusal of a failed timing status (`Solved` is no refusal and
    /// maps to `Internal`); `joint_names` names the arm's joints by index.
    pub fn from_timing(status: &TimingStatus, joint_names: &[String]) -> Self {
        match status {
            TimingStatus::SolverStopped { outcome } => Self::TimingSolver { outcome: *outcome },
            TimingStatus::LimitViolated { violation: v } => Self::TimingLimit {
                quantity: v.kind,
                sample: v.sample,
                joint: match v.kind {
                    LimitKind::ToolSpeed | LimitKind::ToolDeviation => None,
                    _ => joint_names.get(v.joint).cloned(),
                },
                value: v.value,
                limit: v.limit,
            },
            other => Self::internal("timing", format!("no trajectory although {other}")),
        }
    }

    /// The refusal of arms that reach no path: `JointLimit` when every
    /// arm's failure is a joint limit, else `Unreachable`.
    pub fn unreachable(arms: Vec<ArmFailure>) -> Self {
        let limits = arms
            .iter()
            .all(|a| matches!(a.cause, IkFailure::JointLimit { .. }));
        match limits && !arms.is_empty() {
            true => Self::JointLimit { arms },
            false => Self::Unreachable { arms },
        }
    }

    pub fn internal(stage: &str, message: impl fmt::Display) -> Self {
        Self::Internal {
            stage: stage.to_string(),
            message: message.to_string(),
        }
    }

    /// The refusal with its message, for JSON.
    pub fn explained(&self) -> Explained<'_> {
        Explained {
            refusal: self,
            message: self.to_string(),
        }
    }
}

impl From<TimingError> for Refusal {
    fn from(e: TimingError) -> Self {
        match e {
            TimingError::TooManySamples {
                duration_s,
                rate_hz,
                samples,
            } => Self::TooSlow {
                duration_s,
                rate_hz,
                samples,
            },
            TimingError::InsideProtectiveDistance {
                distance_m,
                required_m,
                ..
            } => Self::InsideProtectiveDistance {
                distance_m,
                required_m,
            },
            other => Self::internal("timing", other),
        }
    }
}

/// A refusal and its message: JSON `{"kind": ..., ...fields, "message": ...}`.
#[derive(Debug, Serialize)]
pub struct Explained<'a> {
    #[serde(flatten)]
    pub refusal: &'a Refusal,
    pub message: String,
}

/// Serialises a refusal with its message ([`Explained`]).
pub fn serialize_explained<S: serde::Serializer>(r: &Refusal, s: S) -> Result<S::Ok, S::Error> {
    r.explained().serialize(s)
}

fn no_route(object: &str, goal: &str, blocked_cells: usize) -> String {
    match blocked_cells {
        0 => format!("no free route from the gripper to {object} and on to the {goal}"),
        1 => "no route is left once the cell the arm collides over is blocked".to_string(),
        n => format!("no route is left once the {n} cells the arm collides over are blocked"),
    }
}

fn arm_failures(arms: &[ArmFailure]) -> String {
    if arms.is_empty() {
        return "the robot has no arm".to_string();
    }
    arms.iter()
        .map(|a| {
            let phase = a.phase.map(|p| format!("{} ", phase_name(p)));
            format!(
                "{}waypoint {} is out of reach of the arm '{}': {}",
                phase.unwrap_or_default(),
                a.waypoint,
                a.arm,
                a.cause
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn transit_failures(arms: &[TransitFailure]) -> String {
    arms.iter()
        .map(|a| format!("arm '{}' {}: {}", a.arm, a.place, a.reason))
        .collect::<Vec<_>>()
        .join("; ")
}

fn quantity_name(q: LimitKind) -> &'static str {
    match q {
        LimitKind::Position => "joint position",
        LimitKind::ToolDeviation => "tool-path deviation",
        LimitKind::Velocity => "joint velocity",
        LimitKind::Acceleration => "joint acceleration",
        LimitKind::ToolSpeed => "tool speed",
        LimitKind::Jerk => "joint jerk",
    }
}

fn collision_message(r: &Refusal) -> String {
    let Refusal::Collides {
        arm,
        body,
        other,
        hit,
        place,
        clearance_m,
        penetration_m,
        margin_m,
        depth_m,
    } = r
    else {
        return String::new();
    };
    let mm = |m: &f64| m * 1e3;
    let what = match hit {
        HitKind::Contact => format!("hits {other} (penetration {:.1} mm)", mm(penetration_m)),
        HitKind::SelfCollision => format!(
            "hits the robot's own {other} (penetration {:.1} mm)",
            mm(penetration_m)
        ),
        HitKind::Perimeter if *depth_m > 0.0 => format!(
            "comes {:.1} mm inside the {:.1} mm safety perimeter of {other} ({:.1} mm from it)",
            mm(depth_m),
            mm(margin_m),
            mm(clearance_m)
        ),
        HitKind::Perimeter => format!(
            "reaches the {:.1} mm safety perimeter of {other} ({:.1} mm from it)",
            mm(margin_m),
            mm(clearance_m)
        ),
    };
    format!("the motion of the arm '{arm}' collides {place}: {body} {what}")
}

#[cfg(test)]
mod tests;
