//! The feasibility probe: whether a sub-goal the planner refused has free
//! poses. It owns the rule below and its search: damped least-squares IK
//! on k's chain and Jacobian (from the URDF, as [`crate::chain`]) and the
//! dense check's collision measurement (parry, this crate's scene, bodies
//! and margins: [`crate::dense`], [`crate::scene`]), sharing no code path
//! with the planner's kinematics, IK or collision checks.
//!
//! Rule. Moving object `o` into goal `g` in a scene (the one the caller
//! gives) *has free poses* when for some arm and some grasp yaw there are
//! configurations within the joint limits, each free of every collision
//! with every margin, with the tool pointing straight down (approach axis
//! along −z, tool x along the yaw) at
//!
//! - (a) the grasp: the tool centre point over the centre of `o`'s box, at
//!   the grasp height above its bottom;
//! - (b) [`ProbeSettings::above`] (0.15 m) straight above the grasp;
//! - (c) a release: `o` held as grasped over a spot of `g` where, dropped
//!   onto the floor, it lies inside the inner walls without overlapping
//!   another piece (the check's placement rule), its bottom
//!   [`ProbeSettings::release_clearance`] above the highest of the goal's
//!   wall top and the tops (plus their margins) of the pieces whose
//!   centres lie in the goal's box. Spots: a 7 × 7 lattice over where the
//!   footprint fits, the [`MAX_SPOTS`] placeable ones nearest the centre.
//!
//! Grasp yaws: the yaw of `o`'s longer side (the fingers, closing along the
//! tool's y axis, span the shorter side), that yaw + 90°, and each turned
//! half a turn (the same closing axis, the gripper the other way round: the
//! Care-O-bot's fixed jaw on the other side), leaving out a yaw whose width
//! across the fingers exceeds the gripper's `max_opening`. Grasp height
//! above `o`'s bottom, the planner's documented rule re-implemented
//! ([`ProbeSettings`] holds the same defaults): half `o`'s height, but no
//! lower than `min_grasp_height`, nor the fingertips `tip_clearance` off its
//! support, nor the palm (every tool collider outside the grasp region)
//! less than `obstacle_margin + palm_clearance` above `o`'s top; when the
//! fingertips then reach neither `o`'s middle nor `min_grip_depth` below
//! its top there is no grasp, and no free pose.
//!
//! Collisions, as the check's phases have them: at (a) and (b) the scene
//! of the sub-goal ([`scene::obstacles`]) and the target, near which only
//! the fingers may come; at (c) the scene and the held object riding on the
//! tool. Self-collision on every pair but the allowed ones. The other arms
//! are at their park postures, every joint of no arm at home.
//!
//! Bounded and deterministic: at each pose at most
//! [`ProbeSettings::restarts`] IK attempts of at most
//! [`ProbeSettings::iterations`] steps, first from the previous pose's
//! solution (the arm's home for the grasp; once per release spot), then
//! from seeded random configurations within the limits.

use std::f64::consts::PI;

use afford_kinematics::RobotModel;
use afford_planner::Scenario;
use nalgebra::{DMatrix, DVector};

use crate::bodies::{Body, body};
use crate::chain::Iso;
use crate::check::Robot;
use crate::dense::{Findings, Phase};
use crate::placement::{self, width_across_fingers};
use crate::scene::{self, GOAL_WALL, Obstacle, Piece, Role};

mod poses;
mod settings;
#[cfg(test)]
mod tests;

pub use settings::{MAX_COUNT, MAX_LENGTH, ProbeError, ProbeSettings};

use poses::{SplitMix, grasp_yaws, gripper_reach, mix, release_floor, release_spots, top_down};

/// A pose to reach: the tool poses to choose from, the obstacles and the
/// bodies checked there.
type Pose<'p> = (&'p [Iso], &'p [Obstacle], &'p [Body]);

/// Damping of the least-squares IK step (m or rad).
pub const DAMPING: f64 = 0.1;
/// Largest change of any joint in one IK step, rad or m.
pub const MAX_STEP: f64 = 0.5;
/// Most release spots tried in a goal (those nearest its centre).
pub const MAX_SPOTS: usize = 9;

