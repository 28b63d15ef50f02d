//! Where the robot is along one planned sub-goal, precomputed once per
//! sample of its trajectory: the tool position (robot base frame, m), its
//! planned speed (m/s), the state-grid cell under it and the place in the
//! discrete policy — how many of the sub-goal's actions are done — so a
//! re-simulation can start from the robot's cell with the actions still
//! ahead. Progress along the policy is monotone: a sample over a cell the
//! policy visits later moves it on; the smoothed path cutting a corner
//! over a cell the policy does not visit keeps it where it was.

use afford_kinematics::Arm;

use crate::grid::Cell;
use crate::plan::SubgoalPlan;
use crate::scenario::{MotionPhase, PixelBox, Scenario};
use crate::task::Action;
use crate::trajectory::{GripperCommand, TimedMotion};

/// One sub-goal's plan as the monitor follows it.
#[derive(Debug, Clone)]
pub struct Track {
    /// Tool position per sample, base frame, m.
    pub tool: Vec<[f64; 3]>,
    /// Planned tool speed per sample, m/s.
    pub speed: Vec<f64>,
    /// Actions done at each sample (index of the next action).
    pub done: Vec<usize>,
    /// Plan times of the gripper events: close start/end, open start/end
    /// (a carry that starts holding has close at 0).
    pub close: (f64, f64),
    pub open: (f64, f64),
    /// The motion starts with the object in the gripper (no close command).
    pub starts_holding: bool,
}

impl Track {
    /// The track of `plan` (stage `trajectory`) moved by `arm`, whose grid
    /// was cut from `scene`'s pixels.
    pub fn new(plan: &SubgoalPlan, arm: &Arm, scene: &Scenario) -> Self {
        let motion = plan.trajectory.as_ref().expect("monitored plans are timed");
        let tool: Vec<[f64; 3]> = motion
            .points
            .iter()
            .map(|p| arm.fk(&p.positions).translation.vector.into())
            .collect();
        let speed = speeds(motion, &tool);
        let event = |command| {
            motion
                .gripper
                .iter()
                .find(|e| e.command == command)
                .map(|e| (e.start, e.end))
        };
        let starts_holding = event(GripperCommand::Close).is_none();
        let close = event(GripperCommand::Close).unwrap_or((0.0, 0.0));
        let open = event(GripperCommand::Open).unwrap_or((motion.duration(), motion.duration()));
        let mut track = Self {
            tool,
            speed,
            done: Vec::new(),
            close,
            open,
            starts_holding,
        };
        track.done = track.progress(plan, motion, scene);
        track
    }

    /// The sample at or before plan time `s`.
    pub fn sample_at(motion: &TimedMotion, s: f64) -> usize {
        motion
            .points
            .partition_point(|p| p.time_from_start <= s + 1e-9)
            .saturating_sub(1)
    }

    /// True when the gripper holds the object at plan time `s` (closed, or
    /// closing: the object counts as taken once the close command is under
    /// way), until the gripper has opened.
    pub fn holding(&self, s: f64) -> bool {
        (self.starts_holding || s > self.close.0 + 1e-9) && s < self.open.1 - 1e-9
    }

    /// The target's box the plan's grid was cut for: the cell of its GRASP
    /// (the grid is aligned so the target's box is exactly one cell).
    pub fn planned_box(plan: &SubgoalPlan) -> PixelBox {
        let k = plan
            .actions
            .iter()
            .position(|&a| a == Action::Grasp)
            .unwrap_or(0);
        let [r, c] = plan.cells[k.min(plan.cells.len() - 1)];
        let g = &plan.grid;
        PixelBox {
            u: g.origin_px[0] + c as f64 * g.cell_px[0],
            v: g.origin_px[1] + r as f64 * g.cell_px[1],
            w: g.cell_px[0],
            l: g.cell_px[1],
        }
    }

    /// The phase at plan time `s` and how far through it, 0–1.
    pub fn phase(&self, s: f64, duration: f64) -> (MotionPhase, f64) {
        let bounds = [
            (MotionPhase::Travel, 0.0, self.close.0),
            (MotionPhase::Grasp, self.close.0, self.close.1),
            (MotionPhase::Carry, self.close.1, self.open.0),
            (MotionPhase::Release, self.open.0, self.open.1),
            (MotionPhase::Retreat, self.open.1, duration),
        ];
        let (phase, a, b) = bounds
            .into_iter()
            .find(|&(_, _, b)| s < b - 1e-9)
            .unwrap_or((MotionPhase::Retreat, self.open.1, duration));
        let fraction = match b - a > 1e-9 {
            true => ((s - a) / (b - a)).clamp(0.0, 1.0),
            false => 1.0,
        };
        (phase, fraction)
    }

    fn progress(&self, plan: &SubgoalPlan, motion: &TimedMotion, scene: &Scenario) -> Vec<usize> {
        let cells: Vec<Cell> = plan.cells.iter().map(|&[r, c]| (r, c)).collect();
        let position = |a: Action| plan.actions.iter().position(|&x| x == a);
        let grasp = position(Action::Grasp);
        let goal = position(Action::Goal).unwrap_or(plan.actions.len());
        let cell_of = |p: &[f64; 3]| {
            let [u, v] = scene.base_to_pixel([p[0], p[1]]);
            let g = &plan.grid;
            let idx = |x: f64, o: f64, w: f64, n: usize| {
                (((x - o) / w).floor().max(0.0) as usize).min(n.saturating_sub(1))
            };
            (
                idx(v, g.origin_px[1], g.cell_px[1], g.size[0]),
                idx(u, g.origin_px[0], g.cell_px[0], g.size[1]),
            )
        };
        let mut k = 0;
        motion
            .points
            .iter()
            .zip(&self.tool)
            .map(|(p, tool)| {
                let s = p.time_from_start;
                let range = if s >= self.open.0 - 1e-9 && self.open.0 < motion.duration() {
                    k = plan.actions.len();
                    k..=k
                } else if self.holding(s) {
                    k = k.max(grasp.map_or(0, |g| g + 1));
                    k..=goal.min(cells.len() - 1)
                } else {
                    k..=grasp.unwrap_or(0)
                };
                let here = cell_of(tool);
                if let Some(j) = range.clone().find(|&j| cells.get(j) == Some(&here)) {
                    k = j;
                }
                k
            })
            .collect()
    }
}

/// Tool speed per sample: central differences of the tool positions over
/// the sample times (one-sided at the ends), m/s.
fn speeds(motion: &TimedMotion, tool: &[[f64; 3]]) -> Vec<f64> {
    let n = tool.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            let dt = motion.points[b].time_from_start - motion.points[a].time_from_start;
            let d: f64 = (0..3).map(|k| (tool[b][k] - tool[a][k]).powi(2)).sum();
            match dt > 1e-12 {
                true => d.sqrt() / dt,
                false => 0.0,
            }
        })
        .collect()
}
