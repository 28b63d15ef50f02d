//! The adversarial part of `afford bench monitor`: what a person does that
//! a stop must answer, on both robots. Scenes for the Care-O-bot
//! ([`scene_cob4`]; the KUKA's are [`super::monitor`]'s), and at moments
//! spread over the whole sub-goal (travel, carry, retreat) the timelines:
//!
//! | kind | relevant | built as |
//! |---|---|---|
//! | `tall_hand_ahead` | when the route passes within its perimeter | a hand 0.17 or 0.25 m tall on the tool's remaining route, where a stop can still keep out of its perimeter: the perimeter plus the stopping term of the tool's planned speed plus the hand's half width plus [`SLACK_M`] from the tool, its perimeter plus [`BODY_M`] from every link as it comes (not into the arms); withdrawn [`HOLD_FOR_S`] later |
//! | `flickering_hand_ahead` | likewise | the same hand seen every other 0.1 s frame for [`HOLD_FOR_S`] |
//! | `jitter` | no | every piece's box shifted ±1.5 px every 0.1 s for a second, below the detection tolerance |
//!
//! The placement is geometric (the plan's tool positions and planned
//! speeds), never a question to the monitor. Whether anything came too
//! near a hand is the re-check's ([`super::monitor::Recheck`]) to say.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use afford_planner::monitor::brake::stopping_term;
use afford_planner::monitor::track::Track;
use afford_planner::plan::SubgoalPlan;
use afford_planner::scenario::{
    Camera, FORMAT_VERSION, Goal, Hand, Object, Observation, PixelBox, RobotSpec, Safety, Scenario,
};

/// Room kept between where a stop may end and the hand's perimeter, m.
pub const SLACK_M: f64 = 0.03;
/// How long a hand stays, s.
pub const HOLD_FOR_S: f64 = 1.5;
/// Hand heights tried, m: a hand on the table, a fist, a forearm held up.
pub const HEIGHTS: [f64; 2] = [0.17, 0.25];
/// Moments of the adversarial kinds: fractions of the sub-goal's duration.
pub const SPREAD: [f64; 6] = [0.12, 0.27, 0.42, 0.57, 0.72, 0.87];

/// One perturbation: its kind, whether it is relevant (`None`: not
/// counted either way), the time it comes and the observations from then
/// on (`at` set), the first taken at once.
pub struct Case {
    pub kind: &'static str,
    pub relevant: Option<bool>,
    pub t: f64,
    pub timeline: Vec<Observation>,
}

