//! The grid a sub-goal is planned on. The paper's grid paints every other
//! object and goal, grown by its margin, over every cell it touches; with
//! cells the size of the target, the gap between two grown boxes that a
//! straight carry crosses can round shut and leave the gripper no route
//! at all (`no_route` on an open table). Then the grid is built again with
//! only the sensitive objects and the hands blocked ([`Obstacles::Sensitive`]):
//! the carry passes over the rest at the height of the tallest thing under
//! it, and the 3-D collision check still keeps every margin. The paper's
//! grid is kept whenever it has a route, so such plans do not change.

use crate::grid::{Cell, GridRequest, Obstacles, StateGrid};
use crate::oracle;
use crate::place::Room;
use crate::scenario::Scenario;
use crate::task::GridTask;

/// The grid task for moving `req.object` into `req.goal` with `blocked`
/// cells added (after collision checks) and its BFS optimum: the paper's
/// grid when it has a route, else the grid passing over what is not
/// sensitive when that one has; the paper's grid with `None` otherwise.
pub fn routable_task(
    scenario: &Scenario,
    req: GridRequest,
    room: Room,
    blocked: &[Cell],
) -> (GridTask, Option<usize>) {
    let task = |obstacles: Obstacles| {
        let mut grid = StateGrid::build_painting(scenario, req, room, obstacles);
        blocked.iter().for_each(|&cell| grid.block(cell));
        let task = GridTask::new(grid);
        let optimal = oracle::optimal_length(&task);
        (task, optimal)
    };
    let first = task(Obstacles::All);
    if first.1.is_some() {
        return first;
    }
    let over = task(Obstacles::Sensitive);
    match over.1 {
        Some(_) => over,
        None => first,
    }
}
