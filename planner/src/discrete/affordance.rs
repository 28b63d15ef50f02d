//! Affordances ζ (equation 8) and the contextual initial Q-table (equation 9).
//!
//! Reading of the rules R (equation 7) and equation (8), after the authors'
//! code (see `docs/decisions.md`):
//! - a move is afforded when its destination is on the grid and not a 0.2
//!   (obstacle) or 0.4 (hand) cell, and, while holding, not a goal cell;
//! - GRASP when over the target and not holding;
//! - GOAL when holding and 8-adjacent to the goal with a clear straight carry
//!   to the drop cell; DROP when holding over the drop cell.
//!
//! Where GRASP, GOAL or DROP is afforded it is the only afforded action, so
//! the +10 for entering the goal can never pay the agent to leave and re-enter.
//!
//! Equation (9): Q₀(s, a) = ζ(s, a) + ξ(s, a, g), with ξ = `distance_bias`
//! (0.1) for an afforded move that reduces the Manhattan distance to the
//! current sub-target: the target before GRASP, the nearest goal cell after.

use crate::grid::CellCode;
use crate::task::{Action, AgentState, GridTask, Outcome};

/// The affordance mask ζ(s, ·) of every state, one bit per action.
#[derive(Debug, Clone)]
pub struct Affordances {
    masks: Vec<u8>,
}

impl Affordances {
    /// Evaluates ζ for every state of the task.
    pub fn of(task: &GridTask) -> Self {
        let masks = (0..task.state_count())
            .map(|i| {
                let s = task.state(i);
                Action::ALL
                    .iter()
                    .filter(|&&a| task.step(s, a) != Outcome::Refused)
                    .fold(0u8, |m, a| m | (1 << a.index()))
            })
            .collect();
        Self { masks }
    }

    /// ζ(s, a) ∈ {0, 1}.
    pub fn allows(&self, state: usize, a: Action) -> bool {
        self.masks[state] & (1 << a.index()) != 0
    }

    /// The bit mask of ζ(s, ·).
    pub fn mask(&self, state: usize) -> u8 {
        self.masks[state]
    }
}

/// Manhattan distance (cells) from each cell to the target and to the nearest
/// goal cell: the two sub-targets that ξ points to.
#[derive(Debug, Clone)]
pub struct SubTargetDistances {
    to_target: Vec<u32>,
    to_goal: Vec<u32>,
}

impl SubTargetDistances {
    pub fn of(task: &GridTask) -> Self {
        let grid = &task.grid;
        let to_target = (0..grid.len())
            .map(|i| manhattan(grid.cell(i), grid.target))
            .collect();
        let goal_cells: Vec<_> = (0..grid.len())
            .filter(|&i| grid.codes()[i] == CellCode::Goal)
            .map(|i| grid.cell(i))
            .collect();
        let to_goal = (0..grid.len())
            .map(|i| {
                goal_cells
                    .iter()
                    .map(|&g| manhattan(grid.cell(i), g))
                    .min()
                    .unwrap_or(0)
            })
            .collect();
        Self { to_target, to_goal }
    }

    /// Distance from `s`'s cell to its current sub-target.
    pub fn of_state(&self, task: &GridTask, s: AgentState) -> u32 {
        let i = task.grid.index(s.cell);
        if s.holding {
            self.to_goal[i]
        } else {
            self.to_target[i]
        }
    }
}

fn manhattan(a: (usize, usize), b: (usize, usize)) -> u32 {
    (a.0.abs_diff(b.0) + a.1.abs_diff(b.1)) as u32
}

/// Equation (9): the contextual initial Q-table, row-major `[state][action]`.
/// `affordance_value` is ζ's value for an afforded action (1 in the paper),
/// `distance_bias` is ξ (0.1).
pub fn contextual_q_table(
    task: &GridTask,
    zeta: &Affordances,
    affordance_value: f64,
    distance_bias: f64,
) -> Vec<f64> {
    let distances = SubTargetDistances::of(task);
    let mut q = vec![0.0; task.state_count() * Action::COUNT];
    for i in 0..task.state_count() {
        let s = task.state(i);
        let here = distances.of_state(task, s);
        for a in Action::ALL.into_iter().filter(|&a| zeta.allows(i, a)) {
            let xi = match task.step(s, a) {
                Outcome::Moved(next)
                    if a.delta().is_some() && distances.of_state(task, next) < here =>
                {
                    distance_bias
                }
                _ => 0.0,
            };
            q[i * Action::COUNT + a.index()] = affordance_value + xi;
        }
    }
    q
}
