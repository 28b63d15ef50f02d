//! SRDF (MoveIt's semantic robot description), named by a description's
//! `srdf:` field. Two of its elements are read:
//!
//! - `<disable_collisions link1=".." link2=".." reason=".."/>`: the pair is
//!   skipped by the self-collision check, merged with the adjacent pairs and
//!   the description's `allowed_collisions` (MoveIt's reasons are not
//!   re-checked; both links must be in the URDF).
//! - `<group_state name=".." group=".."><joint name=".." value=".."/></group_state>`:
//!   a named posture ([`NamedPosture`]); a joint of the configuration takes
//!   the value (inside its limits), a mimic joint's value is ignored (its
//!   leader's decides it), any other name is refused.
//!
//! Groups, end effectors, virtual and passive joints are not read.

use std::path::Path;

use roxmltree::{Document, Node};

use crate::error::KinematicsError;
use crate::math::Real;
use crate::model::RobotModel;

/// A posture named in the SRDF (`group_state`).
#[derive(Debug, Clone, PartialEq)]
pub struct NamedPosture {
    pub name: String,
    /// The SRDF group it belongs to.
    pub group: String,
    /// The values it sets: (configuration index, value).
    pub values: Vec<(usize, Real)>,
}

/// What the SRDF says, by name.
pub(crate) struct Srdf {
    pub(crate) disabled: Vec<[String; 2]>,
    pub(crate) states: Vec<GroupState>,
}

/// A `group_state` as written.
pub(crate) struct GroupState {
    pub(crate) name: String,
    pub(crate) group: String,
    pub(crate) joints: Vec<(String, Real)>,
}

/// The text of the SRDF at `path`, within the file-size bound.
pub(crate) fn read_text(path: &Path) -> Result<String, KinematicsError> {
    let text = crate::load::read_text(path)?;
    crate::bounds::check_file_size(text.len() as u64)
        .map_err(|problem| error(path, "<robot>".into(), problem))?;
    Ok(text)
}

/// The disabled pairs and group states of `text`, the SRDF at `path`, as
/// written (not yet checked against a model).
pub(crate) fn parse_text(path: &Path, text: &str) -> Result<Srdf, KinematicsError> {
    parse(text).map_err(|(element, problem)| error(path, element, problem))
}

/// Reads the SRDF at `path` into `model` (module docs).
pub(crate) fn attach(model: &mut RobotModel, path: &Path) -> Result<(), KinematicsError> {
    let srdf = parse_text(path, &read_text(path)?)?;
    let at = |element: String| move |problem: String| error(path, element.clone(), problem);
    for (k, [a, b]) in srdf.disabled.iter().enumerate() {
        let element = format!("disable_collisions #{}", k + 1);
        let (a, b) = (
            link(model, a).map_err(at(element.clone()))?,
            link(model, b).map_err(at(element))?,
        );
        if a != b {
            model.self_collision_skip.push((a.min(b), a.max(b)));
        }
    }
    model.self_collision_skip.sort_unstable();
    model.self_collision_skip.dedup();
    for state in srdf.states {
        let values =
            (posture(model, &state.joints)).map_err(at(format!("group_state '{}'", state.name)))?;
        model.postures.push(NamedPosture {
            name: state.name,
            group: state.group,
            values,
        });
    }
    Ok(())
}

fn error(path: &Path, element: String, problem: String) -> KinematicsError {
    KinematicsError::Srdf {
        file: path.to_path_buf(),
        element,
        problem,
    }
}

fn link(model: &RobotModel, name: &str) -> Result<usize, String> {
    model
        .link_index(name)
        .map_err(|_| format!("link '{name}' is not in the URDF"))
}

/// The configuration values of a `group_state`'s joints.
fn posture(model: &RobotModel, joints: &[(String, Real)]) -> Result<Vec<(usize, Real)>, String> {
    let mut values = Vec::new();
    for (name, value) in joints {
        match model.joint_index(name) {
            Some(i) if model.joints()[i].within(*value, 1e-9) => values.push((i, *value)),
            Some(i) => {
                let j = &model.joints()[i];
                return Err(format!(
                    "joint '{name}': {value} is outside its limits {} .. {}",
                    j.lower, j.upper
                ));
            }
            None if model.mimic_joints().iter().any(|m| &m.name == name) => {}
            None => return Err(format!("joint '{name}' is not a movable joint of the URDF")),
        }
    }
    Ok(values)
}

type Refusal = (String, String);

fn parse(text: &str) -> Result<Srdf, Refusal> {
    let doc = Document::parse(text).map_err(|e| ("<robot>".into(), e.to_string()))?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(("<robot>".into(), "the root element is not <robot>".into()));
    }
    let elements = |name: &'static str| {
        root.children()
            .filter(move |n| n.is_element() && n.tag_name().name() == name)
    };
    let disabled = (elements("disable_collisions").enumerate())
        .map(|(k, n)| {
            let at = format!("disable_collisions #{}", k + 1);
            Ok([attribute(n, "link1", &at)?, attribute(n, "link2", &at)?])
        })
        .collect::<Result<_, Refusal>>()?;
    let states = (elements("group_state").enumerate())
        .map(|(k, n)| group_state(n, k))
        .collect::<Result<_, Refusal>>()?;
    Ok(Srdf { disabled, states })
}

fn attribute(node: Node<'_, '_>, name: &str, at: &str) -> Result<String, Refusal> {
    node.attribute(name)
        .map(str::to_string)
        .ok_or_else(|| (at.to_string(), format!("has no {name}")))
}

fn group_state(node: Node<'_, '_>, k: usize) -> Result<GroupState, Refusal> {
    let at = format!("group_state #{}", k + 1);
    let name = attribute(node, "name", &at)?;
    let group = attribute(node, "group", &at)?;
    let at = format!("group_state '{name}'");
    let joints = (node.children())
        .filter(|n| n.is_element() && n.tag_name().name() == "joint")
        .map(|j| {
            let joint = attribute(j, "name", &at)?;
            let value = attribute(j, "value", &at)?;
            // A multi-DOF joint's value lists several numbers: not supported.
            match value.trim().parse::<Real>() {
                Ok(v) if v.is_finite() => Ok((joint, v)),
                _ => Err((
                    at.clone(),
                    format!("joint '{joint}': value '{value}' is not one finite number"),
                )),
            }
        })
        .collect::<Result<_, Refusal>>()?;
    Ok(GroupState {
        name,
        group,
        joints,
    })
}
