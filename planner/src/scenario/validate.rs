//! Validation after parsing: everything serde cannot check (ranges, names
//! an instruction can tell apart, boxes inside the image, a usable calibration) and every size bound
//! of [`super::bounds`], so no accepted scenario asks for unbounded work.
//! Returns every issue found, each naming its field path.

use std::collections::HashSet;

use super::bounds::*;
use super::names::Names;
use super::{FORMAT_VERSION, PixelBox, Scenario};
use crate::error::FieldIssue;
use crate::instruction::lexicon::{COLOURS, SHAPES};
use afford_collision::GOAL_WALL;

/// Collects issues; `push(field, message)`.
type Push<'a> = dyn FnMut(String, String) + 'a;

/// All problems with `s`; empty when it is valid.
pub fn validate(s: &Scenario) -> Vec<FieldIssue> {
    let mut issues = Vec::new();
    let push = &mut |field: String, message: String| issues.push(FieldIssue::new(field, message));
    if s.afford != FORMAT_VERSION {
        push(
            "afford".into(),
            format!(
                "unsupported format version {} (this build reads {FORMAT_VERSION})",
                s.afford
            ),
        );
    }
    if let Some(name) = &s.name {
        check_text("name", name, push);
    }
    let camera_ok = check_camera(s, push);
    if s.robot.model.trim().is_empty() {
        push(
            "robot.model".into(),
            "must name a robot (kuka_iiwa14, care_o_bot4 or a description file)".into(),
        );
    }
    check_text("robot.model", &s.robot.model, push);
    if let Some(start) = s.robot.start {
        check_pixel(s, "robot.start", start, push);
    }
    for (name, value) in s.robot.joints.iter().flatten() {
        if !(value.is_finite() && value.abs() <= MAX_JOINT_POSITION) {
            push(
                format!("robot.joints.{name}"),
                format!(
                    "must be a finite joint position within ±{MAX_JOINT_POSITION} (rad or m), got {}",
                    shown(*value)
                ),
            );
        }
    }
    if let Some(p) = s.pointing {
        check_pixel(s, "pointing", p, push);
    }
    check_elements(s, camera_ok, push);
    check_observations(s, camera_ok, push);
    for (i, entry) in s.sensitive.iter().take(MAX_SENSITIVE).enumerate() {
        if entry.trim().is_empty() {
            push(
                format!("sensitive[{i}]"),
                "must name a colour, shape or object".into(),
            );
        } else if let Some(message) = unknown_sensitive(s, entry) {
            push(format!("sensitive[{i}]"), message);
        }
        check_text(&format!("sensitive[{i}]"), entry, push);
    }
    check_count("sensitive", s.sensitive.len(), MAX_SENSITIVE, push);
    check_safety(s, push);
    check_instruction(&s.instruction, push);
    for issue in s.learner.validate() {
        push(format!("learner.{}", issue.field), issue.message);
    }
    let learner = &s.learner;
    for (name, value) in [
        ("max_steps", learner.max_steps),
        ("episode_steps", learner.episode_steps),
        ("convergence_window", learner.convergence_window),
    ] {
        if value > MAX_LEARNER_STEPS {
            push(
                format!("learner.{name}"),
                format!("must be at most {MAX_LEARNER_STEPS} steps, got {value}"),
            );
        }
    }
    issues
}

/// Why `entry` of `sensitive:` names nothing (no object's colour, shape or
/// name, no colour or shape afford knows), with the nearest word as a
/// did-you-mean; `None` when it names something.
fn unknown_sensitive(s: &Scenario, entry: &str) -> Option<String> {
    let known = s
        .objects
        .iter()
        .flat_map(|o| [&o.color, &o.shape, &o.name].map(|w| w.to_lowercase()))
        .chain(COLOURS.iter().chain(SHAPES).map(|w| w.to_string()));
    let wanted = entry.trim().to_lowercase();
    let mut nearest: Option<(usize, String)> = None;
    for word in known {
        let distance = strsim::levenshtein(&wanted, &word);
        if distance == 0 {
            return None;
        }
        if nearest.as_ref().is_none_or(|(d, _)| distance < *d) {
            nearest = Some((distance, word));
        }
    }
    let hint = match nearest {
        Some((d, word)) if d <= 2 => format!("; did you mean '{word}'?"),
        _ => String::new(),
    };
    Some(format!(
        "'{entry}' names no colour, shape or object of the scene, so no margin would be kept{hint}"
    ))
}

