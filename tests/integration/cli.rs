//! The command line: help texts, the benchmark's JSON and argument errors.

use serde_json::Value;

use crate::util::{afford, assert_contains_all};

#[test]
fn top_level_help_lists_the_commands() {
    let run = afford(&["--help"]);
    run.assert_code(0).assert_no_panic();
    assert_contains_all(
        "afford --help",
        &run.stdout,
        &["Usage:", "plan", "bench", "--version"],
    );
}

#[test]
fn plan_help_lists_its_options() {
    let run = afford(&["plan", "--help"]);
    run.assert_code(0).assert_no_panic();
    assert_contains_all(
        "afford plan --help",
        &run.stdout,
        &[
            "[SCENARIO]",
            "--seed",
            "--format",
            "json",
            "yaml",
            "-o, --output",
        ],
    );
}

#[test]
fn bench_cql_help_lists_its_options() {
    let run = afford(&["bench", "cql", "--help"]);
    run.assert_code(0).assert_no_panic();
    assert_contains_all(
        "afford bench cql --help",
        &run.stdout,
        &["--scenarios", "--seed", "--json"],
    );
}

#[test]
fn version_is_the_crate_version() {
    let run = afford(&["--version"]);
    run.assert_code(0);
    assert_eq!(
        run.stdout.trim(),
        format!("afford {}", env!("CARGO_PKG_VERSION"))
    );
}

fn number(report: &Value, path: &str) -> f64 {
    path.split('.')
        .fold(report, |v, key| &v[key])
        .as_f64()
        .unwrap_or_else(|| panic!("{path} is not a number in\n{report:#}"))
}

#[test]
fn bench_cql_json_has_the_documented_keys() {
    let run = afford(&["bench", "cql", "--scenarios", "5", "--seed", "1", "--json"]);
    run.assert_code(0).assert_no_panic();
    let report = run.json();
    let solvable = number(&report, "solvable");
    assert!(
        solvable.fract() == 0.0 && (0.0..=5.0).contains(&solvable),
        "solvable = {solvable}"
    );
    for learner in ["cql", "ql"] {
        let rate = number(&report, &format!("{learner}.success_rate"));
        assert!(
            (0.0..=1.0).contains(&rate),
            "{learner}.success_rate = {rate}"
        );
    }
    assert!(number(&report, "cql.median_ms") >= 0.0);
    assert!(number(&report, "cql.mean_steps") > 0.0 || solvable == 0.0);
    let ratio = number(&report, "cql.mean_length_over_optimal");
    if number(&report, "cql.success_rate") > 0.0 {
        // The oracle is optimal: no learned plan can be shorter.
        assert!(
            ratio >= 1.0 - 1e-12,
            "cql.mean_length_over_optimal = {ratio}"
        );
    }
    // The same seed gives the same scenes and the same learning; only the
    // timings may differ.
    let again = afford(&["bench", "cql", "--scenarios", "5", "--seed", "1", "--json"]).json();
    for key in [
        "solvable",
        "cql.success_rate",
        "cql.mean_steps",
        "cql.mean_length_over_optimal",
        "ql.success_rate",
        "ql.mean_steps",
    ] {
        assert_eq!(
            number(&report, key),
            number(&again, key),
            "{key} differs between runs"
        );
    }
}

#[test]
fn bench_cql_prints_a_table_without_json() {
    let run = afford(&["bench", "cql", "--scenarios", "2", "--seed", "3"]);
    run.assert_code(0).assert_no_panic();
    assert!(
        serde_json::from_str::<Value>(&run.stdout).is_err(),
        "printed JSON:\n{}",
        run.stdout
    );
    assert_contains_all("the table", &run.stdout, &["CQL", "QL"]);
}

