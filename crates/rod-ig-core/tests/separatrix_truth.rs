//! Forward map, J, energy and stability near the separatrix and under strong axial force,
//! against a rigorous 320-bit reference: `data/separatrix_truth.jsonl`, written by
//! `scripts/references/gen_separatrix_truth.py` (Taylor integration in arb ball arithmetic, python-flint:
//! every reference number carries a proven bound on its rounding, recorded as `radius`).
//!
//! The sample (seeded): moments and transverse forces from 1e-14 to 1, axial forces from 1 to
//! 1e4 of either sign, and moderate forces with tiny to moderate bending. There the rod lingers
//! by the unstable straight equilibrium and rounding along an integration grows like
//! e^{√‖F‖}: an f64 or even double-double integration can be wrong, and before this test the
//! forward map returned such wrong tips (off by up to 0.25) and J (off by 100 %) as success.
//!
//! Acceptance (issue 9): every call either answers within the tolerances (tip 1e-9,
//! J 1e-6 relative Frobenius, energy 1e-8 relative, the verdict equal wherever the reference's
//! margin is clear, |det_min| > 1e-3) or refuses with a clear error — and refuses only where no
//! certified method exists (√‖F‖ beyond the double-double series' certified 27, with the
//! closed form's own estimate above its last-resort tolerance and the closed form and a tight
//! double-double series disagreeing).

use rod_ig_core::planar;
use rod_ig_core::{PlanarJacobian, PlanarParams};

mod common;
use common::{json_lines, numbers};

/// Issue 9's tolerances.
const TIP_TOL: f64 = 1e-9;
const JAC_TOL: f64 = 1e-6;
const ENERGY_TOL: f64 = 1e-8;
/// A clear verdict: |det_min| above this.
const CLEAR_MARGIN: f64 = 1e-3;
/// The references' det J grid spacing in t (`GRID` = 2000 in the script): their first
/// conjugate point is the first grid point where det J ≤ 0 (or its ball contains 0).
const CONJUGATE_GRID: f64 = 1.0 / 2000.0;
/// Allowance on our conjugate point beyond that grid cell (regula falsi stops at 1e-7).
const CONJUGATE_TOL: f64 = 1e-4;
/// √‖F‖ up to which every rod must be answered (the double-double series is certified there).
const CERTIFIED_ROOT_F: f64 = 27.0;
/// Largest share of the sample whose stability may come back uncertain although the reference
/// is clear. Until the closed form ran in double-double, 7 of these 600 rods (moment and
/// transverse force ≲ 1e-8 under a4 ≳ 700) were refused outright: neither the f64 closed form
/// nor the double-double series certified their tip and J. Now every one is answered, tip, J
/// and energy right, and with the double-double pass of the stability scan none is uncertain
/// (measured 0; the share leaves room for libm differences between machines).
const MAX_UNCERTAIN_SHARE: f64 = 0.01;

#[test]
fn separatrix_rods_match_the_rigorous_reference_or_are_refused() {
    check_reference(include_str!("data/separatrix_truth.jsonl")).assert_within(
        200,
        MAX_UNCERTAIN_SHARE,
        0.0,
    );
}

/// Largest share of issue 23's tiny-bending sample left uncertain although the reference is
/// clear; none may be refused. Measured 0 of 160 (before the closed form in double-double: 2
/// uncertain and 16 refused, rods whose bending, grown from ~1e-12 by e^{√‖F‖ t}, loops late
/// on the rod; with it, before its stability pass: 15 uncertain).
const MAX_EXTREME_UNCERTAIN_SHARE: f64 = 0.01;

/// Issue 23's independent sample (`scripts/references/gen_separatrix_truth.py --extreme`): axial force
/// 1e3..1e4 of either sign, moment and transverse force 1e-14..1e-6 with exact zeros, and the
/// rod the issue quotes. Before, the double-double scan called 30 of 1,429 such rods (stable,
/// det_min 3..250) "unstable" with a certain verdict, its rounding bound blind to the e^{√‖F‖ t}
/// growth. Now no verdict, tip or J is wrong, and refusals say why.
#[test]
fn tiny_bending_under_strong_force_is_never_wrong() {
    check_reference(include_str!("data/separatrix_truth_extreme.jsonl")).assert_within(
        150,
        MAX_EXTREME_UNCERTAIN_SHARE,
        0.0,
    );
    // The rod issue 23 quotes (stable, det_min 2.73 at 320 and 480 bits): stable, certain,
    // with that margin (it was "uncertain" with margin −2.1e39).
    let quoted = PlanarParams::new(0.0, 2473.289745880672, 2.3178627609785778e-14);
    let s = planar::stability(&quoted).expect("issue 23's rod");
    assert!(s.stable && !s.uncertain, "{s:?}");
    assert!((s.margin - 2.73).abs() < 0.01, "{s:?}");
}

