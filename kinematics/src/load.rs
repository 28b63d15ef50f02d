//! Loading: a URDF and its description file become a [`RobotModel`]. Owns the
//! checks that tie the two together (joint names, arm chains, postures) and
//! the file-system side (built-in name, description path, or URDF path with a
//! sibling `.yaml`).

use std::path::{Path, PathBuf};

use crate::bounds::{self, *};
use crate::builtin;
use crate::description::{self, AllowedReason, Description};
use crate::error::KinematicsError;
use crate::math::{Pose, Real};
use crate::mesh::{MeshSearch, PackagePaths};
use crate::model::{Joint, JointDrive, JointKind, Link, MimicJoint, RobotModel};
use crate::urdf::{self, Tree, TreeJoint};

/// Jerk limit of a joint whose description and URDF give none: its
/// acceleration limit reached from zero in this time, 0.02 s (two periods
/// of a 100 Hz controller), so `jerk = acceleration / 0.02 s`. afford's
/// choice (docs/decisions.md): no maker of the built-in arms publishes joint
/// jerk limits; the one that does for a comparable arm (Franka Emika Panda,
/// 7,500 rad/s³ against 7.5–20 rad/s²) allows a far shorter ramp.
pub const DEFAULT_JERK_RAMP_S: Real = 0.02;

impl RobotModel {
    /// A robot built into the binary (`kuka_iiwa14`, `care_o_bot4`).
    pub fn builtin(name: &str) -> Result<Self, KinematicsError> {
        let b = builtin::find(name).ok_or_else(|| KinematicsError::UnknownRobot {
            name: name.to_string(),
            known: builtin::NAMES.join(", "),
        })?;
        let mut model = Self::from_texts(
            b.description,
            Path::new(b.description_file),
            b.urdf,
            Path::new(b.urdf_file),
        )?;
        model.source = "built-in".into();
        Ok(model)
    }

    /// A built-in name, or a path to a description `.yaml` (or to a `.urdf`
    /// with a `.yaml` of the same stem beside it). Relative paths are taken
    /// relative to `base_dir` (the scenario's folder). Meshes are searched
    /// with [`PackagePaths::new`] and no folders of the caller's.
    pub fn load(model: &str, base_dir: &Path) -> Result<Self, KinematicsError> {
        Self::load_with(model, base_dir, &PackagePaths::new(Vec::new()))
    }

    /// As [`Self::load`], with `package://` meshes searched in `packages`.
    pub fn load_with(
        model: &str,
        base_dir: &Path,
        packages: &PackagePaths,
    ) -> Result<Self, KinematicsError> {
        if builtin::find(model).is_some() {
            return Self::builtin(model);
        }
        let path = base_dir.join(model);
        let is_file_like =
            model.contains('/') || model.contains('\\') || path.extension().is_some();
        if !is_file_like {
            return Err(KinematicsError::UnknownRobot {
                name: model.to_string(),
                known: builtin::NAMES.join(", "),
            });
        }
        Self::from_path_with(&path, packages)
    }

    /// Loads a user robot from a description `.yaml`, or from a `.urdf` whose
    /// description is the `.yaml` of the same stem in the same folder.
    pub fn from_path(path: &Path) -> Result<Self, KinematicsError> {
        Self::from_path_with(path, &PackagePaths::new(Vec::new()))
    }

