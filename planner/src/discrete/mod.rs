//! The discrete stages of the pipeline (the paper's Fig. 2, left half): the
//! state grid (Algorithm 2), the grid task as an MDP (equation 5), the
//! affordances and contextual initial Q-table (equations 7–9), the learners
//! (equations 10–11, Algorithm 3) and the BFS oracle they are measured
//! against, and the export of a grid MDP for outside learners. Everything here works in grid cells and pixels; nothing knows
//! about the robot.

pub mod affordance;
pub mod cql;
pub mod export;
pub mod grid;
pub mod hand_exit;
pub mod oracle;
pub mod route_grid;
pub mod task;
