//! Malformed scenario files (tests/fixtures/malformed/): each breaks the
//! well-formed tests/fixtures/valid/minimal.yaml in one way. The library's
//! error names the file, the field path and what is wrong (with line:column
//! where the parser gives one), and `afford plan <file>` exits with code 2,
//! prints that message on stderr, prints nothing on stdout and never panics.

use std::path::{Path, PathBuf};

use afford::planner::scenario;

use crate::util::{afford_with_path, assert_contains_all, fixture, scratch_dir};

/// `file:LINE:COLUMN:` right after the file name.
fn location_line(message: &str, file: &str) -> Option<u64> {
    let rest = message.strip_prefix(file)?.strip_prefix(':')?;
    let mut parts = rest.splitn(3, ':');
    let line = parts.next()?.parse().ok()?;
    let _column: u64 = parts.next()?.parse().ok()?;
    Some(line)
}

/// Where the parser should place the error.
#[derive(Debug, Clone, Copy)]
enum At {
    /// `file:LINE:COLUMN:` with this line.
    Line(u64),
    /// `file:LINE:COLUMN:` with any line.
    SomeLine,
    /// No parser location (validation and I/O errors): `file: …`.
    NoLine,
}

fn check(path: &Path, needles: &[&str], at: At) {
    let file = path.display().to_string();
    let error = match scenario::load(path) {
        Ok(s) => panic!("{file} loaded although it is malformed: {s:?}"),
        Err(e) => e,
    };
    let message = error.to_string();
    assert!(
        message.starts_with(&file),
        "the message does not start with the file name {file}:\n{message}"
    );
    assert_contains_all(&format!("error for {file}"), &message, needles);
    match at {
        At::Line(line) => assert_eq!(
            location_line(&message, &file),
            Some(line),
            "expected {file}:{line}:COLUMN in\n{message}"
        ),
        At::SomeLine => assert!(
            location_line(&message, &file).is_some(),
            "expected {file}:LINE:COLUMN in\n{message}"
        ),
        At::NoLine => assert!(
            message.starts_with(&format!("{file}: ")),
            "expected no location after {file} in\n{message}"
        ),
    }

    let run = afford_with_path(&["plan"], path, &[]);
    run.assert_code(2).assert_no_panic();
    assert!(
        run.stdout.is_empty(),
        "{}: printed on stdout:\n{}",
        run.command,
        run.stdout
    );
    assert!(
        run.stderr.contains(&message),
        "{}: stderr does not carry the library's message\n--- expected ---\n{message}\n--- stderr ---\n{}",
        run.command,
        run.stderr
    );
}

macro_rules! malformed {
    ($($name:ident: $file:literal, $at:expr => [$($needle:literal),+ $(,)?];)*) => {
        $(
            #[test]
            fn $name() {
                check(&fixture(concat!("malformed/", $file)), &[$($needle),+], $at);
            }
        )*
        /// Every fixture file the table covers.
        const COVERED: &[&str] = &[$($file),*];
    };
}

