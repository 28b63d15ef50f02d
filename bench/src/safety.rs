//! `afford bench safety`: the safety campaign. Plans every scene of a seeded
//! series ([`super::scenes`], both built-in robots) with the default
//! options, counts fully planned, partly planned and refused scenes and the
//! refusals by kind ([`super::refusal`]), and re-checks every emitted plan
//! with a checker passed in as a function (the facade passes afford-check's;
//! tests pass their own). Counts are per robot and in total.
//!
//! Next to the checker's classes the runner keeps two structural counts that
//! need no checker ([`super::structural`]), and gives every refused
//! sub-goal to the independent feasibility probe ([`super::free_poses`]):
//! per refusal kind, how many refusals had free poses.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use afford_kinematics::RobotModel;
use serde::Serialize;

use super::free_poses::{FreePoseCount, FreePoseCounts, probe_refusals};
use super::planning_time::{PlanningTimes, planning_times};
use super::refusal::{REFUSAL_KINDS, error_refusals};
use super::scenes;
pub use super::structural::{CONTINUITY_TOLERANCE, POSITION_TOLERANCE, Structural, structural};
use afford_planner::error::PlanError;
use afford_planner::plan::{Plan, PlanOptions};
use afford_planner::scenario::Scenario;

/// Every violation class an independent checker reports (CONTRACTS.md,
/// afford-check `ViolationClass`), listed in every report with 0 where none.
pub const VIOLATION_CLASSES: [&str; 16] = [
    "penetration",
    "margin",
    "self_collision",
    "position",
    "velocity",
    "acceleration",
    "jerk",
    "continuity",
    "start",
    "rest",
    "gripper_events",
    "tool_speed",
    "target_touched",
    "placement",
    "gripper_opening",
    "format",
];

/// Campaign size and seed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SafetyConfig {
    pub scenarios: usize,
    pub seed: u64,
}

impl Default for SafetyConfig {
    fn default() -> Self {
        Self {
            scenarios: 100,
            seed: 1,
        }
    }
}

/// One violation a checker found in a plan.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// One of [`VIOLATION_CLASSES`] (snake_case).
    pub class: String,
    /// The sub-goal whose trajectory it is in; `None` for the plan as a whole.
    pub subgoal: Option<usize>,
    pub message: String,
}

/// How a scene ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Every sub-goal planned.
    Planned,
    /// Some sub-goals planned, some refused.
    PartlyPlanned,
    /// No sub-goal planned.
    Refused,
}

/// The result of one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneOutcome {
    pub index: usize,
    pub robot: &'static str,
    pub outcome: Outcome,
    /// Sub-goal trajectories emitted (and checked).
    pub trajectories: usize,
    /// One entry per refused sub-goal: (kind, reason).
    pub refusals: Vec<(&'static str, String)>,
    /// The probe's verdict per entry of `refusals`: free poses or not;
    /// `None` when not probed.
    pub free_poses: Vec<Option<bool>>,
    /// Why the probe could not run, when it could not.
    pub probe_error: Option<String>,
    pub findings: Vec<Finding>,
    pub structural: Structural,
    /// Wall seconds per sub-goal (the planner's own clock).
    pub subgoal_s: Vec<f64>,
    /// Wall seconds of the whole `plan` call.
    pub scene_s: f64,
}

/// Counts over a set of scenes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tally {
    pub scenarios: usize,
    pub planned: usize,
    pub partly_planned: usize,
    pub refused: usize,
    /// Sub-goal trajectories emitted and re-checked.
    pub trajectories: usize,
    /// Per class, the trajectories (or plans, for findings on no sub-goal)
    /// with at least one violation of that class.
    pub violations: BTreeMap<String, usize>,
    /// Refused sub-goals per kind.
    pub refusals: BTreeMap<String, usize>,
    /// Per kind, the refusals and those the probe found free poses for.
    pub refusals_with_free_poses: FreePoseCounts,
    pub structural: Structural,
}

