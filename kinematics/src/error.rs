//! Errors of the kinematics crate: loading a robot (bad files, unknown names,
//! misuse of the model) and the typed reasons an IK solve gives up.
//!
//! Loading errors always name the file and the element at fault. An IK failure
//! is an answer, not a bug: it says why no configuration was returned.

use std::path::PathBuf;

use serde::Serialize;

/// Something is wrong with a robot description, a URDF, or how the model is used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// No built-in robot has this name (and it is not a path to a file).
    #[error(
        "unknown robot '{name}': built-in robots are {known}; a user robot is a path to its description .yaml"
    )]
    UnknownRobot { name: String, known: String },
    /// A file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The URDF is not well-formed XML or does not follow the URDF schema.
    #[error("{}: malformed URDF: {message}", file.display())]
    UrdfSyntax { file: PathBuf, message: String },
    /// One URDF element is inconsistent or unsupported.
    #[error("{}: {element}: {problem}", file.display())]
    UrdfElement {
        file: PathBuf,
        element: String,
        problem: String,
    },
    /// A `<collision><mesh>` cannot become a convex hull.
    #[error("{}: link '{link}': <mesh filename=\"{mesh}\">: {problem}", file.display())]
    Mesh {
        /// The URDF.
        file: PathBuf,
        link: String,
        /// The mesh's `filename` as the URDF writes it.
        mesh: String,
        problem: Box<MeshProblem>,
    },
    /// A `<mimic>` joint that cannot follow its leader.
    #[error("{}: joint '{joint}': <mimic>: {problem}", file.display())]
    Mimic {
        /// The URDF.
        file: PathBuf,
        joint: String,
        problem: MimicProblem,
    },
    /// The SRDF does not parse or names what the URDF does not have.
    #[error("{}: {element}: {problem}", file.display())]
    Srdf {
        file: PathBuf,
        element: String,
        problem: String,
    },
    /// The description YAML does not parse or does not follow the schema.
    #[error("{}: malformed robot description: {message}", file.display())]
    DescriptionSyntax { file: PathBuf, message: String },
    /// One entry of the description YAML is inconsistent with the URDF.
    #[error("{}: {element}: {problem}", file.display())]
    DescriptionElement {
        file: PathBuf,
        element: String,
        problem: String,
    },
    /// A link name that the robot does not have.
    #[error("robot '{robot}' has no link '{link}'")]
    UnknownLink { robot: String, link: String },
    /// An arm name that the robot does not have.
    #[error("robot '{robot}' has no arm '{arm}' (arms: {known})")]
    UnknownArm {
        robot: String,
        arm: String,
        known: String,
    },
    /// A settings field out of its range.
    #[error("settings: {field} {problem}")]
    Settings {
        field: &'static str,
        problem: String,
    },
    /// A joint vector of the wrong length.
    #[error("{what} has {got} values, expected {expected}")]
    ConfigSize {
        what: &'static str,
        expected: usize,
        got: usize,
    },
}

/// Why a collision mesh was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshProblem {
    /// The filename is not `package://NAME/path`, `file://path` or a path.
    #[error("cannot be resolved: {reason}")]
    BadUri { reason: String },
    /// No folder of the package search path holds the package.
    #[error("package '{package}' not found (searched: {})", list(searched))]
    PackageNotFound {
        package: String,
        searched: Vec<PathBuf>,
    },
    /// The resolved file does not exist.
    #[error("{}: no such file", path.display())]
    Missing { path: PathBuf },
    /// The resolved file cannot be read.
    #[error("{}: cannot read: {message}", path.display())]
    Unreadable { path: PathBuf, message: String },
    /// The file's extension names no supported format.
    #[error("{}: unknown mesh format (supported: .stl, .obj, .dae)", path.display())]
    UnknownFormat { path: PathBuf },
    /// The file does not parse as its format.
    #[error("{}: malformed {format}: {message}", path.display())]
    Malformed {
        path: PathBuf,
        format: &'static str,
        message: String,
    },
    /// The file holds no triangle.
    #[error("{}: the mesh has no triangles", path.display())]
    Empty { path: PathBuf },
    /// The `scale` or a vertex is not finite or too large.
    #[error("{}: {reason}", path.display())]
    OutOfBounds { path: PathBuf, reason: String },
    /// The vertices are flat (coplanar, collinear, one point) or too many
    /// for a convex hull.
    #[error("{}: no usable convex hull: {reason}", path.display())]
    DegenerateHull { path: PathBuf, reason: String },
}

/// Why a `<mimic>` joint was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MimicProblem {
    /// The leader joint is not in the URDF.
    #[error("leader joint '{leader}' is not defined")]
    UnknownLeader { leader: String },
    /// The leader joint is fixed.
    #[error("leader joint '{leader}' is fixed")]
    FixedLeader { leader: String },
    /// The mimicking joint itself is fixed.
    #[error("a fixed joint cannot mimic another")]
    FixedFollower,
    /// The mimic relations form a loop.
    #[error("the mimic relations form a cycle: {}", joints.join(" -> "))]
    Cycle { joints: Vec<String> },
    /// `multiplier` or `offset` is not finite or too large.
    #[error("{reason}")]
    BadValue { reason: String },
}

fn list(paths: &[PathBuf]) -> String {
    match paths.is_empty() {
        true => "nothing".into(),
        false => paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// Why an IK solve returned no configuration. Never a silently wrong answer.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum IkFailure {
    /// The target lies beyond what the arm can reach, whatever its joint limits.
    #[error(
        "target out of reach: even ignoring joint limits the tool stays {position_error:.4} m away"
    )]
    OutOfReach { position_error: f64 },
    /// The target is reachable only with a joint beyond its limit.
    #[error("target needs joint '{joint}' beyond its limit")]
    JointLimit { joint: String },
    /// The solver ended at a singular configuration short of the target.
    #[error("solver stuck at a singular configuration (smallest singular value {sigma_min:.2e})")]
    Singular { sigma_min: f64 },
    /// The solver ran out of iterations/restarts without meeting the tolerance.
    #[error(
        "IK did not converge after {attempts} attempts (best: {position_error:.2e} m, {rotation_error:.2e} rad)"
    )]
    NotConverged {
        attempts: usize,
        position_error: f64,
        rotation_error: f64,
    },
    /// A solution exists near the previous waypoint only after a jump larger
    /// than allowed (a branch change); path IK refuses it.
    #[error("the next solution is {step:.3} rad away from the previous waypoint (branch change)")]
    Discontinuous { step: f64 },
    /// The request itself is unusable (wrong seed length, non-finite target).
    #[error("invalid IK request: {reason}")]
    InvalidRequest { reason: &'static str },
}
