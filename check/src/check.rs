//! The check of a whole plan: the start state against the scenario, then
//! each sub-goal in order — format, continuity, joint limits and rest,
//! gripper events, tool speed near hands, gripper opening, the dense
//! collision check in three phases (before the grasp: the target may be
//! touched by the fingers only; holding: the object rides with the tool;
//! after the release: the object lies where it dropped), placement — and
//! then the world moves on: the object rests where it dropped, the arm
//! where its trajectory ended. A sub-goal whose samples or gripper events
//! cannot be read ends the check (what follows it is unknown), and so does
//! one cut short (an executed run's abort): its phases end where it
//! stopped, and no sub-goal may follow it.

use afford_kinematics::RobotModel;
use afford_planner::Scenario;
use nalgebra::Vector3;

use crate::bodies::{Body, body, robot_bodies};
use crate::chain::Kinematics;
use crate::dense::{self, Findings, MAX_CONFIGURATIONS, Other, Pair, Phase};
use crate::file::{PlanFile, SubgoalFile};
use crate::format::{self, Events};
use crate::jerk;
use crate::placement;
use crate::rates::{self, ArmJoints, REST_TOLERANCE};
use crate::report::{Report, ViolationClass as C};
use crate::scene::{self, GOAL_WALL, Obstacle, Piece, Role};
use crate::start::{self, StartRule};
use crate::tool_speed;

/// The robot as the checker models it.
pub(crate) struct Robot<'a> {
    pub(crate) model: &'a RobotModel,
    pub(crate) kin: Kinematics,
    pub(crate) bodies: Vec<Body>,
    /// Body pairs checked for self-collision.
    pub(crate) self_pairs: Vec<(usize, usize)>,
    /// Bodies that may touch the target before the grasp.
    pub(crate) fingers: Vec<bool>,
}

/// What carries over from one sub-goal to the next.
struct World {
    /// The whole robot's configuration.
    q: Vec<f64>,
    /// Every object of the scenario, where it is now.
    pieces: Vec<Piece>,
}

/// Re-checks a plan the planner returned, in memory (no JSON round trip):
/// `check_plan(scenario, robot, &PlanFile::from(plan))`, with the robot
/// `scenario.robot.model` loaded from `base_dir` (the folder relative
/// robot paths start from, [`afford_planner::PlanOptions::base_dir`]).
/// `Err` when the robot cannot be loaded; an empty report means it passed.
pub fn check(
    scenario: &Scenario,
    plan: &afford_planner::Plan,
    base_dir: &std::path::Path,
) -> Result<Report, afford_kinematics::KinematicsError> {
    let robot = RobotModel::load(&scenario.robot.model, base_dir)?;
    Ok(check_plan(scenario, &robot, &PlanFile::from(plan)))
}

/// Checks `plan` against `scenario` for `robot`. Never panics on any input;
/// an empty report means the plan passed.
pub fn check_plan(scenario: &Scenario, robot: &RobotModel, plan: &PlanFile) -> Report {
    let mut report = Report::default();
    if plan.subgoals.is_empty() {
        report.push(
            C::Format,
            None,
            "the plan has no sub-goals: nothing to execute".into(),
        );
        return report;
    }
    let r = match Robot::new(robot) {
        Ok(r) => r,
        Err(e) => {
            report.push(C::Format, None, format!("robot {}: {e}", robot.name()));
            return report;
        }
    };
    let stated = start::scenario_joint_issues(scenario, robot);
    if !stated.is_empty() {
        for (field, message) in stated {
            report.push(C::Start, None, format!("the scenario's {field}: {message}"));
        }
        return report;
    }
    let q = match start::state(robot, plan.start_state.as_ref()) {
        Ok(q) => q,
        Err(e) => {
            report.push(C::Format, None, e);
            return report;
        }
    };
    let cell = scenario
        .object_index(&plan.subgoals[0].object)
        .map_or([1.0, 1.0], |i| {
            let b = scenario.objects[i].bbox;
            [b.w, b.l]
        });
    for message in start::check(
        &StartRule::of(scenario, robot),
        scenario,
        robot,
        &r.kin,
        &q,
        cell,
    ) {
        report.push(C::Start, None, message);
    }
    let mut world = World {
        q,
        pieces: scene::pieces(scenario),
    };
    for (k, sub) in plan.subgoals.iter().enumerate() {
        if !subgoal(scenario, &r, &mut world, k, sub, &mut report) {
            if sub.cut_short && k + 1 < plan.subgoals.len() {
                let message = "the execution stopped for good in this sub-goal (`cut_short`), yet sub-goals follow it".into();
                report.push(C::Format, Some(k), message);
            }
            break;
        }
    }
    report
}

