//! The closed form in double-double arithmetic ([`DualDd`]): the same generic code as the f64
//! closed form (docs/math.md §1–§3), for the rods whose f64 closed form loses too much to
//! cancellation near the separatrix (J off by ≈ ε/√m1, m1 down to 1e-30) and whose Taylor
//! series, in double-double too, takes milliseconds (√‖F‖ up to 27) or cannot be certified
//! at all (beyond).

use super::closed::{Case, Closed, CLOSED_J_TOLERANCE, ENERGY_REL_TOLERANCE};
use crate::dd::{Dd, DualDd, DD_EPSILON};
use crate::{PlanarJacobian, PlanarParams, PlanarPose};

/// Largest estimated absolute error of the double-double tip (before its rounding to f64)
/// that is accepted: a hundred times inside the 1e-11 the references check.
const EXTENDED_TIP_TOLERANCE: f64 = 1e-13;

/// Largest √‖F‖ of the high-precision references the double-double closed form was measured
/// on (tests/data/separatrix_truth*.jsonl; the `--edge` file reaches √‖F‖ = 692 at up to 1,200
/// bits, near where J ≈ e^{√‖F‖} overflows f64): beyond, it is not used.
const EXTENDED_MAX_ROOT_F: f64 = 700.0;

/// The f64 closed form's pose error model ([`Closed::pose_abs_error`]) scaled to 2⁻¹⁰⁴
/// underestimates the double-double pose's error by up to 3.7× (seen through the energy
/// identity, which subtracts a4·x ≈ ‖F‖ to leave energies down to 1e-18, on the 760 rods of
/// tests/data/separatrix_truth*.jsonl, beyond the references' own rounding): ×3.
const EXTENDED_POSE_FACTOR: f64 = 12.0;

/// The double-double closed form seeded with the identity on a; None where it overflows or
/// its case is not an elliptic one (I, II).
pub(crate) fn seeded(a: &PlanarParams) -> Option<Closed<DualDd>> {
    let c = Closed::new(
        DualDd::variable(a[0], 0),
        DualDd::variable(a[1], 1),
        DualDd::variable(a[2], 2),
    )?;
    matches!(c.case, Case::I | Case::II).then_some(c)
}

/// The double-double closed form within its measured reach (√‖F‖ ≤ [`EXTENDED_MAX_ROOT_F`]):
/// built once per rod, it serves the forward map ([`answer`]), the energy and the second pass
/// of the norm-wise stability scan (`stability::closed_scan`).
pub(crate) fn seeded_within_reach(a: &PlanarParams) -> Option<Closed<DualDd>> {
    if a[1].hypot(a[2]).sqrt() > EXTENDED_MAX_ROOT_F {
        return None;
    }
    seeded(a)
}

/// [`answer`] on the rod's double-double closed form, built here.
#[cfg(test)]
pub(crate) fn tip_jacobian_energy(a: &PlanarParams) -> Option<(PlanarPose, PlanarJacobian, f64)> {
    answer(&seeded_within_reach(a)?, a)
}

/// q(1), J(1) and the energy from the double-double closed form `c` of the rod a, where its
/// error estimates hold: J's relative error estimate ([`Closed::end_jacobian_rel_error_own`],
/// the f64 model at 2⁻¹⁰⁴) within [`CLOSED_J_TOLERANCE`], the tip's within
/// [`EXTENDED_TIP_TOLERANCE`], and the energy λ2/2 − a4 x − a5 y (docs/math.md §1, in
/// double-double) within 1e-9 of itself. None elsewhere.
pub(crate) fn answer(
    c: &Closed<DualDd>,
    a: &PlanarParams,
) -> Option<(PlanarPose, PlanarJacobian, f64)> {
    let pose_error = EXTENDED_POSE_FACTOR * c.pose_abs_error();
    if c.end_jacobian_rel_error_own() > CLOSED_J_TOLERANCE || pose_error > EXTENDED_TIP_TOLERANCE {
        return None;
    }
    let [x, y, th] = c.pose(1.0);
    let energy = identity_energy(a, x.v, y.v, pose_error)?;
    let ((xv, xg), (yv, yg), (tv, tg)) = (x.to_f64(), y.to_f64(), th.to_f64());
    let pose = PlanarPose::new(xv, yv, tv);
    let j = PlanarJacobian::new(
        xg[0], xg[1], xg[2], yg[0], yg[1], yg[2], tg[0], tg[1], tg[2],
    );
    (pose.is_finite() && j.iter().all(|v| v.is_finite())).then_some((pose, j, energy))
}

