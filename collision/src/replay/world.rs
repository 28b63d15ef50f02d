//! The rapier world of a replay: fixed bodies for the table and the boxes
//! (the convex parts [`Scene::from_spec`] builds), one dynamic body per
//! piece, and one position-based kinematic body per robot link carrying the
//! link's colliders from [`RobotGeometry`] (the same shapes the collision
//! checks use). Collision groups say who may push whom:
//!
//! | body | interacts with |
//! |---|---|
//! | robot link | fixed bodies, pieces, the target |
//! | finger collider | fixed bodies, pieces (not the target: it closes around it) |
//! | piece | everything |
//! | target of the current motion | fixed bodies, pieces, non-finger links |
//! | held piece | fixed bodies, pieces (it rides with the tool) |
//! | fixed body | everything but fixed bodies |
//!
//! Robot links and the held piece are kinematic, so rapier is told to
//! compute their contacts with fixed bodies too (`KINEMATIC_FIXED`): such
//! contacts push nothing, but they are what the report lists.

use afford_kinematics::Pose;
use rapier3d::prelude::{
    ActiveCollisionTypes, ColliderBuilder, ColliderHandle, Group, InteractionGroups,
    InteractionTestMode, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, RigidBodyType,
    SharedShape,
};

use crate::convert::to_parry;
use crate::error::CollisionError;
use crate::replay::report::BodyKind;
use crate::replay::scene::{PhysicsScene, PieceShape, SURFACE_FRICTION, stadium_parts};
use crate::robot::RobotGeometry;
use crate::scene::{BoxKind, Scene, SceneSpec};

/// Gravity, m/s², along −Z of the robot base frame.
pub const GRAVITY: f64 = 9.81;

const ROBOT: Group = Group::GROUP_1;
const FINGER: Group = Group::GROUP_2;
const TARGET: Group = Group::GROUP_3;
const PIECE: Group = Group::GROUP_4;
const FIXED: Group = Group::GROUP_5;
const HELD: Group = Group::GROUP_6;

fn groups(memberships: Group, filter: Group) -> InteractionGroups {
    InteractionGroups::new(memberships, filter, InteractionTestMode::And)
}

/// The role a piece plays in the current motion (its collision groups).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    Loose,
    Target,
    Held,
}

/// What a collider belongs to (its `user_data` indexes these).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Tag {
    /// Robot body index in [`RobotGeometry::body_names`].
    Robot(usize),
    Piece(usize),
    Fixed {
        name: String,
        kind: BodyKind,
    },
}

pub(crate) struct World {
    pub physics: PhysicsWorld,
    pub tags: Vec<Tag>,
    /// Kinematic body per robot link (`None`: the link has no collider).
    pub links: Vec<Option<RigidBodyHandle>>,
    pub pieces: Vec<RigidBodyHandle>,
    piece_colliders: Vec<ColliderHandle>,
    /// Each fixed collider with its box's name.
    fixed_colliders: Vec<(String, ColliderHandle)>,
}

/// What a presence switches on and off: a piece, or a fixed box's colliders.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Switched {
    Piece(usize),
    Fixed(Vec<ColliderHandle>),
}

impl World {
    /// Builds the world with the robot at `q` (whole-robot positions).
    pub(crate) fn new(
        scene: &PhysicsScene,
        robot: &RobotGeometry,
        q: &[f64],
        step: f64,
    ) -> Result<Self, CollisionError> {
        let mut physics = PhysicsWorld::new();
        physics.gravity = rapier3d::math::Vector::new(0.0, 0.0, -GRAVITY);
        physics.integration_parameters.dt = step;
        // Pieces are centimetres: a 0.1 m length unit makes the solver's
        // allowed overlap 0.1 mm instead of 1 mm.
        physics.integration_parameters.length_unit = 0.1;
        let mut world = Self {
            physics,
            tags: Vec::new(),
            links: vec![None; robot.model.links().len()],
            pieces: Vec::new(),
            piece_colliders: Vec::new(),
            fixed_colliders: Vec::new(),
        };
        world.add_fixed(scene)?;
        world.add_pieces(scene);
        world.add_robot(robot, q)?;
        Ok(world)
    }

