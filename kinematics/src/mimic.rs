//! Mimic joints: a joint with `<mimic joint="leader" multiplier="m"
//! offset="o"/>` sits at `m * q_leader + o`. It is not a degree of freedom
//! (not in [`crate::RobotModel::joints`]): forward kinematics derives it.
//!
//! A leader may itself mimic another joint; the chain is followed to the
//! joint of the configuration at its end and the relations composed
//! (`q = m1 (m2 q + o2) + o1`). Refused, each with a [`MimicProblem`]: a
//! leader that is not defined or is fixed, a fixed joint with `<mimic>`, a
//! chain that comes back to a joint it passed (a cycle), a multiplier or
//! offset that is not finite or beyond [`MAX_MIMIC_MULTIPLIER`] and the
//! joint-value bounds, and a prismatic joint following a continuous one
//! (its travel would be unbounded). A mimic joint's own `<limit>` is kept
//! ([`crate::MimicJoint`]) but not enforced: planning keeps the leader
//! inside its limits, and a URDF whose relation takes the follower outside
//! its own is the URDF's to fix.

use std::collections::HashMap;
use std::path::Path;

use crate::bounds::{MAX_MIMIC_MULTIPLIER, MAX_PRISMATIC_LIMIT_M, MAX_REVOLUTE_LIMIT_RAD};
use crate::error::{KinematicsError, MimicProblem};
use crate::math::Real;
use crate::model::{JointKind, Mimic};
use crate::urdf::{TreeJoint, TreeLink};

/// A mimic joint resolved to the end of its chain.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Resolved {
    /// The joint named in `<mimic joint=..>`.
    pub leader: String,
    /// The joint at the end of the chain (not a mimic joint).
    pub root: String,
    /// The composed relation to `root`.
    pub mimic: Mimic,
}

/// Resolves the `<mimic>` of every joint of `links` (module docs); `file`
/// names the URDF in errors.
pub(crate) fn resolve(links: &mut [TreeLink], file: &Path) -> Result<(), KinematicsError> {
    let joints: HashMap<&str, &TreeJoint> = links
        .iter()
        .filter_map(|l| l.joint.as_ref())
        .map(|j| (j.name.as_str(), j))
        .collect();
    let mut resolved = Vec::new();
    for (i, link) in links.iter().enumerate() {
        let Some(joint) = link.joint.as_ref().filter(|j| j.mimic.is_some()) else {
            continue;
        };
        let r = follow(joint, &joints).map_err(|problem| KinematicsError::Mimic {
            file: file.to_path_buf(),
            joint: joint.name.clone(),
            problem,
        })?;
        resolved.push((i, r));
    }
    for (i, r) in resolved {
        if let Some(joint) = links[i].joint.as_mut() {
            joint.resolved = Some(r);
        }
    }
    Ok(())
}

/// Follows `joint`'s chain of leaders to a joint that mimics none.
fn follow(joint: &TreeJoint, joints: &HashMap<&str, &TreeJoint>) -> Result<Resolved, MimicProblem> {
    if joint.kind == JointKind::Fixed {
        return Err(MimicProblem::FixedFollower);
    }
    let mut visited = vec![joint.name.clone()];
    let mut composed = Mimic {
        multiplier: 1.0,
        offset: 0.0,
    };
    let mut current = joint;
    while let Some((leader, m, o)) = &current.mimic {
        check_values(current.kind, *m, *o)?;
        composed = Mimic {
            multiplier: composed.multiplier * m,
            offset: composed.multiplier * o + composed.offset,
        };
        if visited.contains(leader) {
            visited.push(leader.clone());
            return Err(MimicProblem::Cycle { joints: visited });
        }
        current = joints
            .get(leader.as_str())
            .ok_or_else(|| MimicProblem::UnknownLeader {
                leader: leader.clone(),
            })?;
        if current.kind == JointKind::Fixed {
            return Err(MimicProblem::FixedLeader {
                leader: leader.clone(),
            });
        }
        visited.push(leader.clone());
    }
    check_values(joint.kind, composed.multiplier, composed.offset)?;
    if joint.kind == JointKind::Prismatic && current.kind == JointKind::Continuous {
        return Err(MimicProblem::BadValue {
            reason: format!(
                "a prismatic joint cannot follow continuous joint '{}': its travel would be unbounded",
                current.name
            ),
        });
    }
    let leader = joint
        .mimic
        .as_ref()
        .map(|(l, _, _)| l.clone())
        .unwrap_or_default();
    Ok(Resolved {
        leader,
        root: current.name.clone(),
        mimic: composed,
    })
}

/// `Err` when a multiplier or offset is not finite or too large for a joint
/// of `kind`.
fn check_values(kind: JointKind, multiplier: Real, offset: Real) -> Result<(), MimicProblem> {
    let largest_offset = match kind {
        JointKind::Prismatic => MAX_PRISMATIC_LIMIT_M,
        _ => MAX_REVOLUTE_LIMIT_RAD,
    };
    let bad = |reason: String| Err(MimicProblem::BadValue { reason });
    if !(multiplier.is_finite() && multiplier.abs() <= MAX_MIMIC_MULTIPLIER) {
        return bad(format!(
            "multiplier {multiplier:?} must be finite and within ±{MAX_MIMIC_MULTIPLIER}"
        ));
    }
    if !(offset.is_finite() && offset.abs() <= largest_offset) {
        return bad(format!(
            "offset {offset:?} must be finite and within ±{largest_offset:.4}"
        ));
    }
    Ok(())
}
