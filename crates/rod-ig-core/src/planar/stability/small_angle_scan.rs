//! The stability of nearly straight rods by the small-angle expansion's det J (its own scan
//! spacing, truncation and rounding bounds).

use super::around;
use super::series::certified_verdict;
use super::SERIES_T_MIN;
use crate::conjugate::{scan, Probe};
use crate::planar::small_angle;
use crate::{PlanarParams, RodError, StabilityReport};

/// Grid spacing of the small-angle scan ([`small_angle_report`]) in periods 2π/max(σ, √|a4|),
/// and its cap. Its samples carry g₀′ ([`small_angle::normalised_det_sloped`]): on 16,280
/// nearly straight rods against g₀ on 8,000 points each, the margin is above the dense
/// minimum by more than 1e-6 (relative to max(|min|, 1e-3)) on 9 rods, by 3e-5 at worst,
/// where the value-only scan on a quarter period capped at 0.1 was above on 1,476, by 12 %
/// at worst (a dip between samples); at 0.75 period, 18 %; with a cap of 0.3, 20 % (two
/// extrema 0.12 apart in one interval under a compression of 26).
pub(super) const SMALL_ANGLE_SPACING: f64 = 0.5;
/// See [`SMALL_ANGLE_SPACING`].
pub(super) const SMALL_ANGLE_MAX_SPACING: f64 = 0.15;

/// Largest truncation bound Θ² of the small-angle g₀ (relative to max(|g|, 1)) for which
/// [`small_angle_report`] answers: margins to 1e-4 relative (Θ ≤ 1e-2, where its constant was
/// measured), where the closed-form scan accepts g to 1e-3.
pub(super) const SMALL_ANGLE_MAX_TRUNCATION: f64 = 1e-4;
/// Constant of the small-angle truncation bound C·Θ²·max(|g|, 1), Θ the largest bending
/// angle ([`small_angle::max_angle`]): measured ≤ 0.16 against the series' g on 6,000 rods
/// (a4 from 1e-6 to 1e4 and 0, either sign; a3, a5 log-scale 1e-20..0.1 and 0;
/// `small_angle_agrees_with_the_series`), ×6.
pub(super) const SMALL_ANGLE_TRUNCATION_C: f64 = 1.0;
/// Rounding of g₀ relative to max(|g₀|, 1) beyond its first-order bound (the normalisation,
/// the division): measured ≤ 2.1e-12 in all (with the series' own, where Θ < 1e-8), ×50.
pub(super) const SMALL_ANGLE_ROUNDING: f64 = 1e-10;
/// Largest first-order rounding bound of g₀ at t = 1, relative to max(|g₀|, 1), for which
/// [`small_angle_report`] answers: under a strong tension det J of the linearised rod is a
/// difference of terms e^{2√a4} times larger than itself (rounding grows with t, so t = 1 is
/// the worst point).
pub(super) const SMALL_ANGLE_MAX_ROUNDING: f64 = 1e-9;

/// Largest √|a4|·t at which [`small_angle_prefix`] stands in for the closed form (the reach of
/// its measurement, `small_angle_prefix_agrees_with_the_series`).
pub(super) const SMALL_ANGLE_PREFIX_REACH: f64 = 12.0;

/// g(t) of a rod whose part [0, t] is nearly straight, from the small-angle limit g₀ (as
/// [`small_angle_report`], with the largest angle Θ(t) of that part: a rod of length t), and
/// its bound (C·Θ(t)² + rounding)·max(|g₀|, 1) plus g₀'s own rounding, and g₀′ (a slope for
/// the scan, [`small_angle::normalised_det_sloped`]). It replaces the short
/// series near the base of a rod bent little there under a strong force, where the closed
/// form's x row is swamped (~65k instructions of series per stability test under
/// |a4| 1e2..1e4). None beyond [`SMALL_ANGLE_PREFIX_REACH`] or for zero/denormal bending.
pub(super) fn small_angle_prefix(a: &PlanarParams, t: f64) -> Option<(f64, f64, f64)> {
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

/// Stability of a nearly straight rod from the small-angle limit g₀ of g (docs/math.md §5 on the
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
    let s = scan(&sloped, SERIES_T_MIN, spacing, around(a3, a5), &[])?;
    let bounded = |t: f64| {
        let (v, rounding) = small_angle::normalised_det(a3, a4, a5, t);
        let bound = (truncation + SMALL_ANGLE_ROUNDING) * v.abs().max(1.0) + rounding;
        (v, bound)
    };
    let report = certified_verdict(s, &bounded, (SERIES_T_MIN, spacing, a3, a5));
    Ok((!report.uncertain).then_some(report))
}
