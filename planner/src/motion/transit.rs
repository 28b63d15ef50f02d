//! Transits: an arm's free moves that the grid does not plan (out of park,
//! from where the last sub-goal left it to this sub-goal's first waypoint,
//! back to park). A straight joint-space move is kept when it is free;
//! otherwise a sampling-based motion planner finds one: dual RRT-Connect
//! (Kuffner & LaValle 2000, OpenRR's `rrt` crate) over the arm's joint
//! space, with afford's continuous collision check of each edge as the
//! validity test, then random shortcutting (Geraerts & Overmars 2007).
//!
//! `rrt` 0.7 hands its validity predicate only the new configuration of
//! each extension. The predicate here mirrors both trees (the extension
//! rule is RRT-Connect's: the nearest vertex steps `extend_length` towards
//! the target, or reaches it), recovers the edge's parent vertex and checks
//! the whole edge continuously; a configuration whose parent it cannot
//! recover is refused, which costs completeness, never safety. Every random
//! draw comes from a ChaCha8 stream seeded by the caller, so a transit is
//! deterministic.
//!
//! Budget ([`TransitSettings`], defaults): 300 RRT-Connect iterations with
//! 1.0 rad extensions (Euclidean joint-space distance), 48 shortcut
//! attempts; the result is cut into steps of at most 0.05 rad per joint for
//! the timing stage. A transit not found within the budget is a refusal
//! with its reason.

use std::cell::RefCell;

use afford_kinematics::Arm;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The transit planner's budget and step sizes.
#[derive(Debug, Clone, PartialEq)]
pub struct TransitSettings {
    /// RRT-Connect iterations (random samples) before a transit is refused.
    pub max_iterations: usize,
    /// Longest tree edge, Euclidean joint-space distance (rad, m for prismatic).
    pub extend_length: f64,
    /// Random shortcut attempts on a found path.
    pub shortcut_attempts: usize,
    /// Largest joint change between consecutive configurations of the
    /// output, rad or m (evenly spaced points for the timing stage).
    pub max_step: f64,
}

impl Default for TransitSettings {
    fn default() -> Self {
        Self {
            max_iterations: 300,
            extend_length: 1.0,
            shortcut_attempts: 48,
            max_step: 0.05,
        }
    }
}

/// How a transit was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransitKind {
    /// The straight joint-space move is free.
    Straight,
    /// Found by RRT-Connect after `iterations` samples and shortcut to
    /// `vertices` configurations (start and end included).
    Planned { iterations: usize, vertices: usize },
}

/// A collision-free transit.
#[derive(Debug, Clone, PartialEq)]
pub struct Transit {
    /// Arm configurations from the start (excluded) to the end (included),
    /// no joint moving more than `max_step` between neighbours.
    pub path: Vec<Vec<f64>>,
    pub kind: TransitKind,
}

/// Why there is no transit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TransitError {
    /// The start configuration itself is not free: no move from it is.
    #[error("the arm's configuration at the start of the transit is not collision-free")]
    StartCollides,
    /// The end configuration itself is not free.
    #[error("the configuration the transit leads to is not collision-free")]
    EndCollides,
    /// The budget ran out.
    #[error(
        "the straight way collides and RRT-Connect found no collision-free transit within its \
         budget ({iterations} iterations, {extend_length} rad extensions)"
    )]
    NotFound {
        iterations: usize,
        extend_length: f64,
    },
    /// The edge check could not run.
    #[error("{0}")]
    Check(String),
}

/// The edge validity test: is the straight joint-space move between two arm
/// configurations free? `Err` when the check cannot run.
pub type EdgeCheck<'a> = dyn FnMut(&[f64], &[f64]) -> Result<bool, String> + 'a;

