//! `afford check`: an independent re-check of planned trajectories against
//! their scenario, sharing nothing with the planner but the robot model and
//! the collision crate. For each sub-goal, in order:
//! - the samples are well formed: joint names are the arm's, times
//!   increase, every vector has one value per joint;
//! - the trajectory starts where the robot is (after the previous sub-goal);
//! - every position is inside its joint limits, every velocity and
//!   acceleration within its limit (relative tolerance 1e-6), and the motion
//!   between consecutive samples is no faster than the velocity limit;
//! - the motion, linear between samples, keeps every safety margin
//!   (continuous check; target ignored until the gripper closes, held
//!   until it opens).
//!
//! Then the world moves on: the object rests where the gripper opened.

use afford_collision::RobotGeometry;
use afford_kinematics::{Arm, RobotModel};
use serde::{Deserialize, Serialize};

use crate::clearance::{ArmMotion, check_motion};
use crate::plan::JointState;
use crate::scenario::Scenario;
use crate::trajectory::{TimedMotion, arm_limits};

/// Relative tolerance of the limit checks.
pub const LIMIT_TOLERANCE: f64 = 1e-6;

/// The parts of a plan file (`afford plan` output) that are checked.
#[derive(Debug, Clone, Deserialize)]
pub struct TrajectoryFile {
    /// The robot's state at t = 0; home when the file has none.
    #[serde(default)]
    pub start_state: Option<JointState>,
    pub subgoals: Vec<PlannedMotion>,
}

/// One sub-goal of a plan file.
#[derive(Debug, Clone, Deserialize)]
pub struct PlannedMotion {
    pub object: String,
    pub goal: String,
    pub arm: String,
    pub joint_names: Vec<String>,
    pub trajectory: TimedMotion,
}

/// One thing wrong with a trajectory.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Violation {
    /// Index of the sub-goal in the file.
    pub subgoal: usize,
    pub object: String,
    /// `format`, `continuity`, `position`, `velocity`, `acceleration`, `collision`.
    pub kind: &'static str,
    pub message: String,
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "sub-goal {} ({}): {}: {}",
            self.subgoal, self.object, self.kind, self.message
        )
    }
}

/// Checks every sub-goal of `file` against `scenario`; empty when all pass.
/// `Err` when the check cannot run at all (robot geometry the collision
/// crate rejects).
pub fn check_trajectories(
    scenario: &Scenario,
    robot: &RobotModel,
    file: &TrajectoryFile,
) -> Result<Vec<Violation>, String> {
    let geometry = RobotGeometry::new(robot).map_err(|e| e.to_string())?;
    let mut scene = scenario.clone();
    let mut rest = robot.home().to_vec();
    if let Some(start) = &file.start_state {
        let names = robot.joints().iter().map(|j| &j.name);
        if !names.eq(&start.joint_names) || start.positions.len() != rest.len() {
            return Err("start_state must name every robot joint in the robot's order".into());
        }
        rest.clone_from(&start.positions);
    }
    let mut violations = Vec::new();
    for (k, motion) in file.subgoals.iter().enumerate() {
        let found = check_one(&scene, robot, &geometry, &rest, motion);
        let failed = !found.is_empty();
        violations.extend(found.into_iter().map(|(kind, message)| Violation {
            subgoal: k,
            object: motion.object.clone(),
            kind,
            message,
        }));
        if failed {
            break;
        }
        advance(&mut scene, &mut rest, robot, motion);
    }
    Ok(violations)
}

