//! Bad and odd input found by trying afford as a new user
//! (tests/fixtures/bad-input/): each test is named after the problem it
//! found. A bad file is refused with exit 2, the file, the field and what is
//! wrong on stderr, nothing on stdout, never a panic; a failed run leaves no
//! file behind; a plan that fails still says why, typed.

use std::path::Path;

use afford::planner::scenario;

use crate::util::{afford, afford_with_path, assert_contains_all, fixture, repo, scratch_dir};

/// `afford plan FILE` refuses `file` (exit 2, stdout empty, no panic) and
/// the library's error and stderr name the file and carry every needle.
#[track_caller]
fn refused(file: &str, needles: &[&str]) {
    let path = fixture(&format!("bad-input/{file}"));
    let error = scenario::load(&path).expect_err("the file is refused");
    let message = error.to_string();
    assert!(
        message.starts_with(&path.display().to_string()),
        "{message}"
    );
    assert_contains_all(file, &message, needles);
    let run = afford_with_path(&["plan"], &path, &[]);
    run.assert_code(2).assert_no_panic();
    assert!(run.stdout.is_empty(), "{}: {}", run.command, run.stdout);
    assert!(run.stderr.contains(&message), "{}", run.stderr);
}

#[test]
fn goal_narrower_than_its_walls_is_refused_naming_the_field_not_an_internal_refusal() {
    refused(
        "goal-narrower-than-its-walls.yaml",
        &["goals[0].box", "0.0013 x 0.0013 m", "two 0.005 m walls"],
    );
}

#[test]
fn goal_as_low_as_its_floor_is_refused_naming_the_field_not_an_internal_refusal() {
    refused(
        "goal-as-low-as-its-floor.yaml",
        &["goals[0].height", "0.005 m floor", "got 0.005"],
    );
}

/// The goal walls are checked on the scene after each observation too.
#[test]
fn goal_narrower_than_its_walls_in_an_observation_is_refused_naming_the_entry() {
    let text = std::fs::read_to_string(fixture("valid/minimal.yaml")).expect("fixture")
        + "observations:\n  - at: 1.0\n    goals: [{name: left box, box: [20, 300, 4, 120], height: 0.1}]\n";
    let path = scratch_dir("observed-goal-narrower-than-walls").join("scene.yaml");
    std::fs::write(&path, text).expect("write");
    let message = scenario::load(&path).expect_err("refused").to_string();
    assert_contains_all(
        "observed goal",
        &message,
        &["observations[0].goals[0].box", "walls"],
    );
}

#[test]
fn name_with_a_newline_is_refused_naming_the_field() {
    refused(
        "name-with-a-newline.yaml",
        &["objects[0].name", "control characters", "'\\n'"],
    );
}

#[test]
fn instruction_with_an_escape_sequence_is_refused_naming_the_field() {
    refused(
        "instruction-with-an-escape-sequence.yaml",
        &["instruction", "control characters", "'\\u{1b}'"],
    );
}

#[test]
fn margin_of_1e300_is_shown_as_1e300_not_301_digits() {
    refused("margin-1e300.yaml", &["safety.hand_margin", "got 1e300"]);
    let message = scenario::load(&fixture("bad-input/margin-1e300.yaml"))
        .expect_err("refused")
        .to_string();
    assert!(!message.contains("10000000000"), "{message}");
}

#[test]
fn robot_description_syntax_error_names_its_file_field_and_line_without_a_snippet() {
    let run = afford_with_path(
        &["plan"],
        &fixture("bad-input/robot-description-unknown-field.yaml"),
        &[],
    );
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &[
            "robot-description-unknown-field.yaml: robot.model:",
            "robot-unknown-field.yaml",
            "unknown field `colour`",
            "line 4",
        ],
    );
    assert!(!run.stderr.contains("<input>"), "{}", run.stderr);
    assert_eq!(run.stderr.lines().count(), 1, "{}", run.stderr);
}

#[test]
fn check_with_an_unknown_robot_names_the_scenario_file_and_field() {
    let scenario = fixture("bad-input/unknown-robot.yaml");
    // The robot is loaded before the plan is read: any plan file will do.
    let plan = scratch_dir("check-unknown-robot").join("plan.json");
    std::fs::write(&plan, "{}").expect("write");
    let run = afford(&[
        "check",
        scenario.to_str().expect("UTF-8"),
        plan.to_str().expect("UTF-8"),
    ]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["unknown-robot.yaml: robot.model:", "unknown robot 'ur5'"],
    );
}

#[test]
fn bench_count_beyond_its_bound_is_refused_not_a_capacity_overflow_panic() {
    let huge = u64::MAX.to_string();
    for (bench, flag) in [
        ("ik", "--poses"),
        ("pipeline", "--runs"),
        ("cql", "--scenarios"),
        ("safety", "--scenarios"),
        ("routes", "--scenarios"),
        ("transits", "--scenes"),
        ("monitor", "--scenes"),
    ] {
        for count in ["0", huge.as_str()] {
            let run = afford(&["bench", bench, flag, count]);
            run.assert_code(2).assert_no_panic();
            assert_contains_all(&run.command, &run.stderr, &[flag, "must be between 1 and"]);
        }
    }
}