/// Free poses of one arm and yaw: the whole robot's configuration at the
/// grasp, above it and at the release.
#[derive(Debug, Clone, PartialEq)]
pub struct FreePoses {
    pub arm: String,
    /// Tool yaw, rad (base frame).
    pub yaw: f64,
    pub grasp: Vec<f64>,
    pub above: Vec<f64>,
    pub release: Vec<f64>,
}

/// One arm as the probe's IK sees it.
struct ArmIk {
    name: String,
    chain: k::SerialChain<f64>,
    /// Robot joint index of each of the chain's movable joints.
    joints: Vec<usize>,
    /// Whether each of the chain's movable joints is the arm's (the others
    /// stay where they are).
    free: Vec<bool>,
    /// Robot joint indices of the arm.
    arm_joints: Vec<usize>,
    tool: usize,
}

/// The probe for one robot (build once, ask for many sub-goals).
pub struct Probe<'a> {
    robot: Robot<'a>,
    arms: Vec<ArmIk>,
    /// Home with every park posture.
    rest: Vec<f64>,
    /// How far the grasp region reaches below the tool centre point, and
    /// the lowest point of the other tool colliders above it, over every arm.
    tips_below: f64,
    palm_above: f64,
    settings: ProbeSettings,
}

impl<'a> Probe<'a> {
    /// The probe for `model` with `settings`.
    pub fn new(model: &'a RobotModel, settings: ProbeSettings) -> Result<Self, ProbeError> {
        let fail = |message: String| ProbeError::Robot {
            robot: model.name().to_string(),
            message,
        };
        settings.validate()?;
        let robot = Robot::new(model).map_err(fail)?;
        let urdf = urdf_rs_k::read_from_string(model.urdf())
            .map_err(|e| fail(format!("the URDF cannot be read by urdf-rs 0.9: {e}")))?;
        let tree = k::Chain::<f64>::from(&urdf);
        let mut arms = Vec::new();
        for arm in model.arms() {
            let end = tree
                .find_link(&arm.tool_link)
                .ok_or_else(|| fail(format!("no link '{}' for k", arm.tool_link)))?;
            let chain = k::SerialChain::from_end(end);
            let names: Vec<String> = chain.iter_joints().map(|j| j.name.clone()).collect();
            let joints = (names.iter())
                .map(|n| {
                    model
                        .joint_index(n)
                        .ok_or_else(|| fail(format!("no joint '{n}'")))
                })
                .collect::<Result<Vec<_>, _>>()?;
            if let Some(j) = (arm.joint_indices.iter()).find(|j| !joints.contains(j)) {
                let name = &model.joints()[*j].name;
                return Err(fail(format!("joint '{name}' is not on the tool's k chain")));
            }
            let free = joints
                .iter()
                .map(|j| arm.joint_indices.contains(j))
                .collect();
            arms.push(ArmIk {
                name: arm.name.clone(),
                chain,
                joints,
                free,
                arm_joints: arm.joint_indices.clone(),
                tool: robot.tool_link(arm),
            });
        }
        let mut rest = model.home().to_vec();
        for &(j, v) in model.arms().iter().flat_map(|a| &a.park) {
            rest[j] = v;
        }
        let (tips_below, palm_above) = gripper_reach(&robot, &arms);
        Ok(Self {
            robot,
            arms,
            rest,
            tips_below,
            palm_above,
            settings,
        })
    }

