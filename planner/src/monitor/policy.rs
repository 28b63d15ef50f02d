//! The paper's valid-policy check (section IV.C): the rest of a sub-goal's
//! discrete policy is re-simulated on the state grid of the newest scene
//! ([`crate::grid`], [`crate::task`]: the same transition function the
//! learner used). A step the grid refuses is the negative reward that
//! triggers: entering a 0.4 cell (a hand on the route), entering a 0.2 cell
//! (a blocker), GRASP where the target no longer is, GOAL from a cell no
//! longer beside the goal; and DROP where the planned release spot is no
//! longer inside the goal (experiment 4: "the drop would land on a 0.0
//! cell") is one too. The sub-goal's own target is left where the plan saw
//! it while it is held, so the grid keeps its geometry, and its release
//! spot leaves room for the later pieces the plan's did
//! ([`SubgoalPlan::room_for`]), so the DROP cell is the plan's.

use serde::Serialize;

use crate::grid::{Cell, CellCode, GridRequest, StateGrid};
use crate::place::{Outline, Room};
use crate::plan::SubgoalPlan;
use crate::scenario::{PixelBox, Scenario};
use crate::task::{Action, AgentState, GridTask, Outcome};

/// Why the rest of a policy fails on the new grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "fault", rename_all = "snake_case")]
pub enum Fault {
    /// A move enters a hand's cell (0.4); `hand` covers it.
    Hand { hand: String },
    /// A move enters an obstacle cell (0.2); `by` covers it.
    Blocked { by: String },
    /// The target is not where the plan grasps it.
    TargetMoved,
    /// The goal is not where the plan carries and drops the object.
    GoalMoved,
    /// The target is gone from the scene.
    TargetGone,
    /// The goal is gone from the scene.
    GoalGone,
}

/// The remaining policy of one sub-goal: its plan, the actions done, and
/// whether the object is in the gripper.
pub struct Remaining<'a> {
    pub plan: &'a SubgoalPlan,
    pub done: usize,
    pub holding: bool,
    /// The target's box the plan was made for (its grid's cell).
    pub target_box: PixelBox,
    /// The open fingers' half-widths for the release spot, m.
    pub opening: Option<[f64; 2]>,
}

/// Re-simulates the remaining actions on `scene`'s grid; `Ok` when they
/// still end with DROP inside the goal at the planned spot.
pub fn check(scene: &Scenario, r: &Remaining) -> Result<(), Fault> {
    let plan = r.plan;
    let object = scene.object_index(&plan.object).ok_or(Fault::TargetGone)?;
    let goal = scene.goal_index(&plan.goal).ok_or(Fault::GoalGone)?;
    let seen = scene.objects[object].bbox;
    if !r.holding && moved(seen, r.target_box) {
        return Err(Fault::TargetMoved);
    }
    let mut planned = scene.clone();
    planned.objects[object].bbox = r.target_box;
    let cells: Vec<Cell> = plan.cells.iter().map(|&[a, b]| (a, b)).collect();
    let from = cells[r.done.min(cells.len() - 1)];
    // The spot leaves room for the same later pieces as when planned.
    let later: Vec<usize> = plan
        .room_for
        .iter()
        .filter_map(|name| scene.object_index(name))
        .collect();
    let grid = StateGrid::build_painting(
        &planned,
        GridRequest {
            object,
            goal,
            gripper: centre(plan, from),
        },
        Room {
            opening: r.opening,
            later: &later,
        },
        plan.grid.obstacles,
    );
    if !release_inside(&planned, object, goal, plan.release_px) {
        return Err(Fault::GoalMoved);
    }
    if let Some(by) = release_taken(&planned, object, plan.release_px) {
        return Err(Fault::Blocked { by });
    }
    let task = GridTask::new(grid);
    let mut state = AgentState {
        cell: from,
        holding: r.holding,
    };
    for &action in &plan.actions[r.done.min(plan.actions.len())..] {
        state = match task.step(state, action) {
            Outcome::Moved(next) => next,
            Outcome::Done => return Ok(()),
            Outcome::Refused => {
                return Err(attributed(
                    scene,
                    goal,
                    refusal(scene, &task, state, action),
                ));
            }
        };
    }
    match r.done >= plan.actions.len() {
        true => Ok(()),
        false => Err(attributed(scene, goal, Fault::GoalMoved)),
    }
}

/// A goal the policy can no longer reach or drop into while a hand's
/// perimeter covers part of it did not move: the hand is in the way (the
/// release spot itself was checked inside the goal above).
fn attributed(scene: &Scenario, goal: usize, fault: Fault) -> Fault {
    if fault != Fault::GoalMoved {
        return fault;
    }
    let [mu, mv] = scene.metres_per_pixel();
    let margin = scene.safety.hand_margin;
    let g = scene.goals[goal].bbox;
    scene
        .hands
        .iter()
        .find(|h| overlap(h.bbox.grown(margin / mu, margin / mv), g))
        .map_or(fault, |h| Fault::Hand {
            hand: h.name.clone(),
        })
}