/// A collision-free transit of `arm` from `from` to `to` (arm
/// configurations): straight when free, else RRT-Connect within the budget.
pub fn plan_transit(
    arm: &Arm,
    from: &[f64],
    to: &[f64],
    free: &mut EdgeCheck,
    settings: &TransitSettings,
    seed: u64,
) -> Result<Transit, TransitError> {
    let mut free = |a: &[f64], b: &[f64]| free(a, b).map_err(TransitError::Check);
    if free(from, to)? {
        return Ok(Transit {
            path: joint_steps(from, to, settings.max_step),
            kind: TransitKind::Straight,
        });
    }
    if !free(from, from)? {
        return Err(TransitError::StartCollides);
    }
    if !free(to, to)? {
        return Err(TransitError::EndCollides);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut vertices, iterations) =
        connect(arm, from, to, &mut free, settings, &mut rng)?.ok_or(TransitError::NotFound {
            iterations: settings.max_iterations,
            extend_length: settings.extend_length,
        })?;
    shortcut(
        &mut vertices,
        &mut free,
        settings.shortcut_attempts,
        &mut rng,
    )?;
    let path = vertices
        .windows(2)
        .flat_map(|w| joint_steps(&w[0], &w[1], settings.max_step))
        .collect();
    Ok(Transit {
        path,
        kind: TransitKind::Planned {
            iterations,
            vertices: vertices.len(),
        },
    })
}

/// Configurations from `a` (excluded) to `b` (included), straight in joint
/// space, no joint moving more than `max_step` per step; empty when equal.
pub fn joint_steps(a: &[f64], b: &[f64], max_step: f64) -> Vec<Vec<f64>> {
    let largest = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let steps = (largest / max_step).ceil() as usize;
    (1..=steps)
        .map(|k| {
            a.iter()
                .zip(b)
                .map(|(x, y)| x + k as f64 / steps as f64 * (y - x))
                .collect()
        })
        .collect()
}

/// Which extension `rrt` asks the predicate about next.
#[derive(Debug, Clone)]
enum Phase {
    /// No extension is expected before the next sample.
    Idle,
    /// Tree `tree` extends once towards `target`, a sample.
    Extend { tree: usize, target: Vec<f64> },
    /// Tree `tree` connects towards `target`, the other tree's new vertex,
    /// one extension after another until it is trapped or reaches it.
    Connect { tree: usize, target: Vec<f64> },
}

/// The predicate's copy of `rrt::dual_rrt_connect`'s two trees (index 0
/// grows from the start, 1 from the goal; they alternate per sample), with
/// each vertex's parent. The path is read from here: `rrt` 0.7's own
/// result leaves out the vertex where the trees meet, joining its two
/// parents by an edge nobody checked.
struct Mirror {
    trees: [Vec<Vec<f64>>; 2],
    parents: [Vec<usize>; 2],
    samples: usize,
    phase: Phase,
    /// The first error of the edge check, reported after the search.
    error: Option<TransitError>,
}

/// Arm configurations in order: a path through joint space.
type Configurations = Vec<Vec<f64>>;

/// The edge test with the planner's error type.
type Free<'a> = dyn FnMut(&[f64], &[f64]) -> Result<bool, TransitError> + 'a;

/// Dual RRT-Connect from `from` to `to`: the path and the samples drawn;
/// `Ok(None)` when the budget runs out. `rrt` 0.7 stops when the trees come
/// within one extension of each other; the edge that joins them is checked
/// here, and when it is not free the search starts again with the rest of
/// the budget.
fn connect(
    arm: &Arm,
    from: &[f64],
    to: &[f64],
    free: &mut Free,
    settings: &TransitSettings,
    rng: &mut ChaCha8Rng,
) -> Result<Option<(Configurations, usize)>, TransitError> {
    let mut used = 0;
    while used < settings.max_iterations {
        let budget = settings.max_iterations - used;
        let (trees, samples) = search(arm, from, to, free, settings, budget, rng)?;
        used += samples;
        let Some([a, b]) = trees else {
            continue;
        };
        let (last, next) = (&a[a.len() - 1], &b[0]);
        if last == next || free(last, next)? {
            let skip = usize::from(last == next);
            return Ok(Some((
                a.into_iter().chain(b.into_iter().skip(skip)).collect(),
                used,
            )));
        }
    }
    Ok(None)
}

