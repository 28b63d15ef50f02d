//! The robot model: links, movable joints, arms, home and park postures, and
//! forward kinematics of any link. A robot configuration is one `Vec<f64>`
//! over all movable joints in [`RobotModel::joints`] order; an arm reads and
//! writes its own slice of it through [`Arm::joint_indices`]. A mimic joint
//! is not in it: the links below it are posed with the value derived from
//! its leader ([`JointDrive::position`]).

use std::sync::Arc;

use nalgebra::{Translation3, UnitQuaternion};
use serde::Serialize;

use crate::chain::Chain;
use crate::description::{AllowedCollisions, Gripper};
use crate::error::KinematicsError;
use crate::math::{Pose, Real, Vec3};

/// How a joint moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JointKind {
    Fixed,
    Revolute,
    Continuous,
    Prismatic,
}

/// A movable joint with its limits (rad, rad/s, rad/s^2; m for prismatic).
/// A continuous joint has no position limits: `lower` is -inf and `upper`
/// +inf, so code doing arithmetic on the limits checks [`Joint::is_bounded`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// Lowest position (rad or m); -inf for a continuous joint (JSON: null).
    pub lower: Real,
    /// Highest position (rad or m); +inf for a continuous joint (JSON: null).
    pub upper: Real,
    pub velocity: Real,
    pub acceleration: Real,
    /// Jerk limit, rad/s^3 (m/s^3): the description's `jerk_limits`, else
    /// the URDF 1.2 `<limit jerk>`, else a documented default (load.rs).
    pub jerk: Real,
    pub effort: Real,
}

impl Joint {
    /// True when the joint has finite position limits (every kind but
    /// continuous).
    pub fn is_bounded(&self) -> bool {
        self.lower.is_finite() && self.upper.is_finite()
    }

    /// Middle of the position range; 0 for a continuous joint.
    pub fn mid(&self) -> Real {
        range_mid(self.lower, self.upper)
    }

    /// True when `q` lies inside the limits (tolerance `eps`).
    pub fn within(&self, q: Real, eps: Real) -> bool {
        q >= self.lower - eps && q <= self.upper + eps
    }
}

/// A collision shape in its link's frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Box centred at the origin.
    Box {
        half_extents: Vec3,
    },
    /// Cylinder along the local z axis, centred at the origin.
    Cylinder {
        radius: Real,
        half_length: Real,
    },
    /// Capsule: the segment z in [-half_length, half_length] swept by `radius`.
    Capsule {
        radius: Real,
        half_length: Real,
    },
    Sphere {
        radius: Real,
    },
    /// The convex hull of a `<mesh>`: its vertices (scaled, in the shape
    /// frame), each a corner of the hull (see the `mesh` module).
    ConvexHull {
        vertices: Arc<[Vec3]>,
    },
}

/// A collision shape placed in its link frame (`pose_link_shape`).
#[derive(Debug, Clone, PartialEq)]
pub struct Collider {
    pub origin: Pose,
    pub shape: Shape,
}

/// A link: its name, its parent link and its collision shapes.
#[derive(Debug, Clone)]
pub struct Link {
    pub name: String,
    /// Index of the parent link in [`RobotModel::links`] (parents come first).
    pub parent: Option<usize>,
    pub colliders: Vec<Collider>,
    /// Pose of the joint frame above this link in the parent link frame.
    pub(crate) origin: Pose,
    /// Movable joint above this link and what drives it.
    pub(crate) joint: Option<JointDrive>,
}

impl Link {
    /// The movable joint above this link (`None`: fixed to its parent).
    pub fn drive(&self) -> Option<JointDrive> {
        self.joint
    }
}

/// The movable joint above a link: its own kind and axis, and the
/// configuration value that drives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointDrive {
    /// Index into the configuration ([`RobotModel::joints`]) of the driving
    /// joint: the joint itself, or a mimic joint's (ultimate) leader.
    pub joint: usize,
    /// Unit axis in the joint frame.
    pub axis: Vec3,
    /// This joint's own kind (a mimic joint's may differ from its leader's).
    pub kind: JointKind,
    /// `Some` for a mimic joint: its position is `multiplier * q[joint] + offset`.
    pub mimic: Option<Mimic>,
}

impl JointDrive {
    /// The joint's position in configuration `q`.
    #[inline]
    pub fn position(&self, q: &[Real]) -> Real {
        match self.mimic {
            None => q[self.joint],
            Some(m) => m.multiplier * q[self.joint] + m.offset,
        }
    }

    /// How far the joint moves per unit of its driving value (|multiplier|;
    /// 1 for a joint of the configuration).
    pub fn gain(&self) -> Real {
        self.mimic.map_or(1.0, |m| m.multiplier.abs())
    }
}

