//! The arm's motion of one sub-goal (IK of the tool waypoints, the
//! collision check of the joint path, timing) and the transits between
//! sub-goals; a collision the grid did not see becomes a [`Replan`].

use afford_collision::{Collision, RobotGeometry};
use afford_kinematics::RobotModel;

use super::types::{Planner, StageTimings, timed};
use super::world::{Pass, Refused, subgoal_seed};
use crate::clearance::{ArmMotion, FreeMoves, Leg, PathHit, check_motion};
use crate::error::{HitPlace, Refusal, TransitFailure};
use crate::grid::{Cell, CellCode};
use crate::lift::{LiftedMotion, Phase, carry_height};
use crate::scenario::Scenario;
use crate::start::{self};
use crate::task::GridTask;
use crate::trajectory::TimedMotion;
use crate::transit::{TransitError, joint_steps, plan_transit};
use afford_kinematics::{Arm, ArmChoice};

impl Planner {
    /// One arm's whole joint path for the sub-goal: the transit from where
    /// the arm is to its path, its IK path, and (when the pass parks) the
    /// transit back to park, each transit straight when free and else found
    /// by the transit planner ([`crate::transit`]); then the continuous
    /// check of the whole path. Leading travel waypoints whose configuration
    /// is not free (the start cell over an obstacle's perimeter, where a
    /// parked arm's gripper never is) are left out: the transit joins the
    /// tool path at the first free one.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn arm_motion(
        &self,
        pass: &Pass,
        robot: &RobotModel,
        geometry: &RobotGeometry,
        arm: &Arm,
        choice: &ArmChoice,
        task: &GridTask,
        motion: &LiftedMotion,
        timings: &mut StageTimings,
    ) -> Result<ArmMotionOutcome, Refused> {
        let (world, request) = (pass.world, pass.request);
        let scene = &world.scene;
        let held = world.held.as_ref().filter(|h| h.object == pass.goal.object);
        let moves = |leg| {
            FreeMoves::new(
                robot,
                geometry,
                scene,
                request.object,
                request.goal,
                &arm.name,
                &world.joints,
                leg,
            )
            .map_err(|e| Refused::motion(Refusal::internal("collision", e)))
        };
        // An object already in the hand is no obstacle to it.
        let before = moves(match held {
            Some(_) => Leg::AfterRelease,
            None => Leg::BeforeGrasp,
        })?;
        let skip = timed(&mut timings.transit, || {
            leading_blocked(&before, motion, &choice.path.waypoints)
        })
        .map_err(|e| Refused::motion(Refusal::internal("collision", e)))?;
        let motion = LiftedMotion {
            waypoints: motion.waypoints[skip..].to_vec(),
            ..motion.clone()
        };
        let start = arm.extract(&world.joints);
        let mut waypoints = choice.path.waypoints[skip..].to_vec();
        // The route starts where the tool is: a first waypoint whose IK lands
        // on the current configuration is that configuration exactly.
        if let Some(q) = waypoints.first_mut()
            && q.iter()
                .zip(&start)
                .all(|(a, b)| (a - b).abs() <= SAME_CONFIGURATION)
        {
            q.clone_from(&start);
        }
        let first = waypoints.first().cloned().unwrap_or_else(|| start.clone());
        let stream = 2 * choice.arm_index;
        let mut lead = match self.transit(pass, arm, &before, &start, &first, stream, timings)? {
            Ok(path) => path,
            Err(e) => {
                return Ok(ArmMotionOutcome::NoTransit(TransitFailure {
                    arm: arm.name.clone(),
                    place: HitPlace::ToFirstWaypoint,
                    reason: e.to_string(),
                }));
            }
        };
        // The transit ends on the first waypoint, which the IK path starts with.
        lead.pop();
        // joint_path[lead.len() + 1 + k] is tool waypoint k.
        let offset = lead.len();
        let mut joint_path: Vec<Vec<f64>> = std::iter::once(start)
            .chain(lead)
            .chain(waypoints)
            .collect();
        if pass.park && !arm.park.is_empty() {
            let after = moves(Leg::AfterRelease)?;
            let last = joint_path.last().cloned().unwrap_or_default();
            let parked = arm.extract(&start::parked_home(robot));
            match self.transit(pass, arm, &after, &last, &parked, stream + 1, timings)? {
                Ok(path) => joint_path.extend(path),
                Err(e) => {
                    return Ok(ArmMotionOutcome::NoTransit(TransitFailure {
                        arm: arm.name.clone(),
                        place: HitPlace::ReturningToPark,
                        reason: e.to_string(),
                    }));
                }
            }
        }
        let (grasp_at, release_at) = motion.gripper_switches();
        // An object already held is held from the start.
        let grasp_at = held.map_or(grasp_at + offset, |_| 0);
        let release_at = release_at + offset;
        let check = ArmMotion {
            scenario: scene,
            target: request.object,
            goal: request.goal,
            arm: &arm.name,
            rest: &world.joints,
            path: &joint_path,
            grasp_at,
            release_at,
            held: held.map(|h| (h.grasped_box, h.grasp.as_slice())),
        };
        if let Some(hit) = timed(&mut timings.collision, || {
            check_motion(robot, geometry, &check)
        })
        .map_err(|e| Refused::motion(Refusal::internal("collision", e)))?
        {
            let mut replan = Replan::of(hit, offset, scene, task, &motion, &arm.name);
            replan.lowered = motion.eased
                || motion.carry_height
                    < carry_height(scene, request.object, &self.options.lift) - 1e-9;
            return Ok(ArmMotionOutcome::Collides(Box::new(replan)));
        }
        Ok(ArmMotionOutcome::Free(PlannedPath {
            joint_path,
            grasp_at,
            release_at,
            motion,
        }))
    }

    /// A transit of `arm` from `from` to `to` (excluded, included) under
    /// `moves`' edge test, with the random stream `stream` of the sub-goal's
    /// seed. An end that is not free gives the straight move, for the whole
    /// path's check to name the hit; the inner `Err` is why no transit
    /// exists within the budget (a search this sub-goal already made in
    /// vain is not made again: [`super::world::FailedTransits`]), the outer
    /// one a check that cannot run.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn transit(
        &self,
        pass: &Pass,
        arm: &Arm,
        moves: &FreeMoves,
        from: &[f64],
        to: &[f64],
        stream: usize,
        timings: &mut StageTimings,
    ) -> Result<Result<Vec<Vec<f64>>, TransitError>, Refused> {
        let settings = &self.options.transit;
        if let Some(e) = pass.failed_transits.get(stream, from, to) {
            return Ok(Err(e));
        }
        let found = timed(&mut timings.transit, || {
            plan_transit(
                arm,
                from,
                to,
                &mut |a, b| moves.edge_free(a, b),
                settings,
                subgoal_seed(pass.seed ^ TRANSIT_STREAM, stream),
            )
        });
        if let Err(e @ TransitError::NotFound { .. }) = &found {
            pass.failed_transits.insert(stream, from, to, e.clone());
        }
        match found {
            Ok(t) => Ok(Ok(t.path)),
            Err(TransitError::StartCollides | TransitError::EndCollides) => {
                Ok(Ok(joint_steps(from, to, settings.max_step)))
            }
            Err(TransitError::Check(e)) => Err(Refused::motion(Refusal::internal("collision", e))),
            Err(e) => Ok(Err(e)),
        }
    }
}

