//! `afford bench routes`: how long the planned tool routes are against the
//! shortest any-angle path around the safety perimeters, on the safety
//! campaign's generated scenes ([`super::scenes`]).
//!
//! Per planned sub-goal (every scene planned up to the `joints` stage, so
//! collision replanning is included):
//! - planned length: the tool's horizontal path in metres, from where the
//!   gripper is when the sub-goal starts (the scenario's `robot.start` for
//!   the first, the previous sub-goal's `release_px` after that) through
//!   every tool waypoint (travel, over the target, carry, over the resting
//!   spot; the vertical moves add nothing);
//! - shortest: the [`super::visibility`] oracle's shortest path from that
//!   start to the target's centre plus from there to the resting spot
//!   (`release_px`), around the perimeters of the scene as it is when the
//!   sub-goal starts (earlier pieces moved): other objects grown by
//!   `obstacle_margin` (`sensitive_margin` when sensitive; pieces resting in
//!   the sub-goal's goal are part of it), other goals by `obstacle_margin`,
//!   hands by `hand_margin`, each grown again by half the target's box (the
//!   footprint the planner keeps off them); the obstacles connected to one
//!   under the gripper are left out, as the grid clears them
//!   ([`super::visibility::Field::escaping`]).
//!
//! Sub-goals for which the oracle finds no path (or that have no waypoints)
//! are counted as `unmeasured`.
//!
//! The ratio is planned / shortest per sub-goal; the report gives the mean
//! and the largest over every planned sub-goal of every scene, the ten
//! largest and the ten smallest to look at, and how many are below 1 (a
//! route shorter than the oracle's passes where the oracle has a
//! perimeter).

use serde::Serialize;

use super::scenes;
use super::visibility::{Field, Rect};
use afford_planner::plan::{PlanOptions, Stage, SubgoalPlan};
use afford_planner::scenario::{PixelBox, Scenario};

/// One planned sub-goal's route against the oracle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RouteRatio {
    pub scene: usize,
    pub subgoal: usize,
    /// Planned horizontal tool path, metres.
    pub planned_m: f64,
    /// The oracle's shortest path, metres.
    pub shortest_m: f64,
    pub ratio: f64,
}

/// What `afford bench routes --json` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoutesReport {
    pub seed: u64,
    pub scenes: usize,
    /// Planned sub-goals measured.
    pub subgoals: usize,
    /// Planned sub-goals the oracle found no path for.
    pub unmeasured: usize,
    pub mean_path_over_shortest: f64,
    pub max_path_over_shortest: f64,
    /// Sum of planned lengths over sum of shortest lengths, metres / metres.
    pub total_path_over_shortest: f64,
    /// The sub-goal with the largest ratio (none when nothing planned).
    pub worst: Option<RouteRatio>,
    /// The [`LISTED`] sub-goals with the largest ratios, largest first
    /// (ties by scene and sub-goal), to look at.
    pub worst_subgoals: Vec<RouteRatio>,
    /// Sub-goals whose route is shorter than the oracle's (ratio below
    /// 1 − 1e-6): each passes where the oracle has a perimeter.
    pub below_oracle: usize,
    /// The [`LISTED`] sub-goals with the smallest ratios, smallest first.
    pub lowest_subgoals: Vec<RouteRatio>,
}

/// How many sub-goals [`RoutesReport::worst_subgoals`] and
/// [`RoutesReport::lowest_subgoals`] list.
pub const LISTED: usize = 10;

impl RoutesReport {
    /// Summarises the measured scenes `measured` (of `scenes` scenes of the
    /// series `seed`).
    pub fn of(seed: u64, scenes: usize, measured: &[SceneRoutes]) -> Self {
        let ratios: Vec<RouteRatio> = measured.iter().flat_map(|m| m.ratios.clone()).collect();
        let sum = |f: fn(&RouteRatio) -> f64| ratios.iter().map(f).sum::<f64>();
        let ranked = |largest_first: bool| {
            let mut listed = ratios.clone();
            listed.sort_by(|a, b| {
                let order = a.ratio.total_cmp(&b.ratio);
                (if largest_first {
                    order.reverse()
                } else {
                    order
                })
                .then(a.scene.cmp(&b.scene))
                .then(a.subgoal.cmp(&b.subgoal))
            });
            listed.truncate(LISTED);
            listed
        };
        let worst_subgoals = ranked(true);
        let worst = worst_subgoals.first().cloned();
        Self {
            seed,
            scenes,
            subgoals: ratios.len(),
            unmeasured: measured.iter().map(|m| m.unmeasured).sum(),
            mean_path_over_shortest: super::mean(
                &ratios.iter().map(|r| r.ratio).collect::<Vec<_>>(),
            ),
            max_path_over_shortest: worst.as_ref().map_or(0.0, |w| w.ratio),
            total_path_over_shortest: match sum(|r| r.shortest_m) {
                s if s > 0.0 => sum(|r| r.planned_m) / s,
                _ => 0.0,
            },
            worst,
            worst_subgoals,
            below_oracle: ratios.iter().filter(|r| r.ratio < 1.0 - 1e-6).count(),
            lowest_subgoals: ranked(false),
        }
    }
}

