//! URDF at the edge: the only module that touches urdf-rs. Parses a URDF
//! string into a validated kinematic tree (links in parent-before-child order,
//! movable joints with their `<mimic>`, collision shapes, meshes through
//! `mesh`) and names the element at fault when something is wrong.

use std::collections::HashMap;
use std::path::Path;

use crate::bounds::{self, *};
use crate::error::KinematicsError;
use crate::math::{Pose, Real, Vec3, pose_from_xyz_rpy};
use crate::mesh::{self, MeshSearch};
use crate::model::{Collider, JointKind, Shape};

/// One link of the parsed tree.
#[derive(Debug, Clone)]
pub(crate) struct TreeLink {
    pub name: String,
    /// Index (in tree order) of the parent link; `None` for the root.
    pub parent: Option<usize>,
    /// The joint connecting this link to its parent.
    pub joint: Option<TreeJoint>,
    pub colliders: Vec<Collider>,
}

/// The joint above a link.
#[derive(Debug, Clone)]
pub(crate) struct TreeJoint {
    pub name: String,
    /// Pose of the joint frame in the parent link frame.
    pub origin: Pose,
    pub kind: JointKind,
    /// Unit axis in the joint frame (unused for fixed joints).
    pub axis: Vec3,
    /// Position limits; -inf/+inf for a continuous joint.
    pub lower: Real,
    pub upper: Real,
    pub velocity: Real,
    pub effort: Real,
    /// URDF 1.2 acceleration limit (infinite when absent).
    pub acceleration: Real,
    /// URDF 1.2 jerk limit (infinite when absent).
    pub jerk: Real,
    /// `<mimic>`: the leader's name, multiplier and offset (as written).
    pub mimic: Option<(String, Real, Real)>,
    /// The mimic chain followed to a configuration joint (`mimic::resolve`).
    pub resolved: Option<crate::mimic::Resolved>,
}

/// A parsed URDF: its links, root first.
#[derive(Debug, Clone)]
pub(crate) struct Tree {
    pub links: Vec<TreeLink>,
}

fn element_error(file: &Path, element: String, problem: impl Into<String>) -> KinematicsError {
    KinematicsError::UrdfElement {
        file: file.to_path_buf(),
        element,
        problem: problem.into(),
    }
}

/// `Err` with the problem when an `<origin>` is not finite or farther than
/// [`MAX_OFFSET_M`] / turned more than [`MAX_ORIGIN_ANGLE_RAD`].
fn check_origin(xyz: &[Real; 3], rpy: &[Real; 3]) -> Result<(), String> {
    if !xyz.iter().chain(rpy).all(|x| x.is_finite()) {
        return Err("<origin> holds a non-finite number".into());
    }
    if xyz.iter().any(|x| x.abs() > MAX_OFFSET_M) {
        return Err(format!(
            "<origin xyz> is more than {MAX_OFFSET_M} m from its parent frame"
        ));
    }
    if rpy.iter().any(|x| x.abs() > MAX_ORIGIN_ANGLE_RAD) {
        return Err(format!(
            "<origin rpy> angles must be within {MAX_ORIGIN_ANGLE_RAD:.4} rad"
        ));
    }
    Ok(())
}

