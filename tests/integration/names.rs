//! Names an instruction cannot tell apart. The instruction reader matches
//! names ignoring case, Unicode form (NFKC: NFC and NFD spellings,
//! fullwidth letters) and hyphens, underscores and slashes, so two objects,
//! goals or hands whose names differ only so are bad input (exit 2, both
//! fields named, nothing written): "put blue-square-1 in the left box" moved
//! the red circle `Blue-Square-1` (tests/fixtures/cases/names-differ-only-in-case.yaml).

use std::path::PathBuf;

use crate::util::{afford_with_path, assert_contains_all, fixture, scratch_dir};

/// The default scene's camera and robot with these objects, goals, hands
/// and instruction, written for test `name`.
fn scene(
    name: &str,
    objects: &[&str],
    goals: &[&str],
    hands: &[&str],
    instruction: &str,
) -> PathBuf {
    let list = |key: &str, items: &[&str]| match items.is_empty() {
        true => String::new(),
        false => format!(
            "{key}:\n{}",
            items
                .iter()
                .map(|i| format!("  - {i}\n"))
                .collect::<String>()
        ),
    };
    let text = format!(
        "afford: 1\ncamera:\n  width: 640\n  height: 480\n  pixel_to_base: [[0.0, -0.000625, 0.66], [-0.000625, 0.0, 0.20]]\n  table_z: -0.40\nrobot: {{model: kuka_iiwa14, start: [320, 460]}}\n{}{}{}instruction: \"{instruction}\"\n",
        list("objects", objects),
        list("goals", goals),
        list("hands", hands),
    );
    let path = scratch_dir(&format!("names-{name}")).join("scene.yaml");
    std::fs::write(&path, text).expect("write the scene");
    path
}

const LEFT_BOX: &str = "{name: left box, box: [20, 300, 120, 120], height: 0.10}";

/// Plans `path` up to the grid into a scratch file: the run and the file.
fn plan_grid(path: &std::path::Path) -> (crate::util::Run, PathBuf) {
    let out = path.with_file_name("plan.json");
    let run = afford_with_path(
        &["plan", "--until", "grid"],
        path,
        &["-o", out.to_str().expect("UTF-8")],
    );
    (run, out)
}

#[test]
fn names_differing_only_in_case_are_refused() {
    let case = fixture("cases/names-differ-only-in-case.yaml");
    let out = scratch_dir("names-case").join("plan.json");
    let run = afford_with_path(&["plan"], &case, &["-o", out.to_str().expect("UTF-8")]);
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &[
            "objects[1].name",
            "'blue-square-1'",
            "'Blue-Square-1'",
            "objects[0].name",
        ],
    );
    assert!(!out.exists(), "a plan was written: {}", out.display());
    afford_with_path(&["validate"], &case, &[]).assert_code(2);
}

#[test]
fn names_differing_only_in_unicode_form_are_refused() {
    // "café" composed (U+00E9) and decomposed (e + U+0301).
    let objects = [
        "{name: \"caf\u{e9}\", color: red, shape: circle, box: [100, 80, 40, 40], height: 0.03}",
        "{name: \"cafe\u{301}\", color: blue, shape: square, box: [420, 120, 40, 40], height: 0.03}",
    ];
    let path = scene(
        "nfd",
        &objects,
        &[LEFT_BOX],
        &[],
        "put the blue square in the left box",
    );
    let run = plan_grid(&path).0;
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["objects[1].name", "objects[0].name", "NFKC"],
    );
}

#[test]
fn a_hand_named_in_fullwidth_letters_like_a_goal_is_refused() {
    let objects =
        ["{name: piece, color: blue, shape: square, box: [100, 80, 40, 40], height: 0.03}"];
    let hand =
        "{name: \"\u{ff4c}\u{ff45}\u{ff46}\u{ff54} box\", box: [300, 200, 30, 30], height: 0.05}";
    let path = scene(
        "fullwidth",
        &objects,
        &[LEFT_BOX],
        &[hand],
        "put the blue square in the left box",
    );
    let run = plan_grid(&path).0;
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["hands[0].name", "goals[0].name"],
    );
}

#[test]
fn an_object_named_like_a_goal_but_for_case_and_hyphens_is_refused() {
    let objects =
        ["{name: Left-Box, color: blue, shape: square, box: [100, 80, 40, 40], height: 0.03}"];
    let path = scene(
        "object-goal",
        &objects,
        &[LEFT_BOX],
        &[],
        "put the blue square in the left box",
    );
    let run = plan_grid(&path).0;
    run.assert_code(2).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stderr,
        &["goals[0].name", "objects[0].name", "'Left-Box'"],
    );
}

/// An instruction typed in NFC finds the one object whose name is stored
/// in NFD: both are read in one form.
#[test]
fn an_instruction_in_nfc_finds_a_name_written_in_nfd() {
    let objects = [
        "{name: \"cafe\u{301}-cup\", color: red, shape: circle, box: [100, 80, 40, 40], height: 0.03}",
        "{name: tea-cup, color: red, shape: circle, box: [420, 120, 40, 40], height: 0.03}",
    ];
    let path = scene(
        "nfc-finds-nfd",
        &objects,
        &[LEFT_BOX],
        &[],
        "put caf\u{e9}-cup in the left box",
    );
    let (run, out) = plan_grid(&path);
    run.assert_code(0).assert_no_panic();
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out).expect("plan written")).expect("JSON");
    assert_eq!(plan["subgoals"][0]["object"], "cafe\u{301}-cup");
    assert_eq!(plan["subgoals"].as_array().map(Vec::len), Some(1));
}

/// Names that differ in a word are two names: each instruction moves the
/// one it names.
#[test]
fn names_differing_in_a_digit_move_the_object_named() {
    let objects = [
        "{name: blue-square-11, color: blue, shape: square, box: [420, 120, 40, 40], height: 0.03}",
        "{name: blue-square-1, color: red, shape: circle, box: [100, 80, 40, 40], height: 0.03}",
    ];
    for (wanted, instruction) in [
        ("blue-square-1", "put blue-square-1 in the left box"),
        ("blue-square-11", "put blue-square-11 in the left box"),
    ] {
        let path = scene(wanted, &objects, &[LEFT_BOX], &[], instruction);
        let (run, out) = plan_grid(&path);
        run.assert_code(0).assert_no_panic();
        let plan: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out).expect("plan")).expect("JSON");
        assert_eq!(plan["subgoals"][0]["object"], wanted, "{instruction}");
    }
}
