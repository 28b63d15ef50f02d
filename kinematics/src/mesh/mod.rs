//! Collision meshes. A `<collision><geometry><mesh filename=.. scale=..>`
//! becomes the convex hull of the mesh's vertices ([`Shape::ConvexHull`]).
//!
//! - Formats, by extension (any case): STL, binary or ASCII (`.stl`),
//!   Wavefront OBJ (`.obj`), Collada (`.dae`; see `dae` for what is read).
//! - `scale="sx sy sz"` multiplies each vertex per axis (default 1 1 1).
//! - `filename` is `package://NAME/path` (the package search path of
//!   [`PackagePaths`]), `file://path` or a plain path; relative paths are
//!   taken from the URDF's folder.
//! - The rule: one convex hull per mesh. It contains the mesh, so a check
//!   against it is conservative: a concave part (a U-shaped bracket, a
//!   hollow gripper palm) is treated as filled. A decomposition into several
//!   convex parts (parry's VHACD, `SharedShape::convex_decomposition`) would
//!   follow concave parts closer; it is not done.
//!
//! Refused with [`MeshProblem`], naming the URDF, the link and the mesh: an
//! unresolvable name, a missing or unreadable file, a file larger than
//! [`MAX_MESH_FILE_BYTES`], a malformed or empty mesh, and a hull that is
//! flat, out of bounds or has more than [`crate::bounds::MAX_HULL_VERTICES`]
//! corners.
//!
//! [`Shape::ConvexHull`]: crate::Shape::ConvexHull

mod dae;
mod formats;
mod hull;
pub(crate) mod resolve;
mod surface;

use std::io::Read;
use std::path::Path;
use std::sync::Arc;

pub use resolve::PackagePaths;
pub use surface::{MeshSurface, mesh_surfaces};

use crate::bounds::MAX_MESH_FILE_BYTES;
use crate::error::MeshProblem;
use crate::math::{Real, Vec3};

/// Where a URDF's meshes are looked for.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MeshSearch<'a> {
    /// The URDF's folder.
    pub urdf_dir: &'a Path,
    pub packages: &'a PackagePaths,
}

/// The hull vertices of the mesh `filename` scaled by `scale` (module docs).
pub(crate) fn convex_hull(
    filename: &str,
    scale: [Real; 3],
    search: MeshSearch<'_>,
) -> Result<Arc<[Vec3]>, MeshProblem> {
    let path = resolve::resolve(filename, search.urdf_dir, search.packages)?;
    let format = formats::Format::of(&path)
        .ok_or_else(|| MeshProblem::UnknownFormat { path: path.clone() })?;
    let bytes = read(&path)?;
    let points = format.read(&bytes, &path)?;
    hull::scaled_hull(&points, scale, &path)
}

/// The file's bytes, at most [`MAX_MESH_FILE_BYTES`].
fn read(path: &Path) -> Result<Vec<u8>, MeshProblem> {
    let unreadable = |message: String| MeshProblem::Unreadable {
        path: path.to_path_buf(),
        message,
    };
    let file = crate::open_regular(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => MeshProblem::Missing {
            path: path.to_path_buf(),
        },
        _ => unreadable(e.to_string()),
    })?;
    let mut bytes = Vec::new();
    file.take(MAX_MESH_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| unreadable(e.to_string()))?;
    if bytes.len() as u64 > MAX_MESH_FILE_BYTES {
        return Err(unreadable(format!(
            "larger than {MAX_MESH_FILE_BYTES} bytes, the largest mesh read"
        )));
    }
    Ok(bytes)
}