/// Which bodies may touch the target before the gripper closes: the
/// description's `gripper.fingers`; when it names none, every body rigid
/// with an arm's tool frame (the rule the robot description documents).
fn grasp_region(model: &RobotModel, kin: &Kinematics, bodies: &[Body]) -> Vec<bool> {
    let named: Vec<bool> = (bodies.iter())
        .map(|b| model.gripper().fingers.contains(&b.name))
        .collect();
    if !model.gripper().fingers.is_empty() {
        return named;
    }
    let tools: Vec<Vec<usize>> = (model.arms().iter())
        .filter_map(|a| model.link_index(&a.tool_link).ok())
        .map(|l| moved_by_arms(model, kin, l))
        .collect();
    (bodies.iter())
        .map(|b| tools.contains(&moved_by_arms(model, kin, b.link)))
        .collect()
}

/// The arm joints (description order) that move `link`, sorted: two links
/// with the same set are rigid with each other while any arm moves (a
/// finger joint, in no arm, stays where it is).
pub(crate) fn moved_by_arms(model: &RobotModel, kin: &Kinematics, link: usize) -> Vec<usize> {
    let in_arm = |j: usize| model.arms().iter().any(|a| a.joint_indices.contains(&j));
    let mut j: Vec<usize> = (kin.ancestry(link).iter())
        .map(|a| a.joint)
        .filter(|&j| in_arm(j))
        .collect();
    j.sort_unstable();
    j.dedup();
    j
}

impl<'a> Robot<'a> {
    pub(crate) fn new(model: &'a RobotModel) -> Result<Self, String> {
        let kin = Kinematics::new(model)?;
        let bodies = robot_bodies(model, &kin)?;
        let self_pairs = self_pairs(model, &kin, &bodies);
        let fingers = grasp_region(model, &kin, &bodies);
        Ok(Self {
            model,
            kin,
            bodies,
            self_pairs,
            fingers,
        })
    }

    /// The arm's tool link index.
    pub(crate) fn tool_link(&self, arm: &afford_kinematics::Arm) -> usize {
        self.model.link_index(&arm.tool_link).unwrap_or(0)
    }

    /// The pairs of a phase: every body against every obstacle (the fingers
    /// not against the target or the piece they just released), the
    /// self-collision pairs, and the held object (last body, when present)
    /// against every link not rigid with the tool.
    pub(crate) fn pairs(&self, obstacles: &[Obstacle], bodies: &[Body]) -> Vec<Pair> {
        let n_robot = self.bodies.len();
        let mut pairs = Vec::new();
        for (b, _) in bodies.iter().enumerate() {
            for (o, obstacle) in obstacles.iter().enumerate() {
                if matches!(obstacle.role, Role::Target | Role::Released) && self.fingers[b] {
                    continue;
                }
                pairs.push(Pair {
                    body: b,
                    other: Other::Obstacle(o),
                    margin: obstacle.margin,
                });
            }
        }
        pairs.extend(self.self_pairs.iter().map(|&(a, b)| Pair {
            body: a,
            other: Other::Body(b),
            margin: 0.0,
        }));
        if bodies.len() > n_robot {
            let tool = &bodies[n_robot];
            for (b, body) in self.bodies.iter().enumerate() {
                let rigid = body
                    .radii
                    .iter()
                    .zip(&tool.radii)
                    .all(|(x, y)| (*x > 0.0) == (*y > 0.0));
                if !rigid {
                    pairs.push(Pair {
                        body: n_robot,
                        other: Other::Body(b),
                        margin: 0.0,
                    });
                }
            }
        }
        pairs
    }

    /// Whole-robot configuration with the arm's values from `arm_q`.
    fn with_arm(&self, rest: &[f64], arm: &afford_kinematics::Arm, arm_q: &[f64]) -> Vec<f64> {
        let mut q = rest.to_vec();
        for (&j, &v) in arm.joint_indices.iter().zip(arm_q) {
            q[j] = v;
        }
        q
    }
}

