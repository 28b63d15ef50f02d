//! Refusal kinds for the safety campaign's counts: the typed kind of each
//! refused sub-goal ([`Refusal::kind`]), plus, for a plan refused before any
//! sub-goal ran, `robot_state` (the robot's start does not fit it, e.g. no
//! arm reaches `robot.start`), `instruction` and `other`.

use afford_planner::error::{PlanError, Refusal};

/// Every kind the campaign counts, in report order.
pub const REFUSAL_KINDS: [&str; Refusal::KINDS.len() + 3] = {
    let mut out = [""; Refusal::KINDS.len() + 3];
    let mut k = 0;
    while k < Refusal::KINDS.len() {
        out[k] = Refusal::KINDS[k];
        k += 1;
    }
    out[k] = "robot_state";
    out[k + 1] = "instruction";
    out[k + 2] = "other";
    out
};

/// The refusals of a plan that failed as a whole, as (kind, "object →
/// goal: message") pairs: one per sub-goal when none could be planned,
/// else the error's kind.
pub fn error_refusals(e: &PlanError) -> Vec<(&'static str, String)> {
    match e {
        PlanError::Unsolvable { unsolved, .. } => unsolved
            .iter()
            .map(|u| {
                let text = format!("{} → {}: {}", u.object, u.goal, u.reason);
                (u.refusal.kind(), text)
            })
            .collect(),
        PlanError::Instruction(i) => vec![("instruction", i.to_string())],
        PlanError::RobotState { .. } => vec![("robot_state", e.to_string())],
        other => vec![("other", other.to_string())],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use afford_planner::error::InstructionError;

    #[test]
    fn refusal_kinds_cover_every_typed_kind_once() {
        for kind in Refusal::KINDS {
            assert_eq!(REFUSAL_KINDS.iter().filter(|k| **k == kind).count(), 1);
        }
        assert_eq!(REFUSAL_KINDS[REFUSAL_KINDS.len() - 2], "instruction");
        let state = PlanError::RobotState {
            robot: "kuka_iiwa14".into(),
            issues: Vec::new(),
        };
        assert_eq!(error_refusals(&state)[0].0, "robot_state");
    }

    #[test]
    fn refusal_kind_of_an_instruction_error_is_instruction() {
        let e = PlanError::Instruction(InstructionError::new("do not"));
        assert_eq!(error_refusals(&e)[0].0, "instruction");
    }
}
