//! What carries over from one sub-goal to the next: the scene as the camera
//! would see it after each sub-goal (the object in its goal, the gripper
//! where it released), its snapshots for going back, the grid request and
//! the room of a sub-goal in it, and the seed of each sub-goal.

use std::cell::RefCell;

use afford_collision::RobotGeometry;
use afford_kinematics::RobotModel;

use super::types::{HeldObject, SubgoalPlan};
use crate::error::Refusal;
use crate::grid::GridRequest;
use crate::instruction::SubGoal;
use crate::lift::GripperReach;
use crate::place::Room;
use crate::scenario::Scenario;
use crate::start::{self};
use crate::transit::TransitError;

/// What carries over from one sub-goal to the next: the scene as the camera
/// would see it and the robot's configuration.
pub(super) struct World {
    pub(super) scene: Scenario,
    pub(super) gripper_px: [f64; 2],
    /// The tool's height above the table when it points down over
    /// `gripper_px` (metres), `None` otherwise ([`start::tool_height_over`]).
    pub(super) gripper_height: Option<f64>,
    pub(super) robot: Option<RobotModel>,
    pub(super) geometry: Option<RobotGeometry>,
    /// The gripper's reach and opening (stage `waypoints` and later).
    pub(super) gripper: Option<GripperReach>,
    pub(super) joints: Vec<f64>,
    /// The object in the gripper when planning starts mid-execution; only
    /// the first sub-goal carries it ([`Planner::plan_from`]).
    pub(super) held: Option<HeldObject>,
}

impl World {
    pub(super) fn snapshot(&self) -> Snapshot {
        Snapshot {
            scene: self.scene.clone(),
            gripper_px: self.gripper_px,
            gripper_height: self.gripper_height,
            joints: self.joints.clone(),
            held: self.held.clone(),
        }
    }

    pub(super) fn restore(&mut self, state: Snapshot) {
        self.scene = state.scene;
        self.gripper_px = state.gripper_px;
        self.gripper_height = state.gripper_height;
        self.joints = state.joints;
        self.held = state.held;
    }

    /// The scene after a planned sub-goal: the object rests on its spot in
    /// the goal box, the gripper is over it, the arm where its path ended
    /// (other arms stay where they are: the collision check sees them there).
    pub(super) fn advance(&mut self, request: GridRequest, done: &SubgoalPlan) {
        self.held = None;
        self.gripper_px = done.release_px;
        self.gripper_height = None;
        let object = &mut self.scene.objects[request.object];
        object.bbox = object.bbox.centred_at(self.gripper_px);
        let (Some(robot), Some(arm), Some(path)) = (&self.robot, &done.arm, &done.joint_path)
        else {
            return;
        };
        // Where the robot really stops: the last trajectory sample (the next
        // sub-goal starts there exactly), or the path's end before timing.
        let last = match &done.trajectory {
            Some(t) => t.points.last().map(|p| &p.positions),
            None => path.last(),
        };
        if let (Ok(arm), Some(last)) = (robot.arm(arm), last) {
            arm.insert(&mut self.joints, last);
        }
        self.gripper_height =
            start::tool_height_over(&self.scene, robot, &self.joints, self.gripper_px);
    }
}

/// The part of the [`World`] a sub-goal changes, to plan it again.
#[derive(Clone)]
pub(super) struct Snapshot {
    pub(super) scene: Scenario,
    pub(super) gripper_px: [f64; 2],
    pub(super) gripper_height: Option<f64>,
    pub(super) joints: Vec<f64>,
    pub(super) held: Option<HeldObject>,
}

/// The sub-goal a chain went back to, and the outcomes and world before.
pub(super) type Rewound = (usize, Vec<Result<SubgoalPlan, Refusal>>, Snapshot);

/// One sub-goal's inputs to a pass through the stages.
#[derive(Clone, Copy)]
pub(super) struct Pass<'a> {
    pub(super) world: &'a World,
    pub(super) goal: &'a SubGoal,
    pub(super) request: GridRequest,
    pub(super) seed: u64,
    /// The arm returns to park at the end (when it has a park posture).
    pub(super) park: bool,
    /// The objects the chain releases into the same goal later
    /// ([`later_in_goal`]).
    pub(super) later: &'a [usize],
    /// The transits of this sub-goal that were not found within the
    /// budget ([`FailedTransits`]).
    pub(super) failed_transits: &'a FailedTransits,
}

