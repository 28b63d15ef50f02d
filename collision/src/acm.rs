//! The allowed-collision matrix (ACM): which link pairs of a robot the
//! self-collision check may skip, derived from the geometry the way the MoveIt
//! Setup Assistant does (`compute_default_collisions.cpp`), with a
//! conservative `never`. Every pair of links with collision geometry gets,
//! in this order:
//!
//! 1. `adjacent`: joined by a joint, links rigidly joined by fixed joints
//!    counting as one body ([`RobotModel::adjacent_link_pairs`]);
//! 2. `default`: in contact at the home posture;
//! 3. `always`: in contact in at least [`AcmSettings::always_fraction`] of the
//!    sampled configurations (MoveIt: 95 %);
//! 4. `never`: farther apart than [`AcmSettings::clearance`] in every sampled
//!    configuration (MoveIt: not in contact in any sample — afford asks for a
//!    clearance so that a pair that comes close in some sample, and may
//!    touch between samples, stays checked);
//! 5. otherwise checked.
//!
//! "In contact" uses the check's criterion: distance <= the default
//! [`CheckSettings::tolerance`](crate::CheckSettings) (0.1 mm). Samples are
//! uniform within the joint limits ([-pi, pi] for a joint without limits),
//! drawn from ChaCha8 seeded with `seed`, one stream per block of
//! [`BLOCK`] samples, so the result does not depend on the thread count.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use afford_kinematics::{
    AllowedCollisions, AllowedPair, AllowedReason, MAX_ACM_SAMPLES, RobotModel,
};
use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose as PPose;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::check::CheckSettings;
use crate::convert::to_parry;
use crate::error::CollisionError;
use crate::robot::RobotGeometry;
use crate::scene::aabb_distance;
use crate::sweep::distance;

/// Samples drawn from one random stream.
pub const BLOCK: u64 = 1_000;

/// How the matrix is derived; defaults written once here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AcmSettings {
    /// Random configurations sampled (1 ..= [`MAX_ACM_SAMPLES`]).
    pub samples: u64,
    /// Seed of the sampler.
    pub seed: u64,
    /// A pair is `never` only when its distance exceeds this in every sample, m.
    pub clearance: f64,
    /// A pair in contact in at least this fraction of the samples is `always`.
    pub always_fraction: f64,
}

impl Default for AcmSettings {
    fn default() -> Self {
        Self {
            samples: 100_000,
            seed: 1,
            clearance: 0.03,
            always_fraction: 0.95,
        }
    }
}

impl AcmSettings {
    /// Errors: [`CollisionError::Settings`] naming the field out of range.
    pub fn validate(&self) -> Result<(), CollisionError> {
        let path_err = |field: &str, problem: String| CollisionError::Settings {
            field: field.into(),
            problem,
        };
        if self.samples == 0 || self.samples > MAX_ACM_SAMPLES {
            return Err(path_err(
                "samples",
                format!("must be 1 ..= {MAX_ACM_SAMPLES}, got {}", self.samples),
            ));
        }
        if !(self.clearance.is_finite() && (0.0..=1.0).contains(&self.clearance)) {
            return Err(path_err("clearance", "must be 0 ..= 1 m".into()));
        }
        if !(self.always_fraction > 0.5 && self.always_fraction <= 1.0) {
            return Err(path_err("always_fraction", "must be in (0.5, 1]".into()));
        }
        Ok(())
    }
}

/// One link pair of the matrix and what the sampling saw.
#[derive(Debug, Clone, PartialEq)]
pub struct PairEntry {
    /// Link names, tree order.
    pub links: [String; 2],
    /// Why the check skips the pair; `None`: checked.
    pub reason: Option<AllowedReason>,
    /// Smallest distance over the samples, m (0 when in contact; `None` for
    /// adjacent pairs, which are not sampled).
    pub min_distance: Option<f64>,
    /// Fraction of the samples in contact (`None` for adjacent pairs).
    pub contact_fraction: Option<f64>,
}

/// The derived matrix: every pair of links with geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct AllowedCollisionMatrix {
    /// Robot name.
    pub robot: String,
    pub settings: AcmSettings,
    /// Every pair, in link (tree) order.
    pub pairs: Vec<PairEntry>,
}

/// Per-pair statistics of some samples.
#[derive(Debug, Clone)]
struct Stats {
    min: Vec<f64>,
    contacts: Vec<u64>,
}

impl Stats {
    fn new(n: usize) -> Self {
        Self {
            min: vec![f64::INFINITY; n],
            contacts: vec![0; n],
        }
    }

