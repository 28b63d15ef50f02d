//! Property tests over random solvable grids: every Contextual Q-learning
//! plan is valid, the same seed gives the same plan, and plain Q-learning's
//! plans are valid whenever it reports one solved.
//!
//! Validity is checked by an independent replay on the raw cell codes (it
//! does not call `GridTask::step`), from the rules of the issue:
//! moves stay on the grid and never enter 0.2 (obstacle) or 0.4 (hand)
//! cells, nor a goal cell while holding; GRASP happens exactly once, on the
//! target, before GOAL; GOAL is taken while holding, from a cell next to
//! (8-neighbourhood) the goal, and carries the object over the wall into one
//! of those goal cells and on to the drop cell in straight legs that cross no
//! blocked cell; the plan ends with DROP on the drop cell.

use afford::planner::cql::{ContextualQLearner, LearnedPlan, LearnerSettings, QLearner};
use afford::planner::grid::{CellCode, StateGrid};
use afford::planner::oracle;
use afford::planner::task::{Action, GridTask};
use proptest::prelude::*;
use proptest::test_runner::{RngAlgorithm, RngSeed};

type Cell = (usize, usize);

/// A random grid: codes, start cell.
#[derive(Debug, Clone)]
struct Spec {
    rows: usize,
    cols: usize,
    codes: Vec<CellCode>,
    start: Cell,
}

impl Spec {
    fn task(&self) -> GridTask {
        let grid = StateGrid::from_codes(self.rows, self.cols, self.codes.clone(), self.start)
            .expect("the generator builds well-formed grids");
        GridTask::new(grid)
    }
}

/// Grids of 3..=20 cells per side: random obstacles and hands (each up to
/// a density drawn per grid), one goal block of 1..=3 × 1..=3 cells, exactly
/// one target outside the goal, a start anywhere that is not blocked.
fn spec() -> impl Strategy<Value = Spec> {
    (3usize..=20, 3usize..=20)
        .prop_flat_map(|(rows, cols)| {
            let n = rows * cols;
            (
                Just(rows),
                Just(cols),
                proptest::collection::vec(0u8..100, n),
                0u8..35, // obstacle density, percent
                0u8..12, // hand density, percent
                (0..rows, 0..cols, 1usize..=3, 1usize..=3),
                0..n, // target
                0..n, // start
            )
        })
        .prop_map(
            |(rows, cols, noise, obstacles, hands, block, target, start)| {
                let mut codes: Vec<CellCode> = noise
                    .iter()
                    .map(|&x| {
                        if x < obstacles {
                            CellCode::Obstacle
                        } else if x < obstacles + hands {
                            CellCode::Hand
                        } else {
                            CellCode::Empty
                        }
                    })
                    .collect();
                let (r0, c0, h, w) = block;
                // Never the whole grid: at least one row stays outside the block.
                let h = h.min(rows - 1);
                let (r1, c1) = ((r0 + h).min(rows), (c0 + w).min(cols));
                for r in r0..r1 {
                    for c in c0..c1 {
                        codes[r * cols + c] = CellCode::Goal;
                    }
                }
                let n = rows * cols;
                let target = (0..n)
                    .map(|k| (target + k) % n)
                    .find(|&i| codes[i] != CellCode::Goal)
                    .expect("a cell outside the goal");
                codes[target] = CellCode::Target;
                if codes[start].is_blocked() {
                    codes[start] = CellCode::Empty;
                }
                Spec {
                    rows,
                    cols,
                    codes,
                    start: (start / cols, start % cols),
                }
            },
        )
}

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        max_global_rejects: 50_000,
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0xAFF0_2D5E),
        ..ProptestConfig::default()
    }
}

