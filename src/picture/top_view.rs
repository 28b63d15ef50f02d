//! The plan's top view in camera pixels: the scene (objects in their
//! shapes and colours, goals, hands, safety perimeters, the first sub-goal's
//! grid) and each sub-goal's cell path, tool path, start and drop.

use afford_planner::Plan;
use afford_planner::plan::SubgoalPlan;
use afford_planner::scenario::{PixelBox, Scenario};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{
    Area, GOAL, HAND, MARGIN, Res, SENSITIVE, TITLE_H, VIEW_MAX, failure_letter, subgoal_colour,
    text_style,
};

/// Pixel-to-canvas mapping of the camera image.
pub(super) struct TopView<'s> {
    scenario: &'s Scenario,
    origin: (i32, i32),
    scale: f64,
    pub(super) size: (i32, i32),
}

impl<'s> TopView<'s> {
    pub(super) fn new(scenario: &'s Scenario) -> Self {
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

    pub(super) fn draw(&self, root: &Area, plan: &Plan) -> Res {
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
