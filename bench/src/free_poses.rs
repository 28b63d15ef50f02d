//! The safety campaign's feasibility probe of its refusals: each refused
//! sub-goal is given to afford-check's independent probe
//! ([`afford_check::probe`]: its own IK and collision geometry, no code
//! shared with the planner's), in the scene as it was when the planner
//! refused it, and counted per refusal kind as having free poses or not.
//!
//! The scene at a refusal: the scenario with every sub-goal planned before
//! it applied, each moved piece's box centred on its release spot, as the
//! planner's chain updates its world (the sub-goals' order is the
//! instruction's, [`afford_planner::instruction::subgoals`]). Refusals of
//! a plan that failed before any sub-goal ran (`robot_state`,
//! `instruction`, `other`) name no sub-goal and are not probed.

use std::collections::BTreeMap;

use afford_check::{Probe, ProbeSettings};
use afford_kinematics::RobotModel;
use afford_planner::error::UnsolvedSubgoal;
use afford_planner::plan::SubgoalPlan;
use afford_planner::scenario::Scenario;
use serde::Serialize;

/// Refused sub-goals of one kind, and how many of them have free poses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct FreePoseCount {
    /// Refused sub-goals (as `refusals` counts them).
    pub refusals: usize,
    /// Those the probe ran on (every refusal that names a sub-goal).
    pub probed: usize,
    /// Those the probe found free poses for.
    pub with_free_poses: usize,
}

impl FreePoseCount {
    /// Counts one refusal: `free` is the probe's verdict, `None` when it
    /// did not run.
    pub fn add(&mut self, free: Option<bool>) {
        self.refusals += 1;
        self.probed += usize::from(free.is_some());
        self.with_free_poses += usize::from(free == Some(true));
    }

    /// `with_free_poses/refusals` for a table cell.
    pub fn cell(&self) -> String {
        format!("{}/{}", self.with_free_poses, self.refusals)
    }
}

/// Per refusal kind (every kind listed, zeros where none).
pub type FreePoseCounts = BTreeMap<String, FreePoseCount>;

/// The scene each refused sub-goal was refused in, in `unsolved`'s order:
/// `scenario` with the pieces of the sub-goals planned before it centred
/// on their release spots. A refusal the instruction's order does not place
/// gets the original scene.
pub fn scenes_at_refusals(
    scenario: &Scenario,
    seed: u64,
    planned: &[SubgoalPlan],
    unsolved: &[UnsolvedSubgoal],
) -> Vec<Scenario> {
    let goals = afford_planner::instruction::subgoals(scenario, seed).unwrap_or_default();
    let mut out: Vec<Option<Scenario>> = vec![None; unsolved.len()];
    let mut world = scenario.clone();
    let (mut p, mut u) = (0, 0);
    for goal in &goals {
        let is = |object: &str, g: &str| object == goal.object && g == goal.goal;
        if unsolved.get(u).is_some_and(|r| is(&r.object, &r.goal)) {
            out[u] = Some(world.clone());
            u += 1;
        } else if let Some(done) = planned.get(p).filter(|d| is(&d.object, &d.goal)) {
            if let Some(i) = world.object_index(&done.object) {
                let piece = &mut world.objects[i];
                piece.bbox = piece.bbox.centred_at(done.release_px);
            }
            p += 1;
        }
    }
    out.into_iter()
        .map(|s| s.unwrap_or_else(|| scenario.clone()))
        .collect()
}

/// The probe's verdict on each refused sub-goal (`unsolved`'s order):
/// `Some(true)` with free poses, `Some(false)` without, `None` when the
/// probe could not run (its error is in the second value).
pub fn probe_refusals(
    robot: &RobotModel,
    scenario: &Scenario,
    seed: u64,
    planned: &[SubgoalPlan],
    unsolved: &[UnsolvedSubgoal],
) -> (Vec<Option<bool>>, Option<String>) {
    if unsolved.is_empty() {
        return (Vec::new(), None);
    }
    let probe = match Probe::new(robot, ProbeSettings::default()) {
        Ok(p) => p,
        Err(e) => return (vec![None; unsolved.len()], Some(e.to_string())),
    };
    let mut error = None;
    let verdicts = scenes_at_refusals(scenario, seed, planned, unsolved)
        .iter()
        .zip(unsolved)
        .map(
            |(scene, u)| match probe.free_poses(scene, &u.object, &u.goal) {
                Ok(found) => Some(found.is_some()),
                Err(e) => {
                    error.get_or_insert_with(|| e.to_string());
                    None
                }
            },
        )
        .collect();
    (verdicts, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_pose_counts_count_refusals_probed_and_free() {
        let mut c = FreePoseCount::default();
        for free in [Some(true), Some(false), None, Some(true)] {
            c.add(free);
        }
        assert_eq!(
            c,
            FreePoseCount {
                refusals: 4,
                probed: 3,
                with_free_poses: 2
            }
        );
        assert_eq!(c.cell(), "2/4");
    }

    /// The default scene's three sub-goals with the middle one refused:
    /// its scene has the first piece on its release spot, the last where
    /// the camera saw it.
    #[test]
    fn a_refusal_is_probed_in_the_scene_the_earlier_subgoals_left() {
        use afford_planner::error::Refusal;
        use afford_planner::instruction::SubGoal;
        let s = afford_planner::scenario::default_scenario().unwrap();
        let options = afford_planner::plan::PlanOptions::default();
        let plan = afford_planner::plan::plan(&s, &options).unwrap();
        assert_eq!(plan.subgoals.len(), 3);
        let [first, middle, last] = [0, 1, 2].map(|k| plan.subgoals[k].clone());
        let refused = UnsolvedSubgoal::new(
            &SubGoal {
                object: middle.object.clone(),
                goal: middle.goal.clone(),
            },
            Refusal::GoalFull {
                goal: middle.goal.clone(),
            },
        );
        let planned = [first.clone(), last.clone()];
        let scenes = scenes_at_refusals(&s, options.seed, &planned, &[refused]);
        assert_eq!(scenes.len(), 1);
        let at = |scene: &Scenario, name: &str| {
            let i = scene.object_index(name).unwrap();
            scene.objects[i].bbox.centre()
        };
        assert_eq!(at(&scenes[0], &first.object), first.release_px);
        assert_eq!(at(&scenes[0], &last.object), at(&s, &last.object));
        assert_eq!(at(&scenes[0], &middle.object), at(&s, &middle.object));
    }
}