/// Does the straight segment between the centres of `a` and `b` pass through
/// the inside of cell `blocked`, shrunk by 0.05 of a cell on every side?
/// (Slab test on the segment's parameter.)
fn segment_crosses(a: Cell, b: Cell, blocked: Cell) -> bool {
    const INSET: f64 = 0.05;
    let p = [a.0 as f64 + 0.5, a.1 as f64 + 0.5];
    let q = [b.0 as f64 + 0.5, b.1 as f64 + 0.5];
    let lo = [blocked.0 as f64 + INSET, blocked.1 as f64 + INSET];
    let hi = [
        blocked.0 as f64 + 1.0 - INSET,
        blocked.1 as f64 + 1.0 - INSET,
    ];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..2 {
        let d = q[k] - p[k];
        if d.abs() < 1e-12 {
            if p[k] < lo[k] || p[k] > hi[k] {
                return false;
            }
        } else {
            let (mut ta, mut tb) = ((lo[k] - p[k]) / d, (hi[k] - p[k]) / d);
            if ta > tb {
                std::mem::swap(&mut ta, &mut tb);
            }
            t0 = t0.max(ta);
            t1 = t1.min(tb);
        }
    }
    t0 <= t1
}

/// Replays `plan` on the raw codes of `grid`; `Err` says what is wrong.
fn validate(grid: &StateGrid, plan: &LearnedPlan) -> Result<(), String> {
    let (rows, cols) = (grid.rows, grid.cols);
    let code = |(r, c): Cell| grid.codes()[r * cols + c];
    let blocked = |cell: Cell| matches!(code(cell), CellCode::Obstacle | CellCode::Hand);
    let cells_of = |want: CellCode| -> Vec<Cell> {
        (0..rows * cols)
            .map(|i| (i / cols, i % cols))
            .filter(|&cell| code(cell) == want)
            .collect()
    };
    let targets = cells_of(CellCode::Target);
    let [target] = targets[..] else {
        return Err(format!("the grid has {} target cells", targets.len()));
    };
    let Some(drop) = grid.drop else {
        return Err("a solved plan on a grid without a drop cell".into());
    };
    if code(drop) != CellCode::Goal {
        return Err(format!("the drop cell {drop:?} is not a goal cell"));
    }

    let actions = &plan.actions;
    if plan.cells.len() != actions.len() + 1 {
        return Err(format!(
            "{} cells for {} actions",
            plan.cells.len(),
            actions.len()
        ));
    }
    if plan.cells[0] != grid.start {
        return Err(format!("cells[0] {:?} is not the start", plan.cells[0]));
    }
    let mut at = grid.start;
    let (mut holding, mut grasps, mut carried) = (false, 0, false);
    for (k, &a) in actions.iter().enumerate() {
        let step = format!("action {k} ({a:?}) at {at:?}");
        let delta: Option<(isize, isize)> = match a {
            Action::Up => Some((-1, 0)),
            Action::Down => Some((1, 0)),
            Action::Left => Some((0, -1)),
            Action::Right => Some((0, 1)),
            _ => None,
        };
        if let Some((dr, dc)) = delta {
            let (r, c) = (at.0 as isize + dr, at.1 as isize + dc);
            if r < 0 || c < 0 || r >= rows as isize || c >= cols as isize {
                return Err(format!("{step}: leaves the grid"));
            }
            let next = (r as usize, c as usize);
            if blocked(next) {
                return Err(format!("{step}: enters the {:?} cell {next:?}", code(next)));
            }
            if holding && code(next) == CellCode::Goal {
                return Err(format!(
                    "{step}: enters the goal cell {next:?} while holding"
                ));
            }
            if carried {
                return Err(format!("{step}: moves after GOAL"));
            }
            at = next;
        } else {
            match a {
                Action::Grasp => {
                    if holding || at != target {
                        return Err(format!(
                            "{step}: GRASP off the target {target:?} or while holding"
                        ));
                    }
                    holding = true;
                    grasps += 1;
                }
                Action::Goal => {
                    if !holding || carried {
                        return Err(format!("{step}: GOAL without holding, or twice"));
                    }
                    if code(at) == CellCode::Goal {
                        return Err(format!("{step}: GOAL from inside the goal"));
                    }
                    // The carry crosses the wall into an 8-adjacent goal cell
                    // and goes on to the drop cell, both legs straight and
                    // clear of blocked cells.
                    let entries: Vec<Cell> = (-1isize..=1)
                        .flat_map(|dr| (-1isize..=1).map(move |dc| (dr, dc)))
                        .map(|(dr, dc)| (at.0 as isize + dr, at.1 as isize + dc))
                        .filter(|&(r, c)| {
                            r >= 0 && c >= 0 && r < rows as isize && c < cols as isize
                        })
                        .map(|(r, c)| (r as usize, c as usize))
                        .filter(|&cell| code(cell) == CellCode::Goal)
                        .collect();
                    if entries.is_empty() {
                        return Err(format!("{step}: GOAL from a cell not next to the goal"));
                    }
                    let leg_is_clear = |a: Cell, b: Cell| {
                        (0..rows * cols)
                            .map(|i| (i / cols, i % cols))
                            .all(|cell| !blocked(cell) || !segment_crosses(a, b, cell))
                    };
                    if !entries
                        .iter()
                        .any(|&e| leg_is_clear(at, e) && leg_is_clear(e, drop))
                    {
                        return Err(format!(
                            "{step}: every carry over the wall to {drop:?} crosses a blocked cell"
                        ));
                    }
                    at = drop;
                    carried = true;
                }
                Action::Drop => {
                    if !holding || !carried || at != drop {
                        return Err(format!(
                            "{step}: DROP away from the drop cell {drop:?}, or before GOAL"
                        ));
                    }
                    if k + 1 != actions.len() {
                        return Err(format!("{step}: actions after DROP"));
                    }
                    holding = false;
                }
                _ => unreachable!("moves are handled above"),
            }
        }
        if plan.cells[k + 1] != at {
            return Err(format!(
                "{step}: cells[{}] is {:?}, the replay is at {at:?}",
                k + 1,
                plan.cells[k + 1]
            ));
        }
    }
    if grasps != 1 {
        return Err(format!("{grasps} GRASPs"));
    }
    if actions.last() != Some(&Action::Drop) || holding {
        return Err("the plan does not end with DROP".into());
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(500))]

    #[test]
    fn cql_plans_on_solvable_grids_are_valid_and_reproducible(spec in spec(), seed in any::<u64>()) {
        let task = spec.task();
        let optimal = oracle::optimal_length(&task);
        prop_assume!(optimal.is_some());
        let optimal = optimal.unwrap();
        let learner = ContextualQLearner::new(LearnerSettings::default());
        let plan = learner.learn(&task, seed);
        prop_assert!(
            plan.solved,
            "CQL did not solve a solvable grid in {} steps", plan.training_steps
        );
        if let Err(why) = validate(&task.grid, &plan) {
            return Err(TestCaseError::fail(format!("invalid plan: {why}\n{plan:?}")));
        }
        prop_assert!(
            plan.actions.len() >= optimal,
            "plan of {} actions is shorter than the optimum {optimal}", plan.actions.len()
        );
        let again = ContextualQLearner::new(LearnerSettings::default()).learn(&spec.task(), seed);
        prop_assert_eq!(&plan, &again, "same seed, different plan");
    }
}