/// Objects, goals and hands: names, boxes, heights, counts; objects also
/// their colour, shape, size in metres and the grid they cut the image into.
fn check_elements(s: &Scenario, camera_ok: bool, push: &mut Push) {
    check_count("objects", s.objects.len(), MAX_OBJECTS, push);
    check_count("goals", s.goals.len(), MAX_GOALS, push);
    check_count("hands", s.hands.len(), MAX_HANDS, push);
    let mut elements: Vec<(String, &str, PixelBox, f64)> = Vec::new();
    let objects = s
        .objects
        .iter()
        .map(|o| (o.name.as_str(), o.bbox, o.height));
    let goals = s.goals.iter().map(|g| (g.name.as_str(), g.bbox, g.height));
    let hands = s.hands.iter().map(|h| (h.name.as_str(), h.bbox, h.height));
    let lists: [(&str, Vec<_>, usize); 3] = [
        ("objects", objects.collect(), MAX_OBJECTS),
        ("goals", goals.collect(), MAX_GOALS),
        ("hands", hands.collect(), MAX_HANDS),
    ];
    for (list, items, max) in lists {
        let named = items.into_iter().take(max).enumerate();
        elements.extend(named.map(|(i, (n, b, h))| (format!("{list}[{i}]"), n, b, h)));
    }
    let mut names = Names::default();
    for (field, name, bbox, height) in elements {
        if name.trim().is_empty() {
            push(format!("{field}.name"), "must not be empty".into());
        } else if let Some(message) = names.clash(&field, name) {
            push(format!("{field}.name"), message);
        }
        check_text(&format!("{field}.name"), name, push);
        let box_ok = check_box(s, &format!("{field}.box"), bbox, push);
        if !(height.is_finite() && (MIN_HEIGHT_M..=MAX_HEIGHT_M).contains(&height)) {
            push(
                format!("{field}.height"),
                format!("must be between {MIN_HEIGHT_M} and {MAX_HEIGHT_M} metres, got {height:?}"),
            );
        }
        if camera_ok && box_ok && field.starts_with("objects") {
            check_target_size(s, &format!("{field}.box"), bbox, push);
        }
        if camera_ok && box_ok && field.starts_with("goals") {
            check_goal_size(s, &field, bbox, height, push);
        }
    }
    for (i, o) in s.objects.iter().take(MAX_OBJECTS).enumerate() {
        for (what, text) in [("color", &o.color), ("shape", &o.shape)] {
            if text.trim().is_empty() {
                push(format!("objects[{i}].{what}"), "must not be empty".into());
            }
            check_text(&format!("objects[{i}].{what}"), text, push);
        }
    }
}

