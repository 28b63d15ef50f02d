//! Physical replay: a planned or executed trajectory re-played in rapier3d
//! (rigid-body dynamics, f64) to see what the motion does to the world —
//! the last verification, after the geometric checks.
//!
//! The model ([`PhysicsScene`], docs/decisions.md "Physical replay"): the
//! table and the boxes are fixed bodies, the pieces dynamic boxes or
//! cylinders with mass and friction under gravity (−Z), the robot's links
//! position-based kinematic bodies that follow the joint trajectory (the
//! collider shapes of [`RobotGeometry`], posed by forward kinematics at every
//! step, as rapier's kinematic bodies are driven with
//! `set_next_kinematic_position`). The grasped piece rides with the tool from
//! the close to the open (kinematic, its pose relative to the tool frozen at
//! the close), then falls as a dynamic body and settles.
//!
//! Stepping: a fixed step ([`STEP`], 2 ms; the joints interpolated linearly
//! between trajectory samples), motions one after another, then
//! [`SETTLE_TIME`] with the robot at rest. Same input, same machine ⇒ the
//! same report, bit for bit (rapier is deterministic for a fixed sequence
//! of operations; nothing here depends on time, threads or hash order).
//!
//! Verdicts ([`ReplayReport`]): each grasped piece rests wholly inside its
//! goal's inner walls ([`INSIDE_TOLERANCE`]); no other piece moved more
//! than [`MOVED_LIMIT`]; no robot link came within [`TOUCH_DISTANCE`] of the
//! table, a box, a hand or a piece it does not hold (the fingers may close
//! around the motion's own target), the held piece no hand and no fixed
//! body deeper than [`HELD_OVERLAP`].

mod motion;
mod report;
mod scene;
mod world;

use std::collections::HashMap;

use afford_kinematics::{Pose, RobotModel};
use serde::{Deserialize, Serialize};

use crate::convert::{from_parry, to_parry};
use crate::error::{CollisionError, path_err};
use crate::robot::RobotGeometry;
use crate::scene::GOAL_WALL;

pub use motion::{Grasp, MAX_MOTION_DURATION, MAX_MOTION_SAMPLES, MAX_MOTIONS, ReplayMotion};
pub use report::{
    BodyKind, INSIDE_TOLERANCE, LinkContact, MOVED_LIMIT, PieceMotion, REST_SPEED, ReplayReport,
    TargetOutcome,
};
pub use scene::{
    MAX_BODIES, Moment, PIECE_DENSITY, PIECE_FRICTION, PIECE_MASS_RANGE, PhysicsPiece,
    PhysicsScene, PieceShape, Presence, SURFACE_FRICTION,
};
pub use world::GRAVITY;

use motion::Checked;
use world::{Role, Switched, Tag, World};

/// Physics step, s: 2 ms keeps a link at 1 m/s within 2 mm per step, well
/// under the smallest piece (5 mm), and a sub-goal of 10 s at 5,000 steps.
pub const STEP: f64 = 0.002;
/// Time simulated after the last motion, robot at rest, s: a piece dropped
/// from 10 cm lands in 0.14 s; the rest lets it stop sliding or tipping.
pub const SETTLE_TIME: f64 = 1.0;
/// A robot body this close to another body touches it, m (rapier's contact
/// solver holds a pushed piece at about zero distance, not below it).
pub const TOUCH_DISTANCE: f64 = 1e-4;

/// The held piece inside the table, a goal box or an obstacle by more than
/// this is a contact, m (it rests on the table when grasped and may be set
/// down on a floor; a hand is a contact at [`TOUCH_DISTANCE`]).
pub const HELD_OVERLAP: f64 = 0.001;

/// The distance below which the held piece touches a fixed body of `kind`.
fn held_limit(kind: BodyKind) -> f64 {
    match kind {
        BodyKind::Hand => TOUCH_DISTANCE,
        _ => -HELD_OVERLAP,
    }
}

/// How a replay steps.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReplaySettings {
    /// Physics step, s, in [0.1 ms, 10 ms].
    pub step: f64,
    /// Settling time after the last motion, s, in [0, 10].
    pub settle: f64,
}

impl Default for ReplaySettings {
    fn default() -> Self {
        Self {
            step: STEP,
            settle: SETTLE_TIME,
        }
    }
}

impl ReplaySettings {
    fn validate(&self) -> Result<(), CollisionError> {
        if !(1e-4..=1e-2).contains(&self.step) {
            return Err(path_err("settings.step", "must be in [0.0001, 0.01] s"));
        }
        if !(0.0..=10.0).contains(&self.settle) {
            return Err(path_err("settings.settle", "must be in [0, 10] s"));
        }
        Ok(())
    }
}

