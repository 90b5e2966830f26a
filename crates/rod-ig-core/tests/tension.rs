//! Barely bent rods under strong tension (issue 42, item 2; issue 53, item 4: the separatrix
//! limit in log form, `data/separatrix_limit_truth.jsonl`, answers every rod with
//! ρ = max(|β|, |a3|/√R) ≤ 1e-7 and never a wrong tip): a = (a3, a4, a5) with a4 > 0,
//! |a3| and |a5| log-uniform down to 1e-300, √a4 up to 700. The rod sits by its unstable
//! straight equilibrium, then loops where ln(8√a4/|a3|)/√a4 < 1: the regime where a wrong tip
//! slipped between a refusal and the series (θ = −6π for 2π at a = (1e-100, 240000, 0)).
//!
//! The reference is the exact pendulum (`scripts/references/gen_tension_truth.py`: Jacobi functions at
//! the complementary parameter m1 passed exactly, mpmath at 80 + 1.5·log10(1/m1) digits, J by
//! central differences; cross-checked against a Taylor integration of the ODE). Every rod is
//! answered within the tolerances (tip 1e-9 absolute, J 1e-6 relative (Frobenius),
//! energy 1e-9 relative or 1e-200 absolute) or refused with a reason, and every tip `shape` (`PlanarRod`) draws
//! is right; shape refuses every rod forward refuses (one domain: beyond √‖F‖ = 25 the full
//! evaluation decides for every entry point; before, shape drew 12 of these rods whose
//! stability forward could not certify).

use rod_ig_core::planar::{self, PlanarRod};
use rod_ig_core::{PlanarJacobian, PlanarParams};
use serde_json::Value;

struct Truth {
    a: PlanarParams,
    tip: [f64; 3],
    jacobian: PlanarJacobian,
    energy: f64,
}

fn truths() -> Vec<Truth> {
    let text = concat!(
        include_str!("data/tension_truth.jsonl"),
        include_str!("data/tension_near_straight.jsonl"),
        include_str!("data/separatrix_limit_truth.jsonl"),
        include_str!("data/separatrix_limit_edge.jsonl")
    );
    text.lines()
        .map(|line| {
            let v: Value = serde_json::from_str(line).expect("JSON line");
            let f = |x: &Value| x.as_f64().expect("number");
            let a: Vec<f64> = v["a"].as_array().expect("a").iter().map(f).collect();
            let tip: Vec<f64> = v["tip"].as_array().expect("tip").iter().map(f).collect();
            let j: Vec<f64> = v["jacobian"]
                .as_array()
                .expect("J")
                .iter()
                .flat_map(|r| r.as_array().expect("row").iter().map(f))
                .collect();
            Truth {
                a: PlanarParams::new(a[0], a[1], a[2]),
                tip: [tip[0], tip[1], tip[2]],
                jacobian: PlanarJacobian::from_row_slice(&j),
                energy: f(&v["energy"]),
            }
        })
        .collect()
}

/// Tip (absolute), J (relative, Frobenius) and energy (relative, or absolute below 1e-300)
/// tolerances of the issue.
const TIP_TOL: f64 = 1e-9;
const J_TOL: f64 = 1e-6;
const ENERGY_TOL: f64 = 1e-9;
const ENERGY_FLOOR: f64 = 1e-200;

/// The tip error of `p` (absolute, the largest coordinate).
fn tip_error(p: &rod_ig_core::PlanarPose, t: &Truth) -> f64 {
    (p.x - t.tip[0])
        .abs()
        .max((p.y - t.tip[1]).abs())
        .max((p.theta - t.tip[2]).abs())
}

#[test]
fn barely_bent_rods_under_tension_are_answered_right_or_refused() {
    let truths = truths();
    assert!(truths.len() >= 100, "{} reference rods", truths.len());
    let (mut answered, mut refused, mut worst_tip, mut worst_j) = (0, 0, 0.0f64, 0.0f64);
    let (mut wrong, mut shape_only) = (Vec::new(), 0);
    for t in &truths {
        // shape (`PlanarRod`): a tip it draws is right, whatever forward does.
        if let Ok(rod) = PlanarRod::new(&t.a) {
            let err = tip_error(&rod.tip(), t);
            // NaN counts as wrong.
            if err.is_nan() || err > TIP_TOL {
                wrong.push(format!("{:?}: shape's tip off by {err:.1e}", t.a));
            }
            shape_only += usize::from(planar::evaluate(&t.a).is_err());
        }
        let e = match planar::evaluate(&t.a) {
            Ok(e) => e,
            Err(err) => {
                refused += 1;
                assert!(!err.to_string().is_empty(), "{:?}: a refusal says why", t.a);
                continue;
            }
        };
        answered += 1;
        let tip_err = tip_error(&e.tip, t);
        // Scaled first: the entries reach 1e195, whose squares overflow.
        let scale = t.jacobian.amax();
        let j_err = ((e.jacobian - t.jacobian) / scale).norm() / (t.jacobian / scale).norm();
        let energy_err = (e.energy - t.energy).abs() / t.energy.abs().max(1e-300);
        worst_tip = worst_tip.max(tip_err);
        worst_j = worst_j.max(j_err);
        // Below |a3| ≈ 1e-154 a3² underflows and energies of 1e-270 come out 0: an absolute
        // floor far below any use (the unit is EI/L).
        let energy_ok = energy_err <= ENERGY_TOL || (e.energy - t.energy).abs() <= ENERGY_FLOOR;
        if !(tip_err <= TIP_TOL && j_err <= J_TOL && energy_ok) {
            wrong.push(format!(
                "{:?}: tip {tip_err:.1e}, J {j_err:.1e}, energy {energy_err:.1e}",
                t.a
            ));
        }
    }
    eprintln!(
        "{answered} answered (worst tip {worst_tip:.1e}, J {worst_j:.1e}), {refused} refused \
         ({shape_only} of them drawn right by shape)"
    );
    assert!(wrong.is_empty(), "wrong answers:\n{}", wrong.join("\n"));
    assert_eq!(shape_only, 0, "shape draws rods forward refuses");
}

