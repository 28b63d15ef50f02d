//! The scenes and perturbations by construction of `afford bench monitor`
//! (the table in [`super`]'s docs): the KUKA's random scene, and for one
//! moment of its plan the goal moved, a hand or a blocker on the route, a
//! new piece, a piece moved away, a hand far away.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::ROBOT;
use crate::adversary::Case;
use afford_planner::monitor::route::REACH_M;
use afford_planner::monitor::separation::TOLERANCE;
use afford_planner::monitor::track::Track;
use afford_planner::plan::{Plan, SubgoalPlan};
use afford_planner::scenario::{
    Camera, FORMAT_VERSION, Goal, Hand, Object, Observation, PixelBox, RobotSpec, Safety, Scenario,
};
use afford_planner::timing::separation::nearest_hand_distance;
use afford_planner::timing::trajectory::hands;

/// arm reaches, apart.
/// A random scene: the square, the red square and the box in the band the
/// arm reaches, apart.
pub(super) fn scene(rng: &mut ChaCha8Rng, k: usize) -> Scenario {
    let mut boxes: Vec<PixelBox> = Vec::new();
    let mut place = |rng: &mut ChaCha8Rng, w: f64, l: f64| loop {
        let b = PixelBox {
            u: rng.random_range(160.0..480.0 - w),
            v: rng.random_range(180.0..380.0 - l),
            w,
            l,
        };
        if boxes.iter().all(|o| apart(o, &b, 30.0)) {
            boxes.push(b);
            return b;
        }
    };
    let goal = place(rng, 70.0, 70.0);
    let blue = place(rng, 20.0, 20.0);
    let red = place(rng, 20.0, 20.0);
    let square = |name: &str, color: &str, bbox| Object {
        name: name.into(),
        color: color.into(),
        shape: "square".into(),
        bbox,
        height: 0.03,
    };
    Scenario {
        afford: FORMAT_VERSION,
        name: Some(format!("bench-monitor-{k}")),
        camera: Camera {
            width: 640,
            height: 480,
            pixel_to_base: [[0.0, -0.002, 1.1], [-0.002, 0.0, 0.64]],
            table_z: -0.2,
        },
        robot: RobotSpec {
            model: ROBOT.into(),
            start: Some([320.0, 330.0]),
            joints: None,
        },
        objects: vec![
            square("blue-square-1", "blue", blue),
            square("red-square-1", "red", red),
        ],
        goals: vec![Goal {
            name: "left box".into(),
            bbox: goal,
            height: 0.08,
        }],
        hands: Vec::new(),
        sensitive: Vec::new(),
        safety: Safety::default(),
        instruction: "put all the blue squares in the left box".into(),
        pointing: None,
        learner: Default::default(),
        observations: Vec::new(),
    }
}

/// True when the boxes are more than `gap` px apart along u or v.
pub(crate) fn apart(a: &PixelBox, b: &PixelBox, gap: f64) -> bool {
    a.u + a.w + gap < b.u || b.u + b.w + gap < a.u || a.v + a.l + gap < b.v || b.v + b.l + gap < a.v
}

/// The plan's track of its one sub-goal.
pub(super) fn track_of(scene: &Scenario, sub: &SubgoalPlan) -> Track {
    let robot = afford_kinematics::RobotModel::builtin(&scene.robot.model).expect("built-in robot");
    let arm = robot
        .arm(sub.arm.as_deref().unwrap_or_default())
        .expect("planned arm");
    Track::new(sub, arm, scene)
}

/// The origins of the robot's links with colliders (base frame, m) at
/// sample `k` of the plan's one sub-goal, the other joints at the start.
pub(super) fn body_links(scene: &Scenario, plan: &Plan, k: usize) -> Vec<[f64; 3]> {
    let robot = afford_kinematics::RobotModel::builtin(&scene.robot.model).expect("built-in robot");
    let sub = &plan.subgoals[0];
    let (Some(start), Some(motion), Ok(arm)) = (
        plan.start_state.as_ref(),
        sub.trajectory.as_ref(),
        robot.arm(sub.arm.as_deref().unwrap_or_default()),
    ) else {
        return Vec::new();
    };
    let mut q = start.positions.clone();
    arm.insert(
        &mut q,
        &motion.points[k.min(motion.points.len() - 1)].positions,
    );
    let poses = robot.link_poses(&q).unwrap_or_default();
    (robot.links().iter().zip(&poses))
        .filter(|(l, _)| !l.colliders.is_empty())
        .map(|(_, p)| [p.translation.x, p.translation.y, p.translation.z])
        .collect()
}

