//! Reaching one table point with the tool pointing down, collision-free: the
//! one query `robots init` (table region, home) and `robots check` (reach)
//! share. IK from home first, then from a few random starts; each solution
//! is checked against the table and the robot itself.

use afford_collision::{PathOptions, RobotGeometry, Scene, SceneSpec, TableSpec};
use afford_kinematics::{
    CameraSetup, IkSettings, IkTarget, RobotModel, Vec3, random_configuration,
};
use rand_chacha::ChaCha8Rng;

/// IK starts tried per point (home, then random configurations): 4
/// missed the UR5's collision-free solutions near its base.
pub const STARTS_PER_POINT: usize = 12;

/// The robot with its collision geometry, and the table of a camera set-up.
pub struct Reacher<'a> {
    pub model: &'a RobotModel,
    pub geometry: RobotGeometry,
    pub scene: Scene,
    pub ik: IkSettings,
}

impl<'a> Reacher<'a> {
    /// The model's geometry and the table under `camera` (none: no table).
    pub fn new(model: &'a RobotModel, camera: Option<&CameraSetup>) -> Result<Self, String> {
        let geometry = RobotGeometry::new(model).map_err(|e| e.to_string())?;
        let scene = Scene::from_spec(&table_spec(camera)).map_err(|e| e.to_string())?;
        let ik = IkSettings {
            restarts: 8,
            ..IkSettings::default()
        };
        Ok(Self {
            model,
            geometry,
            scene,
            ik,
        })
    }

    /// The table under `camera` from now on.
    pub fn set_camera(&mut self, camera: Option<&CameraSetup>) -> Result<(), String> {
        self.scene = Scene::from_spec(&table_spec(camera)).map_err(|e| e.to_string())?;
        Ok(())
    }

    /// True when the whole-robot configuration `q` touches neither the table
    /// nor itself.
    pub fn free(&self, q: &[f64]) -> bool {
        let path = [q.to_vec()];
        (self
            .geometry
            .check_joint_path(&self.scene, &path, &PathOptions::default()))
        .is_ok_and(|v| v.is_free())
    }

    /// A collision-free configuration (whole robot, other joints at home)
    /// with arm `arm`'s tool at `position` pointing down, if one is found.
    pub fn reach(&self, arm: usize, position: Vec3, rng: &mut ChaCha8Rng) -> Option<Vec<f64>> {
        self.reach_all(arm, position, rng, 1).into_iter().next()
    }

    /// Up to `want` different collision-free solutions (module docs).
    pub fn reach_all(
        &self,
        arm: usize,
        position: Vec3,
        rng: &mut ChaCha8Rng,
        want: usize,
    ) -> Vec<Vec<f64>> {
        let a = &self.model.arms()[arm];
        let target = IkTarget::TopDown {
            position,
            yaw: None,
        };
        let mut found = Vec::new();
        for k in 0..STARTS_PER_POINT.max(want) {
            let seed = (k > 0).then(|| random_configuration(a, rng));
            let Ok(s) = a.solve_ik(&target, seed.as_deref(), &self.ik, rng) else {
                if k == 0 && (position - a.reach_centre()).norm() > a.reach {
                    break;
                }
                continue;
            };
            let mut q = self.model.home().to_vec();
            a.insert(&mut q, &s.q);
            if self.free(&q) {
                found.push(q);
                if found.len() >= want {
                    break;
                }
            }
        }
        found
    }
}

/// The scene of a set-up: the table slab under the camera's image.
pub fn table_spec(camera: Option<&CameraSetup>) -> SceneSpec {
    let Some(c) = camera else {
        return SceneSpec {
            table_z: -10.0,
            table: None,
            boxes: Vec::new(),
        };
    };
    let (w, h) = (f64::from(c.width), f64::from(c.height));
    let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)].map(|(u, v)| c.point(u, v));
    let lo = |f: fn(&(f64, f64)) -> f64| corners.iter().map(f).fold(f64::INFINITY, f64::min);
    let hi = |f: fn(&(f64, f64)) -> f64| corners.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
    SceneSpec {
        table_z: c.table_z,
        table: Some(TableSpec {
            min: [lo(|p| p.0), lo(|p| p.1)],
            max: [hi(|p| p.0), hi(|p| p.1)],
            margin: 0.0,
        }),
        boxes: Vec::new(),
    }
}
