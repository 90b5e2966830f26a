//! Benchmark figures of the inverse geometry (paper Table 1 protocol and beyond). No I/O: each
//! function returns a plain report struct; the CLI prints it.
//!
//! Timings are wall-clock per solve on the calling thread, with the atlas built beforehand
//! ([`ig::warm_up`]) so that its one-off construction is not charged to the first solve.

use rod_ig_core::planar::ig::{self, solve, IgError, Method, SolveOptions, Tracker};
use rod_ig_core::{planar, wrap_angle, PlanarParams, PlanarPose};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// One inverse-geometry case, as in `data/oracle/ig_public.jsonl`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IgCase {
    /// A stable rod whose tip is the target.
    pub a_target: [f64; 3],
    /// Target tip pose (θ possibly unwrapped; compared modulo 2π).
    pub target: PlanarPose,
    /// Initial guesses (stable rods).
    pub a0_list: Vec<[f64; 3]>,
}

/// A box of rod parameters |a3| ≤ a3_max, |a4|, |a5| ≤ a45_max.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamBox {
    /// Half-width in a3.
    pub a3_max: f64,
    /// Half-width in a4 and a5.
    pub a45_max: f64,
}

impl ParamBox {
    /// The C++ reference's box |a3| ≤ 2π, |a4|, |a5| ≤ 100.
    pub const PAPER: ParamBox = ParamBox {
        a3_max: std::f64::consts::TAU,
        a45_max: 100.0,
    };
    /// The public oracle box |a3| ≤ 10, |a4|, |a5| ≤ 100 (docs/math.md §7).
    pub const PUBLIC: ParamBox = ParamBox {
        a3_max: 10.0,
        a45_max: 100.0,
    };
}

/// A row of Table 1 for the paper's Newton at one α.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Table1Row {
    /// Step length.
    pub alpha: f64,
    /// Solves run (cases × initial guesses).
    pub runs: usize,
    /// Converged to a stable solution, %.
    pub success_pct: f64,
    /// Failed because an iterate was unstable, %.
    pub instability_pct: f64,
    /// Iteration budget exhausted, %.
    pub max_iterations_pct: f64,
    /// Singular J(1, a), %.
    pub singular_pct: f64,
    /// Non-finite values, %.
    pub non_finite_pct: f64,
    /// Mean iterations of the successful solves.
    pub mean_iterations: f64,
    /// Median time per solve (all solves), µs.
    pub median_us: f64,
    /// Mean time per solve (all solves), µs.
    pub mean_us: f64,
}

/// Figures of the robust solver (or of the tracker) on a set of solves.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobustRow {
    /// What was run.
    pub label: String,
    /// Solves run.
    pub runs: usize,
    /// Returned a solution, %.
    pub success_pct: f64,
    /// Returned solutions that pass an independent re-check (stability test and forward map
    /// within tolerance), % of the returned ones.
    pub verified_pct: f64,
    /// Mean Newton iterations per successful solve (summed over starts).
    pub mean_iterations: f64,
    /// Largest iteration count of a successful solve.
    pub max_iterations: u32,
    /// Mean starts per successful solve.
    pub mean_starts: f64,
    /// Median time per solve, µs.
    pub median_us: f64,
    /// Mean time per solve, µs.
    pub mean_us: f64,
    /// 99th percentile time per solve, µs.
    pub p99_us: f64,
    /// Up to 10 failed targets with their reason (for diagnosis).
    pub failures: Vec<(PlanarPose, String)>,
}

pub use rod_ig_core::rng::SplitMix64;

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i.min(v.len() - 1)]
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

fn pct(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        100.0 * k as f64 / n as f64
    }
}

