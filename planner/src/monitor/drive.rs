//! Driving the execution: one controller period at a time along the
//! current sub-goal ([`super::execute`]), the gripper commands played as
//! planned, sub-goals chained (the replans in [`super::replan`]), and the
//! verdicts turned into speed commands and event-log entries.

use crate::plan::{HeldObject, Plan};
use crate::trajectory::{GripperCommand, GripperEvent, TimedMotion, arm_limits};

use super::belief::Placed;
use super::brake::Braking;
use super::decide::put_in_goal;
use super::execute::{self, Cursor, planned_position};
use super::track::Track;
use super::{Event, ExecutedSubgoal, Monitor, Pending, Status, Verdict};

impl Monitor {
    /// The trajectory of the sub-goal under way.
    pub(super) fn motion(&self) -> &TimedMotion {
        self.plan.subgoals[self.current]
            .trajectory
            .as_ref()
            .expect("monitored plans are timed")
    }

    /// The object in the gripper now and the box it was grasped from.
    pub(super) fn holds(&self) -> Option<(&str, crate::scenario::PixelBox)> {
        let track = &self.tracks[self.current];
        track
            .holding(self.cursor.s)
            .then_some(self.held.as_ref())
            .flatten()
            .map(|h| (h.object.as_str(), h.grasped_box))
    }

    /// Takes `plan` over from its first sub-goal.
    pub(super) fn adopt(&mut self, plan: Plan) {
        self.tracks = plan
            .subgoals
            .iter()
            .map(|g| {
                let arm = self
                    .robot
                    .arm(g.arm.as_deref().unwrap_or_default())
                    .unwrap_or(&self.robot.arms()[0]);
                Track::new(g, arm, &self.scene)
            })
            .collect();
        self.planned_boxes = plan.subgoals.iter().map(Track::planned_box).collect();
        self.reference = self.scene.clone();
        let continues = self.executed.last().is_some_and(|e| {
            let first = &plan.subgoals[0];
            self.current < self.plan.subgoals.len()
                && e.object == first.object
                && Some(&e.arm) == first.arm.as_ref()
        });
        self.plan.subgoals = plan.subgoals;
        self.plan.unsolved.extend(plan.unsolved);
        self.current = 0;
        self.cursor = Cursor::at(0, 0.0, 0.0);
        self.trigger = None;
        if !continues {
            self.begin_subgoal();
        }
    }

    /// Starts the executed record of the sub-goal under way.
    fn begin_subgoal(&mut self) {
        self.placed_current = false;
        self.released_at = None;
        let g = &self.plan.subgoals[self.current];
        let mut first = self.motion().points[0].clone();
        first.time_from_start = 0.0;
        self.executed.push(ExecutedSubgoal {
            object: g.object.clone(),
            goal: g.goal.clone(),
            arm: g.arm.clone().unwrap_or_default(),
            joint_names: g.joint_names.clone().unwrap_or_default(),
            start_time: self.clock,
            trajectory: TimedMotion {
                points: vec![first],
                gripper: Vec::new(),
            },
            scene: None,
            scene_at_start: Some(self.scene.clone()),
            changes: Vec::new(),
            cut_short: false,
        });
    }

    /// One interval of the plan (or one controller period at rest).
    pub(super) fn tick(&mut self) {
        // A gripper event under way at the cursor is played before a
        // pending plan is taken over (the replan counted it: `rest_state`).
        if self.cursor.sigma <= 0.0 && self.event_at_cursor().is_none() {
            if let Some(Pending::AtRest(_)) = &self.pending {
                let Some(Pending::AtRest(plan)) = self.pending.take() else {
                    unreachable!("matched above")
                };
                if self.released() {
                    // The piece is placed: this sub-goal ends here, at rest
                    // on its way out.
                    self.end_at_rest();
                }
                self.adopt(plan);
            }
            if let Some(reason) = self.aborting.clone() {
                self.cut_subgoal();
                self.status = Status::Aborted(reason);
                return;
            }
        }
        // The trajectory is lent out for the period (not cloned: a clone
        // per period would make the cost per period grow with the plan).
        let motion = self.plan.subgoals[self.current]
            .trajectory
            .take()
            .expect("monitored plans are timed");
        match event_in(&motion, self.cursor.s) {
            Some(event) => self.play_gripper(&motion, event),
            None => {
                let limits = arm_limits(&self.robot, self.current_arm());
                let braking = self.braking();
                let step = execute::step(
                    &motion,
                    &limits,
                    &self.cursor,
                    self.command,
                    self.dt,
                    Some(&braking),
                );
                self.cursor = step.cursor;
                self.clock += step.duration;
                self.record(step.point);
            }
        }
        let ended = self.cursor.index + 1 >= motion.points.len();
        self.plan.subgoals[self.current].trajectory = Some(motion);
        if ended {
            self.end_subgoal();
        }
    }

    /// The gripper event of the sub-goal under way that starts at the cursor.
    fn event_at_cursor(&self) -> Option<GripperEvent> {
        event_in(self.motion(), self.cursor.s)
    }

