//! Transits and the two arms: an arm stays where its
//! sub-goal left it, the next sub-goal starts there, and the plan's last
//! sub-goal parks its arm.

use afford::kinematics::RobotModel;
use afford::planner::{PlanOptions, plan, scenario};

use crate::util::repo;

/// True when every joint the arm's park posture sets is at its park value.
fn parked(robot: &RobotModel, arm: &str, names: &[String], q: &[f64]) -> bool {
    let arm = robot.arm(arm).expect("arm");
    arm.park.iter().all(|&(i, v)| {
        let name = &robot.joints()[i].name;
        let k = names
            .iter()
            .position(|n| n == name)
            .expect("park joint of the arm");
        (q[k] - v).abs() < 1e-9
    })
}

#[test]
fn care_o_bot_arm_stays_out_of_park_between_subgoals_and_parks_at_the_end() {
    let path = repo().join("examples/cob4-sort-blue-squares.yaml");
    let scenario = scenario::load(&path).expect("loads");
    let options = PlanOptions {
        base_dir: repo().join("examples"),
        ..PlanOptions::default()
    };
    let plan = plan(&scenario, &options).expect("plans");
    assert!(plan.unsolved.is_empty(), "{:?}", plan.unsolved);
    assert!(plan.subgoals.len() >= 2);
    let robot = RobotModel::builtin("care_o_bot4").expect("robot");
    let ends: Vec<bool> = plan
        .subgoals
        .iter()
        .map(|s| {
            let names = s.joint_names.as_ref().expect("joint names");
            let last = s
                .trajectory
                .as_ref()
                .expect("trajectory")
                .points
                .last()
                .expect("a sample");
            parked(
                &robot,
                s.arm.as_deref().expect("arm"),
                names,
                &last.positions,
            )
        })
        .collect();
    let (last, between) = ends.split_last().expect("sub-goals");
    assert!(*last, "the last sub-goal parks its arm");
    assert!(
        between.iter().all(|p| !p),
        "arms stay out of park between sub-goals: {ends:?}"
    );
    // The next sub-goal starts where the previous one stopped.
    for pair in plan.subgoals.windows(2) {
        let end = &pair[0]
            .trajectory
            .as_ref()
            .unwrap()
            .points
            .last()
            .unwrap()
            .positions;
        let start = &pair[1].trajectory.as_ref().unwrap().points[0].positions;
        if pair[0].arm == pair[1].arm {
            assert_eq!(end, start);
        }
    }
}
