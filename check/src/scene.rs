//! The scene rebuilt from the scenario file, in metres, robot base frame:
//! every pixel box through `camera.pixel_to_base` to a footprint on the table
//! (centre, size along the image axes, yaw of the image u axis), standing on
//! `table_z` with its height. Objects are solids whose pose the check
//! tracks from sub-goal to sub-goal: boxes, or, when their shape is round
//! ([`ROUND_SHAPES`]), the upright stadium inside the box —
//! two cylinders of the narrower side's radius at the ends of the longer
//! side and the box between their axes (one cylinder for a square box),
//! which contains the ellipse inscribed in the box; hands are solid boxes; goals are open
//! boxes (a floor and four walls [`GOAL_WALL`] thick, inside the footprint);
//! the table is a slab [`TABLE_THICKNESS`] thick under the image's footprint.
//!
//! Margins (the safety perimeters a body must stay out of): other objects
//! `obstacle_margin` (`sensitive_margin` when sensitive), hands
//! `hand_margin`, other goals `obstacle_margin`, the sub-goal's own goal,
//! the goal the target rests in at the sub-goal's start (it is picked from
//! that box's floor) and the table 0 (touching still counts as penetration).

use afford_planner::Scenario;
use afford_planner::scenario::PixelBox;
use std::f64::consts::FRAC_PI_2;

use nalgebra::{Translation3, UnitQuaternion, Vector3};
use parry3d::shape::SharedShape;

use crate::chain::{Iso, to_parry};

/// Object shapes whose outline is round (case-insensitive): upright
/// stadiums in the replay and in the check's scene.
pub const ROUND_SHAPES: [&str; 3] = ["circle", "cylinder", "disc"];

/// Whether a scenario shape name is one of [`ROUND_SHAPES`] (any case).
pub(crate) fn is_round(shape: &str) -> bool {
    ROUND_SHAPES.iter().any(|s| s.eq_ignore_ascii_case(shape))
}

/// Wall and floor thickness of a goal box, m (the value of the collision
/// crate's `GOAL_WALL`, copied: the boxes are the scenario's, not afford's).
pub const GOAL_WALL: f64 = 0.005;
/// Thickness of the table slab, m.
pub const TABLE_THICKNESS: f64 = 0.02;

/// A pixel box on the table in the base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Footprint {
    pub centre: [f64; 2],
    /// Size along the footprint's own x (image u) and y axes, m.
    pub size: [f64; 2],
    /// Rotation of the footprint's x axis about the vertical.
    pub yaw: f64,
}

impl Footprint {
    pub(crate) fn of(s: &Scenario, b: PixelBox) -> Self {
        let m = &s.camera.pixel_to_base;
        let [mu, mv] = [m[0][0].hypot(m[1][0]), m[0][1].hypot(m[1][1])];
        Self {
            centre: s.pixel_to_base(b.centre()),
            size: [b.w * mu, b.l * mv],
            yaw: m[1][0].atan2(m[0][0]),
        }
    }

    /// The footprint as a solid box from `z0` up `height`: its centre pose.
    pub(crate) fn pose(&self, z0: f64, height: f64) -> Iso {
        Iso::from_parts(
            Translation3::new(self.centre[0], self.centre[1], z0 + 0.5 * height),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.yaw),
        )
    }

    /// A point (x, y) in the footprint's own frame.
    pub(crate) fn local(&self, [x, y]: [f64; 2]) -> [f64; 2] {
        let (c, s) = (self.yaw.cos(), self.yaw.sin());
        let (dx, dy) = (x - self.centre[0], y - self.centre[1]);
        [c * dx + s * dy, -s * dx + c * dy]
    }
}

/// A box the check tracks (an object of the scenario).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Piece {
    pub name: String,
    /// Pose of the box centre.
    pub pose: Iso,
    pub half: [f64; 3],
    pub sensitive: bool,
    /// Its outline is round: the stadium inside `half` (module doc).
    pub round: bool,
}