/// A `<mimic>` relation resolved to a configuration joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mimic {
    pub multiplier: Real,
    pub offset: Real,
}

/// A joint that follows another (`<mimic>`): not part of the configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct MimicJoint {
    pub name: String,
    /// The joint named in `<mimic joint=..>`.
    pub leader: String,
    /// The configuration joint at the end of the mimic chain, and the
    /// composed relation: `position = multiplier * q[joint] + offset`.
    pub joint: usize,
    pub mimic: Mimic,
    /// The joint's own `<limit>` (not enforced: planning limits the leader).
    pub lower: Real,
    pub upper: Real,
}

/// One serial arm of a robot: root link to tool (grasp point) link.
#[derive(Debug, Clone)]
pub struct Arm {
    pub name: String,
    pub root_link: String,
    pub tool_link: String,
    /// Joint names, base to tool.
    pub joint_names: Vec<String>,
    /// Index of each arm joint in the robot configuration.
    pub joint_indices: Vec<usize>,
    /// Per-arm joint limits (copied from the model).
    pub lower: Vec<Real>,
    pub upper: Vec<Real>,
    /// Comfortable posture of this arm's joints (from the model's home).
    pub home: Vec<Real>,
    /// Robot joints this arm sets while it waits: (configuration index, value).
    pub park: Vec<(usize, Real)>,
    /// Upper bound on the distance from the first joint origin to the tool (m).
    pub reach: Real,
    pub(crate) chain: Chain,
}

impl Arm {
    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.joint_indices.len()
    }

    /// Tool pose in the robot base frame for this arm's joint values.
    pub fn fk(&self, q_arm: &[Real]) -> Pose {
        self.chain.fk(q_arm)
    }

    /// Origin of the first joint in the base frame (centre of the reach bound).
    pub fn reach_centre(&self) -> Vec3 {
        self.chain.first_joint_origin()
    }

    /// This arm's values out of a robot configuration.
    pub fn extract(&self, q_robot: &[Real]) -> Vec<Real> {
        self.joint_indices.iter().map(|&i| q_robot[i]).collect()
    }

    /// Writes this arm's values into a robot configuration.
    pub fn insert(&self, q_robot: &mut [Real], q_arm: &[Real]) {
        for (&i, &v) in self.joint_indices.iter().zip(q_arm) {
            q_robot[i] = v;
        }
    }

    /// True when every value is inside its limit (tolerance `eps`).
    pub fn within_limits(&self, q_arm: &[Real], eps: Real) -> bool {
        q_arm.len() == self.dof()
            && q_arm
                .iter()
                .zip(self.lower.iter().zip(&self.upper))
                .all(|(&q, (&lo, &hi))| q >= lo - eps && q <= hi + eps)
    }

    /// Middle of each joint range (0 for a continuous joint).
    pub fn mid_range(&self) -> Vec<Real> {
        self.lower
            .iter()
            .zip(&self.upper)
            .map(|(&l, &u)| range_mid(l, u))
            .collect()
    }
}

/// Middle of `[lower, upper]`; 0 when either end is infinite (a continuous
/// joint's range is the whole line, centred on 0).
pub(crate) fn range_mid(lower: Real, upper: Real) -> Real {
    match lower.is_finite() && upper.is_finite() {
        true => 0.5 * (lower + upper),
        false => 0.0,
    }
}

/// A loaded robot: kinematic tree, joints, arms and planning data.
#[derive(Debug, Clone)]
pub struct RobotModel {
    pub(crate) name: String,
    pub(crate) source: String,
    pub(crate) links: Vec<Link>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) mimics: Vec<MimicJoint>,
    pub(crate) arms: Vec<Arm>,
    pub(crate) home: Vec<Real>,
    pub(crate) gripper: Gripper,
    pub(crate) self_collision_skip: Vec<(usize, usize)>,
    pub(crate) allowed_collisions: Option<AllowedCollisions>,
    /// The SRDF's `group_state`s.
    pub(crate) postures: Vec<crate::srdf::NamedPosture>,
    /// The URDF text the model was built from.
    pub(crate) urdf: std::sync::Arc<str>,
    /// The description's recommended tabletop set-up.
    pub(crate) camera: Option<crate::description::CameraSetup>,
}

impl RobotModel {
    /// Robot name (the description's `name`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The description's recommended tabletop set-up (`camera:`), if any.
    pub fn camera(&self) -> Option<&crate::description::CameraSetup> {
        self.camera.as_ref()
    }

    /// Where the model came from: `built-in` or the description path.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The URDF text the model was built from, for tools that parse it
    /// themselves (the independent checker `afford-check`).
    pub fn urdf(&self) -> &str {
        &self.urdf
    }