/// One scene's measured sub-goals.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneRoutes {
    pub ratios: Vec<RouteRatio>,
    /// Planned sub-goals the oracle found no path for.
    pub unmeasured: usize,
}

/// Plans scene `index` of the series `seed` up to the `joints` stage and
/// measures every planned sub-goal (none when the scene is refused).
pub fn run_scene(seed: u64, index: usize) -> SceneRoutes {
    let mut measured = run_scenario(&scenes::scene(seed, index));
    for r in &mut measured.ratios {
        r.scene = index;
    }
    measured
}

/// Plans `scenario` up to the `joints` stage and measures every planned
/// sub-goal (none when it is refused); `scene` is 0 in the ratios.
pub fn run_scenario(scenario: &Scenario) -> SceneRoutes {
    let options = PlanOptions {
        until: Stage::Joints,
        ..PlanOptions::default()
    };
    let Ok(plan) = afford_planner::plan::plan(scenario, &options) else {
        return SceneRoutes::default();
    };
    let mut scene = scenario.clone();
    let mut start = scenario.robot.start.unwrap_or_default();
    let mut out = SceneRoutes::default();
    for (k, done) in plan.subgoals.iter().enumerate() {
        match measure(&scene, start, done) {
            Some(ratio) => out.ratios.push(RouteRatio {
                subgoal: k,
                ..ratio
            }),
            None => out.unmeasured += 1,
        }
        // The scene as the next sub-goal sees it: the piece on its spot.
        if let Some(i) = scene.object_index(&done.object) {
            scene.objects[i].bbox = scene.objects[i].bbox.centred_at(done.release_px);
        }
        start = done.release_px;
    }
    out
}

/// One sub-goal's planned length against the oracle's, starting at pixel
/// `start` in `scene`; `None` without waypoints or without an oracle path.
fn measure(scene: &Scenario, start: [f64; 2], done: &SubgoalPlan) -> Option<RouteRatio> {
    let waypoints = &done.waypoints.as_ref()?.waypoints;
    let object = scene.object_index(&done.object)?;
    let goal = scene.goal_index(&done.goal)?;
    let planar = |p: [f64; 3]| [p[0], p[1]];
    let start_m = scene.pixel_to_base(start);
    let mut planned_m = 0.0;
    let mut last = start_m;
    for w in waypoints {
        let p = planar(w.position);
        planned_m += (p[0] - last[0]).hypot(p[1] - last[1]);
        last = p;
    }
    let field = field(scene, object, goal).escaping(start);
    let target = scene.objects[object].bbox.centre();
    let shortest_m = field.shortest(start, target)? + field.shortest(target, done.release_px)?;
    Some(RouteRatio {
        scene: 0,
        subgoal: 0,
        planned_m,
        shortest_m,
        ratio: planned_m / shortest_m.max(1e-9),
    })
}

/// The oracle's obstacles for moving `object` into `goal` (see the module
/// docs), in the scene's image and metric.
fn field(scene: &Scenario, object: usize, goal: usize) -> Field {
    let [mu, mv] = scene.metres_per_pixel();
    let target = scene.objects[object].bbox;
    let grow = |b: PixelBox, margin: f64, escapable: bool| Rect {
        lo: [
            b.u - margin / mu - target.w / 2.0,
            b.v - margin / mv - target.l / 2.0,
        ],
        hi: [
            b.u + b.w + margin / mu + target.w / 2.0,
            b.v + b.l + margin / mv + target.l / 2.0,
        ],
        escapable,
    };
    let safety = &scene.safety;
    let in_goal = |b: &PixelBox| scene.goals[goal].bbox.contains(b.centre());
    let objects = scene
        .objects
        .iter()
        .enumerate()
        .filter(|&(i, o)| i != object && !in_goal(&o.bbox))
        .map(|(_, o)| {
            let margin = match scene.is_sensitive(o) {
                true => safety.sensitive_margin,
                false => safety.obstacle_margin,
            };
            grow(o.bbox, margin, true)
        });
    let goals = scene
        .goals
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != goal)
        .map(|(_, g)| grow(g.bbox, safety.obstacle_margin, true));
    let hands = scene
        .hands
        .iter()
        .map(|h| grow(h.bbox, safety.hand_margin, false));
    let m = &scene.camera.pixel_to_base;
    Field {
        obstacles: objects.chain(goals).chain(hands).collect(),
        image: [
            f64::from(scene.camera.width),
            f64::from(scene.camera.height),
        ],
        metres: [[m[0][0], m[0][1]], [m[1][0], m[1][1]]],
    }
}
