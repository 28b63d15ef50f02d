//! `afford export-mdp`: the grid MDPs of a scenario's sub-goals or of the
//! benchmark's generated scenes, one JSON file each (format in
//! docs/mdp-export.md), for learners outside afford.

use std::path::Path;

use afford_bench::cql::generated_export;
use afford_planner::export::{MdpExport, scenario_exports};

use super::output::{emit, note};
use super::plan::{load, load_robot};
use super::validate::gripper_pixel;
use super::{ExitKind, ExportMdpArgs, Failure, ValidateArgs};

/// Most generated scenes one call writes.
const MAX_GENERATED: usize = 100_000;

pub fn run(args: &ExportMdpArgs) -> Result<(), Failure> {
    let exports = match args.generated {
        Some(0) => {
            return Err(Failure::new(
                ExitKind::BadInput,
                "--generated must be at least 1",
            ));
        }
        Some(n) if n > MAX_GENERATED => {
            return Err(Failure::new(
                ExitKind::BadInput,
                format!("--generated must be at most {MAX_GENERATED}, got {n}"),
            ));
        }
        Some(n) => (0..n)
            .map(|k| generated_export(args.seed, k, args.learner_stats))
            .collect(),
        None => from_scenario(args)?,
    };
    std::fs::create_dir_all(&args.output).map_err(|e| {
        Failure::new(
            ExitKind::BadInput,
            format!("{}: cannot create: {e}", args.output.display()),
        )
    })?;
    for export in &exports {
        write(&args.output, export)?;
    }
    note(format_args!(
        "afford: wrote {} MDP files to {}",
        exports.len(),
        args.output.display()
    ));
    Ok(())
}

/// One export per sub-goal of the scenario file (or the default scenario),
/// the gripper where `afford validate` puts it.
fn from_scenario(args: &ExportMdpArgs) -> Result<Vec<MdpExport>, Failure> {
    if args.learner_stats {
        return Err(Failure::new(
            ExitKind::BadInput,
            "--learner-stats needs --generated N",
        ));
    }
    let path = args.scenario.as_deref();
    let scenario = load(path)?;
    let robot = load_robot(
        &scenario,
        path,
        &afford_kinematics::PackagePaths::new(Vec::new()),
    )?;
    let validate = ValidateArgs {
        scenario: args.scenario.clone(),
        seed: args.seed,
        packages: Default::default(),
    };
    let gripper = gripper_pixel(&scenario, &robot, &validate)?;
    let name = path.and_then(Path::file_stem).map_or_else(
        || "default".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    scenario_exports(&scenario, gripper, args.seed, &name)
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))
}

fn write(dir: &Path, export: &MdpExport) -> Result<(), Failure> {
    let text = serde_json::to_string(export).map_err(|e| {
        Failure::new(
            ExitKind::CouldNotPlan,
            format!("cannot serialise {}: {e}", export.name),
        )
    })?;
    emit(
        &(text + "\n"),
        Some(&dir.join(format!("{}.json", export.name))),
    )
}
