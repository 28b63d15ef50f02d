//! `afford robots`: the built-in robots, their arms, DOF and reach; `afford
//! robots acm`: a robot's allowed-collision matrix (afford-collision `acm`).

use std::fmt::Write;
use std::path::Path;

use afford_collision::{AcmSettings, AllowedCollisionMatrix};
use afford_kinematics::RobotModel;

use super::output::print;
use super::{AcmArgs, ExitKind, Failure, RobotsArgs};

pub fn run(args: &RobotsArgs) -> Result<(), Failure> {
    let robots = afford_kinematics::builtin_robots()
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
    if args.json {
        let json = serde_json::to_string_pretty(&robots).expect("robot list serialises");
        return print(&(json + "\n"));
    }
    let mut out = String::new();
    for robot in &robots {
        let _ = writeln!(out, "{} ({} DOF)", robot.name, robot.dof);
        for arm in &robot.arms {
            let _ = writeln!(
                out,
                "  arm {:<6} {} DOF, reach ≤ {:.3} m, tool {}, joints {}",
                arm.name,
                arm.dof,
                arm.reach,
                arm.tool_link,
                arm.joints.join(" ")
            );
        }
    }
    print(&out)
}

/// Derives the matrix of a built-in robot or a description file and prints
/// the `allowed_collisions:` block (bad robot or settings: exit 2).
pub fn acm(args: &AcmArgs) -> Result<(), Failure> {
    let bad = |e: String| Failure::new(ExitKind::BadInput, e);
    let model = RobotModel::load_with(&args.robot, Path::new("."), &args.packages.paths())
        .map_err(|e| bad(e.to_string()))?;
    let settings = AcmSettings {
        samples: args.samples,
        seed: args.seed,
        clearance: args.clearance,
        ..AcmSettings::default()
    };
    let matrix = AllowedCollisionMatrix::derive(&model, &settings)
        .map_err(|e| bad(format!("afford robots acm: {e}")))?;
    print(&matrix.to_yaml())
}
