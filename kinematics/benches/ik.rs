//! Criterion bench: one unseeded 6-D IK solve per built-in arm, afford's
//! solver against k's `JacobianIkSolver` (fixed seeds; targets are FK of
//! random in-limit configurations).

use afford_kinematics::{
    BENCH_POSITION_TOLERANCE, BENCH_ROTATION_TOLERANCE, IkSettings, IkTarget, KBaseline,
    RobotModel, random_reachable_poses,
};
use criterion::{Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

const TARGETS: usize = 500;

fn ik(c: &mut Criterion) {
    for name in afford_kinematics::BUILTIN_ROBOTS {
        let model = RobotModel::builtin(name).unwrap();
        for arm in model.arms() {
            let targets = random_reachable_poses(arm, TARGETS, 1);
            let settings = IkSettings::default();
            let mut group = c.benchmark_group(format!("ik/{name}/{}", arm.name));
            let mut rng = ChaCha8Rng::seed_from_u64(2);
            let mut i = 0;
            group.bench_function("afford", |b| {
                b.iter(|| {
                    i = (i + 1) % TARGETS;
                    black_box(
                        arm.solve_ik(&IkTarget::Pose(targets[i]), None, &settings, &mut rng)
                            .ok(),
                    )
                })
            });
            let k = KBaseline::new(
                arm,
                BENCH_POSITION_TOLERANCE * 0.5,
                BENCH_ROTATION_TOLERANCE * 0.5,
                10,
            );
            let mut rng = ChaCha8Rng::seed_from_u64(2);
            let mut i = 0;
            group.bench_function("k", |b| {
                b.iter(|| {
                    i = (i + 1) % TARGETS;
                    black_box(k.solve(arm, &targets[i], &arm.home, &mut rng))
                })
            });
            group.finish();
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = ik
}
criterion_main!(benches);