#[test]
fn run_format_summary_is_refused_not_printed_as_yaml() {
    let run = afford(&["run", "--format", "summary"]);
    run.assert_code(2).assert_no_panic();
    assert!(run.stdout.is_empty(), "{}", run.stdout);
    assert_contains_all(&run.command, &run.stderr, &["summary", "json, yaml or csv"]);
}

/// A plan with no sub-goal planned is still written (exit 1): a program
/// reads each `unsolved` entry's typed `refusal`, and stderr tags each
/// reason with its kind.
#[test]
fn nothing_planned_still_writes_the_plan_with_typed_refusals() {
    let run = afford_with_path(
        &["plan"],
        &repo().join("examples/hand-blocks-goal.yaml"),
        &[],
    );
    run.assert_code(1).assert_no_panic();
    let plan = run.json();
    assert_eq!(plan["subgoals"], serde_json::json!([]), "{}", run.stdout);
    let refusal = &plan["unsolved"][0]["refusal"];
    assert_eq!(refusal["kind"], "perimeters_cover_goal", "{}", run.stdout);
    assert_eq!(refusal["goal"], "left box", "{}", run.stdout);
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["no sub-goal could be planned", "[perimeters_cover_goal]"],
    );
}

/// `--svg` to a folder that does not exist: exit 3 (the result cannot be
/// written) and no plan file left behind (the plan was written first, then
/// the run failed).
#[test]
fn svg_that_cannot_be_written_leaves_no_plan_behind() {
    for (command, options) in [("plan", &["--until", "grid"][..]), ("run", &[][..])] {
        let dir = scratch_dir(&format!("svg-cannot-be-written-{command}"));
        let out = dir.join("out.json");
        let svg = dir.join("no-such-folder").join("picture.svg");
        let mut args = vec![command];
        args.extend_from_slice(options);
        args.extend(["-o", out.to_str().expect("UTF-8")]);
        args.extend(["--svg", svg.to_str().expect("UTF-8")]);
        let run = afford(&args);
        run.assert_code(3).assert_no_panic();
        assert_contains_all(&run.command, &run.stderr, &["picture.svg", "cannot write"]);
        assert!(!out.exists(), "{command}: {} was written", out.display());
    }
}

