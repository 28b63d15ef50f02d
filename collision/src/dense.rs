//! The brute-force reference: dense sampling of a path, every pair exact at
//! every sample. Slow and simple on purpose; the fast checks are measured
//! against it (`bench::cross_check`) and the fixtures' verdicts are derived
//! with it.
//!
//! Steps (defaults): joint paths 0.001 rad per joint between samples; tool
//! paths 0.5 mm of translation and 0.001 rad of rotation. A sample collides
//! when some pair's distance minus margin is <= 0. Sampling can miss a brief
//! contact between samples — that is what the continuous checks are for.

use afford_kinematics::Pose;
use parry3d::math::Pose as PPose;
use serde::{Deserialize, Serialize};

use crate::check::{PathOptions, Prepared, active};
use crate::error::CollisionError;
use crate::robot::RobotGeometry;
use crate::scene::{Scene, aabb_distance};
use crate::sweep::{Partner, Sweep, distance};

/// Sampling steps of the reference; defaults written once here.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DenseSettings {
    /// Largest tool translation between samples (tool paths), m.
    pub step_m: f64,
    /// Largest joint (or tool rotation) change between samples, rad.
    pub step_rad: f64,
    /// Stop at the first colliding sample (else scan the whole path for the
    /// minimum slack).
    pub stop_at_first: bool,
}

impl Default for DenseSettings {
    fn default() -> Self {
        Self {
            step_m: 5e-4,
            step_rad: 1e-3,
            stop_at_first: true,
        }
    }
}

/// The closest approach found by dense sampling.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DenseResult {
    /// First sample with slack <= 0: (t, body, other, slack).
    pub first_hit: Option<(f64, String, String, f64)>,
    /// Smallest slack (distance - margin) seen, where, and between what.
    pub min_slack: f64,
    pub min_t: f64,
    pub min_pair: (String, String),
    pub samples: usize,
}

impl DenseResult {
    pub fn collides(&self) -> bool {
        self.first_hit.is_some()
    }
}

/// Dense reference for a joint path (same bodies and pairs as the fast check).
pub fn dense_joint_path(
    robot: &RobotGeometry,
    scene: &Scene,
    path: &[Vec<f64>],
    opts: &PathOptions,
    dense: &DenseSettings,
) -> Result<DenseResult, CollisionError> {
    for (i, q) in path.iter().enumerate() {
        robot.check_config(q, &format!("joints[{i}]"))?;
    }
    let mut p = robot.prepare_joint_path(path, opts)?;
    sample(&mut p, scene, opts, dense)
}

/// Dense reference for a tool path.
pub fn dense_tool_path(
    robot: &RobotGeometry,
    scene: &Scene,
    waypoints: &[Pose],
    opts: &PathOptions,
    dense: &DenseSettings,
) -> Result<DenseResult, CollisionError> {
    let mut p = robot.prepare_tool_path(waypoints, opts)?;
    sample(&mut p, scene, opts, dense)
}

fn sample<S: Sweep>(
    p: &mut Prepared<S>,
    scene: &Scene,
    opts: &PathOptions,
    dense: &DenseSettings,
) -> Result<DenseResult, CollisionError> {
    let active = active(scene, opts, &p.names)?;
    let mut out = DenseResult {
        first_hit: None,
        min_slack: f64::INFINITY,
        min_t: 0.0,
        min_pair: (String::new(), String::new()),
        samples: 0,
    };
    let n = p.sweep.segments();
    let mut ts = vec![0.0];
    for k in 0..n {
        let m = p.sweep.dense_steps(k, dense.step_m, dense.step_rad);
        ts.extend((1..=m).map(|i| k as f64 + i as f64 / m as f64));
    }
    for t in ts {
        out.samples += 1;
        let poses: Vec<PPose> = p.sweep.poses_at(t).to_vec();
        for g in &p.groups {
            let s1 = p.shapes[g.body].as_ref();
            let p1 = &poses[g.body];
            let threshold = if dense.stop_at_first {
                0.0
            } else {
                out.min_slack
            };
            let consider = |slack: f64, other: &str, out: &mut DenseResult| {
                if slack < out.min_slack {
                    out.min_slack = slack;
                    out.min_t = t;
                    out.min_pair = (p.names[g.body].clone(), other.to_string());
                }
                if slack <= 0.0 && out.first_hit.is_none() {
                    out.first_hit = Some((t, p.names[g.body].clone(), other.to_string(), slack));
                }
            };
            match g.partner {
                Partner::Body(o) => {
                    let d = distance(p1, s1, &poses[o], p.shapes[o].as_ref());
                    consider(d, &p.names[o], &mut out);
                }
                Partner::Scene => {
                    let aabb = s1.compute_aabb(p1);
                    for part in &scene.parts {
                        if !active[g.body][part.obstacle] {
                            continue;
                        }
                        let ob = &scene.obstacles[part.obstacle];
                        if aabb_distance(&aabb, &part.aabb) - ob.margin > threshold {
                            continue;
                        }
                        let d = distance(p1, s1, &part.pose, part.shape.as_ref());
                        consider(d - ob.margin, &ob.name, &mut out);
                    }
                }
            }
        }
        if dense.stop_at_first && out.first_hit.is_some() {
            break;
        }
    }
    Ok(out)
}
