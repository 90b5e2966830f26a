//! Inverse-geometry benchmarks (issue #3): the paper's Newton (α = 1) from the public initial
//! guesses, the robust solver from no start on random reachable targets of stable rods
//! (|a3| ≤ 2π, |a4|, |a5| ≤ 100), and one tracking step along a smooth path.
//!
//! Each iteration solves one target, cycling through a fixed, seeded set, so the reported time
//! is per solve. The atlas is built before measuring. The `ig::bench` functions (used by
//! `rod-ig bench`) report success rates and medians; this harness gives criterion's statistics.
//!
//! Run: `cargo bench -p rod-ig-bench --bench ig -- --quick`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use rod_ig_bench::planar::{self as planar_workloads, ParamBox};
use rod_ig_core::planar::ig::{self, Method, SolveOptions, Tracker};
use rod_ig_core::PlanarParams;

fn bench(c: &mut Criterion) {
    let _ = ig::warm_up();
    let targets = planar_workloads::random_stable_targets(256, 42, ParamBox::PAPER);
    let n = targets.len().max(1);
    let mut g = c.benchmark_group("ig");

    let robust = SolveOptions::default();
    let mut i = 0;
    g.bench_function("robust_no_start", |b| {
        b.iter(|| {
            i = (i + 1) % n;
            ig::solve(black_box(&targets[i].1), &robust)
        })
    });

    // Newton from a guess 2 % off the solution (converging runs: the paper's method proper).
    let mut i = 0;
    g.bench_function("newton_alpha1_near_guess", |b| {
        b.iter(|| {
            i = (i + 1) % n;
            let (a, t) = &targets[i];
            let o = SolveOptions {
                method: Method::Newton,
                initial_guess: Some(a.component_mul(&PlanarParams::new(1.02, 0.98, 1.02))),
                ..Default::default()
            };
            ig::solve(black_box(t), &o)
        })
    });

    let path = planar_workloads::random_stable_path(5, ParamBox::PAPER, 400, 0.01);
    if !path.is_empty() {
        let mut tracker = Tracker::new(SolveOptions::default());
        let mut k = 0;
        g.bench_function("tracking_step", |b| {
            b.iter(|| {
                k += 1;
                if k >= path.len() {
                    k = 0;
                    tracker.reset();
                }
                tracker.solve(black_box(&path[k]))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