/// Replays `motions` (in order) in `scene` with the default settings.
/// Never panics on bad input: the report's `input_error` says what is wrong.
pub fn replay(scene: &PhysicsScene, robot: &RobotModel, motions: &[ReplayMotion]) -> ReplayReport {
    replay_with(scene, robot, motions, &ReplaySettings::default())
}

/// [`replay`] with explicit settings.
pub fn replay_with(
    scene: &PhysicsScene,
    robot: &RobotModel,
    motions: &[ReplayMotion],
    settings: &ReplaySettings,
) -> ReplayReport {
    match Replay::new(scene, robot, motions, settings) {
        Ok(mut r) => r.run(),
        Err(e) => ReplayReport::invalid(settings.step, &e),
    }
}

/// The state of one replay.
struct Replay<'a> {
    scene: &'a PhysicsScene,
    geometry: RobotGeometry,
    motions: Vec<Checked<'a>>,
    settings: ReplaySettings,
    world: World,
    /// Whole-robot joint positions now.
    q: Vec<f64>,
    /// Each piece's first pose and its largest distance from it so far.
    first: Vec<Pose>,
    farthest: Vec<f64>,
    contacts: Vec<LinkContact>,
    /// Index into `contacts` per (motion, robot body or held piece, collider tag).
    seen: HashMap<(usize, String, usize), usize>,
    steps: usize,
    /// Each body that is there only part of the time, its interval and
    /// whether it is there now.
    presence: Vec<(Switched, Presence, bool)>,
}

/// Where the grasp of the current motion stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Grip {
    Open,
    /// Holding piece `i` at `rel` in the tool frame.
    Holding(usize, Pose),
    Released,
}

