//! The physical replay of the plain-sort example plans (three sub-goals,
//! both robots): one whole replay per iteration; the time per sub-goal and
//! per simulated second is printed once before measuring.

use std::path::Path;
use std::time::Instant;

use afford_check::PlanFile;
use afford_check::physics::check_physics;
use afford_kinematics::RobotModel;
use afford_planner::{PlanOptions, plan, scenario};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

fn replay(c: &mut Criterion) {
    let mut group = c.benchmark_group("physics_replay");
    group.sample_size(10);
    for example in ["sort-blue-squares", "cob4-sort-blue-squares"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples")
            .join(format!("{example}.yaml"));
        let s = scenario::load(&path).unwrap();
        let robot = RobotModel::builtin(&s.robot.model).unwrap();
        let file = PlanFile::from(&plan(&s, &PlanOptions::default()).unwrap());
        let started = Instant::now();
        let (report, _) = check_physics(&s, &robot, &file);
        let report = report.unwrap();
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let n = file.subgoals.len();
        println!(
            "{example}: {n} sub-goals, {} steps of {} ms ({:.1} s simulated), {ms:.0} ms: {:.0} ms per sub-goal, passed {}",
            report.steps,
            report.step * 1e3,
            report.steps as f64 * report.step,
            ms / n as f64,
            report.passed()
        );
        group.bench_with_input(BenchmarkId::from_parameter(example), &file, |b, file| {
            b.iter(|| check_physics(&s, &robot, file))
        });
    }
    group.finish();
}

criterion_group!(benches, replay);
criterion_main!(benches);
