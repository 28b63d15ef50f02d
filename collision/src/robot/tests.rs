//! The mesh hull against its box (distance, contact, shape cast) and the
//! motion bound of mimic joints.

use super::*;
use parry3d::math::{Pose as PPose, Rotation as PRot};
use parry3d::query;

/// A box's hull and the box primitive, half sizes (0.05, 0.1, 0.15).
fn hull_and_box() -> (SharedShape, SharedShape) {
    let h = [0.05, 0.1, 0.15];
    let corner = |i: usize| {
        let s = |bit: usize, v: f64| if i & bit != 0 { v } else { -v };
        afford_kinematics::Vec3::new(s(1, h[0]), s(2, h[1]), s(4, h[2]))
    };
    let vertices = (0..8).map(corner).collect();
    let (hull, _) = parry_shape(&afford_kinematics::Shape::ConvexHull { vertices }).unwrap();
    (hull, SharedShape::cuboid(h[0], h[1], h[2]))
}

/// Probes of every kind but a cuboid (parry 0.31's cuboid-cuboid distance
/// is not exact, see tests/mesh.rs), at poses around the box.
fn probes() -> Vec<(PPose, SharedShape)> {
    let post = SharedShape::convex_hull(&[
        PVec::new(-0.05, -0.05, -0.25),
        PVec::new(0.05, -0.05, -0.25),
        PVec::new(0.05, 0.05, -0.25),
        PVec::new(-0.05, 0.05, -0.25),
        PVec::new(-0.05, -0.05, 0.25),
        PVec::new(0.05, -0.05, 0.25),
        PVec::new(0.05, 0.05, 0.25),
        PVec::new(-0.05, 0.05, 0.25),
    ])
    .unwrap();
    let shapes = [
        SharedShape::ball(0.03),
        SharedShape::capsule_z(0.05, 0.02),
        SharedShape::cylinder(0.04, 0.03),
        post,
    ];
    let mut out = Vec::new();
    for k in 0..12 {
        let a = 0.55 * k as f64;
        let at = PVec::new(0.3 * a.cos(), 0.35 * a.sin(), 0.3 * (1.3 * a).sin());
        let pose = PPose::from_parts(
            at,
            PRot::from_euler(parry3d::glamx::EulerRot::XYZ, 0.3 * a, 0.7, -a),
        );
        out.push((pose, shapes[k % shapes.len()].clone()));
    }
    out
}

#[test]
fn a_mesh_hull_has_the_distances_of_its_box() {
    let (hull, cuboid) = hull_and_box();
    let origin = PPose::IDENTITY;
    for (pose, probe) in probes() {
        let d = |s: &SharedShape| query::distance(&origin, s.as_ref(), &pose, probe.as_ref());
        let (a, b) = (d(&hull).unwrap().distance, d(&cuboid).unwrap().distance);
        assert!(a > 0.0 && (a - b).abs() < 1e-6, "hull {a} vs box {b}");
    }
}

#[test]
fn a_mesh_hull_penetrates_and_is_swept_into_like_its_box() {
    let (hull, cuboid) = hull_and_box();
    let origin = PPose::IDENTITY;
    let mut overlapping = 0;
    for (pose, probe) in probes() {
        // Moved most of the way to the box: mostly overlapping.
        let near = PPose::from_parts(pose.translation * 0.3, pose.rotation);
        let depth = |s: &SharedShape| {
            let contact = query::contact(&origin, s.as_ref(), &near, probe.as_ref(), 1.0);
            contact.unwrap().expect("within the prediction").dist
        };
        let (a, b) = (depth(&hull), depth(&cuboid));
        assert!((a - b).abs() < 1e-6, "contact: hull {a} vs box {b}");
        overlapping += usize::from(a < 0.0);
        // The probe thrown at the box centre: same time of impact.
        let velocity = -pose.translation;
        let toi = |s: &SharedShape| {
            let options = query::ShapeCastOptions::with_max_time_of_impact(1.0);
            query::cast_shapes(
                &origin,
                PVec::ZERO,
                s.as_ref(),
                &pose,
                velocity,
                probe.as_ref(),
                options,
            )
            .unwrap()
            .map(|hit| hit.time_of_impact)
        };
        let (a, b) = (toi(&hull).unwrap(), toi(&cuboid).unwrap());
        assert!(
            a > 0.0 && (a - b).abs() < 1e-6,
            "time of impact: hull {a} vs box {b}"
        );
    }
    assert!(overlapping >= 6, "only {overlapping} probes overlap");
}

/// Every point of a mimic finger moves no farther than its bound, and
/// the two fingers' relative motion no farther than their pair's.
#[test]
fn the_motion_bound_covers_mimic_joints() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../kinematics/tests/fixtures");
    let model = RobotModel::load("mimic_gripper.yaml", &dir).unwrap();
    let g = RobotGeometry::new(&model).unwrap();
    assert_eq!(g.multi_drive, 0b10, "finger_left_joint drives two joints");
    let (q0, q1) = ([0.3, 0.01], [-0.2, 0.035]);
    let dq = [0.5, 0.025];
    let (p0, p1) = (
        model.link_poses(&q0).unwrap(),
        model.link_poses(&q1).unwrap(),
    );
    let moved = |b: &Body, k: usize| {
        let support = b.shape.as_support_map().unwrap();
        let d = [
            (k % 3) as f64 - 1.0,
            ((k / 3) % 3) as f64 - 1.0,
            (k / 9) as f64 - 1.0,
        ];
        let s = support.local_support_point(PVec::new(d[0], d[1], d[2] + 0.01));
        let local = b.pose_link_shape * nalgebra::Point3::new(s.x, s.y, s.z);
        p1[b.link] * local - p0[b.link] * local
    };
    let bound = |b: &Body| b.radii.iter().zip(&dq).map(|(r, d)| r * d).sum::<f64>();
    let finger = |name: &str| g.bodies.iter().find(|b| b.name == name).unwrap();
    let (left, right) = (finger("finger_left"), finger("finger_right"));
    for k in 0..27 {
        for b in &g.bodies {
            assert!(moved(b, k).norm() <= bound(b) + 1e-12, "{}", b.name);
        }
        let apart = (moved(left, k) - moved(right, k)).norm();
        assert!(apart > 0.0 && apart <= bound(left) + bound(right) + 1e-12);
    }
}

/// A revolute joint driving a prismatic mimic joint bounds that joint's
/// travel: a configuration with it beyond its limits is refused.
#[test]
fn a_leader_of_a_prismatic_mimic_joint_is_held_to_its_limits() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../kinematics/tests/fixtures");
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
    let urdf = read("mimic_gripper.urdf").replace(
        r#"<mimic joint="finger_left_joint" multiplier="1" offset="0"/>"#,
        r#"<mimic joint="lift" multiplier="0.01" offset="0.02"/>"#,
    );
    let model = RobotModel::from_texts(
        &read("mimic_gripper.yaml"),
        std::path::Path::new("mimic_gripper.yaml"),
        &urdf,
        std::path::Path::new("mimic_gripper.urdf"),
    )
    .unwrap();
    let g = RobotGeometry::new(&model).unwrap();
    assert!(g.check_config(&[1.4, 0.02], "q").is_ok());
    let e = g.check_config(&[1.6, 0.02], "q").unwrap_err().to_string();
    assert!(e.contains("'lift'") && e.contains("mimic"), "{e}");
}
