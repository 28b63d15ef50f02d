//! afford: the facade crate. Re-exports the library crates.
pub use afford_check as check;
pub use afford_collision as collision;
pub use afford_kinematics as kinematics;
pub use afford_planner as planner;
pub mod picture;
