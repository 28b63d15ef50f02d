//! Tasks a programmer could do by hand that the grid used to refuse: each
//! plans, passes the independent check and the physical replay, and runs
//! to completion under the valid-policy detector without a false trigger.
//! - A gap between two grown boxes that the target-sized cells round shut
//!   (`no_route` with no cell blocked on an open table): the grid passes
//!   over what is not sensitive, the carry rises over it.
//! - A piece lying in a goal box: picked from the box's floor, the box it
//!   lies in kept like the goal being entered.
//! - A gripper over a low hand's grown footprint but above its 3-D
//!   perimeter: the learner starts from the free cell nearest the gripper.
//! - A Care-O-bot leaving park beside a tall tray: the cheaper arm folds
//!   into the torso, the other needs the tool turned at the grasp.
//! - A wrist at its joint limit at the grasp: the tool turned half a turn
//!   grasps within every limit.

use afford::planner::grid::{CellCode, GridRequest, Obstacles, StateGrid};
use afford::planner::scenario;

use crate::util::{afford_with_path, fixture, scratch_dir};

/// Plans the case (exit `code`: 1 when a sub-goal is rightly refused),
/// checks the plan with physics (exit 0) and runs it (outcome `completed`,
/// no event); returns the plan's JSON.
fn planned_checked_and_run(case: &str, code: i32) -> serde_json::Value {
    let dir = scratch_dir(&format!("false-refusals-{case}"));
    let path = fixture(&format!("cases/{case}.yaml"));
    let plan_path = dir.join("plan.json");
    afford_with_path(&["plan"], &path, &["-o", plan_path.to_str().unwrap()]).assert_code(code);
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&plan_path).unwrap()).unwrap();
    let check = afford_with_path(
        &["check"],
        &path,
        &[plan_path.to_str().unwrap(), "--physics"],
    );
    check.assert_code(0).assert_no_panic();
    let run = afford_with_path(&["run"], &path, &[]);
    run.assert_code(0).assert_no_panic();
    let run = run.json();
    assert_eq!(run["outcome"], "completed", "{run}");
    assert_eq!(run["events"].as_array().map(Vec::len), Some(0), "{run}");
    plan
}

#[test]
fn no_route_on_an_open_table_where_cells_round_a_gap_shut() {
    // The red circle no longer fits beside it: the box is full.
    let plan = planned_checked_and_run("no-route-on-open-table", 1);
    assert_eq!(plan["unsolved"][0]["refusal"]["kind"], "goal_full");
    let moved: Vec<(&str, &str)> = plan["subgoals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s["object"].as_str().unwrap(), s["goal"].as_str().unwrap()))
        .collect();
    assert!(moved.contains(&("red-cube-1", "right box")), "{moved:?}");
    let cube = plan["subgoals"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["object"] == "red-cube-1")
        .unwrap();
    assert_eq!(cube["grid"]["obstacles"], "sensitive", "{}", cube["grid"]);
}

#[test]
fn a_piece_lying_in_a_goal_box_is_picked_from_its_floor() {
    let plan = planned_checked_and_run("regrasp-from-inside-a-goal-box", 0);
    assert_eq!(plan["subgoals"][0]["object"], "blue-square-1");
    assert_eq!(plan["subgoals"][0]["goal"], "left box");
}

/// The grid that passes over things still paints the sensitive objects
/// (and hands); the paper's grid paints every other object and goal.
#[test]
fn the_grid_passing_over_things_never_passes_over_a_sensitive_object() {
    let s = scenario::load(&fixture("cases/no-route-on-open-table.yaml")).unwrap();
    let object = s.object_index("red-cube-1").unwrap();
    let goal = s.goal_index("right box").unwrap();
    let req = GridRequest {
        object,
        goal,
        gripper: s.robot.start.expect("the case gives robot.start"),
    };
    let code_under = |mode: Obstacles, name: &str| {
        let grid = StateGrid::build_painting(&s, req, Default::default(), mode);
        let o = &s.objects[s.object_index(name).unwrap()];
        grid.code(grid.cell_at(o.bbox.centre()))
    };
    assert_eq!(
        code_under(Obstacles::All, "red-circle-1"),
        CellCode::Obstacle
    );
    assert_eq!(
        code_under(Obstacles::Sensitive, "red-circle-1"),
        CellCode::Empty
    );
    for mode in [Obstacles::All, Obstacles::Sensitive] {
        assert_eq!(code_under(mode, "green-hexagon-1"), CellCode::Obstacle);
    }
}

#[test]
fn gripper_over_a_low_hands_footprint_is_not_refused() {
    let plan = planned_checked_and_run("gripper-over-a-low-hands-footprint", 0);
    let subgoal = &plan["subgoals"][0];
    let grid = &subgoal["grid"];
    let cell_of = |k: usize, px: f64| {
        ((px - grid["origin_px"][k].as_f64().unwrap()) / grid["cell_px"][k].as_f64().unwrap())
            .floor() as u64
    };
    // robot.start is (320, 460): the learner starts beside it, off the hand's cells.
    let under_gripper = [cell_of(1, 460.0), cell_of(0, 320.0)];
    let first = [0, 1].map(|k| subgoal["cells"][0][k].as_u64().unwrap());
    assert_ne!(first, under_gripper, "{subgoal}");
    assert!(subgoal["trajectory"].is_object(), "{subgoal}");
}

#[test]
fn care_o_bot_leaving_park_beside_a_tall_tray_is_not_refused() {
    let plan = planned_checked_and_run("cob4-park-exit", 0);
    let subgoal = &plan["subgoals"][0];
    assert_eq!(subgoal["object"], "orange-triangle-2", "{subgoal}");
    assert!(subgoal["trajectory"].is_object(), "{subgoal}");
}

/// The arm-motion budget is what bounds a sub-goal's search: with room for
/// one arm motion the same sub-goal is refused with that motion's hit.
#[test]
fn a_sub_goal_tries_no_more_arm_motions_than_its_budget() {
    use afford::planner::{PlanOptions, Planner};
    let s = scenario::load(&fixture("cases/cob4-park-exit.yaml")).unwrap();
    let options = PlanOptions {
        max_arm_motions: 1,
        ..PlanOptions::default()
    };
    let refused = Planner::new(options).plan(&s).unwrap_err().to_string();
    assert!(refused.contains("collides"), "{refused}");
    assert!(Planner::new(PlanOptions::default()).plan(&s).is_ok());
}

#[test]
fn a_wrist_at_its_joint_limit_at_the_grasp_turns_the_tool_instead_of_refusing() {
    // black-triangle-1 rightly stays refused (its held piece enters a box's
    // perimeter at the grasp); black-triangle-2 needed joint_a7 beyond its
    // limit at the grasp until the tool was turned.
    let plan = planned_checked_and_run("iiwa-wrist-limit-at-grasp", 1);
    let moved: Vec<&str> = (plan["subgoals"].as_array().unwrap().iter())
        .map(|s| s["object"].as_str().unwrap())
        .collect();
    assert_eq!(moved, ["black-triangle-2"], "{plan}");
    let kinds: Vec<&str> = (plan["unsolved"].as_array().unwrap().iter())
        .map(|u| u["refusal"]["kind"].as_str().unwrap())
        .collect();
    assert!(!kinds.contains(&"joint_limit"), "{kinds:?}");
}
