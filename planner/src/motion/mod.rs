//! The metric stages of the pipeline: the robot's state at t = 0, lifting a
//! grid plan to 3-D tool waypoints (smoothing, release spots), IK and the
//! arm choice, and the continuous collision check of the joint path against
//! the scene with its safety perimeters.

pub mod clearance;
pub mod geometry;
pub mod lift;
pub mod place;
pub mod route;
pub mod smooth;
pub mod start;

mod ik;
pub use ik::*;
