//! The probe's geometry: the gripper's reach along the approach axis, the
//! release floor, the grasp yaws, top-down tool poses and the seeded
//! generator of the restarts.

use std::f64::consts::{FRAC_PI_2, PI};

use afford_planner::Scenario;
use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::ArmIk;
use crate::chain::{Iso, to_parry};
use crate::check::Robot;
use crate::scene::{Footprint, GOAL_WALL, Piece};

/// The grasp region's reach below the tool centre point and the lowest
/// point of the other colliders rigid with the tool above it (negative:
/// below), over every arm, measured at home with the tool's +z the
/// approach axis.
pub(super) fn gripper_reach(r: &Robot, arms: &[ArmIk]) -> (f64, f64) {
    let links = r.kin.link_poses(r.model.home());
    let moved_by = |link: usize| crate::check::moved_by_arms(r.model, &r.kin, link);
    let (mut tips, mut palm) = (0.0_f64, f64::INFINITY);
    for arm in arms {
        let tool = moved_by(arm.tool);
        let rigid: Vec<usize> = (0..r.bodies.len())
            .filter(|&b| moved_by(r.bodies[b].link) == tool)
            .collect();
        let any_finger = rigid.iter().any(|&b| r.fingers[b]);
        let frame = links[arm.tool].inverse();
        for &b in &rigid {
            let body = &r.bodies[b];
            let pose = to_parry(&(frame * links[body.link] * body.pose_link_shape));
            let below = body.shape.compute_aabb(&pose).maxs.z;
            match r.fingers[b] || !any_finger {
                true => tips = tips.max(below),
                false => palm = palm.min(-below),
            }
        }
    }
    (tips, palm)
}

/// Height of the release floor (base frame): the goal's wall top, or the
/// top plus margin of the highest piece other than `target` whose centre
/// lies in the goal's box.
pub(super) fn release_floor(s: &Scenario, pieces: &[Piece], target: usize, goal: usize) -> f64 {
    let g = &s.goals[goal];
    let f = Footprint::of(s, g.bbox);
    let wall = s.camera.table_z + g.height;
    (pieces.iter().enumerate())
        .filter(|&(i, p)| {
            let at = p.pose.translation.vector;
            let [x, y] = f.local([at.x, at.y]);
            i != target && x.abs() < 0.5 * f.size[0] && y.abs() < 0.5 * f.size[1]
        })
        .map(|(_, p)| {
            let margin = match p.sensitive {
                true => s.safety.sensitive_margin,
                false => s.safety.obstacle_margin,
            };
            p.pose.translation.vector.z + p.half[2] + margin
        })
        .fold(wall, f64::max)
}

/// The yaw of the object's longer side (its box's u side on a tie), that
/// yaw + 90°, and each turned half a turn (the same closing axis with the
/// gripper the other way round).
pub(super) fn grasp_yaws(s: &Scenario, object: usize) -> [f64; 4] {
    let f = Footprint::of(s, s.objects[object].bbox);
    let longer = match f.size[0] >= f.size[1] {
        true => f.yaw,
        false => f.yaw + FRAC_PI_2,
    };
    [0.0, PI, FRAC_PI_2, -FRAC_PI_2].map(|turn| longer + turn)
}

/// Candidate release spots (base frame x, y) for `piece` (in its
/// orientation on the table) in goal `goal`: a 7 × 7 lattice over where
/// its footprint lies inside the inner walls (the box less its walls, 0.1
/// mm to spare), corners included, nearest the centre first (lattice order
/// on a tie); none when it does not fit.
pub(super) fn release_spots(s: &Scenario, goal: usize, piece: &Piece) -> Vec<[f64; 2]> {
    let f = Footprint::of(s, s.goals[goal].bbox);
    let turn = piece.pose.rotation.euler_angles().2 - f.yaw;
    let (c, sn) = (turn.cos().abs(), turn.sin().abs());
    let [hx, hy] = [piece.half[0], piece.half[1]];
    let half = [c * hx + sn * hy, sn * hx + c * hy];
    let travel = [0, 1].map(|k| 0.5 * f.size[k] - GOAL_WALL - half[k] - 1e-4);
    if travel.iter().any(|&t| t < 0.0) {
        return Vec::new();
    }
    let steps = [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0].map(|k| k / 3.0);
    let mut local: Vec<[f64; 2]> = (steps.iter())
        .flat_map(|&a| steps.iter().map(move |&b| [a * travel[0], b * travel[1]]))
        .collect();
    local.sort_by(|a, b| a[0].hypot(a[1]).total_cmp(&b[0].hypot(b[1])));
    let (c, sn) = (f.yaw.cos(), f.yaw.sin());
    (local.into_iter())
        .map(|[x, y]| [f.centre[0] + c * x - sn * y, f.centre[1] + sn * x + c * y])
        .collect()
}

/// The tool pointing straight down (its +z along −z) at `p`, its x axis
/// along `yaw`.
pub(super) fn top_down([x, y, z]: [f64; 3], yaw: f64) -> Iso {
    let down = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI);
    Iso::from_parts(Translation3::new(x, y, z), down)
}

/// A seed from a seed and two numbers (SplitMix64 steps).
pub(super) fn mix(seed: u64, a: u64, b: u64) -> u64 {
    let mut m = SplitMix(seed ^ a.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    m.next();
    m.0 ^= b.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    m.next()
}

/// SplitMix64: a small seeded generator for the restarts.
pub(super) struct SplitMix(pub(super) u64);

impl SplitMix {
    pub(super) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub(super) fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}
