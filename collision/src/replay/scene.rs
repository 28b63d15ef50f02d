//! What the physical replay simulates besides the robot: the table, fixed
//! boxes (open goal boxes, hands, fixed obstacles) and the loose pieces, in
//! metres, kilograms and radians, robot base frame, gravity along −Z.
//!
//! Material model (documented in docs/decisions.md, Physical replay): pieces
//! are rigid, inelastic (restitution 0) and, unless the caller says
//! otherwise, wooden-toy density [`PIECE_DENSITY`] with friction
//! [`PIECE_FRICTION`] against everything (rapier averages the two
//! coefficients of a contact). The table, the goal boxes and the hands are
//! fixed bodies with [`SURFACE_FRICTION`].

use serde::{Deserialize, Serialize};

use crate::error::{CollisionError, scene_err};
use crate::scene::{BoxKind, SceneBox, TableSpec};

/// Density of a piece when the caller derives its mass from its volume,
/// kg/m³: pine or beech toy blocks (500–750), ABS plastic solids (~1,050 but
/// hollow). A 4 cm cube weighs 45 g.
pub const PIECE_DENSITY: f64 = 700.0;
/// Coulomb friction coefficient of a piece: wood on wood or on a laminate
/// table top, dry (0.3–0.6).
pub const PIECE_FRICTION: f64 = 0.5;
/// Friction of the table, the goal boxes, the hands and the robot links.
pub const SURFACE_FRICTION: f64 = 0.5;
/// Most pieces plus fixed boxes one scene may have.
pub const MAX_BODIES: usize = 1_024;
/// Lightest and heaviest piece accepted, kg.
pub const PIECE_MASS_RANGE: [f64; 2] = [1e-4, 100.0];

/// The shape of a loose piece, standing upright in its own frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PieceShape {
    /// A box of full sizes `size` (x, y, z), m.
    Box { size: [f64; 3] },
    /// An upright cylinder (axis along z), m.
    Cylinder { radius: f64, height: f64 },
    /// An upright stadium inside a footprint of full sizes `size[0]` (x)
    /// by `size[1]` (y), `size[2]` high, m: the disc of the narrower side's
    /// diameter swept along the longer side (a cylinder when the sides are
    /// equal) — how afford shapes a round piece seen as a pixel box.
    Stadium { size: [f64; 3] },
}

impl PieceShape {
    /// Height of the piece standing upright, m.
    pub fn height(&self) -> f64 {
        match *self {
            Self::Box { size } => size[2],
            Self::Cylinder { height, .. } => height,
            Self::Stadium { size } => size[2],
        }
    }

    /// Volume, m³.
    pub fn volume(&self) -> f64 {
        match *self {
            Self::Box { size } => size.iter().product(),
            Self::Cylinder { radius, height } => std::f64::consts::PI * radius * radius * height,
            Self::Stadium { size } => {
                let (r, straight) = stadium_parts(size);
                (std::f64::consts::PI * r * r + 2.0 * r * straight) * size[2]
            }
        }
    }

    fn sizes(&self) -> Vec<f64> {
        match *self {
            Self::Box { size } => size.to_vec(),
            Self::Cylinder { radius, height } => vec![radius, height],
            Self::Stadium { size } => size.to_vec(),
        }
    }
}

/// A stadium footprint's disc radius and the length of its straight part
/// (along the longer side), m.
pub(crate) fn stadium_parts(size: [f64; 3]) -> (f64, f64) {
    let r = 0.5 * size[0].min(size[1]);
    (r, (size[0].max(size[1]) - 2.0 * r).max(0.0))
}

/// One loose piece: a dynamic rigid body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicsPiece {
    /// The piece's name (what a [`crate::replay::Grasp`] names).
    pub name: String,
    pub shape: PieceShape,
    /// Centre of the piece, base frame, m.
    pub centre: [f64; 3],
    /// Rotation about the vertical axis, rad.
    #[serde(default)]
    pub yaw: f64,
    /// Mass, kg.
    pub mass: f64,
    /// Coulomb friction coefficient.
    pub friction: f64,
}