/// One run of `rrt::dual_rrt_connect` with `budget` samples: on success the
/// start tree's branch (start first) and the goal tree's (goal last), whose
/// ends are within one extension of each other; and the samples drawn.
fn search(
    arm: &Arm,
    from: &[f64],
    to: &[f64],
    free: &mut Free,
    settings: &TransitSettings,
    budget: usize,
    rng: &mut ChaCha8Rng,
) -> Result<(Option<[Configurations; 2]>, usize), TransitError> {
    let bounds = sampling_bounds(arm, from, to);
    let mirror = RefCell::new(Mirror {
        trees: [vec![from.to_vec()], vec![to.to_vec()]],
        parents: [vec![0], vec![0]],
        samples: 0,
        phase: Phase::Idle,
        error: None,
    });
    let rng = RefCell::new(rng);
    let sample = || {
        let q: Vec<f64> = {
            let mut rng = rng.borrow_mut();
            bounds
                .iter()
                .map(|&(lo, hi)| rng.random_range(lo..=hi))
                .collect()
        };
        let mut m = mirror.borrow_mut();
        m.phase = Phase::Extend {
            tree: m.samples % 2,
            target: q.clone(),
        };
        m.samples += 1;
        q
    };
    let length = settings.extend_length;
    let is_free = |q_new: &[f64]| {
        let mut m = mirror.borrow_mut();
        let (tree, target, extending) = match m.phase.clone() {
            Phase::Idle => return false,
            Phase::Extend { tree, target } => (tree, target, true),
            Phase::Connect { tree, target } => (tree, target, false),
        };
        let near = parent(&m.trees[tree], &target, q_new, length);
        let verdict = match near {
            Some(p) if m.error.is_none() => free(&m.trees[tree][p].clone(), q_new),
            _ => Ok(false),
        };
        let ok = verdict.unwrap_or_else(|e| {
            m.error.get_or_insert(e);
            false
        });
        m.phase = match (ok, extending) {
            (false, _) => Phase::Idle,
            // After the sampled extension the other tree connects towards
            // the new vertex.
            (true, true) => Phase::Connect {
                tree: 1 - tree,
                target: q_new.to_vec(),
            },
            (true, false) => Phase::Connect { tree, target },
        };
        if let (true, Some(p)) = (ok, near) {
            m.trees[tree].push(q_new.to_vec());
            m.parents[tree].push(p);
        }
        ok
    };
    let found = rrt::dual_rrt_connect(from, to, is_free, sample, length, budget);
    let m = mirror.into_inner();
    if let Some(e) = m.error {
        return Err(e);
    }
    let branches = found.ok().map(|_| {
        let mut a = m.branch(0);
        a.reverse();
        [a, m.branch(1)]
    });
    Ok((branches, m.samples))
}

impl Mirror {
    /// The newest vertex of `tree` and its ancestors up to the root. After a
    /// successful search the two trees' newest vertices are where they met.
    fn branch(&self, tree: usize) -> Vec<Vec<f64>> {
        let mut k = self.trees[tree].len() - 1;
        let mut out = vec![self.trees[tree][k].clone()];
        while k != 0 {
            k = self.parents[tree][k];
            out.push(self.trees[tree][k].clone());
        }
        out
    }
}

/// The vertex of `tree` whose RRT-Connect step towards `target` lands
/// exactly on `q_new` (the nearest such vertex), as `rrt` 0.7 computes it.
fn parent(tree: &[Vec<f64>], target: &[f64], q_new: &[f64], length: f64) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (k, near) in tree.iter().enumerate() {
        let squared: f64 = target
            .iter()
            .zip(near)
            .map(|(x, y)| (x - y) * (x - y))
            .fold(0.0, |a, b| a + b);
        let d = squared.sqrt();
        let lands = match d < length {
            true => target == q_new,
            false => near
                .iter()
                .zip(target)
                .map(|(n, t)| *n + (*t - *n) * length / d)
                .eq(q_new.iter().copied()),
        };
        if lands && best.is_none_or(|(_, b)| d < b) {
            best = Some((k, d));
        }
    }
    best.map(|(k, _)| k)
}

/// Per joint, the range samples are drawn from: the joint limits, or for a
/// continuous joint a full turn either side of the two ends' midpoint.
fn sampling_bounds(arm: &Arm, from: &[f64], to: &[f64]) -> Vec<(f64, f64)> {
    arm.lower
        .iter()
        .zip(&arm.upper)
        .zip(from.iter().zip(to))
        .map(
            |((&lo, &hi), (&a, &b))| match lo.is_finite() && hi.is_finite() {
                true => (lo, hi),
                false => {
                    let mid = 0.5 * (a + b);
                    (mid - std::f64::consts::PI, mid + std::f64::consts::PI)
                }
            },
        )
        .collect()
}

