//! The robot's bodies as the checker sees them: one parry shape per collider
//! of the description (named `link`, or `link#k` when a link has several),
//! posed by [`Kinematics`], the held object as one more body on the tool
//! link, and the motion bound that spaces the dense check.
//!
//! Motion bound. For a body `B` whose link hangs below movable joints
//! `j1` (deepest) … `jm`, let `o_j` be joint `j`'s origin, `c`, `r` the
//! centre and radius of `B`'s bounding sphere. A revolute joint's origin is
//! fixed in both the links it joins, so these distances never change:
//!
//! `R_j1 = |c - o_j1| + r`,  `R_jk = R_j(k-1) + |o_j(k-1) - o_jk|`
//!
//! (plus the travel of `j(k-1)` if it is prismatic). Every point of `B` is
//! within `R_j` of joint `j`'s axis, so turning `j` by `dq` moves it at most
//! `R_j |dq|` (a prismatic joint moves it `|dq|`). Moving the joints one at
//! a time from `q` to `q'` shows `|p(q') - p(q)| <= sum_j R_j |q'_j - q_j|`
//! for every point `p` of `B`, and along the straight joint-space segment
//! the same holds for every intermediate configuration.
//!
//! A mimic joint moves `|multiplier|` times as fast as the robot joint that
//! drives it, so its term counts that much more (and a prismatic mimic
//! joint's travel is its driver's, scaled); a robot joint driving several
//! joints above a body sums their terms.

use afford_kinematics::{RobotModel, Shape};
use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};
use parry3d::math::Vector as PVec;
use parry3d::shape::{ConvexPolyhedron, SharedShape};

use crate::chain::{Ancestor, Iso, Kinematics};
use crate::scene::solid_box;

/// One rigid body of the robot (or the held object).
#[derive(Clone)]
pub(crate) struct Body {
    pub name: String,
    /// Description link the body is fixed to.
    pub link: usize,
    pub shape: SharedShape,
    /// Pose of the parry shape in its link frame.
    pub pose_link_shape: Iso,
    /// Motion-bound coefficient per robot joint (m/rad or m/m; 0 when the
    /// joint does not move the body).
    pub radii: Vec<f64>,
}

impl Body {
    /// Upper bound on how far any point of the body moves when the robot
    /// goes straight from `q` to `q + dq` (see the module docs).
    pub(crate) fn travel(&self, dq: &[f64]) -> f64 {
        self.radii.iter().zip(dq).map(|(r, d)| r * d.abs()).sum()
    }
}

/// Every collider of the robot as a [`Body`]; `Err` names a link whose
/// mesh hull parry refuses.
pub(crate) fn robot_bodies(robot: &RobotModel, kin: &Kinematics) -> Result<Vec<Body>, String> {
    let mut bodies = Vec::new();
    for (li, link) in robot.links().iter().enumerate() {
        let several = link.colliders.len() > 1;
        for (ci, c) in link.colliders.iter().enumerate() {
            let (shape, fix) = parry_shape(&c.shape).ok_or_else(|| {
                format!(
                    "link '{}': no convex polyhedron from its mesh hull",
                    link.name
                )
            })?;
            let name = match several {
                true => format!("{}#{ci}", link.name),
                false => link.name.clone(),
            };
            bodies.push(body(robot, kin, name, li, shape, c.origin * fix));
        }
    }
    Ok(bodies)
}

/// A body with its motion bound (module docs).
pub(crate) fn body(
    robot: &RobotModel,
    kin: &Kinematics,
    name: String,
    link: usize,
    shape: SharedShape,
    pose_link_shape: Iso,
) -> Body {
    let sphere = shape.compute_local_bounding_sphere();
    let c = sphere.center;
    let reference = kin.link_poses(robot.home());
    let centre = reference[link] * (pose_link_shape * Point3::new(c.x, c.y, c.z));
    let mut radii = vec![0.0; robot.dof()];
    let mut reach = sphere.radius();
    let mut below: Option<Ancestor> = None;
    for a in kin.ancestry(link) {
        reach += match below {
            None => (centre.coords - a.origin).norm(),
            Some(b) => (b.origin - a.origin).norm() + prismatic_travel(robot, &b),
        };
        radii[a.joint] += a.gain * if a.prismatic { 1.0 } else { reach };
        below = Some(*a);
    }
    Body {
        name,
        link,
        shape,
        pose_link_shape,
        radii,
    }
}

/// How far a prismatic joint's child origin can be from where it is at home.
fn prismatic_travel(robot: &RobotModel, a: &Ancestor) -> f64 {
    if !a.prismatic {
        return 0.0;
    }
    let joint = &robot.joints()[a.joint];
    let h = robot.home()[a.joint];
    a.gain * (joint.lower - h).abs().max((joint.upper - h).abs())
}

