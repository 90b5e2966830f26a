//! Fast stability test on the closed form (FINDINGS §5).

use super::closed::{Case, Closed, DetFrame, SeriesNeed};
use super::small_angle;
use super::taylor::{CoarseDual3, Gradient, TaylorRod};
use crate::dd::DualDd;
use crate::planar_det_leading_term as normalisation;
use crate::scalar::Dual3;
use crate::types::{det3, det_and_error, det_and_error_by_column};
use crate::{PlanarParams, RodError, StabilityReport, StabilityVerdict};

mod closed_scan;
mod scan;
mod series;
mod small_angle_scan;
#[cfg(test)]
mod tests;

pub(crate) use closed_scan::*;
use scan::*;
pub(crate) use series::*;
pub(crate) use small_angle_scan::*;

/// Below this t the closed-form det J is dominated by rounding; it is positive there by its
/// leading term (FINDINGS §5).
const T_MIN: f64 = crate::STABILITY_T_MIN;
/// Smallest t entering the margin `det_min` (FINDINGS §5).
const T_MARGIN: f64 = 0.05;
/// First t of the scan on the Taylor series. Its J entries are accurate relative to
/// themselves, so det J ≈ t⁹·(…) is resolved down to small t (the cofactor terms are O(t⁸) and
/// cancel to O(t⁹): a 1/t loss, 100× here).
const SERIES_T_MIN: f64 = 0.01;
/// Largest scan spacing on the series (gently bent rods: g is a smooth function of t, varying
/// on 2π/ρ ≥ 25 for the series' rods, ρ ≤ 0.25, and local minima are refined by parabolic
/// steps); the closed-form scan's largest spacing too.
const SERIES_SPACING: f64 = 0.1;
/// Cap of the series scan's spacing where its samples carry slopes ([`series_probe`]; the
/// double-double scan near the separatrix keeps values alone): twice the value-only spacing,
/// at most this. On the 2,467 nearly straight rods of `small_angle_report_matches_the_series_scan`
/// the value-only series scan missed 75 minima that the sloped small-angle scan found; with
/// slopes it misses none, at −0.7 % instructions per stability test on log-scale rods.
const SERIES_SLOPED_MAX_SPACING: f64 = 0.15;
/// Relative accuracy of the Taylor series' J entries (truncation below one unit roundoff plus
/// the rounding of ≲ 33 terms of products: measured ≤ 2e-15 against the reference, ×5).
const SERIES_ENTRY_REL: f64 = 1e-14;
/// Error of the entries of the scan's short series ([`CoarseDual3`], truncated at
/// [`COARSE_TAIL_TOL`] per step): [`COARSE_ENTRY_REL`] of each entry plus
/// [`COARSE_AMPLIFIED`]·e^{√‖F‖ t}·‖J‖ (truncation spread over the entries and grown like
/// rounding near the hyperbolic straight equilibrium). Against the full-accuracy series
/// (`coarse_short_series_within_its_bound`: 3,000 rods, a4 log-scale 1e-2..1e4 of either sign
/// and tensions 10..1e4 near the separatrix, a3 and a5 log-scale 1e-6..10, t over the short
/// series' reach) every entry's error is within 0.09 of this bound.
const COARSE_ENTRY_REL: f64 = 5e-9;
/// See [`COARSE_ENTRY_REL`].
const COARSE_AMPLIFIED: f64 = 2e-13;
/// Below this bending scale max(|a3|, |a5|), g(t) is evaluated on the ray (a3, a5)·λ with
/// λ = SIGMA_RAY/σ: g depends on (a3, a5) only through their ratio up to O(σ²) (the map is odd
/// in (a3, a5)), so the substitution is exact in f64, and it keeps det J ∝ σ² clear of
/// underflow.
const SIGMA_RAY: f64 = 1e-60;

/// Absolute error floor of the closed form's J entries: they are differences of O(1) internal
/// quantities, so an entry that is itself tiny (∂x/∂a4 = O(θ²t⁵) on a nearly straight rod)
/// carries an absolute error of a few ulps of 1 (observed 2.3e-16 at t = 0.05 on a rod with
/// a = (1.4e-5, 10.4, −8.2e-3); ×64 allowance).
const CLOSED_J_ABS: f64 = 64.0 * f64::EPSILON;

