//! The scenario file's data model (format 1): what the overhead camera and the
//! microphone deliver. Pixel boxes are `[u, v, w, l]`: top-left pixel, width
//! along u, length along v. Metric values are metres in the robot base frame.
//!
//! Every struct denies unknown fields, so a typo is an error rather than a
//! silently ignored setting. Defaults are written once, in the `Default` impls.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::cql::LearnerSettings;
use crate::timing::SeparationSettings;

/// The scenario format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// A whole planning request: scene, robot, instruction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Format version; must equal [`FORMAT_VERSION`].
    pub afford: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub camera: Camera,
    pub robot: RobotSpec,
    /// The semantic set O: every object on the table.
    #[serde(default)]
    pub objects: Vec<Object>,
    /// Places objects can be put in.
    #[serde(default)]
    pub goals: Vec<Goal>,
    /// Human hands the camera sees.
    #[serde(default)]
    pub hands: Vec<Hand>,
    /// Colours, shapes or object names that get the sensitive margin.
    #[serde(default)]
    pub sensitive: Vec<String>,
    #[serde(default)]
    pub safety: Safety,
    /// The spoken instruction, as text.
    pub instruction: String,
    /// Pixel the user's hand points at; resolves "here" / "there".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pointing: Option<[f64; 2]>,
    /// Learner parameters; the defaults are documented on [`LearnerSettings`].
    #[serde(default)]
    pub learner: LearnerSettings,
    /// What the camera sees during execution (`afford run`), in order;
    /// see [`super::Observation`]. Planning ignores it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub observations: Vec<super::Observation>,
}

/// The overhead camera: image size and its calibration to the table plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Image width in pixels (the paper's sw).
    pub width: u32,
    /// Image height in pixels (the paper's sh).
    pub height: u32,
    /// 2x3 affine map (u, v, 1) -> table-plane (x, y), metres, robot base frame.
    pub pixel_to_base: [[f64; 3]; 2],
    /// Table surface height in the robot base frame, metres.
    pub table_z: f64,
}

/// Which robot executes the plan, and where it is now. The robot's state at
/// t = 0 follows from `joints` and `start` (rules in [`crate::start`]):
/// joints given — exactly that state (`start`, when also given, must agree
/// within one grid cell); `start` alone — the tool hovering over that pixel;
/// neither — home with every arm parked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Built-in model name (`kuka_iiwa14`, `care_o_bot4`) or a path to a user
    /// robot description file (relative paths are relative to the scenario).
    pub model: String,
    /// Gripper's current position, pixel (u, v); derived from `joints` by
    /// forward kinematics when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<[f64; 2]>,
    /// The robot's current joint positions by joint name (rad for revolute
    /// and continuous joints, m for prismatic ones), as a robot stack reads
    /// them from its joint states; names every movable joint of the robot.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joints: Option<BTreeMap<String, f64>>,
}

/// A pixel rectangle `[u, v, w, l]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "[f64; 4]", into = "[f64; 4]")]
pub struct PixelBox {
    pub u: f64,
    pub v: f64,
    pub w: f64,
    pub l: f64,
}

impl From<[f64; 4]> for PixelBox {
    fn from([u, v, w, l]: [f64; 4]) -> Self {
        Self { u, v, w, l }
    }
}

impl From<PixelBox> for [f64; 4] {
    fn from(b: PixelBox) -> Self {
        [b.u, b.v, b.w, b.l]
    }
}

impl PixelBox {
    /// Centre pixel (u, v).
    pub fn centre(&self) -> [f64; 2] {
        [self.u + self.w / 2.0, self.v + self.l / 2.0]
    }

    /// True when the pixel lies inside the box (edges included).
    pub fn contains(&self, [u, v]: [f64; 2]) -> bool {
        u >= self.u && u <= self.u + self.w && v >= self.v && v <= self.v + self.l
    }

    /// The box grown by `du` pixels along u and `dv` along v on every side.
    pub fn grown(&self, du: f64, dv: f64) -> Self {
        Self {
            u: self.u - du,
            v: self.v - dv,
            w: self.w + 2.0 * du,
            l: self.l + 2.0 * dv,
        }
    }

    /// The same footprint with its centre moved to `centre`.
    pub fn centred_at(&self, [cu, cv]: [f64; 2]) -> Self {
        Self {
            u: cu - self.w / 2.0,
            v: cv - self.l / 2.0,
            ..*self
        }
    }
}

/// An object on the table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Object {
    /// Unique name, e.g. `blue-square-1`.
    pub name: String,
    pub color: String,
    pub shape: String,
    #[serde(rename = "box")]
    pub bbox: PixelBox,
    /// Height above the table, metres.
    pub height: f64,
}

