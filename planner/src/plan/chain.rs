//! The sub-goal chain: the sub-goals one after another, the world updated
//! after each, and going back to an earlier sub-goal when a later one
//! cannot be planned from where it left the world.

use std::time::{Duration, Instant};

use super::types::{Planner, StageTimings, SubgoalPlan};
use super::world::{
    FailedTransits, Pass, Rewound, Snapshot, World, later_in_goal, request, subgoal_seed,
};
use crate::error::{Refusal, UnsolvedSubgoal};
use crate::instruction::SubGoal;
use crate::start::{self};

impl Planner {
    /// The sub-goals one after another, the world updated after each. An
    /// arm stays where its sub-goal left it, except after the last sub-goal,
    /// where it returns to park (when it has a park posture). When a
    /// sub-goal's motion cannot be planned and the arm of the last planned
    /// sub-goal stayed out of park, that sub-goal is planned again with the
    /// arm returning to park, and the failed one is tried once more; if the
    /// parked version does not plan, the first outcome stands.
    pub(super) fn plan_chain(
        &self,
        world: &mut World,
        goals: &[SubGoal],
        timings: &mut StageTimings,
    ) -> (Vec<SubgoalPlan>, Vec<UnsolvedSubgoal>) {
        timings.per_subgoal = vec![Duration::ZERO; goals.len()];
        let mut park = vec![false; goals.len()];
        if let Some(last) = park.last_mut() {
            *last = true;
        }
        let mut outcomes: Vec<Result<SubgoalPlan, Refusal>> = Vec::new();
        let mut snapshots: Vec<Option<Snapshot>> = vec![None; goals.len()];
        // After a rewind to sub-goal j: the outcomes and the world as they
        // were, restored when j does not plan with its arm parking.
        let mut fallback: Option<Rewound> = None;
        while outcomes.len() < goals.len() {
            let k = outcomes.len();
            let goal = &goals[k];
            let request = request(&world.scene, goal, world.gripper_px);
            snapshots[k] = Some(world.snapshot());
            let later = later_in_goal(&world.scene, goals, k);
            let failed_transits = FailedTransits::default();
            let pass = Pass {
                world,
                goal,
                request,
                seed: subgoal_seed(self.options.seed, k),
                park: park[k],
                later: &later,
                failed_transits: &failed_transits,
            };
            let started = Instant::now();
            let planned = self.plan_subgoal(pass, timings);
            timings.per_subgoal[k] += started.elapsed();
            let refused = match planned {
                Ok(done) => {
                    world.advance(request, &done);
                    outcomes.push(Ok(done));
                    fallback = None;
                    continue;
                }
                Err(refused) => refused,
            };
            if let Some((j, saved, state)) = fallback.take() {
                park[j] = false;
                outcomes = saved;
                world.restore(state);
                continue;
            }
            let rewind = match refused.motion {
                true => self.rewind_to(world, &outcomes, &park),
                false => None,
            };
            let Some(j) = rewind else {
                outcomes.push(Err(*refused.reason));
                continue;
            };
            let mut saved = outcomes.clone();
            saved.push(Err(*refused.reason));
            fallback = Some((j, saved, world.snapshot()));
            park[j] = true;
            outcomes.truncate(j);
            if let Some(state) = snapshots[j].clone() {
                world.restore(state);
            }
        }
        let mut subgoals = Vec::new();
        let mut unsolved = Vec::new();
        for (goal, outcome) in goals.iter().zip(outcomes) {
            match outcome {
                Ok(done) => subgoals.push(done),
                Err(refusal) => unsolved.push(UnsolvedSubgoal::new(goal, refusal)),
            }
        }
        (subgoals, unsolved)
    }

    /// The last planned sub-goal, when its arm stayed out of park (it has a
    /// park posture and is not at it): the one to plan again with the arm
    /// parking at its end.
    pub(super) fn rewind_to(
        &self,
        world: &World,
        outcomes: &[Result<SubgoalPlan, Refusal>],
        park: &[bool],
    ) -> Option<usize> {
        let robot = world.robot.as_ref()?;
        let j = outcomes.iter().rposition(|o| o.is_ok())?;
        let arm = outcomes[j].as_ref().ok()?.arm.as_ref()?;
        let arm = robot.arm(arm).ok()?;
        (!park[j] && !arm.park.is_empty() && !start::is_parked(arm, &world.joints)).then_some(j)
    }
}
