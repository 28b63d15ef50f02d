//! The state grid s (the paper's Algorithm 2): the camera image cut into cells
//! the size of the current target's box, each coded 0 empty, 0.1 target,
//! 0.2 obstacle, 0.3 goal, 0.4 hand.
//!
//! Reading choices (the paper's pseudo-code is garbled):
//! - The grid is aligned so the target's box is exactly one cell; a cell
//!   exists when its centre lies inside the image, so the grid covers the
//!   whole image and may hold one more row or column than `ceil(sh / l)`.
//! - An element covers a cell when its box, grown by its safety margin
//!   (metres converted to pixels along u and v with `pixel_to_base`),
//!   overlaps the cell at all: conservative, these are cells the gripper
//!   must never enter.
//! - Painting order, later wins: goal 0.3, obstacles 0.2 (every other object,
//!   including other targets, and every other goal with what rests in it),
//!   hands 0.4, and finally the target 0.1 unless a hand covers it. Objects
//!   already resting in the sub-goal's own goal are part of that goal.
//! - The carry may pass over what is below it ([`Obstacles::Sensitive`]):
//!   when the paper's grid has no route (its cells, the target's size, round
//!   the gaps between grown boxes shut), the grid is built again with only
//!   the sensitive objects' perimeters and the hands blocked; the carry then
//!   rises over the rest (the tallest thing passed over), and the 3-D
//!   collision check keeps every margin ([`crate::discrete::route_grid`]).
//! - If the gripper starts over obstacle cells (it has just released into a
//!   box that is an obstacle for the next sub-goal), that connected obstacle
//!   region is cleared: the gripper is above it and must be able to leave.
//!   If it starts over a hand's cells, which are never cleared, the learner
//!   starts from the free cell nearest it ([`crate::discrete::hand_exit`]).

use crate::place::{NoSpot, Release, Room, release_spot};
use crate::scenario::{PixelBox, Scenario};

/// The semantic code of a cell, with the paper's numeric values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellCode {
    Empty,
    Target,
    Obstacle,
    Goal,
    Hand,
}

impl CellCode {
    /// The paper's numeric token: 0, 0.1, 0.2, 0.3, 0.4.
    pub fn value(self) -> f64 {
        match self {
            Self::Empty => 0.0,
            Self::Target => 0.1,
            Self::Obstacle => 0.2,
            Self::Goal => 0.3,
            Self::Hand => 0.4,
        }
    }

    /// Cells the gripper must never enter.
    pub fn is_blocked(self) -> bool {
        matches!(self, Self::Obstacle | Self::Hand)
    }
}

/// Which elements a grid paints as obstacles (hands are always painted).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Obstacles {
    /// Every other object and every other goal: the paper's grid, the
    /// route goes round them.
    #[default]
    All,
    /// The sensitive objects only: the route may pass over the others and
    /// the other goals at carry height.
    Sensitive,
}

impl Obstacles {
    /// Whether this is the paper's grid (serialised plans leave it out).
    pub fn is_all(&self) -> bool {
        *self == Self::All
    }
}

/// A grid cell, `(row, col)`; rows grow with v, columns with u.
pub type Cell = (usize, usize);

/// The state matrix s of one sub-goal plus the geometry that maps cells back
/// to pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct StateGrid {
    /// n: number of rows (along v).
    pub rows: usize,
    /// m: number of columns (along u).
    pub cols: usize,
    /// Pixel (u, v) of the top-left corner of cell (0, 0).
    pub origin: [f64; 2],
    /// Cell size in pixels (w, l): the target's box.
    pub cell_size: [f64; 2],
    codes: Vec<CellCode>,
    /// Where the gripper starts.
    pub start: Cell,
    /// The target's cell.
    pub target: Cell,
    /// Where the GOAL action carries the object: the goal cell under its
    /// resting spot. `None` when no spot is left.
    pub drop: Option<Cell>,
    /// Pixel (u, v) where the object is released and comes to rest, inside
    /// the drop cell, with its release floor ([`crate::place`]), or why no
    /// spot is left.
    pub release: Result<Release, NoSpot>,
    /// The blocked perimeters as painted (pixel boxes already grown by
    /// their margins: other objects, other goals, hands), for the any-angle
    /// route ([`crate::motion::route`]), which keeps off them rather than off
    /// the whole cells they touch.
    pub perimeters: Vec<PixelBox>,
    /// Cells blocked after a collision check ([`Self::block`]): blocked as
    /// a whole, whatever painted them.
    pub checked: Vec<Cell>,
    /// Obstacle cells cleared under the gripper ([`Self::clear_escape`]).
    pub cleared: Vec<Cell>,
    /// Indices into [`Self::perimeters`] of those the gripper is in: every
    /// one over cleared cells whose configuration-space box (grown by half
    /// a cell, the footprint) holds the gripper, and every one over cleared
    /// cells meeting those, transitively ([`Self::escape_from`]). The route
    /// may cross them over the cleared cells, as the cells do; the others
    /// the cells' flood fill reached only through the grid's rounding stay
    /// closed to it.
    pub escape: Vec<usize>,
    /// What was painted as obstacles.
    pub obstacles: Obstacles,
}

