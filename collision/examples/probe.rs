use afford_collision::*;
use afford_kinematics::RobotModel;
fn main() {
    for name in ["kuka_iiwa14", "care_o_bot4"] {
        let m = RobotModel::builtin(name).unwrap();
        let g = RobotGeometry::new(&m).unwrap();
        println!("{name}: bodies {:?}", g.body_names());
        println!("  self pairs {}", g.self_collision_pairs().len());
        let scene = Scene::from_spec(&SceneSpec { table_z: -0.2, table: None, boxes: vec![] }).unwrap();
        let mut o = PathOptions::default();
        o.settings.max_reports = 50;
        let v = g.check_joint_path(&scene, &[m.home().to_vec()], &o).unwrap();
        for c in &v.collisions { println!("  home: {c}"); }
        for a in m.arms() {
            let q = m.parked_except(m.home(), &a.name);
            let v = g.check_joint_path(&scene, &[q], &o).unwrap();
            for c in &v.collisions { println!("  parked except {}: {c}", a.name); }
            println!("  arm {} tool {} home tcp {:?}", a.name, a.tool_link, a.fk(&a.extract(m.home())).translation.vector);
        }
        let t = std::time::Instant::now();
        for _ in 0..1000 { std::hint::black_box(m.link_poses(m.home()).unwrap()); }
        println!("  link_poses {:?}/call", t.elapsed() / 1000);
    }
}
