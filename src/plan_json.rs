//! A plan as `afford plan` reports it, for every front end of the library
//! (the command, the Python module): the name a scenario file's plan
//! carries, the plan of a scenario none of whose sub-goals could be
//! planned (still a plan: no sub-goals, every `unsolved` entry with its
//! typed refusal) and the plan's JSON text (pretty-printed, one trailing
//! line break: the bytes `afford plan --format json` writes).

use std::path::Path;

use afford_planner::plan::UnsolvedSubgoal;
use afford_planner::scenario::{self, Scenario};
use afford_planner::{Plan, PlanError, PlanOptions};

/// The name a plan of the scenario at `path` carries when the file gives
/// none: the file's stem; the built-in scenario's name for `None`.
pub fn source_name(path: Option<&Path>) -> String {
    match path {
        Some(path) => path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        ),
        None => scenario::DEFAULT_SCENARIO_NAME.to_string(),
    }
}

/// Plans `scenario`; a scenario none of whose sub-goals could be planned
/// gives the plan [`nothing_planned`] builds instead of an `Err`, so every
/// refusal is data. Other errors are as [`afford_planner::plan`]'s.
pub fn plan_or_refusals(scenario: &Scenario, options: &PlanOptions) -> Result<Plan, PlanError> {
    match afford_planner::plan(scenario, options) {
        Err(PlanError::Unsolvable { unsolved, .. }) => {
            Ok(nothing_planned(scenario, options, unsolved))
        }
        other => other,
    }
}

/// The plan of a scenario none of whose sub-goals could be planned.
pub fn nothing_planned(
    scenario: &Scenario,
    options: &PlanOptions,
    unsolved: Vec<UnsolvedSubgoal>,
) -> Plan {
    Plan {
        scenario: scenario.name.clone().unwrap_or_default(),
        seed: options.seed,
        until: options.until,
        start_state: None,
        skipped: Vec::new(),
        subgoals: Vec::new(),
        unsolved,
        timings: Default::default(),
    }
}

/// The plan's JSON text: pretty-printed, ending in one line break.
pub fn to_json(plan: &Plan) -> Result<String, serde_json::Error> {
    let mut text = serde_json::to_string_pretty(plan)?;
    text.push('\n');
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The name rule: the file's stem, the built-in name without a file.
    #[test]
    fn a_plan_is_named_after_its_file_stem() {
        let path = Path::new("examples/sort-blue-squares.yaml");
        assert_eq!(source_name(Some(path)), "sort-blue-squares");
        assert_eq!(source_name(None), scenario::DEFAULT_SCENARIO_NAME);
    }

    /// An unplannable instruction is a plan whose refusals are data.
    #[test]
    fn an_unsolvable_scenario_gives_a_plan_with_its_refusals() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hand-blocks-goal.yaml");
        let scenario = scenario::load(&path).unwrap();
        let options = PlanOptions::default().for_scenario_file(&path);
        let plan = plan_or_refusals(&scenario, &options).unwrap();
        assert!(plan.subgoals.is_empty());
        assert!(!plan.unsolved.is_empty());
        let text = to_json(&plan).unwrap();
        assert!(text.ends_with("}\n") && !text.ends_with("\n\n"), "{text}");
        assert!(text.contains("\"refusal\""), "{text}");
    }
}