fn rows(p: &[Dual3; 3]) -> [[f64; 3]; 3] {
    [p[0].g, p[1].g, p[2].g]
}

/// g(t) alone from the dual-number closed form (scans that bound it elsewhere).
fn normalised_det_value(c: &Closed<Dual3>, a3: f64, a5: f64, t: f64) -> f64 {
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
const COLUMN_WISE_MAX_M: f64 = 0.01;

/// g(t) = det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) (FINDINGS §5) and its error bound, from the
/// dual-number closed form. Each entry of J(t) is off by at most rel·|entry| + 64ε (rel =
/// [`Closed::jacobian_rel_error_at`]), or on a near-circle (case II, m <
/// [`COLUMN_WISE_MAX_M`]) by rel·‖its column‖ + 64ε: a column is the derivative along one
/// parameter, and case II's O(1/m) terms cancel across it (`closed_g_within_its_bound`).
/// With `norm_wise`, every entry's error is bounded by rel·‖J(t)‖ (the Frobenius estimate
/// itself) instead: near the separatrix an entry far below ‖J‖ (the x row while the rod
/// lingers by the straight equilibrium) can be off by that much.
fn normalised_det(c: &Closed<Dual3>, a3: f64, a5: f64, t: f64, norm_wise: bool) -> (f64, f64) {
    let j = rows(&c.pose_for_jacobian(t));
    let (g, e, _) = normalised_det_from(c, &j, (a3, a5, t), norm_wise);
    (g, e)
}

/// [`normalised_det`] and the slope g′(t), from the same Jacobi values: d det J/dt =
/// det[J_x; J_y; ∂κ/∂a] ([`Closed::pose_and_curvature_for_jacobian`]) and
/// g′ = det′/N − g·N′/N (`planar_det_leading_term_log_slope`). The slope
/// only guides where the scan samples next (it is never a verdict), so it carries no bound.
fn normalised_det_sloped(
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
fn normalised_det_from(
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
fn normalised_det_extended(c: &Closed<DualDd>, a3: f64, a5: f64, t: f64) -> (f64, f64) {
    let p = c.pose_for_jacobian(t);
    let j = [0, 1, 2].map(|r| p[r].g.map(|v| v.to_f64()));
    let rel = c.jacobian_rel_error_own_at(t);
    let abs = rel * j.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
    let (det, err) = det_and_error(&j, f64::EPSILON, abs);
    let n = normalisation(a3, a5, t);
    (det / n, err / n)
}

/// g(t) and its error bound from the Taylor series, with the x row and the a4 column divided
/// by σ = max(|a3|, |a5|) (det scales by 1/σ², the normalisation is taken with a/σ): both are
/// O(σ²) for a nearly straight rod, and the scaled quantities are O(1).
fn normalised_det_series<T: Gradient>(rod: &TaylorRod<T>, a3: f64, a5: f64, t: f64) -> (f64, f64) {
    normalised_det_series_amplified(rod, a3, a5, t, 0.0)
}

/// [`normalised_det_series`] with, besides the entries' own [`SERIES_ENTRY_REL`], an error of
/// `amplified`·‖J‖ in every entry: rounding (or truncation) made near the hyperbolic straight
/// equilibrium grows like e^{√‖F‖ t} and spreads over all entries.
fn normalised_det_series_amplified<T: Gradient>(
    rod: &TaylorRod<T>,
    a3: f64,
    a5: f64,
    t: f64,
    amplified: f64,
) -> (f64, f64) {
    let Some(j) = scaled_series_jacobian(rod, a3, a5, t) else {
        return (f64::NAN, f64::INFINITY);
    };
    normalised_det_of(&j, a3, a5, t, SERIES_ENTRY_REL, amplified)
}

/// g(t) and its bound from a scaled series J (see [`normalised_det_series_amplified`]).
/// `entry_rel`: the entries' own relative error ([`SERIES_ENTRY_REL`] for a series truncated
/// at one unit roundoff).
fn normalised_det_of(
    j: &[[f64; 3]; 3],
    a3: f64,
    a5: f64,
    t: f64,
    entry_rel: f64,
    amplified: f64,
) -> (f64, f64) {
    let size = amplified * j.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
    let (det, err) = det_and_error(j, entry_rel, size);
    let n = normalisation_scaled(a3, a5, t);
    (det / n, err / n)
}

/// g(t) alone (the scan's samples; the error bound is needed at the margin's t only).
fn normalised_det_series_value<T: Gradient>(rod: &TaylorRod<T>, a3: f64, a5: f64, t: f64) -> f64 {
    let Some(j) = scaled_series_jacobian(rod, a3, a5, t) else {
        return f64::NAN;
    };
    det3(&j) / normalisation_scaled(a3, a5, t)
}

/// [`normalised_det_series_value`] and its slope g′(t) = det′/N − g·N′/N with d det J/dt =
/// det[J_x; J_y; ∂κ/∂a] from the series' own κ (scaled as the θ row: a4 column over σ).
fn series_probe<T: Gradient>(rod: &TaylorRod<T>, a3: f64, a5: f64, t: f64) -> Probe {
    let nan = Probe {
        v: f64::NAN,
        d: f64::NAN,
    };
    let (Some(pose), Some(kappa)) = (rod.pose(t), rod.curvature(t)) else {
        return nan;
    };
    let Some(j) = scaled_jacobian(pose, a3, a5) else {
        return nan;
    };
    let sigma = a3.abs().max(a5.abs());
    let mut k = kappa.gradient();
    k[1] /= sigma;
    let n = normalisation_scaled(a3, a5, t);
    let v = det3(&j) / n;
    let log_slope = crate::types::planar_det_leading_term_log_slope(a3 / sigma, a5 / sigma, t);
    Probe {
        v,
        d: det3(&[j[0], j[1], k]) / n - v * log_slope,
    }
}

/// J(t) from the series with the x row and the a4 column divided by σ = max(|a3|, |a5|).
fn scaled_series_jacobian<T: Gradient>(
    rod: &TaylorRod<T>,
    a3: f64,
    a5: f64,
    t: f64,
) -> Option<[[f64; 3]; 3]> {
    scaled_jacobian(rod.pose(t)?, a3, a5)
}

/// J from a pose in dual numbers, with the x row and the a4 column divided by σ = max(|a3|,
/// |a5|) (see [`normalised_det_series`]).
fn scaled_jacobian<T: Gradient>(pose: [T; 3], a3: f64, a5: f64) -> Option<[[f64; 3]; 3]> {
    let sigma = a3.abs().max(a5.abs());
    let mut j = pose.map(|v| v.gradient());
    for v in j[0].iter_mut() {
        *v /= sigma;
    }
    for r in j.iter_mut() {
        r[1] /= sigma;
    }
    Some(j)
}

/// The normalisation taken with a/σ (see [`normalised_det_series`]).
fn normalisation_scaled(a3: f64, a5: f64, t: f64) -> f64 {
    let sigma = a3.abs().max(a5.abs());
    normalisation(a3 / sigma, a5 / sigma, t)
}

/// The straight rod a3 = a5 = 0: J's x row vanishes (∂x/∂a ≡ 0: an inextensible straight rod
/// stays straight to first order), so det J ≡ 0 on (0, 1]. The test "det J > 0 on (0, 1]"
/// neither passes nor fails: the rod is a singular point of the a-chart, on the boundary of
/// the reachable set (|tip| = 1). Reported uncertain, margin 0.
fn straight_report() -> StabilityReport {
    StabilityReport {
        stable: false,
        margin: 0.0,
        first_conjugate_t: None,
        uncertain: true,
    }
}

/// The report with the verdict a theorem gives where one applies ([`Closed::theorem_verdict`]:
/// non-inflectional rods and circles have no conjugate point, nor an inflectional rod whose
/// curvature keeps its sign, and an inflectional rod has one by its third inflection point):
/// certain there, whatever the scan could decide. The margin stays the scan's value, floored
/// at 0 for a stable verdict and capped at 0 for an unstable one (where the scan's bound
/// covered zero, its sign was rounding); the conjugate point is the scan's where it found one.
/// Elsewhere, or where the scan already agrees with certainty, unchanged.
pub(crate) fn with_theorem(
    report: StabilityReport,
    theorem: impl FnOnce() -> Option<StabilityVerdict>,
) -> StabilityReport {
    if report.stable && !report.uncertain {
        // A certain scan that contradicts a theorem would be a bound that failed: the
        // theorem is checked against the reference (`conjugate_points_respect_the_theorem`).
        return match theorem() {
            Some(StabilityVerdict::Unstable) => unstable_by_theorem(report),
            _ => report,
        };
    }
    match theorem() {
        Some(StabilityVerdict::Stable) => StabilityReport {
            stable: true,
            margin: report.margin.max(0.0),
            first_conjugate_t: None,
            uncertain: false,
        },
        Some(StabilityVerdict::Unstable) => unstable_by_theorem(report),
        _ => report,
    }
}

/// [`with_theorem`]'s unstable verdict.
fn unstable_by_theorem(report: StabilityReport) -> StabilityReport {
    StabilityReport {
        stable: false,
        margin: report.margin.min(0.0),
        first_conjugate_t: report.first_conjugate_t,
        uncertain: false,
    }
}

/// How many times its own error bound g(1) must lie below zero for [`verdict_of`] to call a
/// rod unstable from that one sample (the scans call a sign beyond one bound certain; the
/// factor is a margin for the bound's own approximations).
const END_UNSTABLE_BOUNDS: f64 = 4.0;

/// True where [`stability_of_with`] scans the f64 closed form with its own bounds (its last
/// branch): no series, no double-double, no small-angle expansion.
fn plain_closed_scan(c: &Closed<Dual3>, a: &PlanarParams) -> bool {
    let theta = small_angle::max_angle(a[0], a[1], a[2]);
    matches!(c.case, Case::I | Case::II)
        && !c.needs_precise_series()
        && !c.det_needs_series()
        && c.needs_series() == SeriesNeed::None
        && SMALL_ANGLE_TRUNCATION_C * theta * theta > SMALL_ANGLE_MAX_TRUNCATION
}

/// True where g(1) < 0 beyond [`END_UNSTABLE_BOUNDS`] times its error bound (on a rod of the
/// plain scan, with the bound that scan uses): g → 1 as t → 0 (det J ~ t⁹(a3²/8640 +
/// a5²t²/33600) > 0 off the straight rod, FINDINGS §5), so det J vanishes somewhere on
/// (0, 1), a conjugate point.
fn unstable_at_the_end(c: &Closed<Dual3>, a: &PlanarParams) -> bool {
    let (g, bound) = normalised_det(c, a[0], a[2], 1.0, false);
    g < -END_UNSTABLE_BOUNDS * bound
}

/// The verdict alone on the closed form ([`crate::planar::stability_verdict`]), None where the
/// caller must run the full test. In order:
/// 1. a theorem ([`Closed::theorem_verdict`]: no conjugate point before the first inflection,
///    one by the third; [`with_theorem`] gives every report that verdict);
/// 2. on the rods of the plain closed-form scan only, g(1) ([`unstable_at_the_end`]);
/// 3. that scan from the theorem's t_free on ([`Closed::conjugate_free_until`]: no conjugate
///    point before it, so det J > 0 on (0, t_free) and the rod is stable iff det J > 0 on
///    [t_free, 1]), where the scan is certain.
///
/// On 20,000 rods of the paper's box the first two decide 64 % (20 % stable and 31 %
/// unstable by the theorems, 13 % unstable by g(1)); with the third, 7.1k instructions per
/// call, against 8.7k with the full test after the first two and 20.0k for the full test
/// (callgrind, 512 box rods).
pub(crate) fn verdict_of(
    c: &Closed<Dual3>,
    a: &PlanarParams,
) -> Result<Option<StabilityVerdict>, RodError> {
    if let Some(verdict) = c.theorem_verdict() {
        return Ok(Some(verdict));
    }
    if !plain_closed_scan(c, a) {
        return Ok(None);
    }
    if unstable_at_the_end(c, a) {
        return Ok(Some(StabilityVerdict::Unstable));
    }
    let report = closed_scan_from(c, a, false, None, c.conjugate_free_until())?;
    Ok((!report.uncertain).then(|| report.verdict()))
}

/// The verdict from a scan and the error bound of g where the margin was found.
fn verdict(scan: Scan, g_error: f64) -> StabilityReport {
    let clear = scan.margin.abs() > g_error;
    let (stable, uncertain) = match scan.first {
        None => (clear, !clear),
        Some(_) => (false, !clear),
    };
    StabilityReport {
        stable,
        margin: scan.margin,
        first_conjugate_t: if uncertain { None } else { scan.first },
        uncertain,
    }
}
