//! One whole-arm check (scene + self-collision) of a 1,000-configuration iiwa
//! joint path against a 20-object scene; and raw shape-pair query throughput.

use afford_collision::{PathOptions, RobotGeometry, bench_case, pair_queries_per_s};
use afford_kinematics::RobotModel;
use criterion::{Criterion, criterion_group, criterion_main};

fn arm_path_1000(c: &mut Criterion) {
    let model = RobotModel::builtin("kuka_iiwa14").unwrap();
    let geometry = RobotGeometry::new(&model).unwrap();
    let (scene, path) = bench_case(&model, 1).unwrap();
    let opts = PathOptions::default();
    let v = geometry.check_joint_path(&scene, &path, &opts).unwrap();
    println!(
        "bench case: free={} evaluations={} pair queries={}",
        v.is_free(),
        v.stats.evaluations,
        v.stats.pair_queries
    );
    let qps = pair_queries_per_s(&model, &scene, 1).unwrap();
    println!("shape-pair distance queries: {qps:.0} /s");
    c.bench_function("arm_path_1000_configs_20_objects", |b| {
        b.iter(|| geometry.check_joint_path(&scene, &path, &opts).unwrap())
    });
}

criterion_group!(benches, arm_path_1000);
criterion_main!(benches);
