use afford_collision::RobotGeometry;
use afford_kinematics::RobotModel;
use afford_planner::clearance::{FreeMoves, Leg};
use afford_planner::start::parked_home;

#[test]
fn probe() {
    let s = afford_planner::scenario::load(std::path::Path::new("../examples/cob4-extra-pieces.yaml")).unwrap();
    let robot = RobotModel::builtin("care_o_bot4").unwrap();
    let geometry = RobotGeometry::new(&robot).unwrap();
    let q = parked_home(&robot);
    for (t, g) in [(0usize, 1usize), (3, 0)] {
        for arm in robot.arms() {
            let m = FreeMoves::new(&robot, &geometry, &s, t, g, &arm.name, &q, Leg::BeforeGrasp).unwrap();
            let a = arm.extract(&q);
            let t0 = std::time::Instant::now();
            let free = m.edge_free(&a, &a).unwrap();
            let mut b = a.clone(); b[3] += 0.3;
            let free2 = m.edge_free(&a, &b).unwrap();
            eprintln!("target {t} goal {g} arm {} parked free {free} move free {free2} {:?}", arm.name, t0.elapsed()/2);
        }
    }
}
