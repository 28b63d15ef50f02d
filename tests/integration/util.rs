//! Shared helpers: paths into the repository, running the `afford` binary and
//! checking what it printed.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root (the facade crate's manifest directory).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A path under `tests/fixtures/`.
pub fn fixture(relative: &str) -> PathBuf {
    repo().join("tests").join("fixtures").join(relative)
}

/// A fresh, empty scratch directory for one test.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("afford-integration")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch directory");
    dir
}

/// What one run of the `afford` binary did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Run {
    /// What was run, for failure messages.
    pub command: String,
    /// Exit code; `None` when killed by a signal.
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    /// Asserts the exit code, showing everything the command printed when it
    /// differs.
    pub fn assert_code(&self, code: i32) -> &Self {
        assert_eq!(
            self.code,
            Some(code),
            "`{}` exited with {:?}, expected {code}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.command,
            self.code,
            self.stdout,
            self.stderr
        );
        self
    }

    /// Asserts that nothing on stderr looks like a Rust panic.
    pub fn assert_no_panic(&self) -> &Self {
        for needle in ["panicked", "RUST_BACKTRACE", "stack backtrace"] {
            assert!(
                !self.stderr.contains(needle),
                "`{}` panicked:\n{}",
                self.command,
                self.stderr
            );
        }
        self
    }

    /// Parses stdout as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(&self.stdout).unwrap_or_else(|e| {
            panic!(
                "`{}` did not print JSON ({e}):\n{}",
                self.command, self.stdout
            )
        })
    }
}

/// Runs the `afford` binary with `args` from the repository root.
pub fn afford(args: &[&str]) -> Run {
    let output = Command::new(env!("CARGO_BIN_EXE_afford"))
        .args(args)
        .current_dir(repo())
        .env_remove("RUST_BACKTRACE")
        .env_remove("RUST_LIB_BACKTRACE")
        .output()
        .expect("run the afford binary");
    Run {
        command: format!("afford {}", args.join(" ")),
        code: output.status.code(),
        stdout: String::from_utf8(output.stdout).expect("stdout is UTF-8"),
        stderr: String::from_utf8(output.stderr).expect("stderr is UTF-8"),
    }
}

/// `afford` with a path argument among plain ones.
pub fn afford_with_path(before: &[&str], path: &Path, after: &[&str]) -> Run {
    let path = path.to_str().expect("UTF-8 path");
    let args: Vec<&str> = before
        .iter()
        .copied()
        .chain([path])
        .chain(after.iter().copied())
        .collect();
    afford(&args)
}

/// Asserts that `haystack` contains every one of `needles`.
#[track_caller]
pub fn assert_contains_all(what: &str, haystack: &str, needles: &[&str]) {
    let missing: Vec<&&str> = needles.iter().filter(|n| !haystack.contains(**n)).collect();
    assert!(missing.is_empty(), "{what} lacks {missing:?}:\n{haystack}");
}

/// Plans `scenario` to `plan.json` in `dir` (exit 0 expected) and returns
/// the file's path and its JSON.
pub fn plan_to_file(scenario: &Path, dir: &Path) -> (PathBuf, serde_json::Value) {
    let out = dir.join("plan.json");
    afford_with_path(
        &["plan"],
        scenario,
        &["-o", out.to_str().expect("UTF-8 path")],
    )
    .assert_code(0);
    let text = std::fs::read_to_string(&out).expect("plan written");
    (out, serde_json::from_str(&text).expect("plan is JSON"))
}

/// Adds `by` to a number of a plan's JSON (a joint position) in place.
pub fn nudge(position: &mut serde_json::Value, by: f64) {
    *position = serde_json::json!(position.as_f64().expect("position") + by);
}
