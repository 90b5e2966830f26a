//! Benchmark figures of the 3-D inverse geometry on random stable rods. No I/O.

use rod_ig_core::rng::SplitMix64;
use rod_ig_core::solver::{self, observe, Counters, IgError, SolveOptions};
use rod_ig_core::spatial::Spatial;
use rod_ig_core::spatial::{self, SpatialParams, SpatialPose, StabilityOptions, Stiffness};

/// Half-widths of the random-target box: |a1..3| ≤ 5, |a4..6| ≤ 30 (docs/math.md §10: ≈ 70 % stable,
/// straddles the Euler load 4π² and the twist limit 8.99).
pub const TARGET_BOX: (f64, f64) = (5.0, 30.0);

/// `n` random stable rods from [`TARGET_BOX`] (rejection sampling with the production
/// stability test, at most 100·n draws) and their tips.
pub fn random_targets(n: usize, seed: u64, k: &Stiffness) -> Vec<(SpatialParams, SpatialPose)> {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::with_capacity(n);
    let (m, f) = TARGET_BOX;
    let opts = StabilityOptions::production();
    for _ in 0..n.saturating_mul(100) {
        if out.len() >= n {
            break;
        }
        let a = SpatialParams::from_fn(|i, _| {
            let h = if i < 3 { m } else { f };
            rng.range(-h, h)
        });
        if let Ok(ev) = spatial::evaluate(&a, k, &opts) {
            if ev.stability.stable {
                out.push((a, ev.tip));
            }
        }
    }
    out
}

/// Success rate and timings of the robust solver on random reachable targets.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchmarkReport3d {
    /// Targets attempted.
    pub targets: usize,
    /// Solves that returned a stable solution within tolerance.
    pub successes: usize,
    /// successes / targets.
    pub success_rate: f64,
    /// Median wall time per solve (µs).
    pub median_us: f64,
    /// 90th percentile wall time (µs).
    pub p90_us: f64,
    /// 99th percentile wall time (µs).
    pub p99_us: f64,
    /// Largest wall time (µs).
    pub max_us: f64,
    /// Mean Newton iterations of the successful solves.
    pub mean_iterations: f64,
    /// Mean rod integrations per solve.
    pub mean_evaluations: f64,
    /// Successful solves that needed more than one start.
    pub restarts_used: usize,
    /// Failure reasons (Display strings) with counts.
    pub failures: Vec<(String, usize)>,
    /// Starts per solve and deadline hits, counted by the solver's observer.
    pub work: Counters,
}

/// Counts one more `key` in `list` (first occurrence order kept).
fn tally(list: &mut Vec<(String, usize)>, key: String) {
    match list.iter_mut().find(|(k, _)| *k == key) {
        Some(e) => e.1 += 1,
        None => list.push((key, 1)),
    }
}

/// Runs the robust solver (default options) on `n` random stable targets ([`random_targets`])
/// and returns the success rate and timings (no I/O; the CLI prints them).
pub fn benchmark_random_targets(n: usize, seed: u64) -> BenchmarkReport3d {
    let k = Stiffness::default();
    let targets = random_targets(n, seed, &k);
    let opts = SolveOptions::default();
    let model = Spatial::with_stiffness(k);
    let mut times = Vec::with_capacity(targets.len());
    let mut successes = 0;
    let mut iters = 0u64;
    let mut evals = 0u64;
    let mut restarts = 0;
    let mut failures: Vec<(String, usize)> = Vec::new();
    let mut work = Counters::default();
    for (_, target) in &targets {
        let t0 = std::time::Instant::now();
        let (r, w) = observe(work, || solver::solve(&model, target, &opts));
        work = w;
        times.push(t0.elapsed().as_secs_f64() * 1e6);
        match r {
            Ok(sol) if sol.stable => {
                successes += 1;
                iters += sol.iterations as u64;
                evals += sol.evaluations as u64;
                if sol.starts > 1 {
                    restarts += 1;
                }
            }
            Ok(_) => tally(&mut failures, "unstable solution".into()),
            Err(f) => {
                let key = match &f.reason {
                    IgError::NoStableSolution {
                        last: Some(last), ..
                    } => format!("no stable solution ({last})"),
                    other => other.to_string(),
                };
                tally(&mut failures, key);
            }
        }
    }
    times.sort_by(f64::total_cmp);
    let pct = |p: f64| -> f64 {
        if times.is_empty() {
            0.0
        } else {
            times[((times.len() - 1) as f64 * p).round() as usize]
        }
    };
    let m = targets.len();
    BenchmarkReport3d {
        targets: m,
        successes,
        success_rate: if m > 0 {
            successes as f64 / m as f64
        } else {
            0.0
        },
        median_us: pct(0.5),
        p90_us: pct(0.9),
        p99_us: pct(0.99),
        max_us: times.last().copied().unwrap_or(0.0),
        mean_iterations: if successes > 0 {
            iters as f64 / successes as f64
        } else {
            0.0
        },
        mean_evaluations: if successes > 0 {
            evals as f64 / successes as f64
        } else {
            0.0
        },
        restarts_used: restarts,
        failures,
        work,
    }
}
