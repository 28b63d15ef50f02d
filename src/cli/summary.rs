//! The plan in a few lines for a person at a terminal: per sub-goal the
//! object and its goal, the arm, the motion's duration and the learner's
//! training steps, or why it could not be planned (its refusal kind in
//! brackets). Programs read the JSON (`--format json`, or stdout piped).

use std::fmt::Write;

use afford_planner::Plan;

/// The summary of `plan`, one line per sub-goal, ending in a newline.
pub fn summary(plan: &Plan) -> String {
    let total = plan.subgoals.len() + plan.unsolved.len();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{}: {} of {total} sub-goals planned (seed {}, until {})",
        if plan.scenario.is_empty() {
            "plan"
        } else {
            &plan.scenario
        },
        plan.subgoals.len(),
        plan.seed,
        format!("{:?}", plan.until).to_lowercase()
    );
    for (k, s) in plan.subgoals.iter().enumerate() {
        let arm = s
            .arm
            .as_deref()
            .map(|a| format!(", arm '{a}'"))
            .unwrap_or_default();
        let duration = s
            .trajectory
            .as_ref()
            .map(|t| format!(", {:.2} s", t.duration()))
            .unwrap_or_default();
        let _ = writeln!(
            out,
            "  {}. ✓ {} → {}{arm}{duration}, {} actions ({} at best), {} training steps",
            k + 1,
            s.object,
            s.goal,
            s.actions.len(),
            s.optimal_length,
            s.training_steps
        );
    }
    for u in &plan.unsolved {
        let _ = writeln!(
            out,
            "  ✗ {} → {}: {} [{}]",
            u.object,
            u.goal,
            u.reason,
            u.refusal.kind()
        );
    }
    for note in &plan.skipped {
        let _ = writeln!(out, "  left where it is: {note}");
    }
    let motion: f64 = plan
        .subgoals
        .iter()
        .filter_map(|s| s.trajectory.as_ref())
        .map(|t| t.duration())
        .sum();
    if motion > 0.0 {
        let _ = writeln!(out, "motion: {motion:.2} s in all");
    }
    let _ = writeln!(
        out,
        "the whole plan: --format json|yaml|csv, -o FILE, or pipe the output"
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_names_each_subgoal_arm_duration_and_steps() {
        let scenario = afford_planner::scenario::default_scenario().unwrap();
        let plan = afford_planner::plan(&scenario, &Default::default()).unwrap();
        let text = summary(&plan);
        assert!(
            text.starts_with(
                "sort-blue-squares: 3 of 3 sub-goals planned (seed 1, until trajectory)"
            ),
            "{text}"
        );
        let first = text.lines().nth(1).unwrap();
        assert!(first.contains("✓ blue-square-") && first.contains("→ left box, arm 'arm', "));
        assert!(first.ends_with(" training steps"), "{first}");
        assert!(
            text.contains("motion: ") && text.lines().count() < 10,
            "{text}"
        );
    }
}
