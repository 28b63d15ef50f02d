//! `afford plan` for people and programs: piped it prints the
//! plan's JSON (today's shape plus each refusal's kind, data and message),
//! `--format summary` (the default on a terminal) a few lines, and `--svg`
//! draws a plan even when nothing or only part of it planned.

use crate::util::{afford, afford_with_path, assert_contains_all, fixture, repo, scratch_dir};

#[test]
fn plan_piped_prints_json_with_the_refusal_kind_and_message() {
    let path = fixture("cases/goal-full.yaml");
    let piped = afford_with_path(&["plan"], &path, &["--until", "joints"]);
    piped.assert_code(1).assert_no_panic();
    let json = piped.json();
    let unsolved = &json["unsolved"][0];
    assert_eq!(unsolved["refusal"]["kind"], "goal_full");
    assert_eq!(unsolved["refusal"]["goal"], "left box");
    assert_eq!(unsolved["refusal"]["message"], unsolved["reason"]);
    let keys: Vec<&str> = unsolved
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(keys, ["goal", "object", "reason", "refusal"]);
    let explicit = afford_with_path(&["plan"], &path, &["--until", "joints", "--format", "json"]);
    assert_eq!(explicit.stdout, piped.stdout, "piped output is the JSON");
}

#[test]
fn plan_summary_gives_one_line_per_subgoal_with_the_reason_it_failed() {
    let path = fixture("cases/goal-full.yaml");
    let run = afford_with_path(&["plan"], &path, &["--format", "summary"]);
    run.assert_code(1).assert_no_panic();
    assert_contains_all(
        &run.command,
        &run.stdout,
        &[
            "sub-goals planned",
            "✓ ",
            ", arm '",
            " training steps",
            "✗ ",
            "left box is full [goal_full]",
        ],
    );
    assert!(run.stdout.lines().count() < 12, "{}", run.stdout);
}

#[test]
fn svg_draws_failures_when_nothing_planned() {
    let dir = scratch_dir("svg-nothing-planned");
    let scene = dir.join("hand-on-square.yaml");
    let text = std::fs::read_to_string(repo().join("examples/hand-on-route.yaml"))
        .unwrap()
        .replace(
            "box: [300, 200, 40, 40], height: 0.08",
            "box: [560, 40, 40, 40], height: 0.08",
        );
    std::fs::write(&scene, text).unwrap();
    let svg = dir.join("plan.svg");
    let run = afford_with_path(&["plan"], &scene, &["--svg", svg.to_str().unwrap()]);
    run.assert_code(1).assert_no_panic();
    assert_eq!(
        run.json()["subgoals"],
        serde_json::json!([]),
        "nothing planned prints the plan of no sub-goals"
    );
    let picture = std::fs::read_to_string(&svg).expect("the picture is drawn");
    assert_contains_all(
        "svg of a plan that failed",
        &picture,
        &[
            "✗ a. blue-square-1 → left box: a hand covers blue-square-1",
            "[hand_covers_target]",
        ],
    );
}

/// The canvas positions of the SVG `<text>` elements whose text is `label`.
fn text_positions(svg: &str, label: &str) -> Vec<(String, String)> {
    svg.split("<text x=\"")
        .skip(1)
        .filter(|t| {
            t.split_once('>')
                .and_then(|(_, rest)| rest.split_once("</text>"))
                .is_some_and(|(text, _)| text.trim() == label)
        })
        .map(|t| {
            let (x, rest) = t.split_once('"').unwrap();
            let y = rest.split('"').nth(1).unwrap();
            (x.to_string(), y.to_string())
        })
        .collect()
}

#[test]
fn svg_drop_markers_of_pieces_in_one_box_do_not_pile_up() {
    let dir = scratch_dir("svg-drops");
    let svg = dir.join("plan.svg");
    afford(&["plan", "--until", "grid", "--svg", svg.to_str().unwrap()]).assert_code(0);
    let picture = std::fs::read_to_string(&svg).unwrap();
    let spots: Vec<_> = ["1", "2", "3"]
        .iter()
        .map(|n| text_positions(&picture, n))
        .collect();
    assert!(spots.iter().all(|s| s.len() == 1), "{spots:?}");
    assert!(
        spots[0] != spots[1] && spots[1] != spots[2] && spots[0] != spots[2],
        "{spots:?}"
    );
    // The built-in scene's yellow hexagon is drawn as one.
    assert!(picture.contains("<polygon"), "no hexagon");
}

#[test]
fn svg_shows_the_pointing_pixel() {
    let dir = scratch_dir("svg-shapes");
    let svg = dir.join("plan.svg");
    let run = afford(&[
        "plan",
        "examples/here-pointing.yaml",
        "--until",
        "grid",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    run.assert_no_panic();
    let picture = std::fs::read_to_string(&svg).expect("the picture is drawn");
    // The label of the crosshair itself, not the hand's "hand: pointing-hand".
    assert_eq!(text_positions(&picture, "pointing").len(), 1);
}