/// A component of a as users produce them: 10 % exact zeros, else a magnitude log-uniform from
/// 1e-300 to `max` with either sign (the refusal-domain scan and its test).
pub fn log_scale_component(r: &mut rod_ig_core::rng::SplitMix64, max: f64) -> f64 {
    if r.range(0.0, 1.0) < 0.1 {
        return 0.0;
    }
    let m = 10f64.powf(r.range(-300.0, max.log10()));
    if r.range(0.0, 1.0) < 0.5 {
        -m
    } else {
        m
    }
}

/// Independent re-check of a returned solution: stable by the stability test (docs/math.md §5)
/// and Υ(a) within `tolerance` of the target (position and wrapped angle).
pub fn verify(target: &PlanarPose, a: &PlanarParams, tolerance: f64) -> bool {
    let Ok((tip, _)) = planar::tip_and_jacobian(a) else {
        return false;
    };
    let f = [
        tip.x - target.x,
        tip.y - target.y,
        wrap_angle(tip.theta - target.theta),
    ];
    let ok_pose = f[0].hypot(f[1]) <= tolerance && f[2].abs() <= tolerance;
    let ok_stable = planar::stability_verdict(a).is_ok_and(|v| v.is_stable());
    ok_pose && ok_stable
}

/// Table 1 (paper §3.2) for the paper's Newton on `cases`: every case × every initial guess,
/// for each α.
pub fn table1(
    cases: &[IgCase],
    alphas: &[f64],
    max_iterations: u32,
    tolerance: f64,
) -> Vec<Table1Row> {
    let _ = ig::warm_up();
    alphas
        .iter()
        .map(|&alpha| {
            let opts = SolveOptions {
                method: Method::Newton,
                alpha,
                max_iterations,
                tolerance,
                ..SolveOptions::default()
            };
            let (mut ok, mut unst, mut maxit, mut sing, mut nonf) = (0, 0, 0, 0, 0);
            let mut iters = Vec::new();
            let mut times = Vec::new();
            for c in cases {
                for a0 in &c.a0_list {
                    let o = SolveOptions {
                        initial_guess: Some(PlanarParams::from(*a0)),
                        ..opts
                    };
                    let t = Instant::now();
                    let r = solve(&c.target, &o);
                    times.push(t.elapsed().as_secs_f64() * 1e6);
                    match r {
                        Ok(s) => {
                            ok += 1;
                            iters.push(s.iterations as f64);
                        }
                        Err(f) => match f.reason {
                            IgError::LeftStableSet { .. } => unst += 1,
                            IgError::MaxIterations { .. } => maxit += 1,
                            IgError::SingularJacobian { .. } => sing += 1,
                            _ => nonf += 1,
                        },
                    }
                }
            }
            let n = times.len();
            Table1Row {
                alpha,
                runs: n,
                success_pct: pct(ok, n),
                instability_pct: pct(unst, n),
                max_iterations_pct: pct(maxit, n),
                singular_pct: pct(sing, n),
                non_finite_pct: pct(nonf, n),
                mean_iterations: mean(&iters),
                median_us: median(&mut times.clone()),
                mean_us: mean(&times),
            }
        })
        .collect()
}

/// Runs the robust solver on (target, initial guess) pairs and summarises.
pub fn robust_runs(
    label: &str,
    runs: &[(PlanarPose, Option<PlanarParams>)],
    options: &SolveOptions,
) -> RobustRow {
    let _ = ig::warm_up();
    let mut ok = 0;
    let mut verified = 0;
    let mut iters = Vec::new();
    let mut starts = Vec::new();
    let mut times = Vec::new();
    let mut failures = Vec::new();
    let mut max_it = 0;
    for (target, guess) in runs {
        let o = SolveOptions {
            method: Method::Robust,
            initial_guess: *guess,
            ..*options
        };
        let t = Instant::now();
        let r = solve(target, &o);
        times.push(t.elapsed().as_secs_f64() * 1e6);
        match r {
            Ok(s) => {
                ok += 1;
                if verify(target, &s.a, options.tolerance) {
                    verified += 1;
                }
                iters.push(s.iterations as f64);
                max_it = max_it.max(s.iterations);
                starts.push(s.starts as f64);
            }
            Err(f) => {
                if failures.len() < 10 {
                    failures.push((*target, f.to_string()));
                }
            }
        }
    }
    let n = runs.len();
    RobustRow {
        label: label.to_string(),
        runs: n,
        success_pct: pct(ok, n),
        verified_pct: pct(verified, ok),
        mean_iterations: mean(&iters),
        max_iterations: max_it,
        mean_starts: mean(&starts),
        median_us: median(&mut times.clone()),
        mean_us: mean(&times),
        p99_us: quantile(&mut times, 0.99),
        failures,
    }
}