/// Pairs of bodies checked against each other: every pair except bodies of
/// one link, pairs that never move relative to each other (the same joints
/// move both; a mimic joint is a joint of its own), adjacent links (one is the nearest link with colliders above
/// the other) and the pairs the description allows.
fn self_pairs(model: &RobotModel, kin: &Kinematics, bodies: &[Body]) -> Vec<(usize, usize)> {
    let joints = |link: usize| {
        let mut j: Vec<usize> = kin.ancestry(link).iter().map(|a| a.slot).collect();
        j.sort_unstable();
        j
    };
    let links = model.links();
    let collider_parent = |mut l: usize| {
        while let Some(p) = links[l].parent {
            if !links[p].colliders.is_empty() {
                return Some(p);
            }
            l = p;
        }
        None
    };
    let mut pairs = Vec::new();
    for a in 0..bodies.len() {
        for b in a + 1..bodies.len() {
            let (la, lb) = (bodies[a].link, bodies[b].link);
            let adjacent = collider_parent(la) == Some(lb) || collider_parent(lb) == Some(la);
            if la == lb
                || adjacent
                || model.skips_self_collision(la, lb)
                || joints(la) == joints(lb)
            {
                continue;
            }
            pairs.push((a, b));
        }
    }
    pairs
}

/// Checks one sub-goal; false when the check cannot go on past it.
fn subgoal(
    s: &Scenario,
    r: &Robot,
    world: &mut World,
    k: usize,
    sub: &SubgoalFile,
    report: &mut Report,
) -> bool {
    let checked = match format::check(s, r.model, sub) {
        Ok(c) => c,
        Err(found) => {
            found
                .into_iter()
                .for_each(|(c, m)| report.push(c, Some(k), m));
            return false;
        }
    };
    let (arm, points) = (checked.arm, &sub.trajectory.points);
    let first = &points[0].positions;
    let here: Vec<f64> = arm.joint_indices.iter().map(|&j| world.q[j]).collect();
    if let Some((j, (a, b))) = first
        .iter()
        .zip(&here)
        .enumerate()
        .find(|(_, (a, b))| (*a - *b).abs() > REST_TOLERANCE)
    {
        let (class, from) = match k {
            0 => (C::Start, "start_state".to_string()),
            _ => (C::Continuity, format!("where sub-goal {} ended", k - 1)),
        };
        report.push(
            class,
            Some(k),
            format!(
                "the trajectory starts with {} = {a:.6}, {:.6} away from {from} ({b:.6})",
                arm.joint_names[j],
                (a - b).abs()
            ),
        );
    }
    let events = format::events(sub);
    let windows = events.as_ref().map_or_else(|_| Vec::new(), Events::windows);
    let joints = ArmJoints {
        joints: arm
            .joint_indices
            .iter()
            .map(|&j| &r.model.joints()[j])
            .collect(),
    };
    for (class, message, data) in rates::check(&joints, points, &windows)
        .into_iter()
        .chain(jerk::check(&joints, points))
    {
        report.push_with(class, Some(k), message, data);
    }
    let events = match events {
        Ok(e) => e,
        Err(found) => {
            found
                .into_iter()
                .for_each(|(c, m)| report.push(c, Some(k), m));
            return false;
        }
    };
    let configurations: Vec<Vec<f64>> = points
        .iter()
        .map(|p| r.with_arm(&world.q, arm, &p.positions))
        .collect();
    let tool_link = r.tool_link(arm);
    let tools: Vec<crate::chain::Iso> = configurations
        .iter()
        .map(|q| r.kin.link_poses(q)[tool_link])
        .collect();
    let times: Vec<f64> = points.iter().map(|p| p.time_from_start).collect();
    let positions: Vec<Vec<Vector3<f64>>> =
        vec![tools.iter().map(|t| t.translation.vector).collect()];
    let hands = scene::hand_boxes(s);
    if let Some(m) = tool_speed::check(&s.safety.separation, &hands, &positions[0], &times) {
        report.push(C::ToolSpeed, Some(k), m);
    }
    let target = checked.target;
    let piece = world.pieces[target].clone();
    // The object's pose in the tool frame from the grasp on.
    let rel = events.close.map(|close| {
        let grasp_tool = tools[close.sample];
        let width = placement::width_across_fingers(&piece, &grasp_tool);
        let opening = r.model.gripper().max_opening;
        if width > opening + placement::PLACEMENT_TOLERANCE {
            report.push(
                C::GripperOpening,
                Some(k),
                format!(
                    "{} is {width:.4} m wide across the fingers (the tool's y axis at the close, t = {:.3} s, sample {}), but the gripper opens {opening:.4} m",
                    piece.name, close.window.0, close.sample
                ),
            );
        }
        grasp_tool.inverse() * piece.pose
    });
    let released = rel.zip(events.open).map(|(rel, open)| Piece {
        pose: placement::dropped(
            &(tools[open.sample] * rel),
            &piece.half,
            s.camera.table_z + GOAL_WALL,
        ),
        ..piece.clone()
    });
    let phases = Phases {
        s,
        r,
        world,
        sub,
        arm,
        target,
        goal: checked.goal,
        events,
        rel,
        released: released.as_ref(),
    };
    if let Err(m) = phases.run(report, k) {
        report.push(C::Format, Some(k), m);
    }
    if let Some(released) = released {
        let others: Vec<&Piece> = world
            .pieces
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != target)
            .map(|(_, p)| p)
            .collect();
        for m in placement::check(s, checked.goal, &released, &others) {
            report.push(C::Placement, Some(k), m);
        }
        world.pieces[target] = released;
    }
    world.q = configurations[configurations.len() - 1].clone();
    !sub.cut_short
}