/// The separatrix limit in log form (issue 53, item 4) answers every rod of its domain, where
/// 1 − k² ≈ ρ² underflows f64 (ρ = max(|β|, |a3|/√R) ≤ 1e-7, R ≥ 1, √R ≤ 709): none refused,
/// θ(1) within 1e-9 of the exact pendulum (checked with the rest by the test above), and the
/// worst tip and J errors stay at rounding level (1e-12 and 1e-9: the neglected terms are
/// O(ρ²) ≤ 1e-14 relative).
#[test]
fn the_separatrix_limit_answers_its_whole_domain() {
    let mut in_domain = 0;
    let (mut worst_tip, mut worst_j) = (0.0f64, 0.0f64);
    for t in truths() {
        let (a3, a4, a5) = (t.a[0], t.a[1], t.a[2]);
        let r = a4.hypot(a5);
        let rho = (a5.atan2(a4)).abs().max(a3.abs() / r.sqrt());
        if !(a4 > 0.0 && r >= 1.0 && r.sqrt() <= 709.0 && rho <= 1e-7) {
            continue;
        }
        in_domain += 1;
        let e = planar::evaluate(&t.a).unwrap_or_else(|err| panic!("{:?} refused: {err}", t.a));
        let scale = t.jacobian.amax();
        let j_err = ((e.jacobian - t.jacobian) / scale).norm() / (t.jacobian / scale).norm();
        worst_tip = worst_tip.max(tip_error(&e.tip, &t));
        worst_j = worst_j.max(j_err);
        let tip = planar::tip(&t.a).expect("tip");
        // The tip alone is the lattice in f64, evaluate's in dual numbers: rounding apart.
        let d = (tip.x - e.tip.x).abs().max((tip.y - e.tip.y).abs());
        let d = d.max((tip.theta - e.tip.theta).abs());
        assert!(d <= 1e-13, "{:?}: tip and evaluate differ by {d:.1e}", t.a);
    }
    eprintln!(
        "{in_domain} rods in the separatrix limit: worst tip {worst_tip:.1e}, J {worst_j:.1e}"
    );
    assert!(in_domain >= 60, "{in_domain} rods in the domain");
    assert!(
        worst_tip <= 1e-12 && worst_j <= 1e-9,
        "tip {worst_tip:.1e}, J {worst_j:.1e}"
    );
}

/// The separatrix limit down to the smallest normal amplitude: rods a = (c, F, 0) with c as
/// small as 3e-301 under √F up to 709 (A = c/(2√F) below 1e-300, refused until 2026-11-29 with a
/// misleading "too strongly bent" from the series) answer θ(1) within 1e-9 of the exact
/// pendulum θ'' = F sin θ. The reference is the first integral in elliptic form,
/// t(θ) = (K(m) ± F(|θ/2 − π/2| | m)) / √(F + c²/4) with m = 4F/(c² + 4F), inverted by bisection
/// in mpmath at 800 digits (independent of the soliton sums the code uses; the values are its
/// 20 digits rounded to 16); odd in c.
#[test]
fn the_separatrix_limit_reaches_the_smallest_normal_amplitude() {
    for (c, f, theta) in [
        (1e-300, 490000.0, 4.265_240_642_936_821),
        (1e-300, 476100.0, 3.336_671_300_074_508e-4),
        (3e-301, 490000.0, 1.990_858_045_350_102),
        (2e-300, 502681.0, 6.283_047_275_571_291),
        (1e-299, 460000.0, 2.632_932_348_442_751e-8),
        (-3e-301, 490000.0, -1.990_858_045_350_102),
    ] {
        let a = PlanarParams::new(c, f, 0.0);
        let tip = planar::tip(&a).unwrap_or_else(|e| panic!("{a:?} refused: {e}"));
        assert!(
            (tip.theta - theta).abs() < 1e-9,
            "{a:?}: θ(1) {} vs {theta}",
            tip.theta
        );
        let e = planar::evaluate(&a).unwrap_or_else(|e| panic!("{a:?} refused: {e}"));
        assert!((e.tip.theta - theta).abs() < 1e-9);
    }
}