/// The robust solver on `cases` from each of their initial guesses (the Table 1 protocol).
pub fn robust_from_starts(cases: &[IgCase], options: &SolveOptions) -> RobustRow {
    let runs: Vec<_> = cases
        .iter()
        .flat_map(|c| {
            c.a0_list
                .iter()
                .map(|a0| (c.target, Some(PlanarParams::from(*a0))))
        })
        .collect();
    robust_runs("robust, from the cases' initial guesses", &runs, options)
}

/// The robust solver on `cases` without initial guess.
pub fn robust_no_start(cases: &[IgCase], options: &SolveOptions) -> RobustRow {
    let runs: Vec<_> = cases.iter().map(|c| (c.target, None)).collect();
    robust_runs("robust, no initial guess", &runs, options)
}

/// `n` random targets: tips of stable rods drawn uniformly from `bx` (seeded; rods failing the
/// stability test are redrawn, at most 100 n draws in all).
pub fn random_stable_targets(n: usize, seed: u64, bx: ParamBox) -> Vec<(PlanarParams, PlanarPose)> {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::with_capacity(n);
    let mut draws = 0usize;
    while out.len() < n && draws < 100 * n.max(1) {
        draws += 1;
        let a = PlanarParams::new(
            rng.range(-bx.a3_max, bx.a3_max),
            rng.range(-bx.a45_max, bx.a45_max),
            rng.range(-bx.a45_max, bx.a45_max),
        );
        if !planar::stability_verdict(&a).is_ok_and(|v| v.is_stable()) {
            continue;
        }
        let Ok((tip, _)) = planar::tip_and_jacobian(&a) else {
            continue;
        };
        out.push((a, tip));
    }
    out
}

/// The robust solver from no start on `n` random reachable targets of stable rods in `bx`.
pub fn robust_random(n: usize, seed: u64, bx: ParamBox, options: &SolveOptions) -> RobustRow {
    let runs: Vec<_> = random_stable_targets(n, seed, bx)
        .into_iter()
        .map(|(_, b)| (b, None))
        .collect();
    robust_runs(
        &format!(
            "robust, no initial guess, {n} random stable targets |a3|<={:.3}, |a4|,|a5|<={}",
            bx.a3_max, bx.a45_max
        ),
        &runs,
        options,
    )
}

/// A smooth closed target path: an ellipse in (x, y) with θ oscillating,
/// (cx + rx cos φ, ry sin φ, θ0 + dθ sin φ) for `steps` values of φ over one turn.
pub fn ellipse_path(
    cx: f64,
    rx: f64,
    ry: f64,
    theta0: f64,
    dtheta: f64,
    steps: usize,
) -> Vec<PlanarPose> {
    (0..=steps)
        .map(|i| {
            let phi = std::f64::consts::TAU * i as f64 / steps.max(1) as f64;
            PlanarPose::new(
                cx + rx * phi.cos(),
                ry * phi.sin(),
                theta0 + dtheta * phi.sin(),
            )
        })
        .collect()
}

