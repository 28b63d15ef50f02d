//! The collision scene: what the robot must not touch, in metres, robot base
//! frame. Owns [`SceneSpec`] (the planner's input, in collision's own terms)
//! and [`Scene`] (parry shapes built from it).
//!
//! Geometry built from a spec:
//! - the table: a box [`TABLE_THICKNESS`] thick whose top face is at `table_z`;
//! - an object, a hand: a solid box standing on the table (bottom at
//!   `table_z`), footprint `size[0] x size[1]` rotated by `yaw`, height
//!   `size[2]`. A hand is modelled as its bounding box (it contains any
//!   capsule fitted to the hand, so it is the conservative choice);
//! - a round object (`round`: a circle, cylinder or disc seen from above):
//!   an upright stadium prism, [`round_parts`] — the disc of the footprint's
//!   narrower side swept along its longer one (a cylinder when the
//!   footprint is square). It lies inside the footprint and contains the
//!   ellipse inscribed in it, so it is the piece whatever its outline
//!   between a disc and that ellipse, without the box's empty corners;
//! - a goal: an OPEN box — a floor and four walls, each [`GOAL_WALL`] thick,
//!   inside the footprint; the top is open, so a held object can go in.
//!
//! Safety perimeters: every box carries a `margin` (the planner fills in
//! `obstacle_margin`, `sensitive_margin` or `hand_margin`). The perimeter is the
//! set of points within `margin` of the real shape (the shape grown by a ball
//! of radius `margin`, i.e. a rounded box). A robot body is inside the
//! perimeter exactly when its distance to the real shape is below `margin`, so
//! one exact distance query answers both "clearance to the real shape" and
//! "perimeter violated by how much".

use parry3d::bounding_volume::Aabb;
use parry3d::math::{Pose as PPose, Rotation as PRot, Vector as PVec};
use parry3d::shape::SharedShape;
use serde::{Deserialize, Serialize};

use crate::error::{CollisionError, scene_err};

/// Thickness of the table slab below `table_z`, metres.
pub const TABLE_THICKNESS: f64 = 0.02;
/// Thickness of a goal box's floor and walls, metres (inside its footprint).
pub const GOAL_WALL: f64 = 0.005;

/// What a box in the scene is; decides its geometry (goals are open).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BoxKind {
    /// A solid object standing on the table.
    Object,
    /// An open box: floor + four walls.
    Goal,
    /// A human hand (solid box; use the hand margin).
    Hand,
    /// An extra table-like slab (solid).
    Table,
}

/// One box of the scene, robot base frame, metres and radians.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneBox {
    pub name: String,
    pub kind: BoxKind,
    /// Footprint centre (x, y) on the table.
    pub centre: [f64; 2],
    /// Footprint size along its own x and y, and height above the table.
    pub size: [f64; 3],
    /// Rotation of the footprint about the vertical axis.
    #[serde(default)]
    pub yaw: f64,
    /// Safety perimeter around the box (0 = touch only).
    #[serde(default)]
    pub margin: f64,
    /// An object whose outline is round (see the module doc): a stadium
    /// prism inside the footprint instead of the box. Objects only.
    #[serde(default)]
    pub round: bool,
}

/// The table top rectangle (x, y) in the base frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    pub min: [f64; 2],
    pub max: [f64; 2],
    /// Perimeter around the table top (default 0).
    #[serde(default)]
    pub margin: f64,
}

/// The scene as the planner describes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Table surface height in the base frame.
    pub table_z: f64,
    /// The table slab; `None` = no table geometry (only the boxes).
    #[serde(default)]
    pub table: Option<TableSpec>,
    #[serde(default)]
    pub boxes: Vec<SceneBox>,
}

/// One convex piece of an obstacle, posed in the base frame.
#[derive(Debug, Clone)]
pub(crate) struct Part {
    /// Index of the obstacle in [`Scene::obstacles`].
    pub obstacle: usize,
    pub shape: SharedShape,
    pub pose: PPose,
    pub aabb: Aabb,
}

/// An obstacle: a named box (or open box) with its perimeter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Obstacle {
    pub name: String,
    pub kind: BoxKind,
    pub margin: f64,
}

/// The built scene: obstacles and their convex parts.
#[derive(Debug, Clone)]
pub struct Scene {
    pub(crate) obstacles: Vec<Obstacle>,
    pub(crate) parts: Vec<Part>,
}