/// A place objects can be put in (an open box on the table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Goal {
    pub name: String,
    #[serde(rename = "box")]
    pub bbox: PixelBox,
    /// Wall height above the table, metres.
    pub height: f64,
}

/// A human hand seen by the camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hand {
    pub name: String,
    #[serde(rename = "box")]
    pub bbox: PixelBox,
    /// Height of the hand's top above the table, metres.
    pub height: f64,
}

/// Safety perimeters, metres. Defaults: 0.02 around obstacles, 0.06 around
/// sensitive objects, 0.10 around hands (a floor; ISO/TS 15066 speed and
/// separation rules apply on top of it in the timing stage).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Safety {
    pub obstacle_margin: f64,
    pub sensitive_margin: f64,
    pub hand_margin: f64,
    /// Speed and separation near hands (ISO/TS 15066); defaults and their
    /// sources are on [`SeparationSettings`].
    pub separation: SeparationSettings,
    /// How the valid-policy detector reads the detector's observations:
    /// the hold time of a hand that dropped out of view, the tolerance of
    /// box shifts ([`crate::monitor::detection::DetectionSettings`]).
    pub detection: crate::monitor::detection::DetectionSettings,
}

impl Default for Safety {
    fn default() -> Self {
        Self {
            obstacle_margin: 0.02,
            sensitive_margin: 0.06,
            hand_margin: 0.10,
            separation: SeparationSettings::default(),
            detection: Default::default(),
        }
    }
}

impl Scenario {
    /// True when `object` matches one of the `sensitive` entries (colour,
    /// shape or name, case-insensitive).
    pub fn is_sensitive(&self, object: &Object) -> bool {
        self.sensitive.iter().any(|s| {
            s.eq_ignore_ascii_case(&object.color)
                || s.eq_ignore_ascii_case(&object.shape)
                || s.eq_ignore_ascii_case(&object.name)
        })
    }

    /// Index of the object called `name`.
    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }

    /// Index of the goal called `name`.
    pub fn goal_index(&self, name: &str) -> Option<usize> {
        self.goals.iter().position(|g| g.name == name)
    }

    /// The goal whose box contains the object's centre, if any: objects
    /// resting in a box belong to that box, not to the free table.
    pub fn goal_holding(&self, object: &Object) -> Option<usize> {
        self.goal_under(object.bbox)
    }

    /// The goal whose box contains the centre of footprint `b`, if any.
    pub fn goal_under(&self, b: PixelBox) -> Option<usize> {
        let c = b.centre();
        self.goals.iter().position(|g| g.bbox.contains(c))
    }

    /// Height of the object's top above the table top, m: its own height,
    /// plus a goal box's floor ([`afford_collision::GOAL_WALL`]) when it
    /// rests in one ([`Self::goal_holding`]). The collision scene stands
    /// every object on the table, so an object in a box spans the floor
    /// too: its top is where it really is, its bottom never above it.
    pub fn top_above_table(&self, object: &Object) -> f64 {
        object.height + self.support_under(object.bbox)
    }

    /// Height above the table top of what an object with footprint `b`
    /// stands on, m: a goal box's floor when the box holds its centre, else
    /// 0 (the table).
    pub fn support_under(&self, b: PixelBox) -> f64 {
        self.goal_under(b)
            .map_or(0.0, |_| afford_collision::GOAL_WALL)
    }

    /// Metres per pixel along u and along v, from `pixel_to_base`.
    pub fn metres_per_pixel(&self) -> [f64; 2] {
        let m = &self.camera.pixel_to_base;
        [m[0][0].hypot(m[1][0]), m[0][1].hypot(m[1][1])]
    }

    /// The pixel that maps to table-plane point (x, y): the inverse of
    /// [`Self::pixel_to_base`] (validation guarantees it exists).
    pub fn base_to_pixel(&self, [x, y]: [f64; 2]) -> [f64; 2] {
        let m = &self.camera.pixel_to_base;
        let (dx, dy) = (x - m[0][2], y - m[1][2]);
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        [
            (m[1][1] * dx - m[0][1] * dy) / det,
            (m[0][0] * dy - m[1][0] * dx) / det,
        ]
    }

    /// Table-plane point (x, y) in the robot base frame for a pixel.
    pub fn pixel_to_base(&self, [u, v]: [f64; 2]) -> [f64; 2] {
        let m = &self.camera.pixel_to_base;
        [
            m[0][0] * u + m[0][1] * v + m[0][2],
            m[1][0] * u + m[1][1] * v + m[1][2],
        ]
    }
}