/// The three phases of the dense collision check of one sub-goal.
struct Phases<'a> {
    s: &'a Scenario,
    r: &'a Robot<'a>,
    world: &'a World,
    sub: &'a SubgoalFile,
    arm: &'a afford_kinematics::Arm,
    target: usize,
    goal: usize,
    events: Events,
    /// The held object's pose in the tool frame (from the close on).
    rel: Option<crate::chain::Iso>,
    /// Where it dropped (after the open).
    released: Option<&'a Piece>,
}

impl Phases<'_> {
    fn run(&self, report: &mut Report, k: usize) -> Result<(), String> {
        let (s, r) = (self.s, self.r);
        let scene = scene::obstacles(s, &self.world.pieces, self.target, self.goal);
        let target = Obstacle::piece(
            &self.world.pieces[self.target],
            s.safety.obstacle_margin,
            Role::Target,
        );
        let before: Vec<Obstacle> = scene.iter().cloned().chain([target]).collect();
        let after: Vec<Obstacle> = scene
            .iter()
            .cloned()
            .chain(
                self.released
                    .map(|p| Obstacle::piece(p, 0.0, Role::Released)),
            )
            .collect();
        let piece = &self.world.pieces[self.target];
        let held = self.rel.map(|rel| {
            body(
                r.model,
                &r.kin,
                format!("held {}", piece.name),
                r.tool_link(self.arm),
                piece.shape(),
                rel,
            )
        });
        let holding: Vec<Body> = r.bodies.iter().cloned().chain(held).collect();
        // A phase runs from an event's sample to the next (the last sample
        // when the sub-goal was cut short before it).
        let n = self.sub.trajectory.points.len();
        let (close, open) = (self.events.close, self.events.open);
        let c = close.map_or(n - 1, |e| e.sample);
        let o = open.map_or(n - 1, |e| e.sample);
        let plans = [
            Some((0, c, &before, &r.bodies)),
            close.map(|_| (c, o, &scene, &holding)),
            open.map(|_| (o, n - 1, &after, &r.bodies)),
        ];
        let rest = &self.world.q;
        let positions: Vec<&[f64]> = self
            .sub
            .trajectory
            .points
            .iter()
            .map(|p| p.positions.as_slice())
            .collect();
        let times: Vec<f64> = self
            .sub
            .trajectory
            .points
            .iter()
            .map(|p| p.time_from_start)
            .collect();
        let speeds: Vec<f64> = (self.arm.joint_indices.iter())
            .map(|&j| r.model.joints()[j].velocity)
            .collect();
        let phases: Vec<Phase> = plans
            .iter()
            .flatten()
            .map(|&(from, to, obstacles, bodies)| Phase {
                kin: &r.kin,
                bodies,
                obstacles,
                pairs: r.pairs(obstacles, bodies),
                rest,
                arm: &self.arm.joint_indices,
                speeds: &speeds,
                positions: &positions[from..=to],
                times: &times[from..=to],
                first_sample: from,
            })
            .collect();
        let needed: usize = phases.iter().map(Phase::configurations).sum();
        if needed > MAX_CONFIGURATIONS {
            return Err(format!(
                "the motion needs {needed} configurations to be checked at {} mm steps, more than the {MAX_CONFIGURATIONS} a sub-goal may need",
                dense::STEP * 1e3
            ));
        }
        let mut findings = Findings::new();
        phases.iter().for_each(|p| p.run(&mut findings));
        for (key, f) in &findings {
            report.push_with(key.0, Some(k), dense::describe(key, f), dense::data(key, f));
        }
        Ok(())
    }
}
