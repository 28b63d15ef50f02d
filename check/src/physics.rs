//! The physical replay of a plan (`afford check --physics`): the scenario
//! read by this crate (its pixel boxes through `camera.pixel_to_base`, as
//! [`crate::scene`] reads them) turned into afford-collision's
//! [`PhysicsScene`], each sub-goal into a [`ReplayMotion`], and the replay's
//! findings into violations of class `physics`.
//!
//! Scene: the table under the image's footprint; goals as open boxes, hands
//! as solid boxes (fixed); every object a dynamic box of its footprint and
//! height (a `circle`/`cylinder`/`disc` the upright stadium inside it: the
//! disc of the narrower side swept along the longer side), standing on the table — on a goal's floor when its
//! centre lies inside that goal — with afford-collision's default density
//! and friction ([`replay::PIECE_DENSITY`], [`replay::PIECE_FRICTION`]); the robot where the plan's `start_state` (or the
//! scenario's rule) puts it.
//!
//! Motions: the arm's samples as planned; the grasp holds the sub-goal's
//! object from the end of the close event (the fingers hold) to the start
//! of the open event (they let go; the arm rests meanwhile), and the object
//! must end inside the sub-goal's goal.

use afford_collision::replay::{
    self, Grasp, PhysicsPiece, PhysicsScene, PieceShape, ReplayMotion, ReplayReport,
};
use afford_collision::{BoxKind, SceneBox, TableSpec};
use afford_kinematics::RobotModel;
use afford_planner::Scenario;
use afford_planner::trajectory::GripperCommand;

use crate::file::{PlanFile, SubgoalFile};
use crate::report::{Report, ViolationClass};
pub use crate::scene::ROUND_SHAPES;
use crate::scene::{Footprint, is_round, support_under, table_extent};
use crate::start;

/// The replay's scene for `scenario`, the robot at the plan's start.
pub fn physics_scene(
    scenario: &Scenario,
    robot: &RobotModel,
    plan: &PlanFile,
) -> Result<PhysicsScene, String> {
    let robot_start = start::state(robot, plan.start_state.as_ref())?;
    let z0 = scenario.camera.table_z;
    let (min, max) = table_extent(scenario);
    let goals = (scenario.goals.iter()).map(|g| (&g.name, BoxKind::Goal, g.bbox, g.height));
    let hands = (scenario.hands.iter()).map(|h| (&h.name, BoxKind::Hand, h.bbox, h.height));
    let boxes = goals
        .chain(hands)
        .map(|(name, kind, bbox, height)| {
            let f = Footprint::of(scenario, bbox);
            SceneBox {
                name: name.clone(),
                kind,
                centre: f.centre,
                size: [f.size[0], f.size[1], height],
                yaw: f.yaw,
                margin: 0.0,
                round: false,
            }
        })
        .collect();
    let pieces = scenario
        .objects
        .iter()
        .map(|o| {
            let f = Footprint::of(scenario, o.bbox);
            let size = [f.size[0], f.size[1], o.height];
            let shape = match is_round(&o.shape) {
                true => PieceShape::Stadium { size },
                false => PieceShape::Box { size },
            };
            let floor = z0 + support_under(scenario, o.bbox);
            PhysicsPiece::standing(&o.name, shape, f.centre, f.yaw, floor)
        })
        .collect();
    Ok(PhysicsScene {
        table_z: z0,
        table: TableSpec {
            min,
            max,
            margin: 0.0,
        },
        boxes,
        pieces,
        robot_start: Some(robot_start),
        presence: Vec::new(),
    })
}

/// One motion per sub-goal: its arm's samples and its grasp.
pub fn replay_motions(plan: &PlanFile) -> Result<Vec<ReplayMotion>, String> {
    plan.subgoals
        .iter()
        .enumerate()
        .map(|(k, sub)| motion(sub).map_err(|m| format!("subgoals[{k}]: {m}")))
        .collect()
}

