//! A loop to profile (perf, callgrind) one call on one sample of [`rod_ig_bench::families`]:
//! `cargo run --release -p rod-ig-bench --example profile -- MODE SAMPLE_INDEX ROUNDS` with MODE
//! forward, tip, tipj, stability, verdict, solve, buckets, slowest-forward or slowest (sample 0 is the
//! uniform box, 1 the log-scale sample, 3 strong force); `one a3 a4 a5` times one rod,
//! `track ROUNDS` follows the benchmark's ellipse of targets with the planar tracker,
//! `calls SAMPLE_INDEX` splits a sample's per-rod times by the sign of a4, `file PATH` lists
//! the refusals and uncertain verdicts of the rods in a file of "a3 a4 a5" lines.

use rod_ig_bench::families::samples;
use rod_ig_core::planar;
use rod_ig_core::planar::ig::{self, SolveOptions};
use std::hint::black_box;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("one") => one(&args),
        Some("calls") => calls(&args),
        Some("file") => file(&args),
        Some("tipj3d" | "evaluate3d" | "solve3d") => spatial_rounds(&args),
        Some("track") => track(&args),
        _ => rounds(&args),
    }
}

/// `one a3 a4 a5`: the forward evaluation of one rod, each call timed over ~0.2 s.
fn one(args: &[String]) {
    let v: Vec<f64> = args[2..5].iter().filter_map(|s| s.parse().ok()).collect();
    let a = rod_ig_core::PlanarParams::new(v[0], v[1], v[2]);
    // µs per call: one call sizes the loop so that a slow rod does not take minutes.
    fn per_call<R>(f: impl Fn() -> R) -> f64 {
        let t = Instant::now();
        let _ = black_box(f());
        let first = t.elapsed().as_secs_f64();
        let calls = (0.2 / first.max(1e-9)).clamp(1.0, 20_000.0) as u32;
        let t = Instant::now();
        for _ in 0..calls {
            let _ = black_box(f());
        }
        t.elapsed().as_secs_f64() * 1e6 / f64::from(calls)
    }
    println!(
        "evaluate {:.2} µs, tip_and_jacobian {:.2} µs, stability {:.2} µs, energy {:.2} µs",
        per_call(|| planar::evaluate(black_box(&a))),
        per_call(|| planar::tip_and_jacobian(black_box(&a))),
        per_call(|| planar::stability(black_box(&a))),
        per_call(|| planar::energy(black_box(&a))),
    );
    println!("{:?}", planar::evaluate(&a));
}

/// `track ROUNDS`: the planar `Tracker` along the benchmark's ellipse of 1,000 targets, a
/// fresh tracker each round (the first, cold solve of each round included).
fn track(args: &[String]) {
    let rounds: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20);
    let path = rod_ig_bench::planar::ellipse_path(0.5, 0.2, 0.3, 0.0, 0.5, 1000);
    let options = SolveOptions::default();
    ig::warm_up();
    let t0 = Instant::now();
    for _ in 0..rounds {
        let mut tracker = ig::Tracker::new(options);
        for b in &path {
            let _ = black_box(tracker.solve(black_box(b)));
        }
    }
    let us = t0.elapsed().as_secs_f64() * 1e6 / (rounds * path.len()).max(1) as f64;
    println!(
        "track on the ellipse: {} steps per round, {us:.2} µs per step",
        path.len()
    );
}

/// `tipj3d|evaluate3d|solve3d N ROUNDS`: the 3-D forward map with J, the evaluation with the
/// stability scan, or the robust 3-D solve, on the benchmark's N stable rods (seed 3).
fn spatial_rounds(args: &[String]) {
    use rod_ig_core::spatial::{self, StabilityOptions, Stiffness, PRODUCTION_RTOL};
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(64);
    let rounds: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(20);
    let k = Stiffness::default();
    let rods = rod_ig_bench::spatial::random_targets(n, 3, &k);
    let opts = StabilityOptions::production();
    let solve_opts = rod_ig_core::solver::SolveOptions::default();
    let model = spatial::Spatial::with_stiffness(k);
    let t0 = Instant::now();
    for _ in 0..rounds {
        for (a, tip) in &rods {
            match args[1].as_str() {
                "tipj3d" => drop(black_box(spatial::tip_and_jacobian(
                    black_box(a),
                    &k,
                    PRODUCTION_RTOL,
                ))),
                "evaluate3d" => drop(black_box(spatial::evaluate(black_box(a), &k, &opts))),
                _ => drop(black_box(rod_ig_core::solver::solve(
                    &model,
                    black_box(tip),
                    &solve_opts,
                ))),
            }
        }
    }
    let calls = (rounds * rods.len()).max(1);
    let us = t0.elapsed().as_secs_f64() * 1e6 / calls as f64;
    println!(
        "{} on {} rods: {calls} calls, {us:.2} µs per call",
        args[1],
        rods.len()
    );
}

