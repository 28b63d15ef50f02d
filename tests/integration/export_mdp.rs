//! `afford export-mdp`: the grid MDPs for learners outside afford.

use afford_planner::export::{FORMAT_VERSION, MdpExport};

use crate::util::{afford, afford_with_path, repo, scratch_dir};

fn read(path: &std::path::Path) -> MdpExport {
    let text = std::fs::read_to_string(path).expect("export written");
    serde_json::from_str(&text).expect("export reads back")
}

/// One file per generated scene, named after it, byte-identical across runs
/// without `--learner-stats`.
#[test]
fn export_mdp_writes_one_file_per_generated_scene_deterministically() {
    let dir = scratch_dir("export-mdp-generated");
    let out = dir.to_str().unwrap();
    afford(&["export-mdp", "--generated", "3", "--seed", "1", "-o", out])
        .assert_code(0)
        .assert_no_panic();
    let first: Vec<Vec<u8>> = (0..3)
        .map(|k| std::fs::read(dir.join(format!("bench-1-{k}.json"))).unwrap())
        .collect();
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
    afford(&["export-mdp", "--generated", "3", "--seed", "1", "-o", out]).assert_code(0);
    for (k, bytes) in first.iter().enumerate() {
        let again = std::fs::read(dir.join(format!("bench-1-{k}.json"))).unwrap();
        assert_eq!(&again, bytes, "bench-1-{k}.json differs between runs");
        let export = read(&dir.join(format!("bench-1-{k}.json")));
        assert_eq!(export.format_version, FORMAT_VERSION);
        assert!(export.learners.is_none());
    }
}

/// A scenario file gives one MDP per sub-goal, and afford's plan in each
/// replays through the exported transitions to DROP.
#[test]
fn export_mdp_of_a_scenario_replays_each_subgoal_plan() {
    let dir = scratch_dir("export-mdp-scenario");
    let scenario = repo().join("examples").join("sort-blue-squares.yaml");
    afford_with_path(&["export-mdp"], &scenario, &["-o", dir.to_str().unwrap()])
        .assert_code(0)
        .assert_no_panic();
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert!(names.len() >= 2, "{names:?}");
    assert_eq!(names[0], "sort-blue-squares-0.json");
    for name in names {
        let export = read(&dir.join(&name));
        let plan = &export.cql_plan.actions;
        assert!(export.cql_plan.solved, "{name}");
        assert_eq!(export.replay(plan), Some(plan.len()), "{name}");
    }
}

/// With statistics, every learner's run is recorded with its times.
#[test]
fn export_mdp_learner_stats_record_all_learners() {
    let dir = scratch_dir("export-mdp-stats");
    afford(&[
        "export-mdp",
        "--generated",
        "2",
        "--learner-stats",
        "-o",
        dir.to_str().unwrap(),
    ])
    .assert_code(0);
    let stats = read(&dir.join("bench-1-1.json")).learners.unwrap();
    for run in [&stats.cql, &stats.ql, &stats.cql_paper, &stats.ql_paper] {
        assert!(run.plan.training_steps > 0 && run.wall_ms > 0.0);
    }
}

/// Bad arguments are bad input (exit 2) with a message, never a panic.
#[test]
fn export_mdp_refuses_bad_arguments() {
    let dir = scratch_dir("export-mdp-bad");
    let out = dir.to_str().unwrap();
    let cases: [&[&str]; 3] = [
        &["export-mdp", "--generated", "0", "-o", out],
        &["export-mdp", "--learner-stats", "-o", out],
        &["export-mdp", "no-such-scenario.yaml", "-o", out],
    ];
    for args in cases {
        let run = afford(args);
        run.assert_code(2).assert_no_panic();
        assert!(!run.stderr.trim().is_empty(), "{}: no message", run.command);
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}
