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
use afford_planner::scenario::{PixelBox, Scenario};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

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

/// Pixel-to-canvas mapping of the camera image.
struct TopView<'s> {
    scenario: &'s Scenario,
    origin: (i32, i32),
    scale: f64,
    size: (i32, i32),
}

impl<'s> TopView<'s> {
    fn new(scenario: &'s Scenario) -> Self {
        let (w, h) = (scenario.camera.width as f64, scenario.camera.height as f64);
        let scale = (VIEW_MAX[0] / w).min(VIEW_MAX[1] / h);
        let size = ((w * scale).round() as i32, (h * scale).round() as i32);
        Self {
            scenario,
            origin: (MARGIN, MARGIN + TITLE_H),
            scale,
            size,
        }
    }

    fn at(&self, [u, v]: [f64; 2]) -> (i32, i32) {
        (
            self.origin.0 + (u * self.scale).round() as i32,
            self.origin.1 + (v * self.scale).round() as i32,
        )
    }

    fn corners(&self, b: &PixelBox) -> [(i32, i32); 2] {
        [self.at([b.u, b.v]), self.at([b.u + b.w, b.v + b.l])]
    }

    /// The closed outline of a box, for dashed paths.
    fn outline(&self, b: &PixelBox) -> Vec<(i32, i32)> {
        let [(x0, y0), (x1, y1)] = self.corners(b);
        vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    }

    fn draw(&self, root: &Area, plan: &Plan) -> Res {
        let s = self.scenario;
        let image = PixelBox::from([0.0, 0.0, s.camera.width as f64, s.camera.height as f64]);
        root.draw(&Rectangle::new(
            self.corners(&image),
            RGBColor(250, 250, 247).filled(),
        ))?;
        if let Some(first) = plan.subgoals.first() {
            self.lattice(root, first)?;
        }
        self.goals(root)?;
        self.objects(root)?;
        self.hands(root)?;
        for (k, sub) in plan.subgoals.iter().enumerate() {
            self.route(root, k, sub)?;
        }
        self.failures(root, plan)?;
        if let Some(p) = s.pointing {
            self.pointing(root, p)?;
        }
        root.draw(&Rectangle::new(self.corners(&image), BLACK.stroke_width(1)))?;
        Ok(())
    }

    /// A red ✗ and the failure's letter (a, b, …, as in the legend) over
    /// each object whose sub-goal could not be planned.
    fn failures(&self, root: &Area, plan: &Plan) -> Res {
        for (k, u) in plan.unsolved.iter().enumerate() {
            let Some(i) = self.scenario.object_index(&u.object) else {
                continue;
            };
            let b = self.scenario.objects[i].bbox;
            let centre = self.at(b.centre());
            root.draw(&Cross::new(centre, 9, SENSITIVE.stroke_width(4)))?;
            let style = text_style(14.0, SENSITIVE).pos(Pos::new(HPos::Left, VPos::Bottom));
            root.draw_text(&failure_letter(k), &style, (centre.0 + 10, centre.1 - 8))?;
        }
        Ok(())
    }

    /// The pixel the person points at: an orange crosshair and a label.
    fn pointing(&self, root: &Area, p: [f64; 2]) -> Res {
        let c = self.at(p);
        let style = HAND.stroke_width(2);
        root.draw(&Circle::new(c, 9, style))?;
        root.draw(&PathElement::new([(c.0 - 14, c.1), (c.0 + 14, c.1)], style))?;
        root.draw(&PathElement::new([(c.0, c.1 - 14), (c.0, c.1 + 14)], style))?;
        let label = text_style(11.0, HAND).pos(Pos::new(HPos::Left, VPos::Top));
        root.draw_text("pointing", &label, (c.0 + 10, c.1 + 4))?;
        Ok(())
    }

