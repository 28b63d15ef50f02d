//! `afford plan --svg`: one SVG picture of a plan.
//!
//! Left, the **top view** in camera pixels (v grows downwards): the image
//! border, the first sub-goal's state-grid lattice, every object filled in
//! its colour and drawn in its shape (circle, cylinder, hexagon, triangle,
//! star as a pentagon, others as their box; sensitive ones with a thick
//! dark-red outline and a `!`), the pointing pixel as an orange crosshair, the
//! goal boxes as brown outlines, hands in orange, and each element's safety
//! perimeter as a dashed rectangle grown by its margin (metres converted to
//! pixels with the camera calibration). Over the scene, per sub-goal in its
//! own colour: the discrete cell path (thin line through the visited cell
//! centres, a dot per cell), the smoothed tool path (the tool waypoints'
//! x, y mapped back to pixels; thick, translucent), a ring at the start and a
//! cross with the sub-goal's number where the object is released (its own
//! spot in the box, so pieces in one box do not pile up). Each sub-goal that
//! could not be planned marks its object with a red ✗ and its letter. The
//! legend under the view names each sub-goal's object, goal and arm, and
//! lists the unsolved ones by letter with their reasons. A plan where
//! nothing could be planned is drawn too (scene, failures, legend).
//!
//! Right (only with a robot model and at least one timed trajectory), one
//! row per joint: position against time with the joint's position limits,
//! and velocity against time with its ± velocity limits, limits dashed. The
//! sub-goals are concatenated on one time axis (each starts and ends at
//! rest), each segment drawn in its sub-goal's colour; grey verticals mark
//! the gripper closing and opening.
//!
//! The output is deterministic: the same plan gives the same bytes. Text is
//! left to the SVG viewer's sans-serif font (no font is embedded).

use afford_kinematics::RobotModel;
use afford_planner::Plan;
use afford_planner::plan::SubgoalPlan;
use afford_planner::scenario::Scenario;
use plotters::coord::Shift;
use plotters::prelude::*;

mod joints;
mod top_view;

use joints::JointRows;
use top_view::TopView;

/// Why a picture could not be drawn.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PictureError(pub String);

impl std::fmt::Display for PictureError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot draw the plan: {}", self.0)
    }
}

impl std::error::Error for PictureError {}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for PictureError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        Self(e.to_string())
    }
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type Res = Result<(), PictureError>;

/// Colours of sub-goals 1, 2, 3, … (cycled): chosen apart from the object
/// colours and the hand orange.
pub const SUBGOAL_COLOURS: [RGBColor; 6] = [
    RGBColor(0x1b, 0x9e, 0x77),
    RGBColor(0x75, 0x70, 0xb3),
    RGBColor(0xe7, 0x29, 0x8a),
    RGBColor(0x66, 0xa6, 0x1e),
    RGBColor(0x8c, 0x5a, 0x1d),
    RGBColor(0x44, 0x44, 0x44),
];

/// The colour of sub-goal `k` (0-based).
pub fn subgoal_colour(k: usize) -> RGBColor {
    SUBGOAL_COLOURS[k % SUBGOAL_COLOURS.len()]
}

const MARGIN: i32 = 20;
const TITLE_H: i32 = 40;
const VIEW_MAX: [f64; 2] = [640.0, 520.0];
const LINE_H: i32 = 18;
const PANEL_W: i32 = 330;
const ROW_H: i32 = 96;
const HAND: RGBColor = RGBColor(0xf5, 0x7c, 0x00);
const GOAL: RGBColor = RGBColor(0x8d, 0x6e, 0x63);
const SENSITIVE: RGBColor = RGBColor(0xb0, 0x00, 0x20);
const LIMIT: RGBColor = RGBColor(0xc6, 0x28, 0x28);

/// The whole picture of `plan` on `scenario` as one SVG document. Without
/// `robot`, without any timed trajectory, or when `robot` lacks a joint the
/// plan moves, only the top view is drawn.
pub fn plan_svg(
    scenario: &Scenario,
    plan: &Plan,
    robot: Option<&RobotModel>,
) -> Result<String, PictureError> {
    let view = TopView::new(scenario);
    let joints = robot.and_then(|r| JointRows::new(r, plan));
    let left_w = view.size.0.max(560);
    let left_h = view.size.1 + LINE_H * (legend_lines(plan) + 1);
    let right = joints
        .as_ref()
        .map_or((0, 0), |j| (2 * PANEL_W + MARGIN, j.height()));
    let width = (2 * MARGIN + left_w + right.0) as u32;
    let height = (2 * MARGIN + TITLE_H + left_h.max(right.1)) as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE)?;
        title(&root, scenario, plan, joints.is_some())?;
        view.draw(&root, plan)?;
        legend(
            &root,
            scenario,
            plan,
            MARGIN + TITLE_H + view.size.1 + LINE_H,
        )?;
        if let Some(j) = &joints {
            j.draw(&root, plan, MARGIN + left_w + MARGIN)?;
        }
        root.present()?;
    }
    Ok(svg)
}

