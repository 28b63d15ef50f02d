//! Where the plan starts: the file's `start_state` must name every robot
//! joint in the robot's order, and follow the scenario by the convention
//! `afford plan` uses:
//! - `robot.joints` given: equal to them;
//! - `robot.start` alone: some arm's tool points straight down (within
//!   [`START_TILT`]) over `robot.start`, within one grid cell (the first
//!   sub-goal's target box) of it; every other arm with a park posture is
//!   parked and every joint of no arm is at home;
//! - neither: home, with every arm that has a park posture parked.

use afford_kinematics::RobotModel;
use afford_planner::Scenario;

use crate::chain::Kinematics;
use crate::file::StartState;
use crate::format::MAX_ABS_POSITION;

/// Largest angle between the tool's approach axis and straight down at a
/// start over `robot.start`, rad.
pub const START_TILT: f64 = 0.01;
/// Largest difference from a stated joint value, rad or m.
pub const START_TOLERANCE: f64 = 1e-9;

/// What the scenario says about the robot's state at t = 0 (README
/// "Scenario format").
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum StartRule {
    /// Joint values by name.
    Joints(Vec<(String, f64)>),
    /// The tool over this pixel (u, v).
    Pixel([f64; 2]),
    /// Home with arms parked.
    Home,
}

impl StartRule {
    /// The rule of a scenario on `robot`: its joint state when given; else
    /// the tool over `robot.start` when some arm has no park posture (an arm
    /// with one waits parked: the Care-O-bot starts at home, parked, and
    /// `robot.start` only places the grid's start cell); else home, parked.
    pub(crate) fn of(s: &Scenario, robot: &RobotModel) -> Self {
        match (&s.robot.joints, s.robot.start) {
            (Some(joints), _) => {
                Self::Joints(joints.iter().map(|(n, &v)| (n.clone(), v)).collect())
            }
            (None, Some(px)) if robot.arms().iter().any(|a| a.park.is_empty()) => Self::Pixel(px),
            _ => Self::Home,
        }
    }
}

/// What is wrong with the scenario's `robot.joints` for `robot`, as
/// (field, message): a joint of the robot not given, a name that is no
/// joint of it, a value outside the joint's limits (by more than
/// [`START_TOLERANCE`]; a continuous joint takes any value the scenario
/// accepts). Empty when `robot.joints` is absent or fits. The start rule
/// compares the plan with these values, so a value the robot cannot take
/// would let the check follow a motion from it (a 100 rad torso asked for
/// minutes of collision queries).
pub fn scenario_joint_issues(s: &Scenario, robot: &RobotModel) -> Vec<(String, String)> {
    let Some(given) = &s.robot.joints else {
        return Vec::new();
    };
    let field = |name: &str| format!("robot.joints.{name}");
    let joints = robot.joints();
    let missing = joints
        .iter()
        .filter(|j| !given.contains_key(&j.name))
        .map(|j| {
            let message = format!("missing: the robot {} has this joint", robot.name());
            (field(&j.name), message)
        });
    let wrong = given.iter().filter_map(|(name, &v)| {
        let message = match robot.joint_index(name).map(|i| &joints[i]) {
            None => format!("is not a joint of the robot {}", robot.name()),
            Some(j) if !(v >= j.lower - START_TOLERANCE && v <= j.upper + START_TOLERANCE) => {
                format!("{v} is outside the joint limits {} .. {}", j.lower, j.upper)
            }
            Some(_) => return None,
        };
        Some((field(name), message))
    });
    missing.chain(wrong).collect()
}

/// The start state's values in robot joint order; `Err` says what is malformed.
pub(crate) fn state(robot: &RobotModel, start: Option<&StartState>) -> Result<Vec<f64>, String> {
    let s = start.ok_or("start_state is missing: the plan must say where the robot is at t = 0")?;
    let names: Vec<&str> = robot.joints().iter().map(|j| j.name.as_str()).collect();
    if s.joint_names != names {
        return Err(format!(
            "start_state.joint_names {:?} are not the robot's joints {names:?}",
            s.joint_names
        ));
    }
    if s.positions.len() != names.len() {
        return Err(format!(
            "start_state.positions holds {} values for {} joints",
            s.positions.len(),
            names.len()
        ));
    }
    if let Some((j, v)) = s
        .positions
        .iter()
        .enumerate()
        .find(|(_, v)| !crate::format::within(**v, MAX_ABS_POSITION))
    {
        return Err(format!(
            "start_state.positions[{j}] ({}) is {v}: not a finite value within ±{MAX_ABS_POSITION:e}",
            names[j]
        ));
    }
    Ok(s.positions.clone())
}

/// Problems with a well-formed start state `q` under `rule`; `cell` is the
/// grid cell size (w, l) in pixels.
pub(crate) fn check(
    rule: &StartRule,
    s: &Scenario,
    robot: &RobotModel,
    kin: &Kinematics,
    q: &[f64],
    cell: [f64; 2],
) -> Vec<String> {
    let mut expected: Vec<Option<f64>> = vec![None; q.len()];
    match rule {
        StartRule::Joints(given) => {
            for (name, v) in given {
                if let Some(j) = robot.joint_index(name) {
                    expected[j] = Some(*v);
                }
            }
        }
        StartRule::Home => {
            for (j, e) in expected.iter_mut().enumerate() {
                *e = Some(parked_home(robot)[j]);
            }
        }
        StartRule::Pixel(pixel) => match over_pixel(s, robot, kin, q, *pixel, cell) {
            Ok(arm) => expected = others_at_rest(robot, arm),
            Err(why) => return vec![why],
        },
    }
    let joints = robot.joints();
    expected
        .iter()
        .zip(q)
        .enumerate()
        .filter_map(|(j, (e, &v))| {
            let want = (*e)?;
            ((v - want).abs() > START_TOLERANCE).then(|| {
                format!(
                    "start_state has {} = {v:.6}, but the scenario's robot {} there: {want:.6}",
                    joints[j].name,
                    match rule {
                        StartRule::Joints(_) => "states",
                        _ => "rests",
                    }
                )
            })
        })
        .collect()
}