impl Scene {
    /// Builds the scene from a spec; rejects non-finite or negative sizes.
    pub fn from_spec(spec: &SceneSpec) -> Result<Self, CollisionError> {
        finite("table_z", spec.table_z)?;
        let mut scene = Scene {
            obstacles: Vec::new(),
            parts: Vec::new(),
        };
        if let Some(t) = &spec.table {
            for (i, v) in t.min.iter().chain(&t.max).enumerate() {
                finite(&format!("table.{}", if i < 2 { "min" } else { "max" }), *v)?;
            }
            margin_ok("table.margin", t.margin)?;
            if t.max[0] <= t.min[0] || t.max[1] <= t.min[1] {
                return Err(scene_err("table", "max must exceed min in x and y"));
            }
            let obstacle = scene.push_obstacle("table", BoxKind::Table, t.margin);
            let half = [
                0.5 * (t.max[0] - t.min[0]),
                0.5 * (t.max[1] - t.min[1]),
                0.5 * TABLE_THICKNESS,
            ];
            let centre = [
                0.5 * (t.max[0] + t.min[0]),
                0.5 * (t.max[1] + t.min[1]),
                spec.table_z - 0.5 * TABLE_THICKNESS,
            ];
            scene.push_part(obstacle, half, centre, 0.0);
        }
        for (i, b) in spec.boxes.iter().enumerate() {
            let field = |f: &str| format!("boxes[{i}] ({}).{f}", b.name);
            for (k, v) in b.centre.iter().chain(&b.size).enumerate() {
                finite(&field(if k < 2 { "centre" } else { "size" }), *v)?;
            }
            if b.size.iter().any(|&s| s <= 0.0) {
                return Err(scene_err(field("size"), "sizes must be positive"));
            }
            finite(&field("yaw"), b.yaw)?;
            margin_ok(&field("margin"), b.margin)?;
            if b.round && b.kind != BoxKind::Object {
                return Err(scene_err(field("round"), "only an object may be round"));
            }
            if scene.obstacles.iter().any(|o| o.name == b.name) {
                return Err(scene_err(field("name"), "name is used twice"));
            }
            let obstacle = scene.push_obstacle(&b.name, b.kind, b.margin);
            let [sx, sy, sz] = b.size;
            let z0 = spec.table_z;
            if b.kind == BoxKind::Goal {
                if sx <= 2.0 * GOAL_WALL || sy <= 2.0 * GOAL_WALL || sz <= GOAL_WALL {
                    return Err(scene_err(
                        field("size"),
                        format!("a goal box must be larger than its {GOAL_WALL} m walls"),
                    ));
                }
                let w = 0.5 * GOAL_WALL;
                // Floor, then walls at +x, -x (full length) and +y, -y (between them).
                let pieces = [
                    ([0.5 * sx, 0.5 * sy, w], [0.0, 0.0, w]),
                    ([w, 0.5 * sy, 0.5 * sz], [0.5 * sx - w, 0.0, 0.5 * sz]),
                    ([w, 0.5 * sy, 0.5 * sz], [-0.5 * sx + w, 0.0, 0.5 * sz]),
                    (
                        [0.5 * sx - GOAL_WALL, w, 0.5 * sz],
                        [0.0, 0.5 * sy - w, 0.5 * sz],
                    ),
                    (
                        [0.5 * sx - GOAL_WALL, w, 0.5 * sz],
                        [0.0, -0.5 * sy + w, 0.5 * sz],
                    ),
                ];
                let (c, s) = (b.yaw.cos(), b.yaw.sin());
                for (half, local) in pieces {
                    let centre = [
                        b.centre[0] + c * local[0] - s * local[1],
                        b.centre[1] + s * local[0] + c * local[1],
                        z0 + local[2],
                    ];
                    scene.push_part(obstacle, half, centre, b.yaw);
                }
            } else {
                let half = [0.5 * sx, 0.5 * sy, 0.5 * sz];
                let pose = PPose::from_parts(
                    PVec::new(b.centre[0], b.centre[1], z0 + 0.5 * sz),
                    PRot::from_rotation_z(b.yaw),
                );
                let parts = match b.round {
                    true => round_parts(half),
                    false => vec![(
                        PPose::IDENTITY,
                        SharedShape::cuboid(half[0], half[1], half[2]),
                    )],
                };
                for (local, shape) in parts {
                    scene.push_shape(obstacle, shape, pose * local);
                }
            }
        }
        Ok(scene)
    }

    /// The obstacles, in spec order (the table first when present).
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Index of an obstacle by name.
    pub fn obstacle_index(&self, name: &str) -> Option<usize> {
        self.obstacles.iter().position(|o| o.name == name)
    }

    fn push_obstacle(&mut self, name: &str, kind: BoxKind, margin: f64) -> usize {
        self.obstacles.push(Obstacle {
            name: name.to_string(),
            kind,
            margin,
        });
        self.obstacles.len() - 1
    }

