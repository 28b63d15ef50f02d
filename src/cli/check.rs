//! `afford check`: re-check a trajectory file against its scenario.

use std::path::Path;

use afford_kinematics::RobotModel;
use afford_planner::verify::{TrajectoryFile, check_trajectories};

use super::plan::{base_dir, load};
use super::{CheckArgs, ExitKind, Failure};

pub fn run(args: &CheckArgs) -> Result<(), Failure> {
    let scenario = load(Some(&args.scenario))?;
    let robot = RobotModel::load(&scenario.robot.model, &base_dir(Some(&args.scenario)))
        .map_err(|e| Failure::new(ExitKind::BadInput, format!("robot: {e}")))?;
    let file = read_trajectories(&args.trajectory)?;
    let violations = check_trajectories(&scenario, &robot, &file)
        .map_err(|e| Failure::new(ExitKind::BadInput, e))?;
    if violations.is_empty() {
        println!(
            "{}: {} sub-goal trajectories within limits and collision-free with every margin",
            args.trajectory.display(),
            file.subgoals.len()
        );
        return Ok(());
    }
    let list: Vec<String> = violations.iter().map(|v| format!("  - {v}")).collect();
    Err(Failure::new(
        ExitKind::CouldNotPlan,
        format!(
            "{}: {} violation(s):\n{}",
            args.trajectory.display(),
            violations.len(),
            list.join("\n")
        ),
    ))
}

fn read_trajectories(path: &Path) -> Result<TrajectoryFile, Failure> {
    let bad = |message: String| {
        Failure::new(ExitKind::BadInput, format!("{}: {message}", path.display()))
    };
    let text =
        std::fs::read_to_string(path).map_err(|e| bad(format!("cannot read the file: {e}")))?;
    let yaml = path.extension().is_some_and(|e| e == "yaml" || e == "yml");
    let parsed = if yaml {
        serde_saphyr::from_str(&text).map_err(|e| e.to_string())
    } else {
        serde_json::from_str(&text).map_err(|e| e.to_string())
    };
    parsed.map_err(|e| bad(format!("not a plan with trajectories: {e}")))
}