/// Home with every park posture applied.
fn parked_home(robot: &RobotModel) -> Vec<f64> {
    let mut q = robot.home().to_vec();
    for &(i, v) in robot.arms().iter().flat_map(|a| &a.park) {
        q[i] = v;
    }
    q
}

/// Expected values with arm `active` free: other arms parked, joints of no arm at home.
fn others_at_rest(robot: &RobotModel, active: usize) -> Vec<Option<f64>> {
    let mut expected: Vec<Option<f64>> = robot.home().iter().map(|&v| Some(v)).collect();
    for arm in robot.arms() {
        for &j in &arm.joint_indices {
            expected[j] = None;
        }
    }
    for (_, arm) in robot
        .arms()
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != active)
    {
        for &(j, v) in &arm.park {
            expected[j] = Some(v);
        }
    }
    for &j in &robot.arms()[active].joint_indices {
        expected[j] = None;
    }
    expected
}

/// The arm whose tool points down over `pixel` within a cell, or why none does.
fn over_pixel(
    s: &Scenario,
    robot: &RobotModel,
    kin: &Kinematics,
    q: &[f64],
    pixel: [f64; 2],
    cell: [f64; 2],
) -> Result<usize, String> {
    let poses = kin.link_poses(q);
    let mut nearest = Vec::new();
    for (k, arm) in robot.arms().iter().enumerate() {
        let Ok(link) = robot.link_index(&arm.tool_link) else {
            continue;
        };
        let pose = &poses[link];
        let down = (pose.rotation * nalgebra::Vector3::z()).dot(&-nalgebra::Vector3::z());
        let tilt = down.clamp(-1.0, 1.0).acos();
        let t = pose.translation.vector;
        let [u, v] = s.base_to_pixel([t.x, t.y]);
        let cells = [
            (u - pixel[0]).abs() / cell[0],
            (v - pixel[1]).abs() / cell[1],
        ];
        if tilt <= START_TILT && cells[0] <= 1.0 && cells[1] <= 1.0 {
            return Ok(k);
        }
        nearest.push(format!(
            "the tool of the arm '{}' is over pixel ({u:.0}, {v:.0}), {:.1} cells away, tilted {:.1}° from straight down",
            arm.name,
            cells[0].max(cells[1]),
            tilt.to_degrees()
        ));
    }
    Err(format!(
        "no arm's tool points down over robot.start ({:.0}, {:.0}) within one grid cell ({:.0}x{:.0} px) at t = 0: {}",
        pixel[0],
        pixel[1],
        cell[0],
        cell[1],
        nearest.join("; ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup() -> (Scenario, RobotModel, Kinematics) {
        let s = afford_planner::scenario::default_scenario().unwrap();
        let robot = RobotModel::builtin("kuka_iiwa14").unwrap();
        let kin = Kinematics::new(&robot).unwrap();
        (s, robot, kin)
    }

    #[test]
    fn home_rule_wants_home_with_parks() {
        let (s, robot, kin) = setup();
        let mut q = robot.home().to_vec();
        assert!(check(&StartRule::Home, &s, &robot, &kin, &q, [40.0, 40.0]).is_empty());
        q[0] += 0.1;
        let found = check(&StartRule::Home, &s, &robot, &kin, &q, [40.0, 40.0]);
        assert_eq!(found.len(), 1);
        assert!(found[0].contains("joint_a1"), "{}", found[0]);
    }

    #[test]
    fn joints_rule_wants_the_stated_values() {
        let (s, robot, kin) = setup();
        let q = vec![0.1; robot.dof()];
        let given: Vec<(String, f64)> = robot
            .joints()
            .iter()
            .map(|j| (j.name.clone(), 0.1))
            .collect();
        assert!(
            check(
                &StartRule::Joints(given.clone()),
                &s,
                &robot,
                &kin,
                &q,
                [40.0, 40.0]
            )
            .is_empty()
        );
        let mut other = given;
        other[6].1 = 7.0;
        let found = check(
            &StartRule::Joints(other),
            &s,
            &robot,
            &kin,
            &q,
            [40.0, 40.0],
        );
        assert!(
            found.len() == 1 && found[0].contains("joint_a7"),
            "{found:?}"
        );
    }

    #[test]
    fn pixel_rule_wants_the_tool_down_over_the_pixel() {
        let (s, robot, kin) = setup();
        let q = robot.home().to_vec();
        let tool = kin.link_poses(&q)[robot.link_index("tcp").unwrap()]
            .translation
            .vector;
        let under = s.base_to_pixel([tool.x, tool.y]);
        let near = StartRule::Pixel([under[0] + 30.0, under[1] - 30.0]);
        assert!(check(&near, &s, &robot, &kin, &q, [40.0, 40.0]).is_empty());
        let far = StartRule::Pixel([under[0] + 50.0, under[1]]);
        let found = check(&far, &s, &robot, &kin, &q, [40.0, 40.0]);
        assert!(
            found.len() == 1 && found[0].contains("1.2 cells away"),
            "{found:?}"
        );
    }
}