/// parry shape for a description shape and the fix-up pose: parry's
/// cylinders run along local y, URDF's along z. A mesh's hull is rebuilt
/// here from its vertices (`None` when parry refuses them).
fn parry_shape(shape: &Shape) -> Option<(SharedShape, Iso)> {
    Some(match shape {
        Shape::Box { half_extents: h } => (solid_box([h.x, h.y, h.z]), Iso::identity()),
        Shape::ConvexHull { vertices } => {
            let points: Vec<PVec> = vertices.iter().map(|v| PVec::new(v.x, v.y, v.z)).collect();
            let hull = ConvexPolyhedron::from_convex_hull(&points)?;
            (SharedShape::new(hull), Iso::identity())
        }
        Shape::Cylinder {
            radius,
            half_length,
        } => (
            SharedShape::cylinder(*half_length, *radius),
            Iso::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
            ),
        ),
        Shape::Capsule {
            radius,
            half_length,
        } => (
            SharedShape::capsule_z(*half_length, *radius),
            Iso::identity(),
        ),
        Shape::Sphere { radius } => (SharedShape::ball(*radius), Iso::identity()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bound holds: no point of any body moves farther than it says
    /// (measured on support points of every shape in 26 directions).
    #[test]
    fn motion_bound_covers_the_real_motion() {
        for robot in crate::chain::test_robots() {
            let name = robot.name();
            let kin = Kinematics::new(&robot).unwrap();
            let bodies = robot_bodies(&robot, &kin).unwrap();
            let q0 = robot.home().to_vec();
            for trial in 0..10 {
                let dq: Vec<f64> = (0..robot.dof())
                    .map(|i| 0.3 * ((trial * 5 + i) as f64).cos())
                    .collect();
                let q1: Vec<f64> = q0.iter().zip(&dq).map(|(a, b)| a + b).collect();
                let (p0, p1) = (kin.link_poses(&q0), kin.link_poses(&q1));
                for b in &bodies {
                    let support = b.shape.as_support_map().unwrap();
                    for k in 0..26 {
                        let d = [
                            (k % 3) as f64 - 1.0,
                            ((k / 3) % 3) as f64 - 1.0,
                            (k / 9) as f64 - 1.0,
                        ];
                        let dir = parry3d::math::Vector::new(d[0], d[1], d[2] + 0.01);
                        let s = support.local_support_point(dir);
                        let local = b.pose_link_shape * Point3::new(s.x, s.y, s.z);
                        let moved = (p1[b.link] * local - p0[b.link] * local).norm();
                        assert!(moved <= b.travel(&dq) + 1e-12, "{name} {}", b.name);
                    }
                }
            }
        }
    }

    /// The checker's own hull of a box mesh (rebuilt from the model's
    /// vertices) is as far from probes of every kind as the box primitive.
    #[test]
    fn a_mesh_body_has_the_distances_of_its_box() {
        let robots = crate::chain::test_robots();
        let robot = robots.iter().find(|r| r.name() == "mesh_box").unwrap();
        let kin = Kinematics::new(robot).unwrap();
        let mesh = &robot_bodies(robot, &kin).unwrap()[0];
        let Shape::ConvexHull { vertices } = &robot.links()[1].colliders[0].shape else {
            panic!("the fixture's part is a mesh");
        };
        let half = vertices
            .iter()
            .fold(Vector3::zeros(), |m, v| m.sup(&v.abs()));
        let cuboid = SharedShape::cuboid(half.x, half.y, half.z);
        let probes = [
            SharedShape::ball(0.02),
            SharedShape::capsule_z(0.04, 0.01),
            SharedShape::cylinder(0.03, 0.02),
        ];
        for k in 0..9 {
            let a = 0.7 * k as f64;
            let at = parry3d::math::Vector::new(0.3 * a.cos(), 0.3 * a.sin(), 0.1 * a.sin());
            let pose = crate::chain::to_parry(&Iso::new(
                Vector3::new(at.x, at.y, at.z),
                Vector3::new(0.2, a, -0.3 * a),
            ));
            let probe = &probes[k % 3];
            let d = |s: &SharedShape| {
                let id = parry3d::math::Pose::IDENTITY;
                parry3d::query::distance(&id, s.as_ref(), &pose, probe.as_ref())
                    .unwrap()
                    .distance
            };
            let (a, b) = (d(&mesh.shape), d(&cuboid));
            assert!(a > 0.0 && (a - b).abs() < 1e-6, "hull {a} vs box {b}");
        }
    }
}
