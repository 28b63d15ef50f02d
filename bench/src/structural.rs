//! Counts the safety campaign takes from the trajectories themselves, no
//! checker needed: samples outside the model's joint position limits, and
//! trajectories that do not start where the robot was (the plan's start
//! state, then where the previous sub-goal ended).

use afford_kinematics::RobotModel;
use afford_planner::plan::Plan;
use serde::Serialize;

/// Joint positions further than this beyond a limit count as outside, rad or m.
pub const POSITION_TOLERANCE: f64 = 1e-9;
/// A first sample further than this from where the robot was counts as a
/// jump, rad or m.
pub const CONTINUITY_TOLERANCE: f64 = 1e-6;

/// Counts the runner takes from the trajectories themselves, no checker needed.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Structural {
    /// Samples with a joint beyond its position limit.
    pub samples_outside_position_limits: usize,
    /// Trajectories with at least one such sample.
    pub trajectories_outside_position_limits: usize,
    /// The largest excess over a position limit, rad or m.
    pub max_position_excess: f64,
    /// Trajectories whose first sample is not where the robot was.
    pub trajectories_not_starting_at_previous_end: usize,
}

impl Structural {
    pub(crate) fn add(&mut self, other: &Self) {
        self.samples_outside_position_limits += other.samples_outside_position_limits;
        self.trajectories_outside_position_limits += other.trajectories_outside_position_limits;
        self.max_position_excess = self.max_position_excess.max(other.max_position_excess);
        self.trajectories_not_starting_at_previous_end +=
            other.trajectories_not_starting_at_previous_end;
    }
}

/// The structural counts of one plan: position limits from the model, and
/// each trajectory's first sample against where the robot was (the plan's
/// start state, then the end of the previous sub-goal, for every arm).
pub fn structural(robot: &RobotModel, plan: &Plan) -> Structural {
    let mut counts = Structural::default();
    let mut now: Option<Vec<f64>> = plan
        .start_state
        .as_ref()
        .map(|s| s.positions.clone())
        .filter(|q| q.len() == robot.dof());
    for sub in &plan.subgoals {
        let (Some(motion), Some(arm)) = (&sub.trajectory, &sub.arm) else {
            continue;
        };
        let Ok(arm) = robot.arm(arm) else {
            continue;
        };
        let mut outside = 0;
        for p in &motion.points {
            let excess = p
                .positions
                .iter()
                .zip(arm.lower.iter().zip(&arm.upper))
                .map(|(&q, (&lo, &hi))| (lo - q).max(q - hi))
                .fold(f64::NEG_INFINITY, f64::max);
            if excess > POSITION_TOLERANCE {
                outside += 1;
                counts.max_position_excess = counts.max_position_excess.max(excess);
            }
        }
        counts.samples_outside_position_limits += outside;
        counts.trajectories_outside_position_limits += usize::from(outside > 0);
        let (Some(first), Some(last)) = (motion.points.first(), motion.points.last()) else {
            continue;
        };
        if let Some(q) = &mut now {
            let jump = arm
                .extract(q)
                .iter()
                .zip(&first.positions)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if jump > CONTINUITY_TOLERANCE {
                counts.trajectories_not_starting_at_previous_end += 1;
            }
            arm.insert(q, &last.positions);
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use afford_planner::plan::PlanOptions;

    #[test]
    fn structural_counts_find_limit_excess_and_jumps() {
        let scenario = afford_planner::scenario::default_scenario().expect("embedded scenario");
        let mut plan =
            afford_planner::plan::plan(&scenario, &PlanOptions::default()).expect("plans");
        let robot = RobotModel::load(&scenario.robot.model, std::path::Path::new("."))
            .expect("built-in robot");
        let before = structural(&robot, &plan);
        let arm = robot.arm("arm").expect("iiwa arm");
        let motion = plan.subgoals[0].trajectory.as_mut().expect("trajectory");
        let sample = &mut motion.points[5].positions;
        assert!(arm.within_limits(sample, 0.0));
        sample[0] = arm.upper[0] + 0.1;
        let next = plan.subgoals[1].trajectory.as_mut().expect("trajectory");
        next.points[0].positions[0] += 0.01;
        let after = structural(&robot, &plan);
        assert_eq!(
            after.samples_outside_position_limits,
            before.samples_outside_position_limits + 1
        );
        assert!(after.max_position_excess >= 0.1 - 1e-12);
        assert_eq!(
            after.trajectories_not_starting_at_previous_end,
            before.trajectories_not_starting_at_previous_end + 1
        );
    }
}
