//! Robot geometry: one rigid body per collider of the robot description,
//! posed by forward kinematics ([`RobotModel::link_poses`]), and the motion
//! bound that makes the joint-path check continuous.
//!
//! Motion bound (conservative advancement, Schwarzer–Saha–Latombe). For body
//! `B` and each joint `j` above it, `r[j][B]` is a configuration-independent
//! upper bound on the distance from joint `j`'s axis to any point of `B`:
//! the sum of the (rigid) distances between consecutive joint origins from
//! `j` down to `B`'s link, plus the distance from the last joint origin to the
//! centre of `B`'s bounding sphere, plus its radius. Then for any two
//! configurations `q`, `q'` and any point `p` of `B`,
//!
//! `|p(q') - p(q)| <= sum_j r[j][B] * |q'_j - q_j|`
//!
//! (move the joints one at a time; a point at distance `r` from an axis
//! rotated by `dq` moves by a chord `<= r |dq|`; a prismatic joint moves it by
//! `|dq|`). Along the straight segment `q(s)` the same bound holds for every
//! `s`, so a body whose clearance is `d` cannot touch anything before the
//! bound reaches `d`. For two robot bodies only the joints above one but not
//! both count: a shared joint moves both rigidly and leaves their distance
//! unchanged.
//!
//! Mimic joints. A configuration joint `j` drives every joint that mimics it,
//! each at `|multiplier|` times its rate, so `r[j][B]` sums, over the
//! joints above `B` that `j` drives, `|multiplier|` times that joint's own
//! bound; a prismatic mimic joint's travel is its leader's scaled the same
//! way. A configuration joint that drives several joints may move two
//! bodies differently even when it is above both, so for such a joint the
//! pair's coefficient is the sum of both bodies' (never 0).

use afford_kinematics::{JointDrive, JointKind, Pose, RobotModel};
use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};
use parry3d::math::Vector as PVec;
use parry3d::shape::SharedShape;

use crate::error::{CollisionError, path_err};

/// A box rigidly held by the gripper, posed in the arm's tool frame. When the
/// target is grasped it leaves the scene (the check ignores the obstacle with
/// the same name) and rides with the tool until released.
#[derive(Debug, Clone, PartialEq)]
pub struct Attachment {
    /// Name of the held object (the scene obstacle it came from).
    pub name: String,
    /// Half sizes of the held box, metres.
    pub half_extents: [f64; 3],
    /// The object is round: the stadium prism inside the box
    /// ([`crate::scene::round_parts`]), as in the scene.
    pub round: bool,
    /// Pose of the box centre in the tool frame (`pose_tool_object`).
    pub pose_tool_object: Pose,
}

impl Attachment {
    /// The object described by a scene box, grasped with the tool at
    /// `pose_base_tool`: the box keeps the pose it had on the table relative
    /// to the tool.
    pub fn grasped(b: &crate::SceneBox, table_z: f64, pose_base_tool: &Pose) -> Self {
        let pose_base_object = Pose::from_parts(
            Translation3::new(b.centre[0], b.centre[1], table_z + 0.5 * b.size[2]),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), b.yaw),
        );
        Self {
            name: b.name.clone(),
            half_extents: [0.5 * b.size[0], 0.5 * b.size[1], 0.5 * b.size[2]],
            round: b.round,
            pose_tool_object: pose_base_tool.inverse() * pose_base_object,
        }
    }

    /// The held solid in its own frame (centre of its box).
    pub(crate) fn shape(&self) -> SharedShape {
        crate::scene::object_shape(self.half_extents, self.round)
    }

    pub(crate) fn validate(&self) -> Result<(), CollisionError> {
        if self
            .half_extents
            .iter()
            .any(|h| !(h.is_finite() && *h > 0.0))
        {
            return Err(path_err("attached.half_extents", "must be finite and > 0"));
        }
        let t = self.pose_tool_object.translation.vector;
        if !(t.iter().all(|v| v.is_finite())
            && self
                .pose_tool_object
                .rotation
                .coords
                .iter()
                .all(|v| v.is_finite()))
        {
            return Err(path_err("attached.pose_tool_object", "must be finite"));
        }
        Ok(())
    }
}

/// One collider of the robot, in its link frame.
#[derive(Debug, Clone)]
pub(crate) struct Body {
    pub link: usize,
    pub name: String,
    pub shape: SharedShape,
    /// Pose of the parry shape in its link frame (`pose_link_shape`).
    pub pose_link_shape: Pose,
    /// Motion-bound coefficient per robot joint (m/rad; 0 when not above).
    pub radii: Vec<f64>,
    /// Bit j set when joint j is above the body.
    pub ancestors: u128,
}

