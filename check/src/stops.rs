//! The stops of an executed run against the stopping distance the
//! separation rule assumes (ISO/TS 15066 §5.5.4.2.3): from the tool's speed
//! `v` when a stop was decided, the tool may travel
//! `S = v·T_r + v²/(2·a_s)` (`T_r`, `a_s` from the scenario's
//! `safety.separation`) before it rests. Measured here on the executed
//! samples with k's forward kinematics, sharing no code with the monitor's
//! braking: the tool's speed over the sample interval under the decision,
//! its path length from there to the first interval it no longer moves in.

use afford_kinematics::RobotModel;
use afford_planner::Scenario;
use nalgebra::Vector3;
use serde::Serialize;

use crate::chain::Kinematics;
use crate::file::PlanFile;
use crate::format;

/// Tool speed below this over a sample interval is rest, m/s.
const REST_SPEED_M_S: f64 = 1e-3;

/// One measured stop.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stop {
    /// Run time of the decision, s.
    pub time_s: f64,
    /// Tool speed then, m/s.
    pub speed_m_s: f64,
    /// Tool path length from the decision to rest, m.
    pub travel_m: f64,
    /// The stopping term at that speed, m.
    pub term_m: f64,
}

impl Stop {
    /// `travel / term` (0 for a stop decided at rest).
    pub fn ratio(&self) -> f64 {
        match self.term_m > 0.0 {
            true => self.travel_m / self.term_m,
            false => 0.0,
        }
    }
}

/// The stopping term at tool speed `v` (m/s) with the scenario's
/// separation settings, m.
pub(crate) fn stopping_term(scene: &Scenario, v: f64) -> f64 {
    let rule = &scene.safety.separation;
    v * rule.reaction_time_s + v * v / (2.0 * rule.stop_deceleration_m_s2)
}

/// The stops decided at run times `decided` (s) that fall in the one
/// sub-goal of `plan`, begun at `start_time` in `scene`. A sub-goal the
/// check cannot read gives none ([`crate::check_plan`] reports it).
pub fn stops(
    scene: &Scenario,
    robot: &RobotModel,
    plan: &PlanFile,
    start_time: f64,
    decided: &[f64],
) -> Vec<Stop> {
    let (Some(sub), Ok(kin)) = (plan.subgoals.first(), Kinematics::new(robot)) else {
        return Vec::new();
    };
    let (Ok(checked), Ok(q0)) = (
        format::check(scene, robot, sub),
        crate::start::state(robot, plan.start_state.as_ref()),
    ) else {
        return Vec::new();
    };
    let arm = checked.arm;
    let tool_link = robot.link_index(&arm.tool_link).unwrap_or(0);
    let points = &sub.trajectory.points;
    let tool: Vec<Vector3<f64>> = points
        .iter()
        .map(|p| {
            let mut q = q0.clone();
            arm.joint_indices
                .iter()
                .zip(&p.positions)
                .for_each(|(&j, &v)| q[j] = v);
            kin.link_poses(&q)[tool_link].translation.vector
        })
        .collect();
    let times: Vec<f64> = points
        .iter()
        .map(|p| start_time + p.time_from_start)
        .collect();
    decided
        .iter()
        .filter(|&&t| t >= times[0] && t < times[times.len() - 1])
        .map(|&t| {
            let i = times.partition_point(|&s| s <= t).saturating_sub(1);
            let step = |k: usize| (tool[k + 1] - tool[k]).norm();
            let dt = times[i + 1] - times[i];
            let speed = if dt > 0.0 { step(i) / dt } else { 0.0 };
            let moving = |k: &usize| step(*k) > REST_SPEED_M_S * (times[k + 1] - times[*k]);
            let travel: f64 = (i..tool.len() - 1).take_while(moving).map(step).sum();
            Stop {
                time_s: t,
                speed_m_s: speed,
                travel_m: travel,
                term_m: stopping_term(scene, speed),
            }
        })
        .collect()
}
