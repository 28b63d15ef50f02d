//! Drafting a robot description from a published URDF (+ MoveIt SRDF), for
//! `afford robots init`. Owns what can be read off the URDF tree and the
//! SRDF's groups without a description: the arms (`arms`), the gripper and
//! the tool's approach axis (`gripper`), the joint limits the URDF lacks,
//! and the description text (`yaml`). Postures, the table region and the
//! allowed-collision matrix need the loaded model and are chosen by the
//! caller (the `afford` crate's `robot_setup`).
//!
//! Every choice that is not read from a file is a [`Draft::guesses`] line.

mod arms;
mod fk;
mod gripper;
mod groups;
pub mod mount;
mod yaml;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::bounds::ACCELERATION_LIMIT_RANGE;
use crate::error::KinematicsError;
use crate::math::{Real, Vec3};
use crate::mesh::{MeshSearch, PackagePaths};
use crate::model::JointKind;

pub use yaml::{Postures, relative};

/// Acceleration limit of a joint whose URDF gives none: its velocity limit
/// reached from rest in this time, 0.25 s (`a = v / 0.25 s`). Franka's
/// published limits are 3.4-7.7 times the velocity limits (7.5-20 rad/s²
/// against 2.2-2.6 rad/s), Universal Robots' 800 °/s² is 4.4 times 180 °/s:
/// four times is within both and errs on the slow side.
pub const DEFAULT_ACCELERATION_RAMP_S: Real = 0.25;

/// The tool's approach axis may be this far from the tool frame's +z
/// (rad, 15°) before `init` says the tool needs another frame.
pub const APPROACH_TOLERANCE_RAD: Real = 0.26;

/// One arm as drafted.
#[derive(Debug, Clone, PartialEq)]
pub struct DraftArm {
    pub name: String,
    pub root: String,
    pub tool: String,
    pub joints: Vec<String>,
    /// Where the arm came from (an SRDF group or the longest chain).
    pub source: String,
}

/// What `init` could read or had to guess, before postures are chosen.
#[derive(Debug, Clone)]
pub struct Draft {
    /// The robot's name (the URDF's `<robot name>`).
    pub name: String,
    pub urdf: PathBuf,
    pub srdf: Option<PathBuf>,
    pub arms: Vec<DraftArm>,
    /// Joints without a URDF `<limit acceleration>`: the default.
    pub acceleration_limits: BTreeMap<String, Real>,
    pub gripper: crate::Gripper,
    /// Finger joints (not in any arm): open in the home posture.
    pub finger_open: BTreeMap<String, Real>,
    /// The approach axis found, in the first arm's tool frame.
    pub approach: Option<Vec3>,
    /// SRDF `group_state`s, by name: joint values as written.
    pub states: Vec<(String, Vec<(String, Real)>)>,
    /// SRDF `disable_collisions` pairs, as written.
    pub disabled: Vec<[String; 2]>,
    /// One line per guess.
    pub guesses: Vec<String>,
}

/// Reads `urdf` (meshes through `packages`) and `srdf` into a [`Draft`].
pub fn draft(
    urdf: &Path,
    srdf: Option<&Path>,
    packages: &PackagePaths,
) -> Result<Draft, KinematicsError> {
    let text = crate::load::read_text(urdf)?;
    draft_text(&text, urdf, srdf, packages)
}

