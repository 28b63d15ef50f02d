//! A gripper over a hand's grid cells (the hand's footprint grown by its
//! margin, painted as a column although the 3-D perimeter has a top). A
//! hand's cells are never cleared, so a grid whose start cell is a hand cell
//! starts the learner at the free cell nearest the gripper instead; the
//! route ([`crate::motion::route`]) leaves from the tool itself without
//! going deeper into the perimeter it is in. The 3-D collision checks keep
//! the full margin: a robot that is inside a hand's 3-D perimeter where it
//! stands is refused (`hand_covers_gripper`).

use crate::grid::{Cell, CellCode, StateGrid};

/// The cell the learner starts from when the gripper at pixel `gripper`
/// lies in a hand cell: the unblocked cell whose centre is nearest the
/// gripper (ties: the earlier cell in row-major order). `None` when the
/// start cell is no hand cell, or when every cell is blocked.
pub fn exit_cell(grid: &StateGrid, gripper: [f64; 2]) -> Option<Cell> {
    if grid.code(grid.start) != CellCode::Hand {
        return None;
    }
    let distance = |cell: Cell| {
        let [u, v] = grid.centre(cell);
        (u - gripper[0]).hypot(v - gripper[1])
    };
    (0..grid.len())
        .map(|i| grid.cell(i))
        .filter(|&cell| !grid.code(cell).is_blocked())
        .map(|cell| (distance(cell), cell))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, cell)| cell)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3 × 4 grid with a hand over the two left columns of the top rows,
    /// the gripper starting in cell `start`.
    fn grid_with_hand(start: Cell) -> StateGrid {
        use CellCode::{Empty as E, Hand as H, Target as T};
        let codes = vec![H, H, E, E, H, H, E, E, E, E, E, T];
        StateGrid::from_codes(3, 4, codes, start).expect("a valid grid")
    }

    #[test]
    fn a_gripper_over_a_hand_starts_at_the_nearest_free_cell() {
        // Cells are 1 px: from the centre of (0, 1) column 2 is nearer than
        // row 2; from (1, 0) row 2 is.
        let g = grid_with_hand((0, 1));
        assert_eq!(exit_cell(&g, g.centre((0, 1))), Some((0, 2)));
        let g = grid_with_hand((1, 0));
        assert_eq!(exit_cell(&g, g.centre((1, 0))), Some((2, 0)));
    }

    #[test]
    fn a_gripper_over_a_free_cell_keeps_its_start() {
        let g = grid_with_hand((2, 3));
        assert_eq!(exit_cell(&g, g.centre((2, 3))), None);
    }
}