    /// The arm rests while the gripper acts: the planned rest is played
    /// as it is, and the command recorded at its executed times.
    fn play_gripper(&mut self, motion: &TimedMotion, event: GripperEvent) {
        let start = self.clock;
        let mut index = self.cursor.index;
        for (i, p) in motion.points.iter().enumerate().filter(|(_, p)| {
            p.time_from_start > event.start + 1e-9 && p.time_from_start <= event.end + 1e-9
        }) {
            self.clock = start + (p.time_from_start - event.start);
            self.record(p.clone());
            index = i;
        }
        let base = self.executed.last().map_or(0.0, |e| e.start_time);
        if let Some(e) = self.executed.last_mut() {
            e.trajectory.gripper.push(GripperEvent {
                command: event.command,
                start: start - base,
                end: self.clock - base,
            });
        }
        match event.command {
            GripperCommand::Close => self.held = Some(self.grasp_record(motion, event.start)),
            GripperCommand::Open => self.place_current(),
        }
        // The arm rests at the event's end: a pending plan takes over there.
        let sigma = match self.pending {
            Some(Pending::AtRest(_)) => 0.0,
            _ => 1.0,
        };
        self.cursor = Cursor::at(index, motion.points[index].time_from_start, sigma);
    }

    /// What the robot knows of the object it closes on at plan time `s`.
    pub(super) fn grasp_record(&self, motion: &TimedMotion, s: f64) -> HeldObject {
        let g = &self.plan.subgoals[self.current];
        HeldObject {
            object: g.object.clone(),
            grasped_box: self.planned_boxes[self.current],
            arm: g.arm.clone().unwrap_or_default(),
            grasp: planned_position(&motion.points, s),
        }
    }

    /// Appends an executed sample (its time the execution clock).
    fn record(&mut self, mut point: crate::timing::TrajectoryPoint) {
        if let Some(e) = self.executed.last_mut() {
            point.time_from_start = self.clock - e.start_time;
            e.trajectory.points.push(point);
        }
    }

