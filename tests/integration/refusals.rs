//! Typed refusals: every kind of [`Refusal`] a scene can cause
//! is produced by a scene built for it, with its data, and the JSON of the
//! plan shows `{"kind": ..., ...fields, "message": ...}` next to `reason`.

use afford::planner::error::Refusal;
use afford::planner::grid::Obstacles;
use afford::planner::plan::UnsolvedSubgoal;
use afford::planner::scenario::{self, Format, Scenario};
use afford::planner::{PlanError, PlanOptions, Stage, plan};

use crate::util::fixture;

/// A scene on the README's table with `objects`, `hands` and an instruction
/// moving blue-square-1 into the left box.
fn scene(objects: &str, hands: &str) -> Scenario {
    let text = format!(
        "afford: 1
camera:
  width: 640
  height: 480
  pixel_to_base: [[0.0, -0.000625, 0.66], [-0.000625, 0.0, 0.20]]
  table_z: -0.40
robot:
  model: kuka_iiwa14
  start: [320, 460]
objects:
{objects}
goals:
  - {{name: left box, box: [20, 300, 120, 120], height: 0.10}}
  - {{name: right box, box: [500, 300, 120, 120], height: 0.10}}
hands: [{hands}]
instruction: put the blue square in the left box
"
    );
    scenario::parse(&text, Format::Yaml, "refusal-scene.yaml").expect("the scene is valid")
}

const SQUARE: &str =
    "  - {name: blue-square-1, color: blue, shape: square, box: [300, 80, 40, 40], height: 0.03}";

/// The one refusal of a plan up to `until` whose every sub-goal is refused.
fn refusal_of(s: &Scenario, until: Stage) -> UnsolvedSubgoal {
    let options = PlanOptions {
        until,
        ..PlanOptions::default()
    };
    match plan(s, &options) {
        Err(PlanError::Unsolvable { mut unsolved, .. }) => unsolved.remove(0),
        other => panic!("expected the sub-goal refused, got {other:?}"),
    }
}

/// The refusal's JSON carries the kind, the data and the message, and the
/// message is the `reason` next to it.
fn assert_json(u: &UnsolvedSubgoal, kind: &str) -> serde_json::Value {
    assert_eq!(u.refusal.kind(), kind, "{}", u.reason);
    assert_eq!(u.reason, u.refusal.to_string());
    let json = serde_json::to_value(u).unwrap();
    assert_eq!(json["refusal"]["kind"], kind);
    assert_eq!(json["refusal"]["message"], u.reason.as_str());
    assert_eq!(json["reason"], u.reason.as_str());
    json
}

#[test]
fn refusal_hand_covers_target() {
    let s = scene(
        SQUARE,
        "{name: hand-1, box: [290, 70, 60, 60], height: 0.08}",
    );
    let u = refusal_of(&s, Stage::Grid);
    let json = assert_json(&u, "hand_covers_target");
    assert_eq!(json["refusal"]["object"], "blue-square-1");
}

/// The tool hovers over `robot.start` inside a tall hand's 3-D perimeter:
/// no motion keeps the margin there, so the hand must move first.
#[test]
fn refusal_hand_covers_gripper() {
    let s = scene(
        SQUARE,
        "{name: hand-1, box: [300, 420, 40, 40], height: 0.08}",
    );
    let u = refusal_of(&s, Stage::Trajectory);
    assert_json(&u, "hand_covers_gripper");
}

