//! Fast stability test on the closed form (FINDINGS §5).

use super::closed::{Case, Closed, DetFrame, SeriesNeed};
use super::small_angle;
use super::taylor::{CoarseDual3, Gradient, TaylorRod};
use crate::dd::DualDd;
use crate::planar_det_leading_term as normalisation;
use crate::scalar::Dual3;
use crate::types::{det3, det_and_error, det_and_error_by_column};
use crate::{PlanarParams, RodError, StabilityReport, StabilityVerdict};

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

/// Grid spacing of the small-angle scan ([`small_angle_report`]) in periods 2π/max(σ, √|a4|),
/// and its cap. Its samples carry g₀′ ([`small_angle::normalised_det_sloped`]): on 16,280
/// nearly straight rods against g₀ on 8,000 points each, the margin is above the dense
/// minimum by more than 1e-6 (relative to max(|min|, 1e-3)) on 9 rods, by 3e-5 at worst,
/// where the value-only scan on a quarter period capped at 0.1 was above on 1,476, by 12 %
/// at worst (a dip between samples); at 0.75 period, 18 %; with a cap of 0.3, 20 % (two
/// extrema 0.12 apart in one interval under a compression of 26).
const SMALL_ANGLE_SPACING: f64 = 0.5;
/// See [`SMALL_ANGLE_SPACING`].
const SMALL_ANGLE_MAX_SPACING: f64 = 0.15;

/// Largest truncation bound Θ² of the small-angle g₀ (relative to max(|g|, 1)) for which
/// [`small_angle_report`] answers: margins to 1e-4 relative (Θ ≤ 1e-2, where its constant was
/// measured), where the closed-form scan accepts g to 1e-3.
const SMALL_ANGLE_MAX_TRUNCATION: f64 = 1e-4;
/// Constant of the small-angle truncation bound C·Θ²·max(|g|, 1), Θ the largest bending
/// angle ([`small_angle::max_angle`]): measured ≤ 0.16 against the series' g on 6,000 rods
/// (a4 from 1e-6 to 1e4 and 0, either sign; a3, a5 log-scale 1e-20..0.1 and 0;
/// `small_angle_agrees_with_the_series`), ×6.
const SMALL_ANGLE_TRUNCATION_C: f64 = 1.0;
/// Rounding of g₀ relative to max(|g₀|, 1) beyond its first-order bound (the normalisation,
/// the division): measured ≤ 2.1e-12 in all (with the series' own, where Θ < 1e-8), ×50.
const SMALL_ANGLE_ROUNDING: f64 = 1e-10;
/// Largest first-order rounding bound of g₀ at t = 1, relative to max(|g₀|, 1), for which
/// [`small_angle_report`] answers: under a strong tension det J of the linearised rod is a
/// difference of terms e^{2√a4} times larger than itself (rounding grows with t, so t = 1 is
/// the worst point).
const SMALL_ANGLE_MAX_ROUNDING: f64 = 1e-9;

/// Largest √|a4|·t at which [`small_angle_prefix`] stands in for the closed form (the reach of
/// its measurement, `small_angle_prefix_agrees_with_the_series`).
const SMALL_ANGLE_PREFIX_REACH: f64 = 12.0;

/// g(t) of a rod whose part [0, t] is nearly straight, from the small-angle limit g₀ (as
/// [`small_angle_report`], with the largest angle Θ(t) of that part: a rod of length t), and
/// its bound (C·Θ(t)² + rounding)·max(|g₀|, 1) plus g₀'s own rounding, and g₀′ (a slope for
/// the scan, [`small_angle::normalised_det_sloped`]). It replaces the short
/// series near the base of a rod bent little there under a strong force, where the closed
/// form's x row is swamped (~65k instructions of series per stability test under
/// |a4| 1e2..1e4). None beyond [`SMALL_ANGLE_PREFIX_REACH`] or for zero/denormal bending.
fn small_angle_prefix(a: &PlanarParams, t: f64) -> Option<(f64, f64, f64)> {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let sigma = a3.abs().max(a5.abs());
    if sigma.is_nan() || sigma < f64::MIN_POSITIVE || a4.abs().sqrt() * t > SMALL_ANGLE_PREFIX_REACH
    {
        return None;
    }
    let theta = small_angle::max_angle_to(a3, a4, a5, t);
    let (g0, rounding, slope) = small_angle::normalised_det_sloped(a3, a4, a5, t);
    let bound = (SMALL_ANGLE_TRUNCATION_C * theta * theta + SMALL_ANGLE_ROUNDING)
        * g0.abs().max(1.0)
        + rounding;
    (g0.is_finite() && bound.is_finite()).then_some((g0, bound, slope))
}

/// Stability of a nearly straight rod from the small-angle limit g₀ of g (FINDINGS §5 on the
/// linearised straight rod, [`small_angle`]), where its truncation C·Θ² is below
/// [`SMALL_ANGLE_MAX_TRUNCATION`] and its rounding below [`SMALL_ANGLE_MAX_ROUNDING`]: no
/// elliptic function, no series (the closed form's x row is swamped by rounding there, the
/// series costs tens of µs). An unstable verdict needs a sample past the sign change with
/// g₀ < 0 beyond its bound. None where Θ or the rounding is larger, σ is zero or denormal, or
/// the verdict is not certain: the caller's scans decide.
pub(crate) fn small_angle_report(a: &PlanarParams) -> Result<Option<StabilityReport>, RodError> {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let sigma = a3.abs().max(a5.abs());
    // NaN fails both tests.
    if sigma.is_nan() || sigma < f64::MIN_POSITIVE {
        return Ok(None);
    }
    let theta = small_angle::max_angle(a3, a4, a5);
    let truncation = SMALL_ANGLE_TRUNCATION_C * theta * theta;
    if truncation.is_nan() || truncation > SMALL_ANGLE_MAX_TRUNCATION {
        return Ok(None);
    }
    let (g1, rounding1) = small_angle::normalised_det(a3, a4, a5, 1.0);
    if rounding1.is_nan() || rounding1 > SMALL_ANGLE_MAX_ROUNDING * g1.abs().max(1.0) {
        return Ok(None);
    }
    // g varies on the rod's own scale; its slopes find the minima between samples.
    let wavelength = std::f64::consts::TAU / sigma.max(a4.abs().sqrt());
    let spacing = (SMALL_ANGLE_SPACING * wavelength).clamp(1e-3, SMALL_ANGLE_MAX_SPACING);
    let sloped = |t: f64| {
        let (v, _, d) = small_angle::normalised_det_sloped(a3, a4, a5, t);
        Probe { v, d }
    };
    let s = scan(&sloped, SERIES_T_MIN, spacing, (a3, a5), &[])?;
    let bounded = |t: f64| {
        let (v, rounding) = small_angle::normalised_det(a3, a4, a5, t);
        let bound = (truncation + SMALL_ANGLE_ROUNDING) * v.abs().max(1.0) + rounding;
        (v, bound)
    };
    let report = certified_verdict(s, &bounded, (SERIES_T_MIN, spacing, a3, a5));
    Ok((!report.uncertain).then_some(report))
}

/// Stability on the Taylor series of near-relaxed rods (`rod`, when given, is their dense
/// dual-number series), or, with `precise` (the rod's closed form), on the double-double
/// series of the rods where the closed form's error estimate fails. `wavelength` bounds the
/// scan spacing.
pub(crate) fn stability_of_series(
    a: &PlanarParams,
    rod: Option<&TaylorRod<Dual3>>,
    wavelength: Option<f64>,
    precise: Option<&Closed<Dual3>>,
) -> Result<StabilityReport, RodError> {
    let sigma = a[0].abs().max(a[2].abs());
    if sigma == 0.0 {
        return Ok(straight_report());
    }
    if let Some(report) = small_angle_report(a)? {
        return Ok(report);
    }
    whole_series_scan(a, rod, wavelength, precise)
}

/// [`stability_of_series`] on the rod's dense dual-number series, for a caller that has
/// already asked [`small_angle_report`].
pub(crate) fn stability_of_dense_series(
    a: &PlanarParams,
    rod: &TaylorRod<Dual3>,
) -> Result<StabilityReport, RodError> {
    series_after_small_angle(a, Some(rod), None, None)
}

/// [`stability_of_series`] for a caller that has already asked [`small_angle_report`] (it
/// would ask again).
fn series_after_small_angle(
    a: &PlanarParams,
    rod: Option<&TaylorRod<Dual3>>,
    wavelength: Option<f64>,
    precise: Option<&Closed<Dual3>>,
) -> Result<StabilityReport, RodError> {
    if a[0] == 0.0 && a[2] == 0.0 {
        return Ok(straight_report());
    }
    whole_series_scan(a, rod, wavelength, precise)
}

/// [`stability_of_series`] without the small-angle shortcut: the scan on the whole rod's series.
fn whole_series_scan(
    a: &PlanarParams,
    rod: Option<&TaylorRod<Dual3>>,
    wavelength: Option<f64>,
    precise: Option<&Closed<Dual3>>,
) -> Result<StabilityReport, RodError> {
    let (mut a3, a4, mut a5) = (a[0], a[1], a[2]);
    let sigma = a3.abs().max(a5.abs());
    let on_ray = sigma < SIGMA_RAY;
    if on_ray {
        let l = SIGMA_RAY / sigma;
        a3 *= l;
        a5 *= l;
    }
    let b = PlanarParams::new(a3, a4, a5);
    // Without the closed form's wavelength, the rod's own scale: κ varies on 1/ρ, so g on
    // about 2π/ρ (the same quarter-wavelength rule as the closed-form scan).
    let wavelength =
        wavelength.unwrap_or_else(|| std::f64::consts::TAU / super::curvature_scale(a));
    let spacing = (0.25 * wavelength).clamp(1e-3, SERIES_SPACING);
    if let Some(closed) = precise {
        let rod = super::series_dd::<false>(&b, true, super::STABILITY_DD_MAX_ROOT_F)?;
        let cross = CrossCheck {
            root_f: a[1].hypot(a[2]).sqrt(),
            closed: (!on_ray).then_some(closed),
            forward_maps_agree: !on_ray && forward_maps_agree(closed, &rod),
        };
        return scan_series(&rod, (a3, a5), spacing, Some(cross));
    }
    match rod {
        Some(r) if !on_ray => scan_series(r, (a3, a5), spacing, None),
        _ => scan_series(&super::series_dual(&b, true)?, (a3, a5), spacing, None),
    }
}

/// Relative error per step of the double-double series (its truncation, see
/// `taylor::DoubleF64`): near the separatrix it grows like e^{√‖F‖ t} along the rod.
const SERIES_DD_STEP_REL: f64 = 1e-22;

/// How the double-double series' g is bounded near the separatrix (see [`scan_series`]).
struct CrossCheck<'a> {
    /// √‖F‖: the growth rate of rounding near the straight equilibrium.
    root_f: f64,
    /// The closed form of the same rod (not on the σ ray).
    closed: Option<&'a Closed<Dual3>>,
    /// Whether the closed form's tip and J(1) agree with the series' within the forward map's
    /// cross-check (`cross_checked_tip`): where they do not, neither is certified at the end of
    /// the rod, and the signs of their huge g values there are noise.
    forward_maps_agree: bool,
}

/// Whether the closed form's q(1) and J(1) agree with the series' within the forward map's
/// cross-check tolerances (`CROSS_CHECK_TIP`, `CROSS_CHECK_J`).
fn forward_maps_agree<T: Gradient>(closed: &Closed<Dual3>, rod: &TaylorRod<T>) -> bool {
    let (Ok((tip_c, j_c)), Ok((tip_s, j_s))) = (
        super::pose_jac_from(closed.pose(1.0)),
        super::pose_jac_from(rod.tip()),
    ) else {
        return false;
    };
    let dtip = (tip_c.x - tip_s.x)
        .abs()
        .max((tip_c.y - tip_s.y).abs())
        .max((tip_c.theta - tip_s.theta).abs());
    dtip <= super::CROSS_CHECK_TIP && (j_c - j_s).norm() <= super::CROSS_CHECK_J * j_s.norm()
}

/// Largest relative disagreement between the double-double series' g and the closed form's
/// for which their agreement bounds both (their errors have unrelated causes: amplified
/// truncation and cancellation in the elliptic derivatives, as for `cross_checked_tip`).
const CROSS_CHECK_G: f64 = 0.1;