/// The observation timeline: each entry happens at a time or a plan point
/// (exactly one, in range), changes at least one list, and the scene after
/// it (the entries before it applied in file order) is valid as the file's
/// own lists are: its issues are named `observations[i].<list>[j]...`.
fn check_observations(s: &Scenario, camera_ok: bool, push: &mut Push) {
    check_count("observations", s.observations.len(), MAX_OBSERVATIONS, push);
    let mut before: HashSet<String> = HashSet::new();
    check_elements(s, camera_ok, &mut |field, message| {
        before.insert(format!("{field}: {message}"));
    });
    let mut scene = s.clone();
    for (i, o) in s.observations.iter().take(MAX_OBSERVATIONS).enumerate() {
        let field = |f: &str| format!("observations[{i}].{f}");
        match (o.at, &o.when) {
            (Some(_), Some(_)) | (None, None) => push(
                format!("observations[{i}]"),
                "must give exactly one of `at` (seconds) and `when` (a plan point)".into(),
            ),
            (Some(at), None) if !(at.is_finite() && (0.0..=MAX_EXECUTION_TIME_S).contains(&at)) => {
                push(
                    field("at"),
                    format!("must be between 0 and {MAX_EXECUTION_TIME_S} seconds, got {at:?}"),
                )
            }
            (None, Some(when)) => {
                if when.subgoal >= MAX_SUBGOALS {
                    push(
                        field("when.subgoal"),
                        format!(
                            "must be below {MAX_SUBGOALS} (the most sub-goals an instruction has), got {}",
                            when.subgoal
                        ),
                    );
                }
                if !(when.fraction.is_finite() && (0.0..=1.0).contains(&when.fraction)) {
                    push(
                        field("when.fraction"),
                        format!("must be between 0 and 1, got {:?}", when.fraction),
                    );
                }
            }
            _ => {}
        }
        if o.is_unchanged() {
            push(
                format!("observations[{i}]"),
                "must list at least one of `objects`, `goals`, `hands`".into(),
            );
        }
        scene.apply(o);
        let mut found = Vec::new();
        check_elements(&scene, camera_ok, &mut |f, message| {
            found.push((f, message))
        });
        for (f, message) in found {
            // Reported once: where the problem first appears.
            if before.insert(format!("{f}: {message}")) {
                push(field(&f), message);
            }
        }
    }
}

/// An object is a target: its box is the grid's cell, so it must be big
/// enough in metres and cut the image into at most [`MAX_GRID_CELLS`] cells.
fn check_target_size(s: &Scenario, field: &str, b: PixelBox, push: &mut Push) {
    let [mu, mv] = s.metres_per_pixel();
    let (w_m, l_m) = (b.w * mu, b.l * mv);
    if w_m.min(l_m) < MIN_OBJECT_SIDE_M {
        push(
            field.into(),
            format!(
                "the object is {:.4} x {:.4} m on the table; objects must be at least {MIN_OBJECT_SIDE_M} m on each side",
                w_m, l_m
            ),
        );
        return;
    }
    let cells = grid_cells_bound(s.camera.width, s.camera.height, b.w, b.l);
    if cells > MAX_GRID_CELLS as f64 {
        push(
            field.into(),
            format!(
                "a target of {} x {} px cuts the {}x{} image into up to {cells:.0} grid cells; at most {MAX_GRID_CELLS} are allowed (use a larger box or a smaller image)",
                b.w, b.l, s.camera.width, s.camera.height
            ),
        );
    }
}

/// A goal is an open box of [`GOAL_WALL`]-thick walls and floor: it must be
/// wider than two walls on each side and taller than its floor, else the
/// collision scene cannot be built (it was an `internal` refusal).
fn check_goal_size(s: &Scenario, field: &str, b: PixelBox, height: f64, push: &mut Push) {
    let [mu, mv] = s.metres_per_pixel();
    let (w_m, l_m) = (b.w * mu, b.l * mv);
    if w_m.min(l_m) <= 2.0 * GOAL_WALL {
        push(
            format!("{field}.box"),
            format!(
                "the goal is {w_m:.4} x {l_m:.4} m on the table; a goal box must be wider than its two {GOAL_WALL} m walls on each side"
            ),
        );
    }
    if height.is_finite() && height <= GOAL_WALL {
        push(
            format!("{field}.height"),
            format!("must be more than the goal box's {GOAL_WALL} m floor, got {height:?}"),
        );
    }
}