impl Piece {
    /// The solid in the piece's frame (one shape; a compound when round).
    pub(crate) fn shape(&self) -> SharedShape {
        match self.round {
            true => SharedShape::compound(
                self.parts()
                    .iter()
                    .map(|(pose, shape)| (to_parry(pose), shape.clone()))
                    .collect(),
            ),
            false => solid_box(self.half),
        }
    }

    /// The solid's convex parts posed in the piece's frame.
    pub(crate) fn parts(&self) -> Vec<(Iso, SharedShape)> {
        let [hx, hy, hz] = self.half;
        if !self.round {
            return vec![(Iso::identity(), solid_box([hx, hy, hz]))];
        }
        let r = hx.min(hy);
        // Where the two cylinders' axes stand: along the longer side.
        let end = Vector3::new(hx - r, hy - r, 0.0);
        // parry's cylinder axis is its y: stood up about x.
        let upright = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2);
        let cylinder = |at: Vector3<f64>| {
            (
                Iso::from_parts(Translation3::from(at), upright),
                SharedShape::cylinder(hz, r),
            )
        };
        if end.x <= 0.0 && end.y <= 0.0 {
            return vec![cylinder(Vector3::zeros())];
        }
        // The box between the axes, as wide as the cylinders.
        let between = match end.x > 0.0 {
            true => solid_box([end.x, hy, hz]),
            false => solid_box([hx, end.y, hz]),
        };
        vec![cylinder(end), (Iso::identity(), between), cylinder(-end)]
    }

    /// The piece's footprint as a prism `2 half_height` tall about its pose.
    pub(crate) fn prism(&self, half_height: f64) -> Self {
        Self {
            half: [self.half[0], self.half[1], half_height],
            ..self.clone()
        }
    }
}

/// Height above the table of what a piece with footprint `b` stands on, m:
/// a goal box's floor ([`GOAL_WALL`]) when a goal's box holds its centre,
/// else the table (0).
pub(crate) fn support_under(s: &Scenario, b: PixelBox) -> f64 {
    match s.goals.iter().any(|g| g.bbox.contains(b.centre())) {
        true => GOAL_WALL,
        false => 0.0,
    }
}

/// The scenario's objects where the camera sees them, each on its support
/// ([`support_under`]).
pub(crate) fn pieces(s: &Scenario) -> Vec<Piece> {
    s.objects
        .iter()
        .map(|o| {
            let f = Footprint::of(s, o.bbox);
            Piece {
                name: o.name.clone(),
                pose: f.pose(s.camera.table_z + support_under(s, o.bbox), o.height),
                half: [0.5 * f.size[0], 0.5 * f.size[1], 0.5 * o.height],
                sensitive: s.is_sensitive(o),
                round: is_round(&o.shape),
            }
        })
        .collect()
}

/// What a body may hit, and what hitting it is called.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    /// Ordinary obstacle: penetration / margin.
    Obstacle,
    /// The target before the grasp: only the fingers may come near.
    Target,
    /// The piece just released, under the open gripper: the fingers may
    /// still straddle it as they rise; every other body must not touch it.
    Released,
}

/// One obstacle: its convex parts (parry pose and shape) and its margin.
#[derive(Clone)]
pub(crate) struct Obstacle {
    pub name: String,
    pub margin: f64,
    pub role: Role,
    pub parts: Vec<(parry3d::math::Pose, SharedShape)>,
}

impl Obstacle {
    pub(crate) fn solid(name: &str, margin: f64, pose: &Iso, half: [f64; 3]) -> Self {
        Self {
            name: name.to_string(),
            margin,
            role: Role::Obstacle,
            parts: vec![(to_parry(pose), solid_box(half))],
        }
    }

    pub(crate) fn piece(p: &Piece, margin: f64, role: Role) -> Self {
        Self {
            name: p.name.clone(),
            margin,
            role,
            parts: p
                .parts()
                .into_iter()
                .map(|(local, shape)| (to_parry(&(p.pose * local)), shape))
                .collect(),
        }
    }
}