/// The energy alone from the double-double closed form ([`identity_energy`]), where the f64
/// identity cancels and its bound holds (√‖F‖ ≤ [`EXTENDED_MAX_ROOT_F`]); None elsewhere.
pub(crate) fn energy(a: &PlanarParams) -> Option<f64> {
    let c = seeded_within_reach(a)?;
    let pose_error = EXTENDED_POSE_FACTOR * c.pose_abs_error();
    if pose_error > EXTENDED_TIP_TOLERANCE {
        return None;
    }
    let [x, y, _] = c.pose(1.0);
    identity_energy(a, x.v, y.v, pose_error)
}

/// E = a3²/2 + a4 − a4 x − a5 y (docs/math.md §1) in double-double, where its bound — the pose
/// error times (|a4| + |a5|) plus the rounding of the sum — is within
/// [`ENERGY_REL_TOLERANCE`] of E.
fn identity_energy(a: &PlanarParams, x: Dd, y: Dd, pose_error: f64) -> Option<f64> {
    let (e, bound) = identity_energy_and_bound(a, x, y, pose_error);
    (e.is_finite() && bound <= ENERGY_REL_TOLERANCE * e.abs()).then_some(e)
}

/// The identity's value (rounded to f64) and its bound (see [`identity_energy`]).
fn identity_energy_and_bound(a: &PlanarParams, x: Dd, y: Dd, pose_error: f64) -> (f64, f64) {
    let (a3, a4, a5) = (Dd::from_f64(a[0]), Dd::from_f64(a[1]), Dd::from_f64(a[2]));
    let half_a3_sq = a3 * a3 * Dd::from_f64(0.5);
    let e = half_a3_sq + a4 - a4 * x - a5 * y;
    let terms = half_a3_sq.hi.abs() + 2.0 * a[1].abs() + a[2].abs();
    let bound = (a[1].abs() + a[2].abs()) * pose_error + 8.0 * DD_EPSILON * terms;
    (e.to_f64(), bound)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each reference rod: (a, tip, J, energy).
    fn references() -> Vec<(PlanarParams, PlanarPose, PlanarJacobian, f64)> {
        let files = [
            include_str!("../../tests/data/separatrix_truth.jsonl"),
            include_str!("../../tests/data/separatrix_truth_extreme.jsonl"),
            include_str!("../../tests/data/separatrix_truth_strong.jsonl"),
            include_str!("../../tests/data/separatrix_truth_edge.jsonl"),
        ];
        files
            .iter()
            .flat_map(|f| f.lines())
            .map(|line| {
                let v: serde_json::Value = serde_json::from_str(line).expect("reference line");
                let a: Vec<f64> = serde_json::from_value(v["a"].clone()).expect("a");
                let t: Vec<f64> = serde_json::from_value(v["tip"].clone()).expect("tip");
                let j: Vec<Vec<f64>> = serde_json::from_value(v["jac"].clone()).expect("jac");
                (
                    PlanarParams::new(a[0], a[1], a[2]),
                    PlanarPose::new(t[0], t[1], t[2]),
                    PlanarJacobian::from_fn(|r, c| j[r][c]),
                    v["energy"].as_f64().expect("energy"),
                )
            })
            .collect()
    }

    /// On the 824 rods of the high-precision references (m1 from 1e-30 to 1, √‖F‖ up to 692,
    /// tensions and compressions, bending down to 1e-14): wherever the double-double closed form
    /// answers, its tip is within 1e-15 + its bound, J within its estimate and the energy within
    /// its bound (beyond the references' own rounding to f64, 1.2e-16 relative); the bound of the
    /// energy identity holds on every rod, answered or not (it is what measured
    /// [`EXTENDED_POSE_FACTOR`]); and it answers every rod that the f64 path had to refuse
    /// (√‖F‖ > 27 near the separatrix).
    #[test]
    fn extended_closed_form_meets_its_estimates_on_the_references() {
        let refs = references();
        let (mut answered, mut worst_j, mut worst_energy) = (0usize, 0.0f64, 0.0f64);
        for (a, tip_ref, j_ref, e_ref) in &refs {
            let Some(c) = seeded(a) else { continue };
            let pose_error = EXTENDED_POSE_FACTOR * c.pose_abs_error();
            let [x, y, _] = c.pose(1.0);
            // The identity's bound, on every rod.
            let (e, bound) = identity_energy_and_bound(a, x.v, y.v, pose_error);
            let off = ((e - e_ref).abs() - 1.2e-16 * e_ref.abs()).max(0.0);
            assert!(
                off <= bound,
                "{a:?}: energy {e} vs {e_ref}, bound {bound:e}"
            );
            worst_energy = worst_energy.max(off / bound);
            let Some((tip, j, energy)) = tip_jacobian_energy(a) else {
                let root_f = a[1].hypot(a[2]).sqrt();
                let ill = crate::planar::closed::seeded_closed(a).is_some_and(|c| {
                    c.needs_series() == super::super::closed::SeriesNeed::IllConditioned
                });
                assert!(
                    !ill || root_f <= super::super::closed::SERIES_DD_MAX_ROOT_F,
                    "{a:?}: not answered at √‖F‖ = {root_f}"
                );
                continue;
            };
            answered += 1;
            let dtip = (tip.x - tip_ref.x)
                .abs()
                .max((tip.y - tip_ref.y).abs())
                .max((tip.theta - tip_ref.theta).abs());
            assert!(dtip <= 1e-15 + pose_error, "{a:?}: tip off by {dtip:e}");
            let dj = (j - j_ref).norm() / j_ref.norm();
            let est = c.end_jacobian_rel_error_own();
            assert!(dj <= est, "{a:?}: J off by {dj:e}, estimate {est:e}");
            worst_j = worst_j.max(dj);
            assert!(
                (energy - e_ref).abs() <= 1e-9 * e_ref.abs(),
                "{a:?}: {energy} vs {e_ref}"
            );
        }
        eprintln!(
            "{answered} of {} answered; worst J {worst_j:.2e}; energy error within {worst_energy:.2} of its bound",
            refs.len()
        );
        assert!(answered >= 600, "{answered}");
        // Measured 4.4e-17 (the references rounded to f64) and 0.38.
        assert!(
            worst_j < 1e-14 && worst_energy > 0.1,
            "{worst_j:e} {worst_energy}"
        );
    }

    /// Out of the references' sample: 600 rods the way users give them (a4 log-scale 1e-2..700
    /// of either sign, a3 and a5 log-scale 1e-12..10 with exact zeros): wherever the
    /// double-double energy answers, it is within 1e-9 of the tight double-double series'
    /// (measured ≤ 1.1e-11 on 459 answered rods).
    #[test]
    fn extended_energy_agrees_with_the_series() {
        use super::super::taylor::Gradient;
        let mut r = crate::rng::SplitMix64::new(41);
        let (mut answered, mut worst) = (0usize, 0.0f64);
        for i in 0..600 {
            let a3 = if i % 11 == 0 {
                0.0
            } else {
                r.signed_pow10(-12.0, 1.0)
            };
            let a5 = if i % 7 == 0 {
                0.0
            } else {
                r.signed_pow10(-12.0, 1.0)
            };
            let a = PlanarParams::new(a3, r.signed_pow10(-2.0, 2.85), a5);
            let Some(e) = energy(&a) else { continue };
            let reference =
                crate::planar::taylor::series_dd::<crate::planar::taylor::DdTight>(&a, false, 27.0)
                    .expect("series")
                    .energy()
                    .value();
            let rel = (e - reference).abs() / reference.abs();
            assert!(rel <= 1e-9, "{a:?}: {e} vs {reference}");
            answered += 1;
            worst = worst.max(rel);
        }
        eprintln!("{answered} answered, worst {worst:.2e}");
        assert!(answered >= 300, "{answered}");
    }
}
