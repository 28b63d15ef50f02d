//! Coverage of `robots check`: for every mesh of a link (its `<collision>`
//! meshes and its `<visual>` ones), how far the mesh's surface samples lie
//! outside the link's collision model, the shapes the checks use (a mesh's
//! convex hull, boxes, cylinders, capsules, spheres). The samples are read
//! again from the mesh files (`afford_kinematics::mesh_surfaces`), and the
//! distance is parry's point query against a polyhedron rebuilt from the
//! model's hull corners, or the primitive's closed form: none of the code
//! that made the hull. A collision mesh is inside its hull by construction
//! (0 up to rounding); a visual mesh may stick out of a coarser collision
//! model, and what sticks out is what the checks do not see.

use afford_kinematics::{Collider, MeshSurface, RobotModel, Shape, Vec3};
use parry3d::math::Vector as PVec;
use parry3d::query::PointQuery;
use parry3d::shape::ConvexPolyhedron;
use serde::Serialize;

/// Largest distance a mesh's surface may lie outside its link's collision
/// model, m: 2 mm, a tenth of the smallest default safety margin (the
/// scenario's 0.02 m obstacle margin), so a surface that far out still keeps
/// nine tenths of every margin.
pub const COVERAGE_TOLERANCE_M: f64 = 0.002;

/// One mesh's coverage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshCoverage {
    pub link: String,
    /// `collision` or `visual`.
    pub kind: &'static str,
    pub mesh: String,
    pub samples: usize,
    /// Largest and mean distance of the samples outside the collision
    /// model, m (0 inside).
    pub max_outside_m: f64,
    pub mean_outside_m: f64,
}

/// The coverage of every mesh in `surfaces` by `model`'s colliders.
pub fn coverage(model: &RobotModel, surfaces: &[MeshSurface]) -> Vec<MeshCoverage> {
    let mut out = Vec::new();
    for s in surfaces {
        let colliders = model
            .links()
            .iter()
            .find(|l| l.name == s.link)
            .map_or(&[][..], |l| &l.colliders[..]);
        let shapes: Vec<Query> = colliders.iter().map(Query::of).collect();
        let outside: Vec<f64> = (s.samples.iter())
            .map(|p| {
                (shapes.iter())
                    .map(|q| q.outside(p))
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let n = outside.len().max(1) as f64;
        out.push(MeshCoverage {
            link: s.link.clone(),
            kind: if s.visual { "visual" } else { "collision" },
            mesh: s.filename.clone(),
            samples: outside.len(),
            max_outside_m: outside.iter().copied().fold(0.0, f64::max),
            mean_outside_m: outside.iter().map(|d| d.min(1e3)).sum::<f64>() / n,
        });
    }
    out
}

/// One collider, ready for point queries in its link's frame.
struct Query {
    origin: afford_kinematics::Pose,
    shape: Primitive,
}

enum Primitive {
    Box(Vec3),
    Cylinder(f64, f64),
    Capsule(f64, f64),
    Sphere(f64),
    Hull(Option<ConvexPolyhedron>),
}

impl Query {
    fn of(c: &Collider) -> Self {
        let shape = match &c.shape {
            Shape::Box { half_extents } => Primitive::Box(*half_extents),
            Shape::Cylinder {
                radius,
                half_length,
            } => Primitive::Cylinder(*radius, *half_length),
            Shape::Capsule {
                radius,
                half_length,
            } => Primitive::Capsule(*radius, *half_length),
            Shape::Sphere { radius } => Primitive::Sphere(*radius),
            Shape::ConvexHull { vertices } => {
                let points: Vec<PVec> = vertices.iter().map(|v| PVec::new(v.x, v.y, v.z)).collect();
                Primitive::Hull(ConvexPolyhedron::from_convex_hull(&points))
            }
        };
        Self {
            origin: c.origin,
            shape,
        }
    }

    /// Distance of link-frame point `p` outside the shape (0 inside).
    fn outside(&self, p: &Vec3) -> f64 {
        let q = self
            .origin
            .inverse_transform_vector(&(*p - self.origin.translation.vector));
        let pos = |v: f64| v.max(0.0);
        match &self.shape {
            Primitive::Box(h) => Vec3::new(
                pos(q.x.abs() - h.x),
                pos(q.y.abs() - h.y),
                pos(q.z.abs() - h.z),
            )
            .norm(),
            Primitive::Cylinder(r, h) => {
                let radial = pos(q.xy().norm() - r);
                radial.hypot(pos(q.z.abs() - h))
            }
            Primitive::Capsule(r, h) => {
                let axis = Vec3::new(0.0, 0.0, q.z.clamp(-h, *h));
                pos((q - axis).norm() - r)
            }
            Primitive::Sphere(r) => pos(q.norm() - r),
            Primitive::Hull(Some(hull)) => {
                hull.distance_to_local_point(PVec::new(q.x, q.y, q.z), true)
            }
            Primitive::Hull(None) => f64::INFINITY,
        }
    }
}
