//! `afford robots init` (a robot description drafted from a URDF and SRDF)
//! and `afford robots check` (the figures a description is judged by): thin
//! wrappers over `afford::robot_setup`. Exit codes: 0 written / passed, 1
//! a check failed, 2 bad input (the message names the file and element), 3
//! the description or scenario could not be written.

use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use afford::robot_setup::{self, InitOptions, check::CheckOptions};
use afford_collision::AcmSettings;

use super::output::{Destination, destination, emit, note, print};
use super::{ExitKind, Failure, RobotsCheckArgs, RobotsInitArgs};

pub fn init(args: &RobotsInitArgs) -> Result<(), Failure> {
    let bad = |e: String| Failure::new(ExitKind::BadInput, e);
    // Refuse an unusable destination before the slow part.
    for path in [&args.output, &args.scenario].into_iter().flatten() {
        regular(path)?;
    }
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("robot.yaml"));
    let start = Instant::now();
    let report = robot_setup::init(&InitOptions {
        urdf: args.urdf.clone(),
        srdf: args.srdf.clone(),
        output: output.clone(),
        packages: args.packages.paths(),
        acm: AcmSettings {
            samples: args.samples,
            ..AcmSettings::default()
        },
        assume_gripper: !args.no_assumed_gripper,
    })
    .map_err(|e| bad(format!("afford robots init: {e}")))?;
    let seconds = start.elapsed().as_secs_f64();
    for g in &report.guesses {
        note(format_args!("guessed: {g}"));
    }
    for d in &report.srdf_differences {
        note(format_args!("srdf: {d}"));
    }
    if let Some((path, text)) = &report.derived_urdf {
        if args.output.is_none() {
            return Err(bad(
                "afford robots init: the URDF has no gripper: the assumed one goes into a URDF beside the description; name it with -o DESCRIPTION (or pass --no-assumed-gripper)".into(),
            ));
        }
        regular(path)?;
        emit(text, Some(path))?;
    }
    emit(&report.description, args.output.as_deref())?;
    if let Some(path) = &args.scenario {
        let Some(camera) = &report.camera else {
            return Err(bad(format!(
                "{}: no scenario written: no table region in reach was found",
                path.display()
            )));
        };
        let dir = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        emit(
            &robot_setup::default_scenario(&output, dir, camera),
            Some(path),
        )?;
    }
    note(format_args!(
        "afford robots init: {} in {seconds:.1} s ({} arm(s), {} guess(es))",
        args.output
            .as_ref()
            .map_or("description".into(), |p| p.display().to_string()),
        report.model.arms().len(),
        report.guesses.len()
    ));
    Ok(())
}

/// `path` must be (or become) a regular file: a description is a file a
/// scenario names, never a stream.
fn regular(path: &Path) -> Result<(), Failure> {
    match destination(path) {
        Ok(Destination::Replace(_)) => Ok(()),
        Ok(Destination::Stream) => Err(Failure::new(
            ExitKind::Output,
            format!(
                "{}: cannot write: a device or FIFO; name a regular file",
                path.display()
            ),
        )),
        Err(why) => Err(Failure::new(
            ExitKind::Output,
            format!("{}: cannot write: {why}", path.display()),
        )),
    }
}

pub fn check(args: &RobotsCheckArgs) -> Result<(), Failure> {
    let options = CheckOptions {
        poses: args.poses,
        seed: args.seed,
        packages: args.packages.paths(),
        ..CheckOptions::default()
    };
    if !(1..=100_000).contains(&args.poses) {
        return Err(Failure::new(
            ExitKind::BadInput,
            "--poses: must be 1 ..= 100000",
        ));
    }
    let report = robot_setup::check::check(&args.description, &options)
        .map_err(|e| Failure::new(ExitKind::BadInput, format!("afford robots check: {e}")))?;
    let text = match args.json {
        true => {
            serde_json::to_string_pretty(&report)
                .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?
                + "\n"
        }
        false => table(&report),
    };
    print(&text)?;
    match report.passed {
        true => Ok(()),
        false => Err(Failure::new(
            ExitKind::CouldNotPlan,
            format!(
                "{}: {}",
                args.description.display(),
                report.failures.join("; ")
            ),
        )),
    }
}

fn table(r: &robot_setup::check::CheckReport) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "robot {}", r.robot);
    match &r.camera {
        Some(c) => {
            let _ = writeln!(
                o,
                "table region ({}): pixel_to_base {:?}, table_z {}",
                r.camera_source, c.pixel_to_base, c.table_z
            );
        }
        None => {
            let _ = writeln!(o, "table region: none in reach");
        }
    }
    let _ = writeln!(
        o,
        "reach          {:>5.1} %  ({} of {} tool-down poses, heights {:?} m above the table)",
        100.0 * r.reach.fraction,
        r.reach.reached,
        r.reach.poses,
        r.reach.heights
    );
    for p in &r.postures {
        let verdict = if p.self_collision_free {
            "free"
        } else {
            "SELF-COLLISION"
        };
        let _ = writeln!(o, "{:<14} {verdict}", p.posture);
    }
    for a in &r.ik {
        let _ = writeln!(
            o,
            "IK {:<11} {:>5.1} %  ({} of {} random reachable poses)",
            a.arm,
            100.0 * a.success_rate,
            a.solved,
            a.poses
        );
    }
    let _ = writeln!(o, "coverage (tolerance {} m):", r.coverage_tolerance_m);
    let _ = writeln!(
        o,
        "  {:<24} {:<9} {:>8} {:>12} {:>12}  mesh",
        "link", "kind", "samples", "max out m", "mean out m"
    );
    for c in &r.coverage {
        let _ = writeln!(
            o,
            "  {:<24} {:<9} {:>8} {:>12.6} {:>12.6}  {}",
            c.link, c.kind, c.samples, c.max_outside_m, c.mean_outside_m, c.mesh
        );
    }
    let _ = writeln!(o, "{}", if r.passed { "passed" } else { "FAILED" });
    for f in &r.failures {
        let _ = writeln!(o, "  {f}");
    }
    o
}