/// The scene of one sub-goal moving `target` into goal `goal`, without the
/// target (the caller adds it with the role of the phase).
pub(crate) fn obstacles(
    s: &Scenario,
    pieces: &[Piece],
    target: usize,
    goal: usize,
) -> Vec<Obstacle> {
    let safety = &s.safety;
    let z0 = s.camera.table_z;
    let mut out = vec![table(s)];
    for (_, p) in pieces.iter().enumerate().filter(|&(i, _)| i != target) {
        let margin = match p.sensitive {
            true => safety.sensitive_margin,
            false => safety.obstacle_margin,
        };
        out.push(Obstacle::piece(p, margin, Role::Obstacle));
    }
    let at = pieces[target].pose.translation.vector;
    for (i, g) in s.goals.iter().enumerate() {
        let footprint = Footprint::of(s, g.bbox);
        let local = footprint.local([at.x, at.y]);
        let holds_target = (0..2).all(|k| local[k].abs() < 0.5 * footprint.size[k]);
        let margin = if i == goal || holds_target {
            0.0
        } else {
            safety.obstacle_margin
        };
        out.push(open_box(&g.name, margin, &footprint, z0, g.height));
    }
    for h in &s.hands {
        let f = Footprint::of(s, h.bbox);
        let half = [0.5 * f.size[0], 0.5 * f.size[1], 0.5 * h.height];
        out.push(Obstacle::solid(
            &h.name,
            safety.hand_margin,
            &f.pose(z0, h.height),
            half,
        ));
    }
    out
}

/// The hands as solid boxes (footprint and height), for the tool-speed rule.
pub(crate) fn hand_boxes(s: &Scenario) -> Vec<(String, Iso, [f64; 3])> {
    s.hands
        .iter()
        .map(|h| {
            let f = Footprint::of(s, h.bbox);
            let half = [0.5 * f.size[0], 0.5 * f.size[1], 0.5 * h.height];
            (h.name.clone(), f.pose(s.camera.table_z, h.height), half)
        })
        .collect()
}

/// The image's footprint on the table: the (x, y) box around its corners.
pub(crate) fn table_extent(s: &Scenario) -> ([f64; 2], [f64; 2]) {
    let (w, h) = (s.camera.width as f64, s.camera.height as f64);
    let corners = [[0.0, 0.0], [w, 0.0], [0.0, h], [w, h]].map(|p| s.pixel_to_base(p));
    let lo = [0, 1].map(|k| corners.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min));
    let hi = [0, 1].map(|k| {
        corners
            .iter()
            .map(|c| c[k])
            .fold(f64::NEG_INFINITY, f64::max)
    });
    (lo, hi)
}

/// The table slab under the image's footprint.
fn table(s: &Scenario) -> Obstacle {
    let (lo, hi) = table_extent(s);
    let z = s.camera.table_z - 0.5 * TABLE_THICKNESS;
    let pose = Iso::translation(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), z);
    let half = [
        0.5 * (hi[0] - lo[0]),
        0.5 * (hi[1] - lo[1]),
        0.5 * TABLE_THICKNESS,
    ];
    Obstacle::solid("table", 0.0, &pose, half)
}

/// An open box: floor and four walls inside the footprint.
fn open_box(name: &str, margin: f64, f: &Footprint, z0: f64, height: f64) -> Obstacle {
    let [sx, sy] = f.size;
    let w = 0.5 * GOAL_WALL;
    let pieces = [
        ([0.5 * sx, 0.5 * sy, w], [0.0, 0.0, w]),
        (
            [w, 0.5 * sy, 0.5 * height],
            [0.5 * sx - w, 0.0, 0.5 * height],
        ),
        (
            [w, 0.5 * sy, 0.5 * height],
            [-0.5 * sx + w, 0.0, 0.5 * height],
        ),
        (
            [(0.5 * sx - GOAL_WALL).max(w), w, 0.5 * height],
            [0.0, 0.5 * sy - w, 0.5 * height],
        ),
        (
            [(0.5 * sx - GOAL_WALL).max(w), w, 0.5 * height],
            [0.0, -0.5 * sy + w, 0.5 * height],
        ),
    ];
    let frame = f.pose(z0, 0.0);
    let parts = pieces
        .into_iter()
        .map(|(half, local)| {
            let pose = frame * Iso::translation(local[0], local[1], local[2]);
            (to_parry(&pose), solid_box(half))
        })
        .collect();
    Obstacle {
        name: name.to_string(),
        margin,
        role: Role::Obstacle,
        parts,
    }
}

