//! The grasp and the release. At the close event the object (a box where
//! the scene has it) must be no wider across the fingers — along the tool's
//! y axis — than the gripper opens. It then rides with the tool, its pose
//! relative to the tool frozen at the close, until the open event; released,
//! it drops vertically onto the goal's floor and must rest wholly inside the
//! goal's inner walls ([`GOAL_WALL`] thick) without overlapping any other
//! piece's footprint (each piece as its solid: a box, or a round piece's
//! stadium, [`crate::scene`]).

use afford_planner::Scenario;
use nalgebra::{Point3, Translation3, Vector3};

use crate::chain::{Iso, to_parry};
use crate::scene::{Footprint, GOAL_WALL, Piece, signed_distance};

/// How far a released object may reach past an inner wall or into another
/// piece's footprint, m (rounding only).
pub const PLACEMENT_TOLERANCE: f64 = 1e-6;

/// The object's width across the fingers when the tool is at `tool`.
pub(crate) fn width_across_fingers(piece: &Piece, tool: &Iso) -> f64 {
    let y = tool.rotation * Vector3::y();
    (0..3)
        .map(|k| {
            let axis = piece.pose.rotation * Vector3::ith(k, 1.0);
            2.0 * piece.half[k] * axis.dot(&y).abs()
        })
        .sum()
}

/// The box's eight corners in the base frame.
fn corners(pose: &Iso, half: &[f64; 3]) -> Vec<Point3<f64>> {
    (0..8)
        .map(|k| {
            let s = |bit: usize| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
            pose * Point3::new(s(0) * half[0], s(1) * half[1], s(2) * half[2])
        })
        .collect()
}

/// The released box dropped straight down until its lowest corner is on
/// the floor at height `floor`.
pub(crate) fn dropped(pose: &Iso, half: &[f64; 3], floor: f64) -> Iso {
    let lowest = corners(pose, half)
        .iter()
        .map(|c| c.z)
        .fold(f64::INFINITY, f64::min);
    Translation3::new(0.0, 0.0, floor - lowest) * pose
}

/// Problems with a released piece resting at `piece.pose` in goal `goal`,
/// among `others` (every other object where it is now).
pub(crate) fn check(s: &Scenario, goal: usize, piece: &Piece, others: &[&Piece]) -> Vec<String> {
    let g = &s.goals[goal];
    let f = Footprint::of(s, g.bbox);
    let inner = [0.5 * f.size[0] - GOAL_WALL, 0.5 * f.size[1] - GOAL_WALL];
    let beyond = corners(&piece.pose, &piece.half)
        .iter()
        .map(|c| {
            let [x, y] = f.local([c.x, c.y]);
            (x.abs() - inner[0]).max(y.abs() - inner[1])
        })
        .fold(f64::NEG_INFINITY, f64::max);
    let mut out = Vec::new();
    if beyond > PLACEMENT_TOLERANCE {
        out.push(format!(
            "{} rests {:.1} mm beyond an inner wall of the {} (inner size {:.3} x {:.3} m)",
            piece.name,
            beyond * 1e3,
            g.name,
            2.0 * inner[0],
            2.0 * inner[1]
        ));
    }
    let shape = piece.shape();
    let pose = to_parry(&piece.pose);
    for other in others {
        // The other piece's footprint as a tall prism: overlapping it is
        // overlapping the footprint, whatever the heights.
        let d = other
            .prism(10.0)
            .parts()
            .iter()
            .map(|(local, part)| {
                signed_distance(&pose, &shape, &to_parry(&(other.pose * local)), part)
            })
            .fold(f64::INFINITY, f64::min);
        if d < -PLACEMENT_TOLERANCE {
            out.push(format!(
                "{} rests on or in {} (footprints overlap by {:.1} mm)",
                piece.name,
                other.name,
                -d * 1e3
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    fn piece(x: f64, yaw: f64) -> Piece {
        Piece {
            name: "p".into(),
            pose: Iso::from_parts(
                Translation3::new(x, 0.0, 0.5),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
            ),
            half: [0.0625, 0.02, 0.015],
            sensitive: false,
            round: false,
        }
    }

    #[test]
    fn width_is_measured_across_the_fingers() {
        let tool = Iso::identity();
        assert!((width_across_fingers(&piece(0.0, 0.0), &tool) - 0.04).abs() < 1e-12);
        let turned = piece(0.0, std::f64::consts::FRAC_PI_2);
        assert!((width_across_fingers(&turned, &tool) - 0.125).abs() < 1e-12);
    }

    #[test]
    fn a_dropped_box_lands_on_the_floor() {
        let p = piece(0.0, 0.3);
        let down = dropped(&p.pose, &p.half, 0.1);
        assert!((down.translation.vector.z - 0.115).abs() < 1e-12);
    }

    /// A 40 mm piece on the floor of a box, its centre at `(x, y)`.
    fn standing(name: &str, x: f64, y: f64, round: bool) -> Piece {
        Piece {
            name: name.into(),
            pose: Iso::translation(x, y, 0.02),
            half: [0.02, 0.02, 0.02],
            sensitive: false,
            round,
        }
    }

    #[test]
    fn round_piece_beside_a_square_corner_keeps_its_room() {
        // Diagonally past the square's corner: the boxes overlap by 2 mm
        // along each axis, the disc is clear of the corner by
        // hypot(0.022, 0.022) - 0.02 = 11 mm.
        let square = standing("square", 0.0, 0.0, false);
        let overlaps = |p: &Piece, q: &Piece| {
            let d = q
                .prism(10.0)
                .parts()
                .iter()
                .map(|(local, part)| {
                    signed_distance(
                        &to_parry(&p.pose),
                        &p.shape(),
                        &to_parry(&(q.pose * local)),
                        part,
                    )
                })
                .fold(f64::INFINITY, f64::min);
            d < -PLACEMENT_TOLERANCE
        };
        let disc = standing("disc", 0.038, 0.038, true);
        assert!(!overlaps(&disc, &square));
        assert!(!overlaps(&square, &disc));
        let boxed = standing("box", 0.038, 0.038, false);
        assert!(overlaps(&boxed, &square));
        // Beside a side the disc reaches as far as its box.
        let beside = standing("disc", 0.039, 0.0, true);
        assert!(overlaps(&beside, &square));
        // Two discs diagonally: clear; head on: overlapping.
        assert!(!overlaps(&disc, &standing("d", 0.0, 0.0, true)));
        assert!(overlaps(
            &standing("d", 0.039, 0.0, true),
            &standing("e", 0.0, 0.0, true)
        ));
    }

    #[test]
    fn a_round_piece_is_a_stadium_inside_its_box() {
        let p = Piece {
            half: [0.02, 0.03, 0.01],
            ..standing("stadium", 0.0, 0.0, true)
        };
        let shape = p.shape();
        let inside = |x: f64, y: f64| {
            let at = parry3d::math::Vector::new(x, y, 0.029);
            shape.contains_point(&to_parry(&p.pose), at)
        };
        // The inscribed ellipse is inside; the box's corners are not.
        for k in 0..32 {
            let t = k as f64 * std::f64::consts::TAU / 32.0;
            assert!(inside(0.0199 * t.cos(), 0.0299 * t.sin()), "angle {t}");
        }
        assert!(!inside(0.0195, 0.0295));
        assert!(!inside(0.0, 0.0301) && !inside(0.0201, 0.0));
    }
}