/// `planar::stability` alone — not behind `evaluate`, which refuses the rods whose forward map
/// cannot be certified — on every reference rod with a clear verdict (643): never wrong.
/// Before, five unstable rods (√‖F‖ 76–90, m1 ≤ 3.5e-26, forward map refused) came back
/// "stable" with margins 12–22: the double-double scan certified its margin but trusted the
/// sign of g where its bound was far above g. Now, where the closed form and the series
/// disagree on q(1) and J(1), a stable verdict needs every sample certified; and the norm-wise
/// scan runs a second pass on the closed form in double-double before the series: measured,
/// none of the 643 uncertain (19 after the first change, 7 before it), none wrong.
#[test]
fn stability_alone_is_never_wrong_on_the_references() {
    let files = [
        include_str!("data/separatrix_truth.jsonl"),
        include_str!("data/separatrix_truth_extreme.jsonl"),
        include_str!("data/stability_truth_tiny_bending.jsonl"),
    ];
    let (mut n, mut uncertain, mut worst_margin) = (0, 0, 0.0f64);
    for v in files.iter().flat_map(|f| json_lines(f)) {
        let (Some(det_min), Some(stable)) = (v["det_min"].as_f64(), v["stable"].as_bool()) else {
            continue;
        };
        if det_min.abs() <= CLEAR_MARGIN {
            continue;
        }
        let a = numbers(&v["a"]);
        let a = PlanarParams::new(a[0], a[1], a[2]);
        n += 1;
        let s = planar::stability(&a).unwrap_or_else(|e| panic!("{a:?}: {e}"));
        if s.stable {
            worst_margin = worst_margin.max((s.margin - det_min).abs() / det_min.abs());
        }
        if s.uncertain {
            uncertain += 1;
        } else {
            assert_eq!(
                s.stable, stable,
                "{a:?}: {s:?}, reference det_min {det_min}"
            );
        }
    }
    eprintln!(
        "{n} rods: {uncertain} uncertain; stable margins within {worst_margin:.1e} of det_min"
    );
    assert_eq!(n, 643);
    assert!(uncertain <= 2, "{uncertain} uncertain");
    // g's narrow dips under a strong tension (~1/√‖F‖ wide) sit at Γ = K(2j + 1) or at the
    // window's ends, where the scan samples and probes them: stable margins within 5.0e-3 of
    // the reference's grid minimum (0.74 when the grid alone sampled them).
    assert!(worst_margin <= 0.02, "{worst_margin}");
}

/// The 110 rods of a seeded tiny-bending sample (a4 ±1e2..1e4, a3 and a5 ±1e-14..1e-6 with
/// exact zeros; `extended_pass_agrees_with_the_series_scan`'s) whose f64 norm-wise scan is
/// uncertain and that the second pass on the closed form in double-double decides, against
/// their 320-bit verdicts (`scripts/references/gen_separatrix_truth.py --verdicts`; 100 stable, 10
/// unstable, all clear): every verdict right and certain, stable margins within 5e-2 of the
/// reference's (measured 2.2e-2). The double-double series scan left 18 of them uncertain.
#[test]
fn extended_pass_verdicts_match_the_reference() {
    let (mut n, mut worst) = (0, 0.0f64);
    for v in json_lines(include_str!("data/stability_truth_extended_pass.jsonl")) {
        let a = numbers(&v["a"]);
        let a = PlanarParams::new(a[0], a[1], a[2]);
        let stable = v["stable"].as_bool().expect("clear verdict");
        let det_min = v["det_min"].as_f64().expect("det_min");
        let s = planar::stability(&a).unwrap_or_else(|e| panic!("{a:?}: {e}"));
        assert!(
            !s.uncertain && s.stable == stable,
            "{a:?}: {s:?}, reference det_min {det_min}"
        );
        if stable {
            worst = worst.max((s.margin - det_min).abs() / det_min.abs());
        }
        n += 1;
    }
    eprintln!("{n} rods right; stable margins within {worst:.1e} of the reference's");
    assert_eq!(n, 110);
    assert!(worst <= 5e-2, "{worst}");
}