    /// Free poses for moving `object` into `goal` in `s` by the rule of the
    /// module docs, or `None` when no arm and yaw has them.
    pub fn free_poses(
        &self,
        s: &Scenario,
        object: &str,
        goal: &str,
    ) -> Result<Option<FreePoses>, ProbeError> {
        let target =
            (s.object_index(object)).ok_or_else(|| ProbeError::UnknownObject(object.into()))?;
        let g = s
            .goal_index(goal)
            .ok_or_else(|| ProbeError::UnknownGoal(goal.into()))?;
        let pieces = scene::pieces(s);
        let piece = &pieces[target];
        let Some(height) = self.grasp_height(s, piece) else {
            return Ok(None);
        };
        let centre = piece.pose.translation.vector;
        let bottom = centre.z - piece.half[2];
        let scene = scene::obstacles(s, &pieces, target, g);
        let near = Obstacle::piece(piece, s.safety.obstacle_margin, Role::Target);
        let before: Vec<Obstacle> = scene.iter().cloned().chain([near]).collect();
        let release_z = release_floor(s, &pieces, target, g) + self.settings.release_clearance;
        let spots = release_spots(s, g, piece);
        let others: Vec<&Piece> = (pieces.iter().enumerate())
            .filter(|&(i, _)| i != target)
            .map(|(_, p)| p)
            .collect();
        let opening = self.robot.model.gripper().max_opening;
        for (y, yaw) in grasp_yaws(s, target).into_iter().enumerate() {
            let grasp = top_down([centre.x, centre.y, bottom + height], yaw);
            if width_across_fingers(piece, &grasp) > opening {
                continue;
            }
            let lifted = bottom + height + self.settings.above;
            let above = top_down([centre.x, centre.y, lifted], yaw);
            let rel = grasp.inverse() * piece.pose;
            let release: Vec<Iso> = (spots.iter())
                .map(|&[x, y]| top_down([x, y, release_z + height], yaw))
                .filter(|tool| {
                    let floor = s.camera.table_z + GOAL_WALL;
                    let pose = placement::dropped(&(tool * rel), &piece.half, floor);
                    let dropped = Piece {
                        pose,
                        ..piece.clone()
                    };
                    placement::check(s, g, &dropped, &others).is_empty()
                })
                .take(MAX_SPOTS)
                .collect();
            if release.is_empty() {
                continue;
            }
            for (a, arm) in self.arms.iter().enumerate() {
                let held = self.held(arm, piece, rel);
                let holding: Vec<Body> = self.robot.bodies.iter().cloned().chain([held]).collect();
                let bodies = &self.robot.bodies;
                let poses: [Pose; 3] = [
                    (&[grasp], &before, bodies),
                    (&[above], &before, bodies),
                    (&release, &scene, &holding),
                ];
                let seed = mix(self.settings.seed, a as u64, y as u64);
                if let Some([grasp, above, release]) = self.arm_poses(arm, poses, seed) {
                    return Ok(Some(FreePoses {
                        arm: arm.name.clone(),
                        yaw,
                        grasp,
                        above,
                        release,
                    }));
                }
            }
        }
        Ok(None)
    }

    /// Free configurations of `arm` at each pose in turn (tool poses to
    /// choose from, obstacles, bodies). Attempt `i` aims at tool pose
    /// `i mod n`, from the previous pose's solution for each of the `n`
    /// tool poses once, then from random configurations.
    fn arm_poses(&self, arm: &ArmIk, poses: [Pose; 3], seed: u64) -> Option<[Vec<f64>; 3]> {
        let mut from = self.rest.clone();
        for &j in &arm.arm_joints {
            from[j] = self.robot.model.home()[j];
        }
        let mut found: [Vec<f64>; 3] = Default::default();
        for (p, (tools, obstacles, bodies)) in poses.into_iter().enumerate() {
            let mut random = SplitMix(mix(seed, p as u64, 0));
            let q = (0..self.settings.restarts).find_map(|attempt| {
                let start = match attempt < tools.len() {
                    true => from.clone(),
                    false => self.random_configuration(arm, &mut random),
                };
                let q = self.solve(arm, &tools[attempt % tools.len()], &start)?;
                self.is_free(&q, obstacles, bodies).then_some(q)
            })?;
            from = q.clone();
            found[p] = q;
        }
        Some(found)
    }

    /// The grasp height above the piece's bottom (module docs), `None`
    /// when the fingers cannot hold it with the palm clear.
    fn grasp_height(&self, s: &Scenario, piece: &Piece) -> Option<f64> {
        let c = &self.settings;
        let h = 2.0 * piece.half[2];
        let grasp = (h / 2.0)
            .max(c.min_grasp_height)
            .max(self.tips_below + c.tip_clearance)
            .max(h + s.safety.obstacle_margin + c.palm_clearance - self.palm_above);
        let tips = grasp - self.tips_below;
        // 1 nm: a grip of exactly `min_grip_depth` holds despite rounding.
        (tips <= h / 2.0 || h - tips >= c.min_grip_depth - 1e-9).then_some(grasp)
    }

