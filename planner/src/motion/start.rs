//! The robot's state at t = 0: where the first sub-goal's
//! trajectory starts and which pixel its grid starts from. A robot stack
//! knows its joint state (`robot.joints`); without it a documented rule
//! stands in:
//!
//! | `robot.joints` | `robot.start` | state at t = 0 | gripper pixel |
//! |---|---|---|---|
//! | given | absent | the given joints | the tool of the arm nearest the image centre, by forward kinematics, clamped into the image |
//! | given | given | the given joints; the tool of the arm nearest `robot.start` must lie within one grid cell (the first target's box) of it | `robot.start` |
//! | absent | given | the tool pointing down over `robot.start` at the first sub-goal's carry height and grasp yaw (any yaw when that one is out of reach): the arm nearest the first target among the arms without a park posture, solved by IK from its home posture (deterministic) at any yaw, then turned to the grasp yaw from there, every other arm parked; when every arm has a park posture (Care-O-bot), home with every arm parked | `robot.start` |
//! | absent | absent | home, every arm that has a park posture parked | as in the first row |
//!
//! "Nearest" compares table-plane distances (metres) from an arm's tool, or
//! for the hover the distance from the arm's tool at its home posture to
//! the first target; ties go to the earlier arm. An arm with a park posture
//! never hovers: an IK posture over a pixel near the body is not known to be
//! free of the body, while its park-home transit is checked.

use std::f64::consts::{PI, TAU};

use afford_kinematics::{Arm, IkSettings, IkTarget, RobotModel, Vec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::error::FieldIssue;
use crate::lift::{LiftSettings, carry_height, longer_side_yaw};
use crate::scenario::Scenario;

/// Tolerance (rad or m) on the joint limits for a given joint state, as for
/// the description's home and park postures.
pub const LIMIT_TOLERANCE: f64 = 1e-9;

/// Seed of the random restarts of the hover IK (a fixed seed: the start
/// state never depends on the plan's seed).
const HOVER_IK_SEED: u64 = 0;

/// The robot's state at t = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct StartState {
    /// Whole-robot configuration, in [`RobotModel::joints`] order.
    pub joints: Vec<f64>,
    /// Where the gripper is in the image, pixel (u, v): the first grid's start.
    pub gripper_px: [f64; 2],
}

/// What the rules need to know of the first sub-goal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstSubgoal {
    /// Grid cell size `[w, l]`, pixels (the target's box).
    pub cell_px: [f64; 2],
    /// Carry height above the table top, metres.
    pub carry_height: f64,
    /// Centre pixel of the first target.
    pub target_px: [f64; 2],
    /// Tool yaw of the first grasp (rad, base frame): the yaw of the first
    /// sub-goal's every waypoint.
    pub grasp_yaw: f64,
}

impl FirstSubgoal {
    /// The first sub-goal when it moves `object` (index into the scenario's
    /// objects): the grid cell is the object's box, the carry height the
    /// lifting stage's.
    pub fn moving(scenario: &Scenario, object: usize, lift: &LiftSettings) -> Self {
        let target = &scenario.objects[object].bbox;
        Self {
            cell_px: [target.w, target.l],
            carry_height: carry_height(scenario, object, lift),
            target_px: target.centre(),
            grasp_yaw: longer_side_yaw(scenario, &scenario.objects[object]),
        }
    }
}

/// Problems with `robot.joints` against the robot model, one per joint, each
/// with the field `robot.joints.<name>`: a movable joint not named, a name
/// that is not a movable joint, a value that is not finite or lies outside
/// the joint's limits (a continuous joint takes any finite value). Empty when
/// `robot.joints` is absent or fits.
pub fn check_joints(scenario: &Scenario, robot: &RobotModel) -> Vec<FieldIssue> {
    let Some(given) = &scenario.robot.joints else {
        return Vec::new();
    };
    let field = |name: &str| format!("robot.joints.{name}");
    let mut issues: Vec<FieldIssue> = robot
        .joints()
        .iter()
        .filter(|j| !given.contains_key(&j.name))
        .map(|j| {
            FieldIssue::new(
                field(&j.name),
                format!(
                    "missing: robot.joints must give every movable joint of {}",
                    robot.name()
                ),
            )
        })
        .collect();
    for (name, &value) in given {
        let message = match robot.joint_index(name).map(|i| &robot.joints()[i]) {
            None => format!(
                "is not a movable joint of {} (its joints: {})",
                robot.name(),
                joint_names(robot)
            ),
            Some(_) if !value.is_finite() => {
                format!("must be a finite joint position (rad or m), got {value}")
            }
            Some(joint) if !joint.within(value, LIMIT_TOLERANCE) => format!(
                "{value} is outside the joint limits {} .. {}",
                joint.lower, joint.upper
            ),
            Some(_) => continue,
        };
        issues.push(FieldIssue::new(field(name), message));
    }
    issues
}