/// `calls SAMPLE_INDEX`: per-rod time of stability and evaluate over the sample, split by the
/// sign of a4, with the slowest stability calls.
fn calls(args: &[String]) {
    let index: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let n = std::env::var("PROFILE_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1000);
    let sets = samples(n);
    let (name, inputs) = &sets[index.min(sets.len() - 1)];
    let time = |f: &dyn Fn()| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64() * 1e6
    };
    let mut rows: Vec<(f64, f64, rod_ig_core::PlanarParams, String)> = inputs
        .iter()
        .map(|a| {
            let s = time(&|| {
                let _ = black_box(planar::stability(black_box(a)));
            });
            let j = time(&|| {
                let _ = black_box(planar::evaluate(black_box(a)));
            });
            let r = planar::stability(a);
            let v = match r {
                Ok(r) => format!(
                    "stable {} unc {} margin {:.3e}",
                    r.stable, r.uncertain, r.margin
                ),
                Err(e) => format!("error {e}"),
            };
            (s, j, *a, v)
        })
        .collect();
    for (label, pos) in [("a4 > 0", true), ("a4 < 0", false)] {
        let mut s: Vec<f64> = rows
            .iter()
            .filter(|r| (r.2[1] > 0.0) == pos)
            .map(|r| r.0)
            .collect();
        let mut j: Vec<f64> = rows
            .iter()
            .filter(|r| (r.2[1] > 0.0) == pos)
            .map(|r| r.1)
            .collect();
        s.sort_by(f64::total_cmp);
        j.sort_by(f64::total_cmp);
        let q = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p) as usize];
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        println!(
            "{name} {label}: {} rods; stability mean {:.1} p50 {:.1} p99 {:.1} µs; evaluate mean {:.1} p50 {:.1} p99 {:.1} µs",
            s.len(), mean(&s), q(&s, 0.5), q(&s, 0.99), mean(&j), q(&j, 0.5), q(&j, 0.99)
        );
    }
    rows.sort_by(|p, q| q.0.total_cmp(&p.0));
    for r in rows.iter().take(12) {
        println!("{:9.1} µs  {:?}  {}", r.0, r.2.as_slice(), r.3);
    }
    let uncertain = rows.iter().filter(|r| !r.3.contains("unc false")).count();
    println!("{uncertain} rods uncertain or refused");
    for r in rows.iter().filter(|r| !r.3.contains("unc false")).take(10) {
        println!("{:9.1} µs  {:?}  {}", r.0, r.2.as_slice(), r.3);
    }
}

/// `file PATH`: evaluate every "a3 a4 a5" line, printing refusals and uncertain verdicts.
fn file(args: &[String]) {
    let text = std::fs::read_to_string(&args[2]).unwrap_or_default();
    for line in text.lines() {
        let v: Vec<f64> = line
            .split_whitespace()
            .filter_map(|s| s.parse().ok())
            .collect();
        let a = rod_ig_core::PlanarParams::new(v[0], v[1], v[2]);
        let t = Instant::now();
        let r = planar::evaluate(&a);
        let us = t.elapsed().as_secs_f64() * 1e6;
        match r {
            Err(e) => println!("{us:9.1} µs {line}: {e}"),
            Ok(e) if e.stability.uncertain => {
                println!("{us:9.1} µs {line}: uncertain {:?}", e.stability)
            }
            Ok(_) => {}
        }
    }
}

