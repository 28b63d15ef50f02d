//! `afford robots`: the built-in robots, their arms, DOF and reach.

use super::{ExitKind, Failure, RobotsArgs};

pub fn run(args: &RobotsArgs) -> Result<(), Failure> {
    let robots = afford_kinematics::builtin_robots()
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&robots).expect("robot list serialises")
        );
        return Ok(());
    }
    for robot in &robots {
        println!("{} ({} DOF)", robot.name, robot.dof);
        for arm in &robot.arms {
            println!(
                "  arm {:<6} {} DOF, reach ≤ {:.3} m, tool {}, joints {}",
                arm.name,
                arm.dof,
                arm.reach,
                arm.tool_link,
                arm.joints.join(" ")
            );
        }
    }
    Ok(())
}