/// [`check_joints`] before anything else is read: a scenario that states
/// `robot.joints` has its robot (`robot.model`, from `base_dir`) loaded and
/// the joint state checked against it, so a bad joint state is bad input
/// even when the instruction could not be executed either.
pub fn check_stated_joints(
    scenario: &Scenario,
    base_dir: &std::path::Path,
    packages: &afford_kinematics::PackagePaths,
) -> Result<(), crate::PlanError> {
    if scenario.robot.joints.is_none() {
        return Ok(());
    }
    let robot = RobotModel::load_with(&scenario.robot.model, base_dir, packages)
        .map_err(|e| crate::PlanError::Robot(e.to_string()))?;
    let issues = check_joints(scenario, &robot);
    match issues.is_empty() {
        true => Ok(()),
        false => Err(crate::PlanError::RobotState {
            robot: robot.name().to_string(),
            issues,
        }),
    }
}

/// The robot's state at t = 0 by the rules in the module docs. `Err` lists
/// the bad fields (`robot.joints.<name>`, `robot.start`).
pub fn resolve(
    scenario: &Scenario,
    robot: &RobotModel,
    first: &FirstSubgoal,
    ik: &IkSettings,
) -> Result<StartState, Vec<FieldIssue>> {
    let issues = check_joints(scenario, robot);
    if !issues.is_empty() {
        return Err(issues);
    }
    let spec = &scenario.robot;
    match (&spec.joints, spec.start) {
        (Some(given), start) => {
            let joints: Vec<f64> = robot.joints().iter().map(|j| given[&j.name]).collect();
            let gripper_px = match start {
                Some(px) => agreeing_start(scenario, robot, &joints, px, first.cell_px)?,
                None => seen_gripper(scenario, robot, &joints),
            };
            Ok(StartState { joints, gripper_px })
        }
        (None, Some(px)) => hover(scenario, robot, px, first, ik)
            .map(|joints| StartState {
                joints,
                gripper_px: px,
            })
            .map_err(|reason| vec![FieldIssue::new("robot.start", reason)]),
        (None, None) => {
            let joints = parked_home(robot);
            let gripper_px = seen_gripper(scenario, robot, &joints);
            Ok(StartState { joints, gripper_px })
        }
    }
}

/// The state of a robot stopped mid-execution (the monitor replans from
/// it): its joints as they are; the grid starts under the tool of `arm`
/// (the arm that moved), or, without one, as in the table's first row.
pub fn mid_execution(
    scenario: &Scenario,
    robot: &RobotModel,
    joints: Vec<f64>,
    arm: Option<&str>,
) -> StartState {
    let gripper_px = match arm.and_then(|name| robot.arm(name).ok()) {
        Some(arm) => {
            let p = arm.fk(&arm.extract(&joints)).translation.vector;
            clamp_into_image(scenario, scenario.base_to_pixel([p.x, p.y]))
        }
        None => seen_gripper(scenario, robot, &joints),
    };
    StartState { joints, gripper_px }
}

/// Home with every arm that has a park posture parked.
pub fn parked_home(robot: &RobotModel) -> Vec<f64> {
    let mut q = robot.home().to_vec();
    for &(i, v) in robot.arms().iter().flat_map(|a| &a.park) {
        q[i] = v;
    }
    q
}

/// True when every joint `arm` sets while it waits is at its park value.
/// False for an arm without a park posture.
pub fn is_parked(arm: &Arm, q_robot: &[f64]) -> bool {
    !arm.park.is_empty()
        && arm
            .park
            .iter()
            .all(|&(i, v)| (q_robot[i] - v).abs() <= LIMIT_TOLERANCE)
}

