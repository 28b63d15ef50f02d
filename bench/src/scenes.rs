//! Seeded random tabletop scenes for the safety campaign (`afford bench
//! safety`), for both built-in robots with the camera calibrations of
//! robots/README.md: pieces of varied footprint and height (tall ones, and
//! some wider than the gripper opens), one to three goal boxes, up to two
//! hands, sensitive colours, and instructions of several clauses ("put the
//! red circle and all the blue squares in the back box, then the green
//! triangle in the left box"). The distributions are listed in
//! docs/decisions.md ("Safety campaign").
//!
//! Scene `k` of seed `s` depends on `(s, k)` alone: even `k` is a
//! `kuka_iiwa14` scene, odd `k` a `care_o_bot4` one.

use std::collections::BTreeMap;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;

use afford_planner::scenario::{PixelBox, Scenario};

/// The built-in robots the campaign alternates between, in scene order.
pub const ROBOTS: [&str; 2] = ["kuka_iiwa14", "care_o_bot4"];

const WIDTH: f64 = 640.0;
const HEIGHT: f64 = 480.0;
const COLOURS: [&str; 7] = ["red", "green", "blue", "yellow", "black", "white", "orange"];
const SHAPES: [&str; 4] = ["square", "circle", "triangle", "hexagon"];
const VERBS: [&str; 3] = ["put", "place", "move"];

/// A robot's tabletop set-up: calibration of the 640 × 480 overhead camera.
struct Setup {
    pixel_to_base: [[f64; 3]; 2],
    table_z: f64,
    /// Metres per pixel along u and v (the calibration's scale).
    metres_per_pixel: f64,
}

/// The set-ups of robots/README.md where every height 0.05–0.25 m above the
/// table is reachable top-down, in the order of [`ROBOTS`].
const SETUPS: [Setup; 2] = [
    Setup {
        pixel_to_base: [[0.0, -0.000625, 0.66], [-0.000625, 0.0, 0.20]],
        table_z: -0.40,
        metres_per_pixel: 0.000625,
    },
    Setup {
        pixel_to_base: [[0.0, -0.001, 0.88], [-0.001, 0.0, 0.32]],
        table_z: 0.75,
        metres_per_pixel: 0.001,
    },
];

/// Goal boxes: name and the region (fractions of the image, `[u0, u1]`,
/// `[v0, v1]`) its centre is drawn from. The image's bottom edge is the
/// table edge nearest the robot.
const GOAL_SLOTS: [(&str, [f64; 2], [f64; 2]); 3] = [
    ("left box", [0.05, 0.25], [0.45, 0.85]),
    ("right box", [0.75, 0.95], [0.45, 0.85]),
    ("back box", [0.35, 0.65], [0.05, 0.25]),
];

/// The robot of scene `index`.
pub fn robot_of(index: usize) -> &'static str {
    ROBOTS[index % ROBOTS.len()]
}

/// Scene `index` of the seeded series `seed`.
pub fn scene(seed: u64, index: usize) -> Scenario {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let robot = index % ROBOTS.len();
    let name = format!("safety-{seed}-{index}");
    let mut draw = || Layout::new(&SETUPS[robot]).build(&mut rng, ROBOTS[robot], &name);
    // A layout where none of the named pieces found room is drawn again
    // (rare: crowded tables of wide pieces); the bound keeps it finite.
    let first = draw();
    if first.1 {
        return first.0;
    }
    (0..20).map(|_| draw()).find(|s| s.1).unwrap_or(first).0
}

/// A (colour, shape) description the instruction names, and its pieces.
struct Group {
    colour: &'static str,
    shape: &'static str,
    pieces: usize,
    goal: usize,
}

/// The boxes placed so far, so new ones do not overlap them.
struct Layout<'a> {
    setup: &'a Setup,
    taken: Vec<PixelBox>,
}

impl<'a> Layout<'a> {
    fn new(setup: &'a Setup) -> Self {
        Self {
            setup,
            taken: Vec::new(),
        }
    }

    fn px(&self, metres: f64) -> f64 {
        metres / self.setup.metres_per_pixel
    }

    /// A box of `size` pixels whose centre is drawn from `region` (fractions
    /// of the image), inside the image and at least `clearance` metres from
    /// every box placed before; `None` after 40 tries.
    fn place(
        &mut self,
        rng: &mut ChaCha8Rng,
        [w, l]: [f64; 2],
        [u_range, v_range]: [[f64; 2]; 2],
        clearance: f64,
    ) -> Option<PixelBox> {
        let gap = self.px(clearance);
        let found = (0..40).find_map(|_| {
            let cu = rng.random_range(u_range[0]..u_range[1]) * WIDTH;
            let cv = rng.random_range(v_range[0]..v_range[1]) * HEIGHT;
            let bbox = PixelBox {
                u: (cu - w / 2.0).clamp(0.0, WIDTH - w),
                v: (cv - l / 2.0).clamp(0.0, HEIGHT - l),
                w,
                l,
            };
            let grown = bbox.grown(gap, gap);
            (!self.taken.iter().any(|t| overlaps(t, &grown))).then_some(bbox)
        })?;
        self.taken.push(found);
        Some(found)
    }

