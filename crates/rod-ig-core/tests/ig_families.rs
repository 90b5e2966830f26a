//! Issue 9, point 3: the robust inverse geometry solves ≥ 99.5 % of the targets that stable
//! rods of every family reach — log-scale, moment with tiny force, small force, tiny, strong
//! axial force, and the paper's box — for the default and the least-energy objective, and
//! every success is a verified stable rod.
//!
//! Families as in `data/oracle/relaxed_public.jsonl`'s README, drawn with our own seeds.
//! Targets: tips of rods our stability test calls stable with a clear verdict, ‖(x, y)‖ < 1.
//! The deadline is raised to 5 s so that the outcome depends on the iteration budgets, not on
//! the machine's speed (the 250 ms default cuts ≈ 0.2 % of strong-force solves, whose
//! evaluations run in double-double; those are reported as `Deadline`, never as success).
//!
//! Independent check of each success: tip and stability by the DOP853 reference where it is
//! accurate (√‖F‖ ≤ 10: its rounding grows like e^{√‖F‖}); under strong force, where no f64
//! integrator is, by the double-double series, which `relaxed_oracle.rs` checks against
//! 40-digit references.

use rod_ig_core::planar::ig::{self, Objective, SolveOptions};
use rod_ig_core::rng::SplitMix64;
use rod_ig_core::{planar, wrap_angle, PlanarParams, PlanarPose};
use std::time::Duration;

fn signed_pow10(r: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    let v = 10f64.powf(r.range(lo, hi));
    if r.uniform() < 0.5 {
        -v
    } else {
        v
    }
}

fn signed(r: &mut SplitMix64, v: f64) -> f64 {
    if r.uniform() < 0.5 {
        -v
    } else {
        v
    }
}

type Family = (&'static str, fn(&mut SplitMix64) -> PlanarParams);

const FAMILIES: [Family; 6] = [
    ("log-scale", |r| {
        PlanarParams::new(
            signed_pow10(r, -8.0, 0.7),
            signed_pow10(r, -9.0, 1.5),
            signed_pow10(r, -9.0, 1.5),
        )
    }),
    ("moment, tiny force", |r| {
        let a3 = r.range(0.01, 6.0);
        PlanarParams::new(
            signed(r, a3),
            signed_pow10(r, -12.0, -3.0),
            signed_pow10(r, -12.0, -3.0),
        )
    }),
    ("small force, tiny or no moment", |r| {
        let a3 = if r.uniform() < 0.2 {
            0.0
        } else {
            signed_pow10(r, -12.0, -3.0)
        };
        let a4 = if r.uniform() < 0.2 {
            0.0
        } else {
            signed_pow10(r, -6.0, 0.5)
        };
        PlanarParams::new(a3, a4, signed_pow10(r, -6.0, 0.5))
    }),
    ("tiny", |r| {
        PlanarParams::new(
            signed_pow10(r, -60.0, -6.0),
            if r.uniform() < 0.2 {
                0.0
            } else {
                signed_pow10(r, -60.0, -6.0)
            },
            signed_pow10(r, -60.0, -6.0),
        )
    }),
    ("strong axial force", |r| {
        PlanarParams::new(
            signed_pow10(r, -6.0, 0.0),
            signed_pow10(r, 2.0, 4.0),
            signed_pow10(r, -6.0, 0.0),
        )
    }),
    ("paper's box", |r| {
        PlanarParams::new(
            r.range(-10.0, 10.0),
            r.range(-100.0, 100.0),
            r.range(-100.0, 100.0),
        )
    }),
];

/// Up to `n` targets: tips of clearly stable rods of the family, strictly inside the disc.
fn targets(family: fn(&mut SplitMix64) -> PlanarParams, seed: u64, n: usize) -> Vec<PlanarPose> {
    let mut r = SplitMix64::new(seed);
    let mut out = Vec::new();
    for _ in 0..200 * n {
        if out.len() == n {
            break;
        }
        let a = family(&mut r);
        let Ok(st) = planar::stability(&a) else {
            continue;
        };
        if !st.stable || st.uncertain {
            continue;
        }
        let Ok(tip) = planar::tip(&a) else { continue };
        if tip.x.hypot(tip.y) < 1.0 {
            out.push(tip);
        }
    }
    out
}

/// The independent check of a success (see the module docs); `None` when it passes.
fn check(target: &PlanarPose, a: &PlanarParams, tol: f64) -> Option<String> {
    use rod_ig_core::ode::planar_reference as reference;
    let force = a[1].hypot(a[2]);
    let (tip, stable) = if force.sqrt() <= 10.0 {
        let (tip, _) = reference::tip_and_jacobian_relative(a, 1e-12).ok()?;
        (tip, reference::stability(a).ok()?.stable)
    } else {
        (planar::tip(a).ok()?, planar::stability(a).ok()?.stable)
    };
    let dp = (tip.x - target.x).hypot(tip.y - target.y);
    let dth = wrap_angle(tip.theta - target.theta).abs();
    // The reference's own error (rtol 1e-12 through a J of norm ≲ 1e3) on top of the tolerance.
    let allowance = 1e-8;
    (dp > tol + allowance || dth > tol + allowance || !stable)
        .then(|| format!("a = {a:?}: tip {tip:?} vs {target:?} ({dp:e}, {dth:e}), stable {stable}"))
}

fn run(objective: Objective, per_family: usize, seed: u64) {
    let opts = SolveOptions {
        objective,
        deadline: Duration::from_secs(5),
        ..SolveOptions::default()
    };
    let mut report = String::new();
    let mut all_ok = true;
    for (name, family) in FAMILIES {
        let ts = targets(family, seed, per_family);
        assert!(
            ts.len() >= per_family / 2,
            "{name}: only {} targets",
            ts.len()
        );
        let mut solved = 0;
        let mut reasons = Vec::new();
        for t in &ts {
            match ig::solve(t, &opts) {
                Ok(s) => {
                    if let Some(bad) = check(t, &s.a, opts.tolerance) {
                        panic!("{name}: wrong answer returned as success: {bad}");
                    }
                    solved += 1;
                }
                Err(f) => reasons.push(format!("{t:?}: {}", f.reason)),
            }
        }
        let rate = solved as f64 / ts.len() as f64;
        report += &format!(
            "{name}: {solved}/{} ({:.2} %) {reasons:?}\n",
            ts.len(),
            100.0 * rate
        );
        all_ok &= rate >= 0.995;
    }
    eprintln!("{report}");
    assert!(all_ok, "below 99.5 % in some family:\n{report}");
}

#[test]
fn robust_solve_every_family_default_objective() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    run(Objective::FirstFound, 400, 91);
}

