//! What a collision check is given and what it reports: the settings
//! ([`CheckSettings`], [`PathOptions`]), one hit ([`Collision`], of a
//! [`HitKind`]), the work done ([`CheckStats`]) and a path's verdict
//! ([`PathVerdict`]). Shared by the checks and the sweep engine under them.

use serde::{Deserialize, Serialize};

use crate::error::{CollisionError, path_err};
use crate::robot::Attachment;

/// A collider's bounding box in the tool frame, `[mins, maxs]` (x, y, z), m.
pub type ToolBounds = [[f64; 3]; 2];

/// Settings of a check; defaults written once here.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CheckSettings {
    /// A pair whose distance minus margin is at most this is a hit (m).
    /// Smaller = fewer false alarms near grazing contacts, more steps.
    pub tolerance: f64,
    /// Stop after this many reported hits (the earliest first).
    pub max_reports: usize,
    /// Check robot links against each other (joint paths only).
    pub self_collision: bool,
    /// Scan each hit forward for its deepest point (the report's
    /// `worst_t`, `clearance`, `penetration`, up to 300 pair queries a
    /// hit). `false`: a hit is reported where it was first seen, which is
    /// all a yes-or-no test (a transit edge, a screen) needs.
    pub describe: bool,
}

impl Default for CheckSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-4,
            max_reports: 1,
            self_collision: true,
            describe: true,
        }
    }
}

impl CheckSettings {
    pub fn validate(&self) -> Result<(), CollisionError> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(path_err("settings.tolerance", "must be finite and > 0"));
        }
        Ok(())
    }
}

/// What a check carries besides the path.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PathOptions {
    /// Arm holding the attachment / whose tool the tool path moves (default:
    /// the first arm).
    pub arm: Option<String>,
    /// Object held by that arm's gripper; the scene obstacle of the same name
    /// is ignored while it is held.
    pub attached: Option<Attachment>,
    /// Obstacles to ignore for every body (e.g. the target once it has been
    /// put down elsewhere).
    pub ignore: Vec<String>,
    /// Pairs `(robot body, obstacle)` left out of the check, every other pair
    /// of that body or obstacle is still checked: e.g. the fingers against the
    /// target they close on, while the palm and the links keep its margin.
    /// Bodies are named like [`Collision::body`]; an unknown body is an error.
    pub exempt: Vec<(String, String)>,
    pub settings: CheckSettings,
}

/// What kind of hit a report is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HitKind {
    /// The real shapes touch or overlap.
    Contact,
    /// Only the safety perimeter (margin) is entered.
    Perimeter,
    /// Two robot bodies (or the held object and a link) touch.
    SelfCollision,
}

/// One hit: what hit what, where along the path and by how much.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Collision {
    /// Robot body: link name (`link#k` for a link's k-th collider) or `held:<name>`.
    pub body: String,
    /// Obstacle name, or the other robot body.
    pub other: String,
    pub kind: HitKind,
    /// Path parameter where the pair first came within tolerance of its
    /// margin (waypoint `k` is `t = k`; segment `k` is `[k, k+1]`).
    pub first_t: f64,
    /// Segment of `first_t`.
    pub segment: usize,
    /// Waypoint nearest to `first_t`.
    pub waypoint: usize,
    /// Path parameter of the deepest point of this contact (scanned forward).
    pub worst_t: f64,
    /// Distance to the real shape at `worst_t` (0 when penetrating), m.
    pub clearance: f64,
    /// Penetration depth of the real shapes at `worst_t`, m.
    pub penetration: f64,
    /// The perimeter of the obstacle (0 for self-collision), m.
    pub margin: f64,
    /// `margin - signed distance` at `worst_t`: how deep into the perimeter, m.
    pub margin_violation: f64,
}

impl std::fmt::Display for Collision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} hits {} ({:?}) from t={:.3} (segment {}), worst at t={:.3}: clearance {:.1} mm, penetration {:.1} mm, margin {:.1} mm violated by {:.1} mm",
            self.body,
            self.other,
            self.kind,
            self.first_t,
            self.segment,
            self.worst_t,
            self.clearance * 1e3,
            self.penetration * 1e3,
            self.margin * 1e3,
            self.margin_violation * 1e3
        )
    }
}

/// Work counters of one check.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct CheckStats {
    /// Instants where poses were computed (FK or tool interpolation).
    pub evaluations: u64,
    /// Exact shape-pair distance/contact queries.
    pub pair_queries: u64,
    /// Broad-phase lower-bound tests: AABBs against the scene, bounding
    /// spheres between moving bodies.
    pub aabb_tests: u64,
}

/// The answer of a check: free, or the hits found (earliest first).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathVerdict {
    pub collisions: Vec<Collision>,
    pub stats: CheckStats,
}

impl PathVerdict {
    pub fn is_free(&self) -> bool {
        self.collisions.is_empty()
    }

    /// The earliest hit.
    pub fn first(&self) -> Option<&Collision> {
        self.collisions.first()
    }
}