/// Horizontal distance (m) within which a tool is taken to be over a pixel.
const OVER_PIXEL: f64 = 1e-3;
/// Tilt (rad) within which a tool is taken to point down.
const POINTS_DOWN: f64 = 0.01;

/// The height above the table (metres) of the tool of an arm that points
/// down within `POINTS_DOWN` rad over pixel `px` (within `OVER_PIXEL` m in
/// the table plane) in the whole-robot configuration `joints`; the first
/// such arm, `None` when no arm's tool is there. The route of the next
/// sub-goal starts at this height, from where the tool really is.
pub fn tool_height_over(
    scenario: &Scenario,
    robot: &RobotModel,
    joints: &[f64],
    px: [f64; 2],
) -> Option<f64> {
    let [x, y] = scenario.pixel_to_base(px);
    robot.arms().iter().find_map(|arm| {
        let tool = arm.fk(&arm.extract(joints));
        let p = tool.translation.vector;
        let down = (tool.rotation * Vec3::z()).angle(&-Vec3::z());
        ((p.x - x).hypot(p.y - y) <= OVER_PIXEL && down <= POINTS_DOWN)
            .then(|| p.z - scenario.camera.table_z)
    })
}

/// `start`, when the tool of the arm nearest it lies within one grid cell of
/// it (along u and along v); otherwise the issue naming both fields.
fn agreeing_start(
    scenario: &Scenario,
    robot: &RobotModel,
    joints: &[f64],
    start: [f64; 2],
    cell: [f64; 2],
) -> Result<[f64; 2], Vec<FieldIssue>> {
    let (arm, tool) = nearest_tool(robot, joints, scenario.pixel_to_base(start));
    let tool_px = scenario.base_to_pixel(tool);
    let off = [0, 1].map(|k| (tool_px[k] - start[k]).abs());
    if off[0] <= cell[0] && off[1] <= cell[1] {
        return Ok(start);
    }
    Err(vec![FieldIssue::new(
        "robot.start",
        format!(
            "({}, {}) disagrees with robot.joints: the tool of the arm '{arm}' is at pixel ({:.1}, {:.1}), \
             {:.1} px along u and {:.1} px along v away, more than one grid cell ({} x {} px); \
             fix or drop one of the two fields",
            start[0], start[1], tool_px[0], tool_px[1], off[0], off[1], cell[0], cell[1]
        ),
    )])
}

/// The pixel of the tool of the arm nearest the image centre, clamped into
/// the image (a parked tool may be outside the camera's view).
fn seen_gripper(scenario: &Scenario, robot: &RobotModel, joints: &[f64]) -> [f64; 2] {
    let (w, h) = (
        f64::from(scenario.camera.width),
        f64::from(scenario.camera.height),
    );
    let centre = scenario.pixel_to_base([w / 2.0, h / 2.0]);
    let (_, tool) = nearest_tool(robot, joints, centre);
    clamp_into_image(scenario, scenario.base_to_pixel(tool))
}

/// The pixel clamped into the image; the last pixel's far edge is outside
/// it, so stay half a pixel in.
fn clamp_into_image(scenario: &Scenario, [u, v]: [f64; 2]) -> [f64; 2] {
    let (w, h) = (
        f64::from(scenario.camera.width),
        f64::from(scenario.camera.height),
    );
    [u.clamp(0.0, w - 0.5), v.clamp(0.0, h - 0.5)]
}

/// The arm whose tool is nearest `point` in the table plane, and that tool's
/// table-plane position (x, y), base frame. Arms out of park come first: a
/// parked tool is not where the robot works.
fn nearest_tool<'a>(robot: &'a RobotModel, joints: &[f64], point: [f64; 2]) -> (&'a str, [f64; 2]) {
    let working = robot.arms().iter().any(|arm| !is_parked(arm, joints));
    let candidates = robot
        .arms()
        .iter()
        .filter(|arm| !working || !is_parked(arm, joints));
    let tools = candidates.map(|arm| {
        let p = arm.fk(&arm.extract(joints)).translation.vector;
        (arm.name.as_str(), [p.x, p.y])
    });
    let distance = |[x, y]: [f64; 2]| (x - point[0]).hypot(y - point[1]);
    tools
        .reduce(|best, next| match distance(next.1) < distance(best.1) {
            true => next,
            false => best,
        })
        .expect("a robot model has at least one arm")
}