/// What one sub-goal puts where: indices into the scenario's objects/goals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridRequest {
    pub object: usize,
    pub goal: usize,
    /// Gripper position, pixel (u, v).
    pub gripper: [f64; 2],
}

impl StateGrid {
    /// Builds the grid for moving `scenario.objects[req.object]` into
    /// `scenario.goals[req.goal]` with the gripper at `req.gripper`; the
    /// resting spot leaves room for the object only ([`Self::build_placing`]).
    pub fn build(scenario: &Scenario, req: GridRequest) -> Self {
        Self::build_placing(scenario, req, Room::default())
    }

    /// [`Self::build`] with the resting spot chosen so the open fingers
    /// (`room.opening`, m, across the grasp axis) also keep the pieces
    /// already in the goal at their margins, and the pieces the chain
    /// releases there later (`room.later`) still fit.
    pub fn build_placing(scenario: &Scenario, req: GridRequest, room: Room) -> Self {
        Self::build_painting(scenario, req, room, Obstacles::All)
    }

    /// [`Self::build_placing`] painting `obstacles` as obstacles.
    pub fn build_painting(
        scenario: &Scenario,
        req: GridRequest,
        room: Room,
        obstacles: Obstacles,
    ) -> Self {
        let target_box = scenario.objects[req.object].bbox;
        let cell_size = [target_box.w, target_box.l];
        let image = [scenario.camera.width as f64, scenario.camera.height as f64];
        let origin = [0, 1].map(|k| aligned_origin(target_box_start(&target_box, k), cell_size[k]));
        let count = |k: usize| {
            (((image[k] - origin[k]) / cell_size[k] - 0.5)
                .ceil()
                .max(1.0)) as usize
        };
        let mut grid = Self {
            rows: count(1),
            cols: count(0),
            origin,
            cell_size,
            codes: Vec::new(),
            start: (0, 0),
            target: (0, 0),
            drop: None,
            release: Err(NoSpot::Covered),
            perimeters: Vec::new(),
            checked: Vec::new(),
            cleared: Vec::new(),
            escape: Vec::new(),
            obstacles,
        };
        grid.codes = vec![CellCode::Empty; grid.rows * grid.cols];
        grid.start = grid.cell_at(req.gripper);
        grid.target = grid.cell_at(target_box.centre());
        grid.paint_scene(scenario, req);
        grid.clear_escape(grid.start);
        grid.escape = grid.escape_from(req.gripper);
        if let Some(exit) = crate::discrete::hand_exit::exit_cell(&grid, req.gripper) {
            grid.start = exit;
        }
        grid.release = release_spot(scenario, req.object, req.goal, room, |p| {
            grid.code(grid.cell_at(p)) == CellCode::Goal
        });
        grid.drop = grid.release.ok().map(|r| grid.cell_at(r.spot));
        grid
    }

    fn paint_scene(&mut self, s: &Scenario, req: GridRequest) {
        let [mu, mv] = s.metres_per_pixel();
        let px = |metres: f64| [metres / mu, metres / mv];
        self.paint(s.goals[req.goal].bbox, [0.0, 0.0], CellCode::Goal);
        let all = self.obstacles == Obstacles::All;
        let other_goals = s
            .goals
            .iter()
            .enumerate()
            .filter(|&(i, _)| all && i != req.goal);
        for (_, goal) in other_goals {
            self.paint(goal.bbox, px(s.safety.obstacle_margin), CellCode::Obstacle);
        }
        for (i, object) in s.objects.iter().enumerate() {
            if i == req.object
                || s.goal_holding(object) == Some(req.goal)
                || !(all || s.is_sensitive(object))
            {
                continue;
            }
            let margin = if s.is_sensitive(object) {
                s.safety.sensitive_margin
            } else {
                s.safety.obstacle_margin
            };
            self.paint(object.bbox, px(margin), CellCode::Obstacle);
        }
        for hand in &s.hands {
            self.paint(hand.bbox, px(s.safety.hand_margin), CellCode::Hand);
        }
        if self.code(self.target) != CellCode::Hand {
            self.set(self.target, CellCode::Target);
        }
    }

