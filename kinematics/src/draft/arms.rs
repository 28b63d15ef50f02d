//! The arms of a draft: the SRDF's planning groups (a `<chain>` or a joint
//! list, with the end effector's parent link as tool), else the longest
//! serial chain of movable joints from the URDF root to a leaf, finger and
//! mimic joints left out. Every arm starts at the URDF root link.

use std::collections::BTreeSet;
use std::path::Path;

use super::DraftArm;
use super::groups::{Group, Groups};
use crate::error::KinematicsError;
use crate::model::JointKind;
use crate::urdf::Tree;

/// Arms from the SRDF's groups (empty when none is usable).
pub(super) fn from_srdf(
    tree: &Tree,
    g: &Groups,
    fingers: &BTreeSet<String>,
    srdf: &Path,
) -> Result<Vec<DraftArm>, KinematicsError> {
    let mut names: Vec<&str> = Vec::new();
    for e in &g.end_effectors {
        for n in [&e.parent_group, &e.group].into_iter().flatten() {
            if !names.contains(&n.as_str()) {
                names.push(n);
            }
        }
    }
    if names.is_empty() {
        names = g.groups.iter().map(|g| g.name.as_str()).collect();
    }
    let mut arms: Vec<DraftArm> = Vec::new();
    for name in names {
        let Some(group) = g.groups.iter().find(|x| x.name == name) else {
            continue;
        };
        let Some(arm) = arm_of(tree, g, group, fingers, srdf)? else {
            continue;
        };
        if arm.joints.len() >= 2 && !arms.iter().any(|a| a.joints == arm.joints) {
            arms.push(arm);
        }
    }
    Ok(arms)
}

/// The arm of one group, `None` when it holds no arm joints.
fn arm_of(
    tree: &Tree,
    g: &Groups,
    group: &Group,
    fingers: &BTreeSet<String>,
    srdf: &Path,
) -> Result<Option<DraftArm>, KinematicsError> {
    let err = |problem: String| KinematicsError::Srdf {
        file: srdf.to_path_buf(),
        element: format!("group '{}'", group.name),
        problem,
    };
    let link = |name: &str| {
        (tree.links.iter().position(|l| l.name == name))
            .ok_or_else(|| err(format!("link '{name}' is not in the URDF")))
    };
    let end_effector = (g.end_effectors.iter())
        .find(|e| e.parent_group.as_deref() == Some(&group.name))
        .or_else(|| (g.end_effectors.iter()).find(|e| e.group.as_deref() == Some(&group.name)));
    let (joints, tip) = match &group.chain {
        Some((_, tip)) => {
            let tip = link(tip)?;
            (arm_joints(tree, &path_to(tree, tip), fingers), Some(tip))
        }
        None => {
            let mut listed: Vec<usize> = (tree.links.iter().enumerate())
                .filter(|(_, l)| {
                    l.joint.as_ref().is_some_and(|j| {
                        group.joints.contains(&j.name) && movable(tree, l.joint.as_ref())
                    })
                })
                .map(|(i, _)| i)
                .collect();
            listed.retain(|&i| !is_finger(tree, i, fingers));
            (listed, None)
        }
    };
    let Some(&last) = joints.last() else {
        return Ok(None);
    };
    let tool = match (end_effector, tip) {
        (Some(e), _) => link(&e.parent_link)?,
        (None, Some(tip)) => tip,
        (None, None) => tool_below(tree, last),
    };
    let on_path = arm_joints(tree, &path_to(tree, tool), fingers);
    let all_movable = path_to(tree, tool)
        .into_iter()
        .filter(|&l| movable(tree, tree.links[l].joint.as_ref()))
        .count();
    if on_path != joints || all_movable != joints.len() {
        return Err(err(format!(
            "its joints are not the movable joints from the root to tool link '{}' in order",
            tree.links[tool].name
        )));
    }
    Ok(Some(DraftArm {
        name: group.name.clone(),
        root: tree.links[0].name.clone(),
        tool: tree.links[tool].name.clone(),
        joints: names(tree, &joints),
        source: format!("SRDF group '{}'", group.name),
    }))
}

