//! What the robot does in a replay: one arm's timed joint trajectory per
//! motion (a sub-goal of a plan, or a stretch of an executed run) and the
//! piece its gripper holds from the close to the open. Between samples the
//! joints move linearly (the samples come at the controller rate, so this
//! is the path the controller interpolates).

use afford_kinematics::RobotModel;
use serde::{Deserialize, Serialize};

use crate::error::{CollisionError, path_err};

/// Most samples one motion may have (100 s at 1 kHz).
pub const MAX_MOTION_SAMPLES: usize = 100_000;
/// Most motions one replay may have (a plan's sub-goal bound).
pub const MAX_MOTIONS: usize = 1_000;
/// Longest motion accepted, s (a physics step every 2 ms: 50,000 steps).
pub const MAX_MOTION_DURATION: f64 = 100.0;

/// The grasp of one motion: the gripper closes on `piece` at `t_close` and
/// lets go at `t_open` (times of the motion's own clock, s).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grasp {
    /// The piece held (a [`crate::replay::PhysicsPiece`] name).
    pub piece: String,
    /// The goal box the piece must end in (`None`: no placement verdict).
    #[serde(default)]
    pub goal: Option<String>,
    pub t_close: f64,
    pub t_open: f64,
}

/// One arm's joint trajectory. Joints the motion does not name stay where
/// the previous motion (or the scene's `robot_start`) left them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReplayMotion {
    /// The arm whose tool holds the grasped piece.
    pub arm: String,
    /// Names of the joints in `positions`, robot joint names.
    pub joint_names: Vec<String>,
    /// Sample times, s, strictly increasing.
    pub times: Vec<f64>,
    /// Joint positions per sample (rad or m), in `joint_names` order.
    pub positions: Vec<Vec<f64>>,
    #[serde(default)]
    pub grasp: Option<Grasp>,
}

/// A motion checked against the robot: joint indices resolved.
#[derive(Debug, Clone)]
pub(crate) struct Checked<'a> {
    pub motion: &'a ReplayMotion,
    /// Robot joint index per column of `positions`.
    pub joints: Vec<usize>,
    /// Index of the arm's tool link.
    pub tool_link: usize,
}

impl ReplayMotion {
    pub(crate) fn check(
        &self,
        robot: &RobotModel,
        k: usize,
    ) -> Result<Checked<'_>, CollisionError> {
        let field = |f: &str| format!("motions[{k}].{f}");
        let arm = robot
            .arm(&self.arm)
            .map_err(|e| path_err(field("arm"), e.to_string()))?;
        let tool_link = robot
            .link_index(&arm.tool_link)
            .map_err(|e| path_err(field("arm"), e.to_string()))?;
        let mut joints = Vec::with_capacity(self.joint_names.len());
        for name in &self.joint_names {
            let j = robot
                .joint_index(name)
                .ok_or_else(|| path_err(field("joint_names"), format!("no joint '{name}'")))?;
            if joints.contains(&j) {
                return Err(path_err(field("joint_names"), format!("'{name}' twice")));
            }
            joints.push(j);
        }
        let n = self.times.len();
        if n == 0 || n > MAX_MOTION_SAMPLES || self.positions.len() != n {
            return Err(path_err(
                field("times"),
                format!(
                    "{n} times and {} position rows: both must be equal, 1..={MAX_MOTION_SAMPLES}",
                    self.positions.len()
                ),
            ));
        }
        if self.times.iter().any(|t| !t.is_finite()) || self.times.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(path_err(
                field("times"),
                "must be finite and strictly increasing",
            ));
        }
        if self.times[n - 1] - self.times[0] > MAX_MOTION_DURATION {
            return Err(path_err(
                field("times"),
                format!("lasts more than {MAX_MOTION_DURATION} s"),
            ));
        }
        for (i, row) in self.positions.iter().enumerate() {
            if row.len() != joints.len() || row.iter().any(|v| !v.is_finite()) {
                return Err(path_err(
                    field(&format!("positions[{i}]")),
                    format!("must hold {} finite values", joints.len()),
                ));
            }
        }
        if let Some(g) = &self.grasp {
            let inside = |t: f64| t.is_finite() && t >= self.times[0] && t <= self.times[n - 1];
            if !(inside(g.t_close) && inside(g.t_open) && g.t_close <= g.t_open) {
                return Err(path_err(
                    field("grasp"),
                    format!(
                        "the gripper closes at {} s and opens at {} s: both must lie within the motion's {} to {} s, the close first",
                        g.t_close,
                        g.t_open,
                        self.times[0],
                        self.times[n - 1]
                    ),
                ));
            }
        }
        Ok(Checked {
            motion: self,
            joints,
            tool_link,
        })
    }
}

impl Checked<'_> {
    /// Writes the joint positions at time `t` (clamped to the motion's
    /// times, linear between samples) into the whole-robot vector `q`.
    pub(crate) fn write_at(&self, t: f64, q: &mut [f64]) {
        let (times, rows) = (&self.motion.times, &self.motion.positions);
        let i = times.partition_point(|&s| s <= t).clamp(1, times.len()) - 1;
        let row = &rows[i];
        let next = rows.get(i + 1).map(|r| (r, times[i + 1] - times[i]));
        for (c, &j) in self.joints.iter().enumerate() {
            q[j] = match next {
                Some((r, dt)) => {
                    let s = ((t - times[i]) / dt).clamp(0.0, 1.0);
                    row[c] + s * (r[c] - row[c])
                }
                None => row[c],
            };
        }
    }

    pub(crate) fn start(&self) -> f64 {
        self.motion.times[0]
    }

    pub(crate) fn end(&self) -> f64 {
        self.motion.times[self.motion.times.len() - 1]
    }
}
