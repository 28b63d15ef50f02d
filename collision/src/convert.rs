//! The one place where afford's pose type meets parry's.
//!
//! afford's public API speaks [`afford_kinematics::Pose`] (nalgebra 0.30
//! `Isometry3<f64>`); parry 0.31 speaks glam (`DPose3` = translation `DVec3` +
//! rotation `DQuat`). Every conversion goes through [`to_parry`] /
//! [`from_parry`]. The round trip is exact: both sides store the same four
//! quaternion coefficients and three translation components; only the storage
//! order differs (nalgebra's `Quaternion::new` takes `w` first, glam's
//! `from_xyzw` takes it last).

use afford_kinematics::Pose;
use nalgebra::{Quaternion, Translation3, UnitQuaternion};
use parry3d::math::{Pose as PPose, Rotation as PRot, Vector as PVec};

/// nalgebra pose → parry pose (exact).
#[inline]
pub(crate) fn to_parry(pose: &Pose) -> PPose {
    let t = &pose.translation.vector;
    let q = &pose.rotation.quaternion().coords; // stored (i, j, k, w)
    PPose::from_parts(
        PVec::new(t.x, t.y, t.z),
        PRot::from_xyzw(q.x, q.y, q.z, q.w),
    )
}

/// parry pose → nalgebra pose (exact).
#[inline]
pub(crate) fn from_parry(pose: &PPose) -> Pose {
    let t = pose.translation;
    let r = pose.rotation;
    Pose::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::new_unchecked(Quaternion::new(r.w, r.x, r.y, r.z)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use afford_kinematics::pose_from_xyz_rpy;

    #[test]
    fn round_trip_is_exact() {
        for (xyz, rpy) in [
            ([0.1, -0.2, 0.3], [0.4, -1.2, 2.9]),
            ([1e-9, 7.0, -3.25], [3.1, 0.0, -3.1]),
            ([0.0; 3], [0.0; 3]),
        ] {
            let p = pose_from_xyz_rpy(xyz, rpy);
            let back = from_parry(&to_parry(&p));
            assert_eq!(p, back);
        }
    }

    #[test]
    fn conversion_preserves_the_transform() {
        let p = pose_from_xyz_rpy([0.1, -0.2, 0.3], [0.4, -1.2, 2.9]);
        let x = nalgebra::Point3::new(0.3, 0.7, -0.1);
        let a = p * x;
        let b = to_parry(&p) * PVec::new(0.3, 0.7, -0.1);
        assert!((a.x - b.x).abs() + (a.y - b.y).abs() + (a.z - b.z).abs() < 1e-15);
    }
}
