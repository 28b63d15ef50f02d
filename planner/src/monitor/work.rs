//! New work (the paper's experiment 2): when the instruction asks for
//! "all" / "every" / "each" of a kind and the camera sees a matching piece
//! the robot has not handled, the instruction is read again on the newest
//! scene ([`crate::instruction::work`], the planner's own reading) and the
//! sub-goals of pieces not yet known become new work, done after the plan
//! in hand. Pieces that already rest in their goal are left, as in planning.

use crate::instruction::{SubGoal, work};
use crate::scenario::Scenario;

/// True when the instruction quantifies over every matching piece.
pub fn asks_for_all(instruction: &str) -> bool {
    instruction
        .split(|c: char| !c.is_alphanumeric())
        .any(|w| matches!(w.to_ascii_lowercase().as_str(), "all" | "every" | "each"))
}

/// The sub-goals the instruction gives on `scene` for objects not in
/// `known` (done, under way, planned or already new work). Empty when the
/// instruction does not ask for all of a kind or cannot be read on `scene`.
pub fn new_work(scene: &Scenario, seed: u64, known: &[String]) -> Vec<SubGoal> {
    if !asks_for_all(&scene.instruction) {
        return Vec::new();
    }
    let Ok(reading) = work(scene, seed) else {
        return Vec::new();
    };
    reading
        .subgoals
        .into_iter()
        .filter(|g| !known.contains(&g.object))
        .collect()
}