/// Parses and validates URDF text; `file` names the URDF in error messages,
/// `search` says where its meshes are.
pub(crate) fn parse(
    text: &str,
    file: &Path,
    search: MeshSearch<'_>,
) -> Result<Tree, KinematicsError> {
    bounds::check_file_size(text.len() as u64)
        .map_err(|problem| element_error(file, "<robot>".into(), problem))?;
    let robot = urdf_rs::read_from_string(text).map_err(|e| KinematicsError::UrdfSyntax {
        file: file.to_path_buf(),
        message: e.to_string(),
    })?;
    if robot.links.is_empty() {
        return Err(element_error(file, "<robot>".into(), "has no <link>"));
    }
    for (what, count, max) in [
        ("<link>", robot.links.len(), MAX_LINKS),
        ("<joint>", robot.joints.len(), MAX_JOINTS),
    ] {
        if count > max {
            return Err(element_error(
                file,
                "<robot>".into(),
                format!("has {count} {what} elements; at most {max} are supported"),
            ));
        }
    }
    let mut link_index: HashMap<&str, usize> = HashMap::new();
    for (i, link) in robot.links.iter().enumerate() {
        if link.name.is_empty() {
            return Err(element_error(
                file,
                format!("link #{}", i + 1),
                "has no name",
            ));
        }
        if link_index.insert(link.name.as_str(), i).is_some() {
            return Err(element_error(
                file,
                format!("link '{}'", link.name),
                "is defined twice",
            ));
        }
    }
    // Parent joint of each link (by URDF index).
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut joint_names: HashMap<&str, ()> = HashMap::new();
    for (ji, joint) in robot.joints.iter().enumerate() {
        let el = format!("joint '{}'", joint.name);
        if joint_names.insert(joint.name.as_str(), ()).is_some() {
            return Err(element_error(file, el, "is defined twice"));
        }
        if !link_index.contains_key(joint.parent.link.as_str()) {
            return Err(element_error(
                file,
                el,
                format!("parent link '{}' is not defined", joint.parent.link),
            ));
        }
        let Some(&child) = link_index.get(joint.child.link.as_str()) else {
            return Err(element_error(
                file,
                el,
                format!("child link '{}' is not defined", joint.child.link),
            ));
        };
        if let Some(other) = parent_joint[child] {
            return Err(element_error(
                file,
                el,
                format!(
                    "link '{}' already has parent joint '{}'",
                    joint.child.link, robot.joints[other].name
                ),
            ));
        }
        parent_joint[child] = Some(ji);
    }
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&i| parent_joint[i].is_none())
        .collect();
    if roots.len() != 1 {
        let names: Vec<&str> = roots
            .iter()
            .map(|&i| robot.links[i].name.as_str())
            .collect();
        return Err(element_error(
            file,
            "<robot>".into(),
            format!(
                "needs exactly one root link, found {}: {}",
                names.len(),
                names.join(", ")
            ),
        ));
    }
    // Breadth-first order from the root; links never reached sit in a cycle.
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (ji, joint) in robot.joints.iter().enumerate() {
        children[link_index[joint.parent.link.as_str()]].push(ji);
    }
    let mut order = vec![roots[0]];
    let mut tree_index = vec![usize::MAX; robot.links.len()];
    tree_index[roots[0]] = 0;
    let mut cursor = 0;
    while cursor < order.len() {
        let li = order[cursor];
        cursor += 1;
        for &ji in &children[li] {
            let child = link_index[robot.joints[ji].child.link.as_str()];
            tree_index[child] = order.len();
            order.push(child);
        }
    }
    if order.len() != robot.links.len() {
        let stray = (0..robot.links.len())
            .find(|&i| tree_index[i] == usize::MAX)
            .unwrap_or(0);
        return Err(element_error(
            file,
            format!("link '{}'", robot.links[stray].name),
            "is part of a joint cycle (not connected to the root)",
        ));
    }
    let mut links = Vec::with_capacity(order.len());
    for &li in &order {
        let link = &robot.links[li];
        if link.collision.len() > MAX_COLLIDERS_PER_LINK {
            return Err(element_error(
                file,
                format!("link '{}'", link.name),
                format!("has more than {MAX_COLLIDERS_PER_LINK} <collision> elements"),
            ));
        }
        let colliders = link
            .collision
            .iter()
            .enumerate()
            .map(|(ci, c)| collider(c, file, &link.name, ci, search))
            .collect::<Result<Vec<_>, _>>()?;
        let (parent, joint) = match parent_joint[li] {
            None => (None, None),
            Some(ji) => {
                let j = &robot.joints[ji];
                let parent = tree_index[link_index[j.parent.link.as_str()]];
                (Some(parent), Some(tree_joint(j, file)?))
            }
        };
        links.push(TreeLink {
            name: link.name.clone(),
            parent,
            joint,
            colliders,
        });
    }
    crate::mimic::resolve(&mut links, file)?;
    Ok(Tree { links })
}