    /// The outline of an object's shape inside its box, canvas points.
    fn shape(&self, shape: &str, b: &PixelBox) -> Shape {
        let [cu, cv] = b.centre();
        let (ru, rv) = (b.w / 2.0, b.l / 2.0);
        let polygon = |n: usize, turn: f64| {
            let pts = (0..n).map(|i| {
                let a = turn + std::f64::consts::TAU * i as f64 / n as f64;
                self.at([cu + ru * a.cos(), cv + rv * a.sin()])
            });
            Shape::Polygon(pts.collect())
        };
        match shape.to_ascii_lowercase().as_str() {
            "circle" | "cylinder" | "disc" | "ball" => {
                let r = (ru.min(rv) * self.scale).round() as i32;
                Shape::Circle(self.at([cu, cv]), r.max(1))
            }
            "hexagon" => polygon(6, 0.0),
            "triangle" => polygon(3, -std::f64::consts::FRAC_PI_2),
            "star" | "pentagon" => polygon(5, -std::f64::consts::FRAC_PI_2),
            _ => Shape::Box(self.corners(b)),
        }
    }

    fn draw_shape(&self, root: &Area, shape: &Shape, style: ShapeStyle) -> Res {
        match shape {
            Shape::Circle(c, r) => root.draw(&Circle::new(*c, *r, style))?,
            Shape::Polygon(pts) if style.filled => root.draw(&Polygon::new(pts.clone(), style))?,
            Shape::Polygon(pts) => {
                let closed: Vec<_> = pts.iter().chain(pts.first()).copied().collect();
                root.draw(&PathElement::new(closed, style))?
            }
            Shape::Box(corners) => root.draw(&Rectangle::new(*corners, style))?,
        }
        Ok(())
    }

    /// The first sub-goal's cell lattice, clipped to the image.
    fn lattice(&self, root: &Area, sub: &SubgoalPlan) -> Res {
        let (w, h) = (
            self.scenario.camera.width as f64,
            self.scenario.camera.height as f64,
        );
        let [ou, ov] = sub.grid.origin_px;
        let [cw, cl] = sub.grid.cell_px;
        let style = RGBColor(215, 215, 215).stroke_width(1);
        for c in 0..=sub.grid.size[1] {
            let u = (ou + c as f64 * cw).clamp(0.0, w);
            root.draw(&PathElement::new(
                [self.at([u, 0.0]), self.at([u, h])],
                style,
            ))?;
        }
        for r in 0..=sub.grid.size[0] {
            let v = (ov + r as f64 * cl).clamp(0.0, h);
            root.draw(&PathElement::new(
                [self.at([0.0, v]), self.at([w, v])],
                style,
            ))?;
        }
        Ok(())
    }

    /// The box grown by a margin in metres (converted to pixels along u
    /// and v), clipped to the image: the grid sees nothing outside it.
    fn grow(&self, b: &PixelBox, metres: f64) -> PixelBox {
        let [mu, mv] = self.scenario.metres_per_pixel();
        let g = b.grown(metres / mu, metres / mv);
        let (w, h) = (
            self.scenario.camera.width as f64,
            self.scenario.camera.height as f64,
        );
        let (u0, v0) = (g.u.max(0.0), g.v.max(0.0));
        let (u1, v1) = ((g.u + g.w).min(w), (g.v + g.l).min(h));
        PixelBox::from([u0, v0, u1 - u0, v1 - v0])
    }

    fn perimeter(&self, root: &Area, b: &PixelBox, metres: f64, colour: RGBColor) -> Res {
        let outline = self.outline(&self.grow(b, metres));
        root.draw(&DashedPathElement::new(
            outline,
            5,
            4,
            colour.stroke_width(1),
        ))?;
        Ok(())
    }

    fn label(&self, root: &Area, b: &PixelBox, text: &str, colour: RGBColor) -> Res {
        let (x, y) = self.at([b.u + b.w / 2.0, b.v + b.l]);
        let style = text_style(11.0, colour).pos(Pos::new(HPos::Center, VPos::Top));
        root.draw_text(text, &style, (x, y + 2))?;
        Ok(())
    }