/// A Care-O-bot scene: a blue square and a red square in reach of the
/// right arm, the box to the left, apart.
pub fn scene_cob4(rng: &mut ChaCha8Rng, k: usize) -> Scenario {
    let mut boxes: Vec<PixelBox> = vec![PixelBox {
        u: 20.0,
        v: 300.0,
        w: 120.0,
        l: 120.0,
    }];
    let mut place = |rng: &mut ChaCha8Rng| loop {
        let b = PixelBox {
            u: rng.random_range(200.0..580.0),
            v: rng.random_range(40.0..300.0),
            w: 40.0,
            l: 40.0,
        };
        if boxes.iter().all(|o| crate::monitor::apart(o, &b, 60.0)) {
            boxes.push(b);
            return b;
        }
    };
    let (blue, red) = (place(rng), place(rng));
    let square = |name: &str, color: &str, bbox| Object {
        name: name.into(),
        color: color.into(),
        shape: "square".into(),
        bbox,
        height: 0.03,
    };
    Scenario {
        afford: FORMAT_VERSION,
        name: Some(format!("bench-monitor-cob4-{k}")),
        camera: Camera {
            width: 640,
            height: 480,
            pixel_to_base: [[0.0, -0.001, 0.88], [-0.001, 0.0, 0.32]],
            table_z: 0.75,
        },
        robot: RobotSpec {
            model: "care_o_bot4".into(),
            start: Some([320.0, 460.0]),
            joints: None,
        },
        objects: vec![
            square("blue-square-1", "blue", blue),
            square("red-square-1", "red", red),
        ],
        goals: vec![Goal {
            name: "left box".into(),
            bbox: boxes[0],
            height: 0.10,
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

/// The adversarial cases of one planned sub-goal at fraction `moment` of
/// its duration. `links`: where the robot's links with colliders are at a
/// sample (base frame, m), to keep a hand off the robot's body.
pub fn cases(
    scene: &Scenario,
    sub: &SubgoalPlan,
    track: &Track,
    links: &dyn Fn(usize) -> Vec<[f64; 3]>,
    moment: f64,
    seed: u64,
) -> Vec<Case> {
    let motion = sub.trajectory.as_ref().expect("timed");
    let end = motion.points.last().map_or(0.0, |p| p.time_from_start);
    let t = moment * end;
    let sample = Track::sample_at(motion, t);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let height = HEIGHTS[rng.random_range(0..HEIGHTS.len())];
    let mut out = Vec::new();
    let ahead = hand_ahead(scene, track, sample, height)
        .filter(|(hand, _)| off_the_body(scene, hand, &links(sample)));
    if let Some((hand, relevant)) = ahead {
        let seen = |at: f64, hands: Vec<Hand>| Observation {
            at: Some(at),
            hands: Some(hands),
            ..Default::default()
        };
        out.push(Case {
            kind: "tall_hand_ahead",
            relevant: Some(relevant),
            t,
            timeline: vec![seen(t, vec![hand.clone()]), seen(t + HOLD_FOR_S, vec![])],
        });
        let frames = (HOLD_FOR_S / 0.1).round() as usize;
        let flicker = (0..=frames)
            .map(|f| {
                let shown = f % 2 == 0 && f < frames;
                seen(
                    t + 0.1 * f as f64,
                    if shown { vec![hand.clone()] } else { vec![] },
                )
            })
            .collect();
        out.push(Case {
            kind: "flickering_hand_ahead",
            relevant: Some(relevant),
            t,
            timeline: flicker,
        });
    }
    // Before the grasp only: a held or placed piece is seen where the
    // gripper or the box has it, not at its first box.
    if t + 1.0 < track.close.0 {
        out.push(Case {
            kind: "jitter",
            relevant: Some(false),
            t,
            timeline: jitter(scene, t, &mut rng),
        });
    }
    out
}

/// A hand of `height` on the tool's remaining route from `sample`, the
/// first route point far enough for a stop to keep out of its perimeter
/// (module docs), on free table (no piece or box under it); with whether
/// the route passes within its perimeter there.
fn hand_ahead(scene: &Scenario, track: &Track, sample: usize, height: f64) -> Option<(Hand, bool)> {
    let here = track.tool[sample];
    let half = 0.02;
    let margin = scene.safety.hand_margin;
    let speed = track.speed.get(sample).copied().unwrap_or(0.0);
    let needed = margin + stopping_term(&scene.safety.separation, speed) + half + SLACK_M;
    let [mu, mv] = scene.metres_per_pixel();
    let (w, l) = (2.0 * half / mu.abs(), 2.0 * half / mv.abs());
    track.tool[sample..].iter().find_map(|p| {
        let far = ((p[0] - here[0]).powi(2) + (p[1] - here[1]).powi(2)).sqrt() >= needed;
        if !far {
            return None;
        }
        let [u, v] = scene.base_to_pixel([p[0], p[1]]);
        let bbox = PixelBox {
            u: u - 0.5 * w,
            v: v - 0.5 * l,
            w,
            l,
        };
        let inside = bbox.u >= 0.0
            && bbox.v >= 0.0
            && bbox.u + w <= scene.camera.width as f64
            && bbox.v + l <= scene.camera.height as f64;
        let free = (scene.objects.iter().map(|o| o.bbox))
            .chain(scene.goals.iter().map(|g| g.bbox))
            .all(|o| crate::monitor::apart(&o, &bbox, 5.0));
        let relevant = p[2] - scene.camera.table_z < height + margin;
        (inside && free).then(|| {
            let hand = Hand {
                name: "hand-7".into(),
                bbox,
                height,
            };
            (hand, relevant)
        })
    })
}

/// The hand's centre lies, horizontally, its perimeter plus [`BODY_M`]
/// from every link (`links`, where they are as it comes): a person does
/// not put a hand into the robot's arms (a link hangs down from its frame,
/// so its height is not trusted).
fn off_the_body(scene: &Scenario, hand: &Hand, links: &[[f64; 3]]) -> bool {
    let b = hand.bbox;
    let c = scene.pixel_to_base([b.u + 0.5 * b.w, b.v + 0.5 * b.l]);
    let reach = scene.safety.hand_margin + BODY_M;
    links
        .iter()
        .all(|p| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() >= reach)
}

/// Room for a link's body around its frame's origin, m.
pub const BODY_M: f64 = 0.12;

/// Every piece's box shifted by ±1.5 px (alternating, a random direction
/// per piece) every 0.1 s for a second from `t`, then back.
fn jitter(scene: &Scenario, t: f64, rng: &mut ChaCha8Rng) -> Vec<Observation> {
    let dirs: Vec<[f64; 2]> = (scene.objects.iter())
        .map(|_| {
            let a: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            [1.5 * a.cos(), 1.5 * a.sin()]
        })
        .collect();
    (0..=10)
        .map(|f| {
            let sign = match f {
                10 => 0.0,
                _ if f % 2 == 0 => 1.0,
                _ => -1.0,
            };
            let objects = (scene.objects.iter().zip(&dirs))
                .map(|(o, d)| Object {
                    bbox: PixelBox {
                        u: o.bbox.u + sign * d[0],
                        v: o.bbox.v + sign * d[1],
                        ..o.bbox
                    },
                    ..o.clone()
                })
                .collect();
            Observation {
                at: Some(t + 0.1 * f as f64),
                objects: Some(objects),
                ..Default::default()
            }
        })
        .collect()
}