    fn add_fixed(&mut self, scene: &PhysicsScene) -> Result<(), CollisionError> {
        let spec = SceneSpec {
            table_z: scene.table_z,
            table: Some(scene.table),
            boxes: scene.boxes.clone(),
        };
        let built = Scene::from_spec(&spec)?;
        let ground = self.physics.bodies.insert(RigidBodyBuilder::fixed());
        for part in &built.parts {
            let obstacle = &built.obstacles[part.obstacle];
            let kind = match obstacle.kind {
                BoxKind::Table => BodyKind::Table,
                BoxKind::Goal => BodyKind::Goal,
                BoxKind::Hand => BodyKind::Hand,
                BoxKind::Object => BodyKind::Obstacle,
            };
            let collider = ColliderBuilder::new(part.shape.clone())
                .position(part.pose)
                .friction(SURFACE_FRICTION)
                .collision_groups(groups(FIXED, Group::ALL.difference(FIXED)))
                .user_data(self.tags.len() as u128);
            self.tags.push(Tag::Fixed {
                name: obstacle.name.clone(),
                kind,
            });
            let b = &mut self.physics.bodies;
            let handle = self
                .physics
                .colliders
                .insert_with_parent(collider, ground, b);
            self.fixed_colliders.push((obstacle.name.clone(), handle));
        }
        Ok(())
    }

    /// What switches body `name` of `scene` (`None`: no such body).
    pub(crate) fn switched(&self, scene: &PhysicsScene, name: &str) -> Option<Switched> {
        if let Some(i) = scene.piece_index(name) {
            return Some(Switched::Piece(i));
        }
        let colliders: Vec<ColliderHandle> = (self.fixed_colliders.iter())
            .filter(|(n, _)| n == name)
            .map(|(_, c)| *c)
            .collect();
        (!colliders.is_empty()).then_some(Switched::Fixed(colliders))
    }

    /// Puts a body in the world or takes it out: absent, it neither
    /// collides nor moves.
    pub(crate) fn set_present(&mut self, body: &Switched, present: bool) {
        let colliders = match body {
            Switched::Piece(i) => {
                self.physics.bodies[self.pieces[*i]].set_enabled(present);
                std::slice::from_ref(&self.piece_colliders[*i])
            }
            Switched::Fixed(colliders) => colliders.as_slice(),
        };
        for c in colliders {
            self.physics.colliders[*c].set_enabled(present);
        }
    }

    fn add_pieces(&mut self, scene: &PhysicsScene) {
        for (i, p) in scene.pieces.iter().enumerate() {
            let pose = Pose::from_parts(
                nalgebra::Translation3::new(p.centre[0], p.centre[1], p.centre[2]),
                nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), p.yaw),
            );
            let body = RigidBodyBuilder::dynamic().pose(to_parry(&pose));
            let collider = piece_collider(p.shape)
                .mass(p.mass)
                .friction(p.friction)
                .restitution(0.0)
                .active_collision_types(ActiveCollisionTypes::all())
                .collision_groups(piece_groups(Role::Loose))
                .user_data(self.tags.len() as u128);
            self.tags.push(Tag::Piece(i));
            let handle = self.physics.bodies.insert(body);
            let b = &mut self.physics.bodies;
            let c = self
                .physics
                .colliders
                .insert_with_parent(collider, handle, b);
            self.pieces.push(handle);
            self.piece_colliders.push(c);
        }
    }

    fn add_robot(&mut self, robot: &RobotGeometry, q: &[f64]) -> Result<(), CollisionError> {
        let poses = robot.model.link_poses(q)?;
        let fingers = &robot.model.gripper().fingers;
        for (index, body) in robot.bodies.iter().enumerate() {
            let handle = match self.links[body.link] {
                Some(h) => h,
                None => {
                    let b = RigidBodyBuilder::kinematic_position_based()
                        .pose(to_parry(&poses[body.link]));
                    let h = self.physics.bodies.insert(b);
                    self.links[body.link] = Some(h);
                    h
                }
            };
            let group = match fingers.contains(&body.name) {
                true => groups(FINGER, FIXED | PIECE),
                false => groups(ROBOT, FIXED | PIECE | TARGET),
            };
            let collider = ColliderBuilder::new(body.shape.clone())
                .position(to_parry(&body.pose_link_shape))
                .friction(SURFACE_FRICTION)
                .active_collision_types(ActiveCollisionTypes::all())
                .collision_groups(group)
                .user_data(self.tags.len() as u128);
            self.tags.push(Tag::Robot(index));
            let b = &mut self.physics.bodies;
            self.physics
                .colliders
                .insert_with_parent(collider, handle, b);
        }
        Ok(())
    }

    /// Sets where every link goes during the next step.
    pub(crate) fn drive_links(&mut self, poses: &[Pose]) {
        for (link, handle) in self.links.iter().enumerate() {
            if let Some(h) = handle {
                self.physics.bodies[*h].set_next_kinematic_position(to_parry(&poses[link]));
            }
        }
    }

    /// Gives piece `i` a role: its collision groups and, held or not, its
    /// body type (a released piece starts at rest, as the arm does).
    pub(crate) fn set_role(&mut self, i: usize, role: Role) {
        let body = &mut self.physics.bodies[self.pieces[i]];
        let kind = match role {
            Role::Held => RigidBodyType::KinematicPositionBased,
            _ => RigidBodyType::Dynamic,
        };
        if body.body_type() != kind {
            body.set_body_type(kind, true);
            body.set_linvel(rapier3d::math::Vector::ZERO, true);
            body.set_angvel(rapier3d::math::Vector::ZERO, true);
        }
        self.physics.colliders[self.piece_colliders[i]].set_collision_groups(piece_groups(role));
    }

    /// Moves the held piece `i` to `pose` during the next step.
    pub(crate) fn drive_piece(&mut self, i: usize, pose: &Pose) {
        self.physics.bodies[self.pieces[i]].set_next_kinematic_position(to_parry(pose));
    }

    pub(crate) fn step(&mut self) {
        self.physics.step();
    }
}

