//! The SRDF elements `init` reads that loading does not: planning groups
//! (`<chain>`, `<joint>` lists, nested `<group>`s), end effectors, and the
//! group states and disabled pairs as written (the loader's `srdf` module
//! checks them against the model later).

use std::path::Path;

use roxmltree::{Document, Node};

use crate::error::KinematicsError;
use crate::math::Real;

/// A planning group as written.
#[derive(Debug, Clone, Default)]
pub(crate) struct Group {
    pub name: String,
    /// `<chain base_link tip_link>`.
    pub chain: Option<(String, String)>,
    pub joints: Vec<String>,
    pub links: Vec<String>,
    pub subgroups: Vec<String>,
}

/// An `<end_effector>`.
#[derive(Debug, Clone)]
pub(crate) struct EndEffector {
    pub parent_link: String,
    /// `parent_group`, else `group`.
    pub parent_group: Option<String>,
    pub group: Option<String>,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct Groups {
    pub groups: Vec<Group>,
    pub end_effectors: Vec<EndEffector>,
    pub states: Vec<(String, Vec<(String, Real)>)>,
    pub disabled: Vec<[String; 2]>,
}

/// Reads the SRDF at `path`.
pub(crate) fn read(path: &Path) -> Result<Groups, KinematicsError> {
    let text = crate::load::read_text(path)?;
    let err = |element: &str, problem: String| KinematicsError::Srdf {
        file: path.to_path_buf(),
        element: element.into(),
        problem,
    };
    let doc = Document::parse(&text).map_err(|e| err("<robot>", e.to_string()))?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(err("<robot>", "the root element is not <robot>".into()));
    }
    let mut out = Groups::default();
    for n in root.children().filter(Node::is_element) {
        let attr = |a: &str| n.attribute(a).map(str::to_string);
        match n.tag_name().name() {
            "group" => out.groups.push(group(n)),
            "end_effector" => match attr("parent_link") {
                Some(parent_link) => out.end_effectors.push(EndEffector {
                    parent_link,
                    parent_group: attr("parent_group"),
                    group: attr("group"),
                }),
                None => return Err(err("end_effector", "has no parent_link".into())),
            },
            "group_state" => {
                let name = attr("name").unwrap_or_default();
                let joints = (n.children())
                    .filter(|j| j.tag_name().name() == "joint")
                    .filter_map(|j| {
                        let v = j.attribute("value")?.trim().parse::<Real>().ok()?;
                        Some((j.attribute("name")?.to_string(), v))
                    })
                    .collect();
                out.states.push((name, joints));
            }
            "disable_collisions" => {
                if let (Some(a), Some(b)) = (attr("link1"), attr("link2")) {
                    out.disabled.push([a, b]);
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

fn group(n: Node<'_, '_>) -> Group {
    let mut g = Group {
        name: n.attribute("name").unwrap_or_default().to_string(),
        ..Group::default()
    };
    for c in n.children().filter(Node::is_element) {
        let name = || c.attribute("name").map(str::to_string);
        match c.tag_name().name() {
            "chain" => {
                if let (Some(b), Some(t)) = (c.attribute("base_link"), c.attribute("tip_link")) {
                    g.chain = Some((b.to_string(), t.to_string()));
                }
            }
            "joint" => g.joints.extend(name()),
            "link" => g.links.extend(name()),
            "group" => g.subgroups.extend(name()),
            _ => {}
        }
    }
    g
}
