//! afford-kinematics: robot models, forward and inverse kinematics.
//!
//! - [`RobotModel`] loads a built-in robot (`kuka_iiwa14`, `care_o_bot4`) or a
//!   user URDF with its description YAML, and gives the pose of any link.
//!   Collision meshes become convex hulls (`mesh`); mimic joints follow their
//!   leaders (`mimic`).
//! - [`Arm`] is one serial chain (base to grasp point) inside the model.
//! - IK solves `FK(q) = target` for a 6-D pose or a top-down grasp with a
//!   damped least-squares / Levenberg-Marquardt iteration with hard joint limits
//!   and a posture task in the null space (see `DESIGN.md`).
//!
//! One pose type, [`Pose`] (nalgebra 0.30 `Isometry3<f64>`), is used throughout;
//! k's types stay in the `kchain` module.

mod adjacency;
mod arms;
mod bench;
pub mod bounds;
mod builtin;
mod chain;
mod choose;
mod description;
pub mod draft;
mod error;
mod ik;
mod input;
mod kchain;
mod load;
mod math;
mod mesh;
mod mimic;
mod model;
mod path;
mod srdf;
mod urdf;

pub use bench::{
    ArmBench, BENCH_POSITION_TOLERANCE, BENCH_ROTATION_TOLERANCE, IkBenchReport, bench_arm,
    ik_benchmark, is_success as ik_bench_success, random_reachable_poses,
};
pub use builtin::{ArmSummary, NAMES as BUILTIN_ROBOTS, RobotSummary, builtin_robots};
pub use choose::{ArmChoice, LIMIT_WEIGHT, NoArmReaches, choose_arm, path_cost};
pub use description::{
    AllowedCollisions, AllowedPair, AllowedReason, CameraSetup, DEFAULT_GRIPPER_TIME,
    DESCRIPTION_FORMAT, Gripper, MAX_ACM_SAMPLES, MAX_GRIPPER_TIME,
};
pub use error::{IkFailure, KinematicsError, MeshProblem, MimicProblem};
pub use ik::{IkSettings, IkSolution, IkTarget, random_configuration};
pub use input::open_regular;
pub use kchain::KBaseline;
pub use load::{DEFAULT_JERK_RAMP_S, description_urdf, read_text};
pub use math::*;
pub use mesh::{MeshSurface, PackagePaths, mesh_surfaces};
pub use model::{
    Arm, Collider, Joint, JointDrive, JointKind, Link, Mimic, MimicJoint, RobotModel, Shape,
};
pub use path::{JointPath, PathFailure, PathSettings, max_joint_step};
pub use srdf::NamedPosture;
