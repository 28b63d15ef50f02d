//! Forward kinematics over the parsed URDF tree, for the draft (no
//! description exists yet): every link's pose at joint values given by
//! name, unnamed joints at 0 clamped into their limits, mimic joints from
//! their leaders.

use std::collections::BTreeMap;

use nalgebra::{Translation3, Unit, UnitQuaternion};

use crate::math::{Pose, Real, Vec3};
use crate::model::JointKind;
use crate::urdf::{Tree, TreeJoint};

/// The pose of every link in the root frame.
pub(crate) fn poses(tree: &Tree, values: &BTreeMap<String, Real>) -> Vec<Pose> {
    let value = |j: &TreeJoint| -> Real {
        let own = |name: &str, lo: Real, hi: Real| {
            values
                .get(name)
                .copied()
                .unwrap_or_else(|| 0.0f64.clamp(lo, hi))
        };
        match &j.resolved {
            Some(r) => {
                let leader = tree
                    .links
                    .iter()
                    .filter_map(|l| l.joint.as_ref())
                    .find(|l| l.name == r.root);
                let q = leader.map_or(0.0, |l| own(&l.name, l.lower, l.upper));
                r.mimic.multiplier * q + r.mimic.offset
            }
            None => own(&j.name, j.lower, j.upper),
        }
    };
    let mut out: Vec<Pose> = Vec::with_capacity(tree.links.len());
    for l in &tree.links {
        let parent = l.parent.map_or_else(Pose::identity, |p| out[p]);
        let pose = match &l.joint {
            None => Pose::identity(),
            Some(j) => parent * j.origin * motion(j, value(j)),
        };
        out.push(pose);
    }
    out
}

/// The joint's own motion at value `q`.
fn motion(j: &TreeJoint, q: Real) -> Pose {
    match j.kind {
        JointKind::Fixed => Pose::identity(),
        JointKind::Prismatic => {
            Pose::from_parts(Translation3::from(j.axis * q), UnitQuaternion::identity())
        }
        JointKind::Revolute | JointKind::Continuous => Pose::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Unit::new_normalize(j.axis), q),
        ),
    }
}

/// The centres of link `l`'s colliders in the link frame (a hull's by the
/// mean of its corners).
pub(crate) fn collider_points(tree: &Tree, l: usize) -> Vec<Vec3> {
    let mut points = Vec::new();
    for c in &tree.links[l].colliders {
        match &c.shape {
            crate::Shape::ConvexHull { vertices } => {
                points.extend(
                    vertices
                        .iter()
                        .map(|v| c.origin * nalgebra::Point3::from(*v))
                        .map(|p| p.coords),
                );
            }
            _ => points.push(c.origin.translation.vector),
        }
    }
    points
}
