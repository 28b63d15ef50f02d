//! The collision regression suite's file format (`tests/collision/*.yaml`)
//! and its runner. A fixture is a scene, a robot, a path and the verdict the
//! geometry really gives (derived by dense sampling when the fixture was
//! generated, see `examples/gen_fixtures.rs`).
//!
//! ```yaml
//! name: hand-perimeter-entered
//! robot: kuka_iiwa14            # built-in robot
//! arm: arm                      # optional, default the first arm
//! scene: {table_z: -0.2, table: {min: [0.2, -0.5], max: [0.9, 0.5]}, boxes: [...]}
//! path: {tool: [[x, y, z, yaw], ...]}   # top-down tool poses, or
//! # path: {arm: [[q1..q7], ...]}        # the arm's joints, others at home, or
//! # path: {robot: [[q...], ...]}        # full robot configurations
//! held: {name: cube, size: [0.04, 0.04, 0.06], offset: [0, 0, 0.01]}  # optional
//! ignore: []                             # optional obstacle names
//! expect: {verdict: collides, pair: [held:cube, goal], segment: 1}
//! ```
//! `segment` matches when the reported first contact is within one segment.

use std::path::{Path, PathBuf};

use afford_kinematics::{RobotModel, top_down_pose};
use nalgebra::{Translation3, Vector3};
use serde::{Deserialize, Serialize};

use crate::check::{PathOptions, PathVerdict};
use crate::error::CollisionError;
use crate::robot::{Attachment, RobotGeometry};
use crate::scene::{Scene, SceneSpec};

/// One fixture file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fixture {
    pub name: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    pub robot: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm: Option<String>,
    pub scene: SceneSpec,
    pub path: FixturePath,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held: Option<HeldSpec>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ignore: Vec<String>,
    pub expect: Expect,
}

/// The path of a fixture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum FixturePath {
    /// Top-down tool poses `[x, y, z, yaw]` of the arm's tool.
    Tool(Vec<[f64; 4]>),
    /// The arm's joint values; every other joint at the robot's home.
    Arm(Vec<Vec<f64>>),
    /// Full robot configurations.
    Robot(Vec<Vec<f64>>),
}

/// A held box in the tool frame (centre at `offset`, axes along the tool's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeldSpec {
    pub name: String,
    pub size: [f64; 3],
    #[serde(default)]
    pub offset: [f64; 3],
}

/// The expected verdict.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// `free` or `collides`.
    pub verdict: Verdict,
    /// The two names of the first hit (order does not matter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pair: Option<[String; 2]>,
    /// Segment of the first contact (±1 accepted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segment: Option<usize>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Free,
    Collides,
}

/// The result of running one fixture.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FixtureOutcome {
    pub name: String,
    pub passed: bool,
    /// One line: expectation, what the check said, work done.
    pub summary: String,
    pub verdict: PathVerdict,
}

/// Reads and parses a fixture file.
pub fn load_fixture(file: &Path) -> Result<Fixture, CollisionError> {
    let text = std::fs::read_to_string(file).map_err(|source| CollisionError::Io {
        file: file.to_path_buf(),
        source,
    })?;
    serde_saphyr::from_str(&text).map_err(|e| CollisionError::FixtureSyntax {
        file: file.to_path_buf(),
        message: e.to_string(),
    })
}

/// Every `*.yaml` in `dir`, sorted.
pub fn fixture_files(dir: &Path) -> Result<Vec<PathBuf>, CollisionError> {
    let rd = std::fs::read_dir(dir).map_err(|source| CollisionError::Io {
        file: dir.to_path_buf(),
        source,
    })?;
    let mut files: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    files.sort();
    Ok(files)
}

