//! Forward kinematics of the whole robot with the k crate, built from the
//! URDF text by urdf-rs 0.9 and `k::Chain::from` — none of
//! afford-kinematics' own FK. Owns the mapping between the robot
//! description's joint and link order and k's nodes, and the one
//! conversion from k's nalgebra poses to parry's glam poses.
//!
//! Mimic joints are movable for k but not joints of the description: each
//! is set from its leader, `multiplier * q + offset`, read from the URDF
//! here (chains of mimics composed), since k's unchecked setter does not
//! propagate them.

use afford_kinematics::RobotModel;
use nalgebra::Isometry3;
use parry3d::math::{Pose as PPose, Rotation as PRot, Vector as PVec};

/// A pose from k (nalgebra 0.30).
pub(crate) type Iso = Isometry3<f64>;

/// A movable joint above a link.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ancestor {
    /// Its position in k's movable joints (one per URDF joint).
    pub slot: usize,
    /// The robot joint (description order) that drives it.
    pub joint: usize,
    /// How fast it moves per unit of that joint: |multiplier| for a mimic
    /// joint, else 1.
    pub gain: f64,
    pub prismatic: bool,
    /// Its origin in the base frame at the reference configuration.
    pub origin: nalgebra::Vector3<f64>,
}

/// Movable ancestor joints of a link, deepest first.
pub(crate) type Ancestry = Vec<Ancestor>;

/// A k joint set from a robot joint: k slot, robot joint, multiplier, offset.
type Follower = (usize, usize, f64, f64);

/// The robot's kinematic tree as k sees it.
pub(crate) struct Kinematics {
    chain: k::Chain<f64>,
    /// Position in k's movable-joint vector of each robot joint (description order).
    k_slot: Vec<usize>,
    /// k's mimic joints, each set from a robot joint.
    followers: Vec<Follower>,
    /// The names of k's movable joints, in k's order.
    k_names: Vec<String>,
    /// Index in `chain.iter()` of the node posing each description link.
    link_node: Vec<usize>,
    /// Per description link: its movable ancestor joints (robot joint
    /// indices), deepest first, each with its origin at the reference
    /// configuration (base frame).
    ancestry: Vec<Ancestry>,
}

