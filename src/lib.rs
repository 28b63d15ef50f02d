//! afford: the facade crate. Re-exports the library crates. The `afford`
//! command and [`picture`] are behind the default features `cli` and `svg`;
//! with `default-features = false` the crate pulls in neither clap,
//! indicatif nor plotters. [`plan_json`] is the plan as `afford plan`
//! reports it, shared by the command and the Python module.
pub use afford_check as check;
pub use afford_collision as collision;
pub use afford_kinematics as kinematics;
pub use afford_planner as planner;
#[cfg(feature = "svg")]
pub mod picture;
pub mod plan_json;
pub mod robot_setup;