/// Signed distance between two posed shapes: the gap when apart, minus the
/// penetration depth when they overlap.
pub(crate) fn signed_distance(
    p1: &parry3d::math::Pose,
    s1: &SharedShape,
    p2: &parry3d::math::Pose,
    s2: &SharedShape,
) -> f64 {
    let gap =
        parry3d::query::distance(p1, s1.as_ref(), p2, s2.as_ref()).map_or(0.0, |d| d.distance);
    if gap > 0.0 {
        return gap;
    }
    parry3d::query::contact(p1, s1.as_ref(), p2, s2.as_ref(), 0.0)
        .ok()
        .flatten()
        .map_or(0.0, |c| c.dist.min(0.0))
}

/// A box of half extents `half` as the convex hull of its eight corners:
/// the checker measures every box as a polyhedron (GJK), never with parry
/// 0.31's dedicated box-box distance, which overestimates the gap of boxes
/// turned about a common axis by up to tens of millimetres
/// (dimforge/parry#431). A flat box (no hull) stays a cuboid.
pub(crate) fn solid_box(half: [f64; 3]) -> SharedShape {
    let corners: Vec<parry3d::math::Vector> = (0..8)
        .map(|k| {
            let side = |bit: usize| if k >> bit & 1 == 1 { 1.0 } else { -1.0 };
            parry3d::math::Vector::new(side(0) * half[0], side(1) * half[1], side(2) * half[2])
        })
        .collect();
    SharedShape::convex_hull(&corners)
        .unwrap_or_else(|| SharedShape::cuboid(half[0], half[1], half[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two boxes turned about the vertical, 5.38 mm apart (GJK on their
    /// corners' hulls and on their support maps agree): parry 0.31's
    /// box-box distance says 69.6 mm.
    #[test]
    fn boxes_turned_about_the_vertical_are_measured_at_their_true_gap() {
        let a = solid_box([0.154_551, 0.070_896, 0.061_880]);
        let b = solid_box([0.038_715, 0.040_928, 0.171_407]);
        let pa = to_parry(&Iso::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -2.856_240),
        ));
        let pb = to_parry(&Iso::translation(0.174_181, -0.065_525, 0.238_664));
        let gap = signed_distance(&pa, &a, &pb, &b);
        assert!((gap - 0.005_377).abs() < 1e-5, "{gap}");
        let cuboids = parry3d::query::distance(
            &pa,
            &parry3d::shape::Cuboid::new(parry3d::math::Vector::new(
                0.154_551, 0.070_896, 0.061_880,
            )),
            &pb,
            &parry3d::shape::Cuboid::new(parry3d::math::Vector::new(
                0.038_715, 0.040_928, 0.171_407,
            )),
        )
        .unwrap()
        .distance;
        assert!(
            cuboids > gap + 0.05,
            "parry's box-box distance is right again: {cuboids}"
        );
    }

    #[test]
    fn signed_distance_is_negative_inside() {
        let a = SharedShape::cuboid(0.1, 0.1, 0.1);
        let here = to_parry(&Iso::identity());
        let apart = to_parry(&Iso::translation(0.25, 0.0, 0.0));
        let inside = to_parry(&Iso::translation(0.15, 0.0, 0.0));
        assert!((signed_distance(&here, &a, &apart, &a) - 0.05).abs() < 1e-9);
        assert!((signed_distance(&here, &a, &inside, &a) + 0.05).abs() < 1e-9);
    }
}