proptest! {
    #![proptest_config(config(150))]

    #[test]
    fn ql_plans_when_solved_are_valid(spec in spec(), seed in any::<u64>()) {
        let task = spec.task();
        let optimal = oracle::optimal_length(&task);
        prop_assume!(optimal.is_some());
        let plan = QLearner::new(LearnerSettings::default()).learn(&task, seed);
        if plan.solved {
            if let Err(why) = validate(&task.grid, &plan) {
                return Err(TestCaseError::fail(format!("invalid QL plan: {why}\n{plan:?}")));
            }
            prop_assert!(plan.actions.len() >= optimal.unwrap());
        }
        prop_assert_eq!(
            &plan,
            &QLearner::new(LearnerSettings::default()).learn(&task, seed),
            "same seed, different QL plan"
        );
    }
}

/// The validator itself rejects what it must: a known-good plan passes and
/// each kind of corruption fails.
#[test]
fn the_validator_catches_broken_plans() {
    use CellCode::{Empty as E, Goal as G, Obstacle as O, Target as T};
    // Row 0: T . . ; row 1: . O . ; row 2: . . G  (start at (0, 1))
    let codes = vec![T, E, E, E, O, E, E, E, G];
    let task = GridTask::new(StateGrid::from_codes(3, 3, codes, (0, 1)).unwrap());
    let good = LearnedPlan {
        actions: vec![
            Action::Left,
            Action::Grasp,
            Action::Down,
            Action::Down,
            Action::Right,
            Action::Goal,
            Action::Drop,
        ],
        cells: vec![
            (0, 1),
            (0, 0),
            (0, 0),
            (1, 0),
            (2, 0),
            (2, 1),
            (2, 2),
            (2, 2),
        ],
        solved: true,
        training_steps: 1,
        converged: true,
    };
    assert_eq!(validate(&task.grid, &good), Ok(()));
    assert_eq!(oracle::optimal_length(&task), Some(good.actions.len()));

    let broken = |actions: Vec<Action>, cells: Vec<Cell>| LearnedPlan {
        actions,
        cells,
        ..good.clone()
    };
    use Action::{Down, Drop, Goal, Grasp, Left, Right, Up};
    let bad = [
        // Into the obstacle.
        broken(vec![Down], vec![(0, 1), (1, 1)]),
        // Off the grid.
        broken(vec![Up], vec![(0, 1), (0, 1)]),
        // GRASP off the target.
        broken(vec![Grasp], vec![(0, 1), (0, 1)]),
        // GOAL without holding.
        broken(
            vec![Right, Down, Goal],
            vec![(0, 1), (0, 2), (1, 2), (2, 2)],
        ),
        // Holding, walks into the goal instead of GOAL.
        broken(
            vec![Left, Grasp, Down, Down, Right, Right, Drop],
            vec![
                (0, 1),
                (0, 0),
                (0, 0),
                (1, 0),
                (2, 0),
                (2, 1),
                (2, 2),
                (2, 2),
            ],
        ),
        // Cells that disagree with the actions.
        broken(
            good.actions.clone(),
            vec![
                (0, 1),
                (0, 0),
                (0, 0),
                (1, 0),
                (2, 0),
                (2, 1),
                (2, 2),
                (2, 1),
            ],
        ),
        // Ends before DROP.
        broken(good.actions[..6].to_vec(), good.cells[..7].to_vec()),
        // Two GRASPs.
        broken(
            vec![Left, Grasp, Grasp, Down, Down, Right, Goal, Drop],
            vec![
                (0, 1),
                (0, 0),
                (0, 0),
                (0, 0),
                (1, 0),
                (2, 0),
                (2, 1),
                (2, 2),
                (2, 2),
            ],
        ),
    ];
    for plan in bad {
        assert!(
            validate(&task.grid, &plan).is_err(),
            "accepted {:?}",
            plan.actions
        );
    }
    // GOAL from (2, 0) must carry the object into (3, 1), the only goal cell
    // next to it, and on to the drop cell (3, 3): that second leg crosses
    // the obstacle at (3, 2).
    let codes = vec![
        T, E, E, E, E, //
        E, E, E, E, E, //
        E, E, E, E, E, //
        E, G, O, G, G, //
        E, G, G, G, G,
    ];
    let task = GridTask::new(StateGrid::from_codes(5, 5, codes, (0, 0)).unwrap());
    assert_eq!(task.grid.drop, Some((4, 3)));
    let across = LearnedPlan {
        actions: vec![Grasp, Down, Down, Goal, Drop],
        cells: vec![(0, 0), (0, 0), (1, 0), (2, 0), (4, 3), (4, 3)],
        ..good.clone()
    };
    let why = validate(&task.grid, &across).expect_err("the carry crosses (3, 2)");
    assert!(why.contains("crosses"), "{why}");
    // From (2, 3) the carry enters at (3, 3) and goes straight down: valid.
    let beside = LearnedPlan {
        actions: vec![Grasp, Right, Right, Right, Down, Down, Goal, Drop],
        cells: vec![
            (0, 0),
            (0, 0),
            (0, 1),
            (0, 2),
            (0, 3),
            (1, 3),
            (2, 3),
            (4, 3),
            (4, 3),
        ],
        ..good.clone()
    };
    assert_eq!(validate(&task.grid, &beside), Ok(()));
    assert!(!segment_crosses((2, 2), (3, 2), (2, 1)));
    assert!(
        !segment_crosses((2, 3), (3, 2), (2, 2)),
        "a corner touch is not a crossing"
    );
}

