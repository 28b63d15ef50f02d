//! afford-collision: is a motion safe? Scene geometry from the planner's
//! boxes, robot geometry from the kinematics model, and continuous collision
//! checks with safety perimeters, built on parry3d (f64).
//!
//! Modules and what each owns:
//! - [`acm`](AllowedCollisionMatrix): which link pairs the self-collision
//!   check skips, derived from the geometry by sampling.
//! - `convert`: the one nalgebra ↔ parry (glam) pose conversion (exact).
//! - [`scene`](SceneSpec): the planner's scene description and the parry
//!   shapes built from it (table, solid boxes, open goal boxes, perimeters).
//! - `robot`: colliders posed by FK, and the joint-space motion bound.
//! - `sweep`: conservative advancement, the engine of every continuous check.
//! - `check`: the public checks, their guarantees and their reports.
//! - `dense`: the brute-force reference (dense sampling) the checks are
//!   cross-checked against.
//! - `fixture`: the regression-suite file format and its runner.
//! - `bench`: the cross-check and timing behind `afford bench collision`.
//! - [`replay`]: the physical replay of a trajectory in rapier3d (pieces
//!   pushed, dropped and settled; contacts of the robot's links).
//!
//! The guarantee (see [`RobotGeometry::check_joint_path`] and
//! [`RobotGeometry::check_tool_path`]): a path reported free keeps every
//! robot body (and the held object) strictly outside every obstacle's
//! perimeter — distance > margin — at every instant of the continuous path,
//! not only at samples. A hit is reported when a pair comes within
//! [`CheckSettings::tolerance`] (0.1 mm) of its margin.

mod acm;
mod bench;
mod check;
mod convert;
mod dense;
mod error;
mod fixture;

pub mod replay;
mod report;
mod robot;
mod scene;
mod sweep;

pub use acm::{AcmSettings, AllowedCollisionMatrix, BLOCK as ACM_BLOCK, PairEntry};
pub use bench::{
    BenchCase, CollisionBenchReport, CrossCheck, bench_case, collision_benchmark, cross_check,
    median_ms_arm_path, pair_queries_per_s, random_case,
};
pub use check::{
    CheckSettings, CheckStats, Collision, HitKind, PathOptions, PathVerdict, ToolBounds,
};
pub use dense::{DenseResult, DenseSettings, dense_joint_path, dense_tool_path};
pub use error::CollisionError;
pub use fixture::{
    Expect, Fixture, FixtureOutcome, FixturePath, HeldSpec, Verdict, fixture_files, load_fixture,
    run_fixture,
};

pub use robot::{Attachment, RobotGeometry};
pub use scene::{
    BoxKind, GOAL_WALL, Obstacle, Scene, SceneBox, SceneSpec, TABLE_THICKNESS, TableSpec,
    round_parts,
};