fn piece_groups(role: Role) -> InteractionGroups {
    match role {
        Role::Loose => groups(PIECE, Group::ALL),
        Role::Target => groups(TARGET, FIXED | PIECE | TARGET | ROBOT),
        Role::Held => groups(HELD, FIXED | PIECE),
    }
}

/// A piece's collider in its own frame (upright along z).
fn piece_collider(shape: PieceShape) -> ColliderBuilder {
    match shape {
        PieceShape::Box { size } => {
            ColliderBuilder::cuboid(0.5 * size[0], 0.5 * size[1], 0.5 * size[2])
        }
        PieceShape::Cylinder { radius, height } => {
            ColliderBuilder::new(upright_cylinder(radius, height)).position(upright_at(0.0, 0.0))
        }
        PieceShape::Stadium { size } => ColliderBuilder::compound(stadium_shapes(size)),
    }
}

/// A cylinder's pose at `(x, y)` in the piece's frame: rapier's cylinders
/// run along local y, a piece's along z.
fn upright_at(x: f64, y: f64) -> rapier3d::math::Pose {
    rapier3d::math::Pose::from_parts(
        rapier3d::math::Vector::new(x, y, 0.0),
        rapier3d::math::Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2),
    )
}

fn upright_cylinder(radius: f64, height: f64) -> SharedShape {
    SharedShape::cylinder(0.5 * height, radius)
}

/// A stadium as a compound: a disc at each end of the straight part, the
/// box between them (one cylinder when there is no straight part).
fn stadium_shapes(size: [f64; 3]) -> Vec<(rapier3d::math::Pose, SharedShape)> {
    let (r, straight) = stadium_parts(size);
    let disc = upright_cylinder(r, size[2]);
    if straight <= 0.0 {
        return vec![(upright_at(0.0, 0.0), disc)];
    }
    let along_x = size[0] >= size[1];
    let end = |sign: f64| {
        let d = sign * 0.5 * straight;
        let pose = match along_x {
            true => upright_at(d, 0.0),
            false => upright_at(0.0, d),
        };
        (pose, disc.clone())
    };
    let half = match along_x {
        true => [0.5 * straight, r, 0.5 * size[2]],
        false => [r, 0.5 * straight, 0.5 * size[2]],
    };
    let core = SharedShape::cuboid(half[0], half[1], half[2]);
    vec![end(-1.0), end(1.0), (rapier3d::math::Pose::IDENTITY, core)]
}