/// The parked home with one arm's tool pointing down over pixel `px` at the
/// first sub-goal's carry height and grasp yaw ([`rolled_to`]; any yaw when
/// no IK reaches that one). Only an arm without a park posture hovers
/// (one with a park posture waits parked and leaves park through its home
/// posture when it works: an IK posture near the body is not known to be
/// free); among those, by distance from their tool at their home posture to
/// the first target, the first whose IK from its home posture converges.
/// Every arm has a park posture: the parked home.
fn hover(
    scenario: &Scenario,
    robot: &RobotModel,
    px: [f64; 2],
    first: &FirstSubgoal,
    ik: &IkSettings,
) -> Result<Vec<f64>, String> {
    let [x, y] = scenario.pixel_to_base(px);
    let z = scenario.camera.table_z + first.carry_height;
    let position = Vec3::new(x, y, z);
    let [tx, ty] = scenario.pixel_to_base(first.target_px);
    let first_target = Vec3::new(tx, ty, z);
    let mut arms: Vec<&Arm> = robot.arms().iter().filter(|a| a.park.is_empty()).collect();
    if arms.is_empty() {
        return Ok(parked_home(robot));
    }
    arms.sort_by(|a, b| {
        let d = |arm: &Arm| (arm.fk(&arm.home).translation.vector - first_target).norm();
        d(a).total_cmp(&d(b))
    });
    let mut rng = ChaCha8Rng::seed_from_u64(HOVER_IK_SEED);
    let mut reasons = Vec::new();
    for arm in arms {
        let any_yaw = IkTarget::TopDown {
            position,
            yaw: None,
        };
        match arm.solve_ik(&any_yaw, None, ik, &mut rng) {
            Ok(solution) => {
                let mut q = parked_home(robot);
                let turned = rolled_to(arm, solution.q, position, first.grasp_yaw, ik, &mut rng);
                arm.insert(&mut q, &turned);
                return Ok(q);
            }
            Err(e) => reasons.push(format!("the arm '{}': {e}", arm.name)),
        }
    }
    Err(format!(
        "no arm can hover over pixel ({:.1}, {:.1}) at the carry height, ({x:.3}, {y:.3}, {z:.3}) m: {}; \
         give the robot's joint state in robot.joints",
        px[0],
        px[1],
        reasons.join("; ")
    ))
}

/// The hover `q` (tool down over `position`) turned to tool yaw `yaw`, so
/// that the first sub-goal starts where its path IK starts (no
/// reconfiguration transit): the last joint (the wrist's roll) turns the
/// tool, then the IK finishes from there (seeded: the rest of the arm stays
/// as it is, a planar arm stays planar); unseeded if that fails; `q` as it
/// is when no IK reaches that yaw.
fn rolled_to(
    arm: &Arm,
    q: Vec<f64>,
    position: Vec3,
    yaw: f64,
    ik: &IkSettings,
    rng: &mut ChaCha8Rng,
) -> Vec<f64> {
    const STEP: f64 = 1e-3;
    let tool_yaw = |q: &[f64]| {
        let x = arm.fk(q).rotation * Vec3::x();
        x.y.atan2(x.x)
    };
    let wrap = |a: f64| (a + PI).rem_euclid(TAU) - PI;
    let last = q.len() - 1;
    let mut nudged = q.clone();
    nudged[last] += STEP;
    let rate = wrap(tool_yaw(&nudged) - tool_yaw(&q)) / STEP;
    let mut seed = q.clone();
    if rate.abs() > 0.5 {
        seed[last] =
            (seed[last] + wrap(yaw - tool_yaw(&q)) / rate).clamp(arm.lower[last], arm.upper[last]);
    }
    let target = IkTarget::TopDown {
        position,
        yaw: Some(yaw),
    };
    arm.solve_ik(&target, Some(&seed), ik, rng)
        .or_else(|_| arm.solve_ik(&target, None, ik, rng))
        .map_or(q, |s| s.q)
}

