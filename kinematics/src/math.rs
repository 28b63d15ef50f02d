//! Math vocabulary of afford's kinematics: the scalar, the one pose type of the
//! public API, and the small pose helpers the solvers share.
//!
//! Frames are carried in names: `pose_base_tool` is the tool frame expressed in
//! the robot base frame. Lengths are metres, angles radians.

use nalgebra::{Unit, UnitQuaternion, Vector3};

/// The scalar of every computation.
pub type Real = f64;

/// A rigid transform (rotation + translation). The one pose type of the
/// public API; it is nalgebra 0.30's `Isometry3<f64>`, the type k uses too.
pub type Pose = nalgebra::Isometry3<Real>;

/// A 3-vector (position, direction, axis).
pub type Vec3 = Vector3<Real>;

/// A rotation.
pub type Rotation = UnitQuaternion<Real>;

/// A unit direction.
pub type Direction = Unit<Vector3<Real>>;

/// Builds a pose from a translation and URDF roll-pitch-yaw angles
/// (fixed axes: R = Rz(yaw) Ry(pitch) Rx(roll)).
pub fn pose_from_xyz_rpy(xyz: [Real; 3], rpy: [Real; 3]) -> Pose {
    Pose::from_parts(
        nalgebra::Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// The rotation of a tool whose approach axis (+z) points straight down and
/// whose x axis points along `yaw` in the horizontal plane.
pub fn top_down_rotation(yaw: Real) -> Rotation {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
}

/// A top-down tool pose at `position` with the given yaw.
pub fn top_down_pose(position: Vec3, yaw: Real) -> Pose {
    Pose::from_parts(position.into(), top_down_rotation(yaw))
}

/// Rotation error as a rotation vector (axis * angle, world frame) taking
/// `current` onto `target`.
pub fn rotation_error(current: &Rotation, target: &Rotation) -> Vec3 {
    (target * current.inverse()).scaled_axis()
}

/// Angle (rad) between two rotations.
pub fn rotation_distance(a: &Rotation, b: &Rotation) -> Real {
    a.angle_to(b)
}

/// Position distance (m) and rotation angle (rad) between two poses.
pub fn pose_distance(a: &Pose, b: &Pose) -> (Real, Real) {
    (
        (a.translation.vector - b.translation.vector).norm(),
        rotation_distance(&a.rotation, &b.rotation),
    )
}

/// Rotation vector that turns direction `from` onto direction `to` (world frame).
pub fn direction_error(from: &Vec3, to: &Vec3) -> Vec3 {
    let cross = from.cross(to);
    let sin = cross.norm();
    let cos = from.dot(to);
    let angle = sin.atan2(cos);
    if sin > 1e-12 {
        cross * (angle / sin)
    } else if cos > 0.0 {
        Vec3::zeros()
    } else {
        // Opposite directions: any axis perpendicular to `from` works.
        let helper = if from.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        from.cross(&helper).normalize() * std::f64::consts::PI
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn top_down_points_down() {
        let r = top_down_rotation(0.3);
        let z = r * Vec3::z();
        assert!((z + Vec3::z()).norm() < 1e-12);
        let x = r * Vec3::x();
        assert!((x.y.atan2(x.x) - 0.3).abs() < 1e-12);
    }

    #[test]
    fn direction_error_rotates_onto_target() {
        let a = Vec3::new(0.3, -0.2, 0.9).normalize();
        let b = Vec3::new(-0.5, 0.1, -0.4).normalize();
        let w = direction_error(&a, &b);
        let r = Rotation::from_scaled_axis(w);
        assert!((r * a - b).norm() < 1e-12);
    }
}