    fn push_part(&mut self, obstacle: usize, half: [f64; 3], centre: [f64; 3], yaw: f64) {
        let shape = SharedShape::cuboid(half[0], half[1], half[2]);
        let pose = PPose::from_parts(
            PVec::new(centre[0], centre[1], centre[2]),
            PRot::from_rotation_z(yaw),
        );
        self.push_shape(obstacle, shape, pose);
    }

    fn push_shape(&mut self, obstacle: usize, shape: SharedShape, pose: PPose) {
        let aabb = shape.compute_aabb(&pose);
        self.parts.push(Part {
            obstacle,
            shape,
            pose,
            aabb,
        });
    }
}

/// A round object of half sizes `half` (footprint x, y and height, m) as
/// convex parts posed in the object's frame (centre of its box, z up): the
/// stadium prism — an upright cylinder of radius `min(half x, half y)` at
/// each end of the longer axis and the box between them (one cylinder when
/// the footprint is square). Each part lies inside the box.
pub fn round_parts(half: [f64; 3]) -> Vec<(PPose, SharedShape)> {
    let radius = half[0].min(half[1]);
    let reach = [half[0] - radius, half[1] - radius];
    // parry's cylinder stands along its y axis: turned upright about x.
    let upright = PRot::from_rotation_x(std::f64::consts::FRAC_PI_2);
    let cylinder = |sign: f64| {
        let at = PVec::new(sign * reach[0], sign * reach[1], 0.0);
        (
            PPose::from_parts(at, upright),
            SharedShape::cylinder(half[2], radius),
        )
    };
    if reach[0].max(reach[1]) <= 0.0 {
        return vec![cylinder(0.0)];
    }
    // The box between the two cylinders' axes, as wide as they are.
    let core = match reach[0] > 0.0 {
        true => SharedShape::cuboid(reach[0], half[1], half[2]),
        false => SharedShape::cuboid(half[0], reach[1], half[2]),
    };
    vec![cylinder(-1.0), (PPose::IDENTITY, core), cylinder(1.0)]
}

/// The solid of an object of half sizes `half` (m) in its own frame: its
/// box, or its [`round_parts`] as one compound shape when `round`.
pub(crate) fn object_shape(half: [f64; 3], round: bool) -> SharedShape {
    match round {
        true => SharedShape::compound(round_parts(half)),
        false => SharedShape::cuboid(half[0], half[1], half[2]),
    }
}

fn finite(field: &str, v: f64) -> Result<(), CollisionError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(scene_err(field, "must be a finite number"))
    }
}

fn margin_ok(field: &str, v: f64) -> Result<(), CollisionError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(scene_err(field, "must be finite and >= 0"))
    }
}

