//! The BFS oracle: the shortest action sequence over (cell, holding) under the
//! same affordances the learners see. It is the physical limit a learner is
//! measured against (optimal plan length, solvability) — a test and benchmark
//! oracle, not the planner.

use std::collections::VecDeque;

use crate::task::{Action, GridTask, Outcome};

/// Length of the shortest plan (actions, DROP included), or `None` when the
/// task is unsolvable.
pub fn optimal_length(task: &GridTask) -> Option<usize> {
    shortest_plan(task).map(|p| p.len())
}

/// A shortest plan, or `None` when the task is unsolvable.
pub fn shortest_plan(task: &GridTask) -> Option<Vec<Action>> {
    let n = task.state_count();
    let mut parent: Vec<Option<(usize, Action)>> = vec![None; n];
    let mut seen = vec![false; n];
    let start = task.state_index(task.start());
    seen[start] = true;
    let mut queue = VecDeque::from([start]);
    while let Some(i) = queue.pop_front() {
        for a in Action::ALL {
            match task.step(task.state(i), a) {
                Outcome::Done => return Some(unwind(&parent, i, a)),
                Outcome::Moved(next) => {
                    let j = task.state_index(next);
                    if !seen[j] {
                        seen[j] = true;
                        parent[j] = Some((i, a));
                        queue.push_back(j);
                    }
                }
                Outcome::Refused => {}
            }
        }
    }
    None
}

fn unwind(parent: &[Option<(usize, Action)>], mut i: usize, last: Action) -> Vec<Action> {
    let mut actions = vec![last];
    while let Some((p, a)) = parent[i] {
        actions.push(a);
        i = p;
    }
    actions.reverse();
    actions
}