/// Two boxes share some area.
fn overlap(a: PixelBox, b: PixelBox) -> bool {
    a.u < b.u + b.w && b.u < a.u + a.w && a.v < b.v + b.l && b.v < a.v + a.l
}

/// Another piece lies where the object would be released (its footprint
/// centred on `release` overlaps the other's, round pieces as discs: the
/// packing's outlines, [`Outline`]): the piece's name.
fn release_taken(scene: &Scenario, object: usize, release: [f64; 2]) -> Option<String> {
    let outline = Outline::of(scene, &scene.objects[object]);
    scene
        .objects
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != object)
        .find(|(_, o)| outline.gap(scene, release, &Outline::of(scene, o), o.bbox.centre()) <= 0.0)
        .map(|(_, o)| o.name.clone())
}

/// Why `action` from `state` is refused.
fn refusal(scene: &Scenario, task: &GridTask, state: AgentState, action: Action) -> Fault {
    let grid = &task.grid;
    match action.delta() {
        Some((dr, dc)) => {
            let r = state.cell.0 as isize + dr;
            let c = state.cell.1 as isize + dc;
            if r < 0 || c < 0 || r as usize >= grid.rows || c as usize >= grid.cols {
                return Fault::GoalMoved;
            }
            let cell = (r as usize, c as usize);
            match grid.code(cell) {
                CellCode::Hand => Fault::Hand {
                    hand: covering(scene, grid, cell, true),
                },
                CellCode::Obstacle => Fault::Blocked {
                    by: covering(scene, grid, cell, false),
                },
                _ => Fault::GoalMoved,
            }
        }
        None if action == Action::Grasp => Fault::TargetMoved,
        None => Fault::GoalMoved,
    }
}

/// The name of the hand (or else the object or goal) whose box, grown by
/// its margin, covers `cell`'s centre; the nearest one when none does.
fn covering(scene: &Scenario, grid: &StateGrid, cell: Cell, hand: bool) -> String {
    let p = grid.centre(cell);
    let [mu, mv] = scene.metres_per_pixel();
    let grown =
        |b: PixelBox, m: f64| b.grown(m / mu + grid.cell_size[0], m / mv + grid.cell_size[1]);
    let hands = scene
        .hands
        .iter()
        .map(|h| (&h.name, grown(h.bbox, scene.safety.hand_margin)));
    let others = scene
        .objects
        .iter()
        .map(|o| (&o.name, grown(o.bbox, scene.safety.sensitive_margin)))
        .chain(
            scene
                .goals
                .iter()
                .map(|g| (&g.name, grown(g.bbox, scene.safety.obstacle_margin))),
        );
    let candidates: Vec<(&String, PixelBox)> = match hand {
        true => hands.collect(),
        false => others.collect(),
    };
    let distance = |b: &PixelBox| {
        let c = b.centre();
        (c[0] - p[0]).hypot(c[1] - p[1])
    };
    candidates
        .iter()
        .find(|(_, b)| b.contains(p))
        .or_else(|| {
            candidates
                .iter()
                .min_by(|a, b| distance(&a.1).total_cmp(&distance(&b.1)))
        })
        .map_or_else(|| "something".to_string(), |(n, _)| n.to_string())
}

/// The object's footprint centred on the planned release pixel lies inside
/// the goal's box.
fn release_inside(scene: &Scenario, object: usize, goal: usize, release: [f64; 2]) -> bool {
    let footprint = scene.objects[object].bbox.centred_at(release);
    let g = scene.goals[goal].bbox;
    footprint.u >= g.u - 1e-6
        && footprint.v >= g.v - 1e-6
        && footprint.u + footprint.w <= g.u + g.w + 1e-6
        && footprint.v + footprint.l <= g.v + g.l + 1e-6
}

/// A box moved when a corner shifted by more than a tenth of a pixel or
/// its size changed.
pub fn moved(a: PixelBox, b: PixelBox) -> bool {
    let (a, b) = (<[f64; 4]>::from(a), <[f64; 4]>::from(b));
    a.iter().zip(&b).any(|(x, y)| (x - y).abs() > 0.1)
}

/// Pixel centre of a cell of the plan's grid.
fn centre(plan: &SubgoalPlan, (r, c): Cell) -> [f64; 2] {
    let g = &plan.grid;
    [
        g.origin_px[0] + (c as f64 + 0.5) * g.cell_px[0],
        g.origin_px[1] + (r as f64 + 0.5) * g.cell_px[1],
    ]
}
