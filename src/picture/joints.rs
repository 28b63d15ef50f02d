//! The joint panels beside the top view: per joint moved, position and
//! velocity against time on one axis for all sub-goals, limits dashed,
//! gripper events as grey verticals.

use afford_kinematics::RobotModel;
use afford_planner::Plan;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{
    Area, LIMIT, LINE_H, MARGIN, PANEL_W, ROW_H, Res, TITLE_H, subgoal_colour, text_style,
};

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
pub(super) struct JointRows {
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
    pub(super) fn new(robot: &RobotModel, plan: &Plan) -> Option<Self> {
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

    pub(super) fn height(&self) -> i32 {
        LINE_H * 2 + ROW_H * self.rows.len() as i32 + 30
    }

    pub(super) fn draw(&self, root: &Area, plan: &Plan, left: i32) -> Res {
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
