//! Serialising results and writing them: standard output, standard error
//! and the files of `-o` and `--svg`. Nothing here panics on a closed or
//! full stream, and a write that fails is exit 3 (`ExitKind::Output`).
//!
//! A file is written whole: to a temporary sibling, then renamed over the
//! path, so no reader ever sees half a plan. What the path names decides
//! how ([`destination`]): a regular file or nothing yet is replaced so; a
//! symlink is followed and its target replaced (the link stays a link); a
//! character device or a FIFO (`/dev/stdout`, a terminal, a named pipe) is
//! written to directly, as a stream, since a rename would put a regular
//! file in the place of the device node; a folder, a socket or a block
//! device is refused.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use afford_planner::timing::TrajectoryPoint;
use serde::Serialize;

use super::{ExitKind, Failure, OutputFormat};

/// Most symbolic links followed from an output path (Linux's own limit).
const MAX_SYMLINKS: usize = 40;

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
/// closes the pipe: that is not an error, the rest is dropped quietly; any
/// other failure (a full disk) is exit 3. Every command prints through
/// here, never with `print!` (which panics on a closed pipe).
pub fn print(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Failure::new(
            ExitKind::Output,
            format!("cannot write to standard output: {e}"),
        )),
        _ => Ok(()),
    }
}

/// Writes one line to standard error. Messages go here, never through
/// `eprintln!` (which panics on a closed or full stderr, exit 101): when
/// stderr cannot take the line, the line is dropped and the command goes on
/// to write its result and exit with its own code.
pub fn note(line: std::fmt::Arguments) {
    let mut err = std::io::stderr().lock();
    // Nowhere is left to report a failure to report.
    let _ = err.write_fmt(format_args!("{line}\n"));
}

/// How a result is written to a path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Destination {
    /// To a temporary sibling of this file, renamed over it: the path
    /// itself, or the target of the symlink(s) it names.
    Replace(PathBuf),
    /// Straight into the path, opened for writing: a character device or a
    /// FIFO.
    Stream,
}

/// How a result for `path` is written, or why it is not (`Err`: what the
/// path is). The kind is read through every symlink (`stat`: also through
/// `/dev/stdout`'s links into `/proc`, which name no file); only a regular
/// file is replaced, at its real path.
pub fn destination(path: &Path) -> Result<Destination, String> {
    let kind = match std::fs::metadata(path) {
        Ok(meta) => meta.file_type(),
        // Nothing there yet, or a symlink that leads nowhere: created at
        // the link's end.
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return link_end(path).map(Destination::Replace);
        }
        Err(e) => return Err(e.to_string()),
    };
    if kind.is_file() {
        let real = std::fs::canonicalize(path).map_err(|e| e.to_string())?;
        return Ok(Destination::Replace(real));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() || kind.is_fifo() {
            return Ok(Destination::Stream);
        }
        if kind.is_block_device() {
            return Err("is a block device (a disk): afford does not write over one".into());
        }
    }
    match kind.is_dir() {
        true => Err("is a folder: name a file in it".into()),
        false => Err(
            "is a socket or another special file: afford writes regular files, character devices and FIFOs"
                .into(),
        ),
    }
}

/// Where a path that names nothing yet is created: the path itself, or
/// the end of the chain of symlinks it starts (a relative link read from
/// the folder the link is in).
fn link_end(path: &Path) -> Result<PathBuf, String> {
    let mut at = path.to_path_buf();
    for _ in 0..MAX_SYMLINKS {
        let is_link = std::fs::symlink_metadata(&at).is_ok_and(|m| m.file_type().is_symlink());
        if !is_link {
            return Ok(at);
        }
        let next = std::fs::read_link(&at).map_err(|e| e.to_string())?;
        at = match at.parent() {
            Some(folder) if next.is_relative() => folder.join(next),
            _ => next,
        };
    }
    Err(format!(
        "more than {MAX_SYMLINKS} symbolic links lead on from it"
    ))
}

