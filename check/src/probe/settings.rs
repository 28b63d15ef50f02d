//! What the probe is given: how it searches, the planner's documented
//! grasp and release heights it re-implements, their bounds, and why it
//! cannot run.

/// How the probe searches, and the planner's documented grasp and release
/// heights it re-implements (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeSettings {
    /// IK attempts per pose.
    pub restarts: usize,
    /// Solver steps per attempt.
    pub iterations: usize,
    /// Height of pose (b) above the grasp.
    pub above: f64,
    /// Lowest tool centre point above the object's bottom at the grasp.
    pub min_grasp_height: f64,
    /// Lowest gap between the fingertips and the object's support.
    pub tip_clearance: f64,
    /// Gap between the palm and the target's `obstacle_margin`.
    pub palm_clearance: f64,
    /// How far below the object's top the fingertips must reach when they
    /// cannot reach its middle.
    pub min_grip_depth: f64,
    /// Gap between the held object's bottom and the release floor.
    pub release_clearance: f64,
    /// Seed of the random restarts.
    pub seed: u64,
}

impl Default for ProbeSettings {
    fn default() -> Self {
        Self {
            restarts: 24,
            iterations: 150,
            above: 0.15,
            min_grasp_height: 0.02,
            tip_clearance: 0.005,
            palm_clearance: 0.003,
            min_grip_depth: 0.01,
            release_clearance: 0.01,
            seed: 1,
        }
    }
}

/// Most IK attempts per pose and steps per attempt.
pub const MAX_COUNT: usize = 10_000;
/// Largest height or clearance of [`ProbeSettings`], m.
pub const MAX_LENGTH: f64 = 1.0;

impl ProbeSettings {
    /// `Err` naming the first field out of range: counts in
    /// `1..=MAX_COUNT`, lengths in `0..=MAX_LENGTH` m.
    pub fn validate(&self) -> Result<(), ProbeError> {
        for (field, n) in [("restarts", self.restarts), ("iterations", self.iterations)] {
            if !(1..=MAX_COUNT).contains(&n) {
                let e = format!("{field} must be between 1 and {MAX_COUNT}, got {n}");
                return Err(ProbeError::Settings(e));
            }
        }
        for (field, m) in [
            ("above", self.above),
            ("min_grasp_height", self.min_grasp_height),
            ("tip_clearance", self.tip_clearance),
            ("palm_clearance", self.palm_clearance),
            ("min_grip_depth", self.min_grip_depth),
            ("release_clearance", self.release_clearance),
        ] {
            if !(0.0..=MAX_LENGTH).contains(&m) {
                let e = format!("{field} must be between 0 and {MAX_LENGTH} m, got {m}");
                return Err(ProbeError::Settings(e));
            }
        }
        Ok(())
    }
}

/// Why the probe cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProbeError {
    /// The robot's chain as k reads it does not fit its description.
    #[error("robot {robot}: {message}")]
    Robot { robot: String, message: String },
    #[error("the scenario has no object '{0}'")]
    UnknownObject(String),
    #[error("the scenario has no goal '{0}'")]
    UnknownGoal(String),
    #[error("probe settings: {0}")]
    Settings(String),
}
