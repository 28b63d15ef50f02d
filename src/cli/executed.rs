//! An executed run ([`Monitor::executed`]) through afford-check: each
//! executed sub-goal becomes a one-sub-goal plan file with the scene it
//! ran in, then goes through the independent check ([`check`]) and the
//! physical replay ([`replay`], rapier3d, [`afford_check::physics`]).
//! Used by `afford run` on its result and by `afford bench monitor` on
//! every perturbed execution; the planner never calls the checker (the
//! dependencies point one way), so the wiring lives here.
//!
//! The check's scene is the one [`ExecutedSubgoal::scene`] records: the
//! goals as believed when it ended, its object where the gripper took it
//! from, the other objects and the hands that stayed put from its start to
//! its end. The replay's scene changes as the believed scene did while the
//! sub-goal ran ([`ExecutedSubgoal::changes`]): a hand is there from when
//! it came until it left, a moved box or piece at its first place until it
//! moved and at its new one after, the sub-goal's own object always where
//! it was grasped. The robot starts where the earlier sub-goals left it. A
//! sub-goal cut short by an abort is checked and replayed as far as it
//! went (`cut_short`: its gripper events a prefix of close, open), since
//! its samples went to the robot too.

use afford_check::physics::check_physics_over_time;
use afford_check::{PlanFile, ViolationClass, check_plan, read_plan};
use afford_collision::replay::ReplayReport;
use afford_kinematics::RobotModel;
use afford_planner::JointState;
use afford_planner::monitor::{ExecutedSubgoal, Monitor};
use afford_planner::scenario::{RobotSpec, Scenario};
use serde::Serialize;

/// One executed sub-goal, ready for the checker.
pub struct ExecutedFile {
    /// Index in the executed timeline.
    pub index: usize,
    /// The scene it ran in, the robot's joints where it began.
    pub scene: Scenario,
    /// The sub-goal alone, from the whole robot's state where it began.
    pub file: PlanFile,
    /// The scene believed while it ran: `(t, scene)`, `t` from its start,
    /// the first at 0, its object where it was grasped in each.
    pub timeline: Vec<(f64, Scenario)>,
    /// Execution time when it began, s.
    pub start_time: f64,
}

/// Every executed sub-goal (ended or cut short), as a plan file with its scene.
/// `Err` names the sub-goal whose timeline the checker cannot read.
pub fn files(monitor: &Monitor, robot: &RobotModel) -> Result<Vec<ExecutedFile>, String> {
    let mut out = Vec::new();
    for (k, sub) in monitor.executed().iter().enumerate() {
        let Some(scene) = &sub.scene else {
            continue;
        };
        let start = whole_state(monitor, robot, k);
        let from_start = |s: &Scenario| Scenario {
            robot: RobotSpec {
                start: None,
                joints: Some(
                    start
                        .joint_names
                        .iter()
                        .cloned()
                        .zip(start.positions.iter().copied())
                        .collect(),
                ),
                ..s.robot.clone()
            },
            observations: Vec::new(),
            ..s.clone()
        };
        let mut scene = from_start(scene);
        keep_goal(&mut scene, sub);
        let grasped = scene.object_index(&sub.object).map(|i| &scene.objects[i]);
        let timeline = (sub.scene_at_start.iter().map(|s| (0.0, s)))
            .chain(sub.changes.iter().map(|(t, s)| (*t, s)))
            .map(|(t, s)| {
                let mut s = from_start(s);
                s.objects.retain(|o| o.name != sub.object);
                s.objects.extend(grasped.cloned());
                (t, s)
            })
            .collect();
        #[derive(Serialize)]
        struct One<'a> {
            start_state: &'a JointState,
            subgoals: [&'a ExecutedSubgoal; 1],
        }
        let text = serde_json::to_string(&One {
            start_state: &start,
            subgoals: [sub],
        })
        .map_err(|e| format!("executed sub-goal {k}: {e}"))?;
        let file = read_plan(&text).map_err(|e| format!("executed sub-goal {k}: {e}"))?;
        out.push(ExecutedFile {
            index: k,
            scene,
            file,
            timeline,
            start_time: sub.start_time,
        });
    }
    Ok(out)
}

/// A sub-goal cut short because its goal left the table ends in a scene
/// without that goal, which the checker cannot read the sub-goal against:
/// the goal is taken where it was last seen while the sub-goal ran (the
/// arm moved toward it there; its walls are obstacles either way).
fn keep_goal(scene: &mut Scenario, sub: &ExecutedSubgoal) {
    if scene.goal_index(&sub.goal).is_some() {
        return;
    }
    let seen = sub
        .scene_at_start
        .iter()
        .chain(sub.changes.iter().map(|(_, s)| s));
    let last = seen
        .rev()
        .find_map(|s| s.goal_index(&sub.goal).map(|g| s.goals[g].clone()));
    scene.goals.extend(last);
}

/// The independent check of every executed sub-goal: violations, one line
/// each, naming the sub-goal.
pub fn check(files: &[ExecutedFile], robot: &RobotModel) -> Vec<String> {
    files
        .iter()
        .flat_map(|f| {
            check_plan(&f.scene, robot, &f.file)
                .violations
                .into_iter()
                .map(move |v| format!("executed sub-goal {}: {v}", f.index))
        })
        .collect()
}

