//! Playing a scenario's observation timeline against the execution: the
//! camera delivers a frame every [`CAMERA_PERIOD_S`]; an entry of the
//! timeline is delivered at the first frame or controller period at which
//! it is due — its `at` time has come, or execution has reached its plan
//! point — and never before the entry listed before it (so "the hand
//! leaves at 8 s" cannot come before "a hand comes in the carry" when the
//! robot is slower than its author thought). Other frames see the same
//! scene: the monitor evaluates the separation rule and the waiting on them.

use crate::scenario::{Observation, bounds::MAX_EXECUTION_TIME_S};

use super::{Monitor, Reason, Status};

/// Period of the overhead camera, s (30 Hz).
pub const CAMERA_PERIOD_S: f64 = 1.0 / 30.0;

/// Runs `monitor` to completion or abort, delivering `observations` as
/// they fall due. Execution longer than the timeline's bound
/// ([`MAX_EXECUTION_TIME_S`]) is aborted. Returns how many entries were
/// delivered: the rest never fell due before the run ended (a plan point
/// the plan never reaches, a time after its end).
pub fn play(monitor: &mut Monitor, observations: &[Observation]) -> usize {
    let mut next = 0;
    let mut frame = 0.0;
    while monitor.status() == &Status::Running {
        let t = monitor.clock();
        if t > MAX_EXECUTION_TIME_S {
            monitor.abort(Reason::NoPlan {
                message: format!("execution ran past {MAX_EXECUTION_TIME_S} s"),
            });
            break;
        }
        if next < observations.len() && due(monitor, &observations[next]) {
            monitor.observe(&observations[next], t);
            next += 1;
        } else if t + 1e-9 >= frame {
            monitor.observe(&Observation::default(), t);
            frame += CAMERA_PERIOD_S;
        }
        monitor.advance(t + monitor.period());
    }
    next
}

/// True when the entry's time or plan point has come.
pub fn due(monitor: &Monitor, o: &Observation) -> bool {
    if let Some(at) = o.at {
        return monitor.clock() + 1e-9 >= at;
    }
    let Some(when) = o.when else {
        return true;
    };
    let (k, phase, fraction) = monitor.position();
    (k, phase) > (when.subgoal, when.phase)
        || (k, phase) == (when.subgoal, when.phase) && fraction + 1e-9 >= when.fraction
}
