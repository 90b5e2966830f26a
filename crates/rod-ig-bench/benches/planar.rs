//! Closed-form planar rod benchmarks: tip, tip + J, stability, shape(100), evaluate.
//!
//! Each iteration evaluates one a, cycling through 64 fixed parameter vectors drawn uniformly
//! (fixed LCG seed) from the public oracle box a3 ∈ [−10, 10], a4, a5 ∈ [−100, 100], so the
//! reported time is per call, averaged over the cases of the box.
//!
//! Run: `cargo bench -p rod-ig-bench --bench planar -- --quick` (or `--measurement-time 2`).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use rod_ig_core::planar::{self, PlanarRod};
use rod_ig_core::PlanarParams;

fn box_cases() -> Vec<PlanarParams> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..64)
        .map(|_| {
            PlanarParams::new(
                -10.0 + 20.0 * next(),
                -100.0 + 200.0 * next(),
                -100.0 + 200.0 * next(),
            )
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let cases = box_cases();
    let n = cases.len();
    let mut g = c.benchmark_group("planar");
    let mut i = 0;
    g.bench_function("tip", |b| {
        b.iter(|| {
            i = (i + 1) % n;
            planar::tip(black_box(&cases[i]))
        })
    });
    g.bench_function("tip_and_jacobian", |b| {
        b.iter(|| {
            i = (i + 1) % n;
            planar::tip_and_jacobian(black_box(&cases[i]))
        })
    });
    g.bench_function("stability", |b| {
        b.iter(|| {
            i = (i + 1) % n;
            planar::stability(black_box(&cases[i]))
        })
    });
    g.bench_function("evaluate", |b| {
        b.iter(|| {
            i = (i + 1) % n;
            planar::evaluate(black_box(&cases[i]))
        })
    });
    g.bench_function("shape_100", |b| {
        b.iter(|| {
            i = (i + 1) % n;
            PlanarRod::new(black_box(&cases[i])).map(|r| r.shape(100))
        })
    });
    let rods: Vec<PlanarRod> = cases
        .iter()
        .filter_map(|a| PlanarRod::new(a).ok())
        .collect();
    g.bench_function("pose_precomputed_rod", |b| {
        b.iter(|| {
            i = (i + 1) % rods.len();
            rods[i].pose(black_box(0.7))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