fn tree_joint(j: &urdf_rs::Joint, file: &Path) -> Result<TreeJoint, KinematicsError> {
    let el = || format!("joint '{}'", j.name);
    if j.name.is_empty() {
        return Err(element_error(
            file,
            format!("joint to link '{}'", j.child.link),
            "has no name",
        ));
    }
    let (xyz, rpy) = (j.origin.xyz.0, j.origin.rpy.0);
    check_origin(&xyz, &rpy).map_err(|problem| element_error(file, el(), problem))?;
    let kind = match j.joint_type {
        urdf_rs::JointType::Fixed => JointKind::Fixed,
        urdf_rs::JointType::Revolute => JointKind::Revolute,
        urdf_rs::JointType::Continuous => JointKind::Continuous,
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        ref other => {
            return Err(element_error(
                file,
                el(),
                format!(
                    "type {other:?} is not supported (use fixed, revolute, continuous or prismatic)"
                ),
            ));
        }
    };
    let axis_raw = Vec3::from(j.axis.xyz.0);
    let axis = if kind == JointKind::Fixed {
        Vec3::z()
    } else {
        let n = axis_raw.norm();
        if !n.is_finite() || n < 1e-9 {
            return Err(element_error(
                file,
                el(),
                "<axis xyz> must be a non-zero, finite vector",
            ));
        }
        axis_raw / n
    };
    let lim = &j.limit;
    let (lower, upper) = match kind {
        JointKind::Fixed => (0.0, 0.0),
        // A continuous joint has no position limits (URDF ignores its
        // <limit lower/upper>): its range is the whole real line.
        JointKind::Continuous => (Real::NEG_INFINITY, Real::INFINITY),
        _ => {
            if !(lim.lower.is_finite() && lim.upper.is_finite() && lim.lower < lim.upper) {
                return Err(element_error(
                    file,
                    el(),
                    format!(
                        "a {} joint needs <limit lower=.. upper=..> with finite lower < upper (got {} .. {})",
                        if kind == JointKind::Revolute {
                            "revolute"
                        } else {
                            "prismatic"
                        },
                        lim.lower,
                        lim.upper
                    ),
                ));
            }
            (lim.lower, lim.upper)
        }
    };
    if kind != JointKind::Fixed {
        bounds::check_range("<limit velocity>", lim.velocity, VELOCITY_LIMIT_RANGE)
            .map_err(|problem| element_error(file, el(), problem))?;
    }
    let largest = match kind {
        JointKind::Prismatic => MAX_PRISMATIC_LIMIT_M,
        _ => MAX_REVOLUTE_LIMIT_RAD,
    };
    for (what, value) in [("lower", lower), ("upper", upper)] {
        if value.is_finite() && value.abs() > largest {
            return Err(element_error(
                file,
                el(),
                format!("<limit {what}> must be within ±{largest:.4}, got {value:?}"),
            ));
        }
    }
    Ok(TreeJoint {
        name: j.name.clone(),
        origin: pose_from_xyz_rpy(xyz, rpy),
        kind,
        axis,
        lower,
        upper,
        velocity: lim.velocity,
        effort: lim.effort,
        acceleration: lim.acceleration,
        jerk: lim.jerk,
        mimic: j.mimic.as_ref().map(|m| {
            (
                m.joint.clone(),
                m.multiplier.unwrap_or(1.0),
                m.offset.unwrap_or(0.0),
            )
        }),
        resolved: None,
    })
}

