//! The monitor as a library: braking is a timed stop along the plan's own
//! samples within the joint limits; relevant perturbations are all
//! detected and irrelevant ones never trigger (a small run of the bench,
//! relevance by construction); planning from a mid-execution state starts
//! exactly there and carries a held object on without a second grasp.

use afford_kinematics::RobotModel;
use afford_planner::bench::monitor::{MonitorBenchConfig, run};
use afford_planner::monitor::execute::{Cursor, step, stopping_point};
use afford_planner::scenario::default_scenario;
use afford_planner::trajectory::{GripperCommand, arm_limits};
use afford_planner::{HeldObject, MidExecution, PlanOptions, Planner};

#[test]
fn monitor_braking_stops_on_plan_samples_within_the_joint_limits() {
    let scenario = default_scenario().expect("default scenario");
    let plan = Planner::default().plan(&scenario).expect("plan");
    let sub = &plan.subgoals[0];
    let motion = sub.trajectory.as_ref().expect("timed");
    let robot = RobotModel::builtin("kuka_iiwa14").expect("robot");
    let limits = arm_limits(&robot, robot.arm(sub.arm.as_deref().unwrap()).expect("arm"));
    // Full speed to a third of the way, then brake.
    let mut cursor = Cursor::START;
    while cursor.s < motion.duration() / 3.0 {
        cursor = step(motion, &limits, &cursor, 1.0, 0.01).cursor;
    }
    let stop = stopping_point(motion, &limits, &cursor, 0.01, 100_000);
    assert_eq!(stop.sigma, 0.0, "comes to rest");
    assert!(stop.s > cursor.s, "brakes along the path, not on the spot");
    let mut braking = cursor.clone();
    let mut previous = motion.points[braking.index].velocities.clone();
    while braking.sigma > 0.0 {
        let step = step(motion, &limits, &braking, 0.0, 0.01);
        let planned = &motion.points[step.cursor.index];
        assert_eq!(
            step.point.positions, planned.positions,
            "never leaves the path"
        );
        for (j, before) in previous.iter().enumerate() {
            assert!(step.point.velocities[j].abs() <= limits.velocity[j]);
            assert!(step.point.accelerations[j].abs() <= limits.acceleration[j]);
            let change = (step.point.velocities[j] - before * braking.sigma) / step.duration;
            assert!(
                change.abs() <= limits.acceleration[j] * 1.0001,
                "joint {j}: {change}"
            );
        }
        previous = planned.velocities.clone();
        braking = step.cursor;
    }
    assert_eq!(braking.index, stop.index);
    // At rest with the command 0 the robot stays.
    let rest = step(motion, &limits, &braking, 0.0, 0.01);
    assert_eq!(rest.cursor.index, braking.index);
    assert!(rest.point.velocities.iter().all(|v| *v == 0.0));
}

#[test]
fn monitor_relevant_always_detected_irrelevant_never_triggers() {
    let report = run(&MonitorBenchConfig { scenes: 4, seed: 7 }, |_| {}, None);
    assert!(report.relevant >= 20, "{report:?}");
    assert!(report.irrelevant >= 5, "{report:?}");
    assert_eq!(report.detected, report.relevant, "{report:?}");
    assert_eq!(report.false_triggers, 0, "{report:?}");
}

#[test]
fn monitor_plan_from_holding_carries_on_without_a_second_grasp() {
    let scenario = default_scenario().expect("default scenario");
    let options = PlanOptions::default();
    let plan = Planner::new(options.clone()).plan(&scenario).expect("plan");
    let sub = &plan.subgoals[0];
    let motion = sub.trajectory.as_ref().expect("timed");
    let close = motion
        .gripper
        .iter()
        .find(|e| e.command == GripperCommand::Close)
        .expect("close");
    let open = motion
        .gripper
        .iter()
        .find(|e| e.command == GripperCommand::Open)
        .expect("open");
    // Stopped halfway through the carry, holding.
    let t = 0.5 * (close.end + open.start);
    let at = motion
        .points
        .iter()
        .find(|p| p.time_from_start >= t)
        .expect("sample");
    let grasp = motion
        .points
        .iter()
        .find(|p| p.time_from_start >= close.start)
        .expect("grasp");
    let robot = RobotModel::builtin("kuka_iiwa14").expect("robot");
    let arm = robot.arm(sub.arm.as_deref().unwrap()).expect("arm");
    let mut joints = plan.start_state.as_ref().expect("start").positions.clone();
    arm.insert(&mut joints, &at.positions);
    let object = scenario.object_index(&sub.object).expect("object");
    let from = MidExecution {
        joints: joints.clone(),
        held: Some(HeldObject {
            object: sub.object.clone(),
            grasped_box: scenario.objects[object].bbox,
            arm: arm.name.clone(),
            grasp: grasp.positions.clone(),
        }),
    };
    let goals = [afford_planner::instruction::SubGoal {
        object: sub.object.clone(),
        goal: sub.goal.clone(),
    }];
    let replanned = Planner::new(options)
        .plan_from(&scenario, &goals, &from)
        .expect("replan");
    assert!(replanned.unsolved.is_empty(), "{:?}", replanned.unsolved);
    let carry = replanned.subgoals[0].trajectory.as_ref().expect("timed");
    assert_eq!(
        carry.points[0].positions, at.positions,
        "starts exactly where it stopped"
    );
    let commands: Vec<GripperCommand> = carry.gripper.iter().map(|e| e.command).collect();
    assert_eq!(commands, [GripperCommand::Open], "no second grasp");
    assert_eq!(replanned.start_state.expect("start").positions, joints);
}