    /// As [`Self::from_path`], with `package://` meshes searched in `packages`.
    pub fn from_path_with(path: &Path, packages: &PackagePaths) -> Result<Self, KinematicsError> {
        let description_path = if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
        {
            let yaml = path.with_extension("yaml");
            if !yaml.exists() {
                return Err(KinematicsError::Io {
                    file: yaml,
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        format!(
                            "a URDF needs its robot description beside it (for {})",
                            path.display()
                        ),
                    ),
                });
            }
            yaml
        } else {
            path.to_path_buf()
        };
        let description_text = read_text(&description_path)?;
        let description = parse_description(&description_text, &description_path)?;
        let urdf_path = description_path
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join(&description.urdf);
        let urdf_text = read_text(&urdf_path)?;
        let search = MeshSearch {
            urdf_dir: urdf_path.parent().unwrap_or_else(|| Path::new(".")),
            packages,
        };
        let tree = urdf::parse(&urdf_text, &urdf_path, search)?;
        let mut model = assemble(&tree, &description, &description_path)?;
        attach_srdf(&mut model, &description, &description_path)?;
        model.source = description_path.display().to_string();
        model.urdf = urdf_text.into();
        Ok(model)
    }

    /// Builds a model from description YAML and URDF text; the paths name
    /// the files in error messages, and meshes are looked for from the URDF
    /// path's folder (as [`Self::load`] does).
    pub fn from_texts(
        description_yaml: &str,
        description_file: &Path,
        urdf_text: &str,
        urdf_file: &Path,
    ) -> Result<Self, KinematicsError> {
        let packages = PackagePaths::new(Vec::new());
        Self::from_texts_with(
            description_yaml,
            description_file,
            urdf_text,
            urdf_file,
            &packages,
        )
    }

    /// As [`Self::from_texts`], with `package://` meshes searched in `packages`.
    pub fn from_texts_with(
        description_yaml: &str,
        description_file: &Path,
        urdf_text: &str,
        urdf_file: &Path,
        packages: &PackagePaths,
    ) -> Result<Self, KinematicsError> {
        let description = parse_description(description_yaml, description_file)?;
        let search = MeshSearch {
            urdf_dir: urdf_file.parent().unwrap_or_else(|| Path::new(".")),
            packages,
        };
        let tree = urdf::parse(urdf_text, urdf_file, search)?;
        let mut model = assemble(&tree, &description, description_file)?;
        attach_srdf(&mut model, &description, description_file)?;
        model.source = description_file.display().to_string();
        model.urdf = urdf_text.into();
        Ok(model)
    }
}

/// The URDF a description file names (a `.urdf` path is its own), as
/// [`RobotModel::from_path`] finds it.
pub fn description_urdf(path: &Path) -> Result<PathBuf, KinematicsError> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
    {
        return Ok(path.to_path_buf());
    }
    let description = parse_description(&read_text(path)?, path)?;
    Ok(path
        .parent()
        .unwrap_or_else(|| Path::new("."))
        .join(&description.urdf))
}

/// A robot file's text: a regular file of at most [`MAX_FILE_BYTES`] (one
/// byte more is read, so that the parsers refuse a larger file).
pub fn read_text(p: &Path) -> Result<String, KinematicsError> {
    use std::io::Read;
    let io = |source| KinematicsError::Io {
        file: p.to_path_buf(),
        source,
    };
    let mut text = String::new();
    crate::open_regular(p)
        .map_err(io)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(io)?;
    Ok(text)
}

/// Reads the description's SRDF, if it names one, into `model`.
fn attach_srdf(
    model: &mut RobotModel,
    d: &Description,
    description_file: &Path,
) -> Result<(), KinematicsError> {
    let Some(srdf) = &d.srdf else {
        return Ok(());
    };
    let dir = description_file.parent().unwrap_or_else(|| Path::new("."));
    crate::srdf::attach(model, &dir.join(srdf))
}

/// Parses a description after checking its size ([`MAX_FILE_BYTES`]).
fn parse_description(text: &str, file: &Path) -> Result<Description, KinematicsError> {
    bounds::check_file_size(text.len() as u64).map_err(|problem| {
        KinematicsError::DescriptionElement {
            file: file.to_path_buf(),
            element: "afford_robot".into(),
            problem,
        }
    })?;
    description::parse(text, file)
}

/// True when a joint value (`home`, `park`) is finite and within the bound
/// of its kind: [`MAX_PRISMATIC_LIMIT_M`] or [`MAX_REVOLUTE_LIMIT_RAD`]
/// (continuous joints too, which have no limits of their own).
pub(crate) fn value_in_bounds(kind: JointKind, v: Real) -> bool {
    let largest = match kind {
        JointKind::Prismatic => MAX_PRISMATIC_LIMIT_M,
        _ => MAX_REVOLUTE_LIMIT_RAD,
    };
    v.is_finite() && v.abs() <= largest
}

