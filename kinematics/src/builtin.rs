//! The robots built into the binary (their URDF and description text is
//! embedded with `include_str!`) and the summary `afford robots` prints.

use serde::Serialize;

use crate::error::KinematicsError;
use crate::math::Real;
use crate::model::RobotModel;

/// Names of the built-in robots.
pub const NAMES: [&str; 2] = ["kuka_iiwa14", "care_o_bot4"];

pub(crate) struct Builtin {
    pub description: &'static str,
    pub description_file: &'static str,
    pub urdf: &'static str,
    pub urdf_file: &'static str,
}

pub(crate) fn find(name: &str) -> Option<Builtin> {
    match name {
        "kuka_iiwa14" => Some(Builtin {
            description: include_str!("../../robots/kuka_iiwa14.yaml"),
            description_file: "robots/kuka_iiwa14.yaml",
            urdf: include_str!("../../robots/kuka_iiwa14.urdf"),
            urdf_file: "robots/kuka_iiwa14.urdf",
        }),
        "care_o_bot4" => Some(Builtin {
            description: include_str!("../../robots/care_o_bot4.yaml"),
            description_file: "robots/care_o_bot4.yaml",
            urdf: include_str!("../../robots/care_o_bot4.urdf"),
            urdf_file: "robots/care_o_bot4.urdf",
        }),
        _ => None,
    }
}

/// One line of `afford robots`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobotSummary {
    pub name: String,
    /// Degrees of freedom of the whole robot.
    pub dof: usize,
    pub arms: Vec<ArmSummary>,
}

/// An arm in a [`RobotSummary`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArmSummary {
    pub name: String,
    pub dof: usize,
    pub joints: Vec<String>,
    pub tool_link: String,
    /// Upper bound on the distance from the arm's first joint to its tool point (m).
    pub reach: Real,
}

impl RobotSummary {
    /// Summary of a loaded model.
    pub fn of(model: &RobotModel) -> Self {
        Self {
            name: model.name().to_string(),
            dof: model.dof(),
            arms: model
                .arms()
                .iter()
                .map(|a| ArmSummary {
                    name: a.name.clone(),
                    dof: a.dof(),
                    joints: a.joint_names.clone(),
                    tool_link: a.tool_link.clone(),
                    reach: a.reach,
                })
                .collect(),
        }
    }
}

/// Every built-in robot, loaded and summarised.
pub fn builtin_robots() -> Result<Vec<RobotSummary>, KinematicsError> {
    NAMES
        .iter()
        .map(|n| RobotModel::builtin(n).map(|m| RobotSummary::of(&m)))
        .collect()
}