    fn merge(mut self, other: Self) -> Self {
        for (a, b) in self.min.iter_mut().zip(other.min) {
            *a = a.min(b);
        }
        for (a, b) in self.contacts.iter_mut().zip(other.contacts) {
            *a += b;
        }
        self
    }
}

/// The sampled link pairs and, per pair, its body pairs.
struct Pairs<'a> {
    geometry: &'a RobotGeometry,
    bodies: Vec<Vec<(usize, usize)>>,
    tolerance: f64,
}

impl Pairs<'_> {
    /// Adds one configuration to `stats`.
    fn sample(&self, q: &[f64], stats: &mut Stats) -> Result<(), CollisionError> {
        let g = self.geometry;
        let links = g.model.link_poses(q)?;
        let poses: Vec<PPose> = g
            .bodies
            .iter()
            .map(|b| to_parry(&(links[b.link] * b.pose_link_shape)))
            .collect();
        let aabbs: Vec<Aabb> = g
            .bodies
            .iter()
            .zip(&poses)
            .map(|(b, p)| b.shape.compute_aabb(p))
            .collect();
        for (k, body_pairs) in self.bodies.iter().enumerate() {
            let mut contact = false;
            for &(a, b) in body_pairs {
                let bound = aabb_distance(&aabbs[a], &aabbs[b]);
                if bound > stats.min[k] && bound > self.tolerance {
                    continue;
                }
                let d = distance(
                    &poses[a],
                    g.bodies[a].shape.as_ref(),
                    &poses[b],
                    g.bodies[b].shape.as_ref(),
                );
                stats.min[k] = stats.min[k].min(d);
                contact |= d <= self.tolerance;
            }
            stats.contacts[k] += u64::from(contact);
        }
        Ok(())
    }
}

impl AllowedCollisionMatrix {
    /// Derives the matrix of `model` (see the module docs).
    ///
    /// Errors: invalid settings (field named), a model the collision crate
    /// cannot use.
    pub fn derive(model: &RobotModel, settings: &AcmSettings) -> Result<Self, CollisionError> {
        settings.validate()?;
        let geometry = RobotGeometry::new(model)?;
        let solid: BTreeSet<usize> = geometry.bodies.iter().map(|b| b.link).collect();
        let solid: Vec<usize> = solid.into_iter().collect();
        let adjacent = model.adjacent_link_pairs();
        let mut link_pairs = Vec::new();
        let mut sampled = Vec::new();
        for (k, &a) in solid.iter().enumerate() {
            for &b in &solid[k + 1..] {
                link_pairs.push((a, b));
                if adjacent.binary_search(&(a, b)).is_err() {
                    sampled.push((a, b));
                }
            }
        }
        let body_pairs = |(la, lb): (usize, usize)| -> Vec<(usize, usize)> {
            let on = |l: usize| -> Vec<usize> {
                (0..geometry.bodies.len())
                    .filter(|&i| geometry.bodies[i].link == l)
                    .collect()
            };
            let (on_a, on_b) = (on(la), on(lb));
            on_a.iter()
                .flat_map(|&a| on_b.iter().map(move |&b| (a, b)))
                .collect()
        };
        let pairs = Pairs {
            geometry: &geometry,
            bodies: sampled.iter().map(|&p| body_pairs(p)).collect(),
            tolerance: CheckSettings::default().tolerance,
        };
        let mut at_home = Stats::new(sampled.len());
        pairs.sample(model.home(), &mut at_home)?;
        let stats = sample_all(model, &pairs, settings)?;
        let name = |l: usize| model.links()[l].name.clone();
        let entries = link_pairs
            .iter()
            .map(|&(a, b)| {
                let links = [name(a), name(b)];
                let Some(k) = sampled.iter().position(|&p| p == (a, b)) else {
                    return PairEntry {
                        links,
                        reason: Some(AllowedReason::Adjacent),
                        min_distance: None,
                        contact_fraction: None,
                    };
                };
                let contact_fraction = stats.contacts[k] as f64 / settings.samples as f64;
                let min_distance = stats.min[k];
                let reason = if at_home.contacts[k] > 0 {
                    Some(AllowedReason::Default)
                } else if contact_fraction >= settings.always_fraction {
                    Some(AllowedReason::Always)
                } else if min_distance > settings.clearance {
                    Some(AllowedReason::Never)
                } else {
                    None
                };
                PairEntry {
                    links,
                    reason,
                    min_distance: Some(min_distance),
                    contact_fraction: Some(contact_fraction),
                }
            })
            .collect();
        Ok(Self {
            robot: model.name().to_string(),
            settings: *settings,
            pairs: entries,
        })
    }