fn collider(
    c: &urdf_rs::Collision,
    file: &Path,
    link: &str,
    index: usize,
    search: MeshSearch<'_>,
) -> Result<Collider, KinematicsError> {
    let el = || format!("link '{link}' <collision> #{}", index + 1);
    let (xyz, rpy) = (c.origin.xyz.0, c.origin.rpy.0);
    check_origin(&xyz, &rpy).map_err(|problem| element_error(file, el(), problem))?;
    let positive = |v: Real| v.is_finite() && (MIN_SHAPE_SIZE_M..=MAX_SHAPE_SIZE_M).contains(&v);
    let shape = match &c.geometry {
        urdf_rs::Geometry::Box { size } if size.0.iter().all(|&s| positive(s)) => Shape::Box {
            half_extents: Vec3::from(size.0) / 2.0,
        },
        urdf_rs::Geometry::Cylinder { radius, length }
            if positive(*radius) && positive(*length) =>
        {
            Shape::Cylinder {
                radius: *radius,
                half_length: length / 2.0,
            }
        }
        urdf_rs::Geometry::Capsule { radius, length }
            if positive(*radius) && (*length == 0.0 || positive(*length)) =>
        {
            Shape::Capsule {
                radius: *radius,
                half_length: length / 2.0,
            }
        }
        urdf_rs::Geometry::Sphere { radius } if positive(*radius) => {
            Shape::Sphere { radius: *radius }
        }
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let scale = scale.map_or([1.0; 3], |s| s.0);
            let vertices = mesh::convex_hull(filename, scale, search).map_err(|problem| {
                KinematicsError::Mesh {
                    file: file.to_path_buf(),
                    link: link.to_string(),
                    mesh: filename.clone(),
                    problem: Box::new(problem),
                }
            })?;
            Shape::ConvexHull { vertices }
        }
        _ => {
            return Err(element_error(
                file,
                el(),
                format!(
                    "geometry sizes must be between {MIN_SHAPE_SIZE_M} and {MAX_SHAPE_SIZE_M} m"
                ),
            ));
        }
    };
    Ok(Collider {
        origin: pose_from_xyz_rpy(xyz, rpy),
        shape,
    })
}

/// A `<mesh>` of a link's `<collision>` or `<visual>`, as written.
#[derive(Debug, Clone)]
pub(crate) struct MeshElement {
    pub link: String,
    pub visual: bool,
    pub filename: String,
    pub scale: [Real; 3],
    /// The element's `<origin>` in the link frame.
    pub origin: Pose,
}

/// Every `<mesh>` of the URDF's links, collision ones first per link.
pub(crate) fn mesh_elements(text: &str, file: &Path) -> Result<Vec<MeshElement>, KinematicsError> {
    let robot = urdf_rs::read_from_string(text).map_err(|e| KinematicsError::UrdfSyntax {
        file: file.to_path_buf(),
        message: e.to_string(),
    })?;
    let mut out = Vec::new();
    for link in &robot.links {
        let collision = link
            .collision
            .iter()
            .map(|c| (false, &c.origin, &c.geometry));
        let visual = link.visual.iter().map(|v| (true, &v.origin, &v.geometry));
        for (visual, origin, geometry) in collision.chain(visual) {
            if let urdf_rs::Geometry::Mesh { filename, scale } = geometry {
                let (xyz, rpy) = (origin.xyz.0, origin.rpy.0);
                check_origin(&xyz, &rpy).map_err(|problem| {
                    element_error(
                        file,
                        format!("link '{}' <mesh filename=\"{filename}\">", link.name),
                        problem,
                    )
                })?;
                out.push(MeshElement {
                    link: link.name.clone(),
                    visual,
                    filename: filename.clone(),
                    scale: scale.map_or([1.0; 3], |s| s.0),
                    origin: pose_from_xyz_rpy(xyz, rpy),
                });
            }
        }
    }
    Ok(out)
}
