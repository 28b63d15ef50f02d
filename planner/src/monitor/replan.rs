//! Replanning during execution: from where braking now brings the robot
//! to rest or from the end of the sub-goal under way, new work taken over
//! after the last sub-goal, and vanished work dropped.

use crate::instruction::SubGoal;
use crate::plan::{MidExecution, Plan, Planner};
use crate::trajectory::arm_limits;

use super::decide::put_in_goal;
use super::execute::{self, planned_position};
use super::{Monitor, Pending, Reason, Status, Verdict};

/// Most controller periods a braking stop is simulated for.
const MAX_BRAKING_STEPS: usize = 100_000;

impl Monitor {
    /// After the last sub-goal: plan the new work from here, or finish.
    pub(super) fn take_new_work(&mut self) {
        let work = std::mem::take(&mut self.new_work);
        self.new_work = work.into_iter().filter(|g| self.still_wanted(g)).collect();
        if self.new_work.is_empty() {
            self.current -= 1;
            self.status = Status::Completed;
            return;
        }
        let goals: Vec<SubGoal> = std::mem::take(&mut self.new_work);
        let from = MidExecution {
            joints: self.joints.clone(),
            held: None,
        };
        let planner = Planner::new(self.options.clone());
        match planner.plan_from_loaded(&self.scene, &self.robot, &self.geometry, &goals, &from) {
            Ok(plan) if !plan.subgoals.is_empty() => self.adopt(plan),
            result => {
                self.current -= 1;
                let message = match result {
                    Err(e) => e.to_string(),
                    Ok(plan) => unsolved_text(&plan),
                };
                self.status = Status::Aborted(Reason::NoPlan { message });
            }
        }
    }

    /// A replan from where braking now brings the robot to rest (`now`),
    /// or from the end of the sub-goal under way.
    pub(super) fn replan(&mut self, reason: Reason, now: bool) -> Verdict {
        let (from, goals, scene) = match now {
            true => self.rest_state(),
            false => self.end_state(),
        };
        let first = now && !self.released();
        let dropped = matches!(reason, Reason::TargetGone { .. } | Reason::GoalGone { .. });
        if goals.is_empty() {
            return match (dropped, first) {
                // Nothing left of the instruction where the robot is.
                (true, true) => Verdict::Abort { reason },
                // The vanished work after this sub-goal is dropped.
                (true, false) => self.drop_later(reason),
                (false, _) => Verdict::Continue,
            };
        }
        let planner = Planner::new(self.options.clone());
        let planned = planner.plan_from_loaded(&scene, &self.robot, &self.geometry, &goals, &from);
        match planned {
            Ok(plan)
                if plan
                    .subgoals
                    .first()
                    .is_some_and(|g| g.object == goals[0].object) =>
            {
                self.pending = Some(match now {
                    true => Pending::AtRest(plan.clone()),
                    false => Pending::AtEnd(plan.clone()),
                });
                Verdict::Replan {
                    plan: Box::new(plan),
                    reason,
                }
            }
            Ok(plan) => Verdict::Abort {
                reason: Reason::NoPlan {
                    message: format!("{reason}; {}", unsolved_text(&plan)),
                },
            },
            Err(e) => Verdict::Abort {
                reason: Reason::NoPlan {
                    message: format!("{reason}; {e}"),
                },
            },
        }
    }

    /// Where braking now ends: the state, the sub-goals left, the scene.
    fn rest_state(&self) -> (MidExecution, Vec<SubGoal>, crate::Scenario) {
        let motion = self.motion();
        let limits = arm_limits(&self.robot, self.current_arm());
        let braking = self.braking();
        let stop = execute::stopping_point(
            motion,
            &limits,
            &self.cursor,
            self.dt,
            MAX_BRAKING_STEPS,
            Some(&braking),
        );
        let mut joints = self.joints.clone();
        self.current_arm()
            .insert(&mut joints, &planned_position(&motion.points, stop.s));
        // The robot plays every gripper event it reaches before it rests
        // (`tick`), so it holds at rest when the stop is at or after the
        // close's start and before the open's start.
        let track = &self.tracks[self.current];
        let holds = (track.starts_holding || stop.s >= track.close.0 - 1e-9)
            && stop.s < track.open.0 - 1e-9;
        let held = holds.then(|| {
            self.held
                .clone()
                .unwrap_or_else(|| self.grasp_record(motion, track.close.0))
        });
        let goals = self.goals_from(self.current + usize::from(self.released()));
        (MidExecution { joints, held }, goals, self.scene.clone())
    }

    /// The end of the sub-goal under way: the state, the sub-goals after
    /// it, the scene with its object in its goal.
    fn end_state(&self) -> (MidExecution, Vec<SubGoal>, crate::Scenario) {
        let mut joints = self.joints.clone();
        if let Some(last) = self.motion().points.last() {
            self.current_arm().insert(&mut joints, &last.positions);
        }
        let mut scene = self.scene.clone();
        put_in_goal(&mut scene, &self.plan.subgoals[self.current]);
        let goals = self.goals_from(self.current + 1);
        (MidExecution { joints, held: None }, goals, scene)
    }

    /// The sub-goals from number `k` on whose object and goal are still
    /// in the scene (vanished work is dropped).
    fn goals_from(&self, k: usize) -> Vec<SubGoal> {
        self.plan.subgoals[k.min(self.plan.subgoals.len())..]
            .iter()
            .map(|g| SubGoal {
                object: g.object.clone(),
                goal: g.goal.clone(),
            })
            .filter(|g| self.still_wanted(g))
            .collect()
    }

    /// The sub-goal's object and goal are on the table.
    pub(super) fn still_wanted(&self, g: &SubGoal) -> bool {
        self.scene.object_index(&g.object).is_some() && self.scene.goal_index(&g.goal).is_some()
    }

    /// Drops the sub-goals after the one under way (their work vanished
    /// and nothing else is left): the run ends with this one.
    fn drop_later(&mut self, reason: Reason) -> Verdict {
        let keep = self.current + 1;
        self.plan.subgoals.truncate(keep);
        self.tracks.truncate(keep);
        self.planned_boxes.truncate(keep);
        self.pending = None;
        Verdict::Replan {
            plan: Box::new(Plan {
                subgoals: Vec::new(),
                unsolved: Vec::new(),
                ..self.plan.clone()
            }),
            reason,
        }
    }
}

/// The unsolved sub-goals of a plan, in words.
fn unsolved_text(plan: &Plan) -> String {
    plan.unsolved
        .iter()
        .map(|u| format!("{} → {}: {}", u.object, u.goal, u.reason))
        .collect::<Vec<_>>()
        .join("; ")
}