    /// The scene, and whether any piece the instruction names was placed.
    fn build(mut self, rng: &mut ChaCha8Rng, model: &str, name: &str) -> (Scenario, bool) {
        let goals = self.goals(rng);
        let groups = groups(rng, goals.len());
        let objects = self.pieces(rng, &groups);
        let hands = self.hands(rng);
        let start = self.start(rng);
        let sensitive: Vec<&str> = match rng.random_bool(0.35) {
            true => vec![COLOURS[rng.random_range(0..COLOURS.len())]],
            false => Vec::new(),
        };
        let placed: Vec<(&Group, usize)> = groups
            .iter()
            .map(|g| (g, count_of(&objects, g)))
            .filter(|&(_, n)| n > 0)
            .collect();
        let goal_names: Vec<&str> = goals
            .iter()
            .map(|g| g["name"].as_str().unwrap_or(""))
            .collect();
        let instruction = instruction(rng, &placed, &goal_names);
        let s = &self.setup;
        // Written as a scenario document (the format a user writes), so a
        // field the format gains later takes its documented default.
        let document = json!({
            "afford": afford_planner::scenario::FORMAT_VERSION,
            "name": name,
            "camera": {"width": WIDTH as u32, "height": HEIGHT as u32, "pixel_to_base": s.pixel_to_base, "table_z": s.table_z},
            "robot": {"model": model, "start": start},
            "objects": objects,
            "goals": goals,
            "hands": hands,
            "sensitive": sensitive,
            "instruction": instruction,
        });
        let scenario =
            serde_json::from_value(document).expect("a generated scene is a scenario document");
        (scenario, !placed.is_empty())
    }

    /// One to three goal boxes in distinct slots: inner sides 0.08–0.13 m,
    /// walls 0.05–0.12 m high.
    fn goals(&mut self, rng: &mut ChaCha8Rng) -> Vec<serde_json::Value> {
        let mut slots = GOAL_SLOTS.to_vec();
        slots.shuffle(rng);
        let count = rng.random_range(1..=slots.len());
        let mut goals = Vec::new();
        for (name, u, v) in slots.into_iter().take(count) {
            let size = [
                self.px(rng.random_range(0.08..0.13)),
                self.px(rng.random_range(0.08..0.13)),
            ];
            let height = rng.random_range(0.05..0.12);
            if let Some(b) = self.place(rng, size, [u, v], 0.02) {
                goals.push(json!({"name": name, "box": <[f64; 4]>::from(b), "height": height}));
            }
        }
        goals
    }

    /// The named groups' pieces, then 0–3 distractors of other descriptions,
    /// each anywhere on the table, 1–5 cm (uniform) from everything placed.
    fn pieces(&mut self, rng: &mut ChaCha8Rng, groups: &[Group]) -> Vec<serde_json::Value> {
        let mut kinds: Vec<(&str, &str)> = groups
            .iter()
            .flat_map(|g| std::iter::repeat_n((g.colour, g.shape), g.pieces))
            .collect();
        for _ in 0..rng.random_range(0..=3) {
            let kind = (
                COLOURS[rng.random_range(0..COLOURS.len())],
                SHAPES[rng.random_range(0..SHAPES.len())],
            );
            if !groups.iter().any(|g| (g.colour, g.shape) == kind) {
                kinds.push(kind);
            }
        }
        let mut numbers: BTreeMap<(&str, &str), usize> = BTreeMap::new();
        let mut objects = Vec::new();
        for (colour, shape) in kinds {
            let footprint = footprint(rng).map(|m| self.px(m));
            let height = piece_height(rng);
            let clearance = rng.random_range(0.01..0.05);
            let Some(b) = self.place(rng, footprint, [[0.0, 1.0], [0.0, 1.0]], clearance) else {
                continue;
            };
            let n = numbers.entry((colour, shape)).or_default();
            *n += 1;
            objects.push(json!({
                "name": format!("{colour}-{shape}-{n}"), "color": colour, "shape": shape,
                "box": <[f64; 4]>::from(b), "height": height,
            }));
        }
        objects
    }