/// As [`draft`], with the URDF's text given (`urdf` names it and its folder).
pub fn draft_text(
    text: &str,
    urdf: &Path,
    srdf: Option<&Path>,
    packages: &PackagePaths,
) -> Result<Draft, KinematicsError> {
    let search = MeshSearch {
        urdf_dir: urdf.parent().unwrap_or_else(|| Path::new(".")),
        packages,
    };
    let tree = crate::urdf::parse(text, urdf, search)?;
    let name = robot_name(text).unwrap_or_else(|| "robot".into());
    let mut guesses = Vec::new();
    let groups = match srdf {
        Some(p) => Some(groups::read(p)?),
        None => None,
    };
    let fingers = gripper::finger_joints(&tree);
    let arms = match &groups {
        Some(g) => arms::from_srdf(&tree, g, &fingers, srdf.unwrap_or(urdf))?,
        None => Vec::new(),
    };
    let arms = match arms.is_empty() {
        false => arms,
        true => {
            if groups.is_some() {
                guesses.push(
                    "arms: the SRDF has no usable planning group; took the longest serial chain instead"
                        .into(),
                );
            }
            let arm = arms::longest_chain(&tree, &fingers, &mut guesses).ok_or_else(|| {
                KinematicsError::UrdfElement {
                    file: urdf.to_path_buf(),
                    element: "<robot>".into(),
                    problem: "no chain of revolute or prismatic joints to take as an arm".into(),
                }
            })?;
            vec![arm]
        }
    };
    let (gripper, finger_open, approach) =
        gripper::gripper(&tree, &arms[0], &fingers, &mut guesses);
    let acceleration_limits = acceleration_defaults(&tree, &mut guesses);
    guesses.push(format!(
        "jerk_limits: not written: each joint without a URDF <limit jerk> takes its acceleration limit over {} s (afford's default)",
        crate::DEFAULT_JERK_RAMP_S
    ));
    let (states, disabled) = groups.map_or_else(Default::default, |g| (g.states, g.disabled));
    Ok(Draft {
        name,
        urdf: urdf.to_path_buf(),
        srdf: srdf.map(Path::to_path_buf),
        arms,
        acceleration_limits,
        gripper,
        finger_open,
        approach,
        states,
        disabled,
        guesses,
    })
}

impl Draft {
    /// Makes the assumed gripper (`mount`) the first arm's: its grasp point
    /// the tool, its finger box the fingers, the iiwa's sizes.
    pub fn use_assumed_gripper(&mut self, urdf: &Path) {
        self.urdf = urdf.to_path_buf();
        self.arms[0].tool = mount::TCP_LINK.into();
        self.gripper = crate::Gripper {
            fingers: vec![mount::FINGERS.into()],
            ..crate::Gripper::default()
        };
        self.guesses
            .retain(|g| !g.starts_with("gripper.") && !g.starts_with("arms[0].tool"));
        self.guesses.push(format!(
            "gripper: the URDF has none: afford's assumed parallel gripper (palm capsule, finger box, opening {} m, grasp point '{}' 0.15 m beyond the flange) mounted in {}",
            self.gripper.max_opening,
            mount::TCP_LINK,
            urdf.display()
        ));
    }
}

/// `<robot name="..">`, the first one in the text.
fn robot_name(text: &str) -> Option<String> {
    let doc = roxmltree::Document::parse(text).ok()?;
    let name = doc.root_element().attribute("name")?;
    let clean: String = name
        .chars()
        .map(
            |c| match c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                true => c,
                false => '_',
            },
        )
        .collect();
    (!clean.is_empty()).then_some(clean)
}

/// The default acceleration of every configuration joint whose URDF gives
/// none ([`DEFAULT_ACCELERATION_RAMP_S`]).
fn acceleration_defaults(
    tree: &crate::urdf::Tree,
    guesses: &mut Vec<String>,
) -> BTreeMap<String, Real> {
    let mut limits = BTreeMap::new();
    for j in tree.links.iter().filter_map(|l| l.joint.as_ref()) {
        if j.kind == JointKind::Fixed || j.resolved.is_some() || j.acceleration.is_finite() {
            continue;
        }
        let (lo, hi) = ACCELERATION_LIMIT_RANGE;
        let a = (j.velocity / DEFAULT_ACCELERATION_RAMP_S).clamp(lo, hi);
        limits.insert(j.name.clone(), round(a, 3));
    }
    if !limits.is_empty() {
        guesses.push(format!(
            "acceleration_limits: {} joint(s) without a URDF <limit acceleration>: velocity limit / {DEFAULT_ACCELERATION_RAMP_S} s",
            limits.len()
        ));
    }
    limits
}

/// `x` rounded to `digits` decimals (stable text in the description).
pub(crate) fn round(x: Real, digits: i32) -> Real {
    let f = 10f64.powi(digits);
    (x * f).round() / f
}