/// The perturbations by construction at one moment of the plan (module
/// docs), each withdrawn a second later (its hands gone).
pub(super) fn perturbations(
    scene: &Scenario,
    plan: &Plan,
    moment: f64,
    rng: &mut ChaCha8Rng,
) -> Vec<Case> {
    let sub = &plan.subgoals[0];
    let motion = sub.trajectory.as_ref().expect("timed");
    let track = track_of(scene, sub);
    let open = track.open.0;
    let t = moment * open;
    let sample = Track::sample_at(motion, t);
    let ahead = Ahead::new(scene, sub, &track, sample);
    let mut cases: Vec<(&'static str, bool, Observation)> = Vec::new();
    let past: Vec<[f64; 2]> = track.tool[..=sample]
        .iter()
        .map(|p| scene.base_to_pixel([p[0], p[1]]))
        .collect();
    if let Some(goals) = goal_moved(scene, sub, &past) {
        cases.push((
            "goal_moved",
            true,
            Observation {
                goals: Some(goals),
                ..Default::default()
            },
        ));
    }
    if let Some(cell) = ahead.route_cell(scene) {
        let hand = Hand {
            name: "hand-9".into(),
            bbox: cell,
            height: 0.08,
        };
        cases.push((
            "hand_on_route",
            true,
            Observation {
                hands: Some(vec![hand]),
                ..Default::default()
            },
        ));
        let mut objects = scene.objects.clone();
        objects.push(Object {
            name: "blocker".into(),
            color: "green".into(),
            shape: "cube".into(),
            bbox: cell,
            height: 0.03,
        });
        cases.push((
            "blocker_on_route",
            true,
            Observation {
                objects: Some(objects),
                ..Default::default()
            },
        ));
    }
    if let Some(spot) = free_spot(scene, rng) {
        let mut objects = scene.objects.clone();
        objects.push(Object {
            name: "blue-square-9".into(),
            color: "blue".into(),
            shape: "square".into(),
            bbox: spot,
            height: 0.03,
        });
        cases.push((
            "new_piece",
            true,
            Observation {
                objects: Some(objects),
                ..Default::default()
            },
        ));
    }
    let red = scene.objects[1].bbox;
    if let Some(spot) = ahead.far_spot(scene, red, scene.safety.sensitive_margin, None, rng) {
        let mut objects = scene.objects.clone();
        objects[1].bbox = spot;
        cases.push((
            "piece_moved_away",
            false,
            Observation {
                objects: Some(objects),
                ..Default::default()
            },
        ));
    }
    let hand_box = PixelBox {
        u: 0.0,
        v: 0.0,
        w: 30.0,
        l: 30.0,
    };
    if let Some(spot) = ahead.far_spot(
        scene,
        hand_box,
        scene.safety.hand_margin,
        Some(&track.speed[sample..]),
        rng,
    ) {
        let hand = Hand {
            name: "hand-8".into(),
            bbox: spot,
            height: 0.08,
        };
        cases.push((
            "hand_far_away",
            false,
            Observation {
                hands: Some(vec![hand]),
                ..Default::default()
            },
        ));
    }
    let withdrawn = Observation {
        at: Some(t + 1.0),
        hands: Some(Vec::new()),
        ..Default::default()
    };
    cases
        .into_iter()
        .map(|(kind, relevant, first)| Case {
            kind,
            relevant: Some(relevant),
            t,
            timeline: vec![first, withdrawn.clone()],
        })
        .collect()
}

/// The goal shifted so the planned release footprint is outside it, and
/// [`REACH_M`] from every tool position so far (`past`, pixels): a person
/// does not put a box through the arm, nor where it already went (the
/// executed sub-goal is checked against the goal where it ends).
fn goal_moved(scene: &Scenario, sub: &SubgoalPlan, past: &[[f64; 2]]) -> Option<Vec<Goal>> {
    let g = scene.goals[0].bbox;
    let [mu, mv] = scene.metres_per_pixel();
    let footprint = scene.objects[0].bbox.centred_at(sub.release_px);
    let shifts = [
        (g.w + 10.0, 0.0),
        (-g.w - 10.0, 0.0),
        (0.0, g.l + 10.0),
        (0.0, -g.l - 10.0),
    ];
    shifts.into_iter().find_map(|(du, dv)| {
        let b = PixelBox {
            u: g.u + du,
            v: g.v + dv,
            ..g
        };
        let inside = b.u >= 0.0 && b.v >= 0.0 && b.u + b.w <= 640.0 && b.v + b.l <= 480.0;
        let clear = scene.objects.iter().all(|o| apart(&o.bbox, &b, 5.0));
        let reach = b.grown(REACH_M / mu, REACH_M / mv);
        let away = past.iter().all(|p| !reach.contains(*p));
        (inside && clear && away && apart(&footprint, &b, 0.0)).then(|| {
            vec![Goal {
                bbox: b,
                ..scene.goals[0].clone()
            }]
        })
    })
}

/// A spot for a 20 × 20 px piece apart from everything.
fn free_spot(scene: &Scenario, rng: &mut ChaCha8Rng) -> Option<PixelBox> {
    (0..200).find_map(|_| {
        let b = PixelBox {
            u: rng.random_range(160.0..460.0),
            v: rng.random_range(180.0..360.0),
            w: 20.0,
            l: 20.0,
        };
        let clear = scene
            .objects
            .iter()
            .map(|o| o.bbox)
            .chain(scene.goals.iter().map(|g| g.bbox));
        clear.clone().all(|o| apart(&o, &b, 10.0)).then_some(b)
    })
}

/// The plan ahead of one moment: the cells the policy still visits and the
/// remaining tool positions.
struct Ahead {
    /// The cell the policy is at.
    here: PixelBox,
    cells: Vec<PixelBox>,
    /// Remaining tool positions (base frame, m) and their pixels.
    tool: Vec<[f64; 3]>,
    pixels: Vec<[f64; 2]>,
}

impl Ahead {
    fn new(scene: &Scenario, sub: &SubgoalPlan, track: &Track, sample: usize) -> Self {
        let done = track.done[sample].min(sub.cells.len() - 1);
        let g = &sub.grid;
        let cell = |&[r, c]: &[usize; 2]| PixelBox {
            u: g.origin_px[0] + c as f64 * g.cell_px[0],
            v: g.origin_px[1] + r as f64 * g.cell_px[1],
            w: g.cell_px[0],
            l: g.cell_px[1],
        };
        let here = cell(&sub.cells[done]);
        let cells = sub.cells[done + 1..].iter().map(cell).collect();
        let tool = track.tool[sample..].to_vec();
        let pixels = tool
            .iter()
            .map(|p| scene.base_to_pixel([p[0], p[1]]))
            .collect();
        Self {
            here,
            cells,
            tool,
            pixels,
        }
    }

    /// A cell the policy still visits, at least three cells from the one
    /// under the tool (an obstacle painted next to the gripper is one it
    /// may leave over, [`afford_planner::grid`]), before the goal: the first such.
    /// Its painted region also stays a cell clear of the other pieces'
    /// (an obstacle region joined to one under the gripper is left over
    /// too), and the cell clear of the goal boxes (a blocker cannot stand
    /// in a box's wall).
    fn route_cell(&self, scene: &Scenario) -> Option<PixelBox> {
        let here = self.here;
        let n = self.cells.len();
        let [mu, mv] = scene.metres_per_pixel();
        let m = scene.safety.sensitive_margin;
        self.cells[..n.saturating_sub(2)].iter().copied().find(|c| {
            let (du, dv) = ((c.u - here.u) / c.w, (c.v - here.v) / c.l);
            let painted = c.grown(m / mu + c.w, m / mv + c.l);
            du.abs().max(dv.abs()) >= 2.5
                && scene.goals.iter().all(|g| apart(&g.bbox, c, 0.0))
                && scene
                    .objects
                    .iter()
                    .all(|o| apart(&o.bbox.grown(m / mu, m / mv), &painted, 0.0))
        })
    }

    /// A spot for `b`'s footprint with `margin` (m) that misses every cell
    /// still visited by a cell, lies [`REACH_M`] + margin from every
    /// remaining tool position, and — for a hand, `speeds` given — leaves
    /// every remaining sample's planned speed under the separation cap.
    fn far_spot(
        &self,
        scene: &Scenario,
        b: PixelBox,
        margin: f64,
        speeds: Option<&[f64]>,
        rng: &mut ChaCha8Rng,
    ) -> Option<PixelBox> {
        let [mu, mv] = scene.metres_per_pixel();
        let cell = self.cells.first().map_or(20.0, |c| c.w.max(c.l));
        let spots: Vec<PixelBox> = (0..16)
            .flat_map(|i| (0..12).map(move |j| (i, j)))
            .map(|(i, j)| PixelBox {
                u: 5.0 + i as f64 * 39.0,
                v: 5.0 + j as f64 * 39.0,
                ..b
            })
            .filter(|s| s.u + s.w <= 640.0 && s.v + s.l <= 480.0)
            .filter(|s| {
                let perimeter = s.grown(margin / mu + cell, margin / mv + cell);
                let reach = s.grown((REACH_M + margin) / mu, (REACH_M + margin) / mv);
                self.cells.iter().all(|c| apart(c, &perimeter, 0.0))
                    && self.pixels.iter().all(|&p| !reach.contains(p))
                    && scene
                        .objects
                        .iter()
                        .chain([])
                        .all(|o| apart(&o.bbox, s, 10.0))
                    && scene.goals.iter().all(|g| apart(&g.bbox, s, 10.0))
            })
            .filter(|s| speeds.is_none_or(|v| self.separated(scene, *s, v)))
            .collect();
        (!spots.is_empty()).then(|| spots[rng.random_range(0..spots.len())])
    }

    /// A hand at `s` leaves every remaining sample under the separation cap.
    fn separated(&self, scene: &Scenario, s: PixelBox, speeds: &[f64]) -> bool {
        let with = Scenario {
            hands: vec![Hand {
                name: "h".into(),
                bbox: s,
                height: 0.08,
            }],
            ..scene.clone()
        };
        let spheres = hands(&with);
        let rule = &scene.safety.separation;
        self.tool.iter().zip(speeds).all(|(p, &v)| {
            let cap = rule.tool_speed_cap(nearest_hand_distance(&spheres, *p));
            v <= cap * (1.0 + TOLERANCE)
        })
    }
}
