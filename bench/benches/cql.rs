//! One Contextual Q-learning solve (task set-up + training + greedy rollout)
//! on generated scenes of 10×10, 20×20, 40×40 and 80×80 cells.

use afford_bench::cql::first_grid;
use afford_bench::generator::scene_of_size;
use afford_planner::grid::StateGrid;
use afford_planner::{ContextualQLearner, GridTask, LearnerSettings, oracle};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

/// The first solvable scene of the series at this size.
fn solvable_grid(side: usize) -> StateGrid {
    (0..)
        .map(|index| first_grid(&scene_of_size(7, index, side, side)))
        .find(|grid| oracle::optimal_length(&GridTask::new(grid.clone())).is_some())
        .expect("the series has solvable scenes")
}

fn cql_solve(c: &mut Criterion) {
    let learner = ContextualQLearner::new(LearnerSettings::default());
    let mut group = c.benchmark_group("cql_solve");
    group.sample_size(20);
    for side in [10, 20, 40, 80] {
        let grid = solvable_grid(side);
        group.bench_with_input(
            BenchmarkId::from_parameter(format!("{side}x{side}")),
            &grid,
            |b, grid| {
                b.iter(|| {
                    let plan = learner.learn(&GridTask::new(grid.clone()), 1);
                    assert!(plan.solved);
                    plan
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, cql_solve);
criterion_main!(benches);