    /// No hand (50 %), one (30 %) or two (20 %): palms 0.07–0.10 × 0.10–0.14
    /// m, 0.04–0.10 m above the table, not on top of anything placed.
    fn hands(&mut self, rng: &mut ChaCha8Rng) -> Vec<serde_json::Value> {
        let count = match rng.random_range(0..10) {
            0..5 => 0,
            5..8 => 1,
            _ => 2,
        };
        (0..count)
            .filter_map(|k| {
                let size = [
                    self.px(rng.random_range(0.07..0.10)),
                    self.px(rng.random_range(0.10..0.14)),
                ];
                let height = rng.random_range(0.04..0.10);
                let b = self.place(rng, size, [[0.0, 1.0], [0.0, 1.0]], 0.0)?;
                Some(json!({"name": format!("hand-{}", k + 1), "box": <[f64; 4]>::from(b), "height": height}))
            })
            .collect()
    }

    /// The gripper's start pixel: over the near part of the table (the
    /// bottom 15 % of the image), off every box when one of 40 draws is.
    fn start(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
        let mut draw = || {
            [
                rng.random_range(0.1..0.9) * WIDTH,
                rng.random_range(0.85..0.99) * HEIGHT,
            ]
        };
        let first = draw();
        (0..40)
            .map(|_| draw())
            .find(|&p| !self.taken.iter().any(|b| b.contains(p)))
            .unwrap_or(first)
    }
}

/// One to three distinct (colour, shape) groups of 1 (40 %), 2 (35 %) or 3
/// (25 %) pieces, each sent to one of `goals` goals.
fn groups(rng: &mut ChaCha8Rng, goals: usize) -> Vec<Group> {
    let mut kinds: Vec<(&'static str, &'static str)> = COLOURS
        .iter()
        .flat_map(|&c| SHAPES.iter().map(move |&s| (c, s)))
        .collect();
    kinds.shuffle(rng);
    let count = rng.random_range(1..=3);
    kinds
        .into_iter()
        .take(count)
        .map(|(colour, shape)| Group {
            colour,
            shape,
            pieces: match rng.random_range(0..20) {
                0..8 => 1,
                8..15 => 2,
                _ => 3,
            },
            goal: rng.random_range(0..goals.max(1)),
        })
        .collect()
}

/// A piece's footprint `[w, l]`, metres: 80 % compact (0.025–0.05 m a
/// side, the other side within ±15 %), 10 % long (one side 0.07–0.13 m),
/// 10 % wide on both sides (0.07–0.13 m: wider than either gripper opens).
fn footprint(rng: &mut ChaCha8Rng) -> [f64; 2] {
    match rng.random_range(0..10) {
        0..8 => {
            let side = rng.random_range(0.025..0.05);
            [side, side * rng.random_range(0.85..1.15)]
        }
        8 => {
            let mut sides = [rng.random_range(0.07..0.13), rng.random_range(0.025..0.05)];
            sides.shuffle(rng);
            sides
        }
        _ => [rng.random_range(0.07..0.13), rng.random_range(0.07..0.13)],
    }
}

/// A piece's height, metres: 70 % 0.02–0.06, 20 % 0.06–0.12, 10 % tall
/// 0.12–0.20.
fn piece_height(rng: &mut ChaCha8Rng) -> f64 {
    match rng.random_range(0..10) {
        0..7 => rng.random_range(0.02..0.06),
        7..9 => rng.random_range(0.06..0.12),
        _ => rng.random_range(0.12..0.20),
    }
}

fn count_of(objects: &[serde_json::Value], g: &Group) -> usize {
    objects
        .iter()
        .filter(|o| o["color"] == g.colour && o["shape"] == g.shape)
        .count()
}

/// The spoken instruction: one phrase per group ("the red circle", "all the
/// blue squares", "the blue squares", "two blue squares"), consecutive
/// phrases with the same goal joined by "and", clauses by ", then".
fn instruction(rng: &mut ChaCha8Rng, groups: &[(&Group, usize)], goals: &[&str]) -> String {
    let mut clauses: Vec<(usize, Vec<String>)> = Vec::new();
    for &(g, placed) in groups {
        let (c, s) = (g.colour, g.shape);
        let phrase = match (placed, rng.random_range(0..3)) {
            (1, _) => format!("the {c} {s}"),
            (_, 0) => format!("all the {c} {s}s"),
            (_, 1) => format!("the {c} {s}s"),
            _ => format!("two {c} {s}s"),
        };
        match clauses.last_mut() {
            Some((goal, phrases)) if *goal == g.goal => phrases.push(phrase),
            _ => clauses.push((g.goal, vec![phrase])),
        }
    }
    let verb = VERBS[rng.random_range(0..VERBS.len())];
    let text: Vec<String> = clauses
        .iter()
        .map(|(goal, phrases)| {
            let goal = goals.get(*goal).copied().unwrap_or("box");
            format!("{} in the {goal}", phrases.join(" and "))
        })
        .collect();
    format!("{verb} {}", text.join(", then "))
}

fn overlaps(a: &PixelBox, b: &PixelBox) -> bool {
    a.u < b.u + b.w && b.u < a.u + a.w && a.v < b.v + b.l && b.v < a.v + a.l
}
