//! `rod-ig bench --only tails`: per-call latency distributions (p50, p99, p99.9, max) of the
//! forward map and of the robust solve on the uniform box next to log-scale samples of the
//! regime a cable lives in (issue 9), with the ratio log-scale / box.

use crate::planar_cmds::forward_line;
use rod_ig_bench::families::samples;
use rod_ig_core::planar::ig::{self, SolveOptions};
use rod_ig_core::rng::SplitMix64;
use rod_ig_core::{planar, PlanarParams, PlanarPose};
use std::hint::black_box;
use std::time::Instant;

/// Latency distribution of one function over one sample (µs).
#[derive(Clone, Copy, Debug)]
pub struct Tails {
    /// Mean per call.
    pub mean: f64,
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// 99.9th percentile.
    pub p999: f64,
    /// Slowest call.
    pub max: f64,
    /// Calls that returned an error.
    pub errors: usize,
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = ((sorted.len() as f64 - 1.0) * q).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// Times every call of `f` individually (after one untimed warm-up pass).
pub fn tails<T, R, E>(inputs: &[T], mut f: impl FnMut(&T) -> Result<R, E>) -> Tails {
    for x in inputs {
        let _ = black_box(f(black_box(x)));
    }
    let mut us = Vec::with_capacity(inputs.len());
    let mut errors = 0;
    for x in inputs {
        let t0 = Instant::now();
        let r = black_box(f(black_box(x)));
        us.push(t0.elapsed().as_secs_f64() * 1e6);
        errors += usize::from(r.is_err());
    }
    let mean = us.iter().sum::<f64>() / us.len().max(1) as f64;
    us.sort_by(f64::total_cmp);
    Tails {
        mean,
        p50: percentile(&us, 0.5),
        p99: percentile(&us, 0.99),
        p999: percentile(&us, 0.999),
        max: us.last().copied().unwrap_or(0.0),
        errors,
    }
}

fn print_row(what: &str, sample: &str, t: &Tails, box_mean: f64) {
    outln!(
        "{what:<8} {sample:<30} {:>9.2} {:>9.2} {:>9.2} {:>10.2} {:>10.2} {:>7.2}× {:>7}",
        t.mean,
        t.p50,
        t.p99,
        t.p999,
        t.max,
        t.mean / box_mean,
        t.errors
    );
}

/// Prints the table.
pub fn run(quick: bool) {
    let n = if quick { 300 } else { 4000 };
    let sets = samples(n);
    outln!("## Latency tails (per call, µs; {n} inputs per sample; single thread)");
    outln!(
        "{:<8} {:<30} {:>9} {:>9} {:>9} {:>10} {:>10} {:>8} {:>7}",
        "call",
        "sample",
        "mean",
        "p50",
        "p99",
        "p99.9",
        "max",
        "vs box",
        "errors"
    );
    let mut box_mean = f64::NAN;
    let mut strong_forward = None;
    let mut within_twice = Vec::new();
    for (name, inputs) in &sets {
        let t = tails(inputs, planar::evaluate);
        if box_mean.is_nan() {
            box_mean = t.mean;
        }
        if name.starts_with("strong force") {
            strong_forward = Some(t);
        }
        if name.starts_with("near-circles") || name.starts_with("nearly straight") {
            within_twice.push((*name, t.mean / box_mean));
        }
        print_row("forward", name, &t, box_mean);
    }
    // Solve: targets that stable rods of each sample reach.
    let opts = SolveOptions::default();
    let mut box_mean = f64::NAN;
    for (name, inputs) in &sets {
        let targets: Vec<PlanarPose> = inputs
            .iter()
            .filter_map(|a| planar::evaluate(a).ok())
            .filter(|e| e.stability.stable)
            .map(|e| e.tip)
            .filter(|p| p.x.hypot(p.y) < 1.0)
            .take(if quick { 100 } else { 1000 })
            .collect();
        let t = tails(&targets, |b| ig::solve(b, &opts));
        if box_mean.is_nan() {
            box_mean = t.mean;
        }
        print_row("solve", name, &t, box_mean);
    }
    outln!("goal (issue 9): the log-scale sample within 1.5× the box per call");
    for (name, ratio) in within_twice {
        let verdict = if ratio <= 2.0 { "met" } else { "NOT met" };
        outln!(
            "goal (issue 23): {name} within 2× the box per forward call: {ratio:.2}×, {verdict}"
        );
    }
    outln!(
        "goal (issue 23): strong force mean ≤ 20 µs and p99 ≤ 200 µs per forward call: {}",
        match strong_forward {
            Some(t) if t.mean <= 20.0 && t.p99 <= 200.0 => "met".to_string(),
            Some(t) => format!("NOT met (mean {:.1} µs, p99 {:.1} µs)", t.mean, t.p99),
            None => "no strong-force sample".to_string(),
        }
    );
    through_the_cli(&sets[0].1, n);
}

/// Mean µs per line of `rod-ig forward`'s work (parse, evaluate, JSON answer), after one
/// untimed pass.
fn per_line(lines: &[String]) -> f64 {
    for l in lines {
        let _ = black_box(forward_line(black_box(l)));
    }
    let t0 = Instant::now();
    for l in lines {
        let _ = black_box(forward_line(black_box(l)));
    }
    t0.elapsed().as_secs_f64() * 1e6 / lines.len().max(1) as f64
}

/// Issue 23's measure through the CLI: on a log-scale sample (|a3| 1e-8..5, |a4|, |a5|
/// 1e-9..3e3, random signs), the rods within the box's magnitudes and those with |a4| or |a5|
/// in [1e2, 3e3] against the uniform box, per line of `rod-ig forward`.
fn through_the_cli(box_rods: &[PlanarParams], n: usize) {
    let line = |a: &PlanarParams| format!("{{\"a\": [{:e}, {:e}, {:e}]}}", a[0], a[1], a[2]);
    let mut rng = SplitMix64::new(23);
    let (mut in_box, mut strong) = (Vec::new(), Vec::new());
    // Draw until both groups are full (about a third of the draws are strong).
    while in_box.len() < n || strong.len() < n {
        let a = PlanarParams::new(
            rng.signed_pow10(-8.0, 0.7),
            rng.signed_pow10(-9.0, 3.5),
            rng.signed_pow10(-9.0, 3.5),
        );
        let force = a[1].abs().max(a[2].abs());
        if (1e2..=3e3).contains(&force) && strong.len() < n {
            strong.push(line(&a));
        } else if force <= 1e2 && a[0].abs() <= 10.0 && in_box.len() < n {
            in_box.push(line(&a));
        }
    }
    let box_lines: Vec<String> = box_rods.iter().map(line).collect();
    let (b, i, s) = (per_line(&box_lines), per_line(&in_box), per_line(&strong));
    outln!(
        "through the CLI (rod-ig forward, per line: parse, evaluate, JSON; {n} lines each): box {b:.2} µs, \
         log-scale within the box's magnitudes {i:.2} µs ({:.2}×), log-scale with |a4| or |a5| 1e2..3e3 {s:.2} µs ({:.2}×)",
        i / b,
        s / b
    );
    let verdict = if s <= 2.0 * b { "met" } else { "NOT met" };
    outln!("goal (issue 23): strong-force rods ≤ 2× the box per rod through the CLI: {:.2}×, {verdict}", s / b);
}
