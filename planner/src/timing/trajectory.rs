//! The trajectory stage: a sub-goal's joint path becomes a timed joint
//! trajectory a controller can execute, in the shape of ROS
//! `trajectory_msgs/JointTrajectory`, plus the gripper commands.
//!
//! The path is timed in three pieces — to the grasp, carrying to the
//! release, retreating — each starting and ending at rest, because the arm
//! stands still while the gripper closes and opens. Each piece is timed by
//! [`crate::timing`] (time-optimal under the joint velocity and acceleration
//! limits, slower near hands by the speed-and-separation rule, never
//! outside the position limits or farther from the planned tool path than
//! [`TimingSettings::max_tool_deviation_m`]) and sampled at the controller
//! rate. Between the pieces the arm rests while the gripper closes (opens)
//! for the robot description's `gripper.closing_time` (`opening_time`):
//! samples at the controller rate hold the arm still, with samples exactly
//! at the command's start and end.

use afford_kinematics::{Arm, RobotModel};
use serde::{Deserialize, Serialize};

use crate::error::Refusal;
use crate::scenario::Scenario;
use crate::timing::{
    Hand, JointLimits, JointTrajectory, Proximity, SeparationSettings, Timing, TimingSettings,
    TrajectoryPoint, time_parameterize_tool,
};

/// Open or close the gripper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GripperCommand {
    Close,
    Open,
}

/// A gripper command and the time it takes, seconds from the start of the
/// sub-goal's trajectory: the command is sent at `start` and the gripper has
/// closed (opened) at `end`; the arm rests from `start` to `end`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GripperEvent {
    pub command: GripperCommand,
    pub start: f64,
    pub end: f64,
}

/// The timed motion of one sub-goal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimedMotion {
    /// Samples at the controller rate (positions, velocities, accelerations, time).
    pub points: Vec<crate::timing::TrajectoryPoint>,
    pub gripper: Vec<GripperEvent>,
}

/// What the gripper is doing at a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GripperState {
    Open,
    Closing,
    Closed,
    Opening,
}

impl GripperState {
    /// Lower-case name, as in the CSV output.
    pub fn name(self) -> &'static str {
        match self {
            Self::Open => "open",
            Self::Closing => "closing",
            Self::Closed => "closed",
            Self::Opening => "opening",
        }
    }
}

impl TimedMotion {
    /// Sample indices where the object is taken and left, for the collision
    /// check: the sample at the end of `close` (the gripper has closed: the
    /// object rides with it from here) and the sample at the start of `open`
    /// (the object rests where it was put from here). The arm rests through
    /// both events, so the check sees the same poses on either side.
    /// A missing event counts as at t = 0.
    pub fn gripper_samples(&self) -> (usize, usize) {
        let at = |t: f64| {
            self.points
                .iter()
                .position(|p| p.time_from_start >= t - 1e-9)
                .unwrap_or(0)
        };
        let close = self.event(GripperCommand::Close).map_or(0.0, |e| e.end);
        let open = self.event(GripperCommand::Open).map_or(0.0, |e| e.start);
        (at(close), at(open))
    }

    /// The gripper's state at time `t` of the sub-goal: a command is under
    /// way from its start (included) to its end (excluded).
    pub fn gripper_state(&self, t: f64) -> GripperState {
        let phase = |command| {
            self.event(command)
                .map(|e| (t >= e.start, t >= e.end))
                .unwrap_or((false, false))
        };
        match (phase(GripperCommand::Close), phase(GripperCommand::Open)) {
            (_, (true, true)) => GripperState::Open,
            (_, (true, false)) => GripperState::Opening,
            ((true, true), _) => GripperState::Closed,
            ((true, false), _) => GripperState::Closing,
            _ => GripperState::Open,
        }
    }

