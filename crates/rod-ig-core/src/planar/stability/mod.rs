//! Fast stability test on the closed form (docs/math.md §5).

use crate::conjugate::undecided as straight_report;
use crate::{StabilityReport, StabilityVerdict};

mod closed_g;
mod closed_scan;
mod lattice_scan;
mod series;
mod small_angle_scan;
#[cfg(test)]
mod tests;

pub(crate) use closed_scan::{
    closed_report, precise_scan, series_report_after_closed, stability_of, stability_of_with,
    verdict_of,
};
pub(crate) use lattice_scan::lattice_report;
pub(crate) use series::{series_after_small_angle, stability_of_dense_series};
pub(crate) use small_angle_scan::small_angle_report;

/// Below this t the closed-form det J is dominated by rounding; it is positive there by its
/// leading term (docs/math.md §5).
const T_MIN: f64 = crate::STABILITY_T_MIN;
/// Smallest t entering the margin `det_min` ([`crate::STABILITY_MARGIN_T_MIN`]).
const T_MARGIN: f64 = crate::STABILITY_MARGIN_T_MIN;
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

/// Largest √‖F‖ for which the stability scan runs on the double-double series near the
/// separatrix (the steps scale like √‖F‖: ≈ 20 ms at √‖F‖ = 100, the top of issue 9's
/// strong-force family a4 ≤ 1e4). Beyond [`crate::planar::closed::SERIES_DD_MAX_ROOT_F`] its g(t) is not certified
/// to the scan's 1e-3, but the sign is robust: its verdicts matched the rigorous 320-bit
/// reference on all 720 separatrix rods of scripts/references/gen_separatrix_truth.py's samples (√‖F‖ up
/// to 100), where its tips and J were off by up to 0.25 and 100 %.
pub(crate) const STABILITY_DD_MAX_ROOT_F: f64 = 120.0;

/// The sample times where the planar normalisation D0(t) = t⁹(a3²/8640 + a5²t²/33600) changes
/// regime, at t* = √(33600/8640)|a3/a5| (0.7 t*, t*, 1.4 t*; NaN without a5), where g often has
/// a narrow dip: the scan samples them for the margin ([`crate::conjugate::scan`]'s `around`).
/// The straight rod a3 = a5 = 0 (J's x row vanishes: det J ≡ 0) is
/// [`crate::conjugate::undecided`].
#[inline]
fn around(a3: f64, a5: f64) -> [f64; 3] {
    let ts_star = if a5 != 0.0 {
        (33600.0f64 / 8640.0).sqrt() * (a3 / a5).abs()
    } else {
        f64::NAN
    };
    [ts_star * 0.7, ts_star, ts_star * 1.4]
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
