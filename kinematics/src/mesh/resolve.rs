//! Where a `<mesh filename=..>` lives: `package://NAME/rest` through the
//! package search path, `file://path`, or a plain path, relative paths taken
//! from the URDF's folder.
//!
//! The package search path, in order (the first folder that holds the
//! package wins; the file must then be in it):
//!
//! 1. the folders the caller passes ([`PackagePaths::new`]),
//! 2. the entries of `ROS_PACKAGE_PATH`,
//! 3. each `AMENT_PREFIX_PATH` entry's `share/`,
//! 4. the URDF's folder and each of its ancestors.
//!
//! In 1, 2 and 4 a folder holds package NAME when it has a sub-folder NAME
//! (in 1 and 2 also when the folder itself is named NAME); in 3 when its
//! `share/` has one.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use crate::error::MeshProblem;

/// The folders searched for `package://` packages (see the module docs).
/// Built once: the environment is read by [`PackagePaths::new`], not at
/// every mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PackagePaths {
    explicit: Vec<PathBuf>,
    ros_package_path: Vec<PathBuf>,
    ament_prefix_path: Vec<PathBuf>,
}

impl PackagePaths {
    /// The caller's folders first, then those of `ROS_PACKAGE_PATH` and
    /// `AMENT_PREFIX_PATH` as the process environment has them now.
    pub fn new(explicit: Vec<PathBuf>) -> Self {
        Self::with_environment(
            explicit,
            std::env::var_os("ROS_PACKAGE_PATH").as_deref(),
            std::env::var_os("AMENT_PREFIX_PATH").as_deref(),
        )
    }

    /// As [`Self::new`] with the two variables' values given (`None`: unset).
    pub fn with_environment(
        explicit: Vec<PathBuf>,
        ros_package_path: Option<&OsStr>,
        ament_prefix_path: Option<&OsStr>,
    ) -> Self {
        let split = |v: Option<&OsStr>| -> Vec<PathBuf> {
            v.map(|v| std::env::split_paths(v).filter(|p| !p.as_os_str().is_empty()))
                .into_iter()
                .flatten()
                .collect()
        };
        Self {
            explicit,
            ros_package_path: split(ros_package_path),
            ament_prefix_path: split(ament_prefix_path),
        }
    }

    /// The folders that may hold `package`, in search order.
    fn candidates(&self, package: &str, urdf_dir: &Path) -> Vec<PathBuf> {
        let mut out = Vec::new();
        for entry in self.explicit.iter().chain(&self.ros_package_path) {
            if entry.file_name() == Some(OsStr::new(package)) {
                out.push(entry.clone());
            }
            out.push(entry.join(package));
        }
        out.extend(
            self.ament_prefix_path
                .iter()
                .map(|e| e.join("share").join(package)),
        );
        // Absolute, so that a relative folder's ancestors go up to the root.
        let dir = std::path::absolute(urdf_dir).unwrap_or_else(|_| urdf_dir.to_path_buf());
        out.extend(dir.ancestors().map(|a| a.join(package)));
        out
    }

    /// The folder of `package`: the first candidate that is a folder.
    fn find(&self, package: &str, urdf_dir: &Path) -> Result<PathBuf, MeshProblem> {
        let searched = self.candidates(package, urdf_dir);
        match searched.iter().find(|p| p.is_dir()) {
            Some(found) => Ok(found.clone()),
            None => Err(MeshProblem::PackageNotFound {
                package: package.into(),
                searched,
            }),
        }
    }
}

/// The file a mesh `filename` names (not yet checked to exist, except that
/// a `package://` package must).
pub(crate) fn resolve(
    filename: &str,
    urdf_dir: &Path,
    packages: &PackagePaths,
) -> Result<PathBuf, MeshProblem> {
    let bad = |reason: &str| MeshProblem::BadUri {
        reason: reason.into(),
    };
    if let Some(rest) = filename.strip_prefix("package://") {
        let (package, path) = rest
            .split_once('/')
            .ok_or_else(|| bad("package://NAME/path needs a path after the package name"))?;
        if package.is_empty() || path.is_empty() {
            return Err(bad("package://NAME/path needs a package name and a path"));
        }
        return Ok(packages.find(package, urdf_dir)?.join(path));
    }
    let path = match filename.strip_prefix("file://") {
        Some(path) => path,
        None if filename.contains("://") => {
            return Err(bad(
                "only package://, file:// and plain paths are supported",
            ));
        }
        None => filename,
    };
    if path.is_empty() {
        return Err(bad("the filename is empty"));
    }
    Ok(urdf_dir.join(path))
}
