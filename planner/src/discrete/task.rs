//! The grid task as a deterministic MDP: agent state (cell, holding), the
//! seven actions of equation (5) and the transition function. Shared by the
//! learners, the BFS oracle and plan validation, so all of them agree on what
//! an action does.
//!
//! UP/DOWN move along v (rows −1/+1), LEFT/RIGHT along u (columns −1/+1).
//! GRASP closes the gripper on the target; GOAL is the macro that carries the
//! held object from a cell next to the goal (8-neighbourhood) over the box
//! wall to the drop cell; DROP opens the gripper there and ends the task.

use serde::{Deserialize, Serialize};

use crate::grid::{Cell, CellCode, StateGrid};

/// The action set A of equation (5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum Action {
    Up,
    Down,
    Left,
    Right,
    Grasp,
    Drop,
    Goal,
}

impl Action {
    pub const ALL: [Action; 7] = [
        Action::Up,
        Action::Down,
        Action::Left,
        Action::Right,
        Action::Grasp,
        Action::Drop,
        Action::Goal,
    ];
    /// The displacement actions I of equation (8).
    pub const MOVES: [Action; 4] = [Action::Up, Action::Down, Action::Left, Action::Right];
    pub const COUNT: usize = 7;

    pub fn index(self) -> usize {
        self as usize
    }

    /// Row/column displacement of a move; `None` for GRASP, DROP, GOAL.
    pub fn delta(self) -> Option<(isize, isize)> {
        match self {
            Action::Up => Some((-1, 0)),
            Action::Down => Some((1, 0)),
            Action::Left => Some((0, -1)),
            Action::Right => Some((0, 1)),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Action::Up => "UP",
            Action::Down => "DOWN",
            Action::Left => "LEFT",
            Action::Right => "RIGHT",
            Action::Grasp => "GRASP",
            Action::Drop => "DROP",
            Action::Goal => "GOAL",
        }
    }
}

/// Agent state: which cell the gripper is over and whether it holds the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AgentState {
    pub cell: Cell,
    pub holding: bool,
}

/// Result of one transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// The agent is now in this state.
    Moved(AgentState),
    /// DROP over the goal: the task is done.
    Done,
    /// The action is not afforded here (would leave the grid, enter a 0.2/0.4
    /// cell, grasp nothing, drop outside the goal, ...).
    Refused,
}

/// One sub-goal's grid as an MDP, with states indexed `cell * 2 + holding`.
#[derive(Debug, Clone)]
pub struct GridTask {
    pub grid: StateGrid,
    /// Per cell, the goal cell where the GOAL macro enters the box from it.
    entry: Vec<Option<Cell>>,
}

impl GridTask {
    pub fn new(grid: StateGrid) -> Self {
        let entry = (0..grid.len())
            .map(|i| goal_entry(&grid, grid.cell(i)))
            .collect();
        Self { grid, entry }
    }

    pub fn start(&self) -> AgentState {
        AgentState {
            cell: self.grid.start,
            holding: false,
        }
    }

    pub fn state_count(&self) -> usize {
        self.grid.len() * 2
    }

    pub fn state_index(&self, s: AgentState) -> usize {
        self.grid.index(s.cell) * 2 + s.holding as usize
    }

    pub fn state(&self, index: usize) -> AgentState {
        AgentState {
            cell: self.grid.cell(index / 2),
            holding: index % 2 == 1,
        }
    }

    /// The transition function T(s' | s, a) (deterministic) under the rules
    /// R of equation (7) as read in the module docs of [`crate::affordance`].
    pub fn step(&self, s: AgentState, a: Action) -> Outcome {
        let grid = &self.grid;
        if !s.holding {
            return match a {
                Action::Grasp if s.cell == grid.target => {
                    Outcome::Moved(AgentState { holding: true, ..s })
                }
                _ if s.cell == grid.target => Outcome::Refused,
                _ => self.move_to(s, a),
            };
        }
        match (a, grid.drop) {
            (Action::Drop, Some(drop)) if s.cell == drop => Outcome::Done,
            (_, Some(drop)) if s.cell == drop => Outcome::Refused,
            (Action::Goal, Some(drop)) if self.is_near_goal(s.cell) => Outcome::Moved(AgentState {
                cell: drop,
                holding: true,
            }),
            _ if self.is_near_goal(s.cell) => Outcome::Refused,
            _ => self.move_to(s, a),
        }
    }