/// The robot's collision geometry and motion bounds.
#[derive(Debug, Clone)]
pub struct RobotGeometry {
    pub(crate) model: RobotModel,
    pub(crate) bodies: Vec<Body>,
    pub(crate) link_ancestors: Vec<u128>,
    /// Bit j set when configuration joint j drives more than one joint
    /// (it has mimic joints).
    pub(crate) multi_drive: u128,
    /// Bit j set when configuration joint j drives a prismatic mimic joint
    /// (its limits bound that joint's travel, as a prismatic joint's own do).
    drives_prismatic: u128,
    /// Link poses (base frame) at the reference configuration.
    ref_poses: Vec<Pose>,
    /// Body pairs (indices, smaller first) checked for self-collision.
    pub(crate) self_pairs: Vec<(usize, usize)>,
}

impl RobotGeometry {
    /// Builds the geometry of every collider of `model`.
    pub fn new(model: &RobotModel) -> Result<Self, CollisionError> {
        let dof = model.dof();
        if dof > 128 {
            return Err(path_err("robot", "more than 128 joints are not supported"));
        }
        let q0 = model.home().to_vec();
        let ref_poses = model.link_poses(&q0)?;
        // Which links each joint moves: perturb it and compare poses.
        let mut link_ancestors = vec![0u128; model.links().len()];
        for j in 0..dof {
            let mut q = q0.clone();
            q[j] += 0.25;
            let moved = model.link_poses(&q)?;
            for (i, (a, b)) in ref_poses.iter().zip(&moved).enumerate() {
                let (dp, dr) = afford_kinematics::pose_distance(a, b);
                if dp > 1e-12 || dr > 1e-12 {
                    link_ancestors[i] |= 1 << j;
                }
            }
        }
        let multi_drive = model
            .mimic_joints()
            .iter()
            .fold(0u128, |bits, m| bits | 1 << m.joint);
        let mut geometry = Self {
            model: model.clone(),
            bodies: Vec::new(),
            link_ancestors,
            multi_drive,
            drives_prismatic: (model.links().iter())
                .filter_map(|l| l.drive())
                .filter(|d| d.mimic.is_some() && d.kind == JointKind::Prismatic)
                .fold(0u128, |bits, d| bits | 1 << d.joint),
            ref_poses,
            self_pairs: Vec::new(),
        };
        for (li, link) in model.links().iter().enumerate() {
            let several = link.colliders.len() > 1;
            for (ci, c) in link.colliders.iter().enumerate() {
                let (shape, fix) = parry_shape(&c.shape).ok_or_else(|| {
                    path_err(
                        format!("robot link '{}'", link.name),
                        "parry builds no convex polyhedron from its mesh hull",
                    )
                })?;
                let pose_link_shape = c.origin * fix;
                let name = if several {
                    format!("{}#{ci}", link.name)
                } else {
                    link.name.clone()
                };
                let body = geometry.body(li, name, shape, pose_link_shape);
                geometry.bodies.push(body);
            }
        }
        let n = geometry.bodies.len();
        for a in 0..n {
            for b in a + 1..n {
                let (la, lb) = (geometry.bodies[a].link, geometry.bodies[b].link);
                if la != lb && !model.skips_self_collision(la, lb) {
                    geometry.self_pairs.push((a, b));
                }
            }
        }
        Ok(geometry)
    }

    /// The robot model this geometry was built from.
    pub fn model(&self) -> &RobotModel {
        &self.model
    }

    /// Names of the robot bodies (link name, `#k` suffix when a link has several colliders).
    pub fn body_names(&self) -> Vec<&str> {
        self.bodies.iter().map(|b| b.name.as_str()).collect()
    }

    /// Link-name pairs checked for self-collision.
    pub fn self_collision_pairs(&self) -> Vec<(&str, &str)> {
        self.self_pairs
            .iter()
            .map(|&(a, b)| (self.bodies[a].name.as_str(), self.bodies[b].name.as_str()))
            .collect()
    }

