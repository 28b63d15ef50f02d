//! A mesh's points, scaled, become the vertices of their convex hull
//! (parry's `try_convex_hull`), refused when out of bounds, too thin
//! ([`MIN_SHAPE_SIZE_M`]) or with more than [`MAX_HULL_VERTICES`] corners.

use std::path::Path;
use std::sync::Arc;

use parry3d::math::Vector as PVec;

use crate::bounds::{MAX_HULL_VERTICES, MAX_SHAPE_SIZE_M, MIN_SHAPE_SIZE_M};
use crate::error::MeshProblem;
use crate::math::{Real, Vec3};

/// The corners of the convex hull of `points` scaled per axis by `scale`;
/// `path` only names the file in errors.
pub(crate) fn scaled_hull(
    points: &[Vec3],
    scale: [Real; 3],
    path: &Path,
) -> Result<Arc<[Vec3]>, MeshProblem> {
    let out_of_bounds = |reason: String| MeshProblem::OutOfBounds {
        path: path.to_path_buf(),
        reason,
    };
    if !scale.iter().all(|s| s.is_finite() && *s != 0.0) {
        return Err(out_of_bounds(format!(
            "scale {scale:?} must be finite and non-zero"
        )));
    }
    let scaled: Vec<PVec> = points
        .iter()
        .map(|p| PVec::new(p.x * scale[0], p.y * scale[1], p.z * scale[2]))
        .collect();
    if !scaled
        .iter()
        .all(|p| p.is_finite() && p.abs().max_element() <= MAX_SHAPE_SIZE_M)
    {
        return Err(out_of_bounds(format!(
            "a vertex is not finite or farther than {MAX_SHAPE_SIZE_M} m from the mesh origin (after scale)"
        )));
    }
    let degenerate = |reason: String| MeshProblem::DegenerateHull {
        path: path.to_path_buf(),
        reason,
    };
    let hull = std::panic::catch_unwind(|| parry3d::transformation::try_convex_hull(&scaled));
    let (vertices, triangles) = match hull {
        Ok(Ok(hull)) => hull,
        Ok(Err(e)) => return Err(degenerate(format!("{e:?}"))),
        Err(_) => return Err(degenerate("the hull computation failed".into())),
    };
    if vertices.len() > MAX_HULL_VERTICES {
        return Err(degenerate(format!(
            "the hull has {} vertices, more than {MAX_HULL_VERTICES}: simplify the mesh",
            vertices.len()
        )));
    }
    let thickness = thinnest_width(&vertices, &triangles);
    if thickness.is_nan() || thickness < MIN_SHAPE_SIZE_M {
        return Err(degenerate(format!(
            "the hull is {thickness:.2e} m thin, less than {MIN_SHAPE_SIZE_M} m (flat or a line)"
        )));
    }
    // What the collision crates build from these vertices must exist.
    if parry3d::shape::ConvexPolyhedron::from_convex_hull(&vertices).is_none() {
        return Err(degenerate(
            "parry builds no convex polyhedron from it".into(),
        ));
    }
    Ok(vertices.iter().map(|v| Vec3::new(v.x, v.y, v.z)).collect())
}

/// The smallest width of the hull across its faces' normals (0 for a flat
/// hull, whose faces all lie in one plane).
fn thinnest_width(vertices: &[PVec], triangles: &[[u32; 3]]) -> Real {
    let width = |n: PVec| {
        let (lo, hi) = vertices.iter().fold((Real::MAX, Real::MIN), |(lo, hi), v| {
            (lo.min(n.dot(*v)), hi.max(n.dot(*v)))
        });
        hi - lo
    };
    triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| vertices.get(i as usize).copied());
            let n = (b? - a?).cross(c? - a?).try_normalize()?;
            Some(width(n))
        })
        .reduce(Real::min)
        .unwrap_or(0.0)
}