#[test]
fn refusal_hand_blocks_every_route() {
    let hands = (0..8)
        .map(|k| {
            format!(
                "{{name: hand-{k}, box: [{}, 200, 80, 30], height: 0.08}}",
                k * 80
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let mut s = scene(SQUARE, &hands);
    // A 2 cm perimeter: the hands wall the table off without covering the
    // square, the gripper or the box.
    s.safety.hand_margin = 0.02;
    let u = refusal_of(&s, Stage::Grid);
    let json = assert_json(&u, "hand_blocks_route");
    assert_eq!(json["refusal"]["goal"], "left box");
}

/// A wall across the table: passed over when it is low and ordinary
/// (the carry rises over it), no route when it is sensitive.
#[test]
fn refusal_no_route_names_object_and_goal() {
    let wall: String = (0..16)
        .map(|k| {
            format!(
                "\n  - {{name: red-{k}, color: red, shape: square, box: [{}, 200, 40, 40], height: 0.03}}",
                k * 40
            )
        })
        .collect();
    let mut s = scene(&format!("{SQUARE}{wall}"), "");
    let options = PlanOptions {
        until: Stage::Grid,
        ..PlanOptions::default()
    };
    let over = plan(&s, &options).expect("the carry passes over a low wall");
    assert_eq!(over.subgoals[0].grid.obstacles, Obstacles::Sensitive);
    s.sensitive = vec!["red".into()];
    let u = refusal_of(&s, Stage::Grid);
    let json = assert_json(&u, "no_route");
    assert_eq!(json["refusal"]["blocked_cells"], 0);
    assert_eq!(json["refusal"]["object"], "blue-square-1");
}

#[test]
fn refusal_perimeters_cover_goal() {
    let s = scene(
        SQUARE,
        "{name: hand-1, box: [50, 330, 60, 60], height: 0.08}",
    );
    let u = refusal_of(&s, Stage::Grid);
    let json = assert_json(&u, "perimeters_cover_goal");
    assert_eq!(json["refusal"]["goal"], "left box");
}

#[test]
fn refusal_goal_full() {
    let s = scenario::load(&fixture("cases/goal-full.yaml")).unwrap();
    let p = plan(&s, &PlanOptions::default()).expect("the other pieces plan");
    let json = assert_json(&p.unsolved[0], "goal_full");
    assert_eq!(json["refusal"]["goal"], "left box");
}

#[test]
fn refusal_does_not_fit_goal_gives_both_sizes() {
    let big = "  - {name: blue-square-1, color: blue, shape: square, box: [300, 80, 150, 150], height: 0.03}";
    let u = refusal_of(&scene(big, ""), Stage::Grid);
    let json = assert_json(&u, "does_not_fit_goal");
    let object = json["refusal"]["object_m"][0].as_f64().unwrap();
    let inner = json["refusal"]["inner_m"][0].as_f64().unwrap();
    assert!(object > inner, "{object} vs {inner}");
}

#[test]
fn refusal_gripper_too_narrow_gives_both_widths() {
    let s = scenario::load(&fixture("cases/grasp-object-wider-than-gripper.yaml")).unwrap();
    let u = refusal_of(&s, Stage::Trajectory);
    let json = assert_json(&u, "gripper_too_narrow");
    let width = json["refusal"]["width_m"].as_f64().unwrap();
    let opening = json["refusal"]["opening_m"].as_f64().unwrap();
    assert!(width > opening - 0.02, "{width} vs {opening}");
}

#[test]
fn refusal_too_tall_for_fingers() {
    let mut s = scenario::load(&fixture("cases/grasp-palm-into-tall-target.yaml")).unwrap();
    // A 4 cm margin leaves the iiwa's fingers 2 mm of the object (see cases.rs).
    s.safety.obstacle_margin = 0.04;
    let p = plan(&s, &PlanOptions::default());
    let unsolved = match p {
        Ok(p) => p.unsolved,
        Err(PlanError::Unsolvable { unsolved, .. }) => unsolved,
        Err(e) => panic!("{e}"),
    };
    let u = unsolved
        .iter()
        .find(|u| u.refusal.kind() == "too_tall_for_fingers")
        .expect("the tall piece is refused");
    let json = assert_json(u, "too_tall_for_fingers");
    assert!(json["refusal"]["finger_length_m"].as_f64().unwrap() > 0.0);
}

#[test]
fn refusal_learner_budget() {
    let mut s = scene(SQUARE, "");
    s.learner.max_steps = 3;
    s.learner.optimistic_search = false;
    s.learner.distance_bias = 0.0;
    let u = refusal_of(&s, Stage::Grid);
    let json = assert_json(&u, "learner_budget");
    assert!(json["refusal"]["training_steps"].as_u64().unwrap() <= 3);
}

#[test]
fn refusal_unreachable_names_arm_and_waypoint() {
    // The table 1.5 m farther out: no arm reaches the square; the robot's
    // start is its parked home posture (no `robot.start`).
    let mut s = scene(SQUARE, "");
    s.camera.pixel_to_base[0][2] = 1.6;
    s.robot.start = None;
    let u = refusal_of(&s, Stage::Joints);
    let json = assert_json(&u, "unreachable");
    let arm = &json["refusal"]["arms"][0];
    assert_eq!(arm["arm"], "arm");
    assert!(arm["waypoint"].is_u64());
    assert_eq!(arm["cause"]["kind"], "out_of_reach", "{arm}");
    assert!(
        u.reason.contains("out of reach of the arm 'arm'") && !u.reason.contains("arm arm"),
        "{}",
        u.reason
    );
}

#[test]
fn refusal_kinds_are_distinct_snake_case() {
    let mut kinds = Refusal::KINDS.to_vec();
    kinds.sort_unstable();
    kinds.dedup();
    assert_eq!(kinds.len(), Refusal::KINDS.len());
    assert!(
        kinds
            .iter()
            .all(|k| k.chars().all(|c| c.is_ascii_lowercase() || c == '_'))
    );
}

/// Every refusal message of the safety campaign's first scenes (both
/// robots, many kinds) says where without ambiguity and nothing the user
/// cannot read: no negative "violated by", no "arm arm", no path parameter
/// `t=` of the collision library, no Debug form; its JSON has the kind,
/// the message and the reason.
#[test]
fn refusal_messages_of_random_scenes_are_unambiguous() {
    let mut seen = std::collections::BTreeSet::new();
    for k in 0..16 {
        let s = afford_bench::scenes::scene(1, k);
        let unsolved = match plan(&s, &PlanOptions::default()) {
            Ok(p) => p.unsolved,
            Err(PlanError::Unsolvable { unsolved, .. }) => unsolved,
            Err(_) => continue,
        };
        for u in &unsolved {
            seen.insert(u.refusal.kind());
            let m = &u.reason;
            for bad in ["violated by -", "arm arm", " t=", "{ ", "Some(", "<goal"] {
                assert!(!m.contains(bad), "scene {k}: {bad:?} in {m}");
            }
            if u.refusal.kind() == "collides" {
                assert!(
                    m.contains("waypoint") || m.contains(" s into ") || m.contains("park"),
                    "{m}"
                );
            }
            assert_json(u, u.refusal.kind());
        }
    }
    assert!(
        seen.len() >= 2,
        "the scenes refuse in several ways: {seen:?}"
    );
}
