//! From tool waypoints to a joint path: every waypoint becomes a top-down
//! IK target (tool axis down, yaw from the lifting stage), and every arm of
//! the robot that reaches all of them is a candidate, cheapest first by
//! kinematics' arm-choice cost (joint-space distance from where the arm is
//! to the first waypoint + path length + distance from the joint limits,
//! [`afford_kinematics::path_cost`]). The pipeline takes the first candidate
//! whose whole motion (transits included) is collision-free, so a robot with
//! two arms chooses per sub-goal by reach, then cost, then clearance.

use afford_kinematics::{
    ArmChoice, IkTarget, NoArmReaches, PathSettings, RobotModel, Vec3, path_cost,
    random_configuration,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::clearance::SelfClearance;
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

/// Where the path IK of [`solve_motions`] starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkStart {
    /// Where the arm is.
    Current,
    /// The arm's home posture (the description's comfortable posture).
    Home,
    /// A random configuration within the limits, the `k`-th stream.
    Random(u64),
}

/// Where the pipeline's path IK starts: where the arm is. Measured on 80
/// random scenes of both robots, trying the arms again from home and from
/// two random postures when none was free never gave a free motion the
/// current start had not (85 of 85 free motions came from it) and took
/// three quarters of the planning time; a branch that folds into the body
/// is left by the path IK's self-clearance screen instead.
pub const IK_START: IkStart = IkStart::Current;

/// Every arm that reaches all of `motion`'s waypoints from the whole-robot
/// configuration `current`, with its joint path, cheapest first (ties keep
/// the robot's arm order). The arms are solved in the robot's order from one
/// random stream seeded with `seed` (and the start's index). Each arm's IK
/// starts as `start` says (another branch when the first one collides); the
/// cost is from where the arm is either way. `Err` names each arm's first
/// unreachable waypoint ([`Refusal::Unreachable`], [`Refusal::JointLimit`]),
/// or a bad configuration or setting ([`Refusal::Internal`]). With a
/// `screen`, each arm's IK prefers a branch whose joint path keeps the
/// robot clear of itself ([`SelfClearance`]).
pub fn solve_motions(
    robot: &RobotModel,
    motion: &LiftedMotion,
    current: &[f64],
    settings: &PathSettings,
    seed: u64,
    start: IkStart,
    screen: Option<&SelfClearance>,
) -> Result<Vec<ArmChoice>, Refusal> {
    if current.len() != robot.dof() {
        return Err(Refusal::internal(
            "IK",
            format!(
                "the robot configuration has {} values, {} has {} joints",
                current.len(),
                robot.name(),
                robot.dof()
            ),
        ));
    }
    settings
        .validate()
        .map_err(|e| Refusal::internal("IK", e))?;
    let stream = match start {
        IkStart::Random(k) => k.wrapping_add(1),
        _ => 0,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let targets = ik_targets(motion);
    let mut choices = Vec::new();
    let mut failures = Vec::new();
    for (arm_index, arm) in robot.arms().iter().enumerate() {
        let now = arm.extract(current);
        let ik_seed = match start {
            IkStart::Current => now.clone(),
            IkStart::Home => arm.home.clone(),
            IkStart::Random(_) => random_configuration(arm, &mut rng),
        };
        let mut admits = |path: &[Vec<f64>]| screen.is_none_or(|s| s.admits(&arm.name, path));
        match arm.solve_path_screened(&targets, Some(&ik_seed), settings, &mut rng, &mut admits) {
            Ok(path) => choices.push(ArmChoice {
                arm: arm.name.clone(),
                arm_index,
                cost: path_cost(arm, &now, &path),
                robot_path: Vec::new(),
                path,
            }),
            Err(f) => failures.push((arm.name.clone(), f)),
        }
    }
    if choices.is_empty() {
        return Err(unreachable(motion, NoArmReaches { failures }));
    }
    choices.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    Ok(choices)
}

/// Each arm's first unreachable waypoint, with its phase.
fn unreachable(motion: &LiftedMotion, none: NoArmReaches) -> Refusal {
    Refusal::unreachable(
        none.failures
            .into_iter()
            .map(|(arm, f)| ArmFailure {
                arm,
                waypoint: f.index,
                phase: motion.waypoints.get(f.index).map(|w| w.phase),
                cause: f.reason,
            })
            .collect(),
    )
}
