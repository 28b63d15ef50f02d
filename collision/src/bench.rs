//! The collision benchmark behind `afford bench collision`: the brute-force
//! cross-check (fast continuous check vs dense sampling on random joint paths
//! in random scenes: the fast check must never call a colliding path free),
//! the timing of one whole-arm check of a 1,000-configuration path against a
//! 20-object scene, and raw shape-pair query throughput. Everything is seeded.

use std::time::Instant;

use afford_kinematics::{RobotModel, pose_from_xyz_rpy};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use crate::check::PathOptions;
use crate::dense::{DenseSettings, dense_joint_path};
use crate::error::CollisionError;
use crate::robot::{Attachment, RobotGeometry};
use crate::scene::{BoxKind, Scene, SceneBox, SceneSpec, TableSpec};

/// What `afford bench collision --json` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CollisionBenchReport {
    pub paths: usize,
    pub missed_collisions: usize,
    pub median_ms_arm_path_1000: f64,
    pub pair_queries_per_s: f64,
}

/// Outcome of the brute-force cross-check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossCheck {
    pub paths: usize,
    /// Paths where dense sampling finds a collision.
    pub dense_collisions: usize,
    /// Paths the fast check reports colliding.
    pub fast_collisions: usize,
    /// Dense collides, fast says free (must be 0).
    pub missed: usize,
    /// Fast collides, dense free (conservatism: contacts between samples or
    /// within the tolerance).
    pub fast_only: usize,
    /// Seeds of the missed paths (to reproduce).
    pub missed_seeds: Vec<u64>,
}

/// A random scene in front of the iiwa (table at z = -0.2) and a random
/// joint path from near home; sometimes with a held box.
pub struct BenchCase {
    pub scene: SceneSpec,
    pub path: Vec<Vec<f64>>,
    pub attached: Option<Attachment>,
}

/// A random box on the table.
fn random_box(rng: &mut impl Rng, i: usize, low: bool) -> SceneBox {
    let kind = match rng.random_range(0..10) {
        0..6 => BoxKind::Object,
        6..8 => BoxKind::Goal,
        _ => BoxKind::Hand,
    };
    let margin = match kind {
        BoxKind::Hand => 0.10,
        _ => [0.0, 0.02, 0.06][rng.random_range(0..3)],
    };
    let size = if kind == BoxKind::Goal {
        [
            rng.random_range(0.08..0.25),
            rng.random_range(0.08..0.25),
            rng.random_range(0.04..0.15),
        ]
    } else {
        let hmax = if low { 0.12 } else { 0.6 };
        [
            rng.random_range(0.02..0.12),
            rng.random_range(0.02..0.12),
            rng.random_range(0.02..hmax),
        ]
    };
    SceneBox {
        name: format!("box-{i}"),
        kind,
        centre: [rng.random_range(0.25..0.85), rng.random_range(-0.5..0.5)],
        size,
        yaw: rng.random_range(-1.5..1.5),
        margin,
        round: false,
    }
}

fn table() -> Option<TableSpec> {
    Some(TableSpec {
        min: [0.2, -0.6],
        max: [0.95, 0.6],
        margin: 0.0,
    })
}

/// A random cross-check case (seeded).
pub fn random_case(model: &RobotModel, seed: u64) -> BenchCase {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n_boxes = rng.random_range(1..8);
    let boxes = (0..n_boxes)
        .map(|i| random_box(&mut rng, i, false))
        .collect();
    let dof = model.dof();
    let mut q: Vec<f64> = model.home().to_vec();
    for v in q.iter_mut() {
        *v += rng.random_range(-0.3..0.3);
    }
    let n_way = rng.random_range(2..5);
    let mut path = vec![q.clone()];
    for _ in 1..n_way {
        for (j, v) in q.iter_mut().enumerate() {
            let joint = &model.joints()[j];
            *v = (*v + rng.random_range(-0.35..0.35)).clamp(joint.lower, joint.upper);
        }
        path.push(q.clone());
    }
    debug_assert_eq!(path[0].len(), dof);
    let attached = rng.random_bool(0.3).then(|| Attachment {
        name: "held".into(),
        half_extents: [
            0.02,
            rng.random_range(0.02..0.06),
            rng.random_range(0.02..0.05),
        ],
        round: false,
        pose_tool_object: pose_from_xyz_rpy([0.0, 0.0, 0.02], [0.0, 0.0, 0.0]),
    });
    BenchCase {
        scene: SceneSpec {
            table_z: -0.2,
            table: table(),
            boxes,
        },
        path,
        attached,
    }
}

