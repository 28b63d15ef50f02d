//! The scenario as metric geometry for the collision checks: every pixel
//! box mapped through `pixel_to_base` to a footprint on the table (centre,
//! size along the image axes, yaw of the image u axis in the base frame),
//! standing on `table_z` with its height (an object resting in a goal box
//! up to its top on the box's floor), and its safety margin.
//!
//! Margins: other objects get `obstacle_margin` (`sensitive_margin` when
//! sensitive), hands `hand_margin`, goals `obstacle_margin` — except the
//! sub-goal's own goal, the goal the target rests in (it is picked from
//! that box's floor) and the table, which the gripper and the held object
//! must enter or come close to and so get none (touching is still a
//! collision). The sub-goal's target is in the scene too, with
//! `obstacle_margin` (it is meant to be touched, so never the sensitive
//! one): the check exempts only the fingers from it until they close on it,
//! then it rides with the gripper (see the collision crate's `Attachment`).

use afford_collision::{BoxKind, SceneBox, SceneSpec, TableSpec};

use crate::scenario::{Object, PixelBox, Scenario};

/// The collision scene for moving `scenario.objects[target]` into
/// `scenario.goals[goal]`: every object (the target included, under its own
/// name), every goal, every hand, and the table.
pub fn scene_spec(scenario: &Scenario, target: usize, goal: usize) -> SceneSpec {
    let margins = &scenario.safety;
    let objects = scenario.objects.iter().enumerate().map(|(i, o)| {
        let margin = match i == target {
            true => margins.obstacle_margin,
            false => object_margin(scenario, o),
        };
        let height = scenario.top_above_table(o);
        object_box(scenario, o, o.bbox, height, margin)
    });
    let source = scenario.goal_holding(&scenario.objects[target]);
    let goals = scenario.goals.iter().enumerate().map(|(i, g)| {
        let margin = if i == goal || Some(i) == source {
            0.0
        } else {
            margins.obstacle_margin
        };
        scene_box(scenario, &g.name, BoxKind::Goal, g.bbox, g.height, margin)
    });
    let hands = scenario.hands.iter().map(|h| {
        scene_box(
            scenario,
            &h.name,
            BoxKind::Hand,
            h.bbox,
            h.height,
            margins.hand_margin,
        )
    });
    SceneSpec {
        table_z: scenario.camera.table_z,
        table: Some(table(scenario)),
        boxes: objects.chain(goals).chain(hands).collect(),
    }
}

/// An object's safety margin, m: `sensitive_margin` when it is sensitive,
/// else `obstacle_margin`.
pub fn object_margin(s: &Scenario, o: &Object) -> f64 {
    match s.is_sensitive(o) {
        true => s.safety.sensitive_margin,
        false => s.safety.obstacle_margin,
    }
}

/// Object `o` with its footprint at pixel box `b`: its box, round when its
/// outline is ([`crate::place::is_round`]).
pub fn object_box(s: &Scenario, o: &Object, b: PixelBox, height: f64, margin: f64) -> SceneBox {
    SceneBox {
        round: crate::place::is_round(o),
        ..scene_box(s, &o.name, BoxKind::Object, b, height, margin)
    }
}

/// A pixel box as a footprint in the base frame.
pub fn scene_box(
    s: &Scenario,
    name: &str,
    kind: BoxKind,
    b: PixelBox,
    height: f64,
    margin: f64,
) -> SceneBox {
    let [mu, mv] = s.metres_per_pixel();
    let m = &s.camera.pixel_to_base;
    SceneBox {
        name: name.to_string(),
        kind,
        centre: s.pixel_to_base(b.centre()),
        size: [b.w * mu, b.l * mv, height],
        yaw: m[1][0].atan2(m[0][0]),
        margin,
        round: false,
    }
}

/// The table top: the bounding rectangle of the image's footprint.
fn table(s: &Scenario) -> TableSpec {
    let (w, h) = (s.camera.width as f64, s.camera.height as f64);
    let corners = [[0.0, 0.0], [w, 0.0], [0.0, h], [w, h]].map(|p| s.pixel_to_base(p));
    let min = [0, 1].map(|k| corners.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min));
    let max = [0, 1].map(|k| {
        corners
            .iter()
            .map(|c| c[k])
            .fold(f64::NEG_INFINITY, f64::max)
    });
    TableSpec {
        min,
        max,
        margin: 0.0,
    }
}
