//! The timing stage (spline → SOCP with Clarabel → 100 Hz samples → check)
//! on seeded random smooth 7-joint paths with iiwa-like limits, at 200, 300
//! and 400 path segments. The figure `afford bench timing`
//! reports is `timing/200`.

use afford_bench::timing::{iiwa_limits, random_smooth_path};
use afford_planner::timing::{TimingSettings, TimingStatus, time_parameterize};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn timing(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let paths: Vec<Vec<Vec<f64>>> = (0..8)
        .map(|_| random_smooth_path(&mut rng, 7, 12))
        .collect();
    let limits = iiwa_limits();
    let mut group = c.benchmark_group("timing");
    group.sample_size(30);
    for segments in [200, 300, 400] {
        let settings = TimingSettings {
            path_points: segments,
            ..TimingSettings::default()
        };
        group.bench_with_input(
            BenchmarkId::from_parameter(segments),
            &settings,
            |b, settings| {
                let mut k = 0;
                b.iter(|| {
                    let path = &paths[k % paths.len()];
                    k += 1;
                    let timing = time_parameterize(path, &limits, None, settings).unwrap();
                    assert_eq!(timing.status, TimingStatus::Solved);
                    timing
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, timing);
criterion_main!(benches);