    /// A body rigidly attached to `link` with pose `pose_link_shape`.
    pub(crate) fn body(
        &self,
        link: usize,
        name: String,
        shape: SharedShape,
        pose_link_shape: Pose,
    ) -> Body {
        let ancestors = self.link_ancestors[link];
        let sphere = shape.compute_local_bounding_sphere();
        let centre_shape = sphere.center;
        let centre_link =
            pose_link_shape * Point3::new(centre_shape.x, centre_shape.y, centre_shape.z);
        let centre_base = self.ref_poses[link] * centre_link;
        let links = self.model.links();
        let origin = |l: usize| self.ref_poses[l].translation.vector;
        let mut radii = vec![0.0; self.model.dof()];
        let mut acc = sphere.radius();
        let mut below: Option<(usize, JointDrive)> = None;
        let mut up = Some(link);
        while let Some(l) = up {
            if let Some(drive) = links[l].drive() {
                acc += match below {
                    None => (centre_base.coords - origin(l)).norm(),
                    Some((k, d)) => (origin(k) - origin(l)).norm() + self.prismatic_travel(d),
                };
                radii[drive.joint] += drive.gain()
                    * match drive.kind {
                        JointKind::Prismatic => 1.0,
                        _ => acc,
                    };
                below = Some((l, drive));
            }
            up = links[l].parent;
        }
        Body {
            link,
            name,
            shape,
            pose_link_shape,
            radii,
            ancestors,
        }
    }

    /// How far a prismatic joint's child origin can be from where it is at the
    /// reference configuration (0 for revolute joints; a mimic joint's is
    /// its leader's times the multiplier).
    fn prismatic_travel(&self, drive: JointDrive) -> f64 {
        if drive.kind != JointKind::Prismatic {
            return 0.0;
        }
        let joint = &self.model.joints()[drive.joint];
        let h = self.model.home()[drive.joint];
        drive.gain() * (joint.lower - h).abs().max((joint.upper - h).abs())
    }

    /// Checks a robot configuration's length and values (prismatic joints,
    /// and the leaders of prismatic mimic joints, must stay inside their
    /// limits for the motion bound to hold).
    pub(crate) fn check_config(&self, q: &[f64], field: &str) -> Result<(), CollisionError> {
        if q.len() != self.model.dof() {
            return Err(path_err(
                field,
                format!(
                    "has {} values, the robot has {} joints",
                    q.len(),
                    self.model.dof()
                ),
            ));
        }
        for (j, (v, joint)) in q.iter().zip(self.model.joints()).enumerate() {
            if !v.is_finite() {
                return Err(path_err(field, format!("value {j} is not finite")));
            }
            if joint.kind == JointKind::Prismatic && !joint.within(*v, 1e-9) {
                return Err(path_err(
                    field,
                    format!("prismatic joint '{}' outside its limits", joint.name),
                ));
            }
            if self.drives_prismatic & 1 << j != 0 && !joint.within(*v, 1e-9) {
                return Err(path_err(
                    field,
                    format!(
                        "joint '{}' (leader of a prismatic mimic joint) outside its limits",
                        joint.name
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Indices of bodies rigidly attached to the arm's tool frame: bodies
    /// moved by exactly the joints that move the tool link (for a tree, such
    /// links all hang rigidly below the deepest of those joints).
    ///
    /// Joints of no arm (a gripper's finger joints) never move while an arm
    /// plans, so they are left out of the comparison: the fingers of a
    /// gripper with its own joints count as rigid with the tool.
    pub(crate) fn tool_rigid_bodies(&self, tool_link: usize) -> Vec<usize> {
        let arm_joints = (self.model.arms().iter())
            .flat_map(|a| a.joint_indices.iter())
            .fold(0u128, |bits, &j| bits | 1 << j);
        let mask = self.link_ancestors[tool_link] & arm_joints;
        (0..self.bodies.len())
            .filter(|&b| self.link_ancestors[self.bodies[b].link] & arm_joints == mask)
            .collect()
    }
}

/// parry shape for a kinematics shape, and the fix-up pose (parry cylinders
/// are along local y; the description's are along z). A mesh hull is
/// rebuilt from its vertices (`None` if parry refuses them).
fn parry_shape(shape: &afford_kinematics::Shape) -> Option<(SharedShape, Pose)> {
    use afford_kinematics::Shape as S;
    Some(match *shape {
        S::Box { half_extents } => (
            SharedShape::cuboid(half_extents.x, half_extents.y, half_extents.z),
            Pose::identity(),
        ),
        S::Cylinder {
            radius,
            half_length,
        } => (
            SharedShape::cylinder(half_length, radius),
            Pose::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
            ),
        ),
        S::Capsule {
            radius,
            half_length,
        } => (
            SharedShape::capsule_z(half_length, radius),
            Pose::identity(),
        ),
        S::Sphere { radius } => (SharedShape::ball(radius), Pose::identity()),
        S::ConvexHull { ref vertices } => {
            let points: Vec<PVec> = vertices.iter().map(|v| PVec::new(v.x, v.y, v.z)).collect();
            (SharedShape::convex_hull(&points)?, Pose::identity())
        }
    })
}

#[cfg(test)]
mod tests;
