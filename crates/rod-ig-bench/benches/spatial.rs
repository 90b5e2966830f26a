//! 3-D rod benchmarks: forward + J at rtol 1e-8 (goal ≤ 50 µs), single-pass evaluation with
//! stability, and the robust 3-D solve (goal median ≤ 1 ms, ≥ 99 % success).

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion};
use rod_ig_bench::spatial::random_targets;
use rod_ig_core::rng::SplitMix64;
use rod_ig_core::solver::{self, SolveOptions};
use rod_ig_core::spatial::Spatial;
use rod_ig_core::spatial::{self, SpatialParams, StabilityOptions, Stiffness};

fn params(n: usize) -> Vec<SpatialParams> {
    let mut rng = SplitMix64::new(17);
    (0..n)
        .map(|_| {
            SpatialParams::from_fn(|i, _| {
                let h = if i < 3 { 5.0 } else { 30.0 };
                rng.range(-h, h)
            })
        })
        .collect()
}

fn forward(c: &mut Criterion) {
    let k = Stiffness::default();
    let a = params(64);
    let mut i = 0;
    c.bench_function("spatial tip_and_jacobian rtol 1e-8", |b| {
        b.iter(|| {
            i = (i + 1) % a.len();
            black_box(spatial::tip_and_jacobian(&a[i], &k, 1e-8).ok())
        })
    });
    c.bench_function("spatial tip rtol 1e-8", |b| {
        b.iter(|| {
            i = (i + 1) % a.len();
            black_box(spatial::tip(&a[i], &k, 1e-8).ok())
        })
    });
    let prod = StabilityOptions::production();
    c.bench_function("spatial evaluate (tip, J, stability) production", |b| {
        b.iter(|| {
            i = (i + 1) % a.len();
            black_box(spatial::evaluate(&a[i], &k, &prod).ok())
        })
    });
    c.bench_function("spatial stability (reference, fast scan)", |b| {
        b.iter(|| {
            i = (i + 1) % a.len();
            black_box(spatial::stability(&a[i], &k).ok())
        })
    });
}

fn solve(c: &mut Criterion) {
    let k = Stiffness::default();
    let targets = random_targets(200, 99, &k);
    let opts = SolveOptions::default();
    let model = Spatial::with_stiffness(k);
    let mut i = 0;
    let mut group = c.benchmark_group("spatial ig");
    group.sample_size(50);
    group.bench_function("robust solve, random stable targets", |b| {
        b.iter_batched(
            || {
                i = (i + 1) % targets.len();
                targets[i].1
            },
            |t| black_box(solver::solve(&model, &t, &opts).ok()),
            BatchSize::SmallInput,
        )
    });
    group.finish();
}

criterion_group!(benches, forward, solve);
criterion_main!(benches);
