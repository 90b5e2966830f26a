//! Forward map, J, energy and stability near the separatrix and under strong axial force,
//! against a rigorous 320-bit reference: `data/separatrix_truth.jsonl`, written by
//! `scripts/gen_separatrix_truth.py` (Taylor integration in arb ball arithmetic, python-flint:
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
use common::numbers;

/// Issue 9's tolerances.
const TIP_TOL: f64 = 1e-9;
const JAC_TOL: f64 = 1e-6;
const ENERGY_TOL: f64 = 1e-8;
/// A clear verdict: |det_min| above this.
const CLEAR_MARGIN: f64 = 1e-3;
/// √‖F‖ up to which every rod must be answered (the double-double series is certified there).
const CERTIFIED_ROOT_F: f64 = 27.0;
/// Largest share of the sample that may be refused: the refusals are rods with moment and
/// transverse force ≲ 1e-8 under a4 ≳ 700 where even the cross-check fails, 7 of these 600
/// deliberately extreme rods (and 5 of 700 more in a wider sample).
const MAX_REFUSED_SHARE: f64 = 0.03;

#[test]
fn separatrix_rods_match_the_rigorous_reference_or_are_refused() {
    let text = include_str!("data/separatrix_truth.jsonl");
    let (mut n, mut refused) = (0usize, 0usize);
    let (mut worst_tip, mut worst_jac, mut worst_energy) = (0.0f64, 0.0f64, 0.0f64);
    let mut failures = Vec::new();
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        let v: serde_json::Value = serde_json::from_str(line).expect("reference line");
        let a = numbers(&v["a"]);
        let a = PlanarParams::new(a[0], a[1], a[2]);
        // the reference's own rounding bound is far below the tolerances checked here
        assert!(v["radius"].as_f64().expect("radius") < 1e-20, "{line}");
        n += 1;
        let root_f = a[1].hypot(a[2]).sqrt();
        let eval = match planar::evaluate(&a) {
            Ok(e) => e,
            Err(e) => {
                refused += 1;
                let msg = e.to_string();
                if root_f <= CERTIFIED_ROOT_F || !msg.contains("cannot be certified") {
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
            if eval.stability.uncertain || eval.stability.stable != stable {
                failures.push(format!(
                    "{:?}: verdict {:?}, reference stable = {stable} (det_min {})",
                    a.as_slice(),
                    eval.stability,
                    v["det_min"]
                ));
            }
        }
    }
    eprintln!(
        "{n} rods: {refused} refused, max |Δtip| {worst_tip:.2e}, max rel ‖ΔJ‖ {worst_jac:.2e}, \
         max rel Δenergy {worst_energy:.2e}"
    );
    assert!(n >= 200, "only {n} reference rods");
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(
        (refused as f64) <= MAX_REFUSED_SHARE * n as f64,
        "{refused} of {n} refused"
    );
}

/// Rods of issue 9's strong-force family, against `scripts/gen_separatrix_truth.py`'s reference
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