impl Default for Tally {
    fn default() -> Self {
        let zeros = |keys: &[&str]| keys.iter().map(|k| (k.to_string(), 0)).collect();
        Self {
            scenarios: 0,
            planned: 0,
            partly_planned: 0,
            refused: 0,
            trajectories: 0,
            violations: zeros(&VIOLATION_CLASSES),
            refusals: zeros(&REFUSAL_KINDS),
            refusals_with_free_poses: (REFUSAL_KINDS.iter())
                .map(|k| (k.to_string(), FreePoseCount::default()))
                .collect(),
            structural: Structural::default(),
        }
    }
}

impl Tally {
    fn add(&mut self, s: &SceneOutcome) {
        self.scenarios += 1;
        match s.outcome {
            Outcome::Planned => self.planned += 1,
            Outcome::PartlyPlanned => self.partly_planned += 1,
            Outcome::Refused => self.refused += 1,
        }
        self.trajectories += s.trajectories;
        let mut seen: Vec<(&str, Option<usize>)> = s
            .findings
            .iter()
            .map(|f| (f.class.as_str(), f.subgoal))
            .collect();
        seen.sort();
        seen.dedup();
        for (class, _) in seen {
            *self.violations.entry(class.to_string()).or_default() += 1;
        }
        for (k, (kind, _)) in s.refusals.iter().enumerate() {
            *self.refusals.entry(kind.to_string()).or_default() += 1;
            let free = s.free_poses.get(k).copied().flatten();
            let counts = self.refusals_with_free_poses.entry(kind.to_string());
            counts.or_default().add(free);
        }
        self.structural.add(&s.structural);
    }

    /// Trajectories with a violation, over every class.
    pub fn violating(&self) -> usize {
        self.violations.values().sum()
    }
}

/// How many scenes [`SafetyReport::free_pose_scenes`] names per kind.
pub const FREE_POSE_SCENES: usize = 50;

/// The campaign's counts: in total (flattened at the top level of the JSON)
/// and per robot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SafetyReport {
    pub seed: u64,
    #[serde(flatten)]
    pub total: Tally,
    pub robots: BTreeMap<String, Tally>,
    /// Wall-clock planning times per robot and in `"total"` (the only
    /// figures that differ from run to run).
    pub planning_time: BTreeMap<String, PlanningTimes>,
    /// Per refusal kind, the scenes (indices, ascending, the first
    /// [`FREE_POSE_SCENES`]) with a refusal of that kind the probe found
    /// free poses for: where to look for a false refusal.
    pub free_pose_scenes: BTreeMap<String, Vec<usize>>,
    /// The first message of each violation class and refusal kind, with its
    /// scene ("scene 17 (care_o_bot4), sub-goal 1: …"), for people; not in
    /// the JSON.
    #[serde(skip)]
    pub examples: BTreeMap<String, String>,
}

impl SafetyReport {
    /// The report of `outcomes`, taken in scene order.
    pub fn of(seed: u64, outcomes: &[SceneOutcome]) -> Self {
        let mut report = Self {
            seed,
            total: Tally::default(),
            robots: scenes::ROBOTS
                .iter()
                .map(|r| (r.to_string(), Tally::default()))
                .collect(),
            examples: BTreeMap::new(),
            free_pose_scenes: BTreeMap::new(),
            planning_time: planning_times(
                outcomes
                    .iter()
                    .map(|s| (s.index, s.robot, s.subgoal_s.as_slice(), s.scene_s)),
            ),
        };
        for s in outcomes {
            report.total.add(s);
            report.robots.entry(s.robot.to_string()).or_default().add(s);
            let at = |sub: Option<usize>| match sub {
                Some(k) => format!("scene {} ({}), sub-goal {k}", s.index, s.robot),
                None => format!("scene {} ({})", s.index, s.robot),
            };
            for f in &s.findings {
                let text = format!("{}: {}", at(f.subgoal), f.message);
                report.examples.entry(f.class.clone()).or_insert(text);
            }
            for (k, (kind, reason)) in s.refusals.iter().enumerate() {
                let text = format!("{}: {reason}", at(None));
                if s.free_poses.get(k) == Some(&Some(true)) {
                    let scenes = report.free_pose_scenes.entry(kind.to_string()).or_default();
                    if scenes.len() < FREE_POSE_SCENES && scenes.last() != Some(&s.index) {
                        scenes.push(s.index);
                    }
                    let key = format!("{kind} with free poses");
                    report.examples.entry(key).or_insert(text.clone());
                }
                report.examples.entry(kind.to_string()).or_insert(text);
            }
            if let Some(e) = &s.probe_error {
                let text = format!("{}: {e}", at(None));
                report.examples.entry("probe".into()).or_insert(text);
            }
        }
        report
    }