impl<'a> Replay<'a> {
    fn new(
        scene: &'a PhysicsScene,
        robot: &RobotModel,
        motions: &'a [ReplayMotion],
        settings: &ReplaySettings,
    ) -> Result<Self, CollisionError> {
        settings.validate()?;
        scene.validate()?;
        if motions.len() > MAX_MOTIONS {
            return Err(path_err(
                "motions",
                format!(
                    "{} motions, more than the {MAX_MOTIONS} accepted",
                    motions.len()
                ),
            ));
        }
        let geometry = RobotGeometry::new(robot)?;
        let q = match &scene.robot_start {
            Some(q) => {
                geometry.check_config(q, "robot_start")?;
                q.clone()
            }
            None => robot.home().to_vec(),
        };
        let motions = motions
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let c = m.check(robot, k)?;
                if let Some(g) = &m.grasp {
                    scene.piece_index(&g.piece).ok_or_else(|| {
                        path_err(
                            format!("motions[{k}].grasp.piece"),
                            format!("no piece '{}'", g.piece),
                        )
                    })?;
                    if let Some(goal) = &g.goal {
                        scene.goal_index(goal).ok_or_else(|| {
                            path_err(
                                format!("motions[{k}].grasp.goal"),
                                format!("no goal box '{goal}'"),
                            )
                        })?;
                    }
                }
                Ok(c)
            })
            .collect::<Result<Vec<_>, CollisionError>>()?;
        let world = World::new(scene, &geometry, &q, settings.step)?;
        let presence = scene
            .presence
            .iter()
            .map(|p| {
                let body = world
                    .switched(scene, &p.body)
                    .ok_or_else(|| path_err("presence", format!("no box or piece '{}'", p.body)))?;
                Ok((body, p.clone(), true))
            })
            .collect::<Result<Vec<_>, CollisionError>>()?;
        let first: Vec<Pose> = world
            .pieces
            .iter()
            .map(|&h| from_parry(world.physics.bodies[h].position()))
            .collect();
        Ok(Self {
            scene,
            farthest: vec![0.0; first.len()],
            first,
            geometry,
            motions,
            settings: *settings,
            world,
            q,
            contacts: Vec::new(),
            seen: HashMap::new(),
            steps: 0,
            presence,
        })
    }

    fn run(&mut self) -> ReplayReport {
        match self.simulate() {
            Ok(()) => self.report(),
            Err(e) => ReplayReport::invalid(self.settings.step, &e),
        }
    }

    fn simulate(&mut self) -> Result<(), CollisionError> {
        for k in 0..self.motions.len() {
            self.motion(k)?;
        }
        let poses = self.geometry.model.link_poses(&self.q)?;
        let (k, end) = match self.motions.last() {
            Some(m) => (self.motions.len() - 1, m.end()),
            None => (0, 0.0),
        };
        let n = (self.settings.settle / self.settings.step).ceil() as usize;
        for i in 1..=n {
            self.world.drive_links(&poses);
            self.step(k, end + i as f64 * self.settings.step, None);
        }
        Ok(())
    }

    /// Plays motion `k`.
    fn motion(&mut self, k: usize) -> Result<(), CollisionError> {
        let m = self.motions[k].clone();
        let grasp = m.motion.grasp.as_ref();
        let target = grasp.and_then(|g| self.scene.piece_index(&g.piece));
        for i in 0..self.world.pieces.len() {
            let role = match Some(i) == target {
                true => Role::Target,
                false => Role::Loose,
            };
            self.world.set_role(i, role);
        }
        let (start, end, dt) = (m.start(), m.end(), self.settings.step);
        let n = ((end - start) / dt).ceil() as usize;
        let mut grip = Grip::Open;
        let mut t_prev = start;
        let mut tool = self.geometry.model.link_poses(&self.q)?[m.tool_link];
        for i in 1..=n.max(1) {
            if let (Some(g), Some(p)) = (grasp, target) {
                grip = self.regrip(grip, g, p, t_prev, &tool);
            }
            let t = (start + i as f64 * dt).min(end);
            m.write_at(t, &mut self.q);
            let poses = self.geometry.model.link_poses(&self.q)?;
            tool = poses[m.tool_link];
            self.world.drive_links(&poses);
            let held = match grip {
                Grip::Holding(p, rel) => {
                    self.world.drive_piece(p, &(tool * rel));
                    Some(p)
                }
                _ => None,
            };
            self.step(k, t, held);
            t_prev = t;
        }
        if let Grip::Holding(p, _) = grip {
            self.world.set_role(p, Role::Target);
        }
        Ok(())
    }

    /// The grip at time `t`: closes on piece `p` at `t_close` (its pose in
    /// the tool frame frozen there), lets go at `t_open`.
    fn regrip(&mut self, grip: Grip, g: &Grasp, p: usize, t: f64, tool: &Pose) -> Grip {
        match grip {
            Grip::Open if t >= g.t_close => {
                let piece = from_parry(self.world.physics.bodies[self.world.pieces[p]].position());
                self.world.set_role(p, Role::Held);
                let grip = Grip::Holding(p, tool.inverse() * piece);
                self.regrip(grip, g, p, t, tool)
            }
            Grip::Holding(..) if t >= g.t_open => {
                self.world.set_role(p, Role::Target);
                Grip::Released
            }
            other => other,
        }
    }

    /// One physics step ending at time `t` of motion `k`; then the bookkeeping.
    fn step(&mut self, k: usize, t: f64, held: Option<usize>) {
        for (body, presence, there) in &mut self.presence {
            let now = presence.at((k, t));
            if now != *there {
                self.world.set_present(body, now);
                *there = now;
            }
        }
        self.world.step();
        self.steps += 1;
        for (i, &h) in self.world.pieces.iter().enumerate() {
            let p = self.world.physics.bodies[h].translation();
            let d = self.first[i].translation.vector;
            let moved = ((p.x - d.x).powi(2) + (p.y - d.y).powi(2) + (p.z - d.z).powi(2)).sqrt();
            self.farthest[i] = self.farthest[i].max(moved);
        }
        self.record_contacts(k, t, held);
    }

    /// Adds the touching pairs of this step to the contact list.
    fn record_contacts(&mut self, k: usize, t: f64, held: Option<usize>) {
        let w = &self.world;
        let mut found = Vec::new();
        for pair in w.physics.narrow_phase.contact_pairs() {
            let tag =
                |h: rapier3d::prelude::ColliderHandle| w.physics.colliders[h].user_data as usize;
            let (a, b) = (tag(pair.collider1), tag(pair.collider2));
            let held_name = |p: usize| format!("held {}", self.scene.pieces[p].name);
            let (robot, other, limit) = match (&w.tags[a], &w.tags[b]) {
                (Tag::Robot(r), _) => (self.geometry.bodies[*r].name.clone(), b, TOUCH_DISTANCE),
                (_, Tag::Robot(r)) => (self.geometry.bodies[*r].name.clone(), a, TOUCH_DISTANCE),
                (Tag::Piece(p), Tag::Fixed { kind, .. }) if Some(*p) == held => {
                    (held_name(*p), b, held_limit(*kind))
                }
                (Tag::Fixed { kind, .. }, Tag::Piece(p)) if Some(*p) == held => {
                    (held_name(*p), a, held_limit(*kind))
                }
                _ => continue,
            };
            let Some((_, contact)) = pair.find_deepest_contact() else {
                continue;
            };
            if contact.dist < limit {
                found.push((robot, other, (-contact.dist).max(0.0)));
            }
        }
        for (link, other, depth) in found {
            let (body, kind) = match &self.world.tags[other] {
                Tag::Fixed { name, kind } => (name.clone(), *kind),
                Tag::Piece(p) => (self.scene.pieces[*p].name.clone(), BodyKind::Piece),
                Tag::Robot(_) => continue,
            };
            let key = (k, link.clone(), other);
            match self.seen.get(&key) {
                Some(&i) => {
                    let c = &mut self.contacts[i];
                    c.last = t;
                    c.depth = c.depth.max(depth);
                }
                None => {
                    self.seen.insert(key, self.contacts.len());
                    self.contacts.push(LinkContact {
                        link,
                        body,
                        kind,
                        motion: k,
                        first: t,
                        last: t,
                        depth,
                    });
                }
            }
        }
    }

    fn report(&mut self) -> ReplayReport {
        let mut targets: Vec<TargetOutcome> = Vec::new();
        for (k, m) in self.motions.iter().enumerate() {
            let Some(g) = &m.motion.grasp else { continue };
            targets.retain(|t| t.piece != g.piece);
            targets.push(self.outcome(k, g));
        }
        let pieces = (0..self.scene.pieces.len())
            .filter(|&i| !targets.iter().any(|t| t.piece == self.scene.pieces[i].name))
            .map(|i| self.piece_motion(i))
            .collect();
        let mut contacts = std::mem::take(&mut self.contacts);
        contacts.sort_by(|a, b| {
            (a.motion, a.first)
                .partial_cmp(&(b.motion, b.first))
                .unwrap_or(std::cmp::Ordering::Equal)
                .then_with(|| (&a.link, &a.body).cmp(&(&b.link, &b.body)))
        });
        ReplayReport {
            step: self.settings.step,
            steps: self.steps,
            targets,
            pieces,
            contacts,
            input_error: None,
        }
    }

    /// Where the piece grasped in motion `k` came to rest.
    fn outcome(&self, k: usize, g: &Grasp) -> TargetOutcome {
        let i = self.scene.piece_index(&g.piece).unwrap_or(0);
        let body = &self.world.physics.bodies[self.world.pieces[i]];
        let (p, r) = (body.translation(), *body.rotation());
        let beyond = g
            .goal
            .as_deref()
            .and_then(|name| self.scene.goal_index(name))
            .map(|gi| self.beyond_inner_walls(i, gi));
        let speed = body.linvel().length();
        TargetOutcome {
            piece: g.piece.clone(),
            goal: g.goal.clone(),
            motion: k,
            centre: [p.x, p.y, p.z],
            rotation: [r.x, r.y, r.z, r.w],
            speed,
            beyond_inner_walls: beyond,
            in_goal: speed <= REST_SPEED && beyond.is_none_or(|b| b <= INSIDE_TOLERANCE),
        }
    }

    /// How far piece `i`'s bounding box in goal box `gi`'s frame reaches past
    /// the inner walls (negative: room left to the nearest wall), m.
    fn beyond_inner_walls(&self, i: usize, gi: usize) -> f64 {
        let g = &self.scene.boxes[gi];
        let frame = Pose::from_parts(
            nalgebra::Translation3::new(g.centre[0], g.centre[1], self.scene.table_z),
            nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), g.yaw),
        );
        let body = &self.world.physics.bodies[self.world.pieces[i]];
        let collider = &self.world.physics.colliders[body.colliders()[0]];
        let local = to_parry(&frame).inv_mul(collider.position());
        let aabb = collider.shape().compute_aabb(&local);
        let inner = [0.5 * g.size[0] - GOAL_WALL, 0.5 * g.size[1] - GOAL_WALL];
        [
            aabb.maxs.x - inner[0],
            -inner[0] - aabb.mins.x,
            aabb.maxs.y - inner[1],
            -inner[1] - aabb.mins.y,
        ]
        .into_iter()
        .fold(f64::NEG_INFINITY, f64::max)
    }

    fn piece_motion(&self, i: usize) -> PieceMotion {
        let now = from_parry(self.world.physics.bodies[self.world.pieces[i]].position());
        let first = &self.first[i];
        PieceMotion {
            piece: self.scene.pieces[i].name.clone(),
            displacement: (now.translation.vector - first.translation.vector).norm(),
            max_displacement: self.farthest[i],
            rotation: now.rotation.angle_to(&first.rotation),
            moved: self.farthest[i] > MOVED_LIMIT,
        }
    }
}
