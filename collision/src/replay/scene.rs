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
}

impl PieceShape {
    /// Height of the piece standing upright, m.
    pub fn height(&self) -> f64 {
        match *self {
            Self::Box { size } => size[2],
            Self::Cylinder { height, .. } => height,
        }
    }

    /// Volume, m³.
    pub fn volume(&self) -> f64 {
        match *self {
            Self::Box { size } => size.iter().product(),
            Self::Cylinder { radius, height } => std::f64::consts::PI * radius * radius * height,
        }
    }

    fn sizes(&self) -> Vec<f64> {
        match *self {
            Self::Box { size } => size.to_vec(),
            Self::Cylinder { radius, height } => vec![radius, height],
        }
    }
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
}

impl PhysicsScene {
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
        Ok(())
    }
}
