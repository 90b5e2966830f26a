//! Stability of a rod in the separatrix limit ([`crate::planar::soliton`]): the theorems
//! where they decide (a rotation is non-inflectional: no conjugate point; an inflectional rod
//! has none before its first inflection point and one by its third; docs/math.md §5), with
//! the margin from a scan of det J(t) on the lattice's own J, normalised in log form (its
//! entries reach 1e300 where the normalisation a3²t⁹/8640 underflows); else the closed form's
//! scans (the lattice's det J cancels by its solitons, beyond a bound it could prove).

use super::around;
use super::series::certified_verdict;
use super::small_angle_scan::small_angle_report;
use super::{with_theorem, SERIES_SPACING, T_MARGIN};
use crate::conjugate::{scan, value_only};
use crate::planar::soliton::Lattice;
use crate::scalar::Dual3;
use crate::types::det_and_error;
use crate::{PlanarParams, RodError, StabilityReport, StabilityVerdict};

/// Relative error of the lattice's J entries: its neglected terms O(ρ²) ≤ 1e-14 and the
/// rounding of a few dozen operations (measured ≤ 4e-13 against the exact pendulum,
/// `tests/separatrix_limit.rs`), ×10.
const LATTICE_ENTRY_REL: f64 = 5e-12;

/// The scan's spacing in soliton widths 1/√R.
const LATTICE_SPACING_WIDTHS: f64 = 3.0;

/// Largest ln |g|: beyond, g is capped (its sign and relative error are kept; a margin of
/// e^700 says as much as a larger one).
const MAX_LN_FACTOR: f64 = 700.0;

/// The stability report of the lattice rod a (`None` outside the lattice's domain).
pub(crate) fn lattice_report(a: &PlanarParams) -> Option<Result<StabilityReport, RodError>> {
    let lattice = Lattice::new(
        Dual3::variable(a[0], 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a[2], 2),
    )?;
    Some(report(&lattice, a))
}

fn report(lattice: &Lattice<Dual3>, a: &PlanarParams) -> Result<StabilityReport, RodError> {
    let (extra, n_extra) = lattice.features();
    // Nearly straight rods (no soliton on the rod): the expansion's certified verdict, as
    // everywhere else. A soliton on the rod bends it by 2π: the expansion cannot apply.
    if n_extra == 0 {
        if let Some(r) = small_angle_report(a)? {
            return Ok(r);
        }
    }
    let (a3, a5) = (a[0], a[2]);
    let inflections = lattice.inflections();
    let theorem = if inflections == 0 {
        Some(StabilityVerdict::Stable)
    } else if inflections >= 3 {
        Some(StabilityVerdict::Unstable)
    } else {
        None
    };
    let g = |t: f64| normalised_det(lattice, a3, a5, t);
    // Where the theorem decides, the scan is asked for the margin alone: samples whose sign
    // is within their bound (det J cancels by the solitons) are dropped rather than read as a
    // sign change. Where it does not, they stay, and the verdict is as certain as they are.
    let probe = |t: f64| {
        let (v, e) = g(t);
        // NaN bounds count as unsure.
        let sure = v.abs() > e;
        if theorem.is_some() && !sure {
            f64::NAN
        } else {
            v
        }
    };
    // g varies on the solitons' width 1/√R: sample them, and the inflection points, as
    // extra times.
    let root_r = a[1].hypot(a[2]).sqrt();
    // g grows like e^{2√R t} away from the solitons, which are sampled by their centres: a
    // grid of a few soliton widths finds the margin's minima between them.
    let spacing = (LATTICE_SPACING_WIDTHS / root_r).clamp(0.02, SERIES_SPACING);
    let s = scan(
        &value_only(probe),
        T_MARGIN,
        spacing,
        around(a3, a5),
        &extra[..n_extra],
    )?;
    let report = certified_verdict(s, &g, (T_MARGIN, spacing, a3, a5));
    if theorem.is_some() {
        return Ok(with_theorem(report, || theorem));
    }
    // Undecided by the theorems: the lattice's det J cancels by its solitons (its bound is
    // not proven there), so the closed form's scans decide, as before the lattice; where they
    // refuse, the verdict is uncertain.
    Ok(
        crate::planar::dispatch::stability_from_closed_form(a).unwrap_or(StabilityReport {
            stable: false,
            first_conjugate_t: None,
            uncertain: true,
            ..report
        }),
    )
}

/// g(t) = det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) and its error bound: J's columns scaled to
/// unit size, the scales and the normalisation applied as one logarithm.
fn normalised_det(lattice: &Lattice<Dual3>, a3: f64, a5: f64, t: f64) -> (f64, f64) {
    let p = lattice.pose(t);
    let mut j = [[0.0; 3]; 3];
    for (row, v) in j.iter_mut().zip(p.iter()) {
        *row = v.g;
    }
    let mut ln_factor = 0.0;
    for c in 0..3 {
        let s = j.iter().map(|r| r[c].abs()).fold(0.0, f64::max);
        if !(s > 0.0 && s.is_finite()) {
            return (f64::NAN, f64::NAN);
        }
        for r in j.iter_mut() {
            r[c] /= s;
        }
        ln_factor += s.ln();
    }
    let m = a3.abs().max(a5.abs());
    let (u3, u5) = (a3 / m, a5 / m);
    let ln_norm = 9.0 * t.ln() + 2.0 * m.ln() + (u3 * u3 / 8640.0 + u5 * u5 * t * t / 33600.0).ln();
    let (det, err) = det_and_error(&j, LATTICE_ENTRY_REL, 0.0);
    if det == 0.0 {
        return (0.0, err * (ln_factor - ln_norm).min(MAX_LN_FACTOR).exp());
    }
    // The scaled det may be tiny where its factor is huge (a barely bent stretch of the rod):
    // their product is taken in logs, and only the product capped.
    let g_abs = (det.abs().ln() + ln_factor - ln_norm)
        .min(MAX_LN_FACTOR)
        .exp();
    (det.signum() * g_abs, g_abs * err / det.abs())
}
