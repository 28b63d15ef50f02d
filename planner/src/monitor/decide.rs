//! The decision on the believed scene: the triggers of the policy ahead
//! (discrete re-simulation, geometric re-check, new work) — evaluated again
//! only when the scene, the plan or the sub-goal under way changes — then
//! the separation rule and the waiting, each frame.

use std::time::Instant;

use crate::plan::SubgoalPlan;
use crate::scenario::Scenario;
use crate::timing::trajectory::hands;

use super::execute::planned_position;
use super::policy::{self, Fault, Remaining};
use super::route::{self, RemainingMotion};
use super::separation::{self, LOOKAHEAD_S, Separation};
use super::track::Track;
use super::work::new_work;
use super::{MAX_WAIT_S, Monitor, Pending, Reason, Verdict};

/// A trigger of the policy ahead, before it becomes a verdict.
enum Trigger {
    Wait(Reason),
    /// `now`: the sub-goal under way (brake and replan from rest); else a
    /// later one (replan from the end of this one).
    Replan {
        reason: Reason,
        now: bool,
    },
    Abort(Reason),
}

impl Monitor {
    /// The verdict now, and the replan's wall-clock time (ms) if one ran.
    pub(super) fn decide(&mut self) -> (Verdict, Option<f64>) {
        if self.trigger.is_none() {
            let trigger = self.policy_trigger();
            self.changes.clear();
            let fresh = self.new_subgoals();
            let mut replan_ms = None;
            let verdict = match trigger {
                Some(Trigger::Abort(reason)) => Some(Verdict::Abort { reason }),
                Some(Trigger::Wait(reason)) => Some(Verdict::Wait { reason }),
                Some(Trigger::Replan { reason, now }) => {
                    let started = Instant::now();
                    let v = self.replan(reason, now);
                    replan_ms = Some(started.elapsed().as_secs_f64() * 1e3);
                    Some(v)
                }
                None if !fresh.is_empty() => Some(Verdict::NewWork {
                    subgoals: fresh.clone(),
                }),
                None => None,
            };
            if let (Some(v), false) = (&verdict, fresh.is_empty())
                && !matches!(v, Verdict::NewWork { .. })
            {
                // Both at once: the new work is logged on its own.
                let new_work = Verdict::NewWork { subgoals: fresh };
                self.log(&new_work, &[], 0.0, None);
            }
            // A replan or new work is acted on once; a wait or an abort
            // stands until the scene changes.
            self.trigger = Some(match &verdict {
                Some(Verdict::Wait { .. }) | Some(Verdict::Abort { .. }) => verdict.clone(),
                _ => None,
            });
            if let Some(v) = verdict {
                return (v, replan_ms);
            }
        }
        if let Some(Some(v)) = &self.trigger {
            return (self.waited(v.clone()), None);
        }
        (self.separation(), None)
    }

    /// A wait that has lasted too long becomes an abort.
    fn waited(&self, verdict: Verdict) -> Verdict {
        match (&verdict, self.waiting_since) {
            (Verdict::Wait { reason }, Some(since)) if self.clock - since > MAX_WAIT_S => {
                let hand = match reason {
                    Reason::HandOnRoute { hand, .. } => hand.clone(),
                    Reason::Blocked { by, .. } => by.clone(),
                    _ => "a hand".into(),
                };
                Verdict::Abort {
                    reason: Reason::WaitedTooLong {
                        hand,
                        seconds: self.clock - since,
                    },
                }
            }
            _ => verdict,
        }
    }

    /// The separation rule at the robot's position now.
    fn separation(&self) -> Verdict {
        if matches!(self.pending, Some(Pending::AtRest(_))) {
            return Verdict::Stop;
        }
        let track = &self.tracks[self.current];
        let motion = self.motion();
        let from = Track::sample_at(motion, self.cursor.s);
        let until = Track::sample_at(motion, self.cursor.s + LOOKAHEAD_S);
        let mut tools = vec![self.tool_now()];
        tools.extend_from_slice(&track.tool[from + 1..=until.max(from)]);
        let mut speeds = vec![track.speed[from]];
        speeds.extend_from_slice(&track.speed[from + 1..=until.max(from)]);
        match separation::rule(&self.scene, &hands(&self.scene), &tools, &speeds) {
            Separation::Clear => Verdict::Continue,
            Separation::Slow { scale, .. } => Verdict::Slow { scale },
            Separation::Stop { .. } => Verdict::Stop,
        }
    }

    /// The gripper of the sub-goal under way has opened on its piece: the
    /// piece is placed ([`Self::place_current`]), only the way out is left.
    pub(super) fn released(&self) -> bool {
        self.placed_current
    }

    /// The believed scene, with the piece of the sub-goal under way and
    /// its goal where they were when it was released (once it was).
    pub(super) fn as_released(&self) -> crate::scenario::Scenario {
        let mut scene = self.scene.clone();
        if let Some(at) = self.released_at.as_ref().filter(|_| self.released()) {
            for (name, bbox) in [&at.object, &at.goal] {
                if let Some(o) = scene.objects.iter_mut().find(|o| &o.name == name) {
                    o.bbox = *bbox;
                }
                if let Some(g) = scene.goals.iter_mut().find(|g| &g.name == name) {
                    g.bbox = *bbox;
                }
            }
        }
        scene
    }

    /// The tool position now (base frame, m).
    fn tool_now(&self) -> [f64; 3] {
        let q = planned_position(&self.motion().points, self.cursor.s);
        let arm = self
            .robot
            .arm(
                self.plan.subgoals[self.current]
                    .arm
                    .as_deref()
                    .unwrap_or_default(),
            )
            .unwrap_or(&self.robot.arms()[0]);
        arm.fk(&q).translation.vector.into()
    }

