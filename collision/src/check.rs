//! The public checks and their reports.
//!
//! - [`RobotGeometry::check_tool_path`]: the gripper (every collider rigid with
//!   the tool frame) and the held object, moved along tool waypoints, against
//!   the scene. Between waypoints the tool moves on the straight line and
//!   rotates by slerp (the shortest rotation). Guarantee: a point at distance
//!   `r` from the tool origin moves at most `|dp| + r * dtheta` over a
//!   segment, and conservative advancement on that bound never skips a
//!   contact: a path reported free keeps every body farther than its margin
//!   from every obstacle at every instant.
//! - [`RobotGeometry::check_joint_path`] / [`RobotGeometry::check_arm_path`]:
//!   every robot collider and the held object along a piecewise-linear joint
//!   path, against the scene and against each other (non-adjacent links, both
//!   arms of a two-armed robot, held object against the non-gripper links).
//!   Guarantee: the same, with the joint-space motion bound of
//!   [`crate::robot`].
//!
//! Both are conservative: a reported collision means some pair came within
//! [`CheckSettings::tolerance`] of its margin (default 0.1 mm); a path with
//! true slack above the tolerance everywhere is reported free.

use afford_kinematics::Pose;
use parry3d::math::Pose as PPose;
use parry3d::shape::SharedShape;

use crate::convert::to_parry;
use crate::error::{CollisionError, path_err};
use crate::robot::RobotGeometry;
use crate::scene::Scene;
use crate::sweep::{self, Bodies, Group, Partner, Sweep};

pub use crate::report::{
    CheckSettings, CheckStats, Collision, HitKind, PathOptions, PathVerdict, ToolBounds,
};

impl RobotGeometry {
    /// Checks a joint path (full robot configurations, linear in between).
    pub fn check_joint_path(
        &self,
        scene: &Scene,
        path: &[Vec<f64>],
        opts: &PathOptions,
    ) -> Result<PathVerdict, CollisionError> {
        let mut p = self.prepare_joint_path(path, opts)?;
        p.run(scene, opts)
    }