/// The scan of g on a series. `cross`: near the separatrix the double-double series' entries
/// are bounded norm-wise by [`SERIES_DD_STEP_REL`]·e^{√‖F‖ t} (rounding made near the straight
/// equilibrium grows at that rate) — or, where that bound is too large to decide, by their
/// disagreement with the closed form when both agree in sign within [`CROSS_CHECK_G`]; and an
/// unstable verdict needs a sample past the first sign change where g < 0 beyond its bound
/// (measured against the 320-bit reference: sign changes seen where the bound covers g were
/// no conjugate points, and such "unstable" verdicts were wrong). Without `cross` (the f64
/// series) the samples carry slopes ([`series_probe`]) on twice `spacing`.
fn scan_series<T: Gradient>(
    rod: &TaylorRod<T>,
    (a3, a5): (f64, f64),
    spacing: f64,
    cross: Option<CrossCheck>,
) -> Result<StabilityReport, RodError> {
    let Some(cross) = cross else {
        // The f64 series with slopes: twice the value-only spacing.
        let sloped_spacing = (2.0 * spacing).min(SERIES_SLOPED_MAX_SPACING);
        let probe = |t| series_probe(rod, a3, a5, t);
        let s = scan(&probe, SERIES_T_MIN, sloped_spacing, (a3, a5), &[])?;
        return Ok(verdict(s, normalised_det_series(rod, a3, a5, s.t_margin).1));
    };
    let s = scan(
        &value_only(|t| normalised_det_series_value(rod, a3, a5, t)),
        SERIES_T_MIN,
        spacing,
        (a3, a5),
        &[],
    )?;
    let g = |t: f64| {
        let amplified = SERIES_DD_STEP_REL * (cross.root_f * t).exp();
        let (v, e) = normalised_det_series_amplified(rod, a3, a5, t, amplified);
        if v.abs() > e {
            return (v, e);
        }
        let Some(c) = cross.closed else {
            return (v, e);
        };
        let (vc, ec) = normalised_det(c, a3, a5, t, true);
        let gap = (v - vc).abs();
        if v.signum() == vc.signum() && gap <= CROSS_CHECK_G * v.abs() {
            (v, gap + normalised_det_series(rod, a3, a5, t).1)
        } else if vc.abs() > ec {
            // The closed form's own (norm-wise) bound decides this sample.
            (vc, ec)
        } else {
            (v, e)
        }
    };
    if !cross.forward_maps_agree
        && s.first.is_none()
        && !every_sample_positive(&g, (SERIES_T_MIN, spacing, a3, a5))
    {
        // Where the forward maps disagree, stable needs g > 0 beyond its bound everywhere, not
        // only at the margin: the huge g values late on the rod are noise of either sign
        // there (five unstable reference rods at √‖F‖ 76–90, m1 ≤ 3.5e-26, whose forward map
        // is refused, came back stable from `stability` on their positive noise). Where they
        // agree, the measured rule stands: every such verdict on the 320-bit references is
        // right.
        return Ok(StabilityReport {
            stable: false,
            first_conjugate_t: None,
            uncertain: true,
            ..verdict(s, g(s.t_margin).1)
        });
    }
    Ok(certified_verdict(s, &g, (SERIES_T_MIN, spacing, a3, a5)))
}

/// Whether g > its bound at every sample of the scan's grid.
fn every_sample_positive(
    g: &impl Fn(f64) -> (f64, f64),
    (t0, spacing, a3, a5): (f64, f64, f64, f64),
) -> bool {
    let (ts, np) = sample_times(t0, spacing, (a3, a5), &[]);
    ts[..np].iter().all(|&t| {
        let (v, e) = g(t);
        v > e
    })
}

/// The verdict of a scan whose samples' values may be far off where their bound is large: an
/// unstable verdict needs a sample past the first sign change where g < 0 beyond its bound,
/// a stable one a margin beyond its bound (else uncertain). `grid`: the scan's (t0, spacing,
/// a3, a5).
fn certified_verdict(
    s: Scan,
    g: &impl Fn(f64) -> (f64, f64),
    (t0, spacing, a3, a5): (f64, f64, f64, f64),
) -> StabilityReport {
    let Some(first) = s.first else {
        return verdict(s, g(s.t_margin).1);
    };
    // Just past the sign change g is small but its bound, where it comes from cancellation
    // near the straight equilibrium, is smaller still: try a few points there first.
    let (ts, np) = sample_times(t0, spacing, (a3, a5), &[]);
    let near = [0.05, 0.1, 0.2, 0.4].map(|f| first + f * spacing);
    let certified = near
        .iter()
        .chain(ts[..np].iter().filter(|&&t| t >= first))
        .filter(|&&t| t <= 1.0)
        .any(|&t| {
            let (v, e) = g(t);
            v < -e
        });
    StabilityReport {
        stable: false,
        margin: s.margin,
        first_conjugate_t: certified.then_some(first),
        uncertain: !certified,
    }
}

/// Stability on the closed form (FINDINGS §5), with the series where the closed form's own
/// error estimate fails.
pub(crate) fn stability_of(
    c: &Closed<Dual3>,
    a: &PlanarParams,
) -> Result<StabilityReport, RodError> {
    stability_of_with(c, a, None)
}

/// [`stability_of`] with the rod's closed form in double-double when the caller has built it
/// already (`planar::extended::seeded_within_reach`; built here when needed otherwise).
pub(crate) fn stability_of_with(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    extended: Option<&Closed<DualDd>>,
) -> Result<StabilityReport, RodError> {
    if c.case == Case::Straight {
        return Ok(straight_report());
    }
    if let Some(report) = small_angle_report(a)? {
        return Ok(report);
    }
    // Near the separatrix under a strong force the closed form's J(t) entries far below ‖J‖
    // (the x row while the rod lingers by the straight equilibrium) are not accurate relative
    // to themselves: with entry-wise error bounds two verdicts in 720 were wrong on the
    // rigorous reference (scripts/gen_separatrix_truth.py). The scan there bounds every entry
    // norm-wise and hands what it cannot decide to a second pass in double-double, then to the
    // double-double series.
    if c.needs_precise_series() {
        let report = closed_scan(c, a, true, None)?;
        if !report.uncertain {
            return Ok(report);
        }
        // Again with the closed form in double-double where the f64 one is far off (a rod
        // lingering by the straight equilibrium before its loop, where the f64 values are noise
        // of either sign): 150–480 µs where the double-double series takes 3–9 ms.
        let mut undecided = None;
        let built;
        let dd = match extended {
            Some(dd) => Some(dd),
            None => {
                built = super::extended::seeded_within_reach(a);
                built.as_ref()
            }
        };
        if let Some(dd) = dd {
            let report = closed_scan(c, a, true, Some(dd))?;
            if !report.uncertain {
                return Ok(report);
            }
            undecided = Some(report);
        }
        // Beyond the double-double series' reach the verdict stays uncertain (with the second
        // pass's margin), rather than refusing a rod whose forward map is certified.
        if let Some(report) = undecided {
            if a[1].hypot(a[2]).sqrt() > super::STABILITY_DD_MAX_ROOT_F {
                return Ok(report);
            }
        }
        return series_after_small_angle(a, None, Some(c.wavelength()), Some(c));
    }
    if c.det_needs_series() {
        if let Some(report) = small_m_scan(c, a)? {
            return Ok(report);
        }
        return series_after_small_angle(a, None, Some(c.wavelength()), None);
    }
    match c.needs_series() {
        SeriesNeed::IllConditioned => {
            return series_after_small_angle(a, None, Some(c.wavelength()), Some(c))
        }
        SeriesNeed::Cancellation => {
            return series_after_small_angle(a, None, Some(c.wavelength()), None)
        }
        SeriesNeed::None => {}
    }
    let report = closed_scan(c, a, false, None)?;
    if report.uncertain {
        // The closed form cannot decide: its error bound covers the margin. The series'
        // entries are accurate relative to themselves; ask it.
        return series_after_small_angle(a, None, Some(c.wavelength()), None);
    }
    Ok(report)
}

/// Farthest t to which [`small_m_scan`] builds its certifying series: beyond, the whole-rod
/// series scan costs hardly more.
const SMALL_M_CERTIFY_MAX_T: f64 = 0.5;
/// Largest relative disagreement between the closed form's g and the series' at the points
/// [`small_m_scan`] certifies (measured: ≲ 1e-5 on nearly straight rods under compression).
const SMALL_M_AGREEMENT: f64 = 1e-3;

/// Stability at small m (a nearly straight rod under compression, often many wavelengths)
/// without the whole-rod series: the closed form's g(t) locates the sign changes and the
/// margin (its values agree with the series' to ~1e-6 there, although its error bound, set by
/// the O(√m) x row of J, cannot certify them), and the f64 series from the base to the first
/// negative sample and to t_margin certifies those two values (bounded as in the series scan,
/// and within [`SMALL_M_AGREEMENT`] of the closed form's). None where the certification does
/// not hold or would reach beyond [`SMALL_M_CERTIFY_MAX_T`]: the caller scans the series.
fn small_m_scan(c: &Closed<Dual3>, a: &PlanarParams) -> Result<Option<StabilityReport>, RodError> {
    let (a3, a5) = (a[0], a[2]);
    if a3.abs().max(a5.abs()) < SIGMA_RAY {
        return Ok(None);
    }
    let wl = c.wavelength();
    let t0 = (0.1 * wl).clamp(T_MIN, T_MARGIN);
    let spacing = (0.25 * wl).clamp(1e-3, SERIES_SPACING);
    let closed = |t: f64| normalised_det_value(c, a3, a5, t);
    let s = scan(&value_only(closed), t0, spacing, (a3, a5), &[])?;
    // The first sample past the sign change where g < 0: the unstable verdict's witness.
    let witness = match s.first {
        None => None,
        Some(first) => {
            let (ts, np) = sample_times(t0, spacing, (a3, a5), &[]);
            let t = ts[..np]
                .iter()
                .copied()
                .find(|&t| t >= first && closed(t) < 0.0);
            let Some(t) = t else {
                return Ok(None);
            };
            Some(t)
        }
    };
    let t_end = witness.unwrap_or(0.0).max(s.t_margin);
    if t_end > SMALL_M_CERTIFY_MAX_T {
        return Ok(None);
    }
    let Ok(rod) = TaylorRod::new_to(
        Dual3::variable(a3, 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a5, 2),
        t_end,
        super::SERIES_MAX_STEPS,
        true,
    ) else {
        return Ok(None);
    };
    // Certified: decided by the series' bound and within SMALL_M_AGREEMENT of the closed form.
    let certified = |t: f64| {
        let (v, e) = normalised_det_series(&rod, a3, a5, t);
        let agree = (v - closed(t)).abs() <= SMALL_M_AGREEMENT * v.abs() + e;
        (v.is_finite() && v.abs() > e && agree).then_some(v)
    };
    let Some(margin) = certified(s.t_margin) else {
        return Ok(None);
    };
    if let Some(t) = witness {
        if !certified(t).is_some_and(|v| v < 0.0) {
            return Ok(None);
        }
    }
    let margin = if s.first.is_some() && s.margin >= 0.0 {
        // The sign change lies below T_MARGIN: the scan reports the negative value seen there.
        s.margin
    } else {
        margin
    };
    Ok(Some(StabilityReport {
        stable: s.first.is_none() && margin > 0.0,
        margin,
        first_conjugate_t: s.first,
        uncertain: false,
    }))
}

/// g's value for [`scan`], but NaN (no sign: the scan drops it) where g ≤ 0 lies within its
/// error bound before `t_free`, where no conjugate point can come yet
/// (`Closed::conjugate_span_bound`): that sign is rounding. Under a strong tension the
/// norm-wise scan's noise there put "conjugate points" at t ≈ 0.1 on rods whose first one is
/// at 0.8 (320-bit references).
fn signs_where_possible(
    g: &impl Fn(f64) -> (f64, f64, f64),
    t_free: f64,
) -> impl Fn(f64) -> Probe + '_ {
    move |t| {
        let (v, e, d) = g(t);
        if t < t_free && v <= 0.0 && -v <= e {
            Probe { v: f64::NAN, d }
        } else {
            Probe { v, d }
        }
    }
}

/// Where the closed-form scan takes g(t) from: the closed form where its bound is within
/// [`CLOSED_G_ERROR`], else (double-double pass) the small-angle prefix or the double-double
/// closed form, else the small-angle prefix or the short series from the base.
struct ClosedSamples<'a> {
    c: &'a Closed<Dual3>,
    a: &'a PlanarParams,
    norm_wise: bool,
    dd: Option<&'a Closed<DualDd>>,
    start: ShortSeries,
    root_f: f64,
    /// The Jacobi fields' det J ([`Closed::det_frame`]), tried first at every sample it covers.
    frame: Option<DetFrame>,
}

