//! The compact serial chain the solvers run on: one fixed transform and one
//! joint axis per movable joint, fixed joints folded in. Owns forward
//! kinematics and the geometric Jacobian of one arm.
//!
//! With `T_i(q_i)` the joint motion, the tool pose is
//! `base_T_tool = O_1 T_1(q_1) O_2 T_2(q_2) ... O_n T_n(q_n) O_tool`.
//! Jacobian column i (world frame) is `[a_i x (p_tool - p_i); a_i]` for a
//! revolute joint and `[a_i; 0]` for a prismatic one.

use nalgebra::{Matrix6xX, Translation3, UnitQuaternion};

use crate::math::{Pose, Real, Vec3};

/// How a chain joint moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Motion {
    Revolute,
    Prismatic,
}

/// One movable joint of a chain.
#[derive(Debug, Clone)]
pub(crate) struct ChainJoint {
    /// Fixed transform from the previous joint's moved frame (or the robot
    /// base) to this joint's frame.
    pub origin: Pose,
    /// Unit axis in this joint's frame.
    pub axis: Vec3,
    pub motion: Motion,
}

/// A serial chain from the robot base frame to a tool frame.
#[derive(Debug, Clone)]
pub(crate) struct Chain {
    pub joints: Vec<ChainJoint>,
    /// Fixed transform from the last joint's moved frame to the tool.
    pub tool: Pose,
}

impl ChainJoint {
    #[inline]
    fn motion_transform(&self, q: Real) -> Pose {
        match self.motion {
            Motion::Revolute => Pose::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_scaled_axis(self.axis * q),
            ),
            Motion::Prismatic => Pose::from_parts(
                Translation3::from(self.axis * q),
                UnitQuaternion::identity(),
            ),
        }
    }
}

impl Chain {
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Tool pose in the robot base frame.
    pub fn fk(&self, q: &[Real]) -> Pose {
        let mut pose = Pose::identity();
        for (joint, &qi) in self.joints.iter().zip(q) {
            pose = pose * joint.origin * joint.motion_transform(qi);
        }
        pose * self.tool
    }

    /// Tool pose and the geometric Jacobian (rows: linear x y z, angular x y z;
    /// world frame, reference point = tool origin). `jac` must be 6 x dof.
    pub fn fk_jacobian(&self, q: &[Real], jac: &mut Matrix6xX<Real>) -> Pose {
        debug_assert_eq!(jac.ncols(), self.dof());
        let mut pose = Pose::identity();
        // Store axis and position of every joint, then fill columns once the tool is known.
        let mut axes = [Vec3::zeros(); MAX_DOF];
        let mut points = [Vec3::zeros(); MAX_DOF];
        for (i, (joint, &qi)) in self.joints.iter().zip(q).enumerate() {
            pose *= joint.origin;
            axes[i] = pose.rotation * joint.axis;
            points[i] = pose.translation.vector;
            pose *= joint.motion_transform(qi);
        }
        let pose = pose * self.tool;
        let p_tool = pose.translation.vector;
        for (i, joint) in self.joints.iter().enumerate() {
            let (lin, ang) = match joint.motion {
                Motion::Revolute => (axes[i].cross(&(p_tool - points[i])), axes[i]),
                Motion::Prismatic => (axes[i], Vec3::zeros()),
            };
            let mut col = jac.column_mut(i);
            col[0] = lin.x;
            col[1] = lin.y;
            col[2] = lin.z;
            col[3] = ang.x;
            col[4] = ang.y;
            col[5] = ang.z;
        }
        pose
    }

    /// Origin of the first joint in the base frame (independent of q).
    pub fn first_joint_origin(&self) -> Vec3 {
        self.joints
            .first()
            .map(|j| j.origin.translation.vector)
            .unwrap_or_else(Vec3::zeros)
    }

    /// Upper bound on the distance from the first joint origin to the tool:
    /// the sum of the fixed offsets along the chain (prismatic strokes added).
    pub fn reach_bound(&self, upper: &[Real], lower: &[Real]) -> Real {
        let mut sum = 0.0;
        for j in self.joints.iter().skip(1) {
            sum += j.origin.translation.vector.norm();
        }
        for (i, j) in self.joints.iter().enumerate() {
            if j.motion == Motion::Prismatic {
                sum += upper[i].abs().max(lower[i].abs());
            }
        }
        sum + self.tool.translation.vector.norm()
    }
}

/// Largest chain the solvers handle (fixed-size scratch arrays).
pub const MAX_DOF: usize = 16;
