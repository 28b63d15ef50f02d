//! `afford run` while people act (tests/fixtures/monitor/run-*.yaml, both
//! robots): protective stops that brake, detectors that drop frames or
//! jitter, hands over boxes, goals and pieces moved around the release,
//! work that appears and vanishes. Each case's header says what a careful
//! operator expects; the stopping distances are measured against the
//! separation rule in planner/tests/monitor.rs.

use serde_json::Value;

use crate::monitor::{completed, verdicts};
use crate::util::afford;

/// `afford run` on a fixture: its verdicts and output (exit code checked).
fn run_case(name: &str, exit: i32) -> (Vec<String>, Value) {
    let path = format!("tests/fixtures/monitor/{name}.yaml");
    let result = afford(&["run", &path]);
    result.assert_no_panic();
    assert_eq!(
        result.code,
        Some(exit),
        "{}\n{}",
        result.command,
        result.stderr
    );
    let json = result.json();
    (verdicts(&json), json)
}

fn event_times(json: &Value, verdict: &str) -> Vec<f64> {
    json["events"]
        .as_array()
        .expect("events")
        .iter()
        .filter(|e| e["verdict"] == verdict)
        .map(|e| e["time"].as_f64().expect("time"))
        .collect()
}

#[test]
fn a_tall_hand_ahead_on_the_route_is_waited_for_and_never_touched_both_robots() {
    for robot in ["cob4", "kuka"] {
        let (verdicts, json) = run_case(&format!("run-stop-not-braked-tall-hand-{robot}"), 0);
        assert_eq!(verdicts, ["wait", "continue"], "{robot}");
        completed(&json, 1);
    }
}

#[test]
fn a_flickering_hand_keeps_the_robot_waiting_until_it_has_been_gone_for_the_hold_time() {
    // (fixture, last frame that saw the hand, frame that first missed it after)
    for (case, gone) in [
        ("run-flickering-hand-cob4", 6.2),
        ("run-flickering-hand-kuka", 5.0),
        ("run-dropouts-hand-cob4", 6.2),
    ] {
        let (verdicts, json) = run_case(case, 0);
        assert_eq!(
            verdicts,
            ["wait", "continue"],
            "{case}: no resume in a dropout"
        );
        let resumed = event_times(&json, "continue")[0];
        assert!(
            resumed >= gone + 0.5 - 1e-6,
            "{case}: resumed at {resumed} s, the hand was last missed from {gone} s (hold 0.5 s)"
        );
        completed(&json, 1);
    }
}

#[test]
fn detector_jitter_below_the_tolerance_is_not_a_move_both_robots() {
    for robot in ["cob4", "kuka"] {
        let (verdicts, json) = run_case(&format!("run-jitter-below-tolerance-{robot}"), 0);
        assert!(verdicts.is_empty(), "{robot}: {verdicts:?}");
        assert!(
            json["events"].as_array().expect("events").is_empty(),
            "{robot}: jitter logged as a change"
        );
        completed(&json, 1);
    }
}

#[test]
fn a_hand_reaching_into_the_goal_box_is_waited_for_not_read_as_a_moved_goal_both_robots() {
    for robot in ["cob4", "kuka"] {
        let (verdicts, json) =
            run_case(&format!("run-hand-reaches-into-goal-late-carry-{robot}"), 0);
        assert_eq!(verdicts, ["wait", "continue"], "{robot}");
        assert_eq!(
            json["events"][0]["reason"]["kind"], "hand_on_route",
            "{robot}"
        );
        completed(&json, 1);
    }
}

#[test]
fn a_goal_moved_after_the_release_leaves_the_placed_piece_alone_both_robots() {
    for robot in ["cob4", "kuka"] {
        let (verdicts, json) = run_case(&format!("run-goal-moved-after-release-{robot}"), 0);
        assert!(
            verdicts.iter().all(|v| v == "continue"),
            "{robot}: {verdicts:?}"
        );
        completed(&json, 1);
    }
}