/// Random shortcutting: `attempts` times, two vertices at least two apart
/// are joined straight when that edge is free, dropping those between.
/// A pair found not free stays not free (the check is deterministic), so it
/// is remembered and never checked again; once every pair left has failed,
/// no draw could shorten the path and the loop ends. Both leave the result
/// unchanged and spare the edge checks that dominate a transit's cost.
fn shortcut(
    path: &mut Vec<Vec<f64>>,
    free: &mut Free,
    attempts: usize,
    rng: &mut ChaCha8Rng,
) -> Result<(), TransitError> {
    // Each vertex keeps its index in the path as found, so a failed pair is
    // recognised after vertices between others were dropped.
    let mut ids: Vec<usize> = (0..path.len()).collect();
    let mut failed = std::collections::BTreeSet::new();
    for _ in 0..attempts {
        if path.len() < 3 || every_pair_failed(&ids, &failed) {
            break;
        }
        let i = rng.random_range(0..path.len() - 2);
        let j = rng.random_range(i + 2..path.len());
        if failed.contains(&(ids[i], ids[j])) {
            continue;
        }
        if free(&path[i], &path[j])? {
            path.drain(i + 1..j);
            ids.drain(i + 1..j);
        } else {
            failed.insert((ids[i], ids[j]));
        }
    }
    Ok(())
}

/// Has every pair of vertices at least two apart been found not free?
fn every_pair_failed(ids: &[usize], failed: &std::collections::BTreeSet<(usize, usize)>) -> bool {
    let n = ids.len();
    let pairs = n.saturating_sub(1) * n.saturating_sub(2) / 2;
    failed.len() >= pairs && (0..n).all(|i| (i + 2..n).all(|j| failed.contains(&(ids[i], ids[j]))))
}

#[cfg(test)]
mod tests {
    use super::*;
    use afford_kinematics::RobotModel;

    /// A wall in joint space: joint 0 within ±0.4 rad needs joint 1 above 1.0.
    fn blocked(q: &[f64]) -> bool {
        q[0].abs() < 0.4 && q[1] < 1.0
    }