/// Fast check vs dense sampling on `paths` random cases (seeds
/// `seed..seed+paths`), in parallel.
pub fn cross_check(
    model: &RobotModel,
    paths: usize,
    seed: u64,
) -> Result<CrossCheck, CollisionError> {
    let geometry = RobotGeometry::new(model)?;
    let results: Vec<Result<(bool, bool, u64), CollisionError>> = (0..paths as u64)
        .into_par_iter()
        .map(|i| {
            let s = seed.wrapping_add(i);
            let case = random_case(model, s);
            let scene = Scene::from_spec(&case.scene)?;
            let opts = PathOptions {
                attached: case.attached.clone(),
                ..PathOptions::default()
            };
            let fast = !geometry
                .check_joint_path(&scene, &case.path, &opts)?
                .is_free();
            let dense = dense_joint_path(
                &geometry,
                &scene,
                &case.path,
                &opts,
                &DenseSettings::default(),
            )?
            .collides();
            Ok((fast, dense, s))
        })
        .collect();
    let mut out = CrossCheck {
        paths,
        dense_collisions: 0,
        fast_collisions: 0,
        missed: 0,
        fast_only: 0,
        missed_seeds: Vec::new(),
    };
    for r in results {
        let (fast, dense, s) = r?;
        out.fast_collisions += fast as usize;
        out.dense_collisions += dense as usize;
        if dense && !fast {
            out.missed += 1;
            out.missed_seeds.push(s);
        }
        out.fast_only += (fast && !dense) as usize;
    }
    Ok(out)
}

/// The timing case: a 20-object scene and a smooth 1,000-configuration
/// iiwa path (5 key postures, linear in between) that is collision-free, so
/// the check runs the whole path. Returns the scene and the path.
pub fn bench_case(model: &RobotModel, seed: u64) -> Result<(Scene, Vec<Vec<f64>>), CollisionError> {
    let geometry = RobotGeometry::new(model)?;
    let mut last = None;
    for attempt in 0..200u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1000).wrapping_add(attempt));
        let boxes: Vec<SceneBox> = (0..20).map(|i| random_box(&mut rng, i, true)).collect();
        let spec = SceneSpec {
            table_z: -0.2,
            table: table(),
            boxes,
        };
        let scene = Scene::from_spec(&spec)?;
        let keys: Vec<Vec<f64>> = (0..5)
            .map(|_| {
                let mut q = model.home().to_vec();
                q[0] += rng.random_range(-0.8..0.8);
                for v in q.iter_mut().skip(1) {
                    *v += rng.random_range(-0.25..0.25);
                }
                q
            })
            .collect();
        let n = 1000;
        let path: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let s = i as f64 / (n - 1) as f64 * (keys.len() - 1) as f64;
                let k = (s.floor() as usize).min(keys.len() - 2);
                let f = s - k as f64;
                keys[k]
                    .iter()
                    .zip(&keys[k + 1])
                    .map(|(a, b)| a + f * (b - a))
                    .collect()
            })
            .collect();
        if geometry
            .check_joint_path(&scene, &path, &PathOptions::default())?
            .is_free()
        {
            return Ok((scene, path));
        }
        last = Some((scene, path));
    }
    // No free case found: time a colliding one rather than fail.
    last.ok_or_else(|| crate::error::path_err("bench", "no case"))
}

/// Shape-pair distance queries per second: every robot collider against
/// every part of the bench scene, at random configurations.
pub fn pair_queries_per_s(
    model: &RobotModel,
    scene: &Scene,
    seed: u64,
) -> Result<f64, CollisionError> {
    let geometry = RobotGeometry::new(model)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut count = 0u64;
    let mut acc = 0.0;
    let start = Instant::now();
    while start.elapsed().as_secs_f64() < 0.3 {
        let mut q = model.home().to_vec();
        for v in q.iter_mut() {
            *v += rng.random_range(-0.5..0.5);
        }
        let links = model.link_poses(&q)?;
        for b in &geometry.bodies {
            let pose = crate::convert::to_parry(&(links[b.link] * b.pose_link_shape));
            for p in &scene.parts {
                acc += crate::sweep::distance(&pose, b.shape.as_ref(), &p.pose, p.shape.as_ref());
                count += 1;
            }
        }
    }
    std::hint::black_box(acc);
    Ok(count as f64 / start.elapsed().as_secs_f64())
}

/// Median wall time (ms) of `runs` whole-arm checks of the bench path.
pub fn median_ms_arm_path(
    model: &RobotModel,
    scene: &Scene,
    path: &[Vec<f64>],
    runs: usize,
) -> Result<f64, CollisionError> {
    let geometry = RobotGeometry::new(model)?;
    let opts = PathOptions::default();
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        std::hint::black_box(geometry.check_joint_path(scene, path, &opts)?);
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// The whole benchmark: 1,000-path cross-check, the timing case, pair
/// queries per second (iiwa).
pub fn collision_benchmark(seed: u64) -> Result<CollisionBenchReport, CollisionError> {
    let model = RobotModel::builtin("kuka_iiwa14")?;
    let cc = cross_check(&model, 1000, seed)?;
    let (scene, path) = bench_case(&model, seed)?;
    let median = median_ms_arm_path(&model, &scene, &path, 51)?;
    let qps = pair_queries_per_s(&model, &scene, seed)?;
    Ok(CollisionBenchReport {
        paths: cc.paths,
        missed_collisions: cc.missed,
        median_ms_arm_path_1000: median,
        pair_queries_per_s: qps,
    })
}