/// Returns true when the camera is usable for the size checks in metres.
fn check_camera(s: &Scenario, push: &mut Push) -> bool {
    let c = &s.camera;
    let mut ok = true;
    for (name, side) in [("width", c.width), ("height", c.height)] {
        if side == 0 || side > MAX_IMAGE_SIDE_PX {
            push(
                format!("camera.{name}"),
                format!("must be between 1 and {MAX_IMAGE_SIDE_PX} pixels, got {side}"),
            );
            ok = false;
        }
    }
    let m = &c.pixel_to_base;
    if m.iter().flatten().any(|x| !x.is_finite()) {
        push(
            "camera.pixel_to_base".into(),
            "must hold finite numbers".into(),
        );
        return false;
    }
    if (m[0][0] * m[1][1] - m[0][1] * m[1][0]).abs() < 1e-12 {
        push(
            "camera.pixel_to_base".into(),
            "is singular: pixels do not map onto the table plane".into(),
        );
        return false;
    }
    let skew = calibration_skew_deg(m);
    if skew > MAX_CALIBRATION_SKEW_DEG {
        push(
            "camera.pixel_to_base".into(),
            format!(
                "is skewed: the image's u and v axes meet at {:.1}° on the table, not 90°; boxes are modelled as rectangles, so they must be perpendicular within {MAX_CALIBRATION_SKEW_DEG}°",
                90.0 - skew
            ),
        );
        return false;
    }
    let (w, h) = (c.width as f64, c.height as f64);
    let far = [[0.0, 0.0], [w, 0.0], [0.0, h], [w, h]]
        .into_iter()
        .map(|p| s.pixel_to_base(p))
        .any(|[x, y]| !(x.abs() <= MAX_TABLE_EXTENT_M && y.abs() <= MAX_TABLE_EXTENT_M));
    if far {
        push(
            "camera.pixel_to_base".into(),
            format!("maps an image corner more than {MAX_TABLE_EXTENT_M} m from the robot base"),
        );
        ok = false;
    }
    if !(c.table_z.is_finite() && c.table_z.abs() <= MAX_TABLE_EXTENT_M) {
        push(
            "camera.table_z".into(),
            format!(
                "must be a height between -{MAX_TABLE_EXTENT_M} and {MAX_TABLE_EXTENT_M} metres, got {:?}",
                c.table_z
            ),
        );
    }
    ok
}

/// How far from perpendicular the table directions of the image's u and v
/// axes (the columns of `pixel_to_base`'s linear part) are, degrees.
fn calibration_skew_deg(m: &[[f64; 3]; 2]) -> f64 {
    let (u, v) = ([m[0][0], m[1][0]], [m[0][1], m[1][1]]);
    let cos = (u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1]));
    90.0 - cos.abs().min(1.0).acos().to_degrees()
}

fn check_safety(s: &Scenario, push: &mut Push) {
    let safety = &s.safety;
    for (name, value) in [
        ("obstacle_margin", safety.obstacle_margin),
        ("sensitive_margin", safety.sensitive_margin),
        ("hand_margin", safety.hand_margin),
    ] {
        if !(value.is_finite() && (0.0..=1.0).contains(&value)) {
            push(
                format!("safety.{name}"),
                format!("must be between 0 and 1 metre, got {}", shown(value)),
            );
        }
    }
    for (field, problem) in safety.detection.problems() {
        push(format!("safety.detection.{field}"), problem);
    }
    let separation = &safety.separation;
    if let Err(crate::timing::TimingError::Setting {
        field,
        value,
        expected,
    }) = separation.validate()
    {
        push(
            format!("safety.separation.{field}"),
            format!("must be {expected}, got {value:?}"),
        );
    }
    // Every field is a number in m, s, m/s or m/s²: one upper bound for all.
    let fields = serde_json::to_value(separation).unwrap_or_default();
    for (field, value) in fields.as_object().into_iter().flatten() {
        if let Some(v) = value.as_f64().filter(|&v| v > MAX_SEPARATION_VALUE) {
            push(
                format!("safety.separation.{field}"),
                format!("must be at most {MAX_SEPARATION_VALUE}, got {v:?}"),
            );
        }
    }
    let crawl = separation.min_tool_speed_m_s;
    if crawl > 0.0 && crawl < MIN_CRAWL_SPEED_M_S {
        push(
            "safety.separation.min_tool_speed_m_s".into(),
            format!(
                "must be 0 (refuse to crawl) or at least {MIN_CRAWL_SPEED_M_S} m/s, got {crawl:?}"
            ),
        );
    }
}

