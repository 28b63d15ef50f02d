//! The draft written as description text (format 1), with a comment on
//! each section saying where its values came from.

use std::fmt::Write;
use std::path::{Component, Path, PathBuf};

use super::Draft;
use crate::math::Real;

/// Joint values by name, in the order they are written.
pub type Values = Vec<(String, Real)>;

/// The postures the caller chose: joint values by name (configuration
/// order reads best).
#[derive(Debug, Clone, Default)]
pub struct Postures {
    pub home: Values,
    /// Where home came from (one comment line).
    pub home_source: String,
    /// Per arm (in the draft's order).
    pub park: Vec<Values>,
    pub park_source: String,
}

impl Draft {
    /// The description text for a file in `dir`, without the
    /// `allowed_collisions` block (the caller appends it).
    pub fn to_yaml(&self, dir: &Path, postures: &Postures) -> String {
        let mut y = String::new();
        let _ = writeln!(
            y,
            "# afford robot description, drafted by `afford robots init` from\n# {}{}.\n# Lengths in metres, angles in radians, accelerations in rad/s^2 (m/s^2).",
            file_name(&self.urdf),
            self.srdf
                .as_ref()
                .map_or(String::new(), |s| format!(" and {}", file_name(s)))
        );
        let _ = writeln!(y, "afford_robot: 1\nname: {}", quote(&self.name));
        let _ = writeln!(y, "urdf: {}", quote(&path_text(&relative(&self.urdf, dir))));
        if let Some(s) = &self.srdf {
            let _ = writeln!(y, "# disable_collisions and group_state are read from it.");
            let _ = writeln!(y, "srdf: {}", quote(&path_text(&relative(s, dir))));
        }
        let _ = writeln!(y, "arms:");
        for (i, a) in self.arms.iter().enumerate() {
            let _ = writeln!(
                y,
                "  # From {}; the tool's +z is the approach axis.",
                a.source
            );
            let _ = writeln!(
                y,
                "  - name: {}\n    root: {}\n    tool: {}",
                quote(&a.name),
                quote(&a.root),
                quote(&a.tool)
            );
            let joints: Vec<String> = a.joints.iter().map(|j| quote(j)).collect();
            let _ = writeln!(y, "    joints: [{}]", joints.join(", "));
            if let Some(park) = postures.park.get(i).filter(|p| !p.is_empty()) {
                let _ = writeln!(y, "    # {}", postures.park_source);
                let _ = writeln!(y, "    park: {}", map(park));
            }
        }
        if !postures.home_source.is_empty() {
            let _ = writeln!(y, "# {}", postures.home_source);
        }
        match postures.home.is_empty() {
            true => y.push_str("home: {}\n"),
            false => {
                let _ = writeln!(y, "home:");
                for (j, v) in &postures.home {
                    let _ = writeln!(y, "  {}: {}", quote(j), number(*v));
                }
            }
        }
        if !self.acceleration_limits.is_empty() {
            let _ = writeln!(
                y,
                "# Not in the URDF: each joint's velocity limit reached in {} s (afford robots init's default).",
                super::DEFAULT_ACCELERATION_RAMP_S
            );
            let _ = writeln!(y, "acceleration_limits:");
            for (j, v) in &self.acceleration_limits {
                let _ = writeln!(y, "  {}: {}", quote(j), number(*v));
            }
        }
        let _ = writeln!(
            y,
            "# No jerk_limits: each joint takes the URDF <limit jerk>, else its acceleration limit over {} s.",
            crate::DEFAULT_JERK_RAMP_S
        );
        let g = &self.gripper;
        let _ = writeln!(
            y,
            "# Opening from the finger joints' limits when they have them; times are afford's default."
        );
        let _ = writeln!(y, "gripper:");
        let _ = writeln!(
            y,
            "  max_opening: {}\n  finger_length: {}",
            number(g.max_opening),
            number(g.finger_length)
        );
        let _ = writeln!(
            y,
            "  closing_time: {}\n  opening_time: {}",
            number(g.closing_time),
            number(g.opening_time)
        );
        let fingers: Vec<String> = g.fingers.iter().map(|f| quote(f)).collect();
        let _ = writeln!(y, "  fingers: [{}]", fingers.join(", "));
        y
    }
}

fn map(m: &[(String, Real)]) -> String {
    let parts: Vec<String> = m
        .iter()
        .map(|(k, v)| format!("{}: {}", quote(k), number(*v)))
        .collect();
    format!("{{{}}}", parts.join(", "))
}

/// A number as YAML reads it back (6 decimals, no `-0`).
fn number(v: Real) -> String {
    let r = super::round(v, 6);
    let r = if r == 0.0 { 0.0 } else { r };
    format!("{r}")
}

/// A YAML scalar: plain when safe, else single-quoted.
fn quote(s: &str) -> String {
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./#".contains(c))
        && !s.starts_with(['-', '.', '#'])
        && s.parse::<f64>().is_err()
        && !matches!(
            s.to_ascii_lowercase().as_str(),
            "true" | "false" | "null" | "yes" | "no" | "on" | "off" | "y" | "n" | "~"
        );
    match plain {
        true => s.to_string(),
        false => format!("'{}'", s.replace('\'', "''")),
    }
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into())
}

fn path_text(p: &Path) -> String {
    p.to_string_lossy().replace('\\', "/")
}

/// `target` relative to the folder `dir` (both made absolute); `target`
/// itself when they share no root.
pub fn relative(target: &Path, dir: &Path) -> PathBuf {
    let abs = |p: &Path| {
        std::fs::canonicalize(p)
            .unwrap_or_else(|_| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()))
    };
    let (t, d) = (abs(target), abs(dir));
    let tc: Vec<Component> = t.components().collect();
    let dc: Vec<Component> = d.components().collect();
    let common = tc.iter().zip(&dc).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return t;
    }
    let mut out = PathBuf::new();
    for _ in common..dc.len() {
        out.push("..");
    }
    for c in &tc[common..] {
        out.push(c.as_os_str());
    }
    out
}