fn text_style(size: f64, colour: RGBColor) -> TextStyle<'static> {
    ("sans-serif", size).into_font().color(&colour)
}

fn title(root: &Area, scenario: &Scenario, plan: &Plan, with_joints: bool) -> Res {
    let name = scenario.name.as_deref().unwrap_or(&plan.scenario);
    let line = format!(
        "afford plan · {name} · seed {} · until {} · \"{}\"",
        plan.seed,
        format!("{:?}", plan.until).to_lowercase(),
        scenario.instruction
    );
    root.draw_text(&line, &text_style(17.0, BLACK), (MARGIN, MARGIN))?;
    let sub = match with_joints {
        true => {
            "top view in camera pixels (left) · joint trajectories of all sub-goals back to back on one time axis, coloured by sub-goal; dotted grey: gripper closes / opens (right)"
        }
        false => {
            "top view in camera pixels (no timed trajectory or no robot model: no joint curves)"
        }
    };
    root.draw_text(
        sub,
        &text_style(13.0, RGBColor(90, 90, 90)),
        (MARGIN, MARGIN + 20),
    )?;
    Ok(())
}

/// The letter of unsolved sub-goal `k` (0-based): a, b, …, z, then a2, b2, ….
fn failure_letter(k: usize) -> String {
    let letter = char::from(b'a' + (k % 26) as u8);
    match k / 26 {
        0 => letter.to_string(),
        n => format!("{letter}{}", n + 1),
    }
}

fn legend_lines(plan: &Plan) -> i32 {
    (2 + plan.subgoals.len() + plan.unsolved.len()) as i32
}

/// Symbol key, one line per sub-goal (object → goal, arm, cells, duration)
/// and one per unsolved sub-goal.
fn legend(root: &Area, scenario: &Scenario, plan: &Plan, top: i32) -> Res {
    let grey = RGBColor(70, 70, 70);
    let key = "thin line + dots: discrete cell path · thick translucent: smoothed tool path · ring: start · ×: drop";
    root.draw_text(key, &text_style(12.0, grey), (MARGIN, top))?;
    let key2 = "dashed: safety perimeters (grey objects, brown boxes, red sensitive, orange hands) · grid: first sub-goal's cells · u right, v down";
    root.draw_text(key2, &text_style(12.0, grey), (MARGIN, top + LINE_H))?;
    let mut y = top + 2 * LINE_H + 4;
    for (k, sub) in plan.subgoals.iter().enumerate() {
        let colour = subgoal_colour(k);
        root.draw(&Rectangle::new(
            [(MARGIN, y + 2), (MARGIN + 14, y + 12)],
            colour.filled(),
        ))?;
        root.draw_text(
            &subgoal_line(k, sub, &scenario.robot.model),
            &text_style(13.0, BLACK),
            (MARGIN + 20, y),
        )?;
        y += LINE_H;
    }
    for (k, u) in plan.unsolved.iter().enumerate() {
        let line = format!(
            "✗ {}. {} → {}: {} [{}]",
            failure_letter(k),
            u.object,
            u.goal,
            u.reason,
            u.refusal.kind()
        );
        let line = clip(&line, 110);
        root.draw_text(&line, &text_style(13.0, SENSITIVE), (MARGIN, y))?;
        y += LINE_H;
    }
    Ok(())
}

fn subgoal_line(k: usize, sub: &SubgoalPlan, robot: &str) -> String {
    let arm = match &sub.arm {
        Some(arm) => format!("{arm} of {robot}"),
        None => "no arm chosen (stopped before joints)".to_string(),
    };
    let mut line = format!(
        "{}. {} → {} · arm: {arm} · {} cells",
        k + 1,
        sub.object,
        sub.goal,
        sub.cells.len()
    );
    if let Some(t) = &sub.trajectory {
        line.push_str(&format!(" · {:.2} s", t.duration()));
    }
    line
}

fn clip(text: &str, max: usize) -> String {
    match text.chars().count() > max {
        true => text.chars().take(max - 1).chain(['…']).collect(),
        false => text.to_string(),
    }
}