#[test]
fn bad_arguments_exit_with_code_2() {
    for args in [
        &[][..],
        &["plan", "--format", "xml"],
        &["plan", "--seed", "minus-one"],
        &["bench", "cql", "--scenarios", "0"],
        &["frobnicate"],
    ] {
        let run = afford(args);
        run.assert_code(2).assert_no_panic();
        assert!(
            run.stdout.is_empty(),
            "{}: printed {}",
            run.command,
            run.stdout
        );
        assert!(
            !run.stderr.trim().is_empty(),
            "{}: nothing on stderr",
            run.command
        );
    }
}

#[test]
fn robots_acm_prints_the_allowed_collisions_block_for_builtin_and_user_robots() {
    let builtin = afford(&["robots", "acm", "kuka_iiwa14", "--samples", "2000"]);
    builtin.assert_code(0);
    assert_contains_all(
        "afford robots acm kuka_iiwa14",
        &builtin.stdout,
        &[
            "allowed_collisions:",
            "samples: 2000",
            "seed: 1",
            "clearance: 0.03",
            "{pair: [base_link, link_1], reason: adjacent}",
            "# checked:",
        ],
    );
    let user = afford(&[
        "robots",
        "acm",
        "kinematics/tests/fixtures/six_dof.yaml",
        "--samples",
        "1000",
        "--seed",
        "7",
    ]);
    user.assert_code(0);
    assert_contains_all(
        "afford robots acm six_dof.yaml",
        &user.stdout,
        &[
            "'six_dof'",
            "seed: 7",
            "{pair: [base, shoulder], reason: adjacent}",
        ],
    );
    let unknown = afford(&["robots", "acm", "no_such_robot"]);
    unknown.assert_code(2);
    assert_contains_all("unknown robot", &unknown.stderr, &["no_such_robot"]);
    let zero = afford(&["robots", "acm", "kuka_iiwa14", "--samples", "0"]);
    zero.assert_code(2);
    assert_contains_all("--samples 0", &zero.stderr, &["samples", "1 ..="]);
}

/// Runs `afford args` with its stdout a pipe whose reading end is already
/// closed, as in `afford validate | head` once head has exited.
fn with_closed_stdout(args: &[&str]) -> crate::util::Run {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_afford"))
        .args(args)
        .current_dir(crate::util::repo())
        .env_remove("RUST_BACKTRACE")
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .expect("run the afford binary");
    crate::util::Run {
        command: format!("afford {} | (closed)", args.join(" ")),
        code: output.status.code(),
        stdout: String::new(),
        stderr: String::from_utf8(output.stderr).expect("stderr is UTF-8"),
    }
}

#[test]
fn closed_stdout_pipe_does_not_panic() {
    for args in [
        &["validate"][..],
        &["plan", "--until", "grid"],
        &["plan", "--until", "grid", "--format", "csv"],
        &["robots"],
        &["robots", "--json"],
    ] {
        let run = with_closed_stdout(args);
        run.assert_no_panic();
        // A reader that stops early is not an error: quiet, and the exit
        // code is the command's own (csv without trajectories is bad input).
        let expected = if args.contains(&"csv") { 2 } else { 0 };
        run.assert_code(expected);
        if expected == 0 {
            assert!(run.stderr.is_empty(), "{}: {}", run.command, run.stderr);
        }
    }
}

#[test]
fn rate_out_of_range_is_bad_input() {
    for rate in ["0", "nan", "-1", "1e-300", "0.5", "1e6", "1e9", "inf"] {
        let flag = format!("--rate={rate}");
        let run = afford(&["plan", "--until", "grid", &flag]);
        run.assert_code(2).assert_no_panic();
        assert_contains_all(
            &run.command,
            &run.stderr,
            &["--rate", "between 1 and 1000 Hz"],
        );
        assert!(run.stdout.is_empty(), "{}: printed a plan", run.command);
    }
    afford(&["plan", "--until", "grid", "--rate", "1000"])
        .assert_code(0)
        .assert_no_panic();
}