/// The transits a sub-goal's passes searched for and did not find, by
/// random stream (arm and leg) and ends. Within one sub-goal the scene, the
/// rest of the robot and the seed are the same for every pass, so the same
/// search gives the same answer: a pass that needs a transit already
/// searched for in vain (the grid replanned elsewhere, the tool turned, the
/// way to the same first waypoint unchanged) takes the answer instead of
/// spending the transit planner's budget again.
#[derive(Debug, Default)]
pub(super) struct FailedTransits(RefCell<Vec<FailedTransit>>);

/// A transit not found: stream, start, end and why.
type FailedTransit = (usize, Vec<f64>, Vec<f64>, TransitError);

impl FailedTransits {
    /// The failure of the same search, if it failed before.
    pub(super) fn get(&self, stream: usize, from: &[f64], to: &[f64]) -> Option<TransitError> {
        (self.0.borrow().iter())
            .find(|(s, a, b, _)| *s == stream && a == from && b == to)
            .map(|(.., e)| e.clone())
    }

    /// Remembers that the search found nothing.
    pub(super) fn insert(&self, stream: usize, from: &[f64], to: &[f64], e: TransitError) {
        (self.0.borrow_mut()).push((stream, from.to_vec(), to.to_vec(), e));
    }
}

/// Why a sub-goal was not planned.
#[derive(Debug)]
pub(super) struct Refused {
    /// Boxed: a refusal is large and `Refused` is every stage's `Err`.
    pub(super) reason: Box<Refusal>,
    /// The arm's motion failed (joints or trajectory stage): another robot
    /// state (the previous arm parked) may plan it.
    pub(super) motion: bool,
}

impl Refused {
    /// Refused before any arm moves (scene, grid, learner, lifting).
    pub(super) fn early(reason: Refusal) -> Self {
        Self {
            reason: Box::new(reason),
            motion: false,
        }
    }

    pub(super) fn motion(reason: Refusal) -> Self {
        Self {
            reason: Box::new(reason),
            motion: true,
        }
    }
}

pub(super) fn request(scene: &Scenario, goal: &SubGoal, gripper: [f64; 2]) -> GridRequest {
    GridRequest {
        object: scene
            .object_index(&goal.object)
            .expect("sub-goals name scenario objects"),
        goal: scene
            .goal_index(&goal.goal)
            .expect("sub-goals name scenario goals"),
        gripper,
    }
}

/// The objects of `goals[k + 1..]` bound for `goals[k]`'s goal, in order:
/// the pieces its release spot leaves room for ([`Room::later`]).
pub(super) fn later_in_goal(scene: &Scenario, goals: &[SubGoal], k: usize) -> Vec<usize> {
    goals[k + 1..]
        .iter()
        .filter(|g| g.goal == goals[k].goal)
        .filter_map(|g| scene.object_index(&g.object))
        .collect()
}

/// What a release spot leaves room for: the grasp region's colliders about
/// the TCP, at least the open fingers (m, see
/// [`GripperReach::finger_half_extent`]), once the robot is known, and the
/// chain's `later` pieces for the same goal.
pub(super) fn room<'a>(world: &World, later: &'a [usize]) -> Room<'a> {
    Room {
        opening: world.gripper.map(|g| g.finger_half_extent),
        later,
    }
}

/// A seed per sub-goal derived from the plan's seed (SplitMix64 step), so a
/// sub-goal's plan does not depend on how much randomness earlier ones drew.
pub fn subgoal_seed(seed: u64, k: usize) -> u64 {
    let mut z = seed.wrapping_add((k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A transit searched for in vain is answered again only for the same
    /// random stream and the same two ends.
    #[test]
    fn a_transit_searched_in_vain_is_not_searched_again_for_the_same_ends() {
        let failed = FailedTransits::default();
        let e = TransitError::NotFound {
            iterations: 300,
            extend_length: 1.0,
        };
        failed.insert(2, &[0.0, 1.0], &[1.0, 0.5], e.clone());
        assert_eq!(failed.get(2, &[0.0, 1.0], &[1.0, 0.5]), Some(e));
        assert_eq!(failed.get(3, &[0.0, 1.0], &[1.0, 0.5]), None);
        assert_eq!(failed.get(2, &[0.0, 1.0], &[1.0, 0.6]), None);
        assert_eq!(failed.get(2, &[0.1, 1.0], &[1.0, 0.5]), None);
    }
}