/// Writes `text` to `path` by its [`destination`], or to stdout when `path`
/// is `None`. A failure is exit 3 naming the path.
pub fn emit(text: &str, path: Option<&Path>) -> Result<(), Failure> {
    let Some(path) = path else {
        return print(text);
    };
    let written = destination(path).and_then(|to| {
        match to {
            Destination::Replace(target) => replace(text, &target),
            Destination::Stream => stream(text, path),
        }
        .map_err(|e| e.to_string())
    });
    written.map_err(|why| {
        Failure::new(
            ExitKind::Output,
            format!("{}: cannot write: {why}", path.display()),
        )
    })
}

/// Writes `text` to a temporary sibling of `target` and renames it over
/// `target`. The temporary is this process's own (`FILE.PID.partial`: two
/// runs writing one file never mix their halves) and is removed when the
/// write or the rename fails.
fn replace(text: &str, target: &Path) -> std::io::Result<()> {
    let mut tmp = target.as_os_str().to_owned();
    tmp.push(format!(".{}.partial", std::process::id()));
    let written = File::create(&tmp)
        .and_then(|mut f| f.write_all(text.as_bytes()))
        .and_then(|()| std::fs::rename(&tmp, target));
    if written.is_err() {
        // Best effort: the temporary may not exist; the error is the write's.
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// Writes `text` straight into the device or FIFO at `path` (a FIFO waits
/// for its reader, as for any program writing to one).
fn stream(text: &str, path: &Path) -> std::io::Result<()> {
    let mut file = OpenOptions::new().write(true).open(path)?;
    file.write_all(text.as_bytes())?;
    file.flush()
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

    /// A fresh folder for one test under the build's temporary folder.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("afford-output-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A character device is written to directly, never replaced: decided
    /// by `stat` alone (nothing is opened or written here: `/dev/zero` is
    /// only looked at).
    #[test]
    fn a_character_device_is_a_stream_never_replaced() {
        assert_eq!(destination(Path::new("/dev/zero")), Ok(Destination::Stream));
    }

    /// A file, a path naming nothing yet and a symlink (to a file, or to
    /// nothing yet) are replaced at the file's real path; the link stays.
    #[test]
    fn a_symlink_is_followed_and_its_target_replaced() {
        let dir = scratch("symlink");
        let file = dir.join("plan.json");
        std::fs::write(&file, "old").unwrap();
        let real = std::fs::canonicalize(&file).unwrap();
        assert_eq!(destination(&file), Ok(Destination::Replace(real.clone())));
        let link = dir.join("link.json");
        std::os::unix::fs::symlink("plan.json", &link).unwrap();
        assert_eq!(destination(&link), Ok(Destination::Replace(real)));
        let dangling = dir.join("dangling.json");
        std::os::unix::fs::symlink("new.json", &dangling).unwrap();
        assert_eq!(
            destination(&dangling),
            Ok(Destination::Replace(dir.join("new.json")))
        );
        emit("new\n", Some(&link)).unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "new\n");
    }

    /// A folder is refused saying so; a loop of symlinks is refused, not
    /// followed forever.
    #[test]
    fn a_folder_or_a_symlink_loop_is_refused_saying_what_it_is() {
        let dir = scratch("refused");
        assert!(destination(&dir).unwrap_err().contains("is a folder"));
        let (a, b) = (dir.join("a"), dir.join("b"));
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        let why = destination(&a).unwrap_err();
        assert!(why.contains("symbolic links"), "{why}");
    }

    /// A FIFO is a stream: written to directly, left a FIFO.
    #[test]
    fn a_fifo_is_written_as_a_stream_and_stays_a_fifo() {
        use std::os::unix::fs::FileTypeExt;
        let dir = scratch("fifo");
        let fifo = dir.join("plan.fifo");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        assert_eq!(destination(&fifo), Ok(Destination::Stream));
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
        };
        emit("through the pipe\n", Some(&fifo)).unwrap();
        assert_eq!(reader.join().unwrap(), "through the pipe\n");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    }

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