type Found = Vec<(&'static str, String)>;

fn check_one(
    scene: &Scenario,
    robot: &RobotModel,
    geometry: &RobotGeometry,
    rest: &[f64],
    m: &PlannedMotion,
) -> Found {
    let (Some(target), Some(goal)) = (scene.object_index(&m.object), scene.goal_index(&m.goal))
    else {
        return vec![(
            "format",
            format!(
                "the scenario has no object '{}' or no goal '{}'",
                m.object, m.goal
            ),
        )];
    };
    let arm = match robot.arm(&m.arm) {
        Ok(arm) => arm,
        Err(e) => return vec![("format", e.to_string())],
    };
    let format = check_format(arm, m);
    if !format.is_empty() {
        return format;
    }
    let mut found = check_limits(robot, arm, &m.trajectory);
    let start = &m.trajectory.points[0].positions;
    let now = arm.extract(rest);
    let jump = start
        .iter()
        .zip(&now)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    if jump > 1e-6 {
        found.push((
            "continuity",
            format!("starts {jump:.6} rad away from where the robot is"),
        ));
    }
    let path: Vec<Vec<f64>> = m
        .trajectory
        .points
        .iter()
        .map(|p| p.positions.clone())
        .collect();
    let (grasp_at, release_at) = m.trajectory.gripper_samples();
    let motion = ArmMotion {
        scenario: scene,
        target,
        goal,
        arm: &arm.name,
        rest,
        path: &path,
        grasp_at,
        release_at,
    };
    match check_motion(robot, geometry, &motion) {
        Ok(None) => {}
        Ok(Some(hit)) => found.push((
            "collision",
            format!(
                "at t = {:.3} s (sample {}): {}",
                m.trajectory.points[hit.index].time_from_start, hit.index, hit.collision
            ),
        )),
        Err(e) => found.push(("collision", format!("cannot check: {e}"))),
    }
    found
}

fn check_format(arm: &Arm, m: &PlannedMotion) -> Found {
    let points = &m.trajectory.points;
    if m.joint_names != arm.joint_names {
        return vec![(
            "format",
            format!(
                "joint_names {:?} are not arm {}'s {:?}",
                m.joint_names, arm.name, arm.joint_names
            ),
        )];
    }
    if points.is_empty() {
        return vec![("format", "the trajectory has no points".to_string())];
    }
    let n = arm.dof();
    for (k, p) in points.iter().enumerate() {
        if [&p.positions, &p.velocities, &p.accelerations]
            .iter()
            .any(|v| v.len() != n)
        {
            return vec![(
                "format",
                format!("point {k} does not hold {n} positions, velocities and accelerations"),
            )];
        }
        let values = p
            .positions
            .iter()
            .chain(&p.velocities)
            .chain(&p.accelerations);
        if !p.time_from_start.is_finite() || values.clone().any(|v| !v.is_finite()) {
            return vec![(
                "format",
                format!("point {k} holds a value that is not a finite number"),
            )];
        }
        if k > 0 && p.time_from_start <= points[k - 1].time_from_start {
            return vec![(
                "format",
                format!("time_from_start does not increase at point {k}"),
            )];
        }
    }
    Vec::new()
}

fn check_limits(robot: &RobotModel, arm: &Arm, t: &TimedMotion) -> Found {
    let limits = arm_limits(robot, arm);
    let over = |value: f64, limit: f64| value.abs() > limit * (1.0 + LIMIT_TOLERANCE);
    let mut found = Vec::new();
    for (k, p) in t.points.iter().enumerate() {
        for (j, name) in arm.joint_names.iter().enumerate() {
            let (q, lo, hi) = (p.positions[j], arm.lower[j], arm.upper[j]);
            let slack = LIMIT_TOLERANCE * (hi - lo).abs().max(1.0);
            if q < lo - slack || q > hi + slack {
                found.push((
                    "position",
                    format!(
                        "{name} at t = {:.3} s is {q:.4}, outside [{lo:.4}, {hi:.4}]",
                        p.time_from_start
                    ),
                ));
            }
            let rates = [
                (
                    "velocity",
                    p.velocities[j],
                    limits.velocity[j],
                    "moves at",
                    "rad/s",
                ),
                (
                    "acceleration",
                    p.accelerations[j],
                    limits.acceleration[j],
                    "accelerates at",
                    "rad/s²",
                ),
            ];
            for (kind, value, limit, verb, unit) in rates.into_iter().filter(|r| over(r.1, r.2)) {
                let t = p.time_from_start;
                found.push((
                    kind,
                    format!("{name} at t = {t:.3} s {verb} {value:.4} {unit}, limit {limit:.4}"),
                ));
            }
            if k > 0 {
                let prev = &t.points[k - 1];
                let mean = (p.positions[j] - prev.positions[j])
                    / (p.time_from_start - prev.time_from_start);
                if over(mean, limits.velocity[j]) {
                    found.push(("velocity", format!("{name} between t = {:.3} s and {:.3} s moves at {mean:.4} rad/s on average, limit {:.4}", prev.time_from_start, p.time_from_start, limits.velocity[j])));
                }
            }
            if found.len() >= 10 {
                return found;
            }
        }
    }
    found
}

/// The world after a checked sub-goal: the object rests under the gripper
/// where it opened, the arm where its trajectory ended.
fn advance(scene: &mut Scenario, rest: &mut [f64], robot: &RobotModel, m: &PlannedMotion) {
    let (Ok(arm), Some(target)) = (robot.arm(&m.arm), scene.object_index(&m.object)) else {
        return;
    };
    let (_, release_at) = m.trajectory.gripper_samples();
    let tool = arm
        .fk(&m.trajectory.points[release_at].positions)
        .translation
        .vector;
    let pixel = scene.base_to_pixel([tool.x, tool.y]);
    let object = &mut scene.objects[target];
    object.bbox = object.bbox.centred_at(pixel);
    if let Some(last) = m.trajectory.points.last() {
        arm.insert(rest, &last.positions);
    }
}