impl Fixture {
    /// The check inputs: robot geometry, scene, options.
    pub fn prepare(
        &self,
        file: &Path,
    ) -> Result<(RobotGeometry, Scene, PathOptions), CollisionError> {
        let field = |f: &str, e: CollisionError| CollisionError::Fixture {
            file: file.to_path_buf(),
            field: f.to_string(),
            problem: e.to_string(),
        };
        let model = RobotModel::builtin(&self.robot).map_err(|e| field("robot", e.into()))?;
        let geometry = RobotGeometry::new(&model).map_err(|e| field("robot", e))?;
        let scene = Scene::from_spec(&self.scene).map_err(|e| field("scene", e))?;
        let attached = self.held.as_ref().map(|h| Attachment {
            name: h.name.clone(),
            half_extents: [0.5 * h.size[0], 0.5 * h.size[1], 0.5 * h.size[2]],
            round: false,
            pose_tool_object: Translation3::from(Vector3::from(h.offset)).into(),
        });
        let opts = PathOptions {
            arm: self.arm.clone(),
            attached,
            ignore: self.ignore.clone(),
            ..PathOptions::default()
        };
        Ok((geometry, scene, opts))
    }

    /// Runs the fast check on the fixture's path.
    pub fn check(
        &self,
        geometry: &RobotGeometry,
        scene: &Scene,
        opts: &PathOptions,
        file: &Path,
    ) -> Result<PathVerdict, CollisionError> {
        let wrap = |e: CollisionError| CollisionError::Fixture {
            file: file.to_path_buf(),
            field: "path".into(),
            problem: e.to_string(),
        };
        match &self.path {
            FixturePath::Tool(w) => {
                let poses: Vec<_> = w
                    .iter()
                    .map(|p| top_down_pose(Vector3::new(p[0], p[1], p[2]), p[3]))
                    .collect();
                geometry.check_tool_path(scene, &poses, opts).map_err(wrap)
            }
            FixturePath::Arm(q) => {
                let arm = match &self.arm {
                    Some(a) => a.clone(),
                    None => geometry
                        .model()
                        .arms()
                        .first()
                        .map(|a| a.name.clone())
                        .unwrap_or_default(),
                };
                let home = geometry.model().home().to_vec();
                geometry
                    .check_arm_path(scene, &arm, &home, q, opts)
                    .map_err(wrap)
            }
            FixturePath::Robot(q) => geometry.check_joint_path(scene, q, opts).map_err(wrap),
        }
    }
}

/// Loads, checks and compares one fixture file.
pub fn run_fixture(file: &Path) -> Result<FixtureOutcome, CollisionError> {
    let fx = load_fixture(file)?;
    let (g, scene, opts) = fx.prepare(file)?;
    let verdict = fx.check(&g, &scene, &opts, file)?;
    let (passed, said) = match (fx.expect.verdict, verdict.first()) {
        (Verdict::Free, None) => (true, "free".to_string()),
        (Verdict::Free, Some(c)) => (false, format!("COLLIDES: {c}")),
        (Verdict::Collides, None) => (false, "FREE".to_string()),
        (Verdict::Collides, Some(c)) => {
            let pair_ok = fx.expect.pair.as_ref().is_none_or(|[a, b]| {
                (same(&c.body, a) && same(&c.other, b)) || (same(&c.body, b) && same(&c.other, a))
            });
            let seg_ok = fx.expect.segment.is_none_or(|s| c.segment.abs_diff(s) <= 1);
            (pair_ok && seg_ok, format!("collides: {c}"))
        }
    };
    let expected = match (&fx.expect.verdict, &fx.expect.pair) {
        (Verdict::Free, _) => "free".to_string(),
        (Verdict::Collides, Some([a, b])) => format!(
            "collides {a}/{b} near segment {}",
            fx.expect.segment.map_or("?".into(), |s| s.to_string())
        ),
        (Verdict::Collides, None) => "collides".to_string(),
    };
    let summary = format!(
        "{} {:<40} expect {expected}; got {said} [{} evals, {} pair queries]",
        if passed { "ok  " } else { "FAIL" },
        fx.name,
        verdict.stats.evaluations,
        verdict.stats.pair_queries
    );
    Ok(FixtureOutcome {
        name: fx.name,
        passed,
        summary,
        verdict,
    })
}

/// Body names match exactly, or `link` matches any collider `link#k`.
fn same(reported: &str, expected: &str) -> bool {
    reported == expected
        || reported
            .strip_prefix(expected)
            .is_some_and(|rest| rest.starts_with('#'))
}