/// 30 stable rods (det_min 3.8..250, 320-bit reference) of a seeded tiny-bending sample under
/// tension 1e3..1e4 that the double-double stability scan called "unstable" with a certain
/// verdict (margins down to -1e29): its rounding bound ignored the e^{√‖F‖ t} growth. Now each
/// is stable with the reference's margin.
#[test]
fn stable_rods_the_double_double_scan_called_unstable() {
    let text = include_str!("data/stability_truth_tiny_bending.jsonl");
    let mut n = 0;
    for v in json_lines(text) {
        let a = numbers(&v["a"]);
        let a = PlanarParams::new(a[0], a[1], a[2]);
        let det_min = v["det_min"].as_f64().expect("det_min");
        assert_eq!(v["stable"].as_bool(), Some(true), "{v}");
        let s = planar::stability(&a).expect("a verdict");
        // The margin is the scan's refined minimum, the reference's the minimum over a grid of
        // 2000 points: both find the same minimum at t = 0.05 here.
        assert!(
            s.stable && !s.uncertain && (s.margin - det_min).abs() <= 1e-9 * det_min,
            "{:?}: {s:?}, reference det_min {det_min}",
            a.as_slice()
        );
        n += 1;
    }
    assert_eq!(n, 30);
}

/// What [`check_reference`] found.
struct ReferenceReport {
    n: usize,
    refused: usize,
    /// Wrong answers (tip, J, energy or a verdict different from a clear reference).
    failures: Vec<String>,
    /// Uncertain verdicts where the reference is clear.
    uncertain: Vec<String>,
}

impl ReferenceReport {
    /// At least `min_n` rods, no wrong answer, and at most these shares of the rods uncertain
    /// where the reference is clear, and refused.
    fn assert_within(&self, min_n: usize, uncertain_share: f64, refused_share: f64) {
        let n = self.n as f64;
        assert!(self.n >= min_n, "only {} reference rods", self.n);
        assert!(
            self.failures.is_empty(),
            "{} failures:\n{}",
            self.failures.len(),
            self.failures.join("\n")
        );
        assert!(
            self.uncertain.len() as f64 <= uncertain_share * n,
            "{} of {} uncertain where the reference is clear:\n{}",
            self.uncertain.len(),
            self.n,
            self.uncertain.join("\n")
        );
        assert!(
            self.refused as f64 <= refused_share * n,
            "{} of {} refused",
            self.refused,
            self.n
        );
    }
}

/// Every rod of a reference file against `planar::evaluate`: tips, J and energy within issue
/// 9's tolerances, refusals only where no certified method exists, and the verdict wherever
/// the reference's margin is clear.
fn check_reference(text: &str) -> ReferenceReport {
    let (mut n, mut refused) = (0usize, 0usize);
    let (mut worst_tip, mut worst_jac, mut worst_energy) = (0.0f64, 0.0f64, 0.0f64);
    let mut worst_conjugate = 0.0f64;
    let (mut failures, mut uncertain) = (Vec::new(), Vec::new());
    for v in json_lines(text) {
        let a = numbers(&v["a"]);
        let a = PlanarParams::new(a[0], a[1], a[2]);
        // the reference's own rounding bound is far below the tolerances checked here
        assert!(v["radius"].as_f64().expect("radius") < 1e-20, "{v}");
        n += 1;
        let root_f = a[1].hypot(a[2]).sqrt();
        let eval = match planar::evaluate(&a) {
            Ok(e) => e,
            Err(e) => {
                refused += 1;
                let msg = e.to_string();
                let certified_refusal =
                    msg.contains("cannot be certified") || msg.contains("bounded time");
                if root_f <= CERTIFIED_ROOT_F || !certified_refusal {
                    failures.push(format!("{:?}: refused: {msg}", a.as_slice()));
                }
                continue;
            }
        };
        let tip = numbers(&v["tip"]);
        let dtip = (eval.tip.x - tip[0])
            .abs()
            .max((eval.tip.y - tip[1]).abs())
            .max((eval.tip.theta - tip[2]).abs());
        let rows: Vec<f64> = v["jac"]
            .as_array()
            .expect("jac")
            .iter()
            .flat_map(numbers)
            .collect();
        let j_ref = PlanarJacobian::from_row_slice(&rows);
        let djac = (eval.jacobian - j_ref).norm() / j_ref.norm();
        let e_ref = v["energy"].as_f64().expect("energy");
        let denergy = (eval.energy - e_ref).abs() / e_ref.abs();
        worst_tip = worst_tip.max(dtip);
        worst_jac = worst_jac.max(djac);
        worst_energy = worst_energy.max(denergy);
        if !(dtip <= TIP_TOL && djac <= JAC_TOL && denergy <= ENERGY_TOL) {
            failures.push(format!(
                "{:?}: tip {dtip:e}, J {djac:e}, energy {denergy:e}",
                a.as_slice()
            ));
        }
        let clear = v["det_min"]
            .as_f64()
            .is_some_and(|m| m.abs() > CLEAR_MARGIN);
        if let (Some(stable), true) = (v["stable"].as_bool(), clear) {
            let line = format!(
                "{:?}: verdict {:?}, reference stable = {stable} (det_min {})",
                a.as_slice(),
                eval.stability,
                v["det_min"]
            );
            if eval.stability.uncertain {
                uncertain.push(line);
            } else if eval.stability.stable != stable {
                failures.push(line);
            } else if let (Some(tc), Some(tc_ref)) = (
                eval.stability.first_conjugate_t,
                v["first_conjugate"].as_f64(),
            ) {
                // The reference's first grid point (spacing 1/2000) with det J ≤ 0 lies at or
                // just after the root.
                let dev = tc - tc_ref;
                worst_conjugate = worst_conjugate.max(dev.abs());
                if !(-CONJUGATE_GRID - CONJUGATE_TOL..=CONJUGATE_TOL).contains(&dev) {
                    failures.push(format!("{line}: conjugate point {tc}, reference {tc_ref}"));
                }
            }
        }
    }
    eprintln!(
        "{n} rods: {refused} refused, {} uncertain, max |Δtip| {worst_tip:.2e}, max rel ‖ΔJ‖ \
         {worst_jac:.2e}, max rel Δenergy {worst_energy:.2e}, max |Δ conjugate point| \
         {worst_conjugate:.1e}",
        uncertain.len()
    );
    ReferenceReport {
        n,
        refused,
        failures,
        uncertain,
    }
}