fn joint_names(robot: &RobotModel) -> String {
    robot
        .joints()
        .iter()
        .map(|j| j.name.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::default_scenario;

    fn with_joints(pairs: &[(&str, f64)]) -> Scenario {
        let mut s = default_scenario().expect("default scenario");
        s.robot.joints = Some(pairs.iter().map(|&(n, v)| (n.to_string(), v)).collect());
        s
    }

    #[test]
    fn start_state_issues_name_every_bad_joint_at_once() {
        let robot = RobotModel::builtin("kuka_iiwa14").expect("robot");
        let mut pairs: Vec<(&str, f64)> = robot
            .joints()
            .iter()
            .zip(robot.home())
            .map(|(j, &h)| (j.name.as_str(), h))
            .collect();
        assert!(check_joints(&with_joints(&pairs), &robot).is_empty());
        pairs.retain(|(n, _)| *n != "joint_a3");
        pairs.push(("joint_a9", 0.0));
        pairs[0].1 = 7.0;
        let fields: Vec<String> = check_joints(&with_joints(&pairs), &robot)
            .into_iter()
            .map(|i| i.field)
            .collect();
        assert_eq!(
            fields,
            [
                "robot.joints.joint_a3",
                "robot.joints.joint_a1",
                "robot.joints.joint_a9"
            ]
        );
    }

    /// The hover stood in for the start state at any yaw (the IK's), and the
    /// first sub-goal's path IK, at the grasp yaw, began with a transit
    /// turning the wrist where the tool stood (0.5 s, and a reversal of
    /// every joint it moved where the route began). The hover takes the
    /// grasp yaw: the first waypoint's IK from it returns it unchanged.
    #[test]
    fn hover_start_at_the_grasp_yaw_needs_no_reconfiguration_transit() {
        let mut s = default_scenario().expect("default scenario");
        s.robot.joints = None;
        let px = s
            .robot
            .start
            .expect("the default scenario gives robot.start");
        let robot = RobotModel::builtin(&s.robot.model).expect("robot");
        let first = FirstSubgoal::moving(&s, 0, &LiftSettings::default());
        let ik = IkSettings::default();
        let state = resolve(&s, &robot, &first, &ik).expect("hovers");
        assert_eq!(state.gripper_px, px);
        let arm = &robot.arms()[0];
        let q = arm.extract(&state.joints);
        let tool = arm.fk(&q);
        let x_axis = tool.rotation * Vec3::x();
        let yaw = x_axis.y.atan2(x_axis.x);
        let turn = (yaw - first.grasp_yaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        assert!(
            turn.abs() < 1e-3,
            "tool yaw {yaw}, grasp yaw {}",
            first.grasp_yaw
        );
        // The iiwa's home is planar (a3 = a5 = 0) and its last joint rolls
        // the tool: the yaw is the wrist's roll, and the arm stays planar (an
        // IK from home split the turn between a5 and a7, and every later
        // vertical move turned all seven joints).
        assert!(q[2].abs() < 1e-6 && q[4].abs() < 1e-6, "{q:?}");
        let target = IkTarget::TopDown {
            position: tool.translation.vector,
            yaw: Some(first.grasp_yaw),
        };
        let restarting = IkSettings {
            restart_when_seeded: true,
            ..ik
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let solved = arm
            .solve_ik(&target, Some(&q), &restarting, &mut rng)
            .expect("solves");
        let moved = solved
            .q
            .iter()
            .zip(&q)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(moved < 1e-9, "the first waypoint's IK moves {moved} rad");
    }

    #[test]
    fn start_state_parked_only_at_the_park_posture() {
        let robot = RobotModel::builtin("care_o_bot4").expect("robot");
        let parked = parked_home(&robot);
        assert!(robot.arms().iter().all(|a| is_parked(a, &parked)));
        let left = robot.arm("left").expect("left");
        let mut out = parked.clone();
        left.insert(&mut out, &left.home);
        assert!(!is_parked(left, &out));
        assert!(is_parked(robot.arm("right").expect("right"), &out));
        let iiwa = RobotModel::builtin("kuka_iiwa14").expect("robot");
        assert!(!is_parked(&iiwa.arms()[0], iiwa.home()), "no park posture");
    }
}