#[test]
fn robust_solve_every_family_least_energy() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    run(Objective::LeastEnergy, 150, 92);
}

/// Work, not time: near full extension (distance from the base > 0.99) the first families'
/// targets are solved from the small-angle start before any atlas seed. Counted per solve:
/// starts and iterations (before the small-angle start went first: 4.2 starts and 125
/// iterations on average for the log-scale targets within 1e-4 of full extension).
#[test]
fn near_full_extension_solves_from_the_small_angle_start() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    let opts = SolveOptions::default();
    for (name, family) in &FAMILIES[..3] {
        let ts: Vec<PlanarPose> = targets(*family, 93, 400)
            .into_iter()
            .filter(|t| t.x.hypot(t.y) > 0.99)
            .collect();
        assert!(ts.len() >= 20, "{name}: only {} targets", ts.len());
        let (mut starts, mut iterations, mut solved) = (0u32, 0u32, 0usize);
        for t in &ts {
            if let Ok(s) = ig::solve(t, &opts) {
                starts += s.starts;
                iterations += s.iterations;
                solved += 1;
            }
        }
        let n = solved as f64;
        let (mean_starts, mean_iterations) = (starts as f64 / n, iterations as f64 / n);
        eprintln!(
            "{name}: {solved}/{} solved, {mean_starts:.2} starts, {mean_iterations:.1} iterations",
            ts.len()
        );
        assert!(
            solved as f64 >= 0.99 * ts.len() as f64,
            "{name}: {solved}/{}",
            ts.len()
        );
        assert!(mean_starts <= 1.3, "{name}: {mean_starts} starts per solve");
        assert!(
            mean_iterations <= 6.0,
            "{name}: {mean_iterations} iterations per solve"
        );
    }
}