    /// When the gripper starts over obstacle cells (it has just released
    /// into a box that is an obstacle for this sub-goal), the 4-connected
    /// obstacle region under it becomes free: the gripper is above it at
    /// carry height and must be able to leave. Hand cells are never cleared.
    fn clear_escape(&mut self, start: Cell) {
        let mut stack = vec![start];
        while let Some(cell) = stack.pop() {
            if self.code(cell) != CellCode::Obstacle {
                continue;
            }
            self.set(cell, CellCode::Empty);
            self.cleared.push(cell);
            stack.extend(self.neighbours(cell));
        }
    }

    /// The perimeters the gripper at pixel `gripper` is in (see
    /// [`Self::escape`]): the configuration-space boxes (open, grown by
    /// half a cell) holding it, then those meeting one already in (closed
    /// boxes overlap or touch), among the perimeters over a cleared cell.
    fn escape_from(&self, gripper: [f64; 2]) -> Vec<usize> {
        let half = [0, 1].map(|k| self.cell_size[k] / 2.0);
        let boxes: Vec<[[f64; 2]; 2]> = self
            .perimeters
            .iter()
            .map(|b| {
                [
                    [b.u - half[0], b.v - half[1]],
                    [b.u + b.w + half[0], b.v + b.l + half[1]],
                ]
            })
            .collect();
        let over_cleared: Vec<bool> = self
            .perimeters
            .iter()
            .map(|b| match (self.span(b.v, b.l, 1), self.span(b.u, b.w, 0)) {
                (Some((r0, r1)), Some((c0, c1))) => self
                    .cleared
                    .iter()
                    .any(|&(r, c)| (r0..=r1).contains(&r) && (c0..=c1).contains(&c)),
                _ => false,
            })
            .collect();
        let holds =
            |[lo, hi]: [[f64; 2]; 2]| (0..2).all(|k| lo[k] < gripper[k] && gripper[k] < hi[k]);
        let meet = |a: [[f64; 2]; 2], b: [[f64; 2]; 2]| {
            (0..2).all(|k| a[0][k] <= b[1][k] && b[0][k] <= a[1][k])
        };
        let mut inside: Vec<bool> = (0..boxes.len())
            .map(|i| over_cleared[i] && holds(boxes[i]))
            .collect();
        let mut grown = true;
        while grown {
            grown = false;
            for i in 0..boxes.len() {
                if !inside[i]
                    && over_cleared[i]
                    && (0..boxes.len()).any(|j| inside[j] && meet(boxes[i], boxes[j]))
                {
                    inside[i] = true;
                    grown = true;
                }
            }
        }
        (0..boxes.len()).filter(|&i| inside[i]).collect()
    }

    /// The 4-neighbours of a cell that lie on the grid.
    pub fn neighbours(&self, (r, c): Cell) -> impl Iterator<Item = Cell> + use<> {
        let (rows, cols) = (self.rows, self.cols);
        [(-1isize, 0isize), (1, 0), (0, -1), (0, 1)]
            .into_iter()
            .filter_map(move |(dr, dc)| {
                let (r, c) = (r.checked_add_signed(dr)?, c.checked_add_signed(dc)?);
                (r < rows && c < cols).then_some((r, c))
            })
    }

    /// Marks every cell the box, grown by `margin` pixels, overlaps; a
    /// blocked code records the grown box in [`Self::perimeters`].
    fn paint(&mut self, bbox: PixelBox, [du, dv]: [f64; 2], code: CellCode) {
        let b = bbox.grown(du, dv);
        if code.is_blocked() {
            self.perimeters.push(b);
        }
        let Some((r0, r1)) = self.span(b.v, b.l, 1) else {
            return;
        };
        let Some((c0, c1)) = self.span(b.u, b.w, 0) else {
            return;
        };
        for r in r0..=r1 {
            for c in c0..=c1 {
                self.set((r, c), code);
            }
        }
    }

    /// Inclusive range of cell indices along axis `k` that the open interval
    /// (start, start + len) overlaps; `None` when it misses the grid.
    pub fn span(&self, start: f64, len: f64, k: usize) -> Option<(usize, usize)> {
        const EPS: f64 = 1e-9;
        let n = if k == 0 { self.cols } else { self.rows } as f64;
        let lo = ((start - self.origin[k]) / self.cell_size[k] + EPS)
            .floor()
            .max(0.0);
        let hi =
            (((start + len - self.origin[k]) / self.cell_size[k] - EPS).ceil() - 1.0).min(n - 1.0);
        (lo <= hi).then_some((lo as usize, hi as usize))
    }

    /// The cell containing pixel `p`, clamped onto the grid.
    pub fn cell_at(&self, p: [f64; 2]) -> Cell {
        let idx = |k: usize, n: usize| {
            (((p[k] - self.origin[k]) / self.cell_size[k])
                .floor()
                .max(0.0) as usize)
                .min(n - 1)
        };
        (idx(1, self.rows), idx(0, self.cols))
    }