malformed! {
    unknown_field_top_level: "unknown-top-level-field.yaml", At::Line(21)
        => ["instructoin", "unknown field", "instruction"];
    unknown_field_nested_yaml: "unknown-nested-field.yaml", At::Line(14)
        => ["objects[1].colr", "unknown field", "color"];
    unknown_field_nested_json: "unknown-nested-field.json", At::Line(51)
        => ["objects[1].colr", "unknown field", "color"];
    unknown_field_in_safety: "unknown-safety-field.yaml", At::Line(20)
        => ["safety.hand_margn", "unknown field", "hand_margin"];
    unknown_field_in_learner: "learner-unknown-field.yaml", At::Line(21)
        => ["learner.learning_rat", "unknown field", "learning_rate"];
    missing_nested_field: "missing-required-field.yaml", At::SomeLine
        => ["camera", "missing field", "table_z"];
    missing_top_level_field_yaml: "missing-instruction.yaml", At::SomeLine
        => ["missing field", "instruction"];
    missing_top_level_field_json: "missing-required-field.json", At::SomeLine
        => ["missing field", "robot"];
    wrong_type_yaml: "wrong-type.yaml", At::Line(5)
        => ["camera.width", "invalid"];
    wrong_type_json: "wrong-type.json", At::Line(23)
        => ["robot.start", "invalid type", "string"];
    wrong_box_length: "wrong-type-box.yaml", At::Line(14)
        => ["objects[1].box", "length 3", "4"];
    duplicate_key: "duplicate-key.yaml", At::Line(6)
        => ["camera", "duplicate", "width"];
    wrong_format_version: "wrong-format-version.yaml", At::NoLine
        => ["afford", "unsupported format version 2", "reads 1"];
    negative_box_width: "negative-box-width.yaml", At::NoLine
        => ["goals[1].box", "width and length must be positive", "w=-120"];
    box_outside_image_yaml: "box-outside-image.yaml", At::NoLine
        => ["objects[1].box", "not inside the 640x480 image"];
    box_outside_image_json: "box-outside-image.json", At::NoLine
        => ["goals[1].box", "not inside the 640x480 image"];
    duplicate_names: "duplicate-names.yaml", At::NoLine
        => ["objects[1].name", "'blue-square-1'", "used twice"];
    singular_pixel_to_base: "singular-pixel-to-base.yaml", At::NoLine
        => ["camera.pixel_to_base", "singular"];
    start_outside_image: "start-outside-image.yaml", At::NoLine
        => ["robot.start", "(320, 500)", "outside the 640x480 image"];
    pointing_outside_image: "pointing-outside-image.yaml", At::NoLine
        => ["pointing", "(-10, 200)", "outside"];
    negative_margin: "negative-margin.yaml", At::NoLine
        => ["safety.hand_margin", "between 0 and 1", "-0.1"];
    negative_height: "negative-height.yaml", At::NoLine
        => ["hands[0].height", "between 0.005 and 2 metres", "-0.08"];
    grid_target_box_of_1e_300_px_is_bad_input: "grid-target-box-1e-300-px.yaml", At::NoLine
        => ["objects[0].box", "at least 1 px", "w=1e-300"];
    grid_target_box_of_5e_324_px_is_bad_input: "grid-target-box-5e-324-px.yaml", At::NoLine
        => ["objects[0].box", "at least 1 px", "w=5e-324"];
    target_box_of_0_001_px_is_bad_input: "target-box-0.001-px.yaml", At::NoLine
        => ["objects[0].box", "at least 1 px", "w=0.001"];
    object_smaller_than_5_mm_is_bad_input: "object-smaller-than-5-mm.yaml", At::NoLine
        => ["objects[0].box", "0.0025 x 0.0025 m", "at least 0.005 m"];
    grid_of_more_cells_than_the_bound_is_bad_input: "too-many-grid-cells.yaml", At::NoLine
        => ["objects[0].box", "672400 grid cells", "at most 40000"];
    height_near_2_pow_63_m_is_bad_input: "height-near-2-pow-63.yaml", At::NoLine
        => ["objects[0].height", "between 0.005 and 2 metres", "9.223372036854776e18"];
    height_of_4_3e9_m_is_bad_input: "height-4.3e9-m.yaml", At::NoLine
        => ["goals[0].height", "between 0.005 and 2 metres", "4300000000"];
    height_below_the_support_gap_is_bad_input: "height-below-support-gap.yaml", At::NoLine
        => ["objects[0].height", "between 0.005 and 2 metres", "0.001"];
    camera_height_of_2_pow_31_is_bad_input: "camera-height-2-pow-31.yaml", At::NoLine
        => ["camera.height", "between 1 and 8192 pixels", "2147483648"];
    calibration_spanning_640_m_is_bad_input: "camera-far-from-base.yaml", At::NoLine
        => ["camera.pixel_to_base", "more than 10 m from the robot base"];
    table_a_million_metres_away_is_bad_input: "table-z-far.yaml", At::NoLine
        => ["camera.table_z", "between -10 and 10 metres", "-1000000"];
    instruction_of_100_clauses_is_bad_input: "instruction-too-many-clauses.yaml", At::NoLine
        => ["instruction", "100 clauses", "at most 64"];
    more_objects_than_the_bound_is_bad_input: "too-many-objects.yaml", At::NoLine
        => ["objects", "259 entries", "at most 256"];
    learner_budget_of_1e12_steps_is_bad_input: "learner-max-steps-too-large.yaml", At::NoLine
        => ["learner.max_steps", "at most 1000000", "1000000000000"];
    safety_separation_is_validated_with_the_scenario: "separation-negative-reaction-time.yaml", At::NoLine
        => ["safety.separation.reaction_time_s", "≥ 0", "-1"];
    separation_human_speed_of_1e308_is_bad_input: "separation-huge-human-speed.yaml", At::NoLine
        => ["safety.separation.human_speed_m_s", "at most 100", "1e308"];
    separation_crawl_of_1e_300_m_s_is_bad_input: "separation-crawl-1e-300.yaml", At::NoLine
        => ["safety.separation.min_tool_speed_m_s", "at least 0.001", "1e-300"];
    name_of_300_characters_is_bad_input: "name-too-long.yaml", At::NoLine
        => ["objects[1].name", "at most 200 characters"];
    empty_instruction: "empty-instruction.yaml", At::NoLine
        => ["instruction", "must not be empty"];
    learner_setting_out_of_range: "learner-out-of-range.yaml", At::NoLine
        => ["learner.epsilon", "between 0 and 1", "1.5"];
    bad_extension: "bad-extension.txt", At::NoLine
        => [".yaml", ".json"];
    invalid_yaml_syntax: "invalid-yaml-syntax.yaml", At::SomeLine
        => ["robot.start"];
    invalid_json_syntax: "invalid-json-syntax.json", At::Line(4)
        => ["expected `,`"];
    nonexistent_file: "does-not-exist.yaml", At::NoLine
        => ["cannot read the file"];
}

