//! The geometric re-check of the remaining trajectory against the newest
//! scene: every arm link, the gripper and — while held — the object
//! (attached where it was grasped) against every obstacle with its safety
//! perimeter, by the planner's own continuous check
//! ([`crate::clearance::check_motion`]). It runs only when a change could
//! matter: an element that appeared or moved within [`REACH_M`] (plus its
//! margin) of the remaining tool path in the table plane, or one at least
//! [`TALL_M`] tall anywhere (an elbow can reach it away from the tool).
//! Anything else is farther from every robot body than the grid and the
//! check look.

use afford_collision::{Collision, RobotGeometry};
use afford_kinematics::RobotModel;

use crate::clearance::{ArmMotion, check_after_release, check_motion};
use crate::plan::SubgoalPlan;
use crate::scenario::{PixelBox, Scenario};

use super::belief::{Change, ElementKind};

/// How far from the tool path a change is looked at, m: the gripper's and
/// a held piece's reach from the tool point with room to spare.
pub const REACH_M: f64 = 0.15;

/// Elements at least this tall are re-checked wherever they are, m.
pub const TALL_M: f64 = 0.15;

/// The remaining trajectory of one sub-goal.
pub struct RemainingMotion<'a> {
    pub plan: &'a SubgoalPlan,
    /// The whole robot's configuration (other arms stay there).
    pub rest: &'a [f64],
    /// First sample still ahead.
    pub from: usize,
    /// Tool positions of every sample, base frame, m.
    pub tool: &'a [[f64; 3]],
    /// The target's box when the plan grasped (or grasps) it.
    pub target_box: PixelBox,
    /// The arm's configuration when the fingers closed, when held now.
    pub held_grasp: Option<&'a [f64]>,
}

/// True when one of `changes` in `scene` could touch the remaining motion.
pub fn could_touch(scene: &Scenario, changes: &[Change], m: &RemainingMotion) -> bool {
    let ahead = &m.tool[m.from.min(m.tool.len())..];
    let [mu, mv] = scene.metres_per_pixel();
    let pixels: Vec<[f64; 2]> = ahead
        .iter()
        .map(|p| scene.base_to_pixel([p[0], p[1]]))
        .collect();
    changes.iter().any(|change| {
        let (Change::Appeared { kind, name } | Change::Moved { kind, name }) = change else {
            return false;
        };
        let Some((bbox, height, margin)) = element(scene, *kind, name) else {
            return false;
        };
        let reach = REACH_M + margin;
        let near = bbox.grown(reach / mu, reach / mv);
        height >= TALL_M || pixels.iter().any(|&p| near.contains(p))
    })
}

/// The first collision of the remaining motion with `scene`, if any.
pub fn first_hit(
    robot: &RobotModel,
    geometry: &RobotGeometry,
    scene: &Scenario,
    m: &RemainingMotion,
) -> Result<Option<Collision>, String> {
    let (Some(motion), Some(arm)) = (&m.plan.trajectory, &m.plan.arm) else {
        return Ok(None);
    };
    let (Some(target), Some(goal)) = (
        scene.object_index(&m.plan.object),
        scene.goal_index(&m.plan.goal),
    ) else {
        return Ok(None);
    };
    let from = m.from.min(motion.points.len() - 1);
    let path: Vec<Vec<f64>> = motion.points[from..]
        .iter()
        .map(|p| p.positions.clone())
        .collect();
    let (grasp, release) = motion.gripper_samples();
    let mut planned = scene.clone();
    if from < release || release == 0 {
        planned.objects[target].bbox = m.target_box;
    }
    let held = m.held_grasp.map(|q| (m.target_box, q));
    let check = ArmMotion {
        scenario: &planned,
        target,
        goal,
        arm,
        rest: m.rest,
        path: &path,
        grasp_at: match held {
            Some(_) => 0,
            None => grasp.saturating_sub(from),
        },
        release_at: release.saturating_sub(from),
        held,
    };
    let hit = match from >= release && release > 0 {
        // Released: the way out only, the piece resting in its goal.
        true => check_after_release(robot, geometry, &check)?,
        false => check_motion(robot, geometry, &check)?,
    };
    Ok(hit.map(|hit| hit.collision))
}

/// An element's box, height and safety margin (m).
fn element(scene: &Scenario, kind: ElementKind, name: &str) -> Option<(PixelBox, f64, f64)> {
    let safety = &scene.safety;
    match kind {
        ElementKind::Object => scene
            .objects
            .iter()
            .find(|o| o.name == name)
            .map(|o| (o.bbox, o.height, safety.sensitive_margin)),
        ElementKind::Goal => scene
            .goals
            .iter()
            .find(|g| g.name == name)
            .map(|g| (g.bbox, g.height, safety.obstacle_margin)),
        ElementKind::Hand => scene
            .hands
            .iter()
            .find(|h| h.name == name)
            .map(|h| (h.bbox, h.height, safety.hand_margin)),
    }
}