    fn goals(&self, root: &Area) -> Res {
        let margin = self.scenario.safety.obstacle_margin;
        for g in &self.scenario.goals {
            root.draw(&Rectangle::new(
                self.corners(&g.bbox),
                GOAL.mix(0.08).filled(),
            ))?;
            root.draw(&Rectangle::new(self.corners(&g.bbox), GOAL.stroke_width(3)))?;
            self.perimeter(root, &g.bbox, margin, GOAL)?;
            let (x, y) = self.at([g.bbox.u + 4.0 / self.scale, g.bbox.v + 4.0 / self.scale]);
            root.draw_text(&g.name, &text_style(12.0, GOAL), (x, y))?;
        }
        Ok(())
    }

    fn objects(&self, root: &Area) -> Res {
        let s = self.scenario;
        for o in &s.objects {
            let sensitive = s.is_sensitive(o);
            let fill = object_colour(&o.color);
            let shape = self.shape(&o.shape, &o.bbox);
            self.draw_shape(root, &shape, fill.filled())?;
            let (edge, width) = if sensitive {
                (SENSITIVE, 3)
            } else {
                (BLACK, 1)
            };
            self.draw_shape(root, &shape, edge.stroke_width(width))?;
            let (margin, dash) = match sensitive {
                true => (s.safety.sensitive_margin, SENSITIVE),
                false => (s.safety.obstacle_margin, RGBColor(110, 110, 110)),
            };
            self.perimeter(root, &o.bbox, margin, dash)?;
            match sensitive {
                true => self.label(
                    root,
                    &o.bbox,
                    &format!("! {} (sensitive)", o.name),
                    SENSITIVE,
                )?,
                false => self.label(root, &o.bbox, &o.name, RGBColor(60, 60, 60))?,
            }
        }
        Ok(())
    }

    fn hands(&self, root: &Area) -> Res {
        let margin = self.scenario.safety.hand_margin;
        for h in &self.scenario.hands {
            root.draw(&Rectangle::new(
                self.corners(&h.bbox),
                HAND.mix(0.55).filled(),
            ))?;
            root.draw(&Rectangle::new(self.corners(&h.bbox), HAND.stroke_width(2)))?;
            self.perimeter(root, &h.bbox, margin, HAND)?;
            self.label(root, &h.bbox, &format!("hand: {}", h.name), HAND)?;
        }
        Ok(())
    }

    /// One sub-goal: smoothed tool path, cell path, start ring, drop cross.
    fn route(&self, root: &Area, k: usize, sub: &SubgoalPlan) -> Res {
        let colour = subgoal_colour(k);
        if let Some(motion) = &sub.waypoints {
            let xy = motion
                .waypoints
                .iter()
                .map(|w| [w.position[0], w.position[1]]);
            let pts = dedup(xy.map(|p| self.at(self.scenario.base_to_pixel(p))));
            root.draw(&PathElement::new(pts, colour.mix(0.45).stroke_width(6)))?;
        }
        let cells = dedup(sub.path_px.iter().map(|&p| self.at(p)));
        root.draw(&PathElement::new(cells.clone(), colour.stroke_width(2)))?;
        for &c in &cells {
            root.draw(&Circle::new(c, 3, colour.filled()))?;
        }
        if let Some(&start) = cells.first() {
            // The release spot, not the drop cell's centre: pieces put in
            // one box each get their own marker.
            let drop = self.at(sub.release_px);
            root.draw(&Circle::new(start, 8, colour.stroke_width(2)))?;
            root.draw(&Cross::new(drop, 7, colour.stroke_width(3)))?;
            let number = text_style(14.0, colour).pos(Pos::new(HPos::Left, VPos::Bottom));
            root.draw_text(&format!("{}", k + 1), &number, (drop.0 + 8, drop.1 - 6))?;
        }
        Ok(())
    }
}

/// An object's outline on the canvas.
enum Shape {
    Circle((i32, i32), i32),
    Polygon(Vec<(i32, i32)>),
    Box([(i32, i32); 2]),
}

/// The letter of unsolved sub-goal `k` (0-based): a, b, …, z, then a2, b2, ….
fn failure_letter(k: usize) -> String {
    let letter = char::from(b'a' + (k % 26) as u8);
    match k / 26 {
        0 => letter.to_string(),
        n => format!("{letter}{}", n + 1),
    }
}

