//! A loop to profile (perf, callgrind) one call on one sample of [`rod_ig_bench::families`]:
//! `cargo run --release -p rod-ig-bench --example profile -- forward|solve SAMPLE_INDEX ROUNDS`
//! (sample 0 is the uniform box, 1 the log-scale sample).

use rod_ig_bench::families::samples;
use rod_ig_core::ig::{self, SolveOptions};
use rod_ig_core::planar;
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let what = args.get(1).map_or("forward", String::as_str);
    let index: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let rounds: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(20);
    let sets = samples(1000);
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
    let targets: Vec<_> = if what != "solve" {
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
    // Builds the atlas (once per process, ~0.5 s) outside the timed loop.
    if let Some(b) = targets.first() {
        let _ = ig::solve(b, &opts);
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
                let _ = black_box(planar::evaluate(black_box(a)));
            }
            calls += inputs.len();
        }
    }
    if what == "buckets" {
        // Mean µs per call of the forward map by curvature scale ρ = max(|a3|, √‖(a4, a5)‖).
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
    let us = t0.elapsed().as_secs_f64() * 1e6 / calls as f64;
    println!("{what} on {name}: {calls} calls, {us:.2} µs per call");
}