    pub(crate) fn prepare_joint_path<'a>(
        &'a self,
        path: &'a [Vec<f64>],
        opts: &PathOptions,
    ) -> Result<Prepared<JointSweep<'a>>, CollisionError> {
        opts.settings.validate()?;
        if path.is_empty() {
            return Err(path_err("joints", "needs at least one waypoint"));
        }
        for (i, q) in path.iter().enumerate() {
            self.check_config(q, &format!("joints[{i}]"))?;
        }
        let mut bodies: Vec<crate::robot::Body> = self.bodies.clone();
        let held = self.held_body(opts)?;
        let tool_rigid = match &held {
            Some((_, tool_link)) => self.tool_rigid_bodies(*tool_link),
            None => Vec::new(),
        };
        let n_robot = bodies.len();
        if let Some((h, _)) = held {
            bodies.push(h);
        }
        let mut groups: Vec<Group> = (0..bodies.len())
            .map(|body| Group {
                body,
                partner: Partner::Scene,
            })
            .collect();
        if opts.settings.self_collision {
            for &(a, b) in &self.self_pairs {
                groups.push(Group {
                    body: a,
                    partner: Partner::Body(b),
                });
            }
            if bodies.len() > n_robot {
                for b in (0..n_robot).filter(|b| !tool_rigid.contains(b)) {
                    groups.push(Group {
                        body: n_robot,
                        partner: Partner::Body(b),
                    });
                }
            }
        }
        let dof = self.model.dof();
        let coeff: Vec<Vec<(usize, f64)>> = groups
            .iter()
            .map(|g| {
                let a = &bodies[g.body];
                (0..dof)
                    .filter_map(|j| {
                        let bit = 1u128 << j;
                        let c = match g.partner {
                            Partner::Scene => a.radii[j],
                            Partner::Body(o) => {
                                let b = &bodies[o];
                                match (a.ancestors & bit != 0, b.ancestors & bit != 0) {
                                    (true, false) => a.radii[j],
                                    (false, true) => b.radii[j],
                                    (true, true) if self.multi_drive & bit != 0 => {
                                        a.radii[j] + b.radii[j]
                                    }
                                    _ => 0.0,
                                }
                            }
                        };
                        (c > 0.0).then_some((j, c))
                    })
                    .collect()
            })
            .collect();
        let dq: Vec<f64> = path
            .windows(2)
            .flat_map(|w| {
                w[0].iter()
                    .zip(&w[1])
                    .map(|(a, b)| (b - a).abs())
                    .collect::<Vec<_>>()
            })
            .collect();
        let shapes: Vec<SharedShape> = bodies.iter().map(|b| b.shape.clone()).collect();
        let names: Vec<String> = bodies.iter().map(|b| b.name.clone()).collect();
        Ok(Prepared {
            sweep: JointSweep {
                geometry: self,
                bodies,
                path,
                dq,
                dof,
                coeff,
                last_t: f64::NAN,
                poses: Vec::new(),
            },
            shapes,
            names,
            groups,
        })
    }

    /// Checks a path of one arm: `path_arm` holds that arm's joint values
    /// (in [`afford_kinematics::Arm::joint_names`] order); every other joint
    /// stays at its value in `q_rest` (a full robot configuration).
    pub fn check_arm_path(
        &self,
        scene: &Scene,
        arm: &str,
        q_rest: &[f64],
        path_arm: &[Vec<f64>],
        opts: &PathOptions,
    ) -> Result<PathVerdict, CollisionError> {
        let a = self.model.arm(arm)?;
        self.check_config(q_rest, "q_rest")?;
        let mut full = Vec::with_capacity(path_arm.len());
        for (i, q) in path_arm.iter().enumerate() {
            if q.len() != a.dof() {
                return Err(path_err(
                    format!("joints[{i}]"),
                    format!("has {} values, arm '{arm}' has {}", q.len(), a.dof()),
                ));
            }
            let mut c = q_rest.to_vec();
            a.insert(&mut c, q);
            full.push(c);
        }
        let mut o = opts.clone();
        o.arm.get_or_insert_with(|| arm.to_string());
        self.check_joint_path(scene, &full, &o)
    }

    /// Checks the gripper (+ held object) moved along tool poses
    /// (`pose_base_tool` of the arm in `opts.arm`) against the scene.
    pub fn check_tool_path(
        &self,
        scene: &Scene,
        waypoints: &[Pose],
        opts: &PathOptions,
    ) -> Result<PathVerdict, CollisionError> {
        let mut p = self.prepare_tool_path(waypoints, opts)?;
        p.run(scene, opts)
    }

    pub(crate) fn prepare_tool_path<'a>(
        &self,
        waypoints: &'a [Pose],
        opts: &PathOptions,
    ) -> Result<Prepared<ToolSweep<'a>>, CollisionError> {
        opts.settings.validate()?;
        if waypoints.is_empty() {
            return Err(path_err("tool", "needs at least one waypoint"));
        }
        for (i, w) in waypoints.iter().enumerate() {
            let ok = w.translation.vector.iter().all(|v| v.is_finite())
                && w.rotation.coords.iter().all(|v| v.is_finite());
            if !ok {
                return Err(path_err(format!("tool[{i}]"), "must be finite"));
            }
        }
        let arm = self.arm_of(opts)?;
        let mut local: Vec<Pose> = Vec::new();
        let mut shapes: Vec<SharedShape> = Vec::new();
        let mut names: Vec<String> = Vec::new();
        for (name, pose, shape) in self.tool_bodies(arm)? {
            local.push(pose);
            shapes.push(shape);
            names.push(name);
        }
        if let Some(a) = &opts.attached {
            a.validate()?;
            local.push(a.pose_tool_object);
            shapes.push(a.shape());
            names.push(format!("held:{}", a.name));
        }
        let reach: Vec<f64> = shapes
            .iter()
            .zip(&local)
            .map(|(s, l)| {
                let sp = s.compute_local_bounding_sphere();
                let c = l * nalgebra::Point3::new(sp.center.x, sp.center.y, sp.center.z);
                c.coords.norm() + sp.radius()
            })
            .collect();
        let seg: Vec<(f64, f64)> = waypoints
            .windows(2)
            .map(|w| {
                (
                    (w[1].translation.vector - w[0].translation.vector).norm(),
                    w[0].rotation.angle_to(&w[1].rotation),
                )
            })
            .collect();
        let groups: Vec<Group> = (0..shapes.len())
            .map(|body| Group {
                body,
                partner: Partner::Scene,
            })
            .collect();
        Ok(Prepared {
            sweep: ToolSweep {
                waypoints,
                local,
                reach,
                seg,
                last_t: f64::NAN,
                poses: Vec::new(),
            },
            shapes,
            names,
            groups,
        })
    }

    /// The colliders rigid with `arm`'s tool frame: name, pose in the tool
    /// frame, shape.
    fn tool_bodies(
        &self,
        arm: &afford_kinematics::Arm,
    ) -> Result<Vec<(String, Pose, SharedShape)>, CollisionError> {
        let tool_link = self.model.link_index(&arm.tool_link)?;
        let home = self.model.link_poses(self.model.home())?;
        let pose_tool_base = home[tool_link].inverse();
        Ok(self
            .tool_rigid_bodies(tool_link)
            .into_iter()
            .map(|b| {
                let body = &self.bodies[b];
                let pose = pose_tool_base * home[body.link] * body.pose_link_shape;
                (body.name.clone(), pose, body.shape.clone())
            })
            .collect())
    }

    /// How far each collider rigid with `arm`'s tool frame extends along
    /// the tool's z axis (the approach direction: down when the tool points
    /// down): `(body name, [lowest, highest] z)` of its bounding box in the
    /// tool frame, metres from the tool origin (the TCP). With the tool
    /// pointing down, `highest` is how far the body reaches below the TCP.
    pub fn tool_body_extents(&self, arm: &str) -> Result<Vec<(String, [f64; 2])>, CollisionError> {
        Ok(self
            .tool_body_bounds(arm)?
            .into_iter()
            .map(|(name, [min, max])| (name, [min[2], max[2]]))
            .collect())
    }

    /// The bounding box of each collider rigid with `arm`'s tool frame, in
    /// that frame: `(body name, [mins, maxs])`, metres from the TCP (x, y,
    /// z; the fingers close along y, z is the approach axis).
    pub fn tool_body_bounds(&self, arm: &str) -> Result<Vec<(String, ToolBounds)>, CollisionError> {
        let arm = self.model.arm(arm)?;
        Ok(self
            .tool_bodies(arm)?
            .into_iter()
            .map(|(name, pose, shape)| {
                let aabb = shape.compute_aabb(&to_parry(&pose));
                let (lo, hi) = (aabb.mins, aabb.maxs);
                (name, [[lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]])
            })
            .collect())
    }

    fn arm_of(&self, opts: &PathOptions) -> Result<&afford_kinematics::Arm, CollisionError> {
        match &opts.arm {
            Some(name) => Ok(self.model.arm(name)?),
            None => self
                .model
                .arms()
                .first()
                .ok_or_else(|| path_err("arm", "the robot has no arm")),
        }
    }

    /// The held object as a body on the tool link, and the tool link index.
    fn held_body(
        &self,
        opts: &PathOptions,
    ) -> Result<Option<(crate::robot::Body, usize)>, CollisionError> {
        let Some(a) = &opts.attached else {
            return Ok(None);
        };
        a.validate()?;
        let arm = self.arm_of(opts)?;
        let tool_link = self.model.link_index(&arm.tool_link)?;
        let shape = a.shape();
        let body = self.body(
            tool_link,
            format!("held:{}", a.name),
            shape,
            a.pose_tool_object,
        );
        Ok(Some((body, tool_link)))
    }
}

