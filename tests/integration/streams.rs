//! Output files and streams. `-o` and `--svg` write a temporary file and
//! rename it over the path only when the path is a regular file or names
//! nothing yet; a symlink is followed (its target replaced, the link kept),
//! a character device or a FIFO is written to directly (a rename made
//! `/dev/null` a regular file), a folder is refused (exit 3). A closed or
//! full stdout or stderr never panics (it was exit 101): the requested file
//! is still written, a lost result is exit 3. A FIFO given as input is
//! refused unread (it blocked forever). No test here names a path under
//! /dev as an output: devices are made in a scratch folder.

use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::util::{afford, assert_contains_all, repo, scratch_dir};

/// Runs afford with `stdout` and `stderr` as given; waits at most 60 s
/// (a run that blocks is killed and fails the test).
fn run_with(args: &[&str], stdout: Stdio, stderr: Stdio) -> Option<i32> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_afford"))
        .args(args)
        .current_dir(repo())
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr)
        .spawn()
        .expect("start afford");
    let started = Instant::now();
    while started.elapsed() < Duration::from_secs(60) {
        if let Some(status) = child.try_wait().expect("wait") {
            return status.code();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    panic!("afford {} still ran after 60 s", args.join(" "));
}

fn text(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

fn mkfifo(path: &Path) {
    let made = Command::new("mkfifo").arg(path).status().expect("mkfifo");
    assert!(made.success(), "mkfifo {}", path.display());
}

/// `-o` naming a character device leaves it a device. The device is made
/// in a scratch folder with mknod (the kernel's null device, 1:3), which
/// needs root, as CI and the developers' machines run; elsewhere the test
/// says so and checks nothing (the decision itself is tested on /dev/zero
/// by `stat` alone in src/cli/output.rs).
#[test]
fn output_to_a_character_device_writes_into_it_not_over_it() {
    let dir = scratch_dir("output-char-device");
    let device = dir.join("null");
    let made = Command::new("mknod")
        .arg(&device)
        .args(["c", "1", "3"])
        .status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mknod is not permitted here: the device case is left to the unit test");
        return;
    }
    for command in ["plan", "run"] {
        let mut args = vec![command];
        if command == "plan" {
            args.extend(["--until", "grid"]);
        }
        args.extend(["-o", text(&device), "--svg", text(&device)]);
        afford(&args).assert_code(0).assert_no_panic();
        let kind = std::fs::symlink_metadata(&device)
            .expect("still there")
            .file_type();
        assert!(
            kind.is_char_device(),
            "{command}: the device became {kind:?}"
        );
    }
    let names: Vec<String> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["null"], "left behind: {names:?}");
}

#[test]
fn output_through_a_symlink_replaces_its_target_not_the_link() {
    let dir = scratch_dir("output-symlink");
    let (target, link) = (dir.join("plan.json"), dir.join("latest.json"));
    std::fs::write(&target, "old").expect("write");
    std::os::unix::fs::symlink("plan.json", &link).expect("symlink");
    afford(&["plan", "--until", "grid", "-o", text(&link)]).assert_code(0);
    assert!(
        std::fs::symlink_metadata(&link)
            .expect("link")
            .file_type()
            .is_symlink()
    );
    let written = std::fs::read_to_string(&target).expect("target");
    assert!(written.starts_with('{'), "the target holds {written:?}");
}

#[test]
fn output_to_a_fifo_is_streamed_to_its_reader() {
    let dir = scratch_dir("output-fifo");
    let fifo = dir.join("plan.fifo");
    mkfifo(&fifo);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).expect("read the FIFO"))
    };
    let code = run_with(
        &["plan", "--until", "grid", "-o", text(&fifo)],
        Stdio::null(),
        Stdio::null(),
    );
    assert_eq!(code, Some(0));
    let streamed = reader.join().expect("reader");
    let plan: serde_json::Value = serde_json::from_str(&streamed).expect("a whole JSON plan");
    assert!(plan["subgoals"].is_array());
    assert!(
        std::fs::metadata(&fifo)
            .expect("fifo")
            .file_type()
            .is_fifo()
    );
}