/// Drops consecutive repeats (vertical moves map to one pixel).
fn dedup(points: impl Iterator<Item = (i32, i32)>) -> Vec<(i32, i32)> {
    let mut out: Vec<(i32, i32)> = Vec::new();
    for p in points {
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    out
}

/// Fill colour of an object named by its colour word.
fn object_colour(name: &str) -> RGBColor {
    match name.to_ascii_lowercase().as_str() {
        "blue" => RGBColor(0x42, 0x7b, 0xd9),
        "red" => RGBColor(0xe0, 0x45, 0x3a),
        "yellow" => RGBColor(0xf2, 0xd0, 0x24),
        "green" => RGBColor(0x4c, 0xaf, 0x50),
        "orange" => RGBColor(0xff, 0x98, 0x00),
        "purple" | "violet" => RGBColor(0x8e, 0x44, 0xad),
        "black" => RGBColor(0x21, 0x21, 0x21),
        "white" => RGBColor(0xfa, 0xfa, 0xfa),
        "pink" => RGBColor(0xf4, 0x8f, 0xb1),
        "brown" => RGBColor(0x79, 0x55, 0x48),
        _ => RGBColor(0x9e, 0x9e, 0x9e),
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

/// One joint's row: name, limits and which sub-goals move it (index into
/// that sub-goal's joint vector).
struct JointRow {
    name: String,
    lower: f64,
    upper: f64,
    velocity: f64,
    columns: Vec<Option<usize>>,
}

/// The joint panels: rows for every joint any timed sub-goal moves, and the
/// time offset of each sub-goal on the shared axis.
struct JointRows {
    rows: Vec<JointRow>,
    offsets: Vec<f64>,
    total: f64,
}

/// Index of `name`'s row, adding it (with the robot's limits) when new;
/// `None` when the robot has no such joint.
fn row_of(rows: &mut Vec<JointRow>, robot: &RobotModel, name: &str, n: usize) -> Option<usize> {
    if let Some(r) = rows.iter().position(|r| r.name == name) {
        return Some(r);
    }
    let joint = robot.joints().iter().find(|j| j.name == name)?;
    rows.push(JointRow {
        name: name.to_string(),
        lower: joint.lower,
        upper: joint.upper,
        velocity: joint.velocity,
        columns: vec![None; n],
    });
    Some(rows.len() - 1)
}

impl JointRows {
    fn new(robot: &RobotModel, plan: &Plan) -> Option<Self> {
        let mut offsets = Vec::new();
        let mut total = 0.0;
        for sub in &plan.subgoals {
            offsets.push(total);
            total += sub.trajectory.as_ref().map_or(0.0, |t| t.duration());
        }
        let mut rows: Vec<JointRow> = Vec::new();
        for (k, sub) in plan.subgoals.iter().enumerate() {
            let (Some(_), Some(names)) = (&sub.trajectory, &sub.joint_names) else {
                continue;
            };
            for (i, name) in names.iter().enumerate() {
                let row = row_of(&mut rows, robot, name, plan.subgoals.len())?;
                rows[row].columns[k] = Some(i);
            }
        }
        (!rows.is_empty() && total > 0.0).then_some(Self {
            rows,
            offsets,
            total,
        })
    }

    fn height(&self) -> i32 {
        LINE_H * 2 + ROW_H * self.rows.len() as i32 + 30
    }

    fn draw(&self, root: &Area, plan: &Plan, left: i32) -> Res {
        let top = MARGIN + TITLE_H;
        let heads = [
            "joint position (rad), dashed: position limits",
            "joint velocity (rad/s), dashed: ± velocity limits",
        ];
        for (c, head) in heads.iter().enumerate() {
            let x = left + c as i32 * PANEL_W + 50;
            root.draw_text(head, &text_style(13.0, BLACK), (x, top))?;
        }
        let rows_top = top + LINE_H + 4;
        for (r, row) in self.rows.iter().enumerate() {
            let last = r + 1 == self.rows.len();
            let h = ROW_H + if last { 30 } else { 0 };
            let y = rows_top + r as i32 * ROW_H;
            for velocity in [false, true] {
                let x = left + i32::from(velocity) * PANEL_W;
                let area = root.clone().shrink((x, y), (PANEL_W as u32, h as u32));
                self.panel(&area, plan, row, velocity, last)?;
            }
        }
        Ok(())
    }

    /// One chart: a joint's position or velocity over the whole plan.
    fn panel(&self, area: &Area, plan: &Plan, row: &JointRow, velocity: bool, last: bool) -> Res {
        let bounded = velocity || (row.lower.is_finite() && row.upper.is_finite());
        let (lo, hi) = match (velocity, bounded) {
            (true, _) => (-row.velocity, row.velocity),
            (false, true) => (row.lower, row.upper),
            // A continuous joint has no limits: the axis spans its positions.
            (false, false) => self.position_span(plan, row),
        };
        let pad = 0.12 * (hi - lo);
        let mut chart = ChartBuilder::on(area)
            .margin_top(16)
            .margin_right(8)
            .x_label_area_size(if last { 30 } else { 0 })
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..self.total, (lo - pad)..(hi + pad))?;
        let mut mesh = chart.configure_mesh();
        mesh.y_labels(5)
            .x_labels(8)
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(RGBColor(232, 232, 232))
            .label_style(text_style(11.0, RGBColor(60, 60, 60)));
        if last {
            mesh.x_desc("time (s), sub-goals back to back");
        }
        mesh.axis_desc_style(text_style(12.0, BLACK)).draw()?;
        self.events(&mut chart, plan, (lo - pad, hi + pad))?;
        for limit in [lo, hi].into_iter().filter(|_| bounded) {
            let line = [(0.0, limit), (self.total, limit)];
            chart.draw_series(DashedLineSeries::new(line, 6, 4, LIMIT.stroke_width(1)))?;
        }
        for (k, sub) in plan.subgoals.iter().enumerate() {
            let (Some(t), Some(i)) = (&sub.trajectory, row.columns[k]) else {
                continue;
            };
            let offset = self.offsets[k];
            let pts = t.points.iter().map(|p| {
                let value = if velocity {
                    p.velocities[i]
                } else {
                    p.positions[i]
                };
                (offset + p.time_from_start, value)
            });
            chart.draw_series(LineSeries::new(pts, subgoal_colour(k).stroke_width(2)))?;
        }
        let name = text_style(11.0, BLACK).pos(Pos::new(HPos::Left, VPos::Top));
        area.draw_text(&row.name, &name, (52, 2))?;
        Ok(())
    }

    /// Lowest and highest position of `row`'s joint over the plan (at least
    /// 1 rad apart).
    fn position_span(&self, plan: &Plan, row: &JointRow) -> (f64, f64) {
        let values = plan
            .subgoals
            .iter()
            .zip(&row.columns)
            .filter_map(|(sub, &c)| {
                let i = c?;
                Some(
                    sub.trajectory
                        .as_ref()?
                        .points
                        .iter()
                        .map(move |p| p.positions[i]),
                )
            });
        let (lo, hi) = values
            .flatten()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        let mid = if lo <= hi { 0.5 * (lo + hi) } else { 0.0 };
        let half = (0.5 * (hi - lo)).max(0.5);
        (mid - half, mid + half)
    }

    /// Dotted grey verticals where the gripper closes and opens.
    fn events<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
        plan: &Plan,
        (lo, hi): (f64, f64),
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let grey = RGBColor(150, 150, 150);
        for (k, sub) in plan.subgoals.iter().enumerate() {
            let Some(t) = &sub.trajectory else { continue };
            for e in &t.gripper {
                for x in [e.start, e.end].map(|t| self.offsets[k] + t) {
                    let line = [(x, lo), (x, hi)];
                    chart.draw_series(DashedLineSeries::new(line, 2, 3, grey.stroke_width(1)))?;
                }
            }
        }
        Ok(())
    }
}