    /// A displacement into a cell on the grid that is not 0.2/0.4, and not
    /// into the goal while holding (the GOAL macro does that).
    fn move_to(&self, s: AgentState, a: Action) -> Outcome {
        let Some((dr, dc)) = a.delta() else {
            return Outcome::Refused;
        };
        let (Some(r), Some(c)) = (
            s.cell.0.checked_add_signed(dr),
            s.cell.1.checked_add_signed(dc),
        ) else {
            return Outcome::Refused;
        };
        if r >= self.grid.rows || c >= self.grid.cols {
            return Outcome::Refused;
        }
        let code = self.grid.code((r, c));
        if code.is_blocked() || (s.holding && code == CellCode::Goal) {
            return Outcome::Refused;
        }
        Outcome::Moved(AgentState {
            cell: (r, c),
            holding: s.holding,
        })
    }

    /// True when GOAL is possible from the cell (see [`Self::goal_entry`]).
    pub fn is_near_goal(&self, cell: Cell) -> bool {
        self.entry[self.grid.index(cell)].is_some()
    }

    /// Where the GOAL macro from `cell` crosses into the box: an 8-adjacent
    /// goal cell. `None` when GOAL is not possible from `cell`.
    pub fn goal_entry(&self, cell: Cell) -> Option<Cell> {
        self.entry[self.grid.index(cell)]
    }
}

/// The GOAL macro from `from`: the 8-adjacent goal cell nearest the drop
/// cell such that the straight carry from `from` into it and on to the drop
/// cell touches no 0.2/0.4 cell (corners included). `None` from a goal cell,
/// from a cell no goal cell touches, or when every carry is blocked.
fn goal_entry(grid: &StateGrid, from: Cell) -> Option<Cell> {
    let drop = grid.drop?;
    if grid.code(from) == CellCode::Goal {
        return None;
    }
    let (r, c) = (from.0 as isize, from.1 as isize);
    let mut entries: Vec<Cell> = (-1..=1)
        .flat_map(|dr| (-1..=1).map(move |dc| (r + dr, c + dc)))
        .filter(|&(rr, cc)| {
            rr >= 0 && cc >= 0 && (rr as usize) < grid.rows && (cc as usize) < grid.cols
        })
        .map(|(rr, cc)| (rr as usize, cc as usize))
        .filter(|&cell| grid.code(cell) == CellCode::Goal)
        .collect();
    entries.sort_by_key(|e| {
        (
            e.0.abs_diff(drop.0).pow(2) + e.1.abs_diff(drop.1).pow(2),
            *e,
        )
    });
    entries
        .into_iter()
        .find(|&entry| segment_is_clear(grid, from, entry) && segment_is_clear(grid, entry, drop))
}

/// The straight segment between two cell centres touches no blocked cell:
/// sampled every 1/64 of a cell, each sample checked in every cell within
/// 1e-6 px of it, so passing exactly through a corner counts all four cells.
fn segment_is_clear(grid: &StateGrid, from: Cell, to: Cell) -> bool {
    let (a, b) = (grid.centre(from), grid.centre(to));
    let samples = ((from.0.abs_diff(to.0) + from.1.abs_diff(to.1)) * 64).max(1);
    let eps = [1e-6 * grid.cell_size[0], 1e-6 * grid.cell_size[1]];
    (0..=samples).all(|i| {
        let t = i as f64 / samples as f64;
        let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
        [-1.0, 1.0].iter().all(|su| {
            [-1.0, 1.0].iter().all(|sv| {
                !grid
                    .code(grid.cell_at([p[0] + su * eps[0], p[1] + sv * eps[1]]))
                    .is_blocked()
            })
        })
    })
}