fn assemble(tree: &Tree, d: &Description, file: &Path) -> Result<RobotModel, KinematicsError> {
    let err = |element: String, problem: String| KinematicsError::DescriptionElement {
        file: PathBuf::from(file),
        element,
        problem,
    };
    for (name, value) in [
        ("max_opening", d.gripper.max_opening),
        ("finger_length", d.gripper.finger_length),
    ] {
        bounds::check_range("the size", value, (0.0, MAX_GRIPPER_SIZE_M))
            .map_err(|problem| err(format!("gripper.{name}"), problem))?;
    }
    // Movable joints in tree order form the configuration; mimic joints
    // follow one of them.
    let mut joints = Vec::new();
    for j in tree.links.iter().filter_map(|l| l.joint.as_ref()) {
        if j.kind != JointKind::Fixed && j.resolved.is_none() {
            joints.push(configuration_joint(j, d, &err)?);
        }
    }
    if joints.len() > MAX_MOVABLE_JOINTS {
        return Err(err(
            "urdf".into(),
            format!("the robot has more than {MAX_MOVABLE_JOINTS} movable joints"),
        ));
    }
    let mut mimics = Vec::new();
    let mut links = Vec::with_capacity(tree.links.len());
    for tl in &tree.links {
        let (origin, joint) = match &tl.joint {
            None => (Pose::identity(), None),
            Some(j) => (j.origin, drive(j, &joints, &mut mimics)),
        };
        links.push(Link {
            name: tl.name.clone(),
            parent: tl.parent,
            colliders: tl.colliders.clone(),
            origin,
            joint,
        });
    }
    let joint_index = |name: &str| joints.iter().position(|j| j.name == name);
    for (section, map) in [
        ("home", &d.home),
        ("acceleration_limits", &d.acceleration_limits),
        ("jerk_limits", &d.jerk_limits),
    ] {
        if let Some(name) = map.keys().find(|n| joint_index(n).is_none()) {
            let problem = match mimics.iter().find(|m| &m.name == name) {
                Some(m) => format!(
                    "is a mimic joint (it follows '{}'): give its leader's value",
                    m.leader
                ),
                None => "is not a movable joint of the URDF".into(),
            };
            return Err(err(format!("{section}.{name}"), problem));
        }
    }
    let mut home = Vec::with_capacity(joints.len());
    for j in &joints {
        let v = d
            .home
            .get(&j.name)
            .copied()
            .unwrap_or_else(|| 0.0f64.clamp(j.lower, j.upper));
        if !j.within(v, 1e-9) || !value_in_bounds(j.kind, v) {
            return Err(err(
                format!("home.{}", j.name),
                format!("{v} is outside the joint limits {} .. {}", j.lower, j.upper),
            ));
        }
        home.push(v);
    }
    let robot = crate::arms::Robot {
        tree,
        links: &links,
        joints: &joints,
        home: &home,
        err: &err,
    };
    let arms = (d.arms.iter().enumerate())
        .map(|(ai, ad)| robot.arm(ai, ad))
        .collect::<Result<Vec<_>, _>>()?;
    let self_collision_skip = allowed_pairs(&links, d, &err)?;
    for (k, finger) in d.gripper.fingers.iter().enumerate() {
        if !names_a_collider(&links, finger) {
            return Err(err(
                format!("gripper.fingers[{k}]"),
                format!(
                    "'{finger}' names no collider (write 'link' for a link with one collider, 'link#k' for its k-th of several)"
                ),
            ));
        }
    }
    Ok(RobotModel {
        name: d.name.clone(),
        source: String::new(),
        links,
        joints,
        mimics,
        arms,
        home,
        gripper: d.gripper.clone(),
        self_collision_skip,
        allowed_collisions: d.allowed_collisions.clone(),
        postures: Vec::new(),
        urdf: "".into(),
        camera: d.camera,
    })
}

