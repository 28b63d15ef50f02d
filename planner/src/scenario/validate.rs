//! Validation after parsing: everything serde cannot check (ranges, unique
//! names, boxes inside the image, a usable calibration). Returns every issue
//! found, each naming its field path.

use std::collections::HashSet;

use super::{FORMAT_VERSION, PixelBox, Scenario};
use crate::error::FieldIssue;

/// All problems with `s`; empty when it is valid.
pub fn validate(s: &Scenario) -> Vec<FieldIssue> {
    let mut issues = Vec::new();
    let mut push = |field: String, message: String| issues.push(FieldIssue::new(field, message));
    if s.afford != FORMAT_VERSION {
        push(
            "afford".into(),
            format!(
                "unsupported format version {} (this build reads {FORMAT_VERSION})",
                s.afford
            ),
        );
    }
    check_camera(s, &mut push);
    if s.robot.model.trim().is_empty() {
        push(
            "robot.model".into(),
            "must name a robot (kuka_iiwa14, care_o_bot4 or a description file)".into(),
        );
    }
    if let Some(start) = s.robot.start {
        check_pixel(s, "robot.start", start, &mut push);
    }
    for (name, value) in s.robot.joints.iter().flatten() {
        if !value.is_finite() {
            push(
                format!("robot.joints.{name}"),
                format!("must be a finite joint position (rad or m), got {value}"),
            );
        }
    }
    if let Some(p) = s.pointing {
        check_pixel(s, "pointing", p, &mut push);
    }
    let elements = s
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| (format!("objects[{i}]"), o.name.as_str(), o.bbox, o.height))
        .chain(
            s.goals
                .iter()
                .enumerate()
                .map(|(i, g)| (format!("goals[{i}]"), g.name.as_str(), g.bbox, g.height)),
        )
        .chain(
            s.hands
                .iter()
                .enumerate()
                .map(|(i, h)| (format!("hands[{i}]"), h.name.as_str(), h.bbox, h.height)),
        );
    let mut names = HashSet::new();
    for (field, name, bbox, height) in elements {
        if name.trim().is_empty() {
            push(format!("{field}.name"), "must not be empty".into());
        } else if !names.insert(name.to_string()) {
            push(
                format!("{field}.name"),
                format!("the name '{name}' is used twice"),
            );
        }
        check_box(s, &format!("{field}.box"), bbox, &mut push);
        if !(height.is_finite() && height > 0.0) {
            push(
                format!("{field}.height"),
                format!("must be a positive number of metres, got {height}"),
            );
        }
    }
    for (i, o) in s.objects.iter().enumerate() {
        for (what, text) in [("color", &o.color), ("shape", &o.shape)] {
            if text.trim().is_empty() {
                push(format!("objects[{i}].{what}"), "must not be empty".into());
            }
        }
    }
    for (i, entry) in s.sensitive.iter().enumerate() {
        if entry.trim().is_empty() {
            push(
                format!("sensitive[{i}]"),
                "must name a colour, shape or object".into(),
            );
        }
    }
    let safety = &s.safety;
    for (name, value) in [
        ("obstacle_margin", safety.obstacle_margin),
        ("sensitive_margin", safety.sensitive_margin),
        ("hand_margin", safety.hand_margin),
    ] {
        if !(value.is_finite() && (0.0..=1.0).contains(&value)) {
            push(
                format!("safety.{name}"),
                format!("must be between 0 and 1 metre, got {value}"),
            );
        }
    }
    if s.instruction.trim().is_empty() {
        push("instruction".into(), "must not be empty".into());
    }
    for issue in s.learner.validate() {
        push(format!("learner.{}", issue.field), issue.message);
    }
    issues
}

fn check_camera(s: &Scenario, push: &mut impl FnMut(String, String)) {
    let c = &s.camera;
    if c.width == 0 || c.height == 0 {
        push(
            "camera".into(),
            format!("image size must be positive, got {}x{}", c.width, c.height),
        );
    }
    let m = &c.pixel_to_base;
    if m.iter().flatten().any(|x| !x.is_finite()) {
        push(
            "camera.pixel_to_base".into(),
            "must hold finite numbers".into(),
        );
    } else if (m[0][0] * m[1][1] - m[0][1] * m[1][0]).abs() < 1e-12 {
        push(
            "camera.pixel_to_base".into(),
            "is singular: pixels do not map onto the table plane".into(),
        );
    }
    if !c.table_z.is_finite() {
        push(
            "camera.table_z".into(),
            "must be a finite height in metres".into(),
        );
    }
}

fn check_pixel(s: &Scenario, field: &str, [u, v]: [f64; 2], push: &mut impl FnMut(String, String)) {
    let (w, h) = (s.camera.width as f64, s.camera.height as f64);
    if !(u.is_finite() && v.is_finite() && (0.0..w).contains(&u) && (0.0..h).contains(&v)) {
        push(
            field.into(),
            format!("pixel ({u}, {v}) is outside the {w}x{h} image"),
        );
    }
}

fn check_box(s: &Scenario, field: &str, b: PixelBox, push: &mut impl FnMut(String, String)) {
    let (w, h) = (s.camera.width as f64, s.camera.height as f64);
    let values = [b.u, b.v, b.w, b.l];
    if values.iter().any(|x| !x.is_finite()) {
        push(
            field.into(),
            "must hold four finite numbers [u, v, w, l]".into(),
        );
    } else if b.w <= 0.0 || b.l <= 0.0 {
        push(
            field.into(),
            format!("width and length must be positive, got w={} l={}", b.w, b.l),
        );
    } else if b.u < 0.0 || b.v < 0.0 || b.u + b.w > w || b.v + b.l > h {
        push(
            field.into(),
            format!(
                "box [{}, {}, {}, {}] is not inside the {w}x{h} image",
                b.u, b.v, b.w, b.l
            ),
        );
    }
}
