//! The robot description file (YAML, format 1): what a URDF cannot say. Owns
//! the schema and its parsing; `load` checks it against the URDF.
//!
//! ```yaml
//! afford_robot: 1
//! name: my_arm
//! urdf: my_arm.urdf            # relative to this file
//! arms:
//!   - name: arm
//!     root: base_link          # chain starts here (fixed to the URDF root)
//!     tool: tcp                # grasp point; +z is the approach axis
//!     joints: [j1, j2, j3, j4, j5, j6]
//!     park: {j1: 0.0}          # optional: where the arm waits while another works
//! home: {j1: 0.0, j2: 0.5}     # optional per joint; default 0 clamped into the limits
//! acceleration_limits: {j1: 5.0}  # rad/s^2 (or m/s^2); else the URDF <limit acceleration>
//! gripper: {max_opening: 0.08, finger_length: 0.05, closing_time: 0.5, opening_time: 0.5, fingers: [gripper_link#1]}
//! self_collision_skip: [[base_link, link_1]]
//! ```

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::KinematicsError;
use crate::math::Real;

/// Longest gripper closing or opening time accepted, s.
pub const MAX_GRIPPER_TIME: Real = 10.0;

/// The format version this build reads.
pub const DESCRIPTION_FORMAT: u32 = 1;

/// A description file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Description {
    pub afford_robot: u32,
    pub name: String,
    pub urdf: String,
    pub arms: Vec<ArmDescription>,
    #[serde(default)]
    pub home: BTreeMap<String, Real>,
    #[serde(default)]
    pub acceleration_limits: BTreeMap<String, Real>,
    #[serde(default)]
    pub gripper: Gripper,
    #[serde(default)]
    pub self_collision_skip: Vec<[String; 2]>,
}

/// One arm as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ArmDescription {
    pub name: String,
    pub root: String,
    pub tool: String,
    pub joints: Vec<String>,
    #[serde(default)]
    pub park: BTreeMap<String, Real>,
}

/// The gripper: its size (metres), how long it takes to act (seconds) and
/// which colliders are its fingers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Gripper {
    /// Widest opening between the fingers.
    pub max_opening: Real,
    /// Finger length from the palm to the tip.
    pub finger_length: Real,
    /// Time from the close command until the fingers hold the object, s;
    /// the arm rests meanwhile.
    pub closing_time: Real,
    /// Time from the open command until the fingers have let go, s.
    pub opening_time: Real,
    /// The colliders that form the fingers' grasp region, named like the
    /// collision crate's bodies (`link`, or `link#k` when the link has
    /// several colliders). Only these may come near the target before the
    /// gripper closes on it.
    pub fingers: Vec<String>,
}

impl Default for Gripper {
    fn default() -> Self {
        Self {
            max_opening: 0.08,
            finger_length: 0.05,
            closing_time: DEFAULT_GRIPPER_TIME,
            opening_time: DEFAULT_GRIPPER_TIME,
            fingers: Vec::new(),
        }
    }
}

/// Closing and opening time of a gripper whose description gives none, s:
/// a typical small electric parallel gripper (e.g. Robotiq 2F-85 full stroke
/// at its default speed, Schunk EGP in 0.2-0.4 s) rounded up.
pub const DEFAULT_GRIPPER_TIME: Real = 0.5;

/// Parses description YAML; `file` is only used in error messages.
pub(crate) fn parse(text: &str, file: &Path) -> Result<Description, KinematicsError> {
    let d: Description =
        serde_saphyr::from_str(text).map_err(|e| KinematicsError::DescriptionSyntax {
            file: file.to_path_buf(),
            message: e.to_string(),
        })?;
    let element = |element: String, problem: String| KinematicsError::DescriptionElement {
        file: file.to_path_buf(),
        element,
        problem,
    };
    if d.afford_robot != DESCRIPTION_FORMAT {
        return Err(element(
            "afford_robot".into(),
            format!(
                "format {} is not supported (this build reads {DESCRIPTION_FORMAT})",
                d.afford_robot
            ),
        ));
    }
    if d.arms.is_empty() {
        return Err(element("arms".into(), "must list at least one arm".into()));
    }
    for (i, arm) in d.arms.iter().enumerate() {
        if arm.joints.is_empty() {
            return Err(element(
                format!("arms[{i}].joints"),
                "must list the arm's joints".into(),
            ));
        }
        if d.arms[..i].iter().any(|a| a.name == arm.name) {
            return Err(element(
                format!("arms[{i}].name"),
                format!("arm name '{}' is used twice", arm.name),
            ));
        }
    }
    let g = &d.gripper;
    if !(g.max_opening.is_finite()
        && g.max_opening >= 0.0
        && g.finger_length.is_finite()
        && g.finger_length >= 0.0)
    {
        return Err(element(
            "gripper".into(),
            "sizes must be finite and non-negative".into(),
        ));
    }
    for (field, t) in [
        ("gripper.closing_time", g.closing_time),
        ("gripper.opening_time", g.opening_time),
    ] {
        if !(t.is_finite() && (0.0..=MAX_GRIPPER_TIME).contains(&t)) {
            return Err(element(
                field.into(),
                format!("must be a time from 0 to {MAX_GRIPPER_TIME} s, not {t}"),
            ));
        }
    }
    Ok(d)
}
