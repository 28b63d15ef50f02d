//! The library API: a scenario or options built in code get the
//! errors a file gets, `sensitive:` entries must name something, relative
//! robot paths follow one rule, a plan re-checks in memory, and `afford
//! validate` exits 1 on an instruction it cannot execute.

use std::path::{Path, PathBuf};

use afford::planner::scenario::{self, Format};
use afford::planner::{FieldIssue, PlanError, PlanOptions, ScenarioError, Stage, plan};

use crate::util::{afford_with_path, assert_contains_all, fixture, scratch_dir};

fn issues_of(e: ScenarioError) -> Vec<FieldIssue> {
    match e {
        ScenarioError::Invalid { issues, .. } => issues,
        other => panic!("expected an invalid scenario, got {other}"),
    }
}

fn grid_options() -> PlanOptions {
    PlanOptions {
        until: Stage::Grid,
        ..PlanOptions::default()
    }
}

#[test]
fn scenario_built_in_code_gets_the_same_error_as_the_file() {
    let text = scenario::DEFAULT_SCENARIO
        .replace("instruction:", "safety: {hand_margin: 2.5}\ninstruction:");
    let from_file = issues_of(scenario::parse(&text, Format::Yaml, "bad.yaml").unwrap_err());
    let mut in_code = scenario::default_scenario().unwrap();
    in_code.safety.hand_margin = 2.5;
    let from_code = match plan(&in_code, &grid_options()) {
        Err(PlanError::Scenario(e)) => issues_of(e),
        other => panic!("expected the scenario refused, got {other:?}"),
    };
    assert_eq!(from_file, from_code);
    assert_eq!(from_code[0].field, "safety.hand_margin");
    assert_eq!(issues_of(in_code.validate().unwrap_err()), from_file);
}

#[test]
fn plan_options_out_of_range_are_named_by_field() {
    let scenario = scenario::default_scenario().unwrap();
    let mut options = grid_options();
    options.lift.max_step = 0.0;
    options.timing.rate_hz = f64::NAN;
    options.max_replans = 1_000_000;
    let issues = match plan(&scenario, &options) {
        Err(PlanError::Options { issues }) => issues,
        other => panic!("expected the options refused, got {other:?}"),
    };
    let fields: Vec<&str> = issues.iter().map(|i| i.field.as_str()).collect();
    assert_eq!(fields, ["timing.rate_hz", "lift.max_step", "max_replans"]);
    assert!(PlanOptions::default().validate().is_ok());
}

#[test]
fn sensitive_entry_naming_nothing_is_bad_input_with_did_you_mean() {
    let text = scenario::DEFAULT_SCENARIO
        .replace("instruction:", "sensitive: [yelow, hexagon]\ninstruction:");
    let issues = issues_of(scenario::parse(&text, Format::Yaml, "s.yaml").unwrap_err());
    assert_eq!(issues.len(), 1, "{issues:?}");
    assert_eq!(issues[0].field, "sensitive[0]");
    assert_contains_all(
        "sensitive typo",
        &issues[0].message,
        &[
            "'yelow' names no colour, shape or object",
            "did you mean 'yellow'?",
        ],
    );
    // A colour afford knows that no piece has yet stays accepted.
    let known =
        scenario::DEFAULT_SCENARIO.replace("instruction:", "sensitive: [green]\ninstruction:");
    assert!(scenario::parse(&known, Format::Yaml, "s.yaml").is_ok());
}

#[test]
fn relative_robot_path_resolves_against_the_scenario_folder() {
    let options = PlanOptions::default().for_scenario_file(Path::new("examples/x.yaml"));
    assert_eq!(options.base_dir, PathBuf::from("examples"));
    let bare = PlanOptions::default().for_scenario_file(Path::new("x.yaml"));
    assert_eq!(bare.base_dir, PathBuf::from("."));
    assert_eq!(PlanOptions::default().base_dir, PathBuf::from("."));
}

#[test]
fn plan_rechecks_in_memory_without_json() {
    let s = scenario::load(&fixture("cases/place-successive-pieces.yaml")).unwrap();
    let options = PlanOptions::default();
    let p = plan(&s, &options).unwrap();
    let report = afford::check::check(&s, &p, &options.base_dir).unwrap();
    assert!(report.passed(), "{:?}", report.violations);
    // Stopped before timing, the same call reports the missing trajectories.
    let grid = plan(&s, &grid_options()).unwrap();
    let report = afford::check::check(&s, &grid, &options.base_dir).unwrap();
    assert!(!report.passed());
}

#[test]
fn validate_exits_1_when_the_instruction_cannot_be_executed() {
    let dir = scratch_dir("validate-not-executable");
    let path = dir.join("never.yaml");
    let text = scenario::DEFAULT_SCENARIO.replace(
        "instruction: \"Put all the blue squares in the left box.\"",
        "instruction: \"put the blue squares next to the left box\"",
    );
    std::fs::write(&path, text).unwrap();
    let run = afford_with_path(&["validate"], &path, &[]);
    run.assert_code(1).assert_no_panic();
    assert_contains_all(&run.command, &run.stderr, &["Not executable instruction"]);
    assert_contains_all(&run.command, &run.stdout, &["instruction:"]);
}