impl ClosedSamples<'_> {
    /// g(t), its bound and its slope (NaN where the value does not come from the f64 closed
    /// form within its acceptance).
    fn eval(&self, t: f64) -> (f64, f64, f64) {
        let (a, a3, a5, root_f) = (self.a, self.a[0], self.a[2], self.root_f);
        // Relative to |g| where g is large: under a strong tension g reaches 1e4 between the
        // base and the margin, its bound 1e-3 of that, and the short series would otherwise be
        // extended there (~100 µs) for samples far above the margin that cannot change it.
        let accepted = |v: f64, e: f64| e <= CLOSED_G_ERROR * v.abs().max(1.0);
        if let Some(frame) = self.frame.as_ref().filter(|f| f.covers(t)) {
            let s = self.c.det_sample(frame, t);
            let n = normalisation(a3, a5, t);
            let (v, e) = (s.det / n, s.error / n);
            if accepted(v, e) {
                let log_slope = crate::types::planar_det_leading_term_log_slope(a3, a5, t);
                return (v, e, s.slope / n - v * log_slope);
            }
        }
        let (v, e, slope) = normalised_det_sloped(self.c, a3, a5, t, self.norm_wise);
        if accepted(v, e) {
            return (v, e, slope);
        }
        if let Some(dd) = self.dd {
            // The double-double pass: the small-angle prefix where its bound holds, else the
            // double-double closed form (its value, with its own norm-wise bound).
            if let Some((v0, e0, d0)) = small_angle_prefix(a, t) {
                if e0 <= CLOSED_G_ERROR * v0.abs().max(1.0) {
                    return (v0, e0, d0);
                }
            }
            if root_f * t > SHORT_SERIES_REACH {
                let (v, e) = normalised_det_extended(dd, a3, a5, t);
                return (v, e, f64::NAN);
            }
        }
        // Past here g is off by more than its acceptance; its slope is not used.
        if self.norm_wise && root_f * t > SHORT_SERIES_REACH {
            return (v, e, f64::NAN);
        }
        if let Some((v0, e0, d0)) = small_angle_prefix(a, t) {
            if e0 <= CLOSED_G_ERROR * v0.abs().max(1.0) {
                return (v0, e0, d0);
            }
        }
        self.start.normalised_det(t).unwrap_or((v, e, f64::NAN))
    }
}

/// The scan of g on the closed form (a short series near the base); the report, uncertain
/// where the error bound covers the margin (`norm_wise`: see [`normalised_det`]).
fn closed_scan(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    norm_wise: bool,
    dd: Option<&Closed<DualDd>>,
) -> Result<StabilityReport, RodError> {
    closed_scan_from(c, a, norm_wise, dd, 0.0)
}

/// [`closed_scan`] over [max(t0, from), 1] only: for a verdict where a theorem rules out any
/// conjugate point before `from` ([`verdict_of`]; the margin it reports is that range's).
fn closed_scan_from(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    norm_wise: bool,
    dd: Option<&Closed<DualDd>>,
    from: f64,
) -> Result<StabilityReport, RodError> {
    let (a3, a5) = (a[0], a[2]);
    // At small t the entries of J(t) are O(t)..O(t³) and the closed form's absolute error
    // floor swamps det J ∝ t⁹: there g comes from a short Taylor series from the base,
    // which is accurate relative to itself (one low-order step for t ≲ 0.2). Norm-wise
    // (near the separatrix under a force) g grows like e^{2√‖F‖ t}, and the closed form's
    // value is taken where it is accurate relative to itself.
    let samples = ClosedSamples {
        c,
        a,
        norm_wise,
        dd,
        start: ShortSeries::for_scan(a, norm_wise),
        root_f: crate::scalar::fast_hypot(a[1], a[2]).sqrt(),
        frame: c.det_frame(),
    };
    let recorded = Recorded::new(|t| samples.eval(t));
    let sloped = |t: f64| recorded.eval(t);
    let g = |t: f64| {
        let (v, e, _) = recorded.eval(t);
        (v, e)
    };
    let wl = c.wavelength();
    // No conjugate point comes before a fraction of the half-wavelength, and there the
    // closed-form det J (≈ t⁹) is swamped by rounding: start the scan at t0.
    let t0 = (0.1 * wl).clamp(T_MIN, T_MARGIN).max(from);
    let spacing = if norm_wise {
        (0.25 * wl).clamp(0.01, 0.1)
    } else {
        (SLOPED_SPACING * wl).clamp(0.01, SLOPED_MAX_SPACING)
    };
    let s = scan(
        &signs_where_possible(&sloped, c.conjugate_span_bound()),
        t0,
        spacing,
        (a3, a5),
        c.dip_times(spacing).as_slice(),
    )?;
    if !norm_wise {
        return Ok(verdict(s, recorded.at(s.t_margin).1));
    }
    // Norm-wise (near the separatrix under a strong force) the closed form's value is far
    // off where its bound is large, and an unstable verdict needs a sample past the first sign
    // change where g < 0 beyond its bound; the margin of a stable one is certified at t_margin
    // (by the closed form's bound or the f64 series, [`certify_margin`]). Between, where the
    // bound exceeds g by orders of magnitude, g ~ e^{2√‖F‖ t} is huge and the closed form's
    // sign is kept: measured against the 320-bit references (tests/separatrix_truth.rs, 760
    // rods) every verdict so reached is right, where the double-double scan called 30 of 1,429
    // stable rods of issue 23's tiny-bending sample "unstable" with a certain verdict.
    if s.first.is_some() {
        return Ok(certified_verdict(s, &g, (t0, spacing, a3, a5)));
    }
    let report = verdict(s, recorded.at(s.t_margin).1);
    if !report.uncertain {
        return Ok(report);
    }
    // It compares against g at t_margin, which the scan has already evaluated.
    Ok(certify_margin(a, s, &|t| recorded.at(t)).unwrap_or(report))
}

/// Grid spacing of the closed-form scan off the separatrix, in wavelengths, and its cap. Every
/// closed-form sample there carries g′ ([`normalised_det_sloped`]), so minima between samples
/// are found from the slopes' signs and the cubic through them ([`refine_margin`]): half a
/// wavelength keeps the margins as close to a dense scan as a quarter does (6,000 rods of
/// `slope_test_rod` against the series on 6,000 points each: worst excess 0.9 % for both, 0.74 %
/// once the small-angle prefix gave slopes too, where the value-only scan at a quarter
/// wavelength, capped at 0.1, was 5.1 % above; at 0.75 wavelength it is 10 %). The norm-wise scan keeps a quarter, capped at 0.1: its verdicts
/// were measured on that grid against the 320-bit references.
const SLOPED_SPACING: f64 = 0.5;
/// See [`SLOPED_SPACING`].
const SLOPED_MAX_SPACING: f64 = 0.3;

/// g with the evaluations it has made kept, so that the margin's error bound, read at
/// t_margin after the scan, costs a lookup ([`Self::at`]) instead of one more pose in dual
/// numbers: −2.2 % instructions per box stability test, net of the recording. Only that
/// read-back looks up (looking up every evaluation cost more than it saved).
struct Recorded<G> {
    g: G,
    seen: std::cell::RefCell<Evaluations>,
}

/// Up to [`RECORDED`] (t, g, its bound, its slope), and how many are filled.
type Evaluations = ([(f64, f64, f64, f64); RECORDED], usize);

/// Evaluations a [`Recorded`] keeps (a box scan makes ~22; later ones are recomputed).
const RECORDED: usize = 48;

impl<G: Fn(f64) -> (f64, f64, f64)> Recorded<G> {
    fn new(g: G) -> Self {
        Self {
            g,
            seen: std::cell::RefCell::new(([(0.0, 0.0, 0.0, 0.0); RECORDED], 0)),
        }
    }

    /// g(t), its bound and its slope, computed and recorded.
    fn eval(&self, t: f64) -> (f64, f64, f64) {
        let (v, e, d) = (self.g)(t);
        let mut seen = self.seen.borrow_mut();
        let (entries, n) = &mut *seen;
        if *n < RECORDED {
            entries[*n] = (t, v, e, d);
            *n += 1;
        }
        (v, e, d)
    }

    /// g(t) and its bound as recorded at exactly t (newest first), else computed.
    fn at(&self, t: f64) -> (f64, f64) {
        let recorded = {
            let seen = self.seen.borrow();
            let (entries, n) = &*seen;
            entries[..*n]
                .iter()
                .rev()
                .find(|x| x.0 == t)
                .map(|x| (x.1, x.2))
        };
        recorded.unwrap_or_else(|| {
            let (v, e, _) = self.eval(t);
            (v, e)
        })
    }
}

/// Step budget of the f64 series that certifies the margin of a rod near the separatrix
/// ([`certify_margin`]): ≈ 3 µs per step.
const MARGIN_SERIES_MAX_STEPS: usize = 60;
/// Largest estimated relative error of that series' J entries for which its g is used (its
/// rounding grows like e^{√‖F‖ t}, see [`certify_margin`]).
const MARGIN_SERIES_MAX_REL: f64 = 1e-6;

/// The margin of a stable rod near the separatrix under a strong force, certified by the f64
/// series from the base to t_margin, its entries' errors bounded by [`SERIES_ENTRY_REL`] plus
/// ε·e^{√‖F‖ t} norm-wise (rounding made near the hyperbolic straight equilibrium grows at
/// that rate), where the closed form's norm-wise bound is too
/// pessimistic. None where that bound, the step budget or the agreement of both values does
/// not hold.
fn certify_margin(
    a: &PlanarParams,
    s: Scan,
    g: &impl Fn(f64) -> (f64, f64),
) -> Option<StabilityReport> {
    let (a3, a5) = (a[0], a[2]);
    if a3.abs().max(a5.abs()) < SIGMA_RAY {
        return None;
    }
    let amplified = f64::EPSILON * (a[1].hypot(a[2]).sqrt() * s.t_margin).exp();
    if amplified.is_nan() || amplified > MARGIN_SERIES_MAX_REL {
        return None;
    }
    let rod = TaylorRod::new_to(
        Dual3::variable(a3, 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a5, 2),
        s.t_margin,
        MARGIN_SERIES_MAX_STEPS,
        false,
    )
    .ok()?;
    let j = scaled_jacobian(rod.tip(), a3, a5)?;
    let (value, error) = normalised_det_of(&j, a3, a5, s.t_margin, SERIES_ENTRY_REL, amplified);
    // The scan's value and the series' must agree within their bounds.
    let (v, e) = g(s.t_margin);
    if !(value.is_finite() && value.abs() > error && (value - v).abs() <= error + e) {
        return None;
    }
    Some(verdict(Scan { margin: value, ..s }, error))
}

/// Largest error bound of the closed form's g(t), relative to max(|g|, 1), for which the scan
/// takes its value (g is scale-free, ≈ 1 on a gently bent rod: a thousandth of that cannot
/// decide a sign or the margin's verdict; near a root of g the bound is small and the closed
/// form is kept).
const CLOSED_G_ERROR: f64 = 1e-3;
/// Near the separatrix (norm-wise scan) the short series stands in for the closed form up to
/// √‖F‖·t = this only: beyond, g grows like e^{2√‖F‖ t} (the rod lingers by the straight
/// equilibrium) and the closed form's value decides its sign, while the margin, found at
/// small t or in a dip where the closed form is accurate, is certified separately
/// ([`certify_margin`]).
const SHORT_SERIES_REACH: f64 = 6.0;
/// The short series' first end on a strongly bent rod is this over ρ = max(|a3|, √‖F‖) (a
/// few steps; 0.2 for ρ ≤ 10, as for every rod before).
const SHORT_SERIES_FIRST_END_RHO: f64 = 2.0;
/// Step budget of the short series (≈ 3 µs per step): beyond, the rod is too strongly bent
/// for a short start and the closed form's value stands (an uncertain verdict then goes to
/// the full series, as without the short series).
const SHORT_SERIES_MAX_STEPS: usize = 24;

/// The rod's Taylor series from the base to some t_end ≤ 1, built on first use and extended
/// (rebuilt to 2t) when asked beyond its end. Truncated at 1e-10 per step ([`CoarseDual3`]):
/// its g is taken to 1e-3 and bounded with the coarse series' own error
/// ([`COARSE_ENTRY_REL`]), and the longer steps cost a third less under a strong force.
struct ShortSeries {
    a: PlanarParams,
    /// The ends it grows to when asked at t beyond its end: 2t within [min_end, max_end]
    /// (at least t).
    min_end: f64,
    max_end: f64,
    rod: std::cell::RefCell<Start>,
}

/// The state of a [`ShortSeries`].
enum Start {
    NotBuilt,
    /// It could not be built or extended within its step budget.
    Failed,
    /// Built to `rod.t_end()`; `steps_left` of the budget remain (0 once an extension failed:
    /// the steps already taken stay valid and keep answering below their end).
    Built {
        rod: Box<TaylorRod<CoarseDual3>>,
        steps_left: usize,
    },
}

impl ShortSeries {
    fn new(a: &PlanarParams, min_end: f64, max_end: f64) -> Self {
        Self {
            a: *a,
            min_end,
            max_end,
            rod: std::cell::RefCell::new(Start::NotBuilt),
        }
    }

    /// The short series of [`closed_scan`]: norm-wise up to √‖F‖·t = [`SHORT_SERIES_REACH`];
    /// otherwise one low-order step reaches t ≈ 0.2 on a gently bent rod, and on a strongly
    /// bent one (ρ = max(|a3|, √‖F‖) ≫ 1) the steps shrink like 1/ρ while the closed form is
    /// accurate from t ~ 1/ρ on: the first end is capped there (it still grows to 2t).
    fn for_scan(a: &PlanarParams, norm_wise: bool) -> Self {
        let root_f = crate::scalar::fast_hypot(a[1], a[2]).sqrt();
        if norm_wise {
            Self::new(a, 0.0, (SHORT_SERIES_REACH / root_f).min(1.0))
        } else {
            let rho = a[0].abs().max(root_f);
            Self::new(a, (SHORT_SERIES_FIRST_END_RHO / rho).min(0.2), 1.0)
        }
    }