/// A sub-goal cut short grasps only if it closed, and is judged on its
/// placement only if it opened; holding at its end, it lets go there. Its
/// piece is its target throughout, as in a whole sub-goal.
fn motion(sub: &SubgoalFile) -> Result<ReplayMotion, String> {
    let event =
        |command: GripperCommand| sub.trajectory.gripper.iter().find(|e| e.command == command);
    let points = &sub.trajectory.points;
    let end = points.last().map_or(0.0, |p| p.time_from_start);
    // Before any close the piece is still the target (the open fingers
    // reach around it as planned), never gripped.
    let (goal, t_close, t_open) = match (event(GripperCommand::Close), event(GripperCommand::Open))
    {
        (Some(close), Some(open)) => (Some(sub.goal.clone()), close.end, open.start),
        (Some(close), None) if sub.cut_short => (None, close.end, end),
        (None, None) if sub.cut_short => (None, end, end),
        (close, _) => {
            let missing = if close.is_none() { "close" } else { "open" };
            return Err(format!("no {missing} gripper event"));
        }
    };
    Ok(ReplayMotion {
        arm: sub.arm.clone(),
        joint_names: sub.joint_names.clone(),
        times: points.iter().map(|p| p.time_from_start).collect(),
        positions: points.iter().map(|p| p.positions.clone()).collect(),
        grasp: Some(Grasp {
            piece: sub.object.clone(),
            goal,
            t_close,
            t_open,
        }),
    })
}

/// Replays `plan` and reports each failure as a `physics` violation.
pub fn check_physics(
    scenario: &Scenario,
    robot: &RobotModel,
    plan: &PlanFile,
) -> (Option<ReplayReport>, Report) {
    check_physics_over_time(&[(0.0, scenario)], robot, plan)
}

/// The replay's scene when the scene changed while the plan ran: `scenes`
/// are `(t, scenario)`, `t` on the first sub-goal's clock, increasing, the
/// first at its start; each goal, hand and object is there while it stays
/// as it is ([`PhysicsScene::over_time`]: a moved box is two bodies, the
/// earlier one named `NAME (until T s)`).
pub fn physics_scene_over_time(
    scenes: &[(f64, &Scenario)],
    robot: &RobotModel,
    plan: &PlanFile,
) -> Result<PhysicsScene, String> {
    let each = scenes
        .iter()
        .map(|(t, s)| Ok((*t, physics_scene(s, robot, plan)?)))
        .collect::<Result<Vec<_>, String>>()?;
    PhysicsScene::over_time(&each).map_err(|e| e.to_string())
}

/// [`check_physics`] in a scene that changed while the plan ran
/// ([`physics_scene_over_time`]).
pub fn check_physics_over_time(
    scenes: &[(f64, &Scenario)],
    robot: &RobotModel,
    plan: &PlanFile,
) -> (Option<ReplayReport>, Report) {
    let mut report = Report::default();
    let built = physics_scene_over_time(scenes, robot, plan)
        .and_then(|scene| Ok((scene, replay_motions(plan)?)));
    let (scene, motions) = match built {
        Ok(b) => b,
        Err(m) => {
            report.push(ViolationClass::Physics, None, format!("cannot replay: {m}"));
            return (None, report);
        }
    };
    let replayed = replay::replay(&scene, robot, &motions);
    for (motion, message) in replayed.failures() {
        report.push(ViolationClass::Physics, motion, message);
    }
    (Some(replayed), report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::GOAL_WALL;

    /// The default scenario's pieces: boxes of their footprint and height on
    /// the table, a round one the stadium of its footprint, one inside a
    /// goal on its floor.
    #[test]
    fn scene_pieces_take_the_scenarios_shapes_and_supports() {
        let mut s = afford_planner::scenario::default_scenario().unwrap();
        let robot = RobotModel::builtin(&s.robot.model).unwrap();
        s.objects[0].shape = "Circle".into();
        let goal = s.goals[0].bbox;
        s.objects[1].bbox = s.objects[1].bbox.centred_at(goal.centre());
        let joints = robot.joints();
        let plan = PlanFile {
            start_state: Some(crate::StartState {
                joint_names: joints.iter().map(|j| j.name.clone()).collect(),
                positions: robot.home().to_vec(),
            }),
            subgoals: Vec::new(),
        };
        let scene = physics_scene(&s, &robot, &plan).unwrap();
        let z0 = s.camera.table_z;
        let (a, b, c) = (&scene.pieces[0], &scene.pieces[1], &scene.pieces[2]);
        let h = |i: usize| s.objects[i].height;
        assert!(matches!(a.shape, PieceShape::Stadium { size } if size[2] == h(0)));
        assert!((a.centre[2] - (z0 + 0.5 * h(0))).abs() < 1e-12);
        assert!((b.centre[2] - (z0 + GOAL_WALL + 0.5 * h(1))).abs() < 1e-12);
        assert!(matches!(c.shape, PieceShape::Box { size } if size[2] == h(2)));
        assert!(c.mass > 0.0 && scene.robot_start.is_some());
        assert_eq!(scene.boxes.len(), s.goals.len() + s.hands.len());
    }
}