fn check_instruction(text: &str, push: &mut Push) {
    if text.trim().is_empty() {
        push("instruction".into(), "must not be empty".into());
    }
    // Echoed in messages: an escape sequence or a NUL would reach the terminal.
    if let Some(c) = text.chars().find(|c| c.is_control() && !c.is_whitespace()) {
        push(
            "instruction".into(),
            format!(
                "must not contain control characters other than line breaks and tabs, got {c:?}"
            ),
        );
    }
    let chars = text.chars().count();
    if chars > MAX_INSTRUCTION_CHARS {
        push(
            "instruction".into(),
            format!("must be at most {MAX_INSTRUCTION_CHARS} characters, got {chars}"),
        );
        return;
    }
    let clauses = clause_count_bound(text);
    if clauses > MAX_CLAUSES {
        push(
            "instruction".into(),
            format!(
                "has up to {clauses} clauses (separated by commas, 'and', 'then'...); at most {MAX_CLAUSES} are allowed"
            ),
        );
    }
}

fn check_count(field: &str, count: usize, max: usize, push: &mut Push) {
    if count > max {
        push(
            field.into(),
            format!("lists {count} entries; at most {max} are allowed"),
        );
    }
}

/// A name, colour, shape, `sensitive` entry or robot model: bounded, and
/// without control characters (a newline split the summary's lines and the
/// CSV's rows).
fn check_text(field: &str, text: &str, push: &mut Push) {
    if let Some(c) = text.chars().find(|c| c.is_control()) {
        push(
            field.into(),
            format!("must not contain control characters (newline, tab...), got {c:?}"),
        );
    }
    let chars = text.chars().count();
    if chars > MAX_NAME_CHARS {
        push(
            field.into(),
            format!("must be at most {MAX_NAME_CHARS} characters, got {chars}"),
        );
    }
}

fn check_pixel(s: &Scenario, field: &str, [u, v]: [f64; 2], push: &mut Push) {
    let (w, h) = (s.camera.width as f64, s.camera.height as f64);
    if !(u.is_finite() && v.is_finite() && (0.0..w).contains(&u) && (0.0..h).contains(&v)) {
        push(
            field.into(),
            format!(
                "pixel ({}, {}) is outside the {w}x{h} image",
                shown(u),
                shown(v)
            ),
        );
    }
}

/// True when the box is usable: finite, big enough, inside the image.
fn check_box(s: &Scenario, field: &str, b: PixelBox, push: &mut Push) -> bool {
    let (w, h) = (s.camera.width as f64, s.camera.height as f64);
    let values = [b.u, b.v, b.w, b.l];
    let problem = if values.iter().any(|x| !x.is_finite()) {
        "must hold four finite numbers [u, v, w, l]".to_string()
    } else if b.w <= 0.0 || b.l <= 0.0 {
        format!(
            "width and length must be positive, got w={} l={}",
            shown(b.w),
            shown(b.l)
        )
    } else if b.w < MIN_BOX_SIDE_PX || b.l < MIN_BOX_SIDE_PX {
        format!(
            "width and length must be at least {MIN_BOX_SIDE_PX} px, got w={:?} l={:?}",
            b.w, b.l
        )
    } else if b.u < 0.0 || b.v < 0.0 || b.u + b.w > w || b.v + b.l > h {
        let [u, v, bw, bl] = values.map(shown);
        format!("box [{u}, {v}, {bw}, {bl}] is not inside the {w}x{h} image")
    } else {
        return true;
    };
    push(field.into(), problem);
    false
}

/// A number as a person reads it: plain (`320`, `-0.1`), but in exponent
/// form beyond 1e15 (`{}` printed all 301 digits of 1e300).
fn shown(x: f64) -> String {
    match x.abs() >= 1e15 {
        true => format!("{x:e}"),
        false => format!("{x}"),
    }
}