    /// The held piece as a body on `arm`'s tool, at `rel` in the tool frame.
    fn held(&self, arm: &ArmIk, piece: &Piece, rel: Iso) -> Body {
        let r = &self.robot;
        let name = format!("held {}", piece.name);
        body(r.model, &r.kin, name, arm.tool, piece.shape(), rel)
    }

    /// A configuration of the rest posture with `arm`'s joints drawn
    /// uniformly within their limits (±π for an unbounded joint).
    fn random_configuration(&self, arm: &ArmIk, random: &mut SplitMix) -> Vec<f64> {
        let mut q = self.rest.clone();
        for &j in &arm.arm_joints {
            let joint = &self.robot.model.joints()[j];
            let (lo, hi) = (joint.lower.max(-PI), joint.upper.min(PI));
            q[j] = lo + random.unit() * (hi - lo);
        }
        q
    }

    /// Damped least squares on k's chain and Jacobian from `start` (a
    /// whole-robot configuration) to the tool pose `tool`: the solution
    /// when it is within the description's joint limits and this crate's
    /// FK puts the tool within 1 mm and 0.01 rad of `tool`.
    fn solve(&self, arm: &ArmIk, tool: &Iso, start: &[f64]) -> Option<Vec<f64>> {
        let joints = self.robot.model.joints();
        let chain = &arm.chain;
        let mut x: Vec<f64> = arm.joints.iter().map(|&j| start[j]).collect();
        let mut converged = false;
        for _ in 0..self.settings.iterations {
            chain.set_joint_positions_unchecked(&x);
            let now = chain.end_transform();
            let dp = tool.translation.vector - now.translation.vector;
            let dr = (tool.rotation * now.rotation.inverse()).scaled_axis();
            if dp.norm() < 1e-4 && dr.norm() < 1e-3 {
                converged = true;
                break;
            }
            let mut jacobian = k::jacobian(chain);
            for (c, free) in arm.free.iter().enumerate() {
                if !free {
                    jacobian.column_mut(c).fill(0.0);
                }
            }
            let error = DVector::from_row_slice(&[dp.x, dp.y, dp.z, dr.x, dr.y, dr.z]);
            let damped = &jacobian * jacobian.transpose()
                + DMatrix::<f64>::identity(6, 6) * (DAMPING * DAMPING);
            let mut dx = jacobian.transpose() * damped.cholesky()?.solve(&error);
            let largest = dx.amax();
            if !largest.is_finite() {
                return None;
            }
            if largest > MAX_STEP {
                dx *= MAX_STEP / largest;
            }
            for (c, &j) in arm.joints.iter().enumerate() {
                x[c] = (x[c] + dx[c]).clamp(joints[j].lower, joints[j].upper);
            }
        }
        let mut q = start.to_vec();
        for (&j, v) in arm.joints.iter().zip(x) {
            q[j] = v;
        }
        let reached = self.robot.kin.link_poses(&q)[arm.tool];
        let off = (reached.translation.vector - tool.translation.vector).norm();
        let turned = reached.rotation.angle_to(&tool.rotation);
        (converged && off < 1e-3 && turned < 1e-2).then_some(q)
    }

    /// Whether configuration `q` keeps every margin: the check's dense
    /// collision measurement ([`Phase`]) at that one configuration.
    fn is_free(&self, q: &[f64], obstacles: &[Obstacle], bodies: &[Body]) -> bool {
        let r = &self.robot;
        let only: [&[f64]; 1] = [&[]];
        let phase = Phase {
            kin: &r.kin,
            bodies,
            obstacles,
            pairs: r.pairs(obstacles, bodies),
            rest: q,
            arm: &[],
            speeds: &[],
            positions: &only,
            times: &[0.0],
            first_sample: 0,
        };
        let mut findings = Findings::new();
        phase.run(&mut findings);
        findings.is_empty()
    }
}