/// The longest serial chain from the root to a leaf, counted in movable
/// joints that are not fingers; its tool is found below its last joint.
pub(super) fn longest_chain(
    tree: &Tree,
    fingers: &BTreeSet<String>,
    guesses: &mut Vec<String>,
) -> Option<DraftArm> {
    let leaves = (0..tree.links.len()).filter(|&i| !tree.links.iter().any(|l| l.parent == Some(i)));
    let mut best: Option<Vec<usize>> = None;
    for leaf in leaves {
        let joints = arm_joints(tree, &path_to(tree, leaf), fingers);
        if best.as_ref().is_none_or(|b| joints.len() > b.len()) {
            best = Some(joints);
        }
    }
    let joints = best.filter(|j| !j.is_empty())?;
    let tool = tool_below(tree, *joints.last()?);
    let names = names(tree, &joints);
    guesses.push(format!(
        "arms[0]: the longest serial chain from '{}': {} joints, tool link '{}' (the fixed frame below the last joint named like tcp/tool/flange/ee, else the deepest)",
        tree.links[0].name,
        names.len(),
        tree.links[tool].name
    ));
    Some(DraftArm {
        name: "arm".into(),
        root: tree.links[0].name.clone(),
        tool: tree.links[tool].name.clone(),
        joints: names,
        source: "the longest chain".into(),
    })
}

/// Links from below the root down to `l`, root side first.
fn path_to(tree: &Tree, l: usize) -> Vec<usize> {
    let mut path = vec![l];
    let mut cur = l;
    while let Some(p) = tree.links[cur].parent {
        if p == 0 {
            break;
        }
        path.push(p);
        cur = p;
    }
    path.reverse();
    path
}

fn movable(_tree: &Tree, j: Option<&crate::urdf::TreeJoint>) -> bool {
    j.is_some_and(|j| j.kind != JointKind::Fixed)
}

fn is_finger(tree: &Tree, l: usize, fingers: &BTreeSet<String>) -> bool {
    tree.links[l]
        .joint
        .as_ref()
        .is_some_and(|j| j.resolved.is_some() || fingers.contains(&j.name))
}

/// The links along `path` whose joint is an arm joint, up to the first
/// finger or mimic joint.
fn arm_joints(tree: &Tree, path: &[usize], fingers: &BTreeSet<String>) -> Vec<usize> {
    let mut out = Vec::new();
    for &l in path {
        if is_finger(tree, l, fingers) {
            break;
        }
        if movable(tree, tree.links[l].joint.as_ref()) {
            out.push(l);
        }
    }
    out
}

fn names(tree: &Tree, links: &[usize]) -> Vec<String> {
    (links.iter())
        .filter_map(|&l| tree.links[l].joint.as_ref().map(|j| j.name.clone()))
        .collect()
}

/// The tool link below link `l`: among `l` and the links fixed to it, the
/// best named (tcp, grasp > tool > flange, ee, hand), else the deepest.
pub(super) fn tool_below(tree: &Tree, l: usize) -> usize {
    let mut fixed = vec![(l, 0usize)];
    let mut k = 0;
    while k < fixed.len() {
        let (p, depth) = fixed[k];
        for (i, c) in tree.links.iter().enumerate() {
            if c.parent == Some(p) && c.joint.as_ref().is_some_and(|j| j.kind == JointKind::Fixed) {
                fixed.push((i, depth + 1));
            }
        }
        k += 1;
    }
    let score = |i: usize| {
        let n = tree.links[i].name.to_ascii_lowercase();
        let has = |words: &[&str]| words.iter().any(|w| n.contains(w));
        match () {
            _ if has(&["tcp", "grasp", "tool_center", "fingertip"]) => 3,
            _ if has(&["tool"]) => 2,
            _ if has(&["flange", "ee", "end_effector", "hand"]) => 1,
            _ => 0,
        }
    };
    // Best name, then deepest, then first in tree order.
    (fixed.iter())
        .max_by_key(|&&(i, d)| (score(i), d, std::cmp::Reverse(i)))
        .map_or(l, |&(i, _)| i)
}