#[test]
fn unknown_robot_model_is_bad_input_for_validate_and_plan() {
    let dir = crate::util::scratch_dir("unknown-robot-model");
    let text = std::fs::read_to_string(crate::util::fixture("valid/minimal.yaml"))
        .unwrap()
        .replace("model: kuka_iiwa14", "model: kuka_iiwa15");
    let path = dir.join("unknown-robot.yaml");
    std::fs::write(&path, text).unwrap();
    for (command, after) in [("validate", &[][..]), ("plan", &["--until", "grid"][..])] {
        let run = crate::util::afford_with_path(&[command], &path, after);
        run.assert_code(2).assert_no_panic();
        assert_contains_all(
            &run.command,
            &run.stderr,
            &["unknown-robot.yaml", "robot.model", "kuka_iiwa15"],
        );
    }
}

#[test]
fn user_robot_with_a_1e308_m_shape_is_bad_input() {
    let dir = crate::util::scratch_dir("user-robot-1e308-shape");
    let robots = crate::util::repo().join("robots");
    std::fs::copy(robots.join("kuka_iiwa14.yaml"), dir.join("huge.yaml")).unwrap();
    let urdf = std::fs::read_to_string(robots.join("kuka_iiwa14.urdf")).unwrap();
    let sphere = urdf.find("<sphere radius=\"").expect("a sphere");
    let end = sphere + urdf[sphere..].find("/>").unwrap();
    let huge = format!(
        "{}<sphere radius=\"1e308\"{}",
        &urdf[..sphere],
        &urdf[end..]
    );
    std::fs::write(dir.join("kuka_iiwa14.urdf"), huge).unwrap();
    let scenario = std::fs::read_to_string(crate::util::fixture("valid/minimal.yaml"))
        .unwrap()
        .replace("model: kuka_iiwa14", "model: huge.yaml");
    std::fs::write(dir.join("scene.yaml"), scenario).unwrap();
    let run = crate::util::afford_with_path(&["plan"], &dir.join("scene.yaml"), &[]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["robot.model", "kuka_iiwa14.urdf", "geometry sizes"],
    );
}

#[test]
fn validate_says_which_pieces_already_rest_in_the_goal() {
    let path = blue_square_already_in_the_left_box("validate-skipped");
    let run = crate::util::afford_with_path(&["validate"], &path, &[]);
    run.assert_code(0).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stdout,
        &["left where it is: blue-square-9 is already in the left box"],
    );
    assert!(
        !run.stdout.contains("blue-square-9 → left box"),
        "{}",
        run.stdout
    );
}

#[test]
fn plan_notes_pieces_already_in_the_goal_and_plans_the_others() {
    let path = blue_square_already_in_the_left_box("plan-skipped");
    let run = crate::util::afford_with_path(&["plan", "--until", "grid"], &path, &[]);
    run.assert_code(0).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["left where it is: blue-square-9 is already in the left box"],
    );
    let plan: serde_json::Value = serde_json::from_str(&run.stdout).expect("JSON plan");
    assert_eq!(
        plan["skipped"][0],
        "blue-square-9 is already in the left box"
    );
    let moved: Vec<&str> = plan["subgoals"]
        .as_array()
        .expect("subgoals")
        .iter()
        .map(|s| s["object"].as_str().expect("object"))
        .collect();
    assert!(
        !moved.is_empty() && !moved.contains(&"blue-square-9"),
        "{moved:?}"
    );
}

/// The default scenario with one more blue square already resting in the
/// left box (a corner of it), written to a scratch folder `name`.
fn blue_square_already_in_the_left_box(name: &str) -> std::path::PathBuf {
    let dir = crate::util::scratch_dir(name);
    let text = std::fs::read_to_string(crate::util::repo().join("examples/sort-blue-squares.yaml"))
        .unwrap()
        .replace(
            "objects:\n",
            "objects:\n  - {name: blue-square-9, color: blue, shape: square, box: [30, 310, 40, 40], height: 0.03}\n",
        );
    let path = dir.join("one-already-in.yaml");
    std::fs::write(&path, text).unwrap();
    path
}
