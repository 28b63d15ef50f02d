//! Adjacent links: the pairs of links that touch at a joint and are never
//! checked for self-collision, after the MoveIt Setup Assistant's connection
//! graph (`compute_default_collisions.cpp`), with one change: links rigidly
//! joined through fixed joints form one body.
//!
//! 1. Bodies: links joined by fixed joints are merged into one rigid body.
//! 2. Each movable joint connects its parent's body and its child's body.
//! 3. A body without collision geometry passes its connections on: all its
//!    neighbours become connected to each other (repeated until stable).
//! 4. Two links with geometry are adjacent when they lie in the same body or
//!    in two connected bodies.

use std::collections::BTreeSet;

use crate::model::{Link, RobotModel};

impl RobotModel {
    /// Link index pairs (smaller first, sorted) that are adjacent in the sense
    /// of this module; only links with collision geometry appear.
    pub fn adjacent_link_pairs(&self) -> Vec<(usize, usize)> {
        adjacent_link_pairs(&self.links)
    }
}

/// See the module docs; `links` in tree order (parents first).
pub(crate) fn adjacent_link_pairs(links: &[Link]) -> Vec<(usize, usize)> {
    // 1. Rigid bodies: a link without a movable joint above it joins its parent's body.
    let mut body = Vec::with_capacity(links.len());
    for (i, link) in links.iter().enumerate() {
        body.push(match (link.joint, link.parent) {
            (None, Some(p)) => body[p],
            _ => i,
        });
    }
    let n = links.len();
    let has_geometry: Vec<bool> = (0..n)
        .map(|b| (0..n).any(|l| body[l] == b && !links[l].colliders.is_empty()))
        .collect();
    // 2. Movable joints connect bodies.
    let mut connected: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for (i, link) in links.iter().enumerate() {
        if let (Some(_), Some(p)) = (link.joint, link.parent) {
            connected[body[i]].insert(body[p]);
            connected[body[p]].insert(body[i]);
        }
    }
    // 3. Bodies without geometry connect their neighbours.
    let mut changed = true;
    while changed {
        changed = false;
        for b in (0..n).filter(|&b| body[b] == b && !has_geometry[b]) {
            let around: Vec<usize> = connected[b].iter().copied().collect();
            for (k, &x) in around.iter().enumerate() {
                for &y in &around[k + 1..] {
                    changed |= connected[x].insert(y);
                    changed |= connected[y].insert(x);
                }
            }
        }
    }
    // 4. Link pairs in one body or in connected bodies.
    let solid: Vec<usize> = (0..n).filter(|&l| !links[l].colliders.is_empty()).collect();
    let mut pairs = Vec::new();
    for (k, &a) in solid.iter().enumerate() {
        for &b in &solid[k + 1..] {
            if body[a] == body[b] || connected[body[a]].contains(&body[b]) {
                pairs.push((a, b));
            }
        }
    }
    pairs
}