/// Which obstacles each moving body sees, `[body][obstacle]`: all but the
/// ignored ones, the held object and the body's exempt pairs. `Err` names
/// the first `exempt` entry whose body is not one of `names`.
pub(crate) fn active(
    scene: &Scene,
    opts: &PathOptions,
    names: &[String],
) -> Result<Vec<Vec<bool>>, CollisionError> {
    if let Some(k) = opts
        .exempt
        .iter()
        .position(|(body, _)| !names.contains(body))
    {
        return Err(path_err(
            format!("exempt[{k}]"),
            format!("'{}' names no robot body", opts.exempt[k].0),
        ));
    }
    Ok(names
        .iter()
        .map(|body| {
            scene
                .obstacles
                .iter()
                .map(|o| {
                    !opts.ignore.contains(&o.name)
                        && opts.attached.as_ref().is_none_or(|a| a.name != o.name)
                        && !opts.exempt.iter().any(|(b, x)| b == body && *x == o.name)
                })
                .collect()
        })
        .collect())
}

/// A path turned into moving bodies and the pairs to check.
pub(crate) struct Prepared<S> {
    pub sweep: S,
    pub shapes: Vec<SharedShape>,
    pub names: Vec<String>,
    pub groups: Vec<Group>,
}

impl<S: Sweep> Prepared<S> {
    pub(crate) fn run(
        &mut self,
        scene: &Scene,
        opts: &PathOptions,
    ) -> Result<PathVerdict, CollisionError> {
        let active = active(scene, opts, &self.names)?;
        let spheres: Vec<_> = (self.shapes.iter())
            .map(|s| s.compute_local_bounding_sphere())
            .collect();
        let b = Bodies {
            shapes: &self.shapes,
            spheres: &spheres,
            names: &self.names,
            groups: &self.groups,
            scene,
            active: &active,
        };
        let (collisions, stats) = sweep::run(&mut self.sweep, &b, &opts.settings);
        Ok(PathVerdict { collisions, stats })
    }
}

