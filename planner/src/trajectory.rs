//! The trajectory stage: a sub-goal's joint path becomes a timed joint
//! trajectory a controller can execute, in the shape of ROS
//! `trajectory_msgs/JointTrajectory`, plus the gripper commands.
//!
//! The path is timed in three pieces — to the grasp, carrying to the
//! release, retreating — each starting and ending at rest, because the arm
//! stands still while the gripper closes and opens. Each piece is timed by
//! [`crate::timing`] (time-optimal under the joint velocity and acceleration
//! limits, slower near hands by the speed-and-separation rule) and sampled at
//! the controller rate; the pieces are joined end to end.

use afford_kinematics::{Arm, RobotModel};
use serde::{Deserialize, Serialize};

use crate::scenario::Scenario;
use crate::timing::{
    Hand, JointLimits, JointTrajectory, Proximity, SeparationSettings, TimingSettings,
    time_parameterize,
};

/// Open or close the gripper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GripperCommand {
    Close,
    Open,
}

/// A gripper command at a time along the trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GripperEvent {
    pub time_from_start: f64,
    pub command: GripperCommand,
}

/// The timed motion of one sub-goal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimedMotion {
    /// Samples at the controller rate (positions, velocities, accelerations, time).
    pub points: Vec<crate::timing::TrajectoryPoint>,
    pub gripper: Vec<GripperEvent>,
}

impl TimedMotion {
    /// Sample indices where the gripper closes and opens.
    pub fn gripper_samples(&self) -> (usize, usize) {
        let at = |command: GripperCommand| {
            let t = self
                .gripper
                .iter()
                .find(|e| e.command == command)
                .map_or(0.0, |e| e.time_from_start);
            self.points
                .iter()
                .position(|p| p.time_from_start >= t - 1e-12)
                .unwrap_or(0)
        };
        (at(GripperCommand::Close), at(GripperCommand::Open))
    }

    pub fn duration(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.time_from_start)
    }
}

/// Everything the timing of one sub-goal needs.
pub struct TimingRequest<'a> {
    pub scenario: &'a Scenario,
    pub robot: &'a RobotModel,
    pub arm: &'a Arm,
    /// The arm's joint path (start configuration, then one per waypoint).
    pub path: &'a [Vec<f64>],
    /// Path indices where the gripper closes and opens.
    pub switches: (usize, usize),
    pub separation: &'a SeparationSettings,
    pub settings: &'a TimingSettings,
}

/// Times the three pieces and joins them. `Err` is the reason in words.
pub fn time_motion(r: &TimingRequest) -> Result<TimedMotion, String> {
    let limits = arm_limits(r.robot, r.arm);
    let hands = hands(r.scenario);
    let (grasp, release) = r.switches;
    let total = chord(r.path).max(f64::EPSILON);
    let mut motion = TimedMotion {
        points: Vec::new(),
        gripper: Vec::new(),
    };
    for (from, to, event) in [
        (0, grasp, Some(GripperCommand::Close)),
        (grasp, release, Some(GripperCommand::Open)),
        (release, r.path.len() - 1, None),
    ] {
        let piece = &r.path[from..=to];
        let proximity = Proximity {
            tool_positions: piece
                .iter()
                .map(|q| r.arm.fk(q).translation.vector.into())
                .collect(),
            hands: hands.clone(),
            rule: r.separation.clone(),
        };
        // The sub-goal's segments are shared by the pieces by length, so the
        // whole path is discretised as finely as one path of `path_points`.
        let share = (r.settings.path_points as f64 * chord(piece) / total).round() as usize;
        let settings = TimingSettings {
            path_points: share.max(MIN_PIECE_SEGMENTS),
            ..r.settings.clone()
        };
        let timing = time_parameterize(piece, &limits, Some(&proximity), &settings)
            .map_err(|e| e.to_string())?;
        let trajectory = timing
            .trajectory
            .ok_or_else(|| format!("timing failed: {}", timing.status))?;
        append(&mut motion, trajectory);
        if let Some(command) = event {
            motion.gripper.push(GripperEvent {
                time_from_start: motion.duration(),
                command,
            });
        }
    }
    Ok(motion)
}

/// Fewest path segments for one piece of a sub-goal's path.
pub const MIN_PIECE_SEGMENTS: usize = 40;

/// Joint-space length of a path (sum of Euclidean steps), rad.
fn chord(path: &[Vec<f64>]) -> f64 {
    path.windows(2)
        .map(|w| {
            w[0].iter()
                .zip(&w[1])
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum()
}

/// Appends a piece that starts where the motion ends (at rest), dropping its
/// first sample, which repeats the motion's last.
fn append(motion: &mut TimedMotion, piece: JointTrajectory) {
    let offset = motion.duration();
    let skip = usize::from(!motion.points.is_empty());
    motion
        .points
        .extend(piece.points.into_iter().skip(skip).map(|mut p| {
            p.time_from_start += offset;
            p
        }));
}

/// The arm's velocity and acceleration limits, in its joint order.
pub fn arm_limits(robot: &RobotModel, arm: &Arm) -> JointLimits {
    let joints = arm.joint_indices.iter().map(|&i| &robot.joints()[i]);
    JointLimits {
        velocity: joints.clone().map(|j| j.velocity).collect(),
        acceleration: joints.map(|j| j.acceleration).collect(),
    }
}

/// Each hand as the sphere around its box (base frame, metres).
fn hands(s: &Scenario) -> Vec<Hand> {
    let [mu, mv] = s.metres_per_pixel();
    s.hands
        .iter()
        .map(|h| {
            let [x, y] = s.pixel_to_base(h.bbox.centre());
            let (w, l) = (h.bbox.w * mu, h.bbox.l * mv);
            Hand {
                centre: [x, y, s.camera.table_z + h.height / 2.0],
                radius: 0.5 * (w * w + l * l + h.height * h.height).sqrt(),
            }
        })
        .collect()
}
