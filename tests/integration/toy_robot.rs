//! A small published-style robot written into a scratch folder: a 6-joint
//! arm with a two-finger gripper (one finger a mimic joint), its collision
//! meshes as generated STL and OBJ files in a `toy_description` package,
//! a URDF naming them by `package://`, and a MoveIt SRDF.

use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Where the files of one toy robot are.
pub struct Toy {
    pub urdf: PathBuf,
    pub srdf: PathBuf,
    /// The folder holding `toy_description/`.
    pub packages: PathBuf,
}

/// Where the package goes, relative to the URDF.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// `DIR/toy_description/{urdf,meshes,srdf}`: found from the URDF's folder.
    Beside,
    /// Meshes in `DIR/elsewhere/toy_description/meshes`, URDF in
    /// `DIR/robot/`: found only through a package path.
    Apart,
}

/// The triangles of a box centred at `c` with half sizes `h`.
fn box_triangles(c: [f64; 3], h: [f64; 3]) -> Vec<[[f64; 3]; 3]> {
    let p = |sx: f64, sy: f64, sz: f64| [c[0] + sx * h[0], c[1] + sy * h[1], c[2] + sz * h[2]];
    let quads = [
        [
            p(-1., -1., -1.),
            p(-1., 1., -1.),
            p(1., 1., -1.),
            p(1., -1., -1.),
        ],
        [
            p(-1., -1., 1.),
            p(1., -1., 1.),
            p(1., 1., 1.),
            p(-1., 1., 1.),
        ],
        [
            p(-1., -1., -1.),
            p(1., -1., -1.),
            p(1., -1., 1.),
            p(-1., -1., 1.),
        ],
        [
            p(-1., 1., -1.),
            p(-1., 1., 1.),
            p(1., 1., 1.),
            p(1., 1., -1.),
        ],
        [
            p(-1., -1., -1.),
            p(-1., -1., 1.),
            p(-1., 1., 1.),
            p(-1., 1., -1.),
        ],
        [
            p(1., -1., -1.),
            p(1., 1., -1.),
            p(1., 1., 1.),
            p(1., -1., 1.),
        ],
    ];
    quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect()
}

