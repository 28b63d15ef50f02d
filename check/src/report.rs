//! What the check finds: one [`Violation`] per problem, each with its class
//! (the vocabulary shared with `afford bench safety`), the sub-goal and a
//! message naming the joint or body, the time, the sample, the value and
//! the limit.

use serde::Serialize;

/// The kind of a violation (snake_case in JSON and in the CLI's lines).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ViolationClass {
    /// A robot body or the held object inside an obstacle.
    Penetration,
    /// Inside an obstacle's safety margin (not touching).
    Margin,
    /// Two robot bodies (or the held object and an arm link) touch.
    SelfCollision,
    /// A joint outside its position limits.
    Position,
    /// A joint faster than its velocity limit.
    Velocity,
    /// A joint accelerating beyond its limit.
    Acceleration,
    /// A joint's jerk (recomputed from positions and times) beyond its limit.
    Jerk,
    /// A sub-goal does not start where the previous one ended.
    Continuity,
    /// The plan does not start where the scenario says the robot is.
    Start,
    /// Not at rest where it must be: start, end, gripper events.
    Rest,
    /// Gripper events missing, repeated, out of order or off the samples.
    GripperEvents,
    /// The tool faster near a hand than the speed-and-separation rule allows.
    ToolSpeed,
    /// A body other than the fingers near the target before the grasp.
    TargetTouched,
    /// The released object does not rest wholly inside its goal, or overlaps a piece.
    Placement,
    /// The object is wider across the fingers than the gripper opens.
    GripperOpening,
    /// The file is not a well-formed plan for this scenario and robot.
    Format,
    /// The physical replay (`--physics`): a piece left outside its goal,
    /// another piece moved, a link touching a hand, the table or a piece.
    Physics,
}

impl ViolationClass {
    /// Every class, in declaration order.
    pub const ALL: [ViolationClass; 17] = [
        Self::Penetration,
        Self::Margin,
        Self::SelfCollision,
        Self::Position,
        Self::Velocity,
        Self::Acceleration,
        Self::Jerk,
        Self::Continuity,
        Self::Start,
        Self::Rest,
        Self::GripperEvents,
        Self::ToolSpeed,
        Self::TargetTouched,
        Self::Placement,
        Self::GripperOpening,
        Self::Format,
        Self::Physics,
    ];

    /// The snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Penetration => "penetration",
            Self::Margin => "margin",
            Self::SelfCollision => "self_collision",
            Self::Position => "position",
            Self::Velocity => "velocity",
            Self::Acceleration => "acceleration",
            Self::Jerk => "jerk",
            Self::Continuity => "continuity",
            Self::Start => "start",
            Self::Rest => "rest",
            Self::GripperEvents => "gripper_events",
            Self::ToolSpeed => "tool_speed",
            Self::TargetTouched => "target_touched",
            Self::Placement => "placement",
            Self::GripperOpening => "gripper_opening",
            Self::Format => "format",
            Self::Physics => "physics",
        }
    }
}

impl std::fmt::Display for ViolationClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One problem found. JSON: `{"class", "subgoal", "message"}` and, where
/// the class knows them, the fields of [`ViolationData`] beside them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Violation {
    pub class: ViolationClass,
    /// Index of the sub-goal in the plan; `None` for the plan as a whole.
    pub subgoal: Option<usize>,
    pub message: String,
    #[serde(flatten)]
    pub data: ViolationData,
}

/// What a program needs to act on a violation without parsing its message:
/// where (seconds into the sub-goal's trajectory and the sample), what (the
/// joint, or the robot body and what it came near) and by how much. A field
/// is absent (`None`, left out of JSON) when the class does not know it.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ViolationData {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joint: Option<String>,
    /// Robot body: link name (`link#k` for its k-th collider) or `held:<object>`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    /// The obstacle, piece or other robot body.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other: Option<String>,
    /// Seconds from the start of the sub-goal's trajectory, at the worst case.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample: Option<usize>,
    /// Signed distance between the shapes at the worst case, m (< 0: inside).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance_m: Option<f64>,
    /// The distance that had to be kept, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin_m: Option<f64>,
    /// How many cases the one violation stands for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cases: Option<usize>,
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.subgoal {
            Some(k) => write!(f, "{} sub-goal {k}: {}", self.class, self.message),
            None => write!(f, "{} plan: {}", self.class, self.message),
        }
    }
}

/// Everything the check found; empty when the plan passes.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Report {
    pub violations: Vec<Violation>,
}

impl Report {
    /// True when nothing was found.
    pub fn passed(&self) -> bool {
        self.violations.is_empty()
    }

    /// Violations of one class.
    pub fn of(&self, class: ViolationClass) -> impl Iterator<Item = &Violation> {
        self.violations.iter().filter(move |v| v.class == class)
    }

    pub(crate) fn push(&mut self, class: ViolationClass, subgoal: Option<usize>, message: String) {
        self.push_with(class, subgoal, message, ViolationData::default());
    }

    pub(crate) fn push_with(
        &mut self,
        class: ViolationClass,
        subgoal: Option<usize>,
        message: String,
        data: ViolationData,
    ) {
        self.violations.push(Violation {
            class,
            subgoal,
            message,
            data,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_names_match_their_json() {
        for class in ViolationClass::ALL {
            let json = serde_json::to_string(&class).unwrap();
            assert_eq!(json, format!("\"{}\"", class.name()));
        }
    }
}
