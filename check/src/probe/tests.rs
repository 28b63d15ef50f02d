//! The probe's tests: free poses found on the open table (both robots),
//! none under a hand's perimeter or for a piece wider than the opening,
//! typed errors, and the grasp rule against the planner's.

use super::*;
use crate::scene;
use afford_planner::scenario::{Hand, default_scenario};

fn iiwa() -> RobotModel {
    RobotModel::builtin("kuka_iiwa14").unwrap()
}

#[test]
fn a_piece_on_the_open_table_has_free_poses() {
    let (s, robot) = (default_scenario().unwrap(), iiwa());
    let probe = Probe::new(&robot, ProbeSettings::default()).unwrap();
    let found = probe.free_poses(&s, "blue-square-1", "left box").unwrap();
    let found = found.expect("free poses on the open table");
    assert_eq!(found.arm, "arm");
    let arm = robot.arm("arm").unwrap();
    for q in [&found.grasp, &found.above, &found.release] {
        assert!(arm.within_limits(&arm.extract(q), 0.0));
    }
    assert_ne!(found.grasp, found.release);
}

/// The default scene under the Care-O-bot's calibration
/// (examples/cob4-sort-blue-squares.yaml): the torso is part of each
/// arm's chain.
#[test]
fn the_care_o_bot_finds_free_poses_on_the_open_table() {
    let mut s = default_scenario().unwrap();
    s.robot.model = "care_o_bot4".into();
    s.camera.pixel_to_base = [[0.0, -0.001, 0.88], [-0.001, 0.0, 0.32]];
    s.camera.table_z = 0.75;
    let robot = RobotModel::builtin("care_o_bot4").unwrap();
    let probe = Probe::new(&robot, ProbeSettings::default()).unwrap();
    let found = probe.free_poses(&s, "blue-square-1", "left box").unwrap();
    let found = found.expect("free poses on the open table");
    let arm = robot.arm(&found.arm).unwrap();
    assert_eq!(arm.dof(), 9);
    assert!(arm.within_limits(&arm.extract(&found.release), 0.0));
}

#[test]
fn a_target_inside_a_hands_perimeter_has_no_free_poses() {
    let (mut s, robot) = (default_scenario().unwrap(), iiwa());
    // blue-square-1 is [100, 80, 40, 40]: a hand 5 px (3 mm) to its
    // left puts every grasp, at either yaw, inside the hand's 0.10 m.
    s.hands.push(Hand {
        name: "hand-1".into(),
        bbox: [40.0, 60.0, 55.0, 60.0].into(),
        height: 0.08,
    });
    let probe = Probe::new(&robot, ProbeSettings::default()).unwrap();
    let found = probe.free_poses(&s, "blue-square-1", "left box").unwrap();
    assert_eq!(found, None);
    let elsewhere = probe.free_poses(&s, "blue-square-2", "right box").unwrap();
    assert!(
        elsewhere.is_some(),
        "a piece far from the hand still has them"
    );
}

#[test]
fn a_piece_wider_than_the_opening_both_ways_has_no_free_poses() {
    let (mut s, robot) = (default_scenario().unwrap(), iiwa());
    // 160 px = 0.10 m a side; the iiwa's gripper opens 0.08 m.
    s.objects[0].bbox = [80.0, 60.0, 160.0, 160.0].into();
    let probe = Probe::new(&robot, ProbeSettings::default()).unwrap();
    let name = s.objects[0].name.clone();
    assert_eq!(probe.free_poses(&s, &name, "left box").unwrap(), None);
}

#[test]
fn a_piece_longer_than_the_goal_has_no_release_and_no_free_poses() {
    let (mut s, robot) = (default_scenario().unwrap(), iiwa());
    // 200 x 40 px = 0.125 x 0.025 m, alone on the table; the left box is
    // 0.075 m a side.
    s.objects.truncate(1);
    s.objects[0].bbox = [100.0, 80.0, 200.0, 40.0].into();
    let probe = Probe::new(&robot, ProbeSettings::default()).unwrap();
    let name = s.objects[0].name.clone();
    assert_eq!(probe.free_poses(&s, &name, "left box").unwrap(), None);
    // 0.15 x 0.10 m: it fits.
    s.goals[0].bbox = [20.0, 260.0, 240.0, 160.0].into();
    assert!(probe.free_poses(&s, &name, "left box").unwrap().is_some());
}

#[test]
fn unknown_names_are_typed_errors() {
    let (s, robot) = (default_scenario().unwrap(), iiwa());
    let probe = Probe::new(&robot, ProbeSettings::default()).unwrap();
    let object = probe.free_poses(&s, "no-such-piece", "left box");
    assert_eq!(
        object,
        Err(ProbeError::UnknownObject("no-such-piece".into()))
    );
    let goal = probe.free_poses(&s, "blue-square-1", "no box");
    assert_eq!(goal, Err(ProbeError::UnknownGoal("no box".into())));
    let none = ProbeSettings {
        restarts: 0,
        ..ProbeSettings::default()
    };
    assert!(matches!(
        Probe::new(&robot, none),
        Err(ProbeError::Settings(_))
    ));
    let nan = ProbeSettings {
        above: f64::NAN,
        ..ProbeSettings::default()
    };
    let e = Probe::new(&robot, nan).err().map(|e| e.to_string());
    assert_eq!(
        e.as_deref(),
        Some("probe settings: above must be between 0 and 1 m, got NaN")
    );
}

/// The re-implemented grasp rule gives the planner's grasp height (the
/// tool centre point where the planned gripper closes), and the
/// settings are the planner's documented defaults.
#[test]
fn grasp_height_and_settings_are_the_planners() {
    let (s, robot) = (default_scenario().unwrap(), iiwa());
    let lift = afford_planner::lift::LiftSettings::default();
    let ours = ProbeSettings::default();
    assert_eq!(
        [
            ours.min_grasp_height,
            ours.tip_clearance,
            ours.palm_clearance
        ],
        [
            lift.min_grasp_height,
            lift.tip_clearance,
            lift.palm_clearance
        ]
    );
    assert_eq!(
        [ours.min_grip_depth, ours.release_clearance],
        [lift.min_grip_depth, lift.release_clearance]
    );
    let plan = afford_planner::plan(&s, &afford_planner::PlanOptions::default()).unwrap();
    let sub = &plan.subgoals[0];
    let waypoints = &sub.waypoints.as_ref().unwrap().waypoints;
    let (close, _) = sub.waypoints.as_ref().unwrap().gripper_switches();
    let planned = waypoints[close - 1].position[2];
    let probe = Probe::new(&robot, ours).unwrap();
    let target = s.object_index(&sub.object).unwrap();
    let piece = &scene::pieces(&s)[target];
    let bottom = piece.pose.translation.vector.z - piece.half[2];
    let height = probe.grasp_height(&s, piece).unwrap();
    assert!(
        (bottom + height - planned).abs() < 1e-9,
        "{} against {planned}",
        bottom + height
    );
}