/// Lower bound on the distance between two boxes' contents: the distance
/// between their AABBs (0 when they overlap).
#[inline]
pub(crate) fn aabb_distance(a: &Aabb, b: &Aabb) -> f64 {
    let d = (a.mins - b.maxs).max(b.mins - a.maxs).max(PVec::ZERO);
    d.length()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> SceneSpec {
        SceneSpec {
            table_z: 0.0,
            table: Some(TableSpec {
                min: [0.0, -0.5],
                max: [1.0, 0.5],
                margin: 0.0,
            }),
            boxes: vec![SceneBox {
                name: "goal".into(),
                kind: BoxKind::Goal,
                centre: [0.5, 0.0],
                size: [0.2, 0.1, 0.1],
                yaw: 0.3,
                margin: 0.0,
                round: false,
            }],
        }
    }

    #[test]
    fn goal_is_open_five_parts() {
        let s = Scene::from_spec(&spec()).unwrap();
        assert_eq!(s.obstacles.len(), 2);
        assert_eq!(s.parts.len(), 6);
        // The inside of the goal, above the floor, is free.
        let probe = SharedShape::ball(0.02);
        let pose = PPose::translation(0.5, 0.0, 0.05);
        for p in &s.parts[1..] {
            let d = parry3d::query::distance(&pose, probe.as_ref(), &p.pose, p.shape.as_ref())
                .unwrap()
                .distance;
            assert!(d > 0.0);
        }
    }

    #[test]
    fn bad_sizes_are_errors_naming_the_field() {
        let mut s = spec();
        s.boxes[0].size[1] = -1.0;
        let e = Scene::from_spec(&s).unwrap_err().to_string();
        assert!(e.contains("boxes[0] (goal).size"), "{e}");
        let mut s = spec();
        s.boxes[0].margin = f64::NAN;
        assert!(Scene::from_spec(&s).is_err());
    }

    /// The distance from `point` to obstacle `o`'s nearest part.
    fn distance_to(s: &Scene, o: usize, point: [f64; 3]) -> f64 {
        let probe = SharedShape::ball(1e-9);
        let at = PPose::translation(point[0], point[1], point[2]);
        s.parts
            .iter()
            .filter(|p| p.obstacle == o)
            .map(|p| {
                parry3d::query::distance(&at, probe.as_ref(), &p.pose, p.shape.as_ref())
                    .unwrap()
                    .distance
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn round_piece(size: [f64; 3], yaw: f64) -> Scene {
        Scene::from_spec(&SceneSpec {
            table_z: 0.1,
            table: None,
            boxes: vec![SceneBox {
                name: "red circle".into(),
                kind: BoxKind::Object,
                centre: [0.5, 0.2],
                size,
                yaw,
                margin: 0.02,
                round: true,
            }],
        })
        .unwrap()
    }

    #[test]
    fn round_piece_is_a_stadium_inside_its_box_around_its_ellipse() {
        for (size, yaw) in [([0.04, 0.04, 0.03], 0.0), ([0.04, 0.05, 0.03], 0.4)] {
            let s = round_piece(size, yaw);
            let (c, sn) = (yaw.cos(), yaw.sin());
            let at = |x: f64, y: f64, z: f64| [0.5 + c * x - sn * y, 0.2 + sn * x + c * y, z];
            let (a, b) = (0.5 * size[0], 0.5 * size[1]);
            for k in 0..64 {
                let t = k as f64 * std::f64::consts::TAU / 64.0;
                // On the inscribed ellipse at mid-height and at the top: inside.
                for z in [0.115, 0.1299] {
                    let d = distance_to(&s, 0, at(0.999 * a * t.cos(), 0.999 * b * t.sin(), z));
                    assert_eq!(d, 0.0, "{size:?} angle {t}");
                }
                // Just outside the box: outside.
                let (x, y) = (t.cos(), t.sin());
                let scale = 1.001 / (x.abs() / a).max(y.abs() / b);
                assert!(distance_to(&s, 0, at(scale * x, scale * y, 0.115)) > 0.0);
            }
            // The box's corner is empty: its distance to the disc end.
            let r = a.min(b);
            let corner = distance_to(&s, 0, at(0.999 * a, 0.999 * b, 0.115));
            let expected = (0.999 * a - (a - r)).hypot(0.999 * b - (b - r)) - r;
            assert!((corner - expected).abs() < 1e-8, "{corner} {expected}");
            assert!(corner > 0.005, "{corner}");
        }
    }

    #[test]
    fn round_held_object_measures_its_distance_to_a_round_piece() {
        // Two 0.04 x 0.05 stadiums side by side along x, 0.1 m apart: their
        // discs are 0.06 m apart; a box held there 0.06 m too.
        let held = object_shape([0.02, 0.025, 0.015], true);
        let boxed = object_shape([0.02, 0.025, 0.015], false);
        let s = round_piece([0.04, 0.05, 0.03], 0.0);
        let at = PPose::translation(0.6, 0.2, 0.115);
        for shape in [&held, &boxed] {
            let d = s
                .parts
                .iter()
                .map(|p| {
                    parry3d::query::distance(&at, shape.as_ref(), &p.pose, p.shape.as_ref())
                        .unwrap()
                        .distance
                })
                .fold(f64::INFINITY, f64::min);
            assert!((d - 0.06).abs() < 1e-9, "{d}");
        }
        // Diagonally, corner to corner, the round ones keep more room.
        let diagonal = PPose::translation(0.55, 0.26, 0.115);
        let gap = |shape: &SharedShape| {
            s.parts
                .iter()
                .map(|p| {
                    parry3d::query::distance(&diagonal, shape.as_ref(), &p.pose, p.shape.as_ref())
                        .unwrap()
                        .distance
                })
                .fold(f64::INFINITY, f64::min)
        };
        // Disc centres (0.5, 0.205) and (0.55, 0.255): 0.0707 - 0.04.
        let expected = 0.05f64.hypot(0.05) - 0.04;
        assert!((gap(&held) - expected).abs() < 1e-9, "{}", gap(&held));
        assert!(gap(&boxed) < gap(&held));
    }

    #[test]
    fn only_objects_may_be_round() {
        let mut s = spec();
        s.boxes[0].round = true;
        let e = Scene::from_spec(&s).unwrap_err().to_string();
        assert!(e.contains("boxes[0] (goal).round"), "{e}");
    }
}
