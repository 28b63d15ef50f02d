//! `afford validate`: parse a scenario and explain it without planning.

use std::fmt::Write;

use afford_kinematics::{IkSettings, RobotModel};
use afford_planner::PlanError;
use afford_planner::grid::{GridRequest, StateGrid};
use afford_planner::instruction::{Interpretation, interpret, subgoals};
use afford_planner::lift::LiftSettings;
use afford_planner::scenario::{PixelBox, Scenario};
use afford_planner::start::{self, FirstSubgoal};

use super::output::print;
use super::plan::{load, load_robot};
use super::{ExitKind, Failure, ValidateArgs};

pub fn run(args: &ValidateArgs) -> Result<(), Failure> {
    let scenario = load(args.scenario.as_deref())?;
    let robot = load_robot(&scenario, args.scenario.as_deref(), &args.packages.paths())?;
    let gripper = gripper_pixel(&scenario, &robot, args)?;
    print(&explain(&scenario, &robot, gripper, args.seed))?;
    // The scene is valid but the instruction cannot be executed: exit 1,
    // as `afford plan` does.
    interpret(&scenario, args.seed)
        .map(|_| ())
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))
}

/// The share of the image a box grown by `margin_m` on every side covers
/// (clipped to the image), 0 to 1: how much of the table a perimeter takes.
fn perimeter_share(s: &Scenario, b: PixelBox, margin_m: f64) -> f64 {
    let [mu, mv] = s.metres_per_pixel();
    let (w, h) = (f64::from(s.camera.width), f64::from(s.camera.height));
    let span = |lo: f64, len: f64, grow: f64, size: f64| {
        ((lo + len + grow).min(size) - (lo - grow).max(0.0)).max(0.0)
    };
    let along_u = span(b.u, b.w, margin_m / mu, w);
    let along_v = span(b.v, b.l, margin_m / mv, h);
    along_u * along_v / (w * h)
}

/// One line per perimeter (every hand, every sensitive object): its width
/// in pixels and the share of the table it covers.
fn perimeter_lines(s: &Scenario, out: &mut String) {
    let [mu, mv] = s.metres_per_pixel();
    let mut line = |what: &str, b: PixelBox, margin: f64| {
        let _ = writeln!(
            out,
            "  {what}: perimeter {margin:.3} m (≈{:.0} px along u, ≈{:.0} px along v) covers {:.0}% of the table",
            margin / mu,
            margin / mv,
            100.0 * perimeter_share(s, b, margin)
        );
    };
    for h in &s.hands {
        line(&format!("hand {}", h.name), h.bbox, s.safety.hand_margin);
    }
    for o in s.objects.iter().filter(|o| s.is_sensitive(o)) {
        line(
            &format!("sensitive {}", o.name),
            o.bbox,
            s.safety.sensitive_margin,
        );
    }
}

/// Where the gripper is in the image: `robot.start` when it is given alone;
/// otherwise from `robot.joints` (checked against the robot) or the home
/// rule, as `afford plan` does (bad input: exit 2, field named).
pub(super) fn gripper_pixel(
    s: &Scenario,
    robot: &RobotModel,
    args: &ValidateArgs,
) -> Result<[f64; 2], Failure> {
    let file = args.scenario.as_ref().map_or_else(
        || afford_planner::scenario::DEFAULT_SCENARIO_NAME.to_string(),
        |p| p.display().to_string(),
    );
    let bad_state = |issues| {
        let e = PlanError::RobotState {
            robot: robot.name().to_string(),
            issues,
        };
        Failure::new(ExitKind::BadInput, format!("{file}: {e}"))
    };
    if let (Some(start), None) = (s.robot.start, &s.robot.joints) {
        return Ok(start);
    }
    // The joint state first: it is bad input whatever the instruction says.
    let issues = start::check_joints(s, robot);
    if !issues.is_empty() {
        return Err(bad_state(issues));
    }
    let Some(object) = subgoals(s, args.seed)
        .ok()
        .and_then(|goals| s.object_index(&goals.first()?.object))
    else {
        return Ok(s.robot.start.unwrap_or_default());
    };
    let first = FirstSubgoal::moving(s, object, &LiftSettings::default());
    let state = start::resolve(s, robot, &first, &IkSettings::default()).map_err(bad_state)?;
    Ok(state.gripper_px)
}