/// A smooth target path through tips of stable rods, with (nearly) uniform steps `db` in tip
/// space (‖Δ(x, y, θ)‖₂): a(τ) moves on a straight line from a random stable rod in `bx` in a
/// random direction (a3 component in [−1, 1], a4 and a5 in [−10, 10]), with the parameter step
/// adapted so that the tip moves by about `db` per target; the path ends before it leaves the
/// stable set (margin > 1e-3). Returns the first path of `steps` targets found (at most 1000
/// tries), or an empty vector.
pub fn random_stable_path(seed: u64, bx: ParamBox, steps: usize, db: f64) -> Vec<PlanarPose> {
    let mut rng = SplitMix64::new(seed);
    let tip_of = |a: &PlanarParams| -> Option<PlanarPose> {
        let st = planar::stability(a).ok()?;
        let (tip, _) = planar::tip_and_jacobian(a).ok()?;
        (st.stable && st.margin > 1e-3).then_some(tip)
    };
    for _ in 0..1000 {
        let starts = random_stable_targets(1, rng.next_u64(), bx);
        let Some(&(a0, b0)) = starts.first() else {
            continue;
        };
        let d = PlanarParams::new(
            rng.range(-1.0, 1.0),
            10.0 * rng.range(-1.0, 1.0),
            10.0 * rng.range(-1.0, 1.0),
        );
        let mut path = Vec::with_capacity(steps);
        path.push(b0);
        let mut a = a0;
        let mut b = b0;
        let mut h = 1e-3;
        'walk: while path.len() < steps {
            // Adapt h so that the tip step is within [0.7, 1.3] db (a few secant tries).
            for _ in 0..8 {
                let an = a + d * h;
                let Some(bn) = tip_of(&an) else {
                    break 'walk;
                };
                let step = (bn.to_vector() - b.to_vector()).norm();
                if !(step.is_finite() && step > 0.0) {
                    break 'walk;
                }
                if (0.7 * db..=1.3 * db).contains(&step) {
                    a = an;
                    b = bn;
                    path.push(bn);
                    continue 'walk;
                }
                h *= (db / step).clamp(0.1, 10.0);
            }
            break;
        }
        if path.len() == steps {
            return path;
        }
    }
    Vec::new()
}

/// Figures of the [`Tracker`] along one target path.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrackingRow {
    /// What was run.
    pub label: String,
    /// Targets on the path.
    pub steps: usize,
    /// Solved, %.
    pub success_pct: f64,
    /// Solutions passing the independent re-check, % of the solved.
    pub verified_pct: f64,
    /// Mean Newton iterations per step (first, cold solve excluded).
    pub mean_iterations: f64,
    /// Max iterations of a step (first excluded).
    pub max_iterations: u32,
    /// Median time per step, µs.
    pub median_us: f64,
    /// Mean time per step, µs.
    pub mean_us: f64,
}

/// Runs a fresh [`Tracker`] along `path`.
pub fn tracking(label: &str, path: &[PlanarPose], options: &SolveOptions) -> TrackingRow {
    let _ = ig::warm_up();
    let mut tr = Tracker::new(*options);
    let (mut ok, mut verified) = (0, 0);
    let mut iters = Vec::new();
    let mut times = Vec::new();
    let mut max_it = 0;
    for (i, b) in path.iter().enumerate() {
        let t = Instant::now();
        let r = tr.solve(b);
        let us = t.elapsed().as_secs_f64() * 1e6;
        if let Ok(s) = r {
            ok += 1;
            if verify(b, &s.a, options.tolerance) {
                verified += 1;
            }
            if i > 0 {
                iters.push(s.iterations as f64);
                max_it = max_it.max(s.iterations);
            }
        }
        if i > 0 {
            times.push(us);
        }
    }
    TrackingRow {
        label: label.to_string(),
        steps: path.len(),
        success_pct: pct(ok, path.len()),
        verified_pct: pct(verified, ok),
        mean_iterations: mean(&iters),
        max_iterations: max_it,
        median_us: median(&mut times.clone()),
        mean_us: mean(&times),
    }
}
