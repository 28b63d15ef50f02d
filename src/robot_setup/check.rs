//! `afford robots check`: the figures a robot description is judged by.
//!
//! - reach: the fraction of a grid of tool-down poses over the table region
//!   (the description's `camera:`, else the one `robots init` would
//!   suggest) at grasp and carry height that IK reaches collision-free;
//! - self-collision at home and at each arm's park posture;
//! - IK success on random reachable poses (FK of random in-limit
//!   configurations; the `afford bench ik` criterion);
//! - coverage of every mesh by the collision model (`coverage`).
//!
//! It fails (`failures`) when home or a park posture collides or a mesh
//! lies farther than [`COVERAGE_TOLERANCE_M`] outside its link's model.

use std::path::Path;

use afford_kinematics::{
    CameraSetup, IkSettings, IkTarget, PackagePaths, RobotModel, Vec3, ik_bench_success,
    random_reachable_poses,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

pub use super::coverage::COVERAGE_TOLERANCE_M;
use super::coverage::{MeshCoverage, coverage};
use super::reach::Reacher;
use super::table;

/// What to measure.
#[derive(Debug, Clone)]
pub struct CheckOptions {
    /// Random reachable poses per arm for the IK rate.
    pub poses: usize,
    /// Grid points per image side for reach.
    pub grid: usize,
    pub seed: u64,
    pub packages: PackagePaths,
}

impl Default for CheckOptions {
    fn default() -> Self {
        Self {
            poses: 1000,
            grid: 9,
            seed: 1,
            packages: PackagePaths::new(Vec::new()),
        }
    }
}

/// The report.
#[derive(Debug, Clone, Serialize)]
pub struct CheckReport {
    pub robot: String,
    /// The table region measured and where it came from.
    pub camera: Option<CameraSetup>,
    pub camera_source: &'static str,
    pub reach: Reach,
    pub postures: Vec<PostureCheck>,
    pub ik: Vec<IkRate>,
    pub coverage: Vec<MeshCoverage>,
    pub coverage_tolerance_m: f64,
    pub passed: bool,
    pub failures: Vec<String>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Reach {
    /// Tool heights above the table, m.
    pub heights: Vec<f64>,
    pub poses: usize,
    pub reached: usize,
    pub fraction: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct PostureCheck {
    pub posture: String,
    pub self_collision_free: bool,
}

#[derive(Debug, Clone, Serialize)]
pub struct IkRate {
    pub arm: String,
    pub poses: usize,
    pub solved: usize,
    pub success_rate: f64,
}

/// Loads the description at `description` and measures it.
pub fn check(description: &Path, o: &CheckOptions) -> Result<CheckReport, String> {
    let model = RobotModel::from_path_with(description, &o.packages).map_err(|e| e.to_string())?;
    let urdf = afford_kinematics::description_urdf(description).map_err(|e| e.to_string())?;
    let surfaces =
        afford_kinematics::mesh_surfaces(&urdf, &o.packages).map_err(|e| e.to_string())?;
    let (camera, camera_source) = match model.camera() {
        Some(c) => (Some(*c), "description"),
        None => (table::suggest(&model)?, "suggested"),
    };
    let reach = reach(&model, camera.as_ref(), o)?;
    let postures = postures(&model)?;
    let ik = model.arms().iter().map(|a| ik_rate(a, o)).collect();
    let coverage = coverage(&model, &surfaces);
    let mut failures = Vec::new();
    for p in postures.iter().filter(|p| !p.self_collision_free) {
        failures.push(format!("{}: the robot collides with itself", p.posture));
    }
    for c in coverage
        .iter()
        .filter(|c| c.max_outside_m.is_nan() || c.max_outside_m > COVERAGE_TOLERANCE_M)
    {
        failures.push(match c.max_outside_m.is_finite() {
            true => format!(
                "link '{}': {} mesh '{}' lies up to {:.4} m outside the collision model (tolerance {COVERAGE_TOLERANCE_M} m)",
                c.link, c.kind, c.mesh, c.max_outside_m
            ),
            false => format!(
                "link '{}': {} mesh '{}' lies outside the collision model: the link has no collision geometry",
                c.link, c.kind, c.mesh
            ),
        });
    }
    Ok(CheckReport {
        robot: model.name().to_string(),
        camera,
        camera_source,
        reach,
        postures,
        ik,
        coverage,
        coverage_tolerance_m: COVERAGE_TOLERANCE_M,
        passed: failures.is_empty(),
        failures,
    })
}

fn reach(
    model: &RobotModel,
    camera: Option<&CameraSetup>,
    o: &CheckOptions,
) -> Result<Reach, String> {
    let heights = table::HEIGHTS.to_vec();
    let Some(c) = camera else {
        return Ok(Reach {
            heights,
            poses: 0,
            reached: 0,
            fraction: 0.0,
        });
    };
    let reacher = Reacher::new(model, Some(c))?;
    let mut rng = ChaCha8Rng::seed_from_u64(o.seed);
    let (mut poses, mut reached) = (0, 0);
    for (x, y) in table::grid(c, o.grid.max(2)) {
        for h in &heights {
            poses += 1;
            let p = Vec3::new(x, y, c.table_z + h);
            if (0..model.arms().len()).any(|a| reacher.reach(a, p, &mut rng).is_some()) {
                reached += 1;
            }
        }
    }
    Ok(Reach {
        heights,
        poses,
        reached,
        fraction: reached as f64 / poses.max(1) as f64,
    })
}

fn postures(model: &RobotModel) -> Result<Vec<PostureCheck>, String> {
    let reacher = Reacher::new(model, None)?;
    let mut out = vec![PostureCheck {
        posture: "home".into(),
        self_collision_free: reacher.free(model.home()),
    }];
    for a in model.arms().iter().filter(|a| !a.park.is_empty()) {
        let mut q = model.home().to_vec();
        for &(i, v) in &a.park {
            q[i] = v;
        }
        out.push(PostureCheck {
            posture: format!("park ({})", a.name),
            self_collision_free: reacher.free(&q),
        });
    }
    Ok(out)
}

fn ik_rate(arm: &afford_kinematics::Arm, o: &CheckOptions) -> IkRate {
    let targets = random_reachable_poses(arm, o.poses, o.seed);
    let settings = IkSettings::default();
    let mut rng = ChaCha8Rng::seed_from_u64(o.seed ^ 0x5eed);
    let solved = (targets.iter())
        .filter(|t| {
            arm.solve_ik(&IkTarget::Pose(**t), None, &settings, &mut rng)
                .is_ok_and(|s| ik_bench_success(arm, &s.q, t))
        })
        .count();
    IkRate {
        arm: arm.name.clone(),
        poses: o.poses,
        solved,
        success_rate: solved as f64 / o.poses.max(1) as f64,
    }
}