    /// Pixel centre (u, v) of a cell.
    pub fn centre(&self, (r, c): Cell) -> [f64; 2] {
        [
            self.origin[0] + (c as f64 + 0.5) * self.cell_size[0],
            self.origin[1] + (r as f64 + 0.5) * self.cell_size[1],
        ]
    }

    pub fn code(&self, (r, c): Cell) -> CellCode {
        self.codes[r * self.cols + c]
    }

    fn set(&mut self, (r, c): Cell, code: CellCode) {
        self.codes[r * self.cols + c] = code;
    }

    /// Number of cells, n·m.
    pub fn len(&self) -> usize {
        self.codes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.codes.is_empty()
    }

    /// Row-major cell index.
    pub fn index(&self, (r, c): Cell) -> usize {
        r * self.cols + c
    }

    /// Cell of a row-major index.
    pub fn cell(&self, index: usize) -> Cell {
        (index / self.cols, index % self.cols)
    }

    /// All codes, row-major.
    pub fn codes(&self) -> &[CellCode] {
        &self.codes
    }

    /// The matrix s with the paper's numeric values, row by row.
    pub fn matrix(&self) -> Vec<Vec<f64>> {
        self.codes
            .chunks(self.cols)
            .map(|row| row.iter().map(|c| c.value()).collect())
            .collect()
    }

    /// The goal cell nearest pixel `p` (ties: lowest index); test grids only.
    fn nearest_goal_cell(&self, p: [f64; 2]) -> Option<Cell> {
        (0..self.len())
            .map(|i| self.cell(i))
            .filter(|&cell| self.code(cell) == CellCode::Goal)
            .min_by(|&a, &b| dist2(self.centre(a), p).total_cmp(&dist2(self.centre(b), p)))
    }

    /// Marks a cell blocked; used when a later check finds a place the grid
    /// did not see (an elbow over a tall object) or to build test grids.
    pub fn block(&mut self, cell: Cell) {
        self.set(cell, CellCode::Obstacle);
        self.checked.push(cell);
    }

    /// A grid given directly by its codes (tests, benchmarks). Cell size is
    /// 1 px, origin 0; `drop` is the goal cell nearest the goal cells' centroid.
    pub fn from_codes(rows: usize, cols: usize, codes: Vec<CellCode>, start: Cell) -> Option<Self> {
        if rows == 0 || cols == 0 || codes.len() != rows * cols {
            return None;
        }
        let target = codes.iter().position(|&c| c == CellCode::Target)?;
        let mut grid = Self {
            rows,
            cols,
            origin: [0.0, 0.0],
            cell_size: [1.0, 1.0],
            codes,
            start,
            target: (target / cols, target % cols),
            drop: None,
            release: Err(NoSpot::Covered),
            perimeters: Vec::new(),
            checked: Vec::new(),
            cleared: Vec::new(),
            escape: Vec::new(),
            obstacles: Obstacles::All,
        };
        let goals: Vec<[f64; 2]> = (0..grid.len())
            .filter(|&i| grid.codes[i] == CellCode::Goal)
            .map(|i| grid.centre(grid.cell(i)))
            .collect();
        if !goals.is_empty() {
            let n = goals.len() as f64;
            let centroid = [
                goals.iter().map(|p| p[0]).sum::<f64>() / n,
                goals.iter().map(|p| p[1]).sum::<f64>() / n,
            ];
            grid.drop = grid.nearest_goal_cell(centroid);
            grid.release = grid
                .drop
                .map(|c| Release {
                    spot: grid.centre(c),
                    floor: 0.0,
                })
                .ok_or(NoSpot::Covered);
        }
        Some(grid)
    }
}

fn target_box_start(b: &PixelBox, k: usize) -> f64 {
    if k == 0 { b.u } else { b.v }
}

/// The grid origin along one axis: a whole number of cells before the
/// target's box start, chosen so the first cell's centre is the first one
/// at or after pixel 0.
fn aligned_origin(target_start: f64, size: f64) -> f64 {
    target_start - ((target_start + size / 2.0) / size).floor() * size
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// A text picture of the grid, one character per cell: `.` empty, `T`
/// target, `#` obstacle, `G` goal, `H` hand, `S` start, `D` drop cell.
impl std::fmt::Display for StateGrid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for r in 0..self.rows {
            let line: String = (0..self.cols)
                .map(|c| match (r, c) {
                    cell if cell == self.start => 'S',
                    cell if Some(cell) == self.drop => 'D',
                    cell => match self.code(cell) {
                        CellCode::Empty => '.',
                        CellCode::Target => 'T',
                        CellCode::Obstacle => '#',
                        CellCode::Goal => 'G',
                        CellCode::Hand => 'H',
                    },
                })
                .collect();
            writeln!(f, "{line}")?;
        }
        Ok(())
    }
}
