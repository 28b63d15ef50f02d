//! What a replay found: where each grasped piece came to rest and whether
//! it lies wholly inside its goal box, how far every other piece moved, and
//! every contact of a robot link with something it must not touch.

use serde::Serialize;

/// A piece other than the targets moved farther than this, m: flagged.
pub const MOVED_LIMIT: f64 = 0.005;
/// How far a resting target may reach past an inner wall of its goal (or
/// below the floor's top) and still count as inside, m: the contact solver
/// lets resting bodies overlap by up to its allowed error (0.1 mm with
/// afford's length unit) and a piece may lean on a wall.
pub const INSIDE_TOLERANCE: f64 = 0.001;
/// A target faster than this at the end has not come to rest, m/s.
pub const REST_SPEED: f64 = 0.01;

/// What a robot link touched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyKind {
    Table,
    Goal,
    Hand,
    /// A fixed obstacle box of the scene.
    Obstacle,
    /// A loose piece the link does not hold.
    Piece,
}

/// Where one grasped piece ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetOutcome {
    pub piece: String,
    /// The goal box it had to end in.
    pub goal: Option<String>,
    /// Index of the motion that carried it (the last one, if several).
    pub motion: usize,
    /// Final centre, base frame, m, and final rotation quaternion (x, y, z, w).
    pub centre: [f64; 3],
    pub rotation: [f64; 4],
    /// Its speed at the end, m/s (≈ 0: at rest).
    pub speed: f64,
    /// How far it reaches past the goal's inner walls (> 0) or how much room
    /// is left to the nearest inner wall (< 0), m, on its bounding box in the
    /// goal's frame; `None` without a goal.
    pub beyond_inner_walls: Option<f64>,
    /// Rests (speed at most [`REST_SPEED`]) wholly inside its goal box
    /// (without a goal: rests).
    pub in_goal: bool,
}

/// How far a piece nobody grasped moved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PieceMotion {
    pub piece: String,
    /// Distance between its first and final centre, m.
    pub displacement: f64,
    /// Largest distance from its first centre at any step, m.
    pub max_displacement: f64,
    /// Angle between its first and final orientation, rad.
    pub rotation: f64,
    /// `max_displacement` > [`MOVED_LIMIT`].
    pub moved: bool,
}

/// A robot link (or the held piece) touching a body it must not touch:
/// one entry per link, body and motion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinkContact {
    /// Robot body name (`link`, `link#k` with several colliders), or
    /// `held <piece>` for the held piece (touching a hand, or more than
    /// `HELD_OVERLAP` inside a fixed body).
    pub link: String,
    pub body: String,
    pub kind: BodyKind,
    pub motion: usize,
    /// First and last time of contact, s, the motion's own clock.
    pub first: f64,
    pub last: f64,
    /// Deepest penetration seen, m.
    pub depth: f64,
}

/// Everything one replay found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplayReport {
    /// Physics step, s, and steps simulated (motions + the final settling).
    pub step: f64,
    pub steps: usize,
    pub targets: Vec<TargetOutcome>,
    /// Every piece no motion grasped, in scene order.
    pub pieces: Vec<PieceMotion>,
    /// Contacts, ordered by motion, then time.
    pub contacts: Vec<LinkContact>,
    /// Why the replay could not run (bad scene or motions); the other lists
    /// are then empty.
    pub input_error: Option<String>,
}

impl ReplayReport {
    pub(crate) fn invalid(step: f64, error: &crate::CollisionError) -> Self {
        Self {
            step,
            steps: 0,
            targets: Vec::new(),
            pieces: Vec::new(),
            contacts: Vec::new(),
            input_error: Some(error.to_string()),
        }
    }

    /// True when every target rests in its goal, no other piece moved more
    /// than [`MOVED_LIMIT`], no link touched anything and the input was read.
    pub fn passed(&self) -> bool {
        self.failures().is_empty()
    }

    /// One sentence per problem, with the motion it happened in (`None`:
    /// the replay as a whole).
    pub fn failures(&self) -> Vec<(Option<usize>, String)> {
        let mut out = Vec::new();
        if let Some(e) = &self.input_error {
            out.push((None, format!("cannot replay: {e}")));
        }
        for t in self.targets.iter().filter(|t| !t.in_goal) {
            let [x, y, z] = t.centre;
            if t.speed > REST_SPEED {
                out.push((
                    Some(t.motion),
                    format!(
                        "{} still moves at {:.3} m/s at the end, at ({x:.4}, {y:.4}, {z:.4}) m",
                        t.piece, t.speed
                    ),
                ));
                continue;
            }
            out.push((
                Some(t.motion),
                format!(
                    "{} comes to rest at ({x:.4}, {y:.4}, {z:.4}) m, {:.1} mm beyond the inner walls of the {}",
                    t.piece,
                    t.beyond_inner_walls.unwrap_or(0.0) * 1e3,
                    t.goal.as_deref().unwrap_or("goal")
                ),
            ));
        }
        for p in self.pieces.iter().filter(|p| p.moved) {
            out.push((
                None,
                format!(
                    "{} moved {:.1} mm (ends {:.1} mm from where it was, turned {:.1} deg; limit {:.0} mm)",
                    p.piece,
                    p.max_displacement * 1e3,
                    p.displacement * 1e3,
                    p.rotation.to_degrees(),
                    MOVED_LIMIT * 1e3
                ),
            ));
        }
        for c in &self.contacts {
            let what = match c.kind {
                BodyKind::Table => "the table".to_string(),
                kind => format!("the {} {}", kind_name(kind), c.body),
            };
            out.push((
                Some(c.motion),
                format!(
                    "{} touches {what} from t = {:.3} s to {:.3} s ({:.1} mm deep)",
                    c.link,
                    c.first,
                    c.last,
                    c.depth * 1e3
                ),
            ));
        }
        out
    }
}

fn kind_name(kind: BodyKind) -> &'static str {
    match kind {
        BodyKind::Table => "table",
        BodyKind::Goal => "goal",
        BodyKind::Hand => "hand",
        BodyKind::Obstacle => "obstacle",
        BodyKind::Piece => "piece",
    }
}