/// `-o` naming a folder: exit 3 saying it is a folder, and no
/// `FOLDER.partial` left beside it.
#[test]
fn output_to_a_folder_leaves_no_partial_file_behind() {
    let dir = scratch_dir("output-to-a-folder");
    let folder = dir.join("plans");
    std::fs::create_dir(&folder).expect("create");
    let run = afford(&[
        "plan",
        "--until",
        "grid",
        "-o",
        folder.to_str().expect("UTF-8"),
    ]);
    run.assert_code(3).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["plans", "cannot write", "is a folder"],
    );
    assert_eq!(entries(&dir), ["plans"], "left behind in {}", dir.display());
}

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("read")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Splits one CSV line (RFC 4180 quoting) into its fields.
fn csv_fields(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

#[test]
fn csv_row_of_an_object_named_with_a_comma_keeps_its_field_count() {
    let path = fixture("bad-input/object-name-with-a-comma.yaml");
    // The object's name is the second field of a plan's rows, the third of a run's.
    for (command, field) in [("plan", 1), ("run", 2)] {
        let run = afford_with_path(&[command], &path, &["--format", "csv"]);
        run.assert_code(0).assert_no_panic();
        let mut lines = run.stdout.lines();
        let columns = csv_fields(lines.next().expect("header")).len();
        let mut rows = 0;
        for line in lines {
            let fields = csv_fields(line);
            assert_eq!(fields.len(), columns, "{command}: {line}");
            assert_eq!(fields[field], "blue square, \"large\"", "{command}: {line}");
            rows += 1;
        }
        assert!(rows > 100, "{command}: {rows} rows");
    }
}

#[test]
fn calibration_skewed_45_degrees_is_refused_naming_the_field() {
    refused(
        "calibration-skewed-45-degrees.yaml",
        &["camera.pixel_to_base", "skewed", "45.0°", "within 1°"],
    );
    let valid = fixture("bad-input/calibration-skewed-half-a-degree.yaml");
    scenario::load(&valid).expect("0.5° of skew is accepted");
}

/// Validation refuses the value before any planning (asserted on the
/// library first, so a regression fails here instead of hanging the CLI).
#[test]
fn continuous_joint_at_1e17_rad_is_refused_naming_the_field_not_planned_forever() {
    refused(
        "continuous-joint-at-1e17-rad.yaml",
        &["robot.joints.j6", "within ±1000", "got 1e17"],
    );
    let path = fixture("bad-input/continuous-joint-at-1e17-rad.yaml");
    let text = std::fs::read_to_string(&path).expect("fixture");
    let dir = scratch_dir("continuous-joint-bound");
    for (value, accepted) in [("1000.0", true), ("-1000.5", false), ("10000.0", false)] {
        let copy = dir.join(format!("j6-{value}.yaml"));
        let model = path
            .parent()
            .expect("folder")
            .join("../../../kinematics/tests/fixtures/continuous.yaml");
        let edited = text.replace("j6: 1e17", &format!("j6: {value}")).replace(
            "../../../kinematics/tests/fixtures/continuous.yaml",
            model.to_str().expect("UTF-8"),
        );
        std::fs::write(&copy, edited).expect("write");
        assert_eq!(scenario::load(&copy).is_ok(), accepted, "j6 = {value}");
    }
}

/// The scenario's bound on `robot.joints` is the independent check's bound
/// on positions: a start afford accepts is one `afford check` reads.
#[test]
fn joint_position_bound_is_the_independent_checks() {
    assert_eq!(
        scenario::bounds::MAX_JOINT_POSITION,
        afford::check::MAX_ABS_POSITION
    );
}

#[test]
fn camera_width_negative_says_a_whole_number_is_wanted_not_invalid_u32() {
    refused(
        "camera-width-negative.yaml",
        &["camera.width", "whole number from 0 to 4294967295"],
    );
    let message = scenario::load(&fixture("bad-input/camera-width-negative.yaml"))
        .expect_err("refused")
        .to_string();
    assert!(!message.contains("u32"), "{message}");
}

#[test]
fn json_with_a_byte_order_mark_is_read_not_expected_value_at_1_1() {
    let path = fixture("bad-input/json-with-a-byte-order-mark.json");
    let scenario = scenario::load(&path).expect("a UTF-8 BOM is skipped");
    assert_eq!(scenario.objects.len(), 1);
    afford_with_path(&["validate"], &path, &[])
        .assert_code(0)
        .assert_no_panic();
}

#[test]
fn utf_16_file_is_refused_saying_it_is_not_utf_8() {
    refused("utf-16.yaml", &["not UTF-8 text", "save it as UTF-8"]);
}

/// A plan whose object is not in the scenario cannot be replayed: its
/// `physics` violation says so, and stderr has no "0 steps … 0 of 0
/// pieces in their goal" summary as if a replay had run.
#[test]
fn physics_check_of_a_plan_it_cannot_replay_prints_no_empty_replay_summary() {
    let dir = scratch_dir("physics-cannot-replay");
    let scenario = repo().join("examples/sort-blue-squares.yaml");
    let (plan_file, mut plan) = crate::util::plan_to_file(&scenario, &dir);
    plan["subgoals"][0]["object"] = serde_json::json!("ghost");
    std::fs::write(&plan_file, plan.to_string()).expect("write");
    let run = afford(&[
        "check",
        "--physics",
        scenario.to_str().expect("UTF-8"),
        plan_file.to_str().expect("UTF-8"),
    ]);
    run.assert_code(1).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stdout,
        &["physics", "cannot replay", "ghost"],
    );
    assert!(!run.stderr.contains("0 steps"), "{}", run.stderr);
}

/// The new checks (goal walls, calibration skew, joint bound, control
/// characters) refuse no scene the benchmarks generate: the safety
/// campaign's and the CQL benchmark's series stay as they were.
#[test]
fn every_benchmark_scene_passes_the_bad_input_checks() {
    use afford_bench::{generator, scenes};
    for k in 0..1000 {
        let scene = scenes::scene(1, k);
        assert!(
            scene.validate().is_ok(),
            "safety scene {k}: {:?}",
            scene.validate()
        );
    }
    // The CQL series is a learner's grid, not a scenario file: some scenes
    // hold more clutter than `objects` allows. Only the new checks matter.
    for k in 0..300 {
        let issues = match generator::scene(1, k).validate() {
            Ok(()) => continue,
            Err(e) => e.to_string(),
        };
        for new_check in [
            "goals[",
            "pixel_to_base",
            "robot.joints",
            "control characters",
        ] {
            assert!(!issues.contains(new_check), "cql scene {k}: {issues}");
        }
    }
}

/// `afford check` printed a sample time of 1e300 with all its 301 digits.
#[test]
fn check_shows_a_sample_time_of_1e300_in_exponent_form() {
    let scenario = repo().join("examples/sort-blue-squares.yaml");
    let dir = scratch_dir("check-time-1e300");
    let (plan, mut json) = crate::util::plan_to_file(&scenario, &dir);
    json["subgoals"][0]["trajectory"]["points"][5]["time_from_start"] = serde_json::json!(1e300);
    std::fs::write(&plan, json.to_string()).expect("write");
    let run = afford(&[
        "check",
        scenario.to_str().expect("UTF-8"),
        plan.to_str().expect("UTF-8"),
    ]);
    run.assert_code(1).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stdout,
        &["points[5].time_from_start is 1e300"],
    );
    assert!(!run.stdout.contains("10000000000"), "{}", run.stdout);
}
