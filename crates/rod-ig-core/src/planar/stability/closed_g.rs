//! The closed form's det J(t) as the scans read it: g(t) normalised, its error bound and its
//! slope, in dual numbers and in double-double (docs/math.md §5). Shared by the closed-form
//! scans and the series scan's cross-checks, below both.

use crate::dd::DualDd;
use crate::planar::closed::{Case, Closed};
use crate::planar_det_leading_term as normalisation;
use crate::scalar::Dual3;
use crate::types::{det3, det_and_error, det_and_error_by_column};

/// Absolute error floor of the closed form's J entries: they are differences of O(1) internal
/// quantities, so an entry that is itself tiny (∂x/∂a4 = O(θ²t⁵) on a nearly straight rod)
/// carries an absolute error of a few ulps of 1 (observed 2.3e-16 at t = 0.05 on a rod with
/// a = (1.4e-5, 10.4, −8.2e-3); ×64 allowance).
pub(super) const CLOSED_J_ABS: f64 = 64.0 * f64::EPSILON;

#[inline]
pub(super) fn rows(p: &[Dual3; 3]) -> [[f64; 3]; 3] {
    [p[0].g, p[1].g, p[2].g]
}

/// g(t) alone from the dual-number closed form (scans that bound it elsewhere).
#[inline]
pub(super) fn normalised_det_value(c: &Closed<Dual3>, a3: f64, a5: f64, t: f64) -> f64 {
    det3(&rows(&c.pose_for_jacobian(t))) / normalisation(a3, a5, t)
}

/// Largest m of a case II rod (a near-circle below) whose closed-form g is bounded column-wise
/// ([`normalised_det`]). Entry-wise, on 813 near-circles (m 1e-6..1e-2) the samples the scan
/// accepted were off by up to 96 times their bound (1,076 of them); column-wise by at most 0.20
/// of it. Above, entry-wise bounds are exceeded too, on fewer samples (up to 7.6×, 82 of
/// 34,212 in `closed_g_within_its_bound`), but column-wise ones there hand the strong-force
/// family's nearly straight first part to the series: +22 % instructions per forward call,
/// where the closed form's values were within 1e-7 of the reference. Case II has no
/// conjugate point, so only margins are at stake.
pub(super) const COLUMN_WISE_MAX_M: f64 = 0.01;

/// g(t) = det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) (docs/math.md §5) and its error bound, from the
/// dual-number closed form. Each entry of J(t) is off by at most rel·|entry| + 64ε (rel =
/// [`Closed::jacobian_rel_error_at`]), or on a near-circle (case II, m <
/// [`COLUMN_WISE_MAX_M`]) by rel·‖its column‖ + 64ε: a column is the derivative along one
/// parameter, and case II's O(1/m) terms cancel across it (`closed_g_within_its_bound`).
/// With `norm_wise`, every entry's error is bounded by rel·‖J(t)‖ (the Frobenius estimate
/// itself) instead: near the separatrix an entry far below ‖J‖ (the x row while the rod
/// lingers by the straight equilibrium) can be off by that much.
#[inline]
pub(super) fn normalised_det(
    c: &Closed<Dual3>,
    a3: f64,
    a5: f64,
    t: f64,
    norm_wise: bool,
) -> (f64, f64) {
    let j = rows(&c.pose_for_jacobian(t));
    let (g, e, _) = normalised_det_from(c, &j, (a3, a5, t), norm_wise);
    (g, e)
}

/// [`normalised_det`] and the slope g′(t), from the same Jacobi values: d det J/dt =
/// det[J_x; J_y; ∂κ/∂a] ([`Closed::pose_and_curvature_for_jacobian`]) and
/// g′ = det′/N − g·N′/N (`planar_det_leading_term_log_slope`). The slope
/// only guides where the scan samples next (it is never a verdict), so it carries no bound.
#[inline]
pub(super) fn normalised_det_sloped(
    c: &Closed<Dual3>,
    a3: f64,
    a5: f64,
    t: f64,
    norm_wise: bool,
) -> (f64, f64, f64) {
    let (pose, kappa) = c.pose_and_curvature_for_jacobian(t);
    let j = rows(&pose);
    let (g, e, n) = normalised_det_from(c, &j, (a3, a5, t), norm_wise);
    let det_slope = det3(&[j[0], j[1], kappa.g]);
    let log_slope = crate::types::planar_det_leading_term_log_slope(a3, a5, t);
    (g, e, det_slope / n - g * log_slope)
}

/// g, its bound and the normalisation N from J(t) of the closed form ([`normalised_det`]).
#[inline]
pub(super) fn normalised_det_from(
    c: &Closed<Dual3>,
    j: &[[f64; 3]; 3],
    (a3, a5, t): (f64, f64, f64),
    norm_wise: bool,
) -> (f64, f64, f64) {
    let rel = c.jacobian_rel_error_at(t);
    let (det, err) = if norm_wise {
        let abs = CLOSED_J_ABS.max(rel * j.iter().flatten().map(|v| v * v).sum::<f64>().sqrt());
        det_and_error(j, rel, abs)
    } else if c.case == Case::II && c.m.v < COLUMN_WISE_MAX_M {
        let column = |k: usize| (j[0][k] * j[0][k] + j[1][k] * j[1][k] + j[2][k] * j[2][k]).sqrt();
        det_and_error_by_column(j, [0, 1, 2].map(|k| rel * column(k) + CLOSED_J_ABS))
    } else {
        det_and_error(j, rel, CLOSED_J_ABS)
    };
    let n = normalisation(a3, a5, t);
    (det / n, err / n, n)
}

/// g(t) and its bound from the closed form in double-double: every entry of J(t) off by its
/// norm-wise estimate ([`Closed::jacobian_rel_error_own_at`], the f64 model at 2⁻¹⁰⁴) times
/// ‖J‖, plus its rounding to f64 (ε of itself).
#[inline]
pub(super) fn normalised_det_extended(c: &Closed<DualDd>, a3: f64, a5: f64, t: f64) -> (f64, f64) {
    let p = c.pose_for_jacobian(t);
    let j = [0, 1, 2].map(|r| p[r].g.map(|v| v.to_f64()));
    let rel = c.jacobian_rel_error_own_at(t);
    let abs = rel * j.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
    let (det, err) = det_and_error(&j, f64::EPSILON, abs);
    let n = normalisation(a3, a5, t);
    (det / n, err / n)
}