/// Rods of issue 9's strong-force family, against `scripts/references/gen_separatrix_truth.py`'s reference
/// (run on these two a): either right or refused, never wrong. The first, a tension of 8158
/// with a moment of 5e-12, came back as success with θ off by 0.034 rad, J off by 100 % and the
/// verdict "unstable" (margin -1.7e28; it is stable, det_min 127); the second took 25 ms on the
/// double-double series (the f64 reference integrator is off by 3e-9 in y there).
#[test]
fn strong_tension_with_tiny_bending_is_right_or_refused() {
    let cases: [([f64; 3], [f64; 3]); 2] = [
        (
            [
                -4.856704215888861e-12,
                8158.235918634759,
                3.872666136073949e-14,
            ],
            [0.955714456895244, -2.266840511124896e-5, -6.285232784836767],
        ),
        (
            [
                0.0018555787994198266,
                9451.308709317114,
                -0.0038858381164479133,
            ],
            [0.8354212295658175, 5.453936815971523e-5, 25.127386166577907],
        ),
    ];
    for (a, tip) in cases {
        let a = PlanarParams::new(a[0], a[1], a[2]);
        match planar::evaluate(&a) {
            Ok(e) => {
                let d = (e.tip.x - tip[0])
                    .abs()
                    .max((e.tip.y - tip[1]).abs())
                    .max((e.tip.theta - tip[2]).abs());
                assert!(d <= TIP_TOL, "{:?}: tip off by {d:e}", a.as_slice());
            }
            Err(e) => assert!(
                e.to_string().contains("cannot be certified"),
                "{:?}: {e}",
                a.as_slice()
            ),
        }
    }
}

/// Tension beyond the double-double series' reach (`scripts/references/gen_separatrix_truth.py --strong`:
/// 48 rods, √‖F‖ 101..470, moment and transverse force 1e-14..1e-3 with exact zeros, each at
/// up to 880 bits): every answer right, none refused, at most 5 % uncertain. Measured: tips
/// within 1.4e-14, J 1.2e-10, energies 7.5e-15, every verdict given right, 1 uncertain (its
/// margin equal to the reference's to 1e-10). Before the closed form in double-double was
/// measured here (it stopped at √‖F‖ = 100), most such rods were refused ("bounded time":
/// 276 of 400 in a sample like this one).
#[test]
fn tension_beyond_the_series_reach() {
    check_reference(include_str!("data/separatrix_truth_strong.jsonl"))
        .assert_within(45, 0.05, 0.0);
}

/// Up to where J ≈ e^{√‖F‖} overflows f64 (`--edge`: 16 rods, √‖F‖ 513..692, up to 1,200
/// bits): every answer right, none refused, at most one uncertain. Measured: tips within
/// 1.4e-14, J 3.0e-12, energies 5.8e-15, every verdict right, none uncertain.
#[test]
fn tension_up_to_the_edge_of_f64() {
    check_reference(include_str!("data/separatrix_truth_edge.jsonl")).assert_within(16, 0.07, 0.0);
}