    /// g(t) and its error bound from the series; None where the series cannot be built (the
    /// caller keeps the closed form's value) or the bending is too small to scale (σ < 1e-60,
    /// where `stability_of_series` works on a ray).
    fn normalised_det(&self, t: f64) -> Option<(f64, f64, f64)> {
        let (a3, a5) = (self.a[0], self.a[2]);
        if a3.abs().max(a5.abs()) < SIGMA_RAY {
            return None;
        }
        let mut slot = self.rod.borrow_mut();
        if let Start::NotBuilt = *slot {
            // Started empty and grown below: a budget that runs out before the first end
            // still leaves the steps taken.
            *slot = match TaylorRod::new_to(
                CoarseDual3(Dual3::variable(a3, 0)),
                CoarseDual3(Dual3::variable(self.a[1], 1)),
                CoarseDual3(Dual3::variable(a5, 2)),
                0.0,
                0,
                true,
            ) {
                Ok(rod) => Start::Built {
                    steps_left: SHORT_SERIES_MAX_STEPS,
                    rod: Box::new(rod),
                },
                Err(_) => Start::Failed,
            };
        }
        // Grown, not rebuilt: the steps to the old end are kept, and kept too when the budget
        // runs out before the new end (they still answer up to where they reached).
        if let Start::Built { rod, steps_left } = &mut *slot {
            if rod.t_end() < t && *steps_left > 0 {
                let end = (2.0 * t).clamp(self.min_end, self.max_end.max(t));
                let before = rod.steps();
                let _ = rod.extend_to(end, *steps_left);
                *steps_left -= rod.steps() - before;
                if rod.t_end() < end {
                    *steps_left = 0;
                }
            }
        }
        let Start::Built { rod, .. } = &*slot else {
            return None;
        };
        if rod.t_end() < t {
            return None;
        }
        let root_f = crate::scalar::fast_hypot(self.a[1], self.a[2]).sqrt();
        let amplified = (f64::EPSILON + COARSE_AMPLIFIED) * (root_f * t).exp();
        let j = scaled_series_jacobian(rod, a3, a5, t)?;
        let (v, e) = normalised_det_of(
            &j,
            a3,
            a5,
            t,
            SERIES_ENTRY_REL + COARSE_ENTRY_REL,
            amplified,
        );
        // g′ as [`normalised_det_sloped`] forms it, on the same scaled rows: the a4 entry of
        // ∂κ/∂a is scaled like J's a4 column (det′ and N then carry the same 1/σ²).
        if !v.is_finite() {
            return None;
        }
        let slope = rod.curvature(t).map_or(f64::NAN, |kappa| {
            let mut k = kappa.gradient();
            k[1] /= a3.abs().max(a5.abs());
            let log_slope = crate::types::planar_det_leading_term_log_slope(a3, a5, t);
            det3(&[j[0], j[1], k]) / normalisation_scaled(a3, a5, t) - v * log_slope
        });
        Some((v, e, slope))
    }
}

/// What a scan of g found.
#[derive(Clone, Copy, Debug)]
struct Scan {
    /// First sign change (det ≤ 0).
    first: Option<f64>,
    /// min g over t ≥ T_MARGIN (or the negative value at a sign change below it).
    margin: f64,
    /// Where the margin was found.
    t_margin: f64,
}

/// One evaluation of g for [`scan`]: its value (NaN: no sign, the sample is dropped) and its
/// slope g′(t), NaN where the source gives none (the series, the short series and the
/// double-double closed form).
#[derive(Clone, Copy, Debug)]
struct Probe {
    v: f64,
    d: f64,
}

/// A value-only g as a [`scan`] probe (no slope).
fn value_only(g: impl Fn(f64) -> f64) -> impl Fn(f64) -> Probe {
    move |t| Probe {
        v: g(t),
        d: f64::NAN,
    }
}

/// Scan of g on [t0, 1] with spacing ≈ `h_target`, root finding on the first sign change and
/// refinement of local minima for the margin (with g′ where the probe gives it).
fn scan(
    g: &impl Fn(f64) -> Probe,
    t0: f64,
    h_target: f64,
    (a3, a5): (f64, f64),
    extra: &[f64],
) -> Result<Scan, RodError> {
    let mut ts = [0.0f64; MAX_SAMPLES];
    let np = sample_times_into(&mut ts, t0, h_target, (a3, a5), extra);
    let mut ps = [Probe { v: 0.0, d: 0.0 }; MAX_SAMPLES];
    // NaN: g's sign there is rounding where det J > 0 is known ([`closed_scan`]); dropped.
    let mut kept = 0;
    for i in 0..np {
        let (t, p) = (ts[i], g(ts[i]));
        if p.v.is_nan() {
            continue;
        }
        if p.v.is_infinite() {
            return Err(RodError::Overflow(
                "stability: det J(t) is not finite (parameters too large)".into(),
            ));
        }
        ts[kept] = t;
        ps[kept] = p;
        kept += 1;
    }
    let (ts, ps) = (&ts[..kept], &ps[..kept]);
    // First sign change (det ≤ 0), and the value seen there.
    let mut first = first_sign_change(g, ts, ps);
    let (mut margin, mut t_margin) = refine_margin(g, ts, ps, &mut first);
    if let Some((_, neg_value, neg_t)) = first.filter(|_| margin >= 0.0) {
        // The sign change lies below T_MARGIN: report the negative value seen there.
        margin = neg_value.min(0.0);
        t_margin = neg_t;
    }
    if !margin.is_finite() {
        margin = 0.0;
    }
    Ok(Scan {
        first: first.map(|f| f.0),
        margin,
        t_margin,
    })
}

/// The sample times: a grid of spacing ≈ `h_target` on [t0, 1], T_MARGIN, three times
/// around t* = √(33600/8640)|a3/a5|, and `extra` (at most [`MAX_EXTRA_SAMPLES`]), sorted;
/// returns them and their number.
fn sample_times(
    t0: f64,
    h_target: f64,
    (a3, a5): (f64, f64),
    extra: &[f64],
) -> ([f64; MAX_SAMPLES], usize) {
    let mut ts = [0.0f64; MAX_SAMPLES];
    let np = sample_times_into(&mut ts, t0, h_target, (a3, a5), extra);
    (ts, np)
}

/// [`sample_times`] written into `ts` (the scan's own array: returned by value, the 112 times
/// were copied); returns their number.
fn sample_times_into(
    ts: &mut [f64; MAX_SAMPLES],
    t0: f64,
    h_target: f64,
    (a3, a5): (f64, f64),
    extra: &[f64],
) -> usize {
    let n = ((1.0 - t0) / h_target).ceil().max(1.0) as usize;
    let n = n.min(MAX_SAMPLES - 4 - MAX_EXTRA_SAMPLES);
    let h = (1.0 - t0) / n as f64;
    let mut np = n + 1;
    for (i, t) in ts.iter_mut().enumerate().take(np) {
        *t = if i == n { 1.0 } else { t0 + i as f64 * h };
    }
    // The normalisation t⁹(a3²/8640 + a5²t²/33600) changes regime at t*, where g often has a
    // narrow dip: sample around it too (for the margin). The margin's window starts at
    // T_MARGIN, where g is often smallest (|a3| ≪ |a5|): sample it exactly.
    let ts_star = if a5 != 0.0 {
        (33600.0f64 / 8640.0).sqrt() * (a3 / a5).abs()
    } else {
        f64::NAN
    };
    let fixed = [T_MARGIN, ts_star * 0.7, ts_star, ts_star * 1.4];
    for &t in fixed.iter().chain(extra.iter().take(MAX_EXTRA_SAMPLES)) {
        if t > t0 && t < 1.0 && np < ts.len() {
            // insert keeping ts sorted
            let mut k = np;
            while k > 0 && ts[k - 1] > t {
                ts[k] = ts[k - 1];
                k -= 1;
            }
            ts[k] = t;
            np += 1;
        }
    }
    np
}

/// The first sign change of g over the samples (det ≤ 0): (where, located by [`find_root`],
/// the negative value sampled, its time).
fn first_sign_change(
    g: &impl Fn(f64) -> Probe,
    ts: &[f64],
    ps: &[Probe],
) -> Option<(f64, f64, f64)> {
    let i = ps.iter().position(|p| p.v <= 0.0)?;
    let t = if i == 0 {
        ts[0]
    } else {
        find_root(g, (ts[i - 1], ps[i - 1]), (ts[i], ps[i]))
    };
    Some((t, ps[i].v, ts[i]))
}

/// The margin: min g over t ≥ T_MARGIN with the coarse minima that matter refined
/// ([`refine_min`]: those low enough to hide a dip below zero or to be the global minimum;
/// only the global one once a sign change is known). A minimum is an interval where g′ turns
/// from ≤ 0 to ≥ 0 where both ends carry slopes (its low estimated by the cubic through
/// them), else a sample below both neighbours. A dip below zero found between two samples
/// becomes the first sign change. Returns (margin, where).
fn refine_margin(
    g: &impl Fn(f64) -> Probe,
    ts: &[f64],
    ps: &[Probe],
    first: &mut Option<(f64, f64, f64)>,
) -> (f64, f64) {
    let mut margin = f64::INFINITY;
    let mut t_margin = 1.0;
    for (&t, p) in ts.iter().zip(ps) {
        if t >= T_MARGIN && p.v < margin {
            margin = p.v;
            t_margin = t;
        }
    }
    let cutoff = if first.is_some() {
        margin
    } else {
        2.0 * margin.max(0.0) + 0.05
    };
    let n = ts.len();
    // Per interval [t_i, t_i+1]: both ends carry slopes and g′ turns from ≤ 0 to ≥ 0 there
    // (NaN slopes fail both tests).
    let mut turns = [false; MAX_SAMPLES];
    for i in 0..n.saturating_sub(1) {
        turns[i] = ps[i].d <= 0.0 && ps[i + 1].d >= 0.0;
    }
    for i in 0..n.saturating_sub(1) {
        let found = if turns[i] {
            // A minimum inside [t_i, t_i+1] (its slopes say so).
            let (left, right) = ((ts[i], ps[i]), (ts[i + 1], ps[i + 1]));
            // (A NaN low is not below the cutoff.)
            let low_enough = cubic_low(left, right) <= cutoff;
            if ts[i + 1] < T_MARGIN || !low_enough {
                continue;
            }
            (i, refine_min_sloped(g, left, right))
        } else if i >= 1 && !turns[i - 1] {
            // A sample below both neighbours that no turn of the slopes beside it accounts
            // for (no slopes there, or two extrema between samples).
            let (v0, v1, v2) = (ps[i - 1].v, ps[i].v, ps[i + 1].v);
            if !(v1 <= v0 && v1 <= v2 && ts[i + 1] >= T_MARGIN && v1 <= cutoff) {
                continue;
            }
            let refined = refine_min(
                g,
                (ts[i - 1], ps[i - 1]),
                (ts[i], ps[i]),
                (ts[i + 1], ps[i + 1]),
            );
            (i - 1, refined)
        } else {
            continue;
        };
        let (k, (tm, pm)) = found;
        if tm < T_MARGIN || pm.v.is_nan() {
            continue;
        }
        if pm.v < margin {
            margin = pm.v;
            t_margin = tm;
        }
        if first.is_none() && pm.v <= 0.0 {
            // A dip below zero between two coarse samples.
            let tc = if ps[k].v > 0.0 {
                find_root(g, (ts[k], ps[k]), (tm, pm))
            } else {
                tm
            };
            *first = Some((tc, pm.v, tm));
        }
    }
    if first.is_none() {
        (margin, t_margin) = refine_window_ends(g, ts, ps, (margin, t_margin), first);
    }
    (margin, t_margin)
}

/// The lowest value on [l, r] of the cubic Hermite interpolant through g and g′ at both ends
/// (g′(l) ≤ 0 ≤ g′(r)): its minimiser by Nocedal & Wright's eq. 3.59.
fn cubic_low((l, pl): (f64, Probe), (r, pr): (f64, Probe)) -> f64 {
    let t = cubic_minimiser((l, pl), (r, pr));
    let cubic = HermiteCubic::new((l, pl), (r, pr));
    let v = cubic.at((t - l) / (r - l));
    v.min(pl.v).min(pr.v)
}

/// The cubic Hermite interpolant through (t0, g0, g0′), (t1, g1, g1′) in s = (t − t0)/h:
/// g0 + m0 s + c2 s² + c3 s³ with m = g′h.
struct HermiteCubic {
    g0: f64,
    m0: f64,
    c2: f64,
    c3: f64,
}

