//! Surface samples of a URDF's meshes, for `afford robots check`'s coverage
//! measurement: each `<collision>` and `<visual>` mesh read again from its
//! file (not from the model's hull), scaled and placed in its link frame;
//! the samples are each triangle's corners, edge midpoints and centroid.

use std::path::Path;

use super::{MeshSearch, PackagePaths, formats, resolve};
use crate::error::KinematicsError;
use crate::math::{Pose, Vec3};

/// One mesh's surface samples in its link frame.
#[derive(Debug, Clone)]
pub struct MeshSurface {
    pub link: String,
    /// A `<visual>` mesh (else `<collision>`).
    pub visual: bool,
    /// The `filename` as the URDF writes it.
    pub filename: String,
    pub samples: Vec<Vec3>,
}

/// The surface samples of every mesh of the URDF at `urdf` (module docs).
/// A visual mesh whose file cannot be found or read is skipped (the model
/// never reads it); a collision mesh's problem is an error, as on loading.
pub fn mesh_surfaces(
    urdf: &Path,
    packages: &PackagePaths,
) -> Result<Vec<MeshSurface>, KinematicsError> {
    let text = crate::load::read_text(urdf)?;
    let dir = urdf.parent().unwrap_or_else(|| Path::new("."));
    let search = MeshSearch {
        urdf_dir: dir,
        packages,
    };
    let mut out = Vec::new();
    for m in crate::urdf::mesh_elements(&text, urdf)? {
        let read = || -> Result<Vec<Vec3>, crate::MeshProblem> {
            let path = resolve::resolve(&m.filename, search.urdf_dir, search.packages)?;
            let format = formats::Format::of(&path)
                .ok_or_else(|| crate::MeshProblem::UnknownFormat { path: path.clone() })?;
            format.read(&super::read(&path)?, &path)
        };
        let points = match (read(), m.visual) {
            (Ok(p), _) => p,
            (Err(_), true) => continue,
            (Err(problem), false) => {
                return Err(KinematicsError::Mesh {
                    file: urdf.to_path_buf(),
                    link: m.link.clone(),
                    mesh: m.filename.clone(),
                    problem: Box::new(problem),
                });
            }
        };
        out.push(MeshSurface {
            link: m.link,
            visual: m.visual,
            filename: m.filename,
            samples: samples(&points, m.scale, &m.origin),
        });
    }
    Ok(out)
}

/// Corners, edge midpoints and centroid of each triangle (3 points each).
fn samples(points: &[Vec3], scale: [f64; 3], origin: &Pose) -> Vec<Vec3> {
    let place = |p: &Vec3| {
        let s = Vec3::new(p.x * scale[0], p.y * scale[1], p.z * scale[2]);
        (origin * nalgebra::Point3::from(s)).coords
    };
    let mut out = Vec::with_capacity(points.len() * 7 / 3);
    for t in points.chunks_exact(3) {
        let [a, b, c] = [place(&t[0]), place(&t[1]), place(&t[2])];
        out.extend([
            a,
            b,
            c,
            (a + b) / 2.0,
            (b + c) / 2.0,
            (c + a) / 2.0,
            (a + b + c) / 3.0,
        ]);
    }
    out
}
