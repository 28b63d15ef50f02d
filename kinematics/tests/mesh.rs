//! Collision meshes: every format loads as the hull of its vertices, `scale`
//! applies per axis, `package://` resolves through each search-path source
//! in order, and every refusal is an error naming the URDF, the link and
//! the mesh. The meshes are written by the tests into a scratch folder
//! (the OBJ and DAE boxes are tiny text fixtures).

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use afford_kinematics::{KinematicsError, MeshProblem, PackagePaths, RobotModel, Shape, Vec3};

/// Half sizes of the fixture box (`tests/fixtures/meshes/box.*`).
const HALF: [f64; 3] = [0.05, 0.1, 0.15];

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/meshes")
        .join(name)
}

/// An empty folder of its own for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("afford-mesh-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The box's 12 triangles (outward winding), corners at ±`HALF`.
fn box_triangles(scale: f64) -> Vec<[[f64; 3]; 3]> {
    let c = |i: usize| {
        let s = |bit: usize, h: f64| if i & bit != 0 { h * scale } else { -h * scale };
        [s(1, HALF[0]), s(2, HALF[1]), s(4, HALF[2])]
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [1, 3, 7, 5],
        [3, 2, 6, 7],
        [2, 0, 4, 6],
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

fn write_binary_stl(path: &Path, scale: f64) {
    let f32s = |p: [f64; 3]| stl_io::Vector::new(p.map(|x| x as f32));
    let triangles: Vec<stl_io::Triangle> = box_triangles(scale)
        .into_iter()
        .map(|t| stl_io::Triangle {
            normal: stl_io::Vector::new([0.0; 3]),
            vertices: t.map(f32s),
        })
        .collect();
    let mut file = std::fs::File::create(path).unwrap();
    stl_io::write_stl(&mut file, triangles.iter()).unwrap();
}

fn write_ascii_stl(path: &Path) {
    let mut text = String::from("solid box\n");
    for t in box_triangles(1.0) {
        text += "facet normal 0 0 0\nouter loop\n";
        for v in t {
            text += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
        }
        text += "endloop\nendfacet\n";
    }
    std::fs::write(path, text + "endsolid box\n").unwrap();
}

/// Writes `robot.urdf` (link `part` with the mesh) and `robot.yaml` into
/// `dir`; returns the description's path.
fn write_robot(dir: &Path, mesh: &str) -> PathBuf {
    let urdf = format!(
        r#"<robot name="mesh_robot" version="1.2">
  <link name="base"/>
  <link name="part"><collision><geometry>{mesh}</geometry></collision></link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="part"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="2" effort="5" acceleration="5"/>
  </joint>
</robot>"#
    );
    std::fs::write(dir.join("robot.urdf"), urdf).unwrap();
    let yaml = "afford_robot: 1\nname: mesh_robot\nurdf: robot.urdf\narms:\n  - {name: arm, root: base, tool: part, joints: [j1]}\ngripper: {max_opening: 0.06, finger_length: 0.04}\n";
    std::fs::write(dir.join("robot.yaml"), yaml).unwrap();
    dir.join("robot.yaml")
}

fn mesh_element(filename: &str) -> String {
    format!(r#"<mesh filename="{filename}"/>"#)
}

fn load(dir: &Path, mesh: &str, packages: &PackagePaths) -> Result<RobotModel, KinematicsError> {
    RobotModel::from_path_with(&write_robot(dir, mesh), packages)
}

fn no_environment() -> PackagePaths {
    PackagePaths::with_environment(Vec::new(), None, None)
}

/// The hull vertices of link `part`, sorted.
fn hull(model: &RobotModel) -> Vec<Vec3> {
    let part = model.link_index("part").unwrap();
    let Shape::ConvexHull { vertices } = &model.links()[part].colliders[0].shape else {
        panic!("part's collider is not a mesh hull");
    };
    let mut v = vertices.to_vec();
    v.sort_by(|a, b| a.iter().partial_cmp(b.iter()).unwrap());
    v
}

/// Asserts that `vertices` are the 8 corners of the box ±`half`.
fn assert_box_corners(vertices: &[Vec3], half: [f64; 3]) {
    assert_eq!(vertices.len(), 8, "{vertices:?}");
    for v in vertices {
        for k in 0..3 {
            assert!(
                (v[k].abs() - half[k]).abs() < 1e-6,
                "{v:?} is no corner of ±{half:?}"
            );
        }
    }
}

#[test]
fn a_box_mesh_in_every_format_becomes_the_box_corners() {
    let dir = scratch("formats");
    write_binary_stl(&dir.join("box_binary.stl"), 1.0);
    write_ascii_stl(&dir.join("box_ascii.STL"));
    for file in ["box.obj", "box.dae"] {
        std::fs::copy(fixture(file), dir.join(file)).unwrap();
    }
    for file in ["box_binary.stl", "box_ascii.STL", "box.obj", "box.dae"] {
        let m = load(&dir, &mesh_element(file), &no_environment()).unwrap();
        assert_box_corners(&hull(&m), HALF);
    }
}

#[test]
fn mesh_scale_multiplies_each_axis() {
    let dir = scratch("scale");
    let mesh = format!(
        r#"<mesh filename="{}" scale="2 1 0.5"/>"#,
        fixture("box.obj").display()
    );
    let m = load(&dir, &mesh, &no_environment()).unwrap();
    assert_box_corners(&hull(&m), [0.1, 0.1, 0.075]);
}

/// A package `name` under `root` whose mesh is the box scaled by `scale`.
fn package(root: &Path, name: &str, scale: f64) {
    let meshes = root.join(name).join("meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    write_binary_stl(&meshes.join("part.stl"), scale);
}

const PACKAGE_MESH: &str = r#"<mesh filename="package://parts/meshes/part.stl"/>"#;

#[test]
fn package_uri_resolves_through_each_search_path_source() {
    let dir = scratch("package-sources");
    let robot = dir.join("robot");
    std::fs::create_dir_all(&robot).unwrap();
    let (explicit, ros, ament) = (dir.join("explicit"), dir.join("ros"), dir.join("ament"));
    let ros_path = std::env::join_paths([Path::new("/nonexistent"), &ros]).unwrap();
    let sources = [
        (
            explicit.clone(),
            PackagePaths::with_environment(vec![explicit.clone()], None, None),
        ),
        (
            ros.clone(),
            PackagePaths::with_environment(Vec::new(), Some(&ros_path), None),
        ),
        (
            ament.join("share"),
            PackagePaths::with_environment(Vec::new(), None, Some(ament.as_os_str())),
        ),
    ];
    for (k, (root, paths)) in sources.iter().enumerate() {
        let scale = 1.0 + k as f64;
        package(root, "parts", scale);
        let m = load(&robot, PACKAGE_MESH, paths).unwrap();
        assert_box_corners(&hull(&m), HALF.map(|h| h * scale));
    }
    // Beside the URDF: a folder named after the package in an ancestor.
    package(&dir, "parts", 4.0);
    let m = load(&robot, PACKAGE_MESH, &no_environment()).unwrap();
    assert_box_corners(&hull(&m), HALF.map(|h| h * 4.0));
}

#[test]
fn package_search_takes_the_first_source_in_order() {
    let dir = scratch("package-order");
    let robot = dir.join("robot");
    std::fs::create_dir_all(&robot).unwrap();
    for (root, scale) in [("explicit", 1.0), ("ros", 2.0), ("ament/share", 3.0)] {
        package(&dir.join(root), "parts", scale);
    }
    package(&dir, "parts", 4.0);
    let ros = dir.join("ros");
    let ament = dir.join("ament");
    let all = |explicit: Vec<PathBuf>, ros: Option<&OsStr>| {
        PackagePaths::with_environment(explicit, ros, Some(ament.as_os_str()))
    };
    let expect = [
        (all(vec![dir.join("explicit")], Some(ros.as_os_str())), 1.0),
        (all(Vec::new(), Some(ros.as_os_str())), 2.0),
        (all(Vec::new(), None), 3.0),
    ];
    for (paths, scale) in expect {
        let m = load(&robot, PACKAGE_MESH, &paths).unwrap();
        assert_box_corners(&hull(&m), HALF.map(|h| h * scale));
    }
}

#[test]
fn file_uri_and_relative_paths_resolve_from_the_urdf_folder() {
    let dir = scratch("file-uri");
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    write_binary_stl(&dir.join("meshes/part.stl"), 1.0);
    let absolute = format!("file://{}", dir.join("meshes/part.stl").display());
    for filename in [
        "meshes/part.stl",
        "file://meshes/part.stl",
        absolute.as_str(),
    ] {
        let m = load(&dir, &mesh_element(filename), &no_environment()).unwrap();
        assert_box_corners(&hull(&m), HALF);
    }
}

/// The load error of `mesh` and its message.
fn refusal(test: &str, mesh: &str, write: impl FnOnce(&Path)) -> (MeshProblem, String) {
    let dir = scratch(test);
    write(&dir);
    let e = load(&dir, mesh, &no_environment()).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("robot.urdf") && message.contains("link 'part'"),
        "{message}"
    );
    match e {
        KinematicsError::Mesh { problem, .. } => (*problem, message),
        other => panic!("not a mesh error: {other}"),
    }
}

#[test]
fn a_missing_mesh_is_an_error_naming_the_urdf_the_link_and_the_file() {
    let (problem, message) = refusal("missing", &mesh_element("meshes/gone.stl"), |_| {});
    assert!(
        matches!(problem, MeshProblem::Missing { .. }),
        "{problem:?}"
    );
    assert!(message.contains("meshes/gone.stl"), "{message}");
}

#[test]
fn an_unknown_package_lists_the_folders_searched() {
    let (problem, message) = refusal("no-package", PACKAGE_MESH, |_| {});
    assert!(
        matches!(problem, MeshProblem::PackageNotFound { ref package, .. } if package == "parts")
    );
    assert!(
        message.contains("package://parts/meshes/part.stl") && message.contains("searched"),
        "{message}"
    );
}

#[test]
fn unusable_meshes_are_typed_errors_not_panics() {
    let text = |name: &'static str, body: &'static str| {
        move |dir: &Path| std::fs::write(dir.join(name), body).unwrap()
    };
    let (p, _) = refusal(
        "empty",
        &mesh_element("empty.obj"),
        text("empty.obj", "v 0 0 0\nv 1 0 0\n"),
    );
    assert!(matches!(p, MeshProblem::Empty { .. }), "{p:?}");
    let flat = "solid f\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\nendsolid f\n";
    let (p, _) = refusal("flat", &mesh_element("flat.stl"), text("flat.stl", flat));
    assert!(matches!(p, MeshProblem::DegenerateHull { .. }), "{p:?}");
    let (p, _) = refusal(
        "garbage-dae",
        &mesh_element("bad.dae"),
        text("bad.dae", "<COLLADA><library_geometries>"),
    );
    assert!(matches!(p, MeshProblem::Malformed { .. }), "{p:?}");
    let (p, _) = refusal(
        "garbage-stl",
        &mesh_element("bad.stl"),
        text("bad.stl", "not an stl"),
    );
    assert!(matches!(p, MeshProblem::Malformed { .. }), "{p:?}");
    let (p, _) = refusal("format", &mesh_element("part.ply"), text("part.ply", "ply"));
    assert!(matches!(p, MeshProblem::UnknownFormat { .. }), "{p:?}");
    let huge = format!(
        r#"<mesh filename="{}" scale="1000 1 1"/>"#,
        fixture("box.obj").display()
    );
    let (p, _) = refusal("huge", &huge, |_| {});
    assert!(matches!(p, MeshProblem::OutOfBounds { .. }), "{p:?}");
}
