//! Refusal kinds for the safety campaign's counts.
//!
//! STOP-GAP: the planner reports why a sub-goal was refused as text
//! ([`crate::plan::UnsolvedSubgoal::reason`]); until it carries a typed kind,
//! [`refusal_kind`] sorts today's messages by the phrases the planner writes
//! (plan.rs `why_unsolvable` and `attempt`, motion.rs, trajectory.rs). Replace
//! it by the typed kind when that lands; a message no phrase matches is
//! `other`, so a new message shows up in the counts rather than vanishing.

/// Every kind [`refusal_kind`] returns, in report order.
pub const REFUSAL_KINDS: [&str; 15] = [
    "gripper_too_narrow",
    "too_tall_for_fingers",
    "goal_full",
    "does_not_fit_goal",
    "hand_covers_target",
    "hand_covers_gripper",
    "hand_blocks_route",
    "perimeters_cover_goal",
    "no_route",
    "unreachable",
    "collides",
    "learner_budget",
    "timing",
    "instruction",
    "other",
];

/// The short kind of a refusal message (see the module doc: a stop-gap).
pub fn refusal_kind(reason: &str) -> &'static str {
    const PHRASES: [(&str, &str); 15] = [
        ("; the gripper opens ", "gripper_too_narrow"),
        (" tall: with the palm ", "too_tall_for_fingers"),
        (" is full", "goal_full"),
        ("'s inner walls", "does_not_fit_goal"),
        ("a hand covers ", "hand_covers_target"),
        (
            "a hand's perimeter covers the gripper",
            "hand_covers_gripper",
        ),
        ("hand blocks every route", "hand_blocks_route"),
        ("safety perimeters cover the whole", "perimeters_cover_goal"),
        ("no free route", "no_route"),
        ("no route is left", "no_route"),
        ("unreachable", "unreachable"),
        ("no arm reaches", "unreachable"),
        ("collides", "collides"),
        ("the learner found no plan", "learner_budget"),
        ("Not executable instruction", "instruction"),
    ];
    if let Some(&(_, kind)) = PHRASES.iter().find(|(p, _)| reason.contains(p)) {
        return kind;
    }
    const TIMING: [&str; 4] = [
        "timing failed",
        "protective separation distance",
        "limit of joint",
        "path needs at least one waypoint",
    ];
    match TIMING.iter().any(|p| reason.contains(p)) {
        true => "timing",
        false => "other",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusal_kind_sorts_the_planners_messages() {
        let cases = [
            ("a hand covers blue-square-1", "hand_covers_target"),
            (
                "a hand's perimeter covers the gripper: wait for the hand to move",
                "hand_covers_gripper",
            ),
            ("hand blocks every route", "hand_blocks_route"),
            (
                "safety perimeters cover the whole left box",
                "perimeters_cover_goal",
            ),
            (
                "no free route from the gripper to x and on to the left box",
                "no_route",
            ),
            (
                "no route is left once 3 cells the arm collides over are blocked",
                "no_route",
            ),
            (
                "grasp waypoint 4 unreachable for arm left: target needs joint 'a' beyond its limit",
                "unreachable",
            ),
            ("the motion collides: carry waypoint 3: …", "collides"),
            ("the timed trajectory collides at t = 1.2 s: …", "collides"),
            (
                "the learner found no plan within 20000 training steps",
                "learner_budget",
            ),
            ("timing failed: NumericalError", "timing"),
            (
                "big is 0.125 m wide across its narrower side (0.135 m with 0.010 m clearance); the gripper opens 0.080 m",
                "gripper_too_narrow",
            ),
            (
                "tall is 0.200 m tall: with the palm 0.020 m above its top the fingers (0.050 m long) reach 5.0 mm below it, less than half its height or 10.0 mm",
                "too_tall_for_fingers",
            ),
            ("left box is full", "goal_full"),
            (
                "big (0.200 m x 0.200 m) does not fit inside the left box's inner walls (0.100 m x 0.100 m, 0.005 m clearance)",
                "does_not_fit_goal",
            ),
            ("something new", "other"),
        ];
        for (reason, kind) in cases {
            assert_eq!(refusal_kind(reason), kind, "{reason}");
            assert!(REFUSAL_KINDS.contains(&kind));
        }
    }
}