/// A configuration joint from its URDF joint, with the description's
/// acceleration and jerk limits (or the URDF's, or the default jerk).
fn configuration_joint(
    j: &TreeJoint,
    d: &Description,
    err: &impl Fn(String, String) -> KinematicsError,
) -> Result<Joint, KinematicsError> {
    let acceleration = match d.acceleration_limits.get(&j.name) {
        Some(&a) => a,
        None => j.acceleration,
    };
    if !(acceleration.is_finite() && acceleration > 0.0) {
        return Err(err(
            format!("acceleration_limits.{}", j.name),
            "missing or not positive: give a limit here or in the URDF <limit acceleration=..>"
                .into(),
        ));
    }
    bounds::check_range("the limit", acceleration, ACCELERATION_LIMIT_RANGE)
        .map_err(|problem| err(format!("acceleration_limits.{}", j.name), problem))?;
    let jerk = match (d.jerk_limits.get(&j.name), j.jerk.is_finite()) {
        (Some(&jerk), _) => jerk,
        (None, true) => j.jerk,
        (None, false) => acceleration / DEFAULT_JERK_RAMP_S,
    };
    bounds::check_range("the limit", jerk, JERK_LIMIT_RANGE)
        .map_err(|problem| err(format!("jerk_limits.{}", j.name), problem))?;
    Ok(Joint {
        name: j.name.clone(),
        kind: j.kind,
        lower: j.lower,
        upper: j.upper,
        velocity: j.velocity,
        acceleration,
        jerk,
        effort: j.effort,
    })
}

/// What drives the URDF joint `j` (`None`: fixed); a mimic joint is added
/// to `mimics`. Its configuration joint is in `joints` (the URDF's mimic
/// chains were resolved to one).
fn drive(j: &TreeJoint, joints: &[Joint], mimics: &mut Vec<MimicJoint>) -> Option<JointDrive> {
    if j.kind == JointKind::Fixed {
        return None;
    }
    let index = |name: &str| joints.iter().position(|c| c.name == name);
    let Some(r) = &j.resolved else {
        return Some(JointDrive {
            joint: index(&j.name)?,
            axis: j.axis,
            kind: j.kind,
            mimic: None,
        });
    };
    let joint = index(&r.root)?;
    mimics.push(MimicJoint {
        name: j.name.clone(),
        leader: r.leader.clone(),
        joint,
        mimic: r.mimic,
        lower: j.lower,
        upper: j.upper,
    });
    Some(JointDrive {
        joint,
        axis: j.axis,
        kind: j.kind,
        mimic: Some(r.mimic),
    })
}

/// True when `body` names a collider the way the collision crate names its
/// bodies: `link` for a link with one collider, `link#k` for the k-th of several.
fn names_a_collider(links: &[Link], body: &str) -> bool {
    let (link, index) = match body.rsplit_once('#') {
        Some((link, k)) => (link, k.parse::<usize>().ok()),
        None => (body, None),
    };
    links.iter().any(|l| {
        l.name == link
            && match index {
                None => l.colliders.len() == 1,
                Some(k) => l.colliders.len() > 1 && k < l.colliders.len(),
            }
    })
}

/// The link pairs skipped by the self-collision check: the adjacent pairs
/// (always) and every pair of the description's `allowed_collisions`; a
/// pair stored as `adjacent` must really be adjacent.
fn allowed_pairs(
    links: &[Link],
    d: &Description,
    err: &impl Fn(String, String) -> KinematicsError,
) -> Result<Vec<(usize, usize)>, KinematicsError> {
    let adjacent = crate::adjacency::adjacent_link_pairs(links);
    let mut skip = adjacent.clone();
    let stored = d.allowed_collisions.as_ref().map_or(&[][..], |a| &a.pairs);
    for (k, entry) in stored.iter().enumerate() {
        let field = format!("allowed_collisions.pairs[{k}]");
        let index = |name: &str| {
            links
                .iter()
                .position(|l| l.name == name)
                .ok_or_else(|| err(field.clone(), format!("link '{name}' is not in the URDF")))
        };
        let (a, b) = (index(&entry.pair[0])?, index(&entry.pair[1])?);
        if a == b {
            return Err(err(
                field,
                format!("pairs link '{}' with itself", entry.pair[0]),
            ));
        }
        let key = (a.min(b), a.max(b));
        if entry.reason == AllowedReason::Adjacent && !adjacent.contains(&key) {
            return Err(err(
                field,
                format!(
                    "'{}' and '{}' are not adjacent (joined by a joint, both with collision geometry); re-derive the section with `afford robots acm`",
                    entry.pair[0], entry.pair[1]
                ),
            ));
        }
        skip.push(key);
    }
    skip.sort_unstable();
    skip.dedup();
    Ok(skip)
}