impl PhysicsPiece {
    /// A piece standing on a surface at height `z0` with the default
    /// density and friction.
    pub fn standing(name: &str, shape: PieceShape, xy: [f64; 2], yaw: f64, z0: f64) -> Self {
        Self {
            name: name.to_string(),
            shape,
            centre: [xy[0], xy[1], z0 + 0.5 * shape.height()],
            yaw,
            mass: PIECE_DENSITY * shape.volume(),
            friction: PIECE_FRICTION,
        }
    }
}

/// A box or piece of a replay's scene: named, and renamed when it is there
/// only for a while.
trait Body: Clone + PartialEq {
    fn name(&self) -> &str;
    fn renamed(&self, name: String) -> Self;
}

/// Both kinds of body keep their name in a `name` field.
macro_rules! named_body {
    ($($t:ty),*) => {$(
        impl Body for $t {
            fn name(&self) -> &str {
                &self.name
            }
            fn renamed(&self, name: String) -> Self {
                Self { name, ..self.clone() }
            }
        }
    )*};
}

named_body!(SceneBox, PhysicsPiece);

/// The bodies of one list (`list` picks it from a scene) over the scenes:
/// each once per stretch of scenes it stays the same in, its interval
/// added to `presence` unless it is there throughout
/// ([`PhysicsScene::over_time`]).
fn bodies_over_time<T: Body>(
    scenes: &[(f64, PhysicsScene)],
    list: impl Fn(&PhysicsScene) -> &[T],
    presence: &mut Vec<Presence>,
) -> Vec<T> {
    let moment = |i: usize| (i > 0 && i < scenes.len()).then(|| (0, scenes[i].0));
    let mut out = Vec::new();
    for (i, (_, scene)) in scenes.iter().enumerate() {
        for b in list(scene) {
            if i > 0 && list(&scenes[i - 1].1).contains(b) {
                continue;
            }
            let stays = scenes[i..].iter().take_while(|(_, s)| list(s).contains(b));
            let until = moment(i + stays.count());
            let name = match until {
                Some((_, t)) => format!("{} (until {t:.3} s)", b.name()),
                None => b.name().to_string(),
            };
            if i > 0 || until.is_some() {
                presence.push(Presence {
                    body: name.clone(),
                    from: moment(i),
                    until,
                });
            }
            out.push(b.renamed(name));
        }
    }
    out
}

/// The scene of a replay.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicsScene {
    /// Height of the table top, m.
    pub table_z: f64,
    /// The table top's rectangle (its `margin` is not used).
    pub table: TableSpec,
    /// Fixed boxes on the table: goals (open: floor and four walls, as
    /// [`crate::Scene`] builds them), hands and fixed obstacles (solid);
    /// margins are not used. A `table` kind is a solid fixed slab too.
    #[serde(default)]
    pub boxes: Vec<SceneBox>,
    /// Loose pieces.
    #[serde(default)]
    pub pieces: Vec<PhysicsPiece>,
    /// The whole robot's joint positions at the start (model order);
    /// `None`: the robot's home.
    #[serde(default)]
    pub robot_start: Option<Vec<f64>>,
    /// Boxes and pieces that are there only part of the time (a hand that
    /// comes and goes, a box a person moves: its two places are two
    /// bodies); every other body is there throughout.
    #[serde(default)]
    pub presence: Vec<Presence>,
}

/// A moment of a replay: motion index and time on that motion's clock, s.
pub type Moment = (usize, f64);

/// When one box or piece is in the world: from `from` (`None`: the start)
/// until `until` (`None`: the end), a half-open interval. Absent, it
/// neither collides nor moves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Presence {
    /// The box's or the piece's name.
    pub body: String,
    #[serde(default)]
    pub from: Option<Moment>,
    #[serde(default)]
    pub until: Option<Moment>,
}

