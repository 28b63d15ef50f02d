//! Serialising results and writing them whole: a file is written to a
//! temporary sibling and renamed, so no reader ever sees half a plan.

use std::io::Write;
use std::path::Path;

use afford_planner::timing::TrajectoryPoint;
use serde::Serialize;

use super::{ExitKind, Failure, OutputFormat};

pub fn render<T: Serialize>(value: &T, format: OutputFormat) -> Result<String, Failure> {
    let text = match format {
        OutputFormat::Json => serde_json::to_string_pretty(value).map_err(|e| e.to_string()),
        OutputFormat::Yaml | OutputFormat::Csv | OutputFormat::Summary => {
            serde_saphyr::to_string(value).map_err(|e| e.to_string())
        }
    };
    text.map(|t| if t.ends_with('\n') { t } else { t + "\n" })
        .map_err(|e| {
            Failure::new(
                ExitKind::CouldNotPlan,
                format!("cannot serialise the result: {e}"),
            )
        })
}

/// Writes `text` to standard output. A reader that stops early (`| head`)
/// closes the pipe: that is not an error, the rest is dropped quietly.
/// Every command prints through here, never with `print!` (which panics on
/// a closed pipe).
pub fn print(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Failure::new(
            ExitKind::CouldNotPlan,
            format!("cannot write to standard output: {e}"),
        )),
        _ => Ok(()),
    }
}

/// Writes `text` to `path` atomically, or to stdout when `path` is `None`.
/// The temporary sibling is this process's own (`FILE.PID.partial`: two
/// runs writing one file never mix their halves) and is removed when the
/// write or the rename fails (`-o` naming a folder left `DIR.partial`).
pub fn emit(text: &str, path: Option<&Path>) -> Result<(), Failure> {
    let Some(path) = path else {
        return print(text);
    };
    let bad = |e: std::io::Error| {
        Failure::new(
            ExitKind::BadInput,
            format!("{}: cannot write: {e}", path.display()),
        )
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".{}.partial", std::process::id()));
    let written = std::fs::write(&tmp, text).and_then(|()| std::fs::rename(&tmp, path));
    if written.is_err() {
        // Best effort: the temporary may not exist; the error is the write's.
        let _ = std::fs::remove_file(&tmp);
    }
    written.map_err(bad)
}

/// The trajectories of a plan as CSV, one row per sample: sub-goal index,
/// object, arm, time, gripper state (`open`, `closing`, `closed`,
/// `opening`: a command is under way from its start to its end), then positions `q1…qn`, velocities
/// `v1…vn` and accelerations `a1…an` in the order of that sub-goal's
/// `joint_names`. Time restarts at 0 with each sub-goal.
pub fn render_csv(plan: &afford_planner::Plan) -> Result<String, Failure> {
    let dof = plan
        .subgoals
        .iter()
        .filter_map(|s| s.joint_names.as_ref())
        .map(Vec::len)
        .max();
    let Some(dof) = dof.filter(|_| plan.subgoals.iter().all(|s| s.trajectory.is_some())) else {
        return Err(Failure::new(
            ExitKind::BadInput,
            "--format csv needs trajectories: use --until trajectory",
        ));
    };
    let mut out = csv_header(
        &["subgoal", "object", "arm", "time_from_start", "gripper"],
        dof,
    );
    for (k, s) in plan.subgoals.iter().enumerate() {
        let Some(t) = &s.trajectory else { continue };
        for p in &t.points {
            let gripper = t.gripper_state(p.time_from_start).name();
            let arm = csv_text(s.arm.as_deref().unwrap_or(""));
            out.push_str(&format!(
                "{k},{},{arm},{},{gripper},{}\n",
                csv_text(&s.object),
                p.time_from_start,
                csv_numbers(p)
            ));
        }
    }
    Ok(out)
}

/// A CSV header line: the `leading` columns, then `q1…qn`, `v1…vn`,
/// `a1…an` for `dof` joints.
pub fn csv_header(leading: &[&str], dof: usize) -> String {
    let names = |prefix: char| (1..=dof).map(move |j| format!("{prefix}{j}"));
    let header: Vec<String> = leading
        .iter()
        .map(|s| s.to_string())
        .chain(names('q'))
        .chain(names('v'))
        .chain(names('a'))
        .collect();
    header.join(",") + "\n"
}

/// A text field as CSV (RFC 4180): quoted, with its quotes doubled, when
/// it holds a comma, a quote or a line break (`left box, top`); as it is
/// otherwise.
pub fn csv_text(text: &str) -> std::borrow::Cow<'_, str> {
    match text.contains([',', '"', '\n', '\r']) {
        true => format!("\"{}\"", text.replace('"', "\"\"")).into(),
        false => text.into(),
    }
}

/// A sample's positions, velocities and accelerations as CSV fields.
pub fn csv_numbers(p: &TrajectoryPoint) -> String {
    let values = p
        .positions
        .iter()
        .chain(&p.velocities)
        .chain(&p.accelerations);
    let numbers: Vec<String> = values.map(|v| format!("{v}")).collect();
    numbers.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A name with a comma or a quote stays one CSV field.
    #[test]
    fn csv_text_with_a_comma_or_quote_stays_one_field() {
        assert_eq!(csv_text("blue-square-1"), "blue-square-1");
        assert_eq!(csv_text("left box, top"), "\"left box, top\"");
        assert_eq!(csv_text("the \"big\" one"), "\"the \"\"big\"\" one\"");
    }

    /// The gripper column follows the events: open, closing for the closing
    /// time, closed while carrying, opening, open again.
    #[test]
    fn csv_shows_the_gripper_state_per_sample() {
        let scenario = afford_planner::scenario::default_scenario().unwrap();
        let plan = afford_planner::plan(&scenario, &Default::default()).unwrap();
        let csv = render_csv(&plan).unwrap();
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let column = header.iter().position(|h| *h == "gripper").unwrap();
        let first_subgoal: Vec<&str> = lines
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|row| row[0] == "0")
            .map(|row| row[column])
            .collect();
        let mut phases = first_subgoal.clone();
        phases.dedup();
        assert_eq!(phases, ["open", "closing", "closed", "opening", "open"]);
        let closing = first_subgoal.iter().filter(|s| **s == "closing").count();
        // 0.5 s at 100 Hz: the samples from the command's start up to its end.
        assert_eq!(closing, 50);
    }
}