    /// Planning time per robot (wall clock, s): sub-goals and scenes.
    fn time_table(&self) -> String {
        let mut out = String::from("planning time, s (median / p99 / max)\n");
        for (robot, t) in &self.planning_time {
            for (what, s) in [("sub-goal", &t.subgoal), ("scene", &t.scene)] {
                out.push_str(&format!(
                    "  {robot:<12} {what:<9} {:>8.3} {:>8.3} {:>8.3}  ({} measured)\n",
                    s.median_s, s.p99_s, s.max_s, s.count
                ));
            }
            let slowest: Vec<String> = t.slowest.iter().map(|s| s.scene.to_string()).collect();
            out.push_str(&format!(
                "  {robot:<12} slowest scenes: {}\n",
                slowest.join(", ")
            ));
        }
        out
    }

    /// The report as a table for people: one column per robot and the total.
    pub fn table(&self) -> String {
        let columns: Vec<(&str, &Tally)> = self
            .robots
            .iter()
            .map(|(r, t)| (r.as_str(), t))
            .chain(std::iter::once(("total", &self.total)))
            .collect();
        let mut out = format!("safety campaign, seed {}\n{:<44}", self.seed, "");
        for (name, _) in &columns {
            out.push_str(&format!(" {name:>12}"));
        }
        out.push('\n');
        let mut line = |label: String, value: &dyn Fn(&Tally) -> String| {
            out.push_str(&format!("{label:<44}"));
            for (_, t) in &columns {
                out.push_str(&format!(" {:>12}", value(t)));
            }
            out.push('\n');
        };
        line("scenes".into(), &|t| t.scenarios.to_string());
        line("  fully planned".into(), &|t| t.planned.to_string());
        line("  partly planned".into(), &|t| t.partly_planned.to_string());
        line("  refused".into(), &|t| t.refused.to_string());
        line("trajectories checked".into(), &|t| {
            t.trajectories.to_string()
        });
        line("trajectories with a violation, by class".into(), &|_| {
            String::new()
        });
        for class in self.total.violations.keys() {
            line(format!("  {class}"), &|t| count(&t.violations, class));
        }
        line("refused sub-goals, by kind".into(), &|_| String::new());
        for kind in self.total.refusals.keys() {
            line(format!("  {kind}"), &|t| count(&t.refusals, kind));
        }
        line(
            "  of them with free poses (probe) / refused".into(),
            &|_| String::new(),
        );
        let probed = self.total.refusals_with_free_poses.iter();
        for (kind, _) in probed.filter(|(_, c)| c.probed > 0) {
            line(format!("    {kind}"), &|t| {
                let counts = t.refusals_with_free_poses.get(kind);
                counts.copied().unwrap_or_default().cell()
            });
        }
        line("structural (no checker)".into(), &|_| String::new());
        line("  samples outside position limits".into(), &|t| {
            t.structural.samples_outside_position_limits.to_string()
        });
        line("  trajectories outside position limits".into(), &|t| {
            t.structural
                .trajectories_outside_position_limits
                .to_string()
        });
        line("  largest excess over a position limit".into(), &|t| {
            format!("{:.4}", t.structural.max_position_excess)
        });
        line("  trajectories not starting where robot was".into(), &|t| {
            t.structural
                .trajectories_not_starting_at_previous_end
                .to_string()
        });
        out.push_str(&self.time_table());
        if !self.examples.is_empty() {
            out.push_str("\nfirst of each:\n");
            for (key, text) in &self.examples {
                out.push_str(&format!("  {key}: {text}\n"));
            }
        }
        out
    }
}

fn count(map: &BTreeMap<String, usize>, key: &str) -> String {
    map.get(key).copied().unwrap_or(0).to_string()
}

