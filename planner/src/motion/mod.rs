//! The metric stages of the pipeline: the robot's state at t = 0, lifting a
//! grid plan to 3-D tool waypoints (smoothing, release spots), IK and the
//! arm choice, the continuous collision check of the joint path against
//! the scene with its safety perimeters, and the transits between them.

pub mod clearance;
pub mod geometry;
pub mod lift;
pub mod place;
pub mod route;
pub mod smooth;
pub mod start;
pub mod transit;

mod ik;
pub use ik::*;
