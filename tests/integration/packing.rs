//! Packing released pieces into goal boxes (issue 9, item 4): a round piece
//! packs by its stadium, not its bounding box, and the independent check
//! agrees on its own geometry (tests/fixtures/packing/).

use crate::util::{afford_with_path, fixture, plan_to_file, scratch_dir};

/// Scene 265 of `afford bench transits --seed 1`: the round piece fits only
/// in the corner the square's box leaves; both sub-goals plan chained, and
/// `afford check --physics` accepts the plan (placement by its own
/// cylinders, the replay's pieces in the box).
#[test]
fn round_piece_packs_into_the_corner_beside_a_square() {
    let scene = fixture("packing/place-round-piece-beside-a-square.yaml");
    let dir = scratch_dir("packing-round-beside-square");
    let (path, plan) = plan_to_file(&scene, &dir);
    let subgoals = plan["subgoals"].as_array().expect("sub-goals");
    assert_eq!(subgoals.len(), 2, "both sub-goals planned");
    let checked = afford_with_path(
        &["check", scene.to_str().expect("UTF-8")],
        &path,
        &["--physics", "--json"],
    );
    checked.assert_code(0);
    let report = checked.json();
    assert_eq!(report["violations"], serde_json::json!([]), "{report}");
    let targets = report["physics"]["targets"].as_array().expect("targets");
    assert_eq!(targets.len(), 2);
    assert!(targets.iter().all(|t| t["in_goal"] == true), "{targets:?}");
}

/// Scene 195 of `afford bench transits --seed 1`: three round pieces fit
/// the right box only as the first two in opposite corners of one side and
/// the large one between them; the second's spot leaves room for the third
/// (bottom-left fill alone put it beside the first: "right box is full"),
/// every sub-goal plans chained and `afford check --physics` accepts the
/// plan.
#[test]
fn chained_round_pieces_leave_room_for_the_later_ones() {
    let scene = fixture("packing/chained-round-pieces-leave-room.yaml");
    let dir = scratch_dir("packing-chained-round-pieces");
    let (path, plan) = plan_to_file(&scene, &dir);
    assert_eq!(
        plan["unsolved"],
        serde_json::json!([]),
        "{}",
        plan["unsolved"]
    );
    let subgoals = plan["subgoals"].as_array().expect("sub-goals");
    assert_eq!(subgoals.len(), 4, "every sub-goal planned");
    let checked = afford_with_path(
        &["check", scene.to_str().expect("UTF-8")],
        &path,
        &["--physics", "--json"],
    );
    checked.assert_code(0);
    let report = checked.json();
    assert_eq!(report["violations"], serde_json::json!([]), "{report}");
    let targets = report["physics"]["targets"].as_array().expect("targets");
    assert_eq!(targets.len(), 4);
    assert!(targets.iter().all(|t| t["in_goal"] == true), "{targets:?}");
}
