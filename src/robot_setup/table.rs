//! The tabletop set-up `robots init` suggests: a 640 x 480 overhead camera
//! whose image is a table region the tool reaches pointing down, at grasp
//! and at carry height, collision-free. Image bottom edge nearest the robot,
//! image left = the robot's left (+y), the region centred on the x axis (as
//! the built-in robots' set-ups, robots/README.md).
//!
//! The search: the largest scale of [`SCALES`], then the highest table of
//! [`TABLE_Z`], then the nearest near edge of [`NEAR_EDGES`] for which every
//! point of a [`GRID`] x [`GRID`] grid over the image is reached at both
//! [`HEIGHTS`]. The first scale is the iiwa's, so the default scenario keeps
//! its size in metres.

use afford_kinematics::{CameraSetup, Vec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::reach::Reacher;

/// Metres per pixel tried, largest first (0.625 mm: the iiwa's set-up).
pub const SCALES: [f64; 4] = [0.000625, 0.0005, 0.000375, 0.00025];
/// Table heights in the base frame tried, highest first: the base on the
/// table top, then on a pedestal up to 0.4 m above it.
pub const TABLE_Z: [f64; 5] = [0.0, -0.1, -0.2, -0.3, -0.4];
/// Distances of the region's near edge from the base axis tried, m.
pub const NEAR_EDGES: [f64; 9] = [0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6];
/// Tool heights above the table checked: grasp and carry (the planner's
/// approach 0.20 lies between).
pub const HEIGHTS: [f64; 2] = [0.05, 0.25];
/// Grid points per image side.
pub const GRID: usize = 5;

/// The camera set-up for a region of scale `s` (m/px) whose near edge is
/// `near` from the base, at table height `z`.
pub fn camera(s: f64, near: f64, z: f64) -> CameraSetup {
    let (w, h) = (640u32, 480u32);
    let far = near + s * f64::from(h);
    let half = s * f64::from(w) / 2.0;
    CameraSetup {
        width: w,
        height: h,
        pixel_to_base: [[0.0, -s, round(far)], [-s, 0.0, round(half)]],
        table_z: z,
    }
}

fn round(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// The grid of table points (x, y) of `c`, corners first.
pub fn grid(c: &CameraSetup, n: usize) -> Vec<(f64, f64)> {
    let (w, h) = (f64::from(c.width), f64::from(c.height));
    let mut pixels: Vec<(f64, f64)> = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let f = |k: usize| k as f64 / (n - 1).max(1) as f64;
            pixels.push((f(i) * w, f(j) * h));
        }
    }
    let corner = |&(u, v): &(f64, f64)| !((u == 0.0 || u == w) && (v == 0.0 || v == h));
    pixels.sort_by_key(corner);
    pixels.into_iter().map(|(u, v)| c.point(u, v)).collect()
}

/// True when some arm reaches every grid point of `c` at every height.
fn covers(reacher: &Reacher, c: &CameraSetup, rng: &mut ChaCha8Rng) -> bool {
    grid(c, GRID).iter().all(|&(x, y)| {
        HEIGHTS.iter().all(|h| {
            let p = Vec3::new(x, y, c.table_z + h);
            (0..reacher.model.arms().len()).any(|a| reacher.reach(a, p, rng).is_some())
        })
    })
}

/// The suggested set-up (module docs), `None` when no candidate passes.
pub fn suggest(model: &afford_kinematics::RobotModel) -> Result<Option<CameraSetup>, String> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut reacher = Reacher::new(model, None)?;
    for s in SCALES {
        for z in TABLE_Z {
            for near in NEAR_EDGES {
                let c = camera(s, near, z);
                reacher.set_camera(Some(&c))?;
                if covers(&reacher, &c, &mut rng) {
                    return Ok(Some(c));
                }
            }
        }
    }
    Ok(None)
}