impl HermiteCubic {
    fn new((t0, p0): (f64, Probe), (t1, p1): (f64, Probe)) -> Self {
        let h = t1 - t0;
        let (m0, m1) = (p0.d * h, p1.d * h);
        Self {
            g0: p0.v,
            m0,
            c2: 3.0 * (p1.v - p0.v) - 2.0 * m0 - m1,
            c3: 2.0 * (p0.v - p1.v) + m0 + m1,
        }
    }

    /// Its value at s.
    fn at(&self, s: f64) -> f64 {
        self.g0 + s * (self.m0 + s * (self.c2 + s * self.c3))
    }

    /// Its derivative in s at s.
    fn slope(&self, s: f64) -> f64 {
        self.m0 + s * (2.0 * self.c2 + s * 3.0 * self.c3)
    }
}

/// The minimiser in (l, r) of the cubic Hermite interpolant through g and g′ at both ends
/// (Nocedal & Wright, Numerical Optimization, eq. 3.59); the midpoint where that fails.
fn cubic_minimiser((l, pl): (f64, Probe), (r, pr): (f64, Probe)) -> f64 {
    let d1 = pl.d + pr.d - 3.0 * (pl.v - pr.v) / (l - r);
    let d2 = (d1 * d1 - pl.d * pr.d).sqrt();
    let t = r - (r - l) * (pr.d + d2 - d1) / (pr.d - pl.d + 2.0 * d2);
    if t > l && t < r {
        t
    } else {
        0.5 * (l + r)
    }
}

/// The margin's window ends (T_MARGIN, 1) where the lowest sample lies there and no slopes
/// say more: g may dip between it and the next sample (under a strong force the dips are
/// ~1/√‖F‖ wide, the grid 0.1). One probe a quarter of the way in; if it is lower, a refinement of the bracket it
/// makes (a dip found below zero becomes the first sign change).
fn refine_window_ends(
    g: &impl Fn(f64) -> Probe,
    ts: &[f64],
    ps: &[Probe],
    (mut margin, mut t_margin): (f64, f64),
    first: &mut Option<(f64, f64, f64)>,
) -> (f64, f64) {
    let n = ts.len();
    let Some(lo) = ts.iter().position(|&t| t >= T_MARGIN) else {
        return (margin, t_margin);
    };
    for (end, inner) in [(lo, lo + 1), (n - 1, n.wrapping_sub(2))] {
        if inner >= n || inner < lo || ps[end].v != margin || ps[inner].v <= ps[end].v {
            continue;
        }
        if ps[end].d.is_finite() && ps[inner].d.is_finite() {
            // The slopes have told already: a minimum inside was refined ([`refine_margin`]),
            // or g rises from the end.
            continue;
        }
        let tp = ts[end] + 0.25 * (ts[inner] - ts[end]);
        let pp = g(tp);
        // (NaN, no sign, is not lower.)
        if pp.v.is_nan() || pp.v >= ps[end].v {
            continue;
        }
        let (left, right) = if end < inner {
            ((ts[end], ps[end]), (ts[inner], ps[inner]))
        } else {
            ((ts[inner], ps[inner]), (ts[end], ps[end]))
        };
        let (tm, pm) = refine_min(g, left, (tp, pp), right);
        (margin, t_margin) = if pm.v < pp.v { (pm.v, tm) } else { (pp.v, tp) };
        if margin <= 0.0 && first.is_none() {
            let at_margin = if pm.v < pp.v { pm } else { pp };
            let tc = if left.1.v > 0.0 {
                find_root(g, left, (t_margin, at_margin))
            } else {
                t_margin
            };
            *first = Some((tc, margin, t_margin));
        }
    }
    (margin, t_margin)
}

/// Sample budget of one scan (coarse grid, T_MARGIN, three samples around t* and the extra
/// ones).
const MAX_SAMPLES: usize = 112;
/// Most extra sample times a scan takes (`Closed::dip_times`).
const MAX_EXTRA_SAMPLES: usize = super::closed::MAX_DIP_TIMES;

/// Illinois regula falsi for the root of g in (t0, t1) with g(t0) > 0 ≥ g(t1).
fn regula_falsi(g: &impl Fn(f64) -> f64, t0: f64, g0: f64, t1: f64, g1: f64) -> f64 {
    let (mut lo, mut glo, mut hi, mut ghi) = (t0, g0, t1, g1);
    let mut side = 0i8;
    for _ in 0..24 {
        if hi - lo <= 1e-7 {
            break;
        }
        let mut t = (lo * ghi - hi * glo) / (ghi - glo);
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let gt = g(t);
        // NaN: a sign known positive ([`scan`]).
        if gt > 0.0 || gt.is_nan() {
            if side == -1 {
                ghi *= anderson_bjorck(gt, glo);
            }
            lo = t;
            glo = gt;
            side = -1;
        } else {
            if side == 1 {
                glo *= anderson_bjorck(gt, ghi);
            }
            hi = t;
            ghi = gt;
            side = 1;
        }
        if gt == 0.0 {
            return t;
        }
    }
    // Illinois stalls on a g growing like e^{2√‖F‖ t} (under a tension of 71,306 it stopped
    // 0.003 past the root): bisection finishes the bracket.
    for _ in 0..32 {
        if hi - lo <= 1e-7 {
            break;
        }
        let t = 0.5 * (lo + hi);
        let gt = g(t);
        if gt > 0.0 || gt.is_nan() {
            lo = t;
        } else {
            hi = t;
        }
    }
    hi
}

/// The factor on the value kept at the end of the bracket that did not move twice in a row
/// (Anderson & Björck 1973): 1 − g_new/g_old for the end that moved, ½ (Illinois) where that
/// is not in (0, 1).
fn anderson_bjorck(g_new: f64, g_old: f64) -> f64 {
    let m = 1.0 - g_new / g_old;
    if m > 0.0 && m < 1.0 {
        m
    } else {
        0.5
    }
}

/// Bracket width to which a conjugate point is located.
const ROOT_TOL: f64 = 1e-7;
/// Steps of [`find_root`] with slopes before the rest of the bracket goes to the regula falsi.
const ROOT_SLOPE_STEPS: usize = 8;

/// The root of g in (t0, t1), g(t0) > 0 ≥ g(t1), to [`ROOT_TOL`] (the end where g ≤ 0). Where
/// both ends carry values and slopes: the root of the cubic Hermite interpolant through them
/// ([`hermite_root`], always inside the bracket), kept 0.4·ROOT_TOL inside so that once an
/// end holds the root to that, the next sample lands past it and closes the bracket: ~3
/// samples from a grid interval of 0.1, where the regula falsi takes ~6. Elsewhere, and for
/// what [`ROOT_SLOPE_STEPS`] steps leave, the regula falsi ([`regula_falsi`]).
fn find_root(g: &impl Fn(f64) -> Probe, (t0, p0): (f64, Probe), (t1, p1): (f64, Probe)) -> f64 {
    let (mut lo, mut plo, mut hi, mut phi) = (t0, p0, t1, p1);
    for _ in 0..ROOT_SLOPE_STEPS {
        if hi - lo <= ROOT_TOL {
            return hi;
        }
        let finite = [plo.v, plo.d, phi.v, phi.d].iter().all(|v| v.is_finite());
        if !(finite && plo.v > 0.0 && phi.v <= 0.0) {
            break;
        }
        let t = hermite_root((lo, plo), (hi, phi));
        let t = if t.is_finite() {
            t.clamp(lo + 0.4 * ROOT_TOL, hi - 0.4 * ROOT_TOL)
        } else {
            0.5 * (lo + hi)
        };
        let p = g(t);
        if p.v == 0.0 {
            return t;
        }
        // NaN: a sign known positive ([`scan`]).
        if p.v > 0.0 || p.v.is_nan() {
            (lo, plo) = (t, p);
        } else {
            (hi, phi) = (t, p);
        }
    }
    if hi - lo <= ROOT_TOL {
        return hi;
    }
    regula_falsi(&|t| g(t).v, lo, plo.v, hi, phi.v)
}

/// A root in (t0, t1) of the cubic Hermite interpolant through (t0, g0, g0′), (t1, g1, g1′)
/// with g0 > 0 ≥ g1 (so one exists): safeguarded Newton steps on the cubic from the regula
/// falsi point, bisection where a step leaves the bracket, to 1e-3 of [`ROOT_TOL`].
fn hermite_root((t0, p0): (f64, Probe), (t1, p1): (f64, Probe)) -> f64 {
    let h = t1 - t0;
    let cubic = HermiteCubic::new((t0, p0), (t1, p1));
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let mut s = p0.v / (p0.v - p1.v);
    for _ in 0..12 {
        let v = cubic.at(s);
        if v > 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        let next = s - v / cubic.slope(s);
        let next = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        let step = (next - s).abs();
        s = next;
        if step * h < 1e-3 * ROOT_TOL {
            break;
        }
    }
    t0 + s * h
}

/// Improvement of a refined minimum, relative to max(|g|, 1), below which [`refine_min`] stops
/// (with slopes; the parabolic steps stop at a bracket of 1e-4, ~1e-9 of g).
const MIN_GAIN_REL: f64 = 1e-10;

/// A local minimum of g bracketed by t0 < t1 < t2 with g(t1) ≤ g(t0), g(t2): (where, g
/// there), the lowest sample seen. With slopes at all three, cubic Hermite steps on the half
/// where g′ changes sign ([`refine_min_sloped`]); otherwise parabolic steps.
fn refine_min(
    g: &impl Fn(f64) -> Probe,
    (t0, p0): (f64, Probe),
    (t1, p1): (f64, Probe),
    (t2, p2): (f64, Probe),
) -> (f64, Probe) {
    if p0.d.is_finite() && p1.d.is_finite() && p2.d.is_finite() {
        let (left, right) = if p1.d <= 0.0 {
            ((t1, p1), (t2, p2))
        } else {
            ((t0, p0), (t1, p1))
        };
        if left.1.d <= 0.0 && right.1.d >= 0.0 {
            return refine_min_sloped(g, left, right);
        }
    }
    refine_min_parabolic(g, (t0, p0), (t1, p1), (t2, p2))
}

/// The minimum of g on [l, r] where g′(l) ≤ 0 ≤ g′(r), by the minimiser of the cubic Hermite
/// interpolant (Nocedal & Wright, Numerical Optimization, eq. 3.59) until the gain the slope
/// predicts, g′²/(2g″), falls below [`MIN_GAIN_REL`]; the lowest sample seen.
fn refine_min_sloped(
    g: &impl Fn(f64) -> Probe,
    (mut l, mut pl): (f64, Probe),
    (mut r, mut pr): (f64, Probe),
) -> (f64, Probe) {
    let mut best = if pl.v <= pr.v { (l, pl) } else { (r, pr) };
    for _ in 0..6 {
        if r - l < 1e-9 {
            break;
        }
        let t = cubic_minimiser((l, pl), (r, pr));
        let p = g(t);
        if !(p.v.is_finite() && p.d.is_finite()) {
            break;
        }
        if p.v < best.1.v {
            best = (t, p);
        }
        if p.d <= 0.0 {
            (l, pl) = (t, p);
        } else {
            (r, pr) = (t, p);
        }
        let curvature = (pr.d - pl.d) / (r - l);
        if curvature > 0.0 && p.d * p.d / (2.0 * curvature) <= MIN_GAIN_REL * p.v.abs().max(1.0) {
            break;
        }
    }
    best
}

