//! The scenario parser and validation, YAML and JSON: no input may panic,
//! and an accepted scenario must hold every documented bound.
#![no_main]

use afford_planner::scenario::{self, Format, bounds};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let format = if selector % 2 == 0 { Format::Yaml } else { Format::Json };
    let Ok(s) = scenario::parse(text, format, "fuzz") else {
        return;
    };
    // Accepted: the grid of every target is bounded, whatever it plans.
    for o in &s.objects {
        let cells = bounds::grid_cells_bound(s.camera.width, s.camera.height, o.bbox.w, o.bbox.l);
        assert!(cells <= bounds::MAX_GRID_CELLS as f64);
    }
    assert!(s.objects.len() <= bounds::MAX_OBJECTS);
    // Sub-goals and each sub-goal's grid, as `afford validate` draws them.
    if let Ok(goals) = afford_planner::instruction::subgoals(&s, 1) {
        for g in goals.iter().take(2) {
            let request = afford_planner::grid::GridRequest {
                object: s.object_index(&g.object).unwrap(),
                goal: s.goal_index(&g.goal).unwrap(),
                gripper: s.robot.start.unwrap_or_default(),
            };
            let grid = afford_planner::StateGrid::build(&s, request);
            assert!(grid.len() <= bounds::MAX_GRID_CELLS);
        }
    }
});