    /// Number of pairs with this reason (`None`: checked pairs).
    pub fn count(&self, reason: Option<AllowedReason>) -> usize {
        self.pairs.iter().filter(|p| p.reason == reason).count()
    }

    /// The section a robot description stores.
    pub fn to_section(&self) -> AllowedCollisions {
        AllowedCollisions {
            samples: self.settings.samples,
            seed: self.settings.seed,
            clearance: self.settings.clearance,
            pairs: self
                .pairs
                .iter()
                .filter_map(|p| {
                    p.reason.map(|reason| AllowedPair {
                        pair: p.links.clone(),
                        reason,
                    })
                })
                .collect(),
        }
    }

    /// The `allowed_collisions:` block to paste into the robot description,
    /// with the sampled distances as comments and the checked pairs listed
    /// (as comments) at the end.
    pub fn to_yaml(&self) -> String {
        let s = &self.settings;
        let mut out = String::new();
        let counts = [
            AllowedReason::Adjacent,
            AllowedReason::Default,
            AllowedReason::Always,
            AllowedReason::Never,
        ]
        .map(|r| format!("{} {}", self.count(Some(r)), r.as_str()))
        .join(", ");
        let _ = writeln!(
            out,
            "# Allowed-collision matrix of '{}', generated by `afford robots acm` (--samples {} --seed {} --clearance {}):\n\
             # pairs skipped by the self-collision check and why; every other link pair is checked.\n\
             # {} link pairs: {counts}, {} checked. `never` = more than {} m apart in all {} samples.",
            self.robot,
            s.samples,
            s.seed,
            s.clearance,
            self.pairs.len(),
            self.count(None),
            s.clearance,
            s.samples
        );
        let _ = writeln!(
            out,
            "allowed_collisions:\n  samples: {}\n  seed: {}\n  clearance: {}\n  pairs:",
            s.samples, s.seed, s.clearance
        );
        for p in &self.pairs {
            let Some(reason) = p.reason else { continue };
            let entry = format!(
                "    - {{pair: [{}, {}], reason: {}}}",
                p.links[0],
                p.links[1],
                reason.as_str()
            );
            let note = match reason {
                AllowedReason::Adjacent => String::new(),
                _ => format!("  # {}", p.observed()),
            };
            let _ = writeln!(out, "{entry}{note}");
        }
        let _ = writeln!(out, "  # checked:");
        for p in self.pairs.iter().filter(|p| p.reason.is_none()) {
            let _ = writeln!(
                out,
                "  #   [{}, {}]  {}",
                p.links[0],
                p.links[1],
                p.observed()
            );
        }
        out
    }
}

impl PairEntry {
    /// What the samples showed, for a comment.
    fn observed(&self) -> String {
        match (self.min_distance, self.contact_fraction) {
            (Some(d), Some(f)) => format!(
                "min distance {d:.3} m, in contact in {:.1} % of samples",
                100.0 * f
            ),
            _ => "adjacent: not sampled".into(),
        }
    }
}

/// Statistics over every sample, one random stream per block, blocks in parallel.
fn sample_all(
    model: &RobotModel,
    pairs: &Pairs,
    settings: &AcmSettings,
) -> Result<Stats, CollisionError> {
    let n = pairs.bodies.len();
    let blocks = settings.samples.div_ceil(BLOCK);
    (0..blocks)
        .into_par_iter()
        .map(|block| {
            let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
            rng.set_stream(block);
            let count = BLOCK.min(settings.samples - block * BLOCK);
            let mut stats = Stats::new(n);
            for _ in 0..count {
                let q = random_within_limits(model, &mut rng);
                pairs.sample(&q, &mut stats)?;
            }
            Ok(stats)
        })
        .try_reduce(|| Stats::new(n), |a, b| Ok(a.merge(b)))
}

/// A configuration uniform within the joint limits ([-pi, pi] where a limit
/// is not finite).
fn random_within_limits(model: &RobotModel, rng: &mut impl Rng) -> Vec<f64> {
    use std::f64::consts::PI;
    model
        .joints()
        .iter()
        .map(|j| {
            let (lo, hi) = if j.lower.is_finite() && j.upper.is_finite() {
                (j.lower, j.upper)
            } else {
                (-PI, PI)
            };
            if hi > lo {
                rng.random_range(lo..=hi)
            } else {
                lo
            }
        })
        .collect()
}