    fn event(&self, command: GripperCommand) -> Option<&GripperEvent> {
        self.gripper.iter().find(|e| e.command == command)
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

/// The path indices `(from, to)` of the three pieces of a sub-goal's path:
/// to the grasp, carrying to the release, retreating.
pub fn pieces(r: &TimingRequest) -> [(usize, usize); 3] {
    let (grasp, release) = r.switches;
    [(0, grasp), (grasp, release), (release, r.path.len() - 1)]
}

/// Times the piece `r.path[from..=to]` with `settings` (the sub-goal's
/// segments shared by the pieces by joint-space length, so the whole path
/// is discretised as finely as one path of `settings.path_points`).
pub fn time_piece(
    r: &TimingRequest,
    piece: (usize, usize),
    settings: &TimingSettings,
) -> Result<Timing, Refusal> {
    time_piece_within(r, piece, settings, &arm_limits(r.robot, r.arm))
}

/// [`time_piece`] under `limits` (the arm's, or e.g. without its jerk
/// limits to measure what they cost).
pub fn time_piece_within(
    r: &TimingRequest,
    (from, to): (usize, usize),
    settings: &TimingSettings,
    limits: &JointLimits,
) -> Result<Timing, Refusal> {
    let fk = |q: &[f64]| -> [f64; 3] { r.arm.fk(q).translation.vector.into() };
    let piece = &r.path[from..=to];
    // Without hands the tool positions would go unused: no forward
    // kinematics of every waypoint for them (the rule is still checked).
    let hands = hands(r.scenario);
    r.separation.validate().map_err(Refusal::from)?;
    let proximity = (!hands.is_empty()).then(|| Proximity {
        tool_positions: piece.iter().map(|q| fk(q)).collect(),
        hands,
        rule: r.separation.clone(),
    });
    let total = chord(r.path).max(f64::EPSILON);
    let share = (settings.path_points as f64 * chord(piece) / total).round() as usize;
    let settings = TimingSettings {
        path_points: share.max(MIN_PIECE_SEGMENTS),
        ..settings.clone()
    };
    time_parameterize_tool(piece, limits, proximity.as_ref(), Some(&fk), &settings)
        .map_err(Refusal::from)
}

/// Times the three pieces and joins them, with the arm resting while the
/// gripper closes and opens. `Err` is the typed reason.
pub fn time_motion(r: &TimingRequest) -> Result<TimedMotion, Refusal> {
    let gripper = r.robot.gripper();
    let mut motion = TimedMotion {
        points: Vec::new(),
        gripper: Vec::new(),
    };
    let events = [
        Some((GripperCommand::Close, gripper.closing_time)),
        Some((GripperCommand::Open, gripper.opening_time)),
        None,
    ];
    for (piece, event) in pieces(r).into_iter().zip(events) {
        let timing = time_piece(r, piece, r.settings)?;
        let trajectory = timing
            .trajectory
            .ok_or_else(|| Refusal::from_timing(&timing.status, &r.arm.joint_names))?;
        append(&mut motion, trajectory);
        if let Some((command, duration)) = event {
            let start = motion.duration();
            rest(&mut motion, duration, r.settings.rate_hz);
            motion.gripper.push(GripperEvent {
                command,
                start,
                end: motion.duration(),
            });
        }
    }
    Ok(motion)
}

/// Holds the motion's last sample (at rest) for `duration` seconds: a
/// sample every controller period and one exactly at the end.
fn rest(motion: &mut TimedMotion, duration: f64, rate_hz: f64) {
    let Some(last) = motion.points.last().cloned() else {
        return;
    };
    let start = last.time_from_start;
    let count = (duration * rate_hz - 1e-9).ceil().max(0.0) as usize;
    let still = |t: f64| TrajectoryPoint {
        time_from_start: t,
        ..last.clone()
    };
    motion
        .points
        .extend((1..count).map(|k| still(start + k as f64 / rate_hz)));
    if duration > 0.0 {
        motion.points.push(still(start + duration));
    }
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

/// The arm's position, velocity and acceleration limits, in its joint order.
pub fn arm_limits(robot: &RobotModel, arm: &Arm) -> JointLimits {
    let joints = arm.joint_indices.iter().map(|&i| &robot.joints()[i]);
    JointLimits {
        lower: arm.lower.clone(),
        upper: arm.upper.clone(),
        velocity: joints.clone().map(|j| j.velocity).collect(),
        acceleration: joints.clone().map(|j| j.acceleration).collect(),
        jerk: joints.map(|j| j.jerk).collect(),
    }
}

/// Each hand as the sphere around its box (base frame, metres).
pub fn hands(s: &Scenario) -> Vec<Hand> {
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