fn explain(s: &Scenario, robot: &RobotModel, gripper: [f64; 2], seed: u64) -> String {
    let mut out = String::new();
    let [mu, mv] = s.metres_per_pixel();
    let px = |m: f64| m / mu.max(mv);
    let _ = writeln!(
        out,
        "scenario: {}",
        s.name.as_deref().unwrap_or("(unnamed)")
    );
    let _ = writeln!(
        out,
        "camera: {}x{} px, {:.2} mm/px along u, {:.2} mm/px along v, table at z = {:.3} m",
        s.camera.width,
        s.camera.height,
        mu * 1e3,
        mv * 1e3,
        s.camera.table_z
    );
    let _ = writeln!(
        out,
        "robot: {} ({}, {} DOF, arms {}), gripper at pixel ({:.1}, {:.1}){}",
        s.robot.model,
        robot.name(),
        robot.dof(),
        robot
            .arms()
            .iter()
            .map(|a| a.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        gripper[0],
        gripper[1],
        match (&s.robot.joints, s.robot.start) {
            (Some(_), None) => " (from robot.joints)",
            (None, None) => " (home)",
            _ => "",
        }
    );
    let _ = writeln!(out, "objects: {}", s.objects.len());
    for o in &s.objects {
        let sensitive = if s.is_sensitive(o) { ", sensitive" } else { "" };
        let _ = writeln!(
            out,
            "  {} ({} {}{sensitive}) at {:?}",
            o.name,
            o.color,
            o.shape,
            <[f64; 4]>::from(o.bbox)
        );
    }
    let _ = writeln!(
        out,
        "goals: {}",
        s.goals
            .iter()
            .map(|g| g.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(out, "hands: {}", s.hands.len());
    let m = &s.safety;
    let _ = writeln!(
        out,
        "safety margins: obstacle {:.3} m (≈{:.0} px), sensitive {:.3} m (≈{:.0} px), hand {:.3} m (≈{:.0} px)",
        m.obstacle_margin,
        px(m.obstacle_margin),
        m.sensitive_margin,
        px(m.sensitive_margin),
        m.hand_margin,
        px(m.hand_margin)
    );
    perimeter_lines(s, &mut out);
    let _ = writeln!(out, "instruction: \"{}\"", s.instruction);
    match interpret(s, seed) {
        Err(e) => {
            let _ = writeln!(out, "sub-goals: {e}");
        }
        Ok(Interpretation {
            subgoals: goals,
            skipped,
        }) => {
            let _ = writeln!(
                out,
                "sub-goals: {} (grids drawn on the scene as it is now)",
                goals.len()
            );
            for note in &skipped {
                let _ = writeln!(out, "  left where it is: {note}");
            }
            for (k, g) in goals.iter().enumerate() {
                let request = GridRequest {
                    object: s.object_index(&g.object).unwrap_or(0),
                    goal: s.goal_index(&g.goal).unwrap_or(0),
                    gripper,
                };
                let grid = StateGrid::build(s, request);
                let _ = writeln!(
                    out,
                    "  {}. {} → {}: grid {}x{} cells of {}x{} px",
                    k + 1,
                    g.object,
                    g.goal,
                    grid.rows,
                    grid.cols,
                    grid.cell_size[0],
                    grid.cell_size[1]
                );
                for line in grid.to_string().lines() {
                    let _ = writeln!(out, "     {line}");
                }
            }
            let _ = writeln!(
                out,
                "     legend: S start, T target, G goal, D drop cell, # obstacle or perimeter, H hand perimeter"
            );
        }
    }
    out
}