#[test]
fn a_hand_beside_the_box_after_the_release_never_aborts_the_placed_piece_both_robots() {
    for robot in ["cob4", "kuka"] {
        let (verdicts, json) = run_case(&format!("run-hand-beside-box-after-release-{robot}"), 0);
        assert!(
            !verdicts.iter().any(|v| v == "abort"),
            "{robot}: {verdicts:?}"
        );
        completed(&json, 1);
    }
}

#[test]
fn a_piece_put_at_the_release_spot_moves_the_release_to_a_free_spot_both_robots() {
    for robot in ["cob4", "kuka"] {
        let (verdicts, json) = run_case(&format!("run-piece-put-at-release-spot-{robot}"), 0);
        assert_eq!(verdicts[0], "replan", "{robot}: {verdicts:?}");
        assert_eq!(json["events"][0]["reason"]["by"], "red-square-9", "{robot}");
        // completed() asserts the carried piece rests in its goal and the
        // red square was not moved by it.
        completed(&json, 1);
    }
}

#[test]
fn a_later_target_taken_away_drops_its_work_and_puts_the_piece_in_hand_away_both_robots() {
    for robot in ["cob4", "kuka"] {
        let (verdicts, json) = run_case(&format!("run-later-target-taken-away-{robot}"), 0);
        assert!(
            !verdicts.iter().any(|v| v == "abort"),
            "{robot}: {verdicts:?}"
        );
        assert_eq!(
            json["events"][0]["reason"]["kind"], "target_gone",
            "{robot}"
        );
        completed(&json, 1);
    }
}

#[test]
fn new_work_that_vanishes_before_its_subgoal_begins_is_dropped_without_a_panic() {
    let (verdicts, json) = run_case("run-new-work-vanishes-panics", 0);
    assert_eq!(verdicts[0], "new_work", "{verdicts:?}");
    completed(&json, 1);
}

#[test]
fn a_run_picture_shows_the_hands_that_came_and_went_and_the_stops() {
    let dir = crate::util::scratch_dir("run-picture-hands");
    let svg = dir.join("run.svg");
    let out = dir.join("run.json");
    let result = afford(&[
        "run",
        "tests/fixtures/monitor/run-flickering-hand-cob4.yaml",
        "-o",
        out.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    result.assert_no_panic();
    let picture = std::fs::read_to_string(&svg).expect("picture written");
    // The hand has left by the end: drawn dashed with the time it was
    // believed present; the wait is numbered on the path and listed.
    assert!(picture.contains("stroke-dasharray"), "{picture}");
    assert!(picture.contains("hand-1 3.30–6.71 s"), "{picture}");
    assert!(picture.contains("1. 3.30 s wait"), "{picture}");
}

/// Every run fixture, re-checked by afford-check against every hand the
/// detector delivered: no contact, no perimeter entered from where a stop
/// could have kept out, every stop within the stopping term.
#[test]
fn no_run_fixture_touches_a_seen_hand_or_stops_past_its_term() {
    let mut stopped = 0;
    for entry in std::fs::read_dir("tests/fixtures/monitor").unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if !name.starts_with("run-") {
            continue;
        }
        let result = afford(&["run", &path.to_string_lossy()]);
        result.assert_no_panic();
        let json = result.json();
        let people = &json["people"];
        assert_eq!(people["passed"], true, "{name}: {people}");
        assert_eq!(
            people["hand_contacts"].as_array().unwrap().len(),
            0,
            "{name}"
        );
        assert_eq!(
            people["perimeter_entries"].as_array().unwrap().len(),
            0,
            "{name}"
        );
        let ratio = people["largest_stop_ratio"].as_f64().unwrap();
        assert!(ratio <= 1.0, "{name}: a stop took {ratio} of its term");
        stopped += usize::from(!people["stops"].as_array().unwrap().is_empty());
    }
    assert!(stopped >= 5, "only {stopped} fixtures stopped at all");
}