/// How many leading travel waypoints have a configuration that is not free
/// (at most all but the last travel waypoint).
pub(super) fn leading_blocked(
    moves: &FreeMoves,
    motion: &LiftedMotion,
    path: &[Vec<f64>],
) -> Result<usize, String> {
    let travel = motion
        .waypoints
        .iter()
        .take_while(|w| w.phase == Phase::Travel)
        .count()
        .min(path.len());
    for (k, q) in path.iter().enumerate().take(travel.saturating_sub(1)) {
        if moves.edge_free(q, q)? {
            return Ok(k);
        }
    }
    Ok(travel.saturating_sub(1))
}

/// Offset of the transit planner's random streams from the learner's
/// (sub-goal seeds are SplitMix64 steps; this keeps the two apart).
pub(super) const TRANSIT_STREAM: u64 = 0x7472_616e_7369_7473;

/// A collision-checked joint path, where the gripper closes and opens, and
/// the tool waypoints it follows.
pub(super) struct PlannedPath {
    pub(super) joint_path: Vec<Vec<f64>>,
    pub(super) grasp_at: usize,
    pub(super) release_at: usize,
    pub(super) motion: LiftedMotion,
}

/// How one arm's motion for a sub-goal turned out.
pub(super) enum ArmMotionOutcome {
    Free(PlannedPath),
    Collides(Box<Replan>),
    /// No collision-free transit within the planner's budget.
    NoTransit(TransitFailure),
}

/// A collision the grid did not see, and the cell to block for the next pass.
pub(super) struct Replan {
    /// The collision with the waypoint and phase where it happens.
    pub(super) refusal: Refusal,
    /// The cell under the colliding waypoint, when it is a travel or carry
    /// waypoint over a cell that may be blocked (not the start, the target or
    /// the goal).
    pub(super) replannable_cell: Option<Cell>,
    /// The hit is where the hand closes or opens on the object (approach,
    /// grasp, lift, release): turning the tool may avoid it.
    pub(super) at_grasp: bool,
    /// The motion carried lower than the full height (the route's height)
    /// or eased its turns over the target: the full-height fallback differs.
    pub(super) lowered: bool,
}

