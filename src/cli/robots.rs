//! `afford robots`: the built-in robots, their arms, DOF and reach.

use std::fmt::Write;

use super::output::print;
use super::{ExitKind, Failure, RobotsArgs};

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