pub(crate) struct JointSweep<'a> {
    geometry: &'a RobotGeometry,
    bodies: Vec<crate::robot::Body>,
    path: &'a [Vec<f64>],
    dq: Vec<f64>,
    dof: usize,
    coeff: Vec<Vec<(usize, f64)>>,
    last_t: f64,
    poses: Vec<PPose>,
}

impl Sweep for JointSweep<'_> {
    fn segments(&self) -> usize {
        self.path.len() - 1
    }

    fn dense_steps(&self, k: usize, _step_m: f64, step_rad: f64) -> usize {
        let d = &self.dq[k * self.dof..(k + 1) * self.dof];
        let m = d.iter().copied().fold(0.0, f64::max);
        ((m / step_rad).ceil() as usize).max(1)
    }

    fn seg_motion(&self, g: usize, k: usize) -> f64 {
        let d = &self.dq[k * self.dof..(k + 1) * self.dof];
        self.coeff[g].iter().map(|&(j, c)| c * d[j]).sum()
    }

    fn poses_at(&mut self, t: f64) -> &[PPose] {
        if t == self.last_t {
            return &self.poses;
        }
        self.last_t = t;
        let q = interpolate(self.path, t);
        let model = &self.geometry.model;
        let links = model
            .link_poses(&q)
            .unwrap_or_else(|_| vec![Pose::identity(); model.links().len()]);
        self.poses.clear();
        self.poses.extend(
            self.bodies
                .iter()
                .map(|b| to_parry(&(links[b.link] * b.pose_link_shape))),
        );
        &self.poses
    }
}

/// Configuration at path parameter `t` (linear between waypoints).
pub(crate) fn interpolate(path: &[Vec<f64>], t: f64) -> Vec<f64> {
    let n = path.len() - 1;
    let k = (t.floor().max(0.0) as usize).min(n);
    if k == n {
        return path[n].clone();
    }
    let s = t - k as f64;
    path[k]
        .iter()
        .zip(&path[k + 1])
        .map(|(a, b)| a + s * (b - a))
        .collect()
}

/// Tool pose at path parameter `t` (lerp + shortest slerp).
pub(crate) fn interpolate_pose(waypoints: &[Pose], t: f64) -> Pose {
    let n = waypoints.len() - 1;
    let k = (t.floor().max(0.0) as usize).min(n);
    if k == n {
        return waypoints[n];
    }
    let s = t - k as f64;
    let (a, b) = (&waypoints[k], &waypoints[k + 1]);
    let tr = a.translation.vector + s * (b.translation.vector - a.translation.vector);
    let rot = a
        .rotation
        .try_slerp(&b.rotation, s, 1e-12)
        .unwrap_or_else(|| a.rotation.rotation_to(&b.rotation).powf(s) * a.rotation);
    Pose::from_parts(tr.into(), rot)
}

pub(crate) struct ToolSweep<'a> {
    waypoints: &'a [Pose],
    local: Vec<Pose>,
    reach: Vec<f64>,
    seg: Vec<(f64, f64)>,
    last_t: f64,
    poses: Vec<PPose>,
}

impl Sweep for ToolSweep<'_> {
    fn segments(&self) -> usize {
        self.waypoints.len() - 1
    }

    fn dense_steps(&self, k: usize, step_m: f64, step_rad: f64) -> usize {
        let (dp, dth) = self.seg[k];
        ((dp / step_m).ceil().max((dth / step_rad).ceil()) as usize).max(1)
    }

    fn seg_motion(&self, g: usize, k: usize) -> f64 {
        let (dp, dth) = self.seg[k];
        dp + self.reach[g] * dth
    }

    fn poses_at(&mut self, t: f64) -> &[PPose] {
        if t == self.last_t {
            return &self.poses;
        }
        self.last_t = t;
        let tool = interpolate_pose(self.waypoints, t);
        self.poses.clear();
        self.poses
            .extend(self.local.iter().map(|l| to_parry(&(tool * l))));
        &self.poses
    }
}