/// `afford run … -o out.json 2>&1 | head -c 1` closed stderr: exit 101. Now
/// the lines are dropped, the file is written, the run's own code stands.
#[test]
fn a_closed_stderr_does_not_panic_and_the_output_file_is_written() {
    let dir = scratch_dir("closed-stderr");
    let out = dir.join("run.json");
    let (reader, writer) = std::io::pipe().expect("pipe");
    drop(reader);
    let code = run_with(
        &["run", "examples/sort-blue-squares.yaml", "-o", text(&out)],
        Stdio::null(),
        Stdio::from(writer),
    );
    assert_eq!(code, Some(0));
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).expect("written")).expect("JSON");
    assert_eq!(run["outcome"], "completed");
    // A failing command with nowhere to say why still exits with its code.
    let (reader, writer) = std::io::pipe().expect("pipe");
    drop(reader);
    let code = run_with(
        &["plan", "no-such-file.yaml"],
        Stdio::null(),
        Stdio::from(writer),
    );
    assert_eq!(code, Some(2));
}

/// `afford robots >/dev/full` exited 1 ("could not plan"); a result that
/// cannot be written is exit 3 with the reason on stderr. (/dev/full is
/// opened as the child's stdout, never named as an output path.)
#[test]
fn a_full_stdout_is_exit_3_saying_so() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("open /dev/full for writing");
    let dir = scratch_dir("full-stdout");
    let err = dir.join("stderr.txt");
    let code = run_with(
        &["robots"],
        Stdio::from(full),
        Stdio::from(std::fs::File::create(&err).expect("stderr file")),
    );
    assert_eq!(code, Some(3));
    let said = std::fs::read_to_string(&err).expect("stderr");
    assert_contains_all("stderr", &said, &["cannot write to standard output"]);
}

#[test]
fn a_fifo_given_as_scenario_or_plan_is_refused_not_waited_on() {
    let dir = scratch_dir("fifo-input");
    let (scenario, plan) = (dir.join("scene.yaml"), dir.join("plan.json"));
    mkfifo(&scenario);
    mkfifo(&plan);
    let err = dir.join("stderr.txt");
    for args in [
        vec!["plan", text(&scenario)],
        vec!["check", "examples/sort-blue-squares.yaml", text(&plan)],
    ] {
        let stderr = Stdio::from(std::fs::File::create(&err).expect("stderr file"));
        assert_eq!(run_with(&args, Stdio::null(), stderr), Some(2), "{args:?}");
        let said = std::fs::read_to_string(&err).expect("stderr");
        assert_contains_all(&args.join(" "), &said, &["FIFO", "not a regular file"]);
    }
}

/// A robot description that is a FIFO (`robot.model: robot.yaml`) is
/// refused like a scenario, not waited on.
#[test]
fn a_fifo_given_as_robot_description_is_refused_not_waited_on() {
    let dir = scratch_dir("fifo-robot");
    mkfifo(&dir.join("robot.yaml"));
    let yaml = std::fs::read_to_string(repo().join("examples/sort-blue-squares.yaml"))
        .expect("example")
        .replace("model: kuka_iiwa14", "model: robot.yaml");
    let scenario = dir.join("scene.yaml");
    std::fs::write(&scenario, yaml).expect("write");
    let err = dir.join("stderr.txt");
    let stderr = Stdio::from(std::fs::File::create(&err).expect("stderr file"));
    let code = run_with(&["plan", text(&scenario)], Stdio::null(), stderr);
    assert_eq!(code, Some(2));
    let said = std::fs::read_to_string(&err).expect("stderr");
    assert_contains_all("stderr", &said, &["robot.yaml", "FIFO"]);
}
