//! From tool waypoints to a joint path: every waypoint becomes a top-down
//! IK target (tool axis down, yaw from the lifting stage), and the robot's
//! arm that reaches all of them at the lowest joint-space cost is chosen
//! (the other arms park). The path starts from the robot's current
//! configuration, so the move to the first waypoint is part of it.

use afford_kinematics::{ArmChoice, IkTarget, PathSettings, RobotModel, Vec3, choose_arm};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::error::{ArmFailure, Refusal};
use crate::lift::LiftedMotion;

/// The IK targets of a lifted motion.
pub fn ik_targets(motion: &LiftedMotion) -> Vec<IkTarget> {
    motion
        .waypoints
        .iter()
        .map(|w| IkTarget::TopDown {
            position: Vec3::new(w.position[0], w.position[1], w.position[2]),
            yaw: Some(w.yaw),
        })
        .collect()
}

/// Chooses the arm and solves the joint path for `motion` from the whole-robot
/// configuration `current`. `Err` names each arm's first unreachable
/// waypoint ([`Refusal::Unreachable`], [`Refusal::JointLimit`]).
pub fn solve_motion(
    robot: &RobotModel,
    motion: &LiftedMotion,
    current: &[f64],
    settings: &PathSettings,
    seed: u64,
) -> Result<ArmChoice, Refusal> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let targets = ik_targets(motion);
    match choose_arm(robot, &targets, current, settings, &mut rng) {
        Err(e) => Err(Refusal::internal("IK", e)),
        Ok(Ok(choice)) => Ok(choice),
        Ok(Err(none)) => Err(Refusal::unreachable(
            none.failures
                .into_iter()
                .map(|(arm, f)| ArmFailure {
                    arm,
                    waypoint: f.index,
                    phase: motion.waypoints.get(f.index).map(|w| w.phase),
                    cause: f.reason,
                })
                .collect(),
        )),
    }
}
