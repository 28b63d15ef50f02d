//! The SRDF elements `init` reads that loading does not: planning groups
//! (`<chain>`, `<joint>` lists, nested `<group>`s) and end effectors; the
//! group states and disabled pairs come from the loader's `srdf` module, as
//! written (it checks them against the model when the description loads).

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
    let text = crate::srdf::read_text(path)?;
    let written = crate::srdf::parse_text(path, &text)?;
    let err = |element: &str, problem: String| KinematicsError::Srdf {
        file: path.to_path_buf(),
        element: element.into(),
        problem,
    };
    // `parse_text` has parsed the same text and found its root `<robot>`.
    let doc = Document::parse(&text).map_err(|e| err("<robot>", e.to_string()))?;
    let mut out = Groups {
        states: (written.states.into_iter())
            .map(|s| (s.name, s.joints))
            .collect(),
        disabled: written.disabled,
        ..Groups::default()
    };
    for n in doc.root_element().children().filter(Node::is_element) {
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