fn fixture_files(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(fixture(dir))
        .expect("read the fixture directory")
        .map(|e| e.expect("directory entry").path())
        .collect();
    files.sort();
    files
}

#[test]
fn every_malformed_fixture_is_in_the_table() {
    let files = fixture_files("malformed");
    assert!(files.len() >= 12, "only {} malformed fixtures", files.len());
    for path in files {
        let name = path.file_name().unwrap().to_str().unwrap();
        assert!(
            COVERED.contains(&name),
            "{name} has no row in scenario_errors.rs"
        );
    }
    assert!(
        !fixture("malformed/does-not-exist.yaml").exists(),
        "the nonexistent-file case needs that file to be absent"
    );
}

#[test]
fn the_baseline_the_fixtures_break_is_valid_in_both_formats() {
    let yaml = scenario::load(&fixture("valid/minimal.yaml"))
        .unwrap_or_else(|e| panic!("baseline YAML: {e}"));
    let json = scenario::load(&fixture("valid/minimal.json"))
        .unwrap_or_else(|e| panic!("baseline JSON: {e}"));
    assert_eq!(yaml, json);
    // Input validity is the point here; examples.rs runs the whole pipeline.
    for file in fixture_files("valid") {
        afford_with_path(&["plan"], &file, &["--until", "grid"])
            .assert_code(0)
            .assert_no_panic();
    }
}

#[test]
fn validation_reports_every_problem_not_just_the_first() {
    let text = std::fs::read_to_string(fixture("valid/minimal.yaml")).unwrap();
    let broken = text
        .replace("start: [320, 460]", "start: [320, 999]")
        .replace("hand_margin: 0.10", "hand_margin: 7")
        .replace("box: [500, 300, 120, 120]", "box: [500, 300, 120, -1]");
    let error = scenario::parse(&broken, scenario::Format::Yaml, "three-problems.yaml")
        .expect_err("three problems");
    assert_contains_all(
        "error",
        &error.to_string(),
        &[
            "three-problems.yaml",
            "robot.start",
            "goals[1].box",
            "safety.hand_margin",
        ],
    );
}

/// The minimal scene with its instruction replaced.
fn with_instruction(instruction: &str) -> String {
    std::fs::read_to_string(fixture("valid/minimal.yaml"))
        .unwrap()
        .replace(
            "instruction: \"put the blue square in the left box\"",
            &format!("instruction: \"{instruction}\""),
        )
}

#[test]
fn validate_of_10000_clauses_is_bad_input() {
    let clauses = vec!["the blue square in the left box"; 10_000].join(" , ");
    let path = scratch_dir("validate-10000-clauses").join("clauses.yaml");
    std::fs::write(&path, with_instruction(&format!("put {clauses}"))).unwrap();
    let error = scenario::load(&path).expect_err("10,000 clauses");
    assert_contains_all(
        "error",
        &error.to_string(),
        &["instruction", "at most 2000 characters"],
    );
    let run = afford_with_path(&["validate"], &path, &[]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all("stderr", &run.stderr, &["instruction", "2000 characters"]);
}

#[test]
fn scenario_file_larger_than_1_mib_is_refused_unparsed() {
    let padding = format!("# {}\n", "x".repeat(1 << 20));
    let path = scratch_dir("scenario-larger-than-1-mib").join("large.yaml");
    std::fs::write(&path, padding + &with_instruction("put it in the left box")).unwrap();
    let error = scenario::load(&path).expect_err("larger than the bound");
    assert_contains_all(
        "error",
        &error.to_string(),
        &["large.yaml", "larger than 1048576 bytes"],
    );
    afford_with_path(&["plan"], &path, &[])
        .assert_code(2)
        .assert_no_panic();
}

#[test]
fn a_scenario_built_in_code_is_validated_before_planning() {
    let mut s = scenario::load(&fixture("valid/minimal.yaml")).unwrap();
    s.objects[0].bbox.w = 1e-300;
    let error = afford::planner::plan(&s, &afford::planner::PlanOptions::default())
        .expect_err("a 1e-300 px target");
    assert_contains_all(
        "error",
        &error.to_string(),
        &["objects[0].box", "at least 1 px"],
    );
}