impl Presence {
    /// True when the body is there at moment `at`.
    pub fn at(&self, at: Moment) -> bool {
        let before = |a: Moment, b: Moment| a.0 < b.0 || (a.0 == b.0 && a.1 < b.1);
        self.from.is_none_or(|f| !before(at, f)) && self.until.is_none_or(|u| before(at, u))
    }
}

impl PhysicsScene {
    /// One scene from the scenes of one motion over time (`(t, scene)`,
    /// `t` on motion 0's clock, increasing, the first at the start): the
    /// table and the robot start from the first; each box or piece present
    /// while it stays unchanged (same name, kind, place and size), in the
    /// order they first appear. A body there at the end keeps its name; an
    /// earlier one is named `NAME (until T s)`.
    pub fn over_time(scenes: &[(f64, PhysicsScene)]) -> Result<Self, CollisionError> {
        let Some((_, first)) = scenes.first() else {
            return Err(scene_err("scenes", "no scene"));
        };
        let mut presence = Vec::new();
        let boxes = bodies_over_time(scenes, |s| &s.boxes, &mut presence);
        let pieces = bodies_over_time(scenes, |s| &s.pieces, &mut presence);
        Ok(Self {
            boxes,
            pieces,
            presence,
            ..first.clone()
        })
    }

    /// Index of a piece by name.
    pub fn piece_index(&self, name: &str) -> Option<usize> {
        self.pieces.iter().position(|p| p.name == name)
    }

    /// Index of a goal box by name.
    pub fn goal_index(&self, name: &str) -> Option<usize> {
        self.boxes
            .iter()
            .position(|b| b.kind == BoxKind::Goal && b.name == name)
    }

    /// Checks what the fixed scene ([`crate::Scene::from_spec`]) does not:
    /// every piece's numbers and names.
    pub(crate) fn validate(&self) -> Result<(), CollisionError> {
        if self.pieces.len() + self.boxes.len() > MAX_BODIES {
            return Err(scene_err(
                "pieces",
                format!("more than {MAX_BODIES} pieces and boxes"),
            ));
        }
        for (i, p) in self.pieces.iter().enumerate() {
            let field = |f: &str| format!("pieces[{i}] ({}).{f}", p.name);
            if self.pieces[..i].iter().any(|q| q.name == p.name)
                || self.boxes.iter().any(|b| b.name == p.name)
            {
                return Err(scene_err(field("name"), "name is used twice"));
            }
            let sizes = p.shape.sizes();
            if sizes
                .iter()
                .any(|s| !(s.is_finite() && *s > 0.0 && *s <= 10.0))
            {
                return Err(scene_err(field("shape"), "sizes must be in (0, 10] m"));
            }
            if p.centre.iter().chain([&p.yaw]).any(|v| !v.is_finite()) {
                return Err(scene_err(field("centre"), "must be finite"));
            }
            let [lo, hi] = PIECE_MASS_RANGE;
            if !(p.mass >= lo && p.mass <= hi) {
                return Err(scene_err(
                    field("mass"),
                    format!("must be in [{lo}, {hi}] kg"),
                ));
            }
            if !(p.friction.is_finite() && (0.0..=2.0).contains(&p.friction)) {
                return Err(scene_err(field("friction"), "must be in [0, 2]"));
            }
        }
        for (i, p) in self.presence.iter().enumerate() {
            let field = |f: &str| format!("presence[{i}] ({}).{f}", p.body);
            let known = self.pieces.iter().any(|q| q.name == p.body)
                || self.boxes.iter().any(|b| b.name == p.body);
            if !known || self.presence[..i].iter().any(|q| q.body == p.body) {
                return Err(scene_err(field("body"), "must name a box or piece, once"));
            }
            if [p.from, p.until].iter().flatten().any(|m| !m.1.is_finite()) {
                return Err(scene_err(field("from"), "times must be finite"));
            }
        }
        Ok(())
    }
}
