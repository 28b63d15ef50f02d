//! An assumed gripper for an arm whose URDF has none (a bare flange): the
//! built-in iiwa's assumed parallel gripper (robots/README.md), mounted on
//! the tool link, written into a copy of the URDF. The copy names every
//! mesh by the absolute path it resolves to, so it loads from any folder.

use std::path::Path;

use crate::error::KinematicsError;
use crate::mesh::{PackagePaths, resolve};

/// The link of the assumed gripper's colliders.
pub const GRIPPER_LINK: &str = "afford_gripper";
/// Its grasp point, 0.15 m beyond the flange: the tool of the arm.
pub const TCP_LINK: &str = "afford_tcp";
/// Its finger box, the grasp region.
pub const FINGERS: &str = "afford_gripper#1";

/// `text` (the URDF at `urdf`) with absolute mesh paths and the assumed
/// gripper fixed to link `tool` (its +z the approach axis).
pub fn with_assumed_gripper(
    text: &str,
    urdf: &Path,
    packages: &PackagePaths,
    tool: &str,
) -> Result<String, KinematicsError> {
    let dir = urdf.parent().unwrap_or_else(|| Path::new("."));
    let mut out = String::with_capacity(text.len() + 1024);
    let mut rest = text;
    while let Some(at) = rest.find("filename=") {
        let (head, tail) = rest.split_at(at + "filename=".len());
        out.push_str(head);
        let Some(quote) = tail.chars().next().filter(|c| *c == '"' || *c == '\'') else {
            rest = tail;
            continue;
        };
        let Some(end) = tail[1..].find(quote) else {
            rest = tail;
            continue;
        };
        let value = &tail[1..1 + end];
        let resolved = resolve::resolve(&unescape(value), dir, packages)
            .ok()
            .and_then(|p| std::path::absolute(p).ok());
        out.push(quote);
        match resolved {
            Some(p) => out.push_str(&escape(&p.to_string_lossy())),
            None => out.push_str(value),
        }
        out.push(quote);
        rest = &tail[end + 2..];
    }
    out.push_str(rest);
    let Some(close) = out.rfind("</robot>") else {
        return Err(KinematicsError::UrdfElement {
            file: urdf.to_path_buf(),
            element: "<robot>".into(),
            problem: "has no closing </robot>".into(),
        });
    };
    let tool = escape(tool);
    let gripper = format!(
        r#"  <!-- afford robots init: an assumed parallel gripper (the URDF has none): a palm
       capsule, a finger box covering both fingers, the grasp point 0.15 m beyond the flange. -->
  <link name="{GRIPPER_LINK}">
    <collision><origin xyz="0 0 0.055"/><geometry><capsule radius="0.045" length="0.04"/></geometry></collision>
    <collision><origin xyz="0 0 0.14"/><geometry><box size="0.02 0.1 0.05"/></geometry></collision>
  </link>
  <joint name="{GRIPPER_LINK}_mount" type="fixed"><parent link="{tool}"/><child link="{GRIPPER_LINK}"/><origin xyz="0 0 0"/></joint>
  <link name="{TCP_LINK}"/>
  <joint name="{TCP_LINK}_joint" type="fixed"><parent link="{GRIPPER_LINK}"/><child link="{TCP_LINK}"/><origin xyz="0 0 0.15"/></joint>
"#
    );
    out.insert_str(close, &gripper);
    Ok(out)
}

fn unescape(s: &str) -> String {
    s.replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