    /// The edge is free when 200 evenly spaced points on it are.
    fn sampled_edge(a: &[f64], b: &[f64]) -> Result<bool, String> {
        Ok((0..=200).all(|k| {
            let t = k as f64 / 200.0;
            let q: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + t * (y - x)).collect();
            !blocked(&q)
        }))
    }

    fn iiwa_ends() -> (RobotModel, Vec<f64>, Vec<f64>) {
        let robot = RobotModel::builtin("kuka_iiwa14").expect("robot");
        let mut from = vec![0.0; robot.arms()[0].dof()];
        let mut to = from.clone();
        from[0] = -1.0;
        to[0] = 1.0;
        (robot, from, to)
    }

    /// Every step of the output is free and within `max_step`, from `from` to `to`.
    fn assert_free_steps(transit: &Transit, from: &[f64], to: &[f64], max_step: f64) {
        let mut prev = from.to_vec();
        for q in &transit.path {
            assert!(
                sampled_edge(&prev, q).expect("check"),
                "edge {prev:?} -> {q:?}"
            );
            assert!(
                prev.iter()
                    .zip(q)
                    .all(|(a, b)| (a - b).abs() <= max_step + 1e-12)
            );
            prev = q.clone();
        }
        assert_eq!(prev, to);
    }

    /// A transit of the iiwa's arm under the sampled edge test.
    fn sampled_transit(
        robot: &RobotModel,
        from: &[f64],
        to: &[f64],
        settings: &TransitSettings,
        seed: u64,
    ) -> Result<Transit, TransitError> {
        plan_transit(
            &robot.arms()[0],
            from,
            to,
            &mut sampled_edge,
            settings,
            seed,
        )
    }

    #[test]
    fn transit_goes_around_when_the_straight_move_collides() {
        let (robot, from, to) = iiwa_ends();
        let settings = TransitSettings::default();
        let transit = sampled_transit(&robot, &from, &to, &settings, 7).expect("path");
        assert!(matches!(transit.kind, TransitKind::Planned { .. }));
        assert_free_steps(&transit, &from, &to, settings.max_step);
        let again = sampled_transit(&robot, &from, &to, &settings, 7).expect("path");
        assert_eq!(transit, again, "same seed, same transit");
    }

    #[test]
    fn transit_checks_every_edge_it_returns_across_seeds() {
        // rrt 0.7 joins its trees by an edge it never checks: the mirror's
        // path must be free on every seed, not only where the trees meet
        // exactly.
        let (robot, from, to) = iiwa_ends();
        // A budget that crosses this test's wall on every seed.
        let settings = TransitSettings {
            shortcut_attempts: 0,
            max_iterations: 600,
            ..TransitSettings::default()
        };
        for seed in 0..20 {
            let transit = sampled_transit(&robot, &from, &to, &settings, seed).expect("path");
            assert_free_steps(&transit, &from, &to, settings.max_step);
        }
    }

    #[test]
    fn transit_keeps_the_straight_move_when_free() {
        let (robot, from, mut to) = iiwa_ends();
        to[0] = -0.5;
        let settings = TransitSettings::default();
        let transit = sampled_transit(&robot, &from, &to, &settings, 1).expect("path");
        assert_eq!(transit.kind, TransitKind::Straight);
        assert_eq!(transit.path, joint_steps(&from, &to, settings.max_step));
    }

    #[test]
    fn transit_refuses_without_a_way_within_its_budget() {
        let (robot, from, to) = iiwa_ends();
        let settings = TransitSettings {
            max_iterations: 50,
            ..TransitSettings::default()
        };
        // A wall no joint can pass: joint 0 never crosses ±0.4 rad.
        let mut wall = |a: &[f64], b: &[f64]| {
            Ok::<bool, String>(a[0].abs() >= 0.4 && b[0].abs() >= 0.4 && a[0] * b[0] > 0.0)
        };
        let refused = plan_transit(&robot.arms()[0], &from, &to, &mut wall, &settings, 1);
        assert_eq!(
            refused,
            Err(TransitError::NotFound {
                iterations: 50,
                extend_length: settings.extend_length
            })
        );
        let mut start_blocked =
            |a: &[f64], b: &[f64]| Ok::<bool, String>(!blocked(a) && !blocked(b) && a[0] > -0.9);
        let refused = plan_transit(
            &robot.arms()[0],
            &from,
            &to,
            &mut start_blocked,
            &settings,
            1,
        );
        assert_eq!(refused, Err(TransitError::StartCollides));
    }

    /// Shortcutting a path whose shortcuts all collide checks each pair of
    /// vertices at most once, and stops once every pair has failed.
    #[test]
    fn shortcutting_never_checks_a_failed_pair_twice() {
        let mut path: Vec<Vec<f64>> = (0..5).map(|k| vec![f64::from(k)]).collect();
        let original = path.clone();
        let mut checked: Vec<(f64, f64)> = Vec::new();
        let mut never = |a: &[f64], b: &[f64]| {
            checked.push((a[0], b[0]));
            Ok::<bool, TransitError>(false)
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        shortcut(&mut path, &mut never, 1000, &mut rng).expect("check runs");
        assert_eq!(path, original);
        let mut distinct = checked.clone();
        distinct.sort_by(|x, y| x.partial_cmp(y).expect("finite"));
        distinct.dedup();
        assert_eq!(distinct.len(), checked.len(), "{checked:?}");
        // Pairs at least two apart among 5 vertices: 6, each checked once.
        assert_eq!(checked.len(), 6);
    }

    /// Remembering failed pairs does not change which shortcuts are taken:
    /// the same seed gives the same path as checking every draw.
    #[test]
    fn shortcutting_keeps_its_result_with_failed_pairs_remembered() {
        let free = |a: &[f64], b: &[f64]| (a[0] - b[0]).abs() <= 3.0;
        let path: Vec<Vec<f64>> = (0..12).map(|k| vec![f64::from(k)]).collect();
        let mut remembered = path.clone();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut check = |a: &[f64], b: &[f64]| Ok::<bool, TransitError>(free(a, b));
        shortcut(&mut remembered, &mut check, 48, &mut rng).expect("check runs");
        // The plain rule, every draw checked.
        let mut plain = path.clone();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..48 {
            if plain.len() < 3 {
                break;
            }
            let i = rng.random_range(0..plain.len() - 2);
            let j = rng.random_range(i + 2..plain.len());
            if free(&plain[i], &plain[j]) {
                plain.drain(i + 1..j);
            }
        }
        assert_eq!(remembered, plain);
        assert!(remembered.len() < path.len());
    }
}
