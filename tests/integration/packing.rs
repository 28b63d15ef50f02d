//! Packing released pieces into goal boxes: a round piece
//! packs by its stadium, not its bounding box, a chained piece leaves room
//! for the later ones, the monitor agrees on the spots, and the independent
//! check agrees on its own geometry (tests/fixtures/packing/).

use afford::collision::RobotGeometry;
use afford::kinematics::RobotModel;
use afford::planner::clearance::gripper_reach;
use afford::planner::grid::{GridRequest, StateGrid};
use afford::planner::monitor::policy::{Remaining, check};
use afford::planner::place::Room;
use afford::planner::{PlanOptions, Planner, scenario};

use crate::util::{afford_with_path, fixture, plan_to_file, scratch_dir};

/// Scene 265 of `afford bench transits --seed 1`: the round piece fits only
/// in the corner the square's box leaves; both sub-goals plan chained, and
/// `afford check --physics` accepts the plan (placement by its own
/// cylinders, the replay's pieces in the box).
#[test]
fn round_piece_packs_into_the_corner_beside_a_square() {
    plan_and_land_every_piece("place-round-piece-beside-a-square", 2);
}

/// Plans the packing fixture `name`, checks that `pieces` sub-goals were
/// planned and that `afford check --physics` passes with every piece in
/// its goal; returns the plan.
fn plan_and_land_every_piece(name: &str, pieces: usize) -> serde_json::Value {
    let scene = fixture(&format!("packing/{name}.yaml"));
    let dir = scratch_dir(&format!("packing-{name}"));
    let (path, plan) = plan_to_file(&scene, &dir);
    let subgoals = plan["subgoals"].as_array().expect("sub-goals");
    assert_eq!(subgoals.len(), pieces, "every sub-goal planned");
    let checked = afford_with_path(
        &["check", scene.to_str().expect("UTF-8")],
        &path,
        &["--physics", "--json"],
    );
    checked.assert_code(0);
    let report = checked.json();
    assert_eq!(report["violations"], serde_json::json!([]), "{report}");
    let targets = report["physics"]["targets"].as_array().expect("targets");
    assert_eq!(targets.len(), pieces);
    assert!(targets.iter().all(|t| t["in_goal"] == true), "{targets:?}");
    plan
}

/// Scene 195 of `afford bench transits --seed 1`: three round pieces fit
/// the right box only as the first two in opposite corners of one side and
/// the large one between them; the second's spot leaves room for the third
/// (bottom-left fill alone put it beside the first: "right box is full"),
/// every sub-goal plans chained and `afford check --physics` accepts the
/// plan.
#[test]
fn chained_round_pieces_leave_room_for_the_later_ones() {
    let plan = plan_and_land_every_piece("chained-round-pieces-leave-room", 4);
    assert_eq!(
        plan["unsolved"],
        serde_json::json!([]),
        "{}",
        plan["unsolved"]
    );
}

/// The monitor's valid-policy check rebuilds each sub-goal's grid on the
/// scene as planned (the same fixture, nothing changed): its release spot
/// is the plan's to the bit, since it leaves room for the same later
/// pieces (`SubgoalPlan::room_for`), and the rest of every policy passes.
/// Without them green-circle-2's spot would be the one beside
/// green-circle-1.
#[test]
fn monitor_rebuilds_the_spot_that_leaves_room() {
    let path = fixture("packing/chained-round-pieces-leave-room.yaml");
    let scenario = scenario::load(&path).expect("loads");
    let options = PlanOptions::default().for_scenario_file(&path);
    let plan = Planner::new(options).plan(&scenario).expect("plans");
    assert!(plan.unsolved.is_empty(), "{:?}", plan.unsolved);
    let robot = RobotModel::builtin("care_o_bot4").expect("robot");
    let geometry = RobotGeometry::new(&robot).expect("geometry");
    let opening = Some(
        gripper_reach(&robot, &geometry)
            .expect("gripper")
            .finger_half_extent,
    );
    let mut scene = scenario.clone();
    let mut moved = Vec::new();
    for sub in &plan.subgoals {
        let (object, goal) = (
            scene.object_index(&sub.object).expect("object"),
            scene.goal_index(&sub.goal).expect("goal"),
        );
        let remaining = Remaining {
            plan: sub,
            done: 0,
            holding: false,
            target_box: scene.objects[object].bbox,
            opening,
        };
        assert_eq!(check(&scene, &remaining), Ok(()), "{}", sub.object);
        let request = GridRequest {
            object,
            goal,
            gripper: scene.objects[object].bbox.centre(),
        };
        let spot = |later: &[usize]| {
            let grid = StateGrid::build_placing(&scene, request, Room { opening, later });
            grid.release.expect("a spot").spot
        };
        let later: Vec<usize> = sub
            .room_for
            .iter()
            .map(|name| scene.object_index(name).expect("object"))
            .collect();
        assert_eq!(spot(&later), sub.release_px, "{}", sub.object);
        if spot(&[]) != sub.release_px {
            moved.push(sub.object.clone());
        }
        let b = &mut scene.objects[object].bbox;
        *b = b.centred_at(sub.release_px);
    }
    assert_eq!(moved, ["green-circle-2"]);
}