/// The built-in robot models, loaded once for a campaign.
pub struct Robots(Vec<(&'static str, RobotModel)>);

impl Robots {
    /// Loads every robot of [`scenes::ROBOTS`].
    pub fn load() -> Result<Self, PlanError> {
        scenes::ROBOTS
            .iter()
            .map(|&name| {
                RobotModel::load(name, std::path::Path::new("."))
                    .map(|m| (name, m))
                    .map_err(|e| PlanError::Robot(e.to_string()))
            })
            .collect::<Result<_, _>>()
            .map(Self)
    }

    fn get(&self, name: &str) -> Option<&RobotModel> {
        self.0.iter().find(|(n, _)| *n == name).map(|(_, m)| m)
    }
}

/// Plans scene `index` of the series `seed` and re-checks what it emits
/// with `check` (scenario, robot model, plan → findings).
pub fn run_scene(
    robots: &Robots,
    seed: u64,
    index: usize,
    check: &(impl Fn(&Scenario, &RobotModel, &Plan) -> Vec<Finding> + ?Sized),
) -> SceneOutcome {
    let robot = scenes::robot_of(index);
    let scenario = scenes::scene(seed, index);
    let mut outcome = SceneOutcome {
        index,
        robot,
        outcome: Outcome::Refused,
        trajectories: 0,
        refusals: Vec::new(),
        free_poses: Vec::new(),
        probe_error: None,
        findings: Vec::new(),
        structural: Structural::default(),
        subgoal_s: Vec::new(),
        scene_s: 0.0,
    };
    let options = PlanOptions::default();
    let model = robots.get(robot);
    let started = Instant::now();
    let planned = afford_planner::plan::plan(&scenario, &options);
    outcome.scene_s = started.elapsed().as_secs_f64();
    let seconds = |times: &[Duration]| times.iter().map(Duration::as_secs_f64).collect();
    let plan = match planned {
        Ok(plan) => plan,
        Err(e) => {
            outcome.refusals = error_refusals(&e);
            outcome.free_poses = vec![None; outcome.refusals.len()];
            if let PlanError::Unsolvable {
                subgoal_times,
                unsolved,
                ..
            } = &e
            {
                outcome.subgoal_s = seconds(subgoal_times);
                if let Some(model) = model {
                    let probed = probe_refusals(model, &scenario, options.seed, &[], unsolved);
                    (outcome.free_poses, outcome.probe_error) = probed;
                }
            }
            return outcome;
        }
    };
    outcome.subgoal_s = seconds(&plan.timings.per_subgoal);
    outcome.outcome = match plan.unsolved.is_empty() {
        true => Outcome::Planned,
        false => Outcome::PartlyPlanned,
    };
    outcome.refusals = plan
        .unsolved
        .iter()
        .map(|u| {
            let text = format!("{} → {}: {}", u.object, u.goal, u.reason);
            (u.refusal.kind(), text)
        })
        .collect();
    outcome.trajectories = plan
        .subgoals
        .iter()
        .filter(|s| s.trajectory.is_some())
        .count();
    outcome.free_poses = vec![None; outcome.refusals.len()];
    if let Some(model) = model {
        outcome.findings = check(&scenario, model, &plan);
        outcome.structural = structural(model, &plan);
        let (subgoals, unsolved) = (&plan.subgoals, &plan.unsolved);
        let probed = probe_refusals(model, &scenario, options.seed, subgoals, unsolved);
        (outcome.free_poses, outcome.probe_error) = probed;
    }
    outcome
}

/// Runs the campaign scene by scene; `progress` is called with the number
/// of scenes done after each.
pub fn run_campaign(
    config: &SafetyConfig,
    mut progress: impl FnMut(usize),
    check: impl Fn(&Scenario, &RobotModel, &Plan) -> Vec<Finding>,
) -> Result<SafetyReport, PlanError> {
    let robots = Robots::load()?;
    let outcomes: Vec<SceneOutcome> = (0..config.scenarios)
        .map(|k| {
            let outcome = run_scene(&robots, config.seed, k, &check);
            progress(k + 1);
            outcome
        })
        .collect();
    Ok(SafetyReport::of(config.seed, &outcomes))
}

#[cfg(test)]
mod tests;