/// `forward|tip|tipj|stability|solve|buckets|slowest-forward|slowest SAMPLE_INDEX ROUNDS [RHO_LO
/// RHO_HI]`: the timed loop over one sample, then the mode's report.
fn rounds(args: &[String]) {
    let what = args.get(1).map_or("forward", String::as_str);
    let index: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let rounds: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(20);
    let sets = samples(
        std::env::var("PROFILE_N")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(1000),
    );
    let (name, inputs) = &sets[index.min(sets.len() - 1)];
    // Optional ρ window: only rods with lo ≤ ρ < hi.
    let lo: f64 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(0.0);
    let hi: f64 = args
        .get(5)
        .and_then(|s| s.parse().ok())
        .unwrap_or(f64::INFINITY);
    let inputs: &Vec<_> = &inputs
        .iter()
        .filter(|a| (lo..hi).contains(&a[0].abs().max(a[1].hypot(a[2]).sqrt())))
        .copied()
        .collect();
    let targets: Vec<_> = if what != "solve" && what != "slowest" {
        Vec::new()
    } else {
        inputs
            .iter()
            .filter_map(|a| planar::evaluate(a).ok())
            .filter(|e| e.stability.stable && e.tip.x.hypot(e.tip.y) < 1.0)
            .map(|e| e.tip)
            .collect()
    };
    let opts = SolveOptions::default();
    // Builds the whole atlas (once per process, ~0.25 s) outside the timed loop: under valgrind
    // a first solve would build only its deadline's share and leave the rest to the rounds.
    if !targets.is_empty() {
        ig::warm_up();
    }
    let t0 = Instant::now();
    let mut calls = 0usize;
    for _ in 0..rounds {
        if what == "solve" {
            for b in &targets {
                let _ = black_box(ig::solve(black_box(b), &opts));
            }
            calls += targets.len();
        } else {
            for a in inputs {
                match what {
                    "tip" => drop(black_box(planar::tip(black_box(a)))),
                    "tipj" => drop(black_box(planar::tip_and_jacobian(black_box(a)))),
                    "stability" => drop(black_box(planar::stability(black_box(a)))),
                    "verdict" => drop(black_box(planar::stability_verdict(black_box(a)))),
                    _ => drop(black_box(planar::evaluate(black_box(a)))),
                }
            }
            calls += inputs.len();
        }
    }
    match what {
        "buckets" => buckets(inputs, rounds),
        "slowest-forward" => slowest_forward(inputs),
        "slowest" => slowest(&targets, &opts),
        _ => {}
    }
    let us = t0.elapsed().as_secs_f64() * 1e6 / calls as f64;
    println!("{what} on {name}: {calls} calls, {us:.2} µs per call");
}

/// Mean µs per call of the forward map by curvature scale ρ = max(|a3|, √‖(a4, a5)‖).
fn buckets(inputs: &[rod_ig_core::PlanarParams], rounds: usize) {
    let mut b = [(0.0f64, 0usize); 8];
    for _ in 0..rounds {
        for a in inputs {
            let rho = a[0].abs().max(a[1].hypot(a[2]).sqrt());
            let i = ((rho.log10() + 4.0).floor().clamp(0.0, 7.0)) as usize;
            let i = if (2.0..10.0).contains(&rho) { 7 } else { i };
            let t = Instant::now();
            let _ = black_box(planar::evaluate(black_box(a)));
            b[i].0 += t.elapsed().as_secs_f64() * 1e6;
            b[i].1 += 1;
        }
    }
    for (i, (t, n)) in b.iter().enumerate() {
        if *n > 0 {
            println!(
                "rho in 1e{}..1e{}: {:5.1} % of calls, {:.2} µs",
                i as i32 - 4,
                i as i32 - 3,
                100.0 * *n as f64 / (rounds * inputs.len()) as f64,
                t / *n as f64
            );
        }
    }
}

/// The ten slowest forward evaluations of the sample, with their curvature scale.
fn slowest_forward(inputs: &[rod_ig_core::PlanarParams]) {
    let mut rows: Vec<(f64, String)> = inputs
        .iter()
        .map(|a| {
            let t = Instant::now();
            for _ in 0..20 {
                let _ = black_box(planar::evaluate(black_box(a)));
            }
            let us = t.elapsed().as_secs_f64() * 1e6 / 20.0;
            let rho = a[0].abs().max(a[1].hypot(a[2]).sqrt());
            (us, format!("{:?} rho {rho:.3}", a.as_slice()))
        })
        .collect();
    rows.sort_by(|p, q| q.0.total_cmp(&p.0));
    for (us, row) in rows.iter().take(10) {
        println!("{us:8.1} µs  {row}");
    }
}

/// The five slowest solves of the sample's targets, with their work.
fn slowest(targets: &[rod_ig_core::PlanarPose], opts: &SolveOptions) {
    let mut rows: Vec<(f64, String)> = targets
        .iter()
        .map(|b| {
            let t = Instant::now();
            let r = ig::solve(b, opts);
            let us = t.elapsed().as_secs_f64() * 1e6;
            let what = match r {
                Ok(s) => format!(
                    "a {:?} iterations {} starts {}",
                    s.a, s.iterations, s.starts
                ),
                Err(f) => format!("failed: {}", f.reason),
            };
            (us, format!("{b:?}: {what}"))
        })
        .collect();
    rows.sort_by(|p, q| q.0.total_cmp(&p.0));
    for (us, row) in rows.iter().take(5) {
        println!("{us:8.1} µs  {row}");
    }
    let failed: Vec<_> = rows.iter().filter(|r| r.1.contains("failed")).collect();
    println!(
        "{} of {} targets solved",
        rows.len() - failed.len(),
        rows.len()
    );
    for (us, row) in failed {
        println!("{us:8.1} µs  {row}");
    }
}