/// The property tests are not vacuous: the generator yields grids of every
/// size, most of them solvable, many needing detours around obstacles and
/// hands, and some unsolvable ones that `prop_assume!` skips.
#[test]
fn the_generator_yields_varied_grids_mostly_solvable() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::{TestRng, TestRunner};
    let mut runner =
        TestRunner::new_with_rng(config(1), TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let strategy = spec();
    let (mut solvable, mut detours, mut hands, mut large) = (0, 0, 0, 0);
    let (mut ql_tried, mut ql_solved) = (0, 0);
    const N: usize = 300;
    for _ in 0..N {
        let spec = strategy.new_tree(&mut runner).expect("a grid").current();
        let task = spec.task();
        let targets = spec
            .codes
            .iter()
            .filter(|&&c| c == CellCode::Target)
            .count();
        assert_eq!(targets, 1, "{spec:?}");
        assert!((3..=20).contains(&spec.rows) && (3..=20).contains(&spec.cols));
        large += usize::from(spec.rows >= 15 && spec.cols >= 15);
        hands += usize::from(spec.codes.contains(&CellCode::Hand));
        if let Some(optimal) = oracle::optimal_length(&task) {
            solvable += 1;
            // The same grid without obstacles and hands: a shorter optimum
            // there means the obstacles forced a detour.
            let open = Spec {
                codes: spec
                    .codes
                    .iter()
                    .map(|&c| if c.is_blocked() { CellCode::Empty } else { c })
                    .collect(),
                ..spec.clone()
            };
            let free = oracle::optimal_length(&open.task()).expect("an open grid is solvable");
            detours += usize::from(optimal > free);
            if ql_tried < 60 {
                ql_tried += 1;
                let plan = QLearner::new(LearnerSettings::default()).learn(&task, 1);
                ql_solved += usize::from(plan.solved);
            }
        }
    }
    assert!(
        solvable >= N / 2,
        "only {solvable} of {N} grids are solvable"
    );
    assert!(
        solvable < N,
        "every grid is solvable: prop_assume! never skips"
    );
    assert!(detours >= N / 20, "only {detours} grids need a detour");
    assert!(hands >= N / 2, "only {hands} grids have hands");
    assert!(large >= N / 20, "only {large} grids are 15x15 or larger");
    // Otherwise "QL plans, when solved, are valid" would check nothing.
    assert!(
        ql_solved >= ql_tried / 4,
        "QL solved only {ql_solved} of {ql_tried} solvable grids"
    );
    eprintln!(
        "{N} grids: {solvable} solvable, {detours} with detours, {hands} with hands, \
         {large} large; QL solved {ql_solved} of the first {ql_tried} solvable"
    );
}