/// ASCII STL of a box.
pub fn stl_box(c: [f64; 3], h: [f64; 3]) -> String {
    let mut s = String::from("solid part\n");
    for t in box_triangles(c, h) {
        s.push_str("  facet normal 0 0 0\n    outer loop\n");
        for v in t {
            let _ = writeln!(s, "      vertex {} {} {}", v[0], v[1], v[2]);
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str("endsolid part\n");
    s
}

/// Wavefront OBJ of a box.
pub fn obj_box(c: [f64; 3], h: [f64; 3]) -> String {
    let mut s = String::new();
    let tris = box_triangles(c, h);
    for t in &tris {
        for v in t {
            let _ = writeln!(s, "v {} {} {}", v[0], v[1], v[2]);
        }
    }
    for k in 0..tris.len() {
        let _ = writeln!(s, "f {} {} {}", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    s
}

/// The arm's links: name, mesh file, box centre and half sizes (link frame).
const LINKS: [(&str, &str, [f64; 3], [f64; 3]); 7] = [
    (
        "base_link",
        "base.stl",
        [0.0, 0.0, 0.05],
        [0.06, 0.06, 0.05],
    ),
    ("link1", "link1.stl", [0.0, 0.0, 0.1], [0.04, 0.04, 0.1]),
    ("link2", "link2.obj", [0.0, 0.0, 0.175], [0.03, 0.03, 0.175]),
    ("link3", "link3.stl", [0.0, 0.0, 0.15], [0.025, 0.025, 0.15]),
    (
        "link4",
        "link4.stl",
        [0.0, 0.0, 0.025],
        [0.025, 0.025, 0.02],
    ),
    (
        "link5",
        "link5.stl",
        [0.0, 0.0, 0.025],
        [0.025, 0.025, 0.02],
    ),
    ("link6", "hand.obj", [0.0, 0.0, 0.03], [0.02, 0.05, 0.025]),
];

/// Joint above each of LINKS[1..]: name, axis, origin z in the parent.
const JOINTS: [(&str, &str, f64); 6] = [
    ("joint1", "0 0 1", 0.1),
    ("joint2", "0 1 0", 0.2),
    ("joint3", "0 1 0", 0.35),
    ("joint4", "0 0 1", 0.3),
    ("joint5", "0 1 0", 0.05),
    ("joint6", "0 0 1", 0.05),
];

/// The URDF text. `visual` adds a visual mesh to link3 of that half size
/// (a model whose collision box leaves it outside when it is larger);
/// `fingers: false` leaves the gripper out (a bare flange, `link6`).
pub fn urdf(visual: Option<[f64; 3]>, fingers: bool) -> String {
    let mut u = String::from("<?xml version=\"1.0\"?>\n<robot name=\"toy_arm\">\n");
    for (i, (name, file, _, _)) in LINKS.iter().enumerate() {
        let mesh = format!("package://toy_description/meshes/{file}");
        let _ = writeln!(u, "  <link name=\"{name}\">");
        let _ = writeln!(
            u,
            "    <collision><geometry><mesh filename=\"{mesh}\"/></geometry></collision>"
        );
        if let (Some(_), 3) = (visual, i) {
            u.push_str("    <visual><geometry><mesh filename=\"package://toy_description/meshes/link3_visual.stl\"/></geometry></visual>\n");
        }
        u.push_str("  </link>\n");
        if i + 1 < LINKS.len() {
            let (joint, axis, z) = JOINTS[i];
            let child = LINKS[i + 1].0;
            let _ = writeln!(
                u,
                "  <joint name=\"{joint}\" type=\"revolute\"><parent link=\"{name}\"/><child link=\"{child}\"/><origin xyz=\"0 0 {z}\"/><axis xyz=\"{axis}\"/><limit lower=\"-2.9\" upper=\"2.9\" velocity=\"2.0\" effort=\"50\"/></joint>"
            );
        }
    }
    let sides = [
        ("left", "0 1 0", ""),
        ("right", "0 -1 0", "<mimic joint=\"finger_left_joint\"/>"),
    ];
    for (side, axis, mimic) in sides.into_iter().filter(|_| fingers) {
        let y = if side == "left" { 0.005 } else { -0.005 };
        let _ = writeln!(
            u,
            "  <link name=\"finger_{side}\"><collision><origin xyz=\"0 {y} 0.025\"/><geometry><box size=\"0.015 0.01 0.05\"/></geometry></collision></link>"
        );
        let _ = writeln!(
            u,
            "  <joint name=\"finger_{side}_joint\" type=\"prismatic\"><parent link=\"link6\"/><child link=\"finger_{side}\"/><origin xyz=\"0 0 0.055\"/><axis xyz=\"{axis}\"/><limit lower=\"0\" upper=\"0.03\" velocity=\"0.1\" effort=\"20\"/>{mimic}</joint>"
        );
    }
    if fingers {
        u.push_str("  <link name=\"tcp\"/>\n  <joint name=\"tcp_joint\" type=\"fixed\"><parent link=\"link6\"/><child link=\"tcp\"/><origin xyz=\"0 0 0.1\"/></joint>\n");
    }
    u.push_str("</robot>\n");
    u
}

/// The SRDF: a chain group, the hand as end effector, a ready posture and
/// one disabled pair.
pub const SRDF: &str = r#"<?xml version="1.0"?>
<robot name="toy_arm">
  <group name="manipulator"><chain base_link="base_link" tip_link="tcp"/></group>
  <group name="hand"><joint name="finger_left_joint"/></group>
  <group_state name="ready" group="manipulator">
    <joint name="joint2" value="0.4"/><joint name="joint3" value="1.4"/><joint name="joint5" value="1.3"/>
  </group_state>
  <end_effector name="gripper" parent_link="tcp" group="hand" parent_group="manipulator"/>
  <disable_collisions link1="base_link" link2="link2" reason="Never"/>
</robot>
"#;

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().expect("folder")).expect("create folder");
    std::fs::write(path, text).expect("write file");
}

/// Writes the toy robot into `dir` (see [`Layout`]); `visual` as for [`urdf`].
pub fn write_toy(dir: &Path, layout: Layout, visual: Option<[f64; 3]>) -> Toy {
    write_toy_with(dir, layout, visual, true)
}

/// As [`write_toy`]; `fingers` as for [`urdf`].
pub fn write_toy_with(dir: &Path, layout: Layout, visual: Option<[f64; 3]>, fingers: bool) -> Toy {
    let (package, urdf_dir, packages) = match layout {
        Layout::Beside => (
            dir.join("toy_description"),
            dir.join("toy_description/urdf"),
            dir.to_path_buf(),
        ),
        Layout::Apart => (
            dir.join("elsewhere/toy_description"),
            dir.join("robot"),
            dir.join("elsewhere"),
        ),
    };
    for (_, file, c, h) in LINKS {
        let text = match file.ends_with(".obj") {
            true => obj_box(c, h),
            false => stl_box(c, h),
        };
        write(&package.join("meshes").join(file), &text);
    }
    if let Some(h) = visual {
        write(
            &package.join("meshes/link3_visual.stl"),
            &stl_box([0.0, 0.0, 0.15], h),
        );
    }
    let urdf_path = urdf_dir.join("toy_arm.urdf");
    write(&urdf_path, &urdf(visual, fingers));
    let srdf = urdf_dir.join("toy_arm.srdf");
    write(&srdf, SRDF);
    Toy {
        urdf: urdf_path,
        srdf,
        packages,
    }
}
