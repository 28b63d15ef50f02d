//! The tool's heights and yaw over the table: the grasp pose and height
//! (the fingers on the object's middle, the palm clear of its top), the
//! carry height (the tallest thing passed over plus the held object and
//! `carry_clearance`) and the yaw that puts the fingers across the
//! object's shorter side.

use super::settings::{GripperReach, LiftSettings};
use crate::error::Refusal;
use crate::grid::StateGrid;
use crate::motion::route::crosses_open_box;
use crate::scenario::{Object, PixelBox, Scenario};

/// The grasp's tool yaw and TCP height above the table ([`grasp_yaw`],
/// [`grasp_height`]), or why the gripper cannot take the object.
pub fn grasp_pose(
    s: &Scenario,
    held: &Object,
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<(f64, f64), Refusal> {
    Ok((
        grasp_yaw(s, held, gripper, settings)?,
        grasp_height(s, held, gripper, settings)?,
    ))
}

/// TCP height above the table at the grasp (see the module doc; over a
/// goal box's floor for a piece resting in one), or why no
/// height keeps the palm clear of the object while the fingers still hold it.
pub fn grasp_height(
    s: &Scenario,
    held: &Object,
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<f64, Refusal> {
    let h = held.height;
    let margin = s.safety.obstacle_margin;
    let grasp = (h / 2.0)
        .max(settings.min_grasp_height)
        .max(gripper.tips_below_tcp + settings.tip_clearance)
        .max(h + margin + settings.palm_clearance - gripper.palm_above_tcp);
    let tips = grasp - gripper.tips_below_tcp;
    let depth = h - tips;
    // 1 nm: a grip of exactly `min_grip_depth` passes despite rounding.
    if tips <= h / 2.0 || depth >= settings.min_grip_depth - 1e-9 {
        // Heights so far are above the piece's bottom: a piece resting in
        // a goal box stands on its floor.
        return Ok(grasp + s.support_under(held.bbox));
    }
    Err(Refusal::TooTallForFingers {
        object: held.name.clone(),
        height_m: h,
        palm_gap_m: margin,
        finger_length_m: gripper.finger_length,
        grip_depth_m: depth.max(0.0),
        min_grip_depth_m: settings.min_grip_depth,
    })
}

/// Carry height (metres above the table top) of a sub-goal that moves
/// `object` when the route is not known: the tallest other thing on the
/// table + the object's height + `carry_clearance`.
pub fn carry_height(scenario: &Scenario, object: usize, settings: &LiftSettings) -> f64 {
    tallest(scenario, object) + scenario.objects[object].height + settings.carry_clearance
}

/// What a footprint (a cell-sized square) passes over on the way: objects
/// other than the held one and goal walls grown by the margins the grid
/// paints them with (the sub-goal's own goal by none), hands by
/// `hand_margin`, each grown again by half the footprint, with their
/// heights above the table (metres).
pub(super) struct Under(Vec<(PixelBox, f64)>);

impl Under {
    pub(super) fn of(s: &Scenario, grid: &StateGrid, object: usize, goal: usize) -> Self {
        let [mu, mv] = s.metres_per_pixel();
        let grown = |b: PixelBox, margin: f64| {
            b.grown(
                margin / mu + grid.cell_size[0] / 2.0,
                margin / mv + grid.cell_size[1] / 2.0,
            )
        };
        let objects = s
            .objects
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != object)
            .map(|(_, o)| {
                let margin = match s.is_sensitive(o) {
                    true => s.safety.sensitive_margin,
                    false => s.safety.obstacle_margin,
                };
                (grown(o.bbox, margin), s.top_above_table(o))
            });
        let goals = s.goals.iter().enumerate().map(|(i, g)| {
            let margin = if i == goal {
                0.0
            } else {
                s.safety.obstacle_margin
            };
            (grown(g.bbox, margin), g.height)
        });
        let hands = s
            .hands
            .iter()
            .map(|h| (grown(h.bbox, s.safety.hand_margin), h.height));
        Self(objects.chain(goals).chain(hands).collect())
    }

    /// Height of the tallest thing the footprint passes over from `a` to
    /// `b` (pixels; touching counts), 0 when none.
    pub(super) fn tallest(&self, a: [f64; 2], b: [f64; 2]) -> f64 {
        self.0
            .iter()
            .filter(|(b_, _)| {
                // Touching counts: the box grown by a micro-pixel.
                let lo = [b_.u - 1e-6, b_.v - 1e-6];
                let hi = [b_.u + b_.w + 1e-6, b_.v + b_.l + 1e-6];
                crosses_open_box(a, b, lo, hi)
            })
            .fold(0.0, |t: f64, (_, h)| t.max(*h))
    }
}

/// Height above the table of the tallest object (other than the held one),
/// goal wall or hand.
pub(super) fn tallest(s: &Scenario, held: usize) -> f64 {
    let objects = s
        .objects
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != held)
        .map(|(_, o)| s.top_above_table(o));
    objects
        .chain(s.goals.iter().map(|g| g.height))
        .chain(s.hands.iter().map(|h| h.height))
        .fold(0.0, f64::max)
}

/// Tool yaw that lays the tool's x axis along the object's longer side
/// (metres), so the fingers (closing along the tool's y axis) span its
/// narrower side; pixel axes are mapped through `pixel_to_base`. `Err` names
/// both widths when that side plus `opening_clearance` exceeds the
/// gripper's opening.
pub fn grasp_yaw(
    s: &Scenario,
    held: &Object,
    gripper: &GripperReach,
    settings: &LiftSettings,
) -> Result<f64, Refusal> {
    let [mu, mv] = s.metres_per_pixel();
    let (along_u, along_v) = (held.bbox.w * mu, held.bbox.l * mv);
    let across = along_u.min(along_v);
    if across + settings.opening_clearance > gripper.max_opening {
        return Err(Refusal::GripperTooNarrow {
            object: held.name.clone(),
            width_m: across,
            clearance_m: settings.opening_clearance,
            opening_m: gripper.max_opening,
        });
    }
    Ok(longer_side_yaw(s, held))
}

/// Tool yaw (rad, base frame) that lays the tool's x axis along the
/// object's longer side (along u on a tie), as [`grasp_yaw`] without the
/// opening check.
pub fn longer_side_yaw(s: &Scenario, held: &Object) -> f64 {
    let [mu, mv] = s.metres_per_pixel();
    let m = &s.camera.pixel_to_base;
    let (dx, dy) = if held.bbox.w * mu >= held.bbox.l * mv {
        (m[0][0], m[1][0])
    } else {
        (m[0][1], m[1][1])
    };
    dy.atan2(dx)
}
