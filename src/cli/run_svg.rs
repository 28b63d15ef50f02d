//! `afford run --svg`: a top view of the executed run — the scene as it
//! was at the end (goals, objects, hands with their names), every hand
//! that came and went during the run (dashed, labelled with the times it
//! was believed present), the tool's executed path per sub-goal, and each
//! event (stops, waits, replans …) marked where the tool was when it was
//! decided, numbered as in the list below the view.

use std::fmt::Write;

use afford_kinematics::RobotModel;
use afford_planner::Scenario;
use afford_planner::monitor::{Event, ExecutedSubgoal};
use afford_planner::scenario::PixelBox;

const COLOURS: [&str; 6] = [
    "#1565c0", "#2e7d32", "#ef6c00", "#6a1b9a", "#00838f", "#ad1457",
];

/// The SVG document.
pub fn draw(
    scene: &Scenario,
    executed: &[ExecutedSubgoal],
    events: &[Event],
    robot: &RobotModel,
) -> String {
    let (w, h) = (scene.camera.width as f64, scene.camera.height as f64);
    let line = 16.0;
    let height = h + 40.0 + line * (events.len() as f64 + 1.0);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{height}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"{w}\" height=\"{h}\" fill=\"#fafafa\" stroke=\"#999\"/>\n"
    );
    let boxes = scene
        .goals
        .iter()
        .map(|g| (&g.name, g.bbox, "#fff3c4"))
        .chain(scene.objects.iter().map(|o| (&o.name, o.bbox, "#cfd8dc")))
        .chain(scene.hands.iter().map(|x| (&x.name, x.bbox, "#ffcdd2")));
    for (name, b, fill) in boxes {
        let _ = writeln!(
            svg,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{fill}\" stroke=\"#555\"/><text x=\"{}\" y=\"{}\">{}</text>",
            b.u,
            b.v,
            b.w,
            b.l,
            b.u + 2.0,
            b.v + 12.0,
            escape(name)
        );
    }
    for (name, b, from, to) in hand_spans(executed) {
        if scene.hands.iter().any(|h| h.name == name && h.bbox == b) {
            continue;
        }
        let until = to.map_or("end".to_string(), |t| format!("{t:.2} s"));
        let _ = writeln!(
            svg,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#ffcdd2\" fill-opacity=\"0.4\" stroke=\"#c62828\" stroke-dasharray=\"4 3\"/><text x=\"{}\" y=\"{}\" fill=\"#c62828\">{} {from:.2}–{until}</text>",
            b.u,
            b.v,
            b.w,
            b.l,
            b.u + 2.0,
            b.v + b.l + 12.0,
            escape(&name)
        );
    }
    let mut marks = Vec::new();
    for (k, sub) in executed.iter().enumerate() {
        let Ok(arm) = robot.arm(&sub.arm) else {
            continue;
        };
        let pixel = |q: &[f64]| {
            let p = arm.fk(q).translation.vector;
            scene.base_to_pixel([p.x, p.y])
        };
        let points: Vec<String> = sub
            .trajectory
            .points
            .iter()
            .step_by(5)
            .map(|p| {
                let [u, v] = pixel(&p.positions);
                format!("{u:.1},{v:.1}")
            })
            .collect();
        let _ = writeln!(
            svg,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>",
            points.join(" "),
            COLOURS[k % COLOURS.len()]
        );
        let end = sub.start_time + sub.trajectory.duration();
        for (i, e) in events.iter().enumerate() {
            if e.time >= sub.start_time - 1e-9 && e.time <= end + 1e-9 {
                let t = e.time - sub.start_time;
                let p = sub
                    .trajectory
                    .points
                    .iter()
                    .find(|p| p.time_from_start >= t - 1e-9)
                    .or(sub.trajectory.points.last());
                if let Some(p) = p {
                    marks.push((i, pixel(&p.positions)));
                }
            }
        }
    }
    for (i, [u, v]) in marks {
        let _ = writeln!(
            svg,
            "<circle cx=\"{u:.1}\" cy=\"{v:.1}\" r=\"6\" fill=\"#d32f2f\"/><text x=\"{:.1}\" y=\"{:.1}\" fill=\"#d32f2f\">{}</text>",
            u + 8.0,
            v - 4.0,
            i + 1
        );
    }
    for (i, e) in events.iter().enumerate() {
        let text = match &e.message {
            Some(m) => format!("{}: {m}", e.verdict),
            None => e.verdict.to_string(),
        };
        let _ = writeln!(
            svg,
            "<text x=\"4\" y=\"{:.0}\">{}. {:.2} s {}{}</text>",
            h + 24.0 + line * i as f64,
            i + 1,
            e.time,
            escape(&text),
            escape(&match e.changes.is_empty() {
                true => String::new(),
                false => format!(" [{}]", e.changes.join("; ")),
            })
        );
    }
    svg.push_str("</svg>\n");
    svg
}

/// Every hand believed present during the run, each place it was in:
/// (name, box, from, until; `None` while still there at the end), times
/// on the execution clock, in the order they came.
fn hand_spans(executed: &[ExecutedSubgoal]) -> Vec<(String, PixelBox, f64, Option<f64>)> {
    let mut spans: Vec<(String, PixelBox, f64, Option<f64>)> = Vec::new();
    let scenes = executed.iter().flat_map(|sub| {
        let start = sub.scene_at_start.iter().map(|s| (sub.start_time, s));
        let changes = (sub.changes.iter()).map(|(t, s)| (sub.start_time + t, s));
        start.chain(changes)
    });
    for (t, scene) in scenes {
        for span in spans.iter_mut().filter(|s| s.3.is_none()) {
            if !scene
                .hands
                .iter()
                .any(|h| h.name == span.0 && h.bbox == span.1)
            {
                span.3 = Some(t);
            }
        }
        for h in &scene.hands {
            if !spans
                .iter()
                .any(|s| s.3.is_none() && s.0 == h.name && s.1 == h.bbox)
            {
                spans.push((h.name.clone(), h.bbox, t, None));
            }
        }
    }
    spans
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
