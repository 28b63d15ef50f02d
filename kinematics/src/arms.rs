//! Arms: one serial chain of a robot description from its root link to its
//! tool link, checked against the URDF (the root fixed to the base, the
//! listed joints exactly the movable ones between, no mimic joint among
//! them) and folded into the solvers' compact chain.

use crate::chain::{Chain, ChainJoint, MAX_DOF, Motion};
use crate::description::ArmDescription;
use crate::error::KinematicsError;
use crate::load::value_in_bounds;
use crate::math::{Pose, Real};
use crate::model::{Arm, Joint, JointDrive, JointKind, Link};
use crate::urdf::Tree;

/// What an arm is checked against; `err` builds the description's errors.
pub(crate) struct Robot<'a, E> {
    pub tree: &'a Tree,
    pub links: &'a [Link],
    pub joints: &'a [Joint],
    pub home: &'a [Real],
    pub err: &'a E,
}

impl<E: Fn(String, String) -> KinematicsError> Robot<'_, E> {
    /// Arm `ai` of the description.
    pub(crate) fn arm(&self, ai: usize, ad: &ArmDescription) -> Result<Arm, KinematicsError> {
        let at = |field: &str| format!("arms[{ai}].{field}");
        let root = self.link(&ad.root, at("root"))?;
        let tool = self.link(&ad.tool, at("tool"))?;
        let path = self.path(root, tool, ad, at("tool"))?;
        let base = self.base(root, ad, at("root"))?;
        let listed = self.listed(&path, ad, ai)?;
        let chain = self.fold(base, &path);
        let lower: Vec<Real> = listed.iter().map(|&i| self.joints[i].lower).collect();
        let upper: Vec<Real> = listed.iter().map(|&i| self.joints[i].upper).collect();
        let park = self.park(ad, ai)?;
        let reach = chain.reach_bound(&upper, &lower);
        Ok(Arm {
            name: ad.name.clone(),
            root_link: ad.root.clone(),
            tool_link: ad.tool.clone(),
            joint_names: ad.joints.clone(),
            home: listed.iter().map(|&i| self.home[i]).collect(),
            joint_indices: listed,
            lower,
            upper,
            park,
            reach,
            chain,
        })
    }

    fn link(&self, name: &str, field: String) -> Result<usize, KinematicsError> {
        (self.links.iter().position(|l| l.name == name))
            .ok_or_else(|| (self.err)(field, format!("link '{name}' is not in the URDF")))
    }

    fn joint(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The links from below `root` down to `tool`, root side first.
    fn path(
        &self,
        root: usize,
        tool: usize,
        ad: &ArmDescription,
        field: String,
    ) -> Result<Vec<usize>, KinematicsError> {
        let mut path = Vec::new();
        let mut cur = tool;
        while cur != root {
            path.push(cur);
            cur = self.links[cur].parent.ok_or_else(|| {
                (self.err)(
                    field.clone(),
                    format!(
                        "link '{}' does not hang below root link '{}'",
                        ad.tool, ad.root
                    ),
                )
            })?;
        }
        path.reverse();
        Ok(path)
    }

    /// The pose of the root link in the base frame; the root must be fixed
    /// to the base.
    fn base(
        &self,
        root: usize,
        ad: &ArmDescription,
        field: String,
    ) -> Result<Pose, KinematicsError> {
        let mut base = Pose::identity();
        let mut up = Some(root);
        while let Some(i) = up {
            if let Some(drive) = self.links[i].joint {
                return Err((self.err)(
                    field,
                    format!(
                        "link '{}' moves with joint '{}'; start the arm lower or list that joint among its joints",
                        ad.root, self.joints[drive.joint].name
                    ),
                ));
            }
            base = self.links[i].origin * base;
            up = self.links[i].parent;
        }
        Ok(base)
    }

    /// The configuration indices of the arm's joints, which must be the
    /// movable joints along `path` in order, none of them a mimic joint.
    fn listed(
        &self,
        path: &[usize],
        ad: &ArmDescription,
        ai: usize,
    ) -> Result<Vec<usize>, KinematicsError> {
        let err = |problem: String| (self.err)(format!("arms[{ai}].joints"), problem);
        if let Some(m) = path.iter().find_map(|&l| self.mimic_name(l)) {
            return Err(err(format!(
                "mimic joint '{m}' lies between '{}' and '{}'; an arm's chain cannot hold a mimic joint",
                ad.root, ad.tool
            )));
        }
        let movable: Vec<usize> = (path.iter())
            .filter_map(|&l| self.links[l].joint.map(|d| d.joint))
            .collect();
        let listed: Vec<usize> = (ad.joints.iter().enumerate())
            .map(|(k, n)| {
                self.joint(n).ok_or_else(|| {
                    (self.err)(
                        format!("arms[{ai}].joints[{k}]"),
                        format!("'{n}' is not a movable joint of the URDF"),
                    )
                })
            })
            .collect::<Result<_, _>>()?;
        if listed != movable {
            let names: Vec<&str> = (movable.iter())
                .map(|&i| self.joints[i].name.as_str())
                .collect();
            return Err(err(format!(
                "must list the movable joints from '{}' to '{}' in order: [{}]",
                ad.root,
                ad.tool,
                names.join(", ")
            )));
        }
        if listed.len() > MAX_DOF {
            return Err(err(format!(
                "at most {MAX_DOF} joints per arm are supported"
            )));
        }
        Ok(listed)
    }

    /// The name of the mimic joint above link `l`, if it has one.
    fn mimic_name(&self, l: usize) -> Option<&str> {
        self.links[l].joint?.mimic?;
        self.tree.links[l].joint.as_ref().map(|j| j.name.as_str())
    }

    /// The compact chain: fixed transforms folded into the next movable
    /// joint's origin.
    fn fold(&self, base: Pose, path: &[usize]) -> Chain {
        let mut joints = Vec::with_capacity(path.len());
        let mut pending = base;
        for &l in path {
            let link = &self.links[l];
            pending *= link.origin;
            if let Some(JointDrive { axis, kind, .. }) = link.joint {
                joints.push(ChainJoint {
                    origin: pending,
                    axis,
                    motion: if kind == JointKind::Prismatic {
                        Motion::Prismatic
                    } else {
                        Motion::Revolute
                    },
                });
                pending = Pose::identity();
            }
        }
        Chain {
            joints,
            tool: pending,
        }
    }

    /// The arm's park posture: (configuration index, value) pairs.
    fn park(&self, ad: &ArmDescription, ai: usize) -> Result<Vec<(usize, Real)>, KinematicsError> {
        let mut park = Vec::with_capacity(ad.park.len());
        for (name, &v) in &ad.park {
            let field = || format!("arms[{ai}].park.{name}");
            let i = (self.joint(name))
                .ok_or_else(|| (self.err)(field(), "is not a movable joint of the URDF".into()))?;
            if !self.joints[i].within(v, 1e-9) || !value_in_bounds(self.joints[i].kind, v) {
                return Err((self.err)(
                    field(),
                    format!("{v} is outside the joint limits"),
                ));
            }
            park.push((i, v));
        }
        Ok(park)
    }
}