impl Kinematics {
    /// Builds k's chain from the model's URDF. `Err` names what does not
    /// match the description (a joint or link k does not know).
    pub(crate) fn new(robot: &RobotModel) -> Result<Self, String> {
        let urdf = urdf_rs_k::read_from_string(robot.urdf())
            .map_err(|e| format!("the URDF cannot be read by urdf-rs 0.9: {e}"))?;
        let chain = k::Chain::<f64>::from(&urdf);
        let movable: Vec<String> = chain.iter_joints().map(|j| j.name.clone()).collect();
        let followers = followers(robot, &urdf, &movable)?;
        let k_slot = robot
            .joints()
            .iter()
            .map(|j| {
                movable
                    .iter()
                    .position(|n| *n == j.name)
                    .ok_or_else(|| format!("joint '{}' is not a movable joint for k", j.name))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let nodes: Vec<&k::Node<f64>> = chain.iter().collect();
        let link_node = robot
            .links()
            .iter()
            .map(|l| {
                nodes
                    .iter()
                    .position(|n| n.link().as_ref().is_some_and(|k| k.name == l.name))
                    .ok_or_else(|| format!("link '{}' is not in k's chain", l.name))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut kinematics = Self {
            chain,
            k_slot,
            followers,
            k_names: movable,
            link_node,
            ancestry: Vec::new(),
        };
        kinematics.ancestry = kinematics.ancestry_at(robot)?;
        Ok(kinematics)
    }

    /// Pose of every description link (base frame) for a robot configuration.
    pub(crate) fn link_poses(&self, q: &[f64]) -> Vec<Iso> {
        let mut slots = vec![0.0; self.k_names.len()];
        for (&slot, &v) in self.k_slot.iter().zip(q) {
            slots[slot] = v;
        }
        for &(slot, j, multiplier, offset) in &self.followers {
            slots[slot] = multiplier * q[j] + offset;
        }
        self.chain.set_joint_positions_unchecked(&slots);
        let all = self.chain.update_transforms();
        self.link_node.iter().map(|&n| all[n]).collect()
    }

    /// Movable ancestor joints of a link, deepest first, with their origins
    /// at the reference configuration (see [`Self::new`]).
    pub(crate) fn ancestry(&self, link: usize) -> &[Ancestor] {
        &self.ancestry[link]
    }

    /// Walks every link's node up to the root at the robot's home posture.
    fn ancestry_at(&self, robot: &RobotModel) -> Result<Vec<Ancestry>, String> {
        let _ = self.link_poses(robot.home());
        let nodes: Vec<&k::Node<f64>> = self.chain.iter().collect();
        let mut out = Vec::with_capacity(self.link_node.len());
        for &n in &self.link_node {
            let mut list = Vec::new();
            let mut node = Some(nodes[n].clone());
            while let Some(current) = node {
                let joint = current.joint();
                if joint.is_movable() {
                    let (slot, j, multiplier) = self.driver(&joint.name)?;
                    let origin = joint
                        .world_transform()
                        .ok_or("k has no transform for a joint")?
                        .translation
                        .vector;
                    list.push(Ancestor {
                        slot,
                        joint: j,
                        gain: multiplier.abs(),
                        prismatic: matches!(joint.joint_type, k::JointType::Linear { .. }),
                        origin,
                    });
                }
                drop(joint);
                node = current.parent();
            }
            out.push(list);
        }
        Ok(out)
    }

    /// k's slot of its joint `name`, the robot joint driving it and the
    /// multiplier (1 for a robot joint).
    fn driver(&self, name: &str) -> Result<(usize, usize, f64), String> {
        let missing = || format!("joint '{name}' is not in the description");
        let slot = self
            .k_names
            .iter()
            .position(|n| n == name)
            .ok_or_else(missing)?;
        if let Some(j) = self.k_slot.iter().position(|&s| s == slot) {
            return Ok((slot, j, 1.0));
        }
        self.followers
            .iter()
            .find(|f| f.0 == slot)
            .map(|f| (slot, f.1, f.2))
            .ok_or_else(missing)
    }
}

/// Every k joint that is not a robot joint, as a follower of one: its
/// URDF `<mimic>` chain followed to a robot joint, relations composed.
fn followers(
    robot: &RobotModel,
    urdf: &urdf_rs_k::Robot,
    movable: &[String],
) -> Result<Vec<Follower>, String> {
    let mimic_of = |name: &str| {
        let joint = urdf.joints.iter().find(|j| j.name == name)?;
        let m = joint.mimic.as_ref()?;
        Some((
            m.joint.clone(),
            m.multiplier.unwrap_or(1.0),
            m.offset.unwrap_or(0.0),
        ))
    };
    let robot_joint = |name: &str| robot.joints().iter().position(|j| j.name == name);
    let mut out = Vec::new();
    for (slot, name) in movable.iter().enumerate() {
        if robot_joint(name).is_some() {
            continue;
        }
        let (mut leader, mut multiplier, mut offset) = (name.clone(), 1.0, 0.0);
        let mut steps = 0;
        let j = loop {
            if let Some(j) = robot_joint(&leader) {
                break j;
            }
            let (next, m, o) = mimic_of(&leader)
                .filter(|_| steps <= urdf.joints.len())
                .ok_or_else(|| {
                    format!("joint '{name}' follows no movable joint of the description")
                })?;
            (leader, multiplier, offset) = (next, multiplier * m, multiplier * o + offset);
            steps += 1;
        };
        out.push((slot, j, multiplier, offset));
    }
    Ok(out)
}

/// k's pose → parry's pose (exact: the same quaternion coefficients; glam
/// stores w last, nalgebra's `coords` are (i, j, k, w) too).
pub(crate) fn to_parry(pose: &Iso) -> PPose {
    let t = &pose.translation.vector;
    let q = &pose.rotation.quaternion().coords;
    PPose::from_parts(
        PVec::new(t.x, t.y, t.z),
        PRot::from_xyzw(q.x, q.y, q.z, q.w),
    )
}

/// The built-in robots and the test fixtures' robot with a mesh link and
/// gripper with mimic joints (kinematics/tests/fixtures).
#[cfg(test)]
pub(crate) fn test_robots() -> Vec<RobotModel> {
    let fixtures =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../kinematics/tests/fixtures");
    let builtin = afford_kinematics::BUILTIN_ROBOTS
        .iter()
        .map(|n| RobotModel::builtin(n));
    let files = ["mesh_box.yaml", "mimic_gripper.yaml"].map(|f| RobotModel::load(f, &fixtures));
    builtin.chain(files).map(Result::unwrap).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// k's FK against afford-kinematics' own (the only place both are used),
    /// mimic joints included.
    #[test]
    fn k_forward_kinematics_agrees_with_afford_kinematics() {
        for robot in test_robots() {
            let name = robot.name().to_string();
            let kin = Kinematics::new(&robot).unwrap();
            for trial in 0..20 {
                let q: Vec<f64> = robot
                    .joints()
                    .iter()
                    .enumerate()
                    .map(|(i, j)| {
                        let s = 0.5 + 0.45 * ((trial * 7 + i * 3) as f64).sin();
                        let (lo, hi) = (j.lower.max(-3.0), j.upper.min(3.0));
                        lo + s * (hi - lo)
                    })
                    .collect();
                let ours = kin.link_poses(&q);
                let theirs = robot.link_poses(&q).unwrap();
                for (link, (a, b)) in robot.links().iter().zip(ours.iter().zip(&theirs)) {
                    let dp = (a.translation.vector - b.translation.vector).norm();
                    let dr = a.rotation.angle_to(&b.rotation);
                    assert!(
                        dp < 1e-9 && dr < 1e-9,
                        "{name} {}: {dp} m, {dr} rad",
                        link.name
                    );
                }
            }
        }
    }

    #[test]
    fn pose_conversion_keeps_the_transform() {
        let pose = Iso::new(
            nalgebra::Vector3::new(0.1, -0.2, 0.3),
            nalgebra::Vector3::new(0.4, -1.2, 2.9),
        );
        let p = nalgebra::Point3::new(0.3, 0.7, -0.1);
        let a = pose * p;
        let b = to_parry(&pose) * PVec::new(0.3, 0.7, -0.1);
        assert!((a.x - b.x).abs() + (a.y - b.y).abs() + (a.z - b.z).abs() < 1e-15);
    }
}