impl Replan {
    /// `offset`: joint-path configurations between the start and the first
    /// waypoint (the way out of park).
    pub(super) fn of(
        hit: PathHit,
        offset: usize,
        scene: &Scenario,
        task: &GridTask,
        motion: &LiftedMotion,
        arm: &str,
    ) -> Self {
        let at = hit
            .index
            .checked_sub(offset)
            .and_then(|i| motion.waypoint_of(i));
        let place = match at {
            Some((waypoint, phase)) => HitPlace::Waypoint { phase, waypoint },
            None if hit.index <= offset => HitPlace::ToFirstWaypoint,
            None => HitPlace::ReturningToPark,
        };
        let cell = at.and_then(|(k, phase)| blockable_cell(scene, task, motion, k, phase));
        let at_grasp = at.is_some_and(|(_, p)| where_the_hand_acts(p));
        // The robot is inside a hand's perimeter where it stands: no motion
        // can keep that margin, the hand has to move first.
        let in_hand_at_start = hit.collision.first_t <= 1e-9
            && scene.hands.iter().any(|h| h.name == hit.collision.other);
        let refusal = match in_hand_at_start {
            true => Refusal::HandCoversGripper,
            false => collides(arm, &hit.collision, place),
        };
        Self {
            refusal,
            replannable_cell: cell,
            at_grasp,
            lowered: false,
        }
    }

    /// The next pass after no arm reached the tool path within its joint
    /// limits (`joint_limit`) or at all (`unreachable`), as after a
    /// collision at the waypoint where each arm failed: a travel or carry
    /// waypoint's cell is blocked (the route passing too near the base, or
    /// too far out, goes round it), and a failure where the hand acts turns
    /// the tool (half a turn unwinds a wrist at its limit). `Err`: the
    /// refusal stands (another kind, or no failure the grid or a turn can
    /// change).
    pub(super) fn out_of_reach(
        refusal: Refusal,
        scene: &Scenario,
        task: &GridTask,
        motion: &LiftedMotion,
    ) -> Result<Self, Refusal> {
        let (Refusal::JointLimit { arms } | Refusal::Unreachable { arms }) = &refusal else {
            return Err(refusal);
        };
        let at = |f: &crate::error::ArmFailure| f.phase.map(|p| (f.waypoint, p));
        // The earliest waypoint any arm failed at decides the cell.
        let cell = (arms.iter().filter_map(at))
            .filter_map(|(k, p)| Some((k, blockable_cell(scene, task, motion, k, p)?)))
            .min_by_key(|&(k, _)| k)
            .map(|(_, cell)| cell);
        let at_grasp = arms
            .iter()
            .filter_map(at)
            .any(|(_, p)| where_the_hand_acts(p));
        if cell.is_none() && !at_grasp {
            return Err(refusal);
        }
        Ok(Self {
            refusal,
            replannable_cell: cell,
            at_grasp,
            lowered: false,
        })
    }
}

/// The grid cell under tool waypoint `k` when the waypoint is a travel or
/// carry one over a cell that may be blocked (not the start, the target or
/// an obstacle's).
fn blockable_cell(
    scene: &Scenario,
    task: &GridTask,
    motion: &LiftedMotion,
    k: usize,
    phase: Phase,
) -> Option<Cell> {
    let grid = &task.grid;
    let p = motion.waypoints.get(k)?.position;
    let cell = grid.cell_at(scene.base_to_pixel([p[0], p[1]]));
    let blockable = cell != grid.start && cell != grid.target && grid.code(cell) == CellCode::Empty;
    (matches!(phase, Phase::Travel | Phase::Carry) && blockable).then_some(cell)
}

/// Whether the hand closes or opens on the object in `phase` (approach,
/// grasp, lift, release): turning the tool may change what happens there.
fn where_the_hand_acts(phase: Phase) -> bool {
    matches!(
        phase,
        Phase::Approach | Phase::Grasp | Phase::Lift | Phase::Release
    )
}

/// Largest joint difference (rad or m) at which a solved configuration is
/// taken as the current one (IK converges to about 1e-9).
pub(super) const SAME_CONFIGURATION: f64 = 1e-6;

/// The lifted motion of an object already in the gripper: everything up
/// to the lift (travel, approach, grasp, lift) is dropped, so the motion
/// starts with the carry.
pub(super) fn carry_on(motion: &mut LiftedMotion) {
    let carry = motion
        .waypoints
        .iter()
        .position(|w| matches!(w.phase, Phase::Carry | Phase::OverWall))
        .unwrap_or(0);
    motion.waypoints.drain(..carry);
}

/// The trajectory of a motion that starts holding: the close command the
/// timing stage put at t = 0 (and the rest it waited for it) is dropped.
pub(super) fn drop_leading_close(motion: &mut TimedMotion) {
    let Some(close) = motion
        .gripper
        .iter()
        .position(|e| e.command == crate::trajectory::GripperCommand::Close)
    else {
        return;
    };
    let shift = motion.gripper.remove(close).end;
    motion.points.retain(|p| p.time_from_start >= shift - 1e-9);
    for p in &mut motion.points {
        p.time_from_start = (p.time_from_start - shift).max(0.0);
    }
    for e in &mut motion.gripper {
        e.start -= shift;
        e.end -= shift;
    }
}

/// The refusal of a collision `hit` of `arm` at `place`.
pub(super) fn collides(arm: &str, hit: &Collision, place: HitPlace) -> Refusal {
    Refusal::Collides {
        arm: arm.to_string(),
        body: hit.body.clone(),
        other: hit.other.clone(),
        hit: hit.kind,
        place,
        clearance_m: hit.clearance,
        penetration_m: hit.penetration,
        margin_m: hit.margin,
        depth_m: hit.margin_violation.max(0.0),
    }
}