    /// What a stop of the sub-goal under way keeps to: its tool path and
    /// the scene's separation settings.
    pub(super) fn braking(&self) -> Braking<'_> {
        Braking {
            tool: &self.tracks[self.current].tool,
            separation: &self.scene.safety.separation,
        }
    }

    pub(super) fn current_arm(&self) -> &afford_kinematics::Arm {
        self.robot
            .arm(
                self.plan.subgoals[self.current]
                    .arm
                    .as_deref()
                    .unwrap_or_default(),
            )
            .unwrap_or(&self.robot.arms()[0])
    }

    /// The sub-goal under way is done: its object rests in its goal, the
    /// next sub-goal (or a replan, or the new work) takes over.
    fn end_subgoal(&mut self) {
        let last = self.motion().points.last().map(|p| p.positions.clone());
        if let Some(q) = last {
            let arm = self.current_arm().clone();
            arm.insert(&mut self.joints, &q);
        }
        self.close_record();
        self.current += 1;
        let next = match self.pending.take() {
            Some(Pending::AtEnd(plan)) | Some(Pending::AtRest(plan)) => Some(plan),
            None => None,
        };
        match next {
            Some(plan) => self.adopt(plan),
            None if self.current < self.plan.subgoals.len() => {
                self.cursor = Cursor::at(0, 0.0, 0.0);
                self.trigger = None;
                self.begin_subgoal();
            }
            None => self.take_new_work(),
        }
    }

    /// The piece of the sub-goal under way rests in its goal where it was
    /// released: it moves with its goal from now on ([`Placed`]).
    pub(super) fn place_current(&mut self) {
        if self.placed_current {
            return;
        }
        self.placed_current = true;
        let g = self.plan.subgoals[self.current].clone();
        if let (Some(i), Some(goal)) = (
            self.scene.object_index(&g.object),
            self.scene.goals.iter().find(|x| x.name == g.goal),
        ) {
            let mut object = self.scene.objects[i].clone();
            object.bbox = object.bbox.centred_at(g.release_px);
            self.released_at = Some(super::ReleasedAt {
                object: (g.object.clone(), object.bbox),
                goal: (g.goal.clone(), goal.bbox),
            });
            self.placed.push(Placed {
                offset: [object.bbox.u - goal.bbox.u, object.bbox.v - goal.bbox.v],
                object,
                goal: g.goal.clone(),
            });
        }
        put_in_goal(&mut self.scene, &g);
    }

    /// The executed record of the sub-goal under way is complete (its
    /// piece placed): the scene to check it against, the piece done.
    fn close_record(&mut self) {
        let object = self.plan.subgoals[self.current].object.clone();
        let seen = self.scene_seen(&object);
        if let Some(e) = self.executed.last_mut() {
            e.scene = Some(seen);
        }
        self.place_current();
        self.done.push(object);
        self.held = None;
    }

    /// What the independent check of the sub-goal under way (moving
    /// `object`) runs against ([`ExecutedSubgoal::scene`]): the scene now,
    /// less what came while it ran, its object where the gripper took it
    /// (where it was at the start if it has gone since).
    fn scene_seen(&self, object: &str) -> crate::Scenario {
        let mut seen = self.as_released();
        if let Some(start) = self.executed.last().and_then(|e| e.scene_at_start.as_ref()) {
            seen.objects
                .retain(|o| o.name == object || start.objects.contains(o));
            seen.hands.retain(|h| start.hands.contains(h));
            let gone = start.objects.iter().filter(|o| o.name == object);
            if seen.object_index(object).is_none() {
                seen.objects.extend(gone.cloned());
            }
        }
        if let (Some(i), Some(held)) = (seen.object_index(object), &self.held) {
            seen.objects[i].bbox = held.grasped_box;
        }
        seen
    }

    /// The sub-goal under way stops for good where the robot rests: its
    /// record keeps what was executed, ending at rest (velocities and
    /// accelerations 0), marked cut short, with the scene to check it
    /// against; a record without motion (its first sample only) is dropped.
    fn cut_subgoal(&mut self) {
        let last = self
            .executed
            .last()
            .and_then(|e| e.trajectory.points.last());
        if last.is_some_and(|p| p.accelerations.iter().any(|a| *a != 0.0)) {
            // Braked this period: one period at rest ends the record at rest.
            let motion = self.motion().clone();
            let limits = arm_limits(&self.robot, self.current_arm());
            let braking = self.braking();
            let step = execute::step(&motion, &limits, &self.cursor, 0.0, self.dt, Some(&braking));
            self.cursor = step.cursor;
            self.clock += step.duration;
            self.record(step.point);
        }
        let object = self.plan.subgoals[self.current].object.clone();
        let seen = self.scene_seen(&object);
        match self.executed.last_mut() {
            Some(e) if e.trajectory.points.len() < 2 => {
                self.executed.pop();
            }
            Some(e) => {
                e.cut_short = true;
                e.scene = Some(seen);
            }
            None => {}
        }
    }

    /// The sub-goal under way ends where the robot rests (after its
    /// release): the whole robot's joints there, its record closed.
    fn end_at_rest(&mut self) {
        let q = planned_position(&self.motion().points, self.cursor.s);
        let arm = self.current_arm().clone();
        arm.insert(&mut self.joints, &q);
        self.close_record();
    }

    /// Turns a verdict into the speed command.
    pub(super) fn act(&mut self, verdict: &Verdict) {
        match verdict {
            Verdict::Continue => {
                self.command = 1.0;
                self.waiting_since = None;
            }
            Verdict::Slow { scale } => {
                self.command = *scale;
                self.waiting_since = None;
            }
            Verdict::Stop => self.command = 0.0,
            Verdict::Wait { .. } => {
                self.command = 0.0;
                self.waiting_since.get_or_insert(self.clock);
            }
            Verdict::Replan { .. } => {
                if matches!(self.pending, Some(Pending::AtRest(_))) {
                    self.command = 0.0;
                }
            }
            Verdict::NewWork { .. } => {}
            Verdict::Abort { reason } => {
                self.command = 0.0;
                self.aborting = Some(reason.clone());
            }
        }
    }

    /// Logs a verdict that changes what the robot does, or one taken on a
    /// changed scene.
    pub(super) fn log(
        &mut self,
        verdict: &Verdict,
        changes: &[String],
        decision_us: f64,
        replan_ms: Option<f64>,
    ) {
        // Braking for a replan is part of the replan's event.
        if changes.is_empty() && matches!(self.pending, Some(Pending::AtRest(_))) {
            return;
        }
        let name = verdict.name();
        let scale = match verdict {
            Verdict::Slow { scale } => Some(*scale),
            _ => None,
        };
        // A standing verdict is logged once; replans and new work each time.
        let standing = !matches!(verdict, Verdict::Replan { .. } | Verdict::NewWork { .. });
        if changes.is_empty() && standing && name == self.last {
            return;
        }
        self.last = name;
        let subgoals = match verdict {
            Verdict::NewWork { subgoals } => subgoals
                .iter()
                .map(|g| format!("{} → {}", g.object, g.goal))
                .collect(),
            _ => Vec::new(),
        };
        let brakes = match verdict {
            Verdict::Stop | Verdict::Wait { .. } | Verdict::Abort { .. } => true,
            Verdict::Replan { .. } => matches!(self.pending, Some(Pending::AtRest(_))),
            _ => false,
        };
        self.events.push(Event {
            time: self.clock,
            changes: changes.to_vec(),
            verdict: name,
            brakes,
            reason: verdict.reason().cloned(),
            message: verdict.reason().map(|r| r.to_string()),
            scale,
            subgoals,
            decision_us,
            replan_ms,
        });
    }
}

/// The gripper event of `motion` that starts at plan time `s`.
fn event_in(motion: &TimedMotion, s: f64) -> Option<GripperEvent> {
    motion
        .gripper
        .iter()
        .find(|e| (e.start - s).abs() < 1e-9 && e.end > e.start)
        .copied()
}