    /// The first trigger of the sub-goals ahead: the one under way by its
    /// policy and its motion, the later ones by their policies.
    fn policy_trigger(&self) -> Option<Trigger> {
        let current = &self.plan.subgoals[self.current];
        let track = &self.tracks[self.current];
        let motion = self.motion();
        let sample = Track::sample_at(motion, self.cursor.s);
        let holding = track.holding(self.cursor.s);
        let remaining = Remaining {
            plan: current,
            done: track.done[sample],
            holding,
            target_box: self.planned_boxes[self.current],
            opening: Some(self.opening),
        };
        let k = self.executed.len().saturating_sub(1);
        // Once released, the piece is placed: only the way out matters.
        if !self.released()
            && let Err(fault) = policy::check(&self.scene, &remaining)
        {
            return Some(trigger(fault, current, k, true));
        }
        if let Some(t) = self.route_trigger(sample, holding, k) {
            return Some(t);
        }
        let mut scene = self.scene.clone();
        for (j, later) in self.plan.subgoals.iter().enumerate().skip(self.current) {
            if j > self.current {
                let remaining = Remaining {
                    plan: later,
                    done: 0,
                    holding: false,
                    target_box: self.planned_boxes[j],
                    opening: Some(self.opening),
                };
                match policy::check(&scene, &remaining) {
                    // A hand far ahead may leave: it is judged when its
                    // sub-goal is under way.
                    Err(Fault::Hand { .. }) | Ok(()) => {}
                    // Vanished work is dropped when the piece in hand is
                    // put away (a replan from the end of this sub-goal).
                    Err(fault) => return Some(trigger(fault, later, k + j - self.current, false)),
                }
            }
            put_in_goal(&mut scene, later);
        }
        None
    }

    /// The geometric re-check of the motion under way, when a change since
    /// the last evaluation comes near it.
    fn route_trigger(&self, sample: usize, holding: bool, k: usize) -> Option<Trigger> {
        let current = &self.plan.subgoals[self.current];
        let grasp = self.held.as_ref().map(|h| h.grasp.as_slice());
        let m = RemainingMotion {
            plan: current,
            rest: &self.joints,
            from: sample,
            tool: &self.tracks[self.current].tool,
            target_box: self
                .held
                .as_ref()
                .filter(|_| holding)
                .map_or(self.planned_boxes[self.current], |h| h.grasped_box),
            held_grasp: grasp.filter(|_| holding),
        };
        // After the release the way out leaves the placed piece and its
        // goal where they were when the gripper opened: they moving since
        // (the box carried away) is no obstacle to leaving them.
        let scene = self.as_released();
        if !route::could_touch(&scene, &self.changes, &m) {
            return None;
        }
        let hit = match route::first_hit(&self.robot, &self.geometry, &scene, &m) {
            Ok(hit) => hit?,
            Err(message) => {
                return Some(Trigger::Abort(Reason::NoPlan { message }));
            }
        };
        let reason = match scene.hands.iter().any(|h| h.name == hit.other) {
            true => Reason::HandOnRoute {
                hand: hit.other,
                subgoal: k,
            },
            false => Reason::Blocked {
                by: hit.other,
                subgoal: k,
            },
        };
        // A blocker on the way out with no work left: wait for it to go.
        let nothing_left = self.released() && self.current + 1 >= self.plan.subgoals.len();
        Some(match reason {
            Reason::HandOnRoute { .. } => Trigger::Wait(reason),
            _ if nothing_left => Trigger::Wait(reason),
            _ => Trigger::Replan { reason, now: true },
        })
    }

    /// New sub-goals for an "all" instruction, remembered as new work.
    fn new_subgoals(&mut self) -> Vec<crate::instruction::SubGoal> {
        let mut known = self.done.clone();
        known.extend(
            self.plan.subgoals[self.current..]
                .iter()
                .map(|g| g.object.clone()),
        );
        known.extend(self.new_work.iter().map(|g| g.object.clone()));
        let fresh = new_work(&self.scene, self.options.seed, &known);
        self.new_work.extend(fresh.iter().cloned());
        fresh
    }
}

/// The trigger of a policy fault on sub-goal `plan` (number `k` in
/// execution order); `now` when it is the sub-goal under way.
fn trigger(fault: Fault, plan: &SubgoalPlan, k: usize, now: bool) -> Trigger {
    let (object, goal) = (plan.object.clone(), plan.goal.clone());
    match fault {
        Fault::Hand { hand } => Trigger::Wait(Reason::HandOnRoute { hand, subgoal: k }),
        Fault::Blocked { by } => Trigger::Replan {
            reason: Reason::Blocked { by, subgoal: k },
            now,
        },
        Fault::TargetMoved => Trigger::Replan {
            reason: Reason::TargetMoved { object, subgoal: k },
            now,
        },
        Fault::GoalMoved => Trigger::Replan {
            reason: Reason::GoalMoved { goal, subgoal: k },
            now,
        },
        // Vanished work is dropped (a replan without it; with nothing
        // left to do, an abort).
        Fault::TargetGone => Trigger::Replan {
            reason: Reason::TargetGone { object },
            now,
        },
        Fault::GoalGone => Trigger::Replan {
            reason: Reason::GoalGone { goal },
            now,
        },
    }
}

/// The scene after `plan`'s object rests at its planned release spot.
pub(super) fn put_in_goal(scene: &mut Scenario, plan: &SubgoalPlan) {
    if let Some(i) = scene.object_index(&plan.object) {
        let b = &mut scene.objects[i].bbox;
        *b = b.centred_at(plan.release_px);
    }
}
