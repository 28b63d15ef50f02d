//! Reading the vertices of a mesh file: STL (binary and ASCII, `stl_io`),
//! Wavefront OBJ (`tobj`) and Collada DAE (`dae`). Each reader returns the
//! vertices its triangles use, in the file's own units and frame.

use std::io::Cursor;
use std::path::Path;

use crate::error::MeshProblem;
use crate::math::Vec3;

/// The vertices a mesh's triangles use (repeats allowed).
pub(crate) type Points = Vec<Vec3>;

/// The supported formats, chosen by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Format {
    Stl,
    Obj,
    Dae,
}

impl Format {
    /// The format of `path` by its extension (any case); `None` when unknown.
    pub(crate) fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(Self::Stl),
            "obj" => Some(Self::Obj),
            "dae" => Some(Self::Dae),
            _ => None,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Stl => "STL",
            Self::Obj => "OBJ",
            Self::Dae => "Collada DAE",
        }
    }

    /// The used vertices of a file's bytes; `path` only names the file.
    pub(crate) fn read(self, bytes: &[u8], path: &Path) -> Result<Points, MeshProblem> {
        let points = match self {
            Self::Stl => stl(bytes),
            Self::Obj => obj(bytes),
            Self::Dae => super::dae::points(bytes),
        }
        .map_err(|message| MeshProblem::Malformed {
            path: path.to_path_buf(),
            format: self.name(),
            message,
        })?;
        match points.is_empty() {
            true => Err(MeshProblem::Empty {
                path: path.to_path_buf(),
            }),
            false => Ok(points),
        }
    }
}

/// STL, binary or ASCII (`stl_io` tells them apart).
fn stl(bytes: &[u8]) -> Result<Points, String> {
    let mesh = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| e.to_string())?;
    let vertex = |i: usize| {
        let v = mesh
            .vertices
            .get(i)
            .ok_or("a triangle names a missing vertex")?;
        Ok(Vec3::new(v[0].into(), v[1].into(), v[2].into()))
    };
    mesh.faces
        .iter()
        .flat_map(|f| f.vertices)
        .map(vertex)
        .collect()
}

/// Wavefront OBJ: every face of every object, triangulated; materials,
/// points and lines ignored.
fn obj(bytes: &[u8]) -> Result<Points, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj_buf(&mut Cursor::new(bytes), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| e.to_string())?;
    let mut points = Vec::new();
    for model in &models {
        let p = &model.mesh.positions;
        for &i in &model.mesh.indices {
            let k = 3 * i as usize;
            let xyz = p.get(k..k + 3).ok_or("a face names a missing vertex")?;
            points.push(Vec3::new(xyz[0], xyz[1], xyz[2]));
        }
    }
    Ok(points)
}
