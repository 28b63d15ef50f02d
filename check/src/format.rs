//! Is a sub-goal a well-formed trajectory for this scenario and robot?
//! Names (object, goal, arm, joints), one value per joint in every vector,
//! finite and sane values, at least two samples, times from 0 strictly
//! increasing; then the gripper events: exactly one close then one open,
//! each `start <= end`, `close.end <= open.start`, inside the trajectory's
//! time span, with a sample at each start and end.
//!
//! Absurd values are refused before any arithmetic uses them, each with the
//! field named: |position| > [`MAX_ABS_POSITION`], |velocity| or
//! |acceleration| > [`MAX_ABS_RATE`], time > [`MAX_TIME`].

use afford_kinematics::{Arm, RobotModel};
use afford_planner::Scenario;
use afford_planner::trajectory::GripperCommand;

use crate::file::{Sample, SubgoalFile};
use crate::report::ViolationClass;

/// Largest |position| read as a position, rad or m.
pub const MAX_ABS_POSITION: f64 = 1e3;
/// Largest |velocity| (rad/s) or |acceleration| (rad/s²) read as one.
pub const MAX_ABS_RATE: f64 = 1e6;
/// Latest time of a sample or gripper event, s.
pub const MAX_TIME: f64 = 1e5;
/// How close a sample's time must be to a gripper event's start or end, s.
pub const EVENT_TIME_TOLERANCE: f64 = 1e-9;

/// A sub-goal that passed the format check.
pub(crate) struct Checked<'a> {
    pub target: usize,
    pub goal: usize,
    pub arm: &'a Arm,
}

/// One gripper event, checked: its window and the sample at its start.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Event {
    pub window: (f64, f64),
    pub sample: usize,
}

/// The gripper events, checked: the close (the grasp) and the open (the
/// release). Both are there in a whole sub-goal; one cut short has a
/// prefix of them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Events {
    pub close: Option<Event>,
    pub open: Option<Event>,
}

impl Events {
    /// The events' windows, in order.
    pub fn windows(&self) -> Vec<(f64, f64)> {
        [self.close, self.open]
            .iter()
            .flatten()
            .map(|e| e.window)
            .collect()
    }
}

type Found = Vec<(ViolationClass, String)>;

fn format(message: String) -> Found {
    vec![(ViolationClass::Format, message)]
}

/// The names and the samples. `Err` holds the first problem found.
pub(crate) fn check<'a>(
    s: &Scenario,
    robot: &'a RobotModel,
    sub: &SubgoalFile,
) -> Result<Checked<'a>, Found> {
    let target = s
        .object_index(&sub.object)
        .ok_or_else(|| format(format!("object '{}' is not in the scenario", sub.object)))?;
    let goal = s
        .goal_index(&sub.goal)
        .ok_or_else(|| format(format!("goal '{}' is not in the scenario", sub.goal)))?;
    let arm = robot
        .arm(&sub.arm)
        .map_err(|e| format(format!("arm: {e}")))?;
    if sub.joint_names != arm.joint_names {
        return Err(format(format!(
            "joint_names {:?} are not the joints of the arm '{}' {:?}",
            sub.joint_names, arm.name, arm.joint_names
        )));
    }
    let points = &sub.trajectory.points;
    if points.len() < 2 {
        return Err(format(format!(
            "the trajectory has {} samples: a motion needs at least 2",
            points.len()
        )));
    }
    for (i, p) in points.iter().enumerate() {
        sample(i, p, arm).map_err(format)?;
    }
    if points[0].time_from_start != 0.0 {
        return Err(format(format!(
            "points[0].time_from_start is {}: times start at 0",
            shown(points[0].time_from_start)
        )));
    }
    if let Some(i) =
        (1..points.len()).find(|&i| points[i].time_from_start <= points[i - 1].time_from_start)
    {
        return Err(format(format!(
            "points[{i}].time_from_start is {} after {} at points[{}]: times must strictly increase",
            shown(points[i].time_from_start),
            shown(points[i - 1].time_from_start),
            i - 1
        )));
    }
    Ok(Checked { target, goal, arm })
}

