//! Seeded scene configurations like the paper's first experiment: each has its
//! own start, target, goal and obstacles, on grids from 10×10 to 40×40 cells;
//! some carry hands, sensitive objects and walls across the straight route.
//!
//! Scenes are full [`Scenario`]s (one object to move), so the benchmark runs
//! the same grid construction as `afford plan`. The synthetic camera maps one
//! target box to 4 cm, so the default margins span ½ cell (obstacles),
//! 1½ cells (sensitive) and 2½ cells (hands).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use afford_planner::cql::LearnerSettings;
use afford_planner::scenario::{
    Camera, FORMAT_VERSION, Goal, Hand, Object, PixelBox, RobotSpec, Safety, Scenario,
};

/// Side of one cell on the table, metres.
const CELL_METRES: f64 = 0.04;
const COLOURS: [&str; 5] = ["red", "green", "yellow", "black", "white"];
const SHAPES: [&str; 4] = ["square", "hexagon", "triangle", "circle"];

/// Scene number `index` of the seeded series `seed`, on a grid of 10 to 40
/// cells a side.
pub fn scene(seed: u64, index: usize) -> Scenario {
    let mut rng = scene_rng(seed, index);
    let size = [rng.random_range(10..=40), rng.random_range(10..=40)];
    layout(&mut rng, size, format!("bench-{seed}-{index}"))
}

/// Like [`scene`], with `cols` × `rows` cells.
pub fn scene_of_size(seed: u64, index: usize, cols: usize, rows: usize) -> Scenario {
    layout(
        &mut scene_rng(seed, index),
        [cols, rows],
        format!("bench-{seed}-{index}-{cols}x{rows}"),
    )
}

fn scene_rng(seed: u64, index: usize) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0xA24B_AED4_963E_E407))
}

fn layout(rng: &mut ChaCha8Rng, [m, n]: [usize; 2], name: String) -> Scenario {
    let (cw, cl) = (
        rng.random_range(24..=48) as f64,
        rng.random_range(24..=48) as f64,
    );
    let (width, height) = (m as f64 * cw, n as f64 * cl);
    let cell = |rng: &mut ChaCha8Rng| {
        [
            rng.random_range(0..m) as f64 * cw,
            rng.random_range(0..n) as f64 * cl,
        ]
    };
    let target = cell(rng);
    let goal_size = [
        rng.random_range(1..=3) as f64 * cw,
        rng.random_range(1..=3) as f64 * cl,
    ];
    let goal_at = [
        rng.random_range(0.0..width - goal_size[0]),
        rng.random_range(0.0..height - goal_size[1]),
    ];
    let start = cell(rng);
    let mut objects = vec![Object {
        name: "target".into(),
        color: "blue".into(),
        shape: "square".into(),
        bbox: PixelBox {
            u: target[0],
            v: target[1],
            w: cw,
            l: cl,
        },
        height: 0.03,
    }];
    let goal = PixelBox {
        u: goal_at[0],
        v: goal_at[1],
        w: goal_size[0],
        l: goal_size[1],
    };
    // Clutter, walls and hands are placed clear of the target and the goal
    // (grown by two cells), as a person laying out a task would.
    let keep_clear = [
        objects[0].bbox.grown(2.0 * cw, 2.0 * cl),
        goal.grown(2.0 * cw, 2.0 * cl),
    ];
    let place = |rng: &mut ChaCha8Rng, size: [f64; 2]| {
        (0..20)
            .map(|_| random_box(rng, size, [width, height]))
            .find(|b| !keep_clear.iter().any(|k| overlaps(k, b)))
    };
    let clutter = (m * n) as f64 * rng.random_range(0.01..0.04);
    for k in 0..clutter as usize {
        let size = [
            rng.random_range(0.4..1.5) * cw,
            rng.random_range(0.4..1.5) * cl,
        ];
        let Some(bbox) = place(rng, size) else {
            continue;
        };
        objects.push(Object {
            name: format!("obstacle-{k}"),
            color: COLOURS[rng.random_range(0..COLOURS.len())].into(),
            shape: SHAPES[rng.random_range(0..SHAPES.len())].into(),
            bbox,
            height: 0.03,
        });
    }
    if rng.random_bool(0.35) {
        let horizontal = rng.random_bool(0.5);
        let fraction = rng.random_range(0.4..0.8);
        let size = if horizontal {
            [width * fraction, 0.3 * cl]
        } else {
            [0.3 * cw, height * fraction]
        };
        if let Some(bbox) = place(rng, size) {
            objects.push(Object {
                name: "wall".into(),
                color: "white".into(),
                shape: "rectangle".into(),
                bbox,
                height: 0.05,
            });
        }
    }
    let hand_count = if rng.random_bool(0.3) {
        rng.random_range(1..=2)
    } else {
        0
    };
    let hands = (0..hand_count)
        .filter_map(|k| {
            let bbox = place(rng, [1.5 * cw, 2.0 * cl])?;
            Some(Hand {
                name: format!("hand-{k}"),
                bbox,
                height: 0.08,
            })
        })
        .collect();
    let sensitive = if rng.random_bool(0.3) {
        vec!["yellow".to_string()]
    } else {
        Vec::new()
    };
    let px_to_m = CELL_METRES / cw.max(cl);
    Scenario {
        afford: FORMAT_VERSION,
        name: Some(name),
        camera: Camera {
            width: width.ceil() as u32,
            height: height.ceil() as u32,
            pixel_to_base: [[0.0, -px_to_m, 0.8], [-px_to_m, 0.0, 0.4]],
            table_z: -0.2,
        },
        robot: RobotSpec {
            model: "kuka_iiwa14".into(),
            start: Some([start[0] + cw / 2.0, start[1] + cl / 2.0]),
            joints: None,
        },
        objects,
        goals: vec![Goal {
            name: "goal".into(),
            bbox: goal,
            height: 0.1,
        }],
        hands,
        sensitive,
        safety: Safety::default(),
        instruction: "put the target in the goal".into(),
        pointing: None,
        observations: Vec::new(),
        learner: LearnerSettings::default(),
    }
}

fn random_box(rng: &mut ChaCha8Rng, [w, l]: [f64; 2], [width, height]: [f64; 2]) -> PixelBox {
    PixelBox {
        u: rng.random_range(0.0..width - w),
        v: rng.random_range(0.0..height - l),
        w,
        l,
    }
}

fn overlaps(a: &PixelBox, b: &PixelBox) -> bool {
    a.u < b.u + b.w && b.u < a.u + a.w && a.v < b.v + b.l && b.v < a.v + a.l
}