    /// All links, parents before children; index 0 is the base frame.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// Movable joints, in configuration order.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Joints that follow another (`<mimic>`), in tree order; none of them
    /// is in [`Self::joints`].
    pub fn mimic_joints(&self) -> &[MimicJoint] {
        &self.mimics
    }

    /// Degrees of freedom of the whole robot.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    pub fn arms(&self) -> &[Arm] {
        &self.arms
    }

    /// Arm by name.
    pub fn arm(&self, name: &str) -> Result<&Arm, KinematicsError> {
        self.arms
            .iter()
            .find(|a| a.name == name)
            .ok_or_else(|| KinematicsError::UnknownArm {
                robot: self.name.clone(),
                arm: name.to_string(),
                known: self
                    .arms
                    .iter()
                    .map(|a| a.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The comfortable robot configuration.
    pub fn home(&self) -> &[Real] {
        &self.home
    }

    /// The postures the SRDF names (`group_state`), in its order.
    pub fn named_postures(&self) -> &[crate::srdf::NamedPosture] {
        &self.postures
    }

    /// The robot configuration of a named posture: home, with the posture's
    /// joints set; `None` when no posture has that name.
    pub fn posture(&self, name: &str) -> Option<Vec<Real>> {
        let posture = self.postures.iter().find(|p| p.name == name)?;
        let mut q = self.home.clone();
        for &(i, v) in &posture.values {
            q[i] = v;
        }
        Some(q)
    }

    pub fn gripper(&self) -> &Gripper {
        &self.gripper
    }

    /// The description's `allowed_collisions` section as written (`None`:
    /// only adjacent links are skipped).
    pub fn allowed_collisions(&self) -> Option<&AllowedCollisions> {
        self.allowed_collisions.as_ref()
    }

    /// Link index pairs never checked for self-collision (smaller index first):
    /// the adjacent pairs, the description's `allowed_collisions` and the
    /// SRDF's `disable_collisions`.
    pub fn self_collision_skip(&self) -> &[(usize, usize)] {
        &self.self_collision_skip
    }

    /// True when the pair of links needs no self-collision check.
    pub fn skips_self_collision(&self, a: usize, b: usize) -> bool {
        let key = (a.min(b), a.max(b));
        a == b || self.self_collision_skip.binary_search(&key).is_ok()
    }

    /// Index of a link by name.
    pub fn link_index(&self, name: &str) -> Result<usize, KinematicsError> {
        self.links
            .iter()
            .position(|l| l.name == name)
            .ok_or_else(|| KinematicsError::UnknownLink {
                robot: self.name.clone(),
                link: name.to_string(),
            })
    }

    /// Index of a movable joint by name.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    fn check_config(&self, q: &[Real]) -> Result<(), KinematicsError> {
        if q.len() != self.joints.len() {
            return Err(KinematicsError::ConfigSize {
                what: "robot configuration",
                expected: self.joints.len(),
                got: q.len(),
            });
        }
        Ok(())
    }

    /// Pose of every link in the base frame (`pose_base_link`), in [`Self::links`] order.
    pub fn link_poses(&self, q: &[Real]) -> Result<Vec<Pose>, KinematicsError> {
        self.check_config(q)?;
        let mut poses: Vec<Pose> = Vec::with_capacity(self.links.len());
        for link in &self.links {
            let parent = link.parent.map_or_else(Pose::identity, |p| poses[p]);
            poses.push(parent * link.origin * motion(link.joint, q));
        }
        Ok(poses)
    }

    /// Pose of one link in the base frame.
    pub fn link_pose(&self, q: &[Real], link: &str) -> Result<Pose, KinematicsError> {
        self.check_config(q)?;
        let mut index = Some(self.link_index(link)?);
        let mut pose = Pose::identity();
        while let Some(i) = index {
            let l = &self.links[i];
            pose = l.origin * motion(l.joint, q) * pose;
            index = l.parent;
        }
        Ok(pose)
    }

    /// A robot configuration with every arm except `active` at its park posture
    /// (arms without a park posture stay where `q` has them).
    pub fn parked_except(&self, q: &[Real], active: &str) -> Vec<Real> {
        let mut out = q.to_vec();
        for arm in self.arms.iter().filter(|a| a.name != active) {
            for &(i, v) in &arm.park {
                out[i] = v;
            }
        }
        out
    }
}

#[inline]
fn motion(joint: Option<JointDrive>, q: &[Real]) -> Pose {
    let Some(d) = joint else {
        return Pose::identity();
    };
    match d.kind {
        JointKind::Prismatic => Pose::from_parts(
            Translation3::from(d.axis * d.position(q)),
            UnitQuaternion::identity(),
        ),
        JointKind::Fixed => Pose::identity(),
        _ => Pose::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_scaled_axis(d.axis * d.position(q)),
        ),
    }
}
