//! `rod-ig bench --only tails`: per-call latency distributions (p50, p99, p99.9, max) of the
//! forward map and of the robust solve on the uniform box next to log-scale samples of the
//! regime a cable lives in (issue 9), with the ratio log-scale / box; the samples are timed
//! interleaved, so that the ratios are not the machine's phases.

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

/// Slices each sample is cut into, timed in turn (slice j of every sample, then slice j + 1):
/// the machine's phases (its speed varies ~1.5× within a minute) fall on every sample alike,
/// so the ratios to the box compare like with like. Timed one sample after the other, the
/// nearly straight rods' ratio ranged over 0.98–2.34× in thirteen runs of one build.
const SLICES: usize = 20;

/// Times every call of `f` on every sample individually, the samples interleaved slice by
/// slice ([`SLICES`]), after one untimed warm-up pass: one [`Tails`] per sample.
pub fn tails_interleaved<T, R, E>(
    samples: &[&[T]],
    mut f: impl FnMut(&T) -> Result<R, E>,
) -> Vec<Tails> {
    for x in samples.iter().flat_map(|s| s.iter()) {
        let _ = black_box(f(black_box(x)));
    }
    let mut us: Vec<Vec<f64>> = samples
        .iter()
        .map(|s| Vec::with_capacity(s.len()))
        .collect();
    let mut errors = vec![0usize; samples.len()];
    for j in 0..SLICES {
        for (k, sample) in samples.iter().enumerate() {
            let slice = &sample[j * sample.len() / SLICES..(j + 1) * sample.len() / SLICES];
            for x in slice {
                let t0 = Instant::now();
                let r = black_box(f(black_box(x)));
                us[k].push(t0.elapsed().as_secs_f64() * 1e6);
                errors[k] += usize::from(r.is_err());
            }
        }
    }
    us.into_iter()
        .zip(errors)
        .map(|(mut us, errors)| {
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
        })
        .collect()
}

/// Times every call of `f` individually (after one untimed warm-up pass).
pub fn tails<T, R, E>(inputs: &[T], f: impl FnMut(&T) -> Result<R, E>) -> Tails {
    tails_interleaved(&[inputs], f)[0]
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
    let inputs: Vec<&[PlanarParams]> = sets.iter().map(|(_, v)| v.as_slice()).collect();
    let forward = tails_interleaved(&inputs, planar::evaluate);
    let box_mean = forward[0].mean;
    let mut strong_forward = None;
    let mut within_twice = Vec::new();
    for ((name, _), t) in sets.iter().zip(&forward) {
        if name.starts_with("strong force") {
            strong_forward = Some(*t);
        }
        if name.starts_with("near-circles") || name.starts_with("nearly straight") {
            within_twice.push((*name, t.mean / box_mean));
        }
        print_row("forward", name, t, box_mean);
    }
    // Solve: targets that stable rods of each sample reach.
    let opts = SolveOptions::default();
    let targets: Vec<Vec<PlanarPose>> = sets
        .iter()
        .map(|(_, inputs)| {
            inputs
                .iter()
                .filter_map(|a| planar::evaluate(a).ok())
                .filter(|e| e.stability.stable)
                .map(|e| e.tip)
                .filter(|p| p.x.hypot(p.y) < 1.0)
                .take(if quick { 100 } else { 1000 })
                .collect()
        })
        .collect();
    let target_sets: Vec<&[PlanarPose]> = targets.iter().map(Vec::as_slice).collect();
    let solve = tails_interleaved(&target_sets, |b| ig::solve(b, &opts));
    for ((name, _), t) in sets.iter().zip(&solve) {
        print_row("solve", name, t, solve[0].mean);
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

/// Mean µs per line of `rod-ig forward`'s work (parse, evaluate, JSON answer) for each group
/// of lines, after one untimed pass, the groups interleaved slice by slice ([`SLICES`]).
fn per_line(groups: &[&[String]]) -> Vec<f64> {
    for l in groups.iter().flat_map(|g| g.iter()) {
        let _ = black_box(forward_line(black_box(l)));
    }
    let mut seconds = vec![0.0; groups.len()];
    for j in 0..SLICES {
        for (k, lines) in groups.iter().enumerate() {
            let slice = &lines[j * lines.len() / SLICES..(j + 1) * lines.len() / SLICES];
            let t0 = Instant::now();
            for l in slice {
                let _ = black_box(forward_line(black_box(l)));
            }
            seconds[k] += t0.elapsed().as_secs_f64();
        }
    }
    seconds
        .iter()
        .zip(groups)
        .map(|(s, g)| s * 1e6 / g.len().max(1) as f64)
        .collect()
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
    let times = per_line(&[&box_lines, &in_box, &strong]);
    let (b, i, s) = (times[0], times[1], times[2]);
    outln!(
        "through the CLI (rod-ig forward, per line: parse, evaluate, JSON; {n} lines each): box {b:.2} µs, \
         log-scale within the box's magnitudes {i:.2} µs ({:.2}×), log-scale with |a4| or |a5| 1e2..3e3 {s:.2} µs ({:.2}×)",
        i / b,
        s / b
    );
    let verdict = if s <= 2.0 * b { "met" } else { "NOT met" };
    outln!("goal (issue 23): strong-force rods ≤ 2× the box per rod through the CLI: {:.2}×, {verdict}", s / b);
}