#[test]
fn validate_reports_the_share_of_the_table_each_perimeter_covers() {
    let run = afford_with_path(
        &["validate"],
        &crate::util::repo().join("examples/hand-on-route.yaml"),
        &[],
    );
    run.assert_code(0);
    assert_contains_all(
        &run.command,
        &run.stdout,
        &[
            "hand hand-1: perimeter 0.100 m (≈160 px along u, ≈160 px along v) covers",
            "% of the table",
        ],
    );
}

/// The README's scenario example, as written there.
fn readme_scenario() -> String {
    let readme = std::fs::read_to_string(crate::util::repo().join("README.md")).unwrap();
    let section = &readme[readme
        .find("## Scenario format (version 1)")
        .expect("section")..];
    let start = section.find("```yaml\n").expect("yaml block") + "```yaml\n".len();
    let end = start + section[start..].find("```").expect("block end");
    section[start..end].to_string()
}

#[test]
fn readme_example_scenario_plans_as_written() {
    let s = scenario::parse(&readme_scenario(), Format::Yaml, "README.md").expect("valid");
    let p = plan(&s, &PlanOptions::default()).expect("the README's scene plans");
    assert!(p.unsolved.is_empty(), "{:?}", p.unsolved);
    assert!(p.subgoals.iter().all(|sg| sg.trajectory.is_some()));
}

#[test]
fn yaml_reader_internals_are_said_in_the_authors_terms() {
    let dup = scenario::DEFAULT_SCENARIO.replace("name: sort-blue-squares", "name: a\nname: b");
    let e = scenario::parse(&dup, Format::Yaml, "dup.yaml")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("dup.yaml:"), "{e}");
    assert_contains_all(
        "duplicate key",
        &e,
        &["`name` is given twice", "duplicate key"],
    );
    assert!(!e.contains("DuplicateKeyPolicy"), "{e}");
    let big = format!("afford: 1\nsensitive: [{}]\n", vec!["x"; 300_000].join(","));
    let e = scenario::parse(&big, Format::Yaml, "big.yaml")
        .unwrap_err()
        .to_string();
    assert_contains_all(
        "budget",
        &e,
        &[
            "big.yaml:2:",
            "sensitive: the file is too large for a scenario: more than 250000 values",
        ],
    );
    assert!(
        !e.contains("budget breached") && !e.contains("Nodes"),
        "{e}"
    );
}

#[test]
fn check_violations_carry_typed_data_beside_the_message() {
    let scenario = scenario::default_scenario().unwrap();
    let options = PlanOptions::default();
    let mut p = plan(&scenario, &options).unwrap();
    // A hand put on the first route after planning: the margin class names
    // the body, the hand, the time and the sample, and how near.
    let mid = p.subgoals[0].path_px[p.subgoals[0].path_px.len() / 2];
    let mut with_hand = scenario.clone();
    let hand = format!(
        "hands:\n  - {{name: intruding-hand, box: [{}, {}, 30, 30], height: 0.06}}\ninstruction:",
        mid[0] - 15.0,
        mid[1] - 15.0
    );
    with_hand.hands = scenario::parse(
        &scenario::DEFAULT_SCENARIO.replace("instruction:", &hand),
        Format::Yaml,
        "hand.yaml",
    )
    .unwrap()
    .hands;
    let report = afford::check::check(&with_hand, &p, &options.base_dir).unwrap();
    let margin = report
        .violations
        .iter()
        .find(|v| v.data.other.as_deref() == Some("intruding-hand"))
        .expect("the hand's margin is entered");
    let d = &margin.data;
    assert!(
        d.body.is_some() && d.time_s.is_some() && d.sample.is_some(),
        "{d:?}"
    );
    assert!(d.distance_m.unwrap() < d.margin_m.unwrap(), "{d:?}");
    let json = serde_json::to_value(margin).unwrap();
    assert_eq!(json["other"], "intruding-hand");
    assert_eq!(json["message"], margin.message.as_str());
    // A joint pushed past its limit: the position class names the joint.
    let trajectory = p.subgoals[0].trajectory.as_mut().unwrap();
    for point in &mut trajectory.points[30..33] {
        point.positions[3] = -2.12;
    }
    let report = afford::check::check(&scenario, &p, &options.base_dir).unwrap();
    let position = report
        .of(afford::check::ViolationClass::Position)
        .next()
        .expect("the limit is broken");
    assert_eq!(position.data.joint.as_deref(), Some("joint_a4"));
}

/// The planner's clock gives one wall time per sub-goal, refused ones
/// included, and their sum is at least half the stages' sum (the stages run
/// inside the sub-goals; some are timed inside one another).
#[test]
fn planning_time_is_kept_for_every_subgoal() {
    let s = scenario::parse(scenario::DEFAULT_SCENARIO, Format::Yaml, "default.yaml")
        .expect("the default scenario is valid");
    let planned = plan(&s, &PlanOptions::default()).expect("the default scenario plans");
    let count = planned.subgoals.len() + planned.unsolved.len();
    assert!(count > 1, "the default scenario has several sub-goals");
    let t = &planned.timings;
    assert_eq!(t.per_subgoal.len(), count);
    assert!(
        t.per_subgoal.iter().all(|d| !d.is_zero()),
        "{:?}",
        t.per_subgoal
    );
    let stages = t.grid + t.cql + t.lift + t.ik + t.collision + t.transit + t.timing;
    let total: std::time::Duration = t.per_subgoal.iter().sum();
    assert!(
        total * 2 >= stages,
        "sub-goals {total:?}, stages {stages:?}"
    );
}
