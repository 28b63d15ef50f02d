//! The bridge to k: builds one `k::SerialChain` per arm from afford's parsed
//! URDF data and runs k's `JacobianIkSolver` as the baseline the bench
//! measures against. k's types (and their `Arc<Mutex>` nodes) stay in here.

use k::InverseKinematicsSolver;
use rand::Rng;

use crate::chain::Motion;
use crate::ik::random_configuration;
use crate::math::{Pose, Real};
use crate::model::Arm;

/// k's serial chain for an arm: one node per movable joint (fixed transforms
/// folded into the joint origins, as in afford's own chain) and a fixed tool node.
pub(crate) fn serial_chain(arm: &Arm) -> k::SerialChain<Real> {
    let mut nodes: Vec<k::Node<Real>> = Vec::with_capacity(arm.dof() + 1);
    for (i, j) in arm.chain.joints.iter().enumerate() {
        let axis = nalgebra::Unit::new_normalize(j.axis);
        let joint_type = match j.motion {
            Motion::Revolute => k::JointType::Rotational { axis },
            Motion::Prismatic => k::JointType::Linear { axis },
        };
        let node: k::Node<Real> = k::NodeBuilder::new()
            .name(&arm.joint_names[i])
            .joint_type(joint_type)
            .origin(j.origin)
            .limits(
                (arm.lower[i].is_finite() && arm.upper[i].is_finite())
                    .then(|| k::joint::Range::new(arm.lower[i], arm.upper[i])),
            )
            .into_node();
        if let Some(parent) = nodes.last() {
            node.set_parent(parent);
        }
        nodes.push(node);
    }
    let tool: k::Node<Real> = k::NodeBuilder::new()
        .name("tool")
        .joint_type(k::JointType::Fixed)
        .origin(arm.chain.tool)
        .into_node();
    tool.set_parent(nodes.last().expect("arms have at least one joint"));
    nodes.push(tool);
    k::SerialChain::new_unchecked(k::Chain::from_nodes(nodes))
}

/// k's Jacobian solver, the baseline the IK bench compares against: 100
/// iterations per try (multiplier 0.5) and up to `restarts` random restarts,
/// as in the stack notes' best case. Holds k's chain, so use one per thread.
pub struct KBaseline {
    chain: k::SerialChain<Real>,
    solver: k::JacobianIkSolver<Real>,
    restarts: usize,
}

impl KBaseline {
    pub fn new(
        arm: &Arm,
        position_tolerance: Real,
        rotation_tolerance: Real,
        restarts: usize,
    ) -> Self {
        Self {
            chain: serial_chain(arm),
            solver: k::JacobianIkSolver::new(position_tolerance, rotation_tolerance, 0.5, 100),
            restarts,
        }
    }

    /// Tool pose for joint values (k's FK).
    #[cfg(test)]
    pub fn fk(&self, q: &[Real]) -> Pose {
        self.chain.set_joint_positions_unchecked(q);
        self.chain.end_transform()
    }

    /// Solves from `start`, then random restarts; returns joint values on success.
    pub fn solve(
        &self,
        arm: &Arm,
        target: &Pose,
        start: &[Real],
        rng: &mut impl Rng,
    ) -> Option<Vec<Real>> {
        for attempt in 0..=self.restarts {
            let q0 = if attempt == 0 {
                start.to_vec()
            } else {
                random_configuration(arm, rng)
            };
            self.chain.set_joint_positions_clamped(&q0);
            if self.solver.solve(&self.chain, target).is_ok() {
                return Some(self.chain.joint_positions());
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::RobotModel;

    #[test]
    fn k_chain_fk_matches_afford_chain() {
        for name in crate::builtin::NAMES {
            let m = RobotModel::builtin(name).unwrap();
            for arm in m.arms() {
                let k = KBaseline::new(arm, 1e-4, 1e-3, 0);
                let q: Vec<Real> = (0..arm.dof())
                    .map(|i| 0.2 * (i as Real + 0.5).cos())
                    .collect();
                let a = arm.fk(&q);
                let b = k.fk(&q);
                assert!((a.translation.vector - b.translation.vector).norm() < 1e-12);
                assert!(a.rotation.angle_to(&b.rotation) < 1e-12);
            }
        }
    }
}