/// A number as a person reads it: plain, but in exponent form from 1e15 on
/// (plain `{}` prints all 301 digits of 1e300).
fn shown(x: f64) -> String {
    match x.abs() >= 1e15 {
        true => format!("{x:e}"),
        false => format!("{x}"),
    }
}

/// True when `v` is a finite number with `|v| <= bound` (false for NaN).
pub(crate) fn within(v: f64, bound: f64) -> bool {
    v.is_finite() && v.abs() <= bound
}

/// One sample's sizes and values.
fn sample(i: usize, p: &Sample, arm: &Arm) -> Result<(), String> {
    let n = arm.dof();
    for (field, values, bound) in [
        ("positions", &p.positions, MAX_ABS_POSITION),
        ("velocities", &p.velocities, MAX_ABS_RATE),
        ("accelerations", &p.accelerations, MAX_ABS_RATE),
    ] {
        if values.len() != n {
            return Err(format!(
                "points[{i}].{field} holds {} values, the arm '{}' has {n} joints",
                values.len(),
                arm.name
            ));
        }
        if let Some((j, v)) = values.iter().enumerate().find(|(_, v)| !within(**v, bound)) {
            return Err(format!(
                "points[{i}].{field}[{j}] ({}) is {}: not a finite value within ±{bound:e}",
                arm.joint_names[j],
                shown(*v)
            ));
        }
    }
    let t = p.time_from_start;
    if !(0.0..=MAX_TIME).contains(&t) {
        return Err(format!(
            "points[{i}].time_from_start is {}: times lie between 0 and {MAX_TIME:e} s",
            shown(t)
        ));
    }
    Ok(())
}

/// The gripper events of a well-formed trajectory: close then open, or a
/// prefix of them when the sub-goal was cut short.
pub(crate) fn events(sub: &SubgoalFile) -> Result<Events, Found> {
    let bad = |m: String| vec![(ViolationClass::GripperEvents, m)];
    let e = &sub.trajectory.gripper;
    let commands: Vec<GripperCommand> = e.iter().map(|e| e.command).collect();
    let whole = [GripperCommand::Close, GripperCommand::Open];
    let allowed = match sub.cut_short {
        true => whole.starts_with(&commands),
        false => commands == whole,
    };
    if !allowed {
        let names: Vec<&str> = commands
            .iter()
            .map(|c| match c {
                GripperCommand::Close => "close",
                GripperCommand::Open => "open",
            })
            .collect();
        return Err(bad(format!(
            "the gripper events are {names:?}: a sub-goal closes the gripper once, then opens it once"
        )));
    }
    let points = &sub.trajectory.points;
    let last = points[points.len() - 1].time_from_start;
    for (k, ev) in e.iter().enumerate() {
        if !(ev.start.is_finite()
            && ev.end.is_finite()
            && 0.0 <= ev.start
            && ev.start <= ev.end
            && ev.end <= last)
        {
            return Err(bad(format!(
                "gripper[{k}] runs from {} s to {} s: an event starts no later than it ends, inside the trajectory's 0 .. {last:.3} s",
                ev.start, ev.end
            )));
        }
    }
    if let [close, open] = e.as_slice()
        && close.end > open.start
    {
        return Err(bad(format!(
            "the gripper opens at {:.3} s before it has closed at {:.3} s",
            open.start, close.end
        )));
    }
    let sample_at = |k: usize, what: &str, t: f64| {
        points
            .iter()
            .position(|p| (p.time_from_start - t).abs() <= EVENT_TIME_TOLERANCE)
            .ok_or_else(|| bad(format!("gripper[{k}].{what} ({t} s) falls on no sample")))
    };
    let mut checked = e.iter().enumerate().map(|(k, ev)| {
        let sample = sample_at(k, "start", ev.start)?;
        sample_at(k, "end", ev.end)?;
        Ok::<_, Found>(Event {
            window: (ev.start, ev.end),
            sample,
        })
    });
    Ok(Events {
        close: checked.next().transpose()?,
        open: checked.next().transpose()?,
    })
}