/// What the run did near people, measured by afford-check on the executed
/// samples: every hand the detector delivered against every body and the
/// held piece ([`afford_check::check_hands`]), every stop against the
/// stopping term ([`afford_check::stops`]).
#[derive(Debug, Default, Serialize)]
pub struct PeopleCheck {
    pub passed: bool,
    pub hand_contacts: Vec<String>,
    pub perimeter_entries: Vec<String>,
    pub stops: Vec<afford_check::Stop>,
    /// The largest stop travel over its stopping term (0: no stop).
    pub largest_stop_ratio: f64,
}

/// Checks every executed sub-goal against the hands the detector delivered
/// (`monitor.sightings()`, a dropout shorter than the scenario's hold time
/// bridged) and measures the stop of every verdict that brakes.
pub fn people(files: &[ExecutedFile], monitor: &Monitor, robot: &RobotModel) -> PeopleCheck {
    let Some(first) = files.first() else {
        return PeopleCheck {
            passed: true,
            ..PeopleCheck::default()
        };
    };
    let hold = first.scene.safety.detection.hand_hold_s;
    let present = afford_check::presence(monitor.sightings(), hold);
    let decided: Vec<f64> = (monitor.events().iter())
        .filter(|e| e.brakes)
        .map(|e| e.time)
        .collect();
    let mut hands = afford_check::HandReport::default();
    let mut stops = Vec::new();
    for f in files {
        let found = afford_check::check_hands(&f.scene, robot, &f.file, f.start_time, &present);
        let who = format!("executed sub-goal {}", f.index);
        hands
            .contacts
            .extend(found.contacts.iter().map(|m| format!("{who}: {m}")));
        (hands.perimeter_entries).extend(
            found
                .perimeter_entries
                .iter()
                .map(|m| format!("{who}: {m}")),
        );
        stops.extend(afford_check::stops(
            &f.scene,
            robot,
            &f.file,
            f.start_time,
            &decided,
        ));
    }
    let largest = stops
        .iter()
        .map(afford_check::Stop::ratio)
        .fold(0.0, f64::max);
    PeopleCheck {
        passed: hands.passed() && largest <= 1.0,
        hand_contacts: hands.contacts,
        perimeter_entries: hands.perimeter_entries,
        stops,
        largest_stop_ratio: largest,
    }
}

/// The physical replay of one executed sub-goal.
#[derive(Debug, Serialize)]
pub struct SubgoalReplay {
    /// Index in the executed timeline.
    pub subgoal: usize,
    pub object: String,
    pub passed: bool,
    /// The replay's findings, one sentence each (empty when it passed).
    pub failures: Vec<String>,
    /// The replay's full report (`None` when the sub-goal could not be
    /// turned into a replay; `failures` says why).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub report: Option<ReplayReport>,
}

/// What the physical replay of an executed run found.
#[derive(Debug, Serialize)]
pub struct RunReplay {
    /// Every replayed sub-goal passed.
    pub passed: bool,
    /// One entry per executed sub-goal (ended or cut short), in execution order.
    pub subgoals: Vec<SubgoalReplay>,
}

impl RunReplay {
    /// Each failure as `sub-goal k (object): finding`.
    pub fn failures(&self) -> Vec<String> {
        self.subgoals
            .iter()
            .flat_map(|s| {
                let who = format!("sub-goal {} ({})", s.subgoal, s.object);
                s.failures.iter().map(move |f| format!("{who}: {f}"))
            })
            .collect()
    }
}

/// Replays every executed sub-goal physically, each alone in its scene as
/// it changed while the sub-goal ran.
pub fn replay(files: &[ExecutedFile], robot: &RobotModel) -> RunReplay {
    let subgoals: Vec<SubgoalReplay> = files
        .iter()
        .map(|f| {
            let timeline: Vec<(f64, &Scenario)> = f.timeline.iter().map(|(t, s)| (*t, s)).collect();
            let (report, found) = check_physics_over_time(&timeline, robot, &f.file);
            let failures: Vec<String> = found
                .of(ViolationClass::Physics)
                .map(|v| v.message.clone())
                .collect();
            SubgoalReplay {
                subgoal: f.index,
                object: f.file.subgoals[0].object.clone(),
                passed: failures.is_empty(),
                failures,
                report,
            }
        })
        .collect();
    RunReplay {
        passed: subgoals.iter().all(|s| s.passed),
        subgoals,
    }
}

/// The whole robot's state when executed sub-goal `k` began: the start
/// state with every earlier sub-goal's arm where it ended.
fn whole_state(monitor: &Monitor, robot: &RobotModel, k: usize) -> JointState {
    let mut state = monitor.start_state().cloned().unwrap_or(JointState {
        joint_names: Vec::new(),
        positions: Vec::new(),
    });
    for sub in &monitor.executed()[..k] {
        if let (Ok(arm), Some(last)) = (robot.arm(&sub.arm), sub.trajectory.points.last()) {
            arm.insert(&mut state.positions, &last.positions);
        }
    }
    state
}