/// Parabolic steps on a bracketed minimum (values alone), to a bracket of 1e-4.
fn refine_min_parabolic(
    g: &impl Fn(f64) -> Probe,
    (t0, p0): (f64, Probe),
    (t1, p1): (f64, Probe),
    (t2, p2): (f64, Probe),
) -> (f64, Probe) {
    let (mut a, mut b, mut c) = (t0, t1, t2);
    let (mut fa, mut fc) = (p0.v, p2.v);
    let mut pb = p1;
    for _ in 0..6 {
        if c - a < 1e-4 {
            break;
        }
        let fb = pb.v;
        let p = (b - a) * (b - a) * (fb - fc) - (b - c) * (b - c) * (fb - fa);
        let q = (b - a) * (fb - fc) - (b - c) * (fb - fa);
        if q == 0.0 {
            break;
        }
        let mut t = b - 0.5 * p / q;
        if !(t > a && t < c) || (t - b).abs() < 1e-9 {
            if (t - b).abs() < 1e-9 {
                break;
            }
            t = 0.5 * (b + if b - a > c - b { a } else { c });
        }
        let pt = g(t);
        let ft = pt.v;
        if ft < fb {
            if t < b {
                c = b;
                fc = fb;
            } else {
                a = b;
                fa = fb;
            }
            b = t;
            pb = pt;
        } else if t < b {
            a = t;
            fa = ft;
        } else {
            c = t;
            fc = ft;
        }
    }
    (b, pb)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    use crate::planar::small_angle::tests::nearly_straight_sample;

    /// A rod for the slope tests: the paper's box, log-scale magnitudes with exact zeros,
    /// looped rods and near-circles under a small force.
    fn slope_test_rod(r: &mut SplitMix64, i: usize) -> PlanarParams {
        match i % 4 {
            0 => PlanarParams::new(
                r.range(-10.0, 10.0),
                r.range(-100.0, 100.0),
                r.range(-100.0, 100.0),
            ),
            1 => {
                let z = |r: &mut SplitMix64, v: f64| if r.range(0.0, 1.0) < 0.15 { 0.0 } else { v };
                let a3 = r.signed_pow10(-4.0, 1.5);
                let a4 = r.signed_pow10(-4.0, 3.0);
                let a5 = r.signed_pow10(-4.0, 3.0);
                PlanarParams::new(a3, z(r, a4), z(r, a5))
            }
            2 => PlanarParams::new(r.range(-40.0, 40.0), r.range(-5.0, 5.0), r.range(-5.0, 5.0)),
            _ => {
                let a3 = r.range(3.0, 12.0) * if r.range(0.0, 1.0) < 0.5 { -1.0 } else { 1.0 };
                let f = a3 * a3 * r.signed_pow10(-3.0, -0.5);
                let phi = r.range(0.0, std::f64::consts::TAU);
                PlanarParams::new(a3, f * phi.cos(), f * phi.sin())
            }
        }
    }

    /// [`find_root`] and [`refine_min`] on functions with known roots and minima: with slopes
    /// the root comes within [`ROOT_TOL`] past the true one in at most 5 samples from a bracket
    /// of 0.1, and the minimum to 1e-10 of g; without slopes (the regula falsi, parabolic
    /// steps) the same answers to their own tolerances; non-finite values end in the regula
    /// falsi without a panic.
    #[test]
    fn root_and_minimum_from_slopes() {
        use std::cell::Cell;
        let calls = Cell::new(0);
        // g = e^{−3t} − e^{−1.5}: root at 0.5, slope −3e^{−3t}.
        let g = |t: f64| {
            calls.set(calls.get() + 1);
            Probe {
                v: (-3.0 * t).exp() - (-1.5f64).exp(),
                d: -3.0 * (-3.0 * t).exp(),
            }
        };
        for (t0, t1) in [
            (0.45, 0.55),
            (0.41, 0.51),
            (0.499_999_99, 0.6),
            (0.3, 0.500_000_05),
        ] {
            calls.set(0);
            let root = find_root(&g, (t0, g(t0)), (t1, g(t1)));
            assert!(root >= 0.5 && root - 0.5 <= ROOT_TOL, "{t0}..{t1}: {root}");
            assert!(calls.get() <= 2 + 5, "{t0}..{t1}: {} samples", calls.get());
            let values = |t: f64| Probe {
                d: f64::NAN,
                ..g(t)
            };
            let root = find_root(&values, (t0, values(t0)), (t1, values(t1)));
            assert!(
                root >= 0.5 && root - 0.5 <= ROOT_TOL,
                "{t0}..{t1}: {root} (no slopes)"
            );
        }
        // Non-finite values inside the bracket: no panic, a point of the bracket.
        let wild = |t: f64| Probe {
            v: if (t - 0.5).abs() < 0.01 {
                f64::NEG_INFINITY
            } else {
                0.5 - t
            },
            d: -1.0,
        };
        let root = find_root(&wild, (0.4, wild(0.4)), (0.6, wild(0.6)));
        assert!((0.4..=0.6).contains(&root), "{root}");
        // A minimum of g = 1 − cos 3(t − 0.31) + 0.05 (t − 0.31)³ bracketed by 0.2, 0.3, 0.4.
        let bowl = |t: f64| {
            let x = t - 0.31;
            Probe {
                v: 1.0 - (3.0 * x).cos() + 0.05 * x.powi(3),
                d: 3.0 * (3.0 * x).sin() + 0.15 * x * x,
            }
        };
        let dense_min = (0..=200_000)
            .map(|k| bowl(0.2 + 0.2 * f64::from(k) / 200_000.0).v)
            .fold(f64::INFINITY, f64::min);
        let (a, b, c) = ((0.2, bowl(0.2)), (0.3, bowl(0.3)), (0.4, bowl(0.4)));
        let sloped = refine_min(&bowl, a, b, c);
        assert!((sloped.0 - 0.31).abs() < 1e-4, "{sloped:?}");
        assert!(
            sloped.1.v <= dense_min + 1e-10,
            "{sloped:?} against {dense_min}"
        );
        let values = |t: f64| Probe {
            d: f64::NAN,
            ..bowl(t)
        };
        let (a, b, c) = ((0.2, values(0.2)), (0.3, values(0.3)), (0.4, values(0.4)));
        let plain = refine_min(&values, a, b, c);
        assert!(
            plain.1.v <= dense_min + 1e-8,
            "{plain:?} against {dense_min}"
        );
    }

    /// The small-angle g₀′(t) ([`small_angle::normalised_det_sloped`]) against central
    /// differences of g₀ on 3,000 nearly straight rods (a4 log-scale 1e-6..1e4 of either sign
    /// and 0, a3 and a5 log-scale 1e-20..0.1 and 0) at 12 times each, where g₀'s rounding is
    /// below 1e-10 of max(|g₀|, 1): within 1e-5 of |g₀′| + |g₀|/λ, λ = min(1, 2π/√|a4|), beyond
    /// the rounding of the differences (Richardson-extrapolated over h = 1e-4·λ and h/2).
    #[test]
    fn small_angle_slope_is_the_derivative() {
        let mut r = SplitMix64::new(17);
        let (mut compared, mut worst) = (0usize, 0.0f64);
        for i in 0..3000 {
            let Some(a) = nearly_straight_sample(&mut r, i) else {
                continue;
            };
            let (a3, a4, a5) = (a[0], a[1], a[2]);
            let wl = (std::f64::consts::TAU / a4.abs().sqrt()).min(1.0);
            let h = 1e-4 * wl;
            for k in 1..=12 {
                let t = 0.05 + 0.9 * f64::from(k) / 12.0;
                let (v, e, d) = small_angle::normalised_det_sloped(a3, a4, a5, t);
                // Central differences over h and h/2, extrapolated (Richardson): g₀ has narrow
                // features (near t* = 1.97|a3/a5|) where one difference's h²g₀‴/6 is 1e-4.
                let central = |h: f64| {
                    let (vp, ep) = small_angle::normalised_det(a3, a4, a5, t + h);
                    let (vm, em) = small_angle::normalised_det(a3, a4, a5, t - h);
                    ((vp - vm) / (2.0 * h), (ep + em) / (2.0 * h))
                };
                let ((d1, r1), (d2, r2)) = (central(h), central(0.5 * h));
                if e > 1e-10 * v.abs().max(1.0) || !(d.is_finite() && d1.is_finite()) {
                    continue;
                }
                let diff = (4.0 * d2 - d1) / 3.0;
                // The extrapolation's rounding, (4r₂ + r₁)/3, ×2.
                let rounding = 2.0 * (4.0 * r2 + r1) / 3.0;
                let scale = d.abs() + v.abs() / wl;
                let dev = (d - diff).abs();
                assert!(
                    dev <= 1e-5 * scale + rounding,
                    "a = {a:?}, t = {t}: g₀′ {d} against {diff} (g₀ {v})"
                );
                worst = worst.max(dev / scale);
                compared += 1;
            }
        }
        assert!(compared >= 10_000, "{compared}");
        eprintln!("{compared} small-angle slopes, worst deviation {worst:.2e}");
    }

    /// The margin and verdict of `planar::stability` against a dense scan of the series' g (an
    /// independent computation, J entries accurate to 1e-14 relative) on 1,200 rods of
    /// [`slope_test_rod`], 2,000 points on [T_MARGIN, 1] each: the margin within 2 % of
    /// max(|dense min|, 1e-3) of the dense minimum (measured on 6,000 rods: at most 0.74 % above
    /// it, a dip the grid leaves between samples, and 0.13 % below, the small-angle path's
    /// 1e-4 truncation on near-relaxed rods; the value-only scan before slopes was up to 5.1 %
    /// above), and the same verdict wherever the dense minimum is clear of zero (1e-9).
    #[test]
    fn margin_matches_a_dense_scan() {
        let mut r = SplitMix64::new(99);
        let (mut compared, mut worst) = (0usize, 0.0f64);
        for i in 0..1200 {
            let a = slope_test_rod(&mut r, i);
            let Ok(rod) = crate::planar::series_dual(&a, true) else {
                continue;
            };
            let mut dense = f64::INFINITY;
            for k in 0..=2000 {
                let t = T_MARGIN + (1.0 - T_MARGIN) * f64::from(k) / 2000.0;
                let (v, e) = normalised_det_series(&rod, a[0], a[2], t);
                assert!(
                    e <= 1e-6 * v.abs().max(1.0),
                    "a = {a:?}: series g at {t} ± {e}"
                );
                dense = dense.min(v);
            }
            let report = crate::planar::stability(&a).expect("a rod of the box");
            let dev = (report.margin - dense).abs() / dense.abs().max(1e-3);
            assert!(
                dev <= 0.02,
                "a = {a:?}: margin {} against {dense}",
                report.margin
            );
            if dense.abs() > 1e-9 && !report.uncertain {
                assert_eq!(
                    report.stable,
                    dense > 0.0,
                    "a = {a:?}: {report:?}, dense {dense}"
                );
            }
            worst = worst.max(dev);
            compared += 1;
        }
        assert!(compared >= 1150, "{compared}");
        eprintln!("{compared} margins against the dense scan, worst {worst:.2e}");
    }

    /// g′(t) of [`normalised_det_sloped`] (d det J/dt = det[J_x; J_y; ∂κ/∂a]) against central
    /// differences of g on 2,000 rods of cases I and II at 12 times each: within 1e-5 of
    /// |g′| + |g|/λ (λ the rod's wavelength). The difference's own error is ~h²|g‴| + e/h with
    /// h = 1e-4·λ and g's bound e ≤ 1e-10·max(|g|, 1) where the test compares (~1e-8 and
    /// ~1e-6 of that scale); a wrong formula is off by O(1).
    #[test]
    fn slope_is_the_derivative_of_g() {
        let mut r = SplitMix64::new(20_261_126);
        let (mut compared, mut worst) = ([0usize; 3], 0.0f64);
        for i in 0..2000 {
            let a = slope_test_rod(&mut r, i);
            let Some(c) = crate::planar::seeded_closed(&a) else {
                continue;
            };
            let case = match c.case {
                Case::I => 0,
                Case::II => 1,
                Case::III => 2,
                _ => continue,
            };
            let (a3, a5) = (a[0], a[2]);
            let wl = c.wavelength();
            let h = 1e-4 * wl.min(1.0);
            for k in 1..=12 {
                let t = 0.1 + 0.85 * f64::from(k) / 12.0;
                let (v, e, d) = normalised_det_sloped(&c, a3, a5, t, false);
                let (vp, ep) = normalised_det(&c, a3, a5, t + h, false);
                let (vm, em) = normalised_det(&c, a3, a5, t - h, false);
                if e.max(ep).max(em) > 1e-10 * v.abs().max(1.0) || !d.is_finite() {
                    continue;
                }
                let diff = (vp - vm) / (2.0 * h);
                let scale = d.abs() + v.abs() / wl.min(1.0);
                let dev = (d - diff).abs() / scale;
                assert!(
                    dev <= 1e-5,
                    "a = {a:?}, t = {t}: g′ {d} against {diff} (g {v})"
                );
                worst = worst.max(dev);
                compared[case] += 1;
            }
        }
        // (Case III, λ4 = 0 as computed, is a set of measure zero: no random rod lands there.)
        assert!(compared[0] >= 1000 && compared[1] >= 1000, "{compared:?}");
        eprintln!("slopes compared {compared:?}, worst deviation {worst:.2e}");
    }

    /// The small-angle g₀ against g on the dual-number Taylor series (an independent
    /// computation of the full nonlinear rod, entries accurate to 1e-14 relative): on 6,000
    /// nearly straight rods, 40 points each, |g − g₀| ≤ (C·Θ² + rounding)·max(|g|, 1) with the
    /// constants [`small_angle_report`] uses, and the measured constants far inside them
    /// (truncation ≤ 0.16·Θ² where Θ < 1e-2, rounding ≤ 2.1e-12 where Θ < 1e-8).
    #[test]
    fn small_angle_agrees_with_the_series() {
        let mut r = SplitMix64::new(5);
        let (mut worst_c, mut worst_rounding, mut points) = (0.0f64, 0.0f64, 0);
        for i in 0..6000 {
            let Some(a) = nearly_straight_sample(&mut r, i) else {
                continue;
            };
            let (a3, a4, a5) = (a[0], a[1], a[2]);
            let Ok(rod) = crate::planar::series_dual(&a, true) else {
                continue;
            };
            let theta = small_angle::max_angle(a3, a4, a5);
            if theta > 1e-2 {
                continue;
            }
            for k in 1..=40 {
                let t = f64::from(k) / 40.0;
                let (g, e) = normalised_det_series(&rod, a3, a5, t);
                if e.is_nan() || e > 1e-9 * g.abs() {
                    continue;
                }
                let dev =
                    (g - small_angle::normalised_det(a3, a4, a5, t).0).abs() / g.abs().max(1.0);
                let bound = SMALL_ANGLE_TRUNCATION_C * theta * theta + SMALL_ANGLE_ROUNDING;
                assert!(
                    dev <= bound,
                    "{a:?} t = {t}: |g − g₀| = {dev:e} > {bound:e}"
                );
                points += 1;
                if theta < 1e-8 {
                    worst_rounding = worst_rounding.max(dev);
                } else if theta > 1e-5 {
                    worst_c = worst_c.max(dev / (theta * theta));
                }
            }
        }
        assert!(points > 100_000, "{points}");
        assert!(worst_c <= 0.2 && worst_c > 0.01, "{worst_c}");
        assert!(worst_rounding <= 5e-12, "{worst_rounding}");
    }

    /// [`small_angle_prefix`] against the dual-number series on the part [0, t] of 3,000 rods
    /// (a4 log-scale 1 to 1e4 of either sign, a3 and a5 log-scale 1e-10..1 with exact zeros;
    /// √|a4|·t up to [`SMALL_ANGLE_PREFIX_REACH`], where the series' rounding, grown like
    /// e^{√|a4| t}, is bounded): wherever the series' g is accurate to 1e-9, |g − g₀| is within
    /// the prefix's bound, whose Θ(t)² constant is measured as for the whole rod.
    #[test]
    fn small_angle_prefix_agrees_with_the_series() {
        let mut r = SplitMix64::new(12);
        let (mut worst_c, mut points, mut taken) = (0.0f64, 0usize, 0usize);
        for i in 0..3000 {
            let a3 = if i % 9 == 0 {
                0.0
            } else {
                r.signed_pow10(-10.0, 0.0)
            };
            let a5 = if i % 7 == 0 && a3 != 0.0 {
                0.0
            } else {
                r.signed_pow10(-10.0, 0.0)
            };
            let a4 = r.signed_pow10(0.0, 4.0);
            let a = PlanarParams::new(a3, a4, a5);
            let t_end = (SMALL_ANGLE_PREFIX_REACH / a4.abs().sqrt()).min(1.0);
            let Ok(rod) = TaylorRod::new_to(
                Dual3::variable(a3, 0),
                Dual3::variable(a4, 1),
                Dual3::variable(a5, 2),
                t_end,
                crate::planar::SERIES_MAX_STEPS,
                true,
            ) else {
                continue;
            };
            for k in 1..=30 {
                let t = t_end * f64::from(k) / 30.0;
                let amplified = 10.0 * f64::EPSILON * (a4.abs().sqrt() * t).exp();
                let (g, e) = normalised_det_series_amplified(&rod, a3, a5, t, amplified);
                if e.is_nan() || e > 1e-9 * g.abs().max(1.0) {
                    continue;
                }
                let Some((g0, bound, _)) = small_angle_prefix(&a, t) else {
                    continue;
                };
                let dev = (g - g0).abs();
                assert!(
                    dev <= bound + e,
                    "{a:?} t = {t}: |g − g₀| = {dev:e} > {bound:e}"
                );
                points += 1;
                if bound <= CLOSED_G_ERROR * g0.abs().max(1.0) {
                    taken += 1;
                }
                let theta = small_angle::max_angle_to(a3, a4, a5, t);
                if theta > 1e-5 && theta < 0.1 {
                    let (_, rounding) = small_angle::normalised_det(a3, a4, a5, t);
                    let c = (dev - rounding).max(0.0) / (theta * theta * g.abs().max(1.0));
                    worst_c = worst_c.max(c);
                }
            }
        }
        eprintln!("{points} points, {taken} within the scan's 1e-3, worst C {worst_c:.3}");
        assert!(points > 20_000 && taken > 10_000, "{points} {taken}");
        assert!(worst_c <= 0.2 && worst_c > 0.01, "{worst_c}");
    }

    /// The norm-wise scan's second pass, on the closed form in double-double, against the
    /// double-double series scan, out of the references' sample: 500 rods of issue 23's
    /// tiny-bending family (a4 ±1e2..1e4, a3 and a5 ±1e-14..1e-6 with exact zeros, √‖F‖ ≤ 100)
    /// that take the norm-wise scan (the pass itself runs where the f64 one is uncertain; run
    /// here on all of them). Wherever both verdicts are certain they agree (and all 110 of the
    /// rods that took it before the f64 pass knew where conjugate points cannot be agree with
    /// their 320-bit verdicts in tests/data/stability_truth_extended_pass.jsonl,
    /// `extended_pass_verdicts_match_the_reference`).
    #[test]
    fn extended_pass_agrees_with_the_series_scan() {
        let mut r = SplitMix64::new(29);
        let (mut used, mut agree, mut only_extended) = (0usize, 0usize, 0usize);
        for i in 0..500 {
            let a3 = if i % 5 == 0 {
                0.0
            } else {
                r.signed_pow10(-14.0, -6.0)
            };
            let a5 = if i % 7 == 0 {
                0.0
            } else {
                r.signed_pow10(-14.0, -6.0)
            };
            let a = PlanarParams::new(a3, r.signed_pow10(2.0, 4.0), a5);
            let Some(c) = super::super::seeded_closed(&a) else {
                continue;
            };
            if !c.needs_precise_series() || small_angle_report(&a).expect("finite").is_some() {
                continue;
            }
            let Some(dd) = super::super::extended::seeded_within_reach(&a) else {
                continue;
            };
            used += 1;
            let extended = closed_scan(&c, &a, true, Some(&dd)).expect("finite");
            let Ok(series) = series_after_small_angle(&a, None, Some(c.wavelength()), Some(&c))
            else {
                continue;
            };
            match (extended.uncertain, series.uncertain) {
                (false, false) => {
                    assert_eq!(
                        extended.stable, series.stable,
                        "{a:?}: {extended:?} vs {series:?}"
                    );
                    agree += 1;
                }
                (false, true) => only_extended += 1,
                _ => {}
            }
        }
        eprintln!("{used} rods took the second pass: {agree} agree with the series, {only_extended} decided by it alone");
        assert!(agree >= 150, "{used} {agree} {only_extended}");
    }

    /// Under tension a nearly straight rod is stable (the straight rod is, and stability is
    /// open): wherever [`small_angle_report`] answers on tensioned rods up to a4 = 1e4 with
    /// bending down to 1e-300, it says stable with a positive margin. Under a strong tension
    /// g₀'s determinant cancels by e^{2√a4}: without its rounding bound it called
    /// (1e-22, 1433.68, 1e-23) unstable with a certain verdict and margin −2.2e39.
    #[test]
    fn small_angle_never_calls_a_tensioned_rod_unstable() {
        let mut r = SplitMix64::new(8);
        let mut answered = 0;
        let quoted = PlanarParams::new(1e-22, 1433.68, 1e-23);
        let rods = (0..4000).map(|_| {
            let a4 = 10f64.powf(r.range(0.0, 4.0));
            let sigma = 10f64.powf(r.range(-300.0, -3.0));
            PlanarParams::new(sigma * r.range(-1.0, 1.0), a4, sigma * r.range(-1.0, 1.0))
        });
        for a in std::iter::once(quoted).chain(rods) {
            if let Some(s) = small_angle_report(&a).unwrap() {
                answered += 1;
                assert!(s.stable && s.margin > 0.0, "{a:?}: {s:?}");
            }
        }
        assert!(answered > 1000, "{answered}");
    }

    /// Where [`small_angle_report`] answers, it gives the series scan's verdict, first
    /// conjugate point (to 1e-5 + 10× its truncation bound C·Θ²) and margin (to twice that
    /// bound, relative, + 1e-6: both refine the same minimum from slightly different samples;
    /// where the series scan misses a minimum between its samples, the margin is lower and the
    /// series' minimum on 4,000 points matches it: 75 rods with the value-only series scan,
    /// none since it has slopes too), on the sample above
    /// (tension up to a4 = 289, where the f64 series is the reference); and it answers most of
    /// it.
    #[test]
    fn small_angle_report_matches_the_series_scan() {
        let mut r = SplitMix64::new(6);
        let (mut n, mut answered, mut unstable, mut deeper) = (0, 0, 0, 0);
        for i in 0..3000 {
            let Some(a) = nearly_straight_sample(&mut r, i) else {
                continue;
            };
            // The f64 series is the reference up to √a4 = 17 under tension (beyond, its
            // rounding grows like ε·e^{√a4}).
            if a[1] > 289.0 {
                continue;
            }
            let Ok(rod) = crate::planar::series_dual(&a, true) else {
                continue;
            };
            n += 1;
            let Some(fast) = small_angle_report(&a).unwrap() else {
                continue;
            };
            answered += 1;
            let wavelength = std::f64::consts::TAU / crate::planar::curvature_scale(&a);
            let spacing = (0.25 * wavelength).clamp(1e-3, SERIES_SPACING);
            let slow = scan_series(&rod, (a[0], a[2]), spacing, None).unwrap();
            assert!(!slow.uncertain, "{a:?}: {slow:?}");
            assert_eq!(fast.stable, slow.stable, "{a:?}: {fast:?} vs {slow:?}");
            let theta = small_angle::max_angle(a[0], a[1], a[2]);
            let rel = SMALL_ANGLE_TRUNCATION_C * theta * theta + SMALL_ANGLE_ROUNDING;
            let tol = 2.0 * rel * slow.margin.abs().max(1.0) + 1e-6;
            if (fast.margin - slow.margin).abs() > tol {
                // The small-angle scan's slopes find minima between samples that the
                // value-only series scan misses: the series' dense minimum decides.
                let dense = (0..=4000)
                    .map(|k| T_MARGIN + (1.0 - T_MARGIN) * f64::from(k) / 4000.0)
                    .map(|t| normalised_det_series(&rod, a[0], a[2], t).0)
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    fast.margin < slow.margin && (fast.margin - dense).abs() <= tol,
                    "{a:?}: {fast:?} vs {slow:?}, dense minimum {dense}"
                );
                deeper += 1;
            }
            match (fast.first_conjugate_t, slow.first_conjugate_t) {
                (None, None) => {}
                (Some(f), Some(s)) => {
                    unstable += 1;
                    assert!(
                        (f - s).abs() <= 1e-5 + 10.0 * rel,
                        "{a:?}: {fast:?} vs {slow:?}"
                    )
                }
                _ => panic!("{a:?}: {fast:?} vs {slow:?}"),
            }
        }
        assert!(
            answered * 2 > n && unstable > 50,
            "{answered} of {n}, {unstable} unstable"
        );
        eprintln!("{answered} of {n} answered, {unstable} unstable, {deeper} deeper minima");
    }

    /// A rod of the samples [`scans_never_contradict_the_theorem`] draws from: the box,
    /// log-scale magnitudes with exact zeros, strong force, near-circles and many-looped rods.
    fn theorem_sample(r: &mut SplitMix64, i: usize) -> PlanarParams {
        let zero_or = |r: &mut SplitMix64, v: f64| if r.uniform() < 0.1 { 0.0 } else { v };
        let a = match i % 5 {
            0 => [
                r.range(-10.0, 10.0),
                r.range(-100.0, 100.0),
                r.range(-100.0, 100.0),
            ],
            1 => {
                let a3 = r.signed_pow10(-4.0, 1.5);
                let a4 = r.signed_pow10(-4.0, 2.5);
                let a5 = r.signed_pow10(-4.0, 2.5);
                [zero_or(r, a3), zero_or(r, a4), zero_or(r, a5)]
            }
            2 => {
                let a3 = r.signed_pow10(-10.0, 1.0);
                let a5 = r.signed_pow10(-10.0, 1.0);
                [zero_or(r, a3), r.signed_pow10(2.0, 4.0), zero_or(r, a5)]
            }
            3 => [
                r.signed_pow10(-0.5, 1.3),
                r.signed_pow10(-12.0, -2.0),
                r.signed_pow10(-12.0, -2.0),
            ],
            _ => [
                r.signed_pow10(0.5, 1.6),
                r.signed_pow10(0.0, 2.5),
                r.signed_pow10(0.0, 2.5),
            ],
        };
        PlanarParams::new(a[0], a[1], a[2])
    }

    /// Sachkov's theorem ([`Closed::conjugate_free_until`], [`Closed::conjugate_by`]) against
    /// the reference integration (DOP853 at rtol 1e-12 with its variational equations, det J
    /// on a grid of 2,000 points; it knows nothing of elliptic functions or the theorem) on
    /// 4,000 rods of five families: every first conjugate point the reference finds lies
    /// between t_free and t_conj (within its grid), no rod the theorem calls free of them is
    /// unstable there, every rod with t_conj ≤ 1 is unstable where the reference decides, and
    /// where the reference's margin is clear `stability` gives its verdict.
    #[test]
    fn conjugate_points_respect_the_theorem() {
        let mut r = SplitMix64::new(2011);
        let (mut free, mut certain, mut unstable_i) = (0, 0, 0);
        let (mut closest, mut farthest) = (f64::INFINITY, 0.0f64);
        for i in 0..4000 {
            let a = theorem_sample(&mut r, i);
            // Under a tension beyond ~150 the reference's rounding grows like e^{√a4} past its
            // tolerance: the 320-bit references (tests/separatrix_truth.rs) cover those rods.
            if a[1] > 150.0 {
                continue;
            }
            let (Ok(reference), Some(c)) = (
                crate::ode::planar_reference::stability(&a),
                Closed::<f64>::new(a[0], a[1], a[2]),
            ) else {
                continue;
            };
            let (t_free, t_conj) = (c.conjugate_free_until(), c.conjugate_by());
            free += usize::from(t_free > 1.0);
            certain += usize::from(t_conj <= 1.0);
            if t_conj <= 1.0 && !reference.uncertain {
                assert!(
                    !reference.stable,
                    "{a:?}: conjugate point by {t_conj}, {reference:?}"
                );
            }
            if let (Some(tc), false) = (reference.first_conjugate_t, reference.stable) {
                assert!(
                    tc >= t_free - 1.0 / 2000.0,
                    "{a:?} ({:?}): the reference's conjugate point {tc} < t_free {t_free}",
                    c.case
                );
                assert!(
                    tc <= t_conj + 1.0 / 2000.0,
                    "{a:?} ({:?}): the reference's conjugate point {tc} > t_conj {t_conj}",
                    c.case
                );
                if c.case == Case::I {
                    unstable_i += 1;
                    closest = closest.min(tc / t_free);
                    farthest = farthest.max(tc / t_conj);
                }
            }
            if reference.margin.abs() > 1e-3 && !reference.uncertain {
                let ours = crate::planar::stability(&a).expect("answered");
                assert_eq!(
                    ours.stable, reference.stable,
                    "{a:?}: {ours:?} / {reference:?}"
                );
            }
        }
        assert!(
            free > 1000 && certain > 300 && unstable_i > 300,
            "{free} free, {certain} with one by t = 1, {unstable_i} unstable"
        );
        eprintln!("{free} free of conjugate points, {certain} with one by t = 1, {unstable_i} unstable in case I, conjugate points ≥ {closest:.4}× t_free and ≤ {farthest:.6}× t_conj");
    }

    /// `planar::stability_verdict` gives the full test's verdict on every rod of
    /// [`theorem_sample`]'s five families (12,000 rods: the box, log-scale with exact zeros,
    /// strong force, near-circles, many loops) and of the nearly straight sample (2,000,
    /// a4 = 0 and a3 or a5 = 0 among them), and where it decides without the full test
    /// ([`verdict_of`]: a theorem, g(1), or the scan from the theorem's t_free) it
    /// agrees with the reference integration (DOP853 at rtol 1e-12, det J on 2,000 points;
    /// a4 ≤ 150 as in [`conjugate_points_respect_the_theorem`]; every eighth such rod, and
    /// every second one the upper bound decides) wherever the reference's own verdict is
    /// certain (its margins on looped rods are often ~1e-5, so no threshold on them). Each of
    /// the four shortcuts must be exercised.
    #[test]
    fn verdict_alone_agrees_with_the_full_test_and_the_reference() {
        let mut r = SplitMix64::new(4242);
        let (mut by_theorem, mut by_upper, mut by_end, mut by_scan) = (0, 0, 0, 0);
        let mut checked = 0;
        for i in 0..14_000 {
            let a = if i < 12_000 {
                theorem_sample(&mut r, i)
            } else {
                match crate::planar::small_angle::tests::nearly_straight_sample(&mut r, i) {
                    Some(a) => a,
                    None => continue,
                }
            };
            let full = crate::planar::stability(&a).map(|s| s.verdict());
            let alone = crate::planar::stability_verdict(&a);
            assert_eq!(alone, full, "{a:?}");
            let Some(c) = crate::planar::seeded_closed(&a) else {
                continue;
            };
            let shortcut = verdict_of(&c, &a).expect("finite");
            let upper = c.conjugate_certain();
            let by_the_end = || plain_closed_scan(&c, &a) && unstable_at_the_end(&c, &a);
            match (c.theorem_verdict(), shortcut) {
                (Some(StabilityVerdict::Stable), _) => by_theorem += 1,
                (Some(_), _) => by_upper += 1,
                (None, Some(_)) if by_the_end() => by_end += 1,
                (None, Some(_)) => by_scan += 1,
                (None, None) => continue,
            }
            if !(i % 8 == 0 || upper && i % 2 == 0) || a[1] > 150.0 {
                continue;
            }
            let reference = crate::ode::planar_reference::stability(&a).expect("reference");
            if !reference.uncertain {
                checked += 1;
                assert_eq!(shortcut, Some(reference.verdict()), "{a:?}: {reference:?}");
            }
        }
        let counts = format!(
            "{by_theorem} stable and {by_upper} unstable by a theorem, {by_end} unstable by \
             g(1), {by_scan} by the scan from t_free, {checked} against the reference"
        );
        assert!(
            by_theorem > 2000
                && by_upper > 1000
                && by_end > 300
                && by_scan > 1000
                && checked > 1500,
            "{counts}"
        );
        eprintln!("{counts}");
    }

    /// The f64 closed form's g(t) within its bound ([`normalised_det`], as the plain scan uses
    /// it) against the double-double closed form (within its own bound), at t = 0.05, 0.075,
    /// …, 1 wherever the scan accepts the sample (bound ≤ [`CLOSED_G_ERROR`]·max(|g|, 1)), on
    /// the rods the plain scan takes: 3,000 near-circles (ρ 0.3..2 of either sign, F
    /// 1e-12..1e-2: m from 1e-6 to 1e-2 in case II) and 3,000 of [`theorem_sample`]'s five
    /// families. Asserted in case I and on near-circles (case II, m < [`COLUMN_WISE_MAX_M`],
    /// column-wise); case II above keeps the entry-wise bound, whose excesses are only counted
    /// here ([`COLUMN_WISE_MAX_M`] says why).
    #[test]
    fn closed_g_within_its_bound() {
        let mut r = SplitMix64::new(77);
        // Per regime (case I, near-circles, case II above): samples, worst error over bound,
        // and samples beyond their bound.
        let mut seen = [(0usize, 0.0f64, 0usize); 3];
        for i in 0..6000 {
            let a = if i < 3000 {
                let rho = r.range(0.3, 2.0) * if i % 2 == 0 { 1.0 } else { -1.0 };
                let (f, psi) = (10f64.powf(r.range(-12.0, -2.0)), r.range(-3.1, 3.1));
                PlanarParams::new(rho, f * psi.cos(), f * psi.sin())
            } else {
                theorem_sample(&mut r, i)
            };
            let Some(c) = crate::planar::seeded_closed(&a) else {
                continue;
            };
            if !plain_closed_scan(&c, &a) {
                continue;
            }
            let Some(dd) = crate::planar::extended::seeded_within_reach(&a) else {
                continue;
            };
            let regime = match c.case {
                Case::I => 0,
                _ if c.m.v < COLUMN_WISE_MAX_M => 1,
                _ => 2,
            };
            for k in 2..=40 {
                let t = f64::from(k) / 40.0;
                let (g, bound) = normalised_det(&c, a[0], a[2], t, false);
                if bound > CLOSED_G_ERROR * g.abs().max(1.0) {
                    continue;
                }
                let (g_dd, bound_dd) = normalised_det_extended(&dd, a[0], a[2], t);
                let excess = (g - g_dd).abs() - bound_dd;
                assert!(
                    regime == 2 || excess <= bound,
                    "{a:?} ({:?}, m {:e}) at t = {t}: g {g} against {g_dd}, bound {bound:e}",
                    c.case,
                    c.m.v
                );
                let s = &mut seen[regime];
                s.0 += 1;
                s.1 = s.1.max(excess / bound);
                s.2 += usize::from(excess > bound);
            }
        }
        assert!(seen.iter().all(|s| s.0 > 5_000), "{seen:?}");
        eprintln!("(samples, worst error over bound, beyond it): case I, near-circles, case II above: {seen:?}");
    }

    /// Nearly straight rods under compression (a4 from −0.1 to −1e4, log-scale a3 and a5, a5
    /// sometimes 0): where [`small_m_scan`] answers, its verdict is the whole-rod series
    /// scan's, the same first conjugate point (to 1e-4: the closed form's g differs by ~1e-6
    /// there) and a margin within 5 % (measured 1.8 %:
    /// the two scans refine the same minimum from different samples). Margins here are
    /// 1e-5..1e-3, so that is far inside the 1e-3 absolute the oracle tests allow.
    #[test]
    fn small_m_scan_agrees_with_the_series_scan() {
        let mut r = SplitMix64::new(11);
        let (mut n, mut fast) = (0, 0);
        for i in 0..1500 {
            let a3 = r.signed_pow10(-8.0, 0.5);
            let a4 = -10f64.powf(r.range(-1.0, 4.0));
            let a5 = if i % 9 == 0 {
                0.0
            } else {
                r.signed_pow10(-8.0, 1.0)
            };
            let a = PlanarParams::new(a3, a4, a5);
            let Some(c) = crate::planar::seeded_closed(&a) else {
                continue;
            };
            if !c.det_needs_series() || c.needs_precise_series() {
                continue;
            }
            n += 1;
            let Some(f) = small_m_scan(&c, &a).expect("no error") else {
                continue;
            };
            fast += 1;
            let s = whole_series_scan(&a, None, Some(c.wavelength()), None).expect("series");
            assert!(!s.uncertain && !f.uncertain, "{a:?}: {f:?} vs {s:?}");
            let same_first = match (f.first_conjugate_t, s.first_conjugate_t) {
                (Some(x), Some(y)) => (x - y).abs() < 1e-4,
                (None, None) => true,
                _ => false,
            };
            let margin = (f.margin - s.margin).abs() <= 0.05 * s.margin.abs();
            assert!(
                f.stable == s.stable && same_first && margin,
                "{a:?}: {f:?} vs {s:?}"
            );
        }
        assert!(
            n >= 500 && fast * 5 >= n,
            "{fast} of {n} by the small-m scan"
        );
    }

    /// The scan's short series ([`CoarseDual3`], truncated at 1e-10 per step) against the
    /// full-accuracy dual-number series over the short series' reach (t up to
    /// [`SHORT_SERIES_REACH`]/ρ), on 3,000 rods the way users give them: half tensions 10..1e4
    /// with a3, a5 log-scale 1e-6..1 (near the separatrix, where the norm-wise scan uses it),
    /// half a4 log-scale 1e-2..1e4 of either sign with a3, a5 log-scale 1e-6..10. Every entry's
    /// error is within its bound [`COARSE_ENTRY_REL`]·|J_ij| + [`COARSE_AMPLIFIED`]·e^{√‖F‖ t}·‖J‖
    /// (measured ≤ 0.09 of it, asserted ≤ 0.1 so that a looser series shows).
    #[test]
    fn coarse_short_series_within_its_bound() {
        let mut r = SplitMix64::new(9);
        let (mut worst, mut rods) = (0.0f64, 0);
        for i in 0..3000 {
            let a = if i % 2 == 0 {
                PlanarParams::new(
                    r.signed_pow10(-6.0, 0.0),
                    10f64.powf(r.range(1.0, 4.0)),
                    r.signed_pow10(-6.0, 0.0),
                )
            } else {
                PlanarParams::new(
                    r.signed_pow10(-6.0, 1.0),
                    r.signed_pow10(-2.0, 4.0),
                    r.signed_pow10(-6.0, 1.0),
                )
            };
            let root_f = a[1].hypot(a[2]).sqrt();
            let reach = (SHORT_SERIES_REACH / root_f.max(a[0].abs())).min(1.0);
            let seed = |i| Dual3::variable(a[i], i);
            let Ok(full) = TaylorRod::new_to(seed(0), seed(1), seed(2), reach, 1000, true) else {
                continue;
            };
            let coarse = TaylorRod::new_to(
                CoarseDual3(seed(0)),
                CoarseDual3(seed(1)),
                CoarseDual3(seed(2)),
                reach,
                1000,
                true,
            )
            .expect("the coarse series where the full one exists");
            rods += 1;
            for k in 1..=10 {
                let t = reach * f64::from(k) / 10.0;
                let jf = scaled_series_jacobian(&full, a[0], a[2], t).expect("within reach");
                let jc = scaled_series_jacobian(&coarse, a[0], a[2], t).expect("within reach");
                let norm = jf.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
                let spread = COARSE_AMPLIFIED * (root_f * t).exp() * norm;
                for (rf, rc) in jf.iter().zip(&jc) {
                    for (f, c) in rf.iter().zip(rc) {
                        worst = worst.max((c - f).abs() / (COARSE_ENTRY_REL * f.abs() + spread));
                    }
                }
            }
        }
        assert!(rods > 2900, "{rods}");
        assert!(worst <= 0.1, "{worst}");
    }
}
