//! The elastic energy ½∫₀¹κ² of a rod whose closed form is built (docs/math.md §1): the
//! identity λ2/2 − a4 x(1) − a5 y(1) where its error bound allows, the Jacobi ζ form where its
//! rounding does, else the small-angle expansion or the series. Below the formulations and the
//! shape, which both ask it.

use crate::planar::closed::{overflow, Case, Closed, ENERGY_REL_TOLERANCE, SERIES_DD_MAX_ROOT_F};
use crate::planar::taylor::{series_dd, series_f64, DdStandard, Gradient};
use crate::planar::{extended, small_angle};
use crate::scalar::Real;
use crate::{PlanarParams, PlanarPose, RodError};

/// Largest √‖F‖ for which the f64 series answers the tip, J and energy of an ill-conditioned
/// rod. Its rounding grows like e^{√‖F‖ t} at most, and far less where the rod only leaves the
/// straight equilibrium: against the 320-bit references (the 82 rods of
/// `tests/data/separatrix_truth*.jsonl` near the separatrix with √‖F‖ from 10.7 to 27) its J is
/// within 0.04·ε·e^{√‖F‖} and its tip within a hundredth of that. With ×3, J stays within 1e-9
/// up to √‖F‖ = 17.4, a hundred times inside the 1e-6 asked of J, at ~1/50 of the
/// double-double series' cost.
pub(crate) const SERIES_F64_TIP_MAX_ROOT_F: f64 = 17.0;

/// λ2/2 − a4 x(1) − a5 y(1) with λ2 = a3² + 2a4 (docs/math.md §1).
#[inline]
pub(crate) fn energy_from_tip(a: &PlanarParams, tip: &PlanarPose) -> f64 {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    0.5 * a3 * a3 + a4 - a4 * tip.x - a5 * tip.y
}

/// Rounding of [`Closed::energy_by_zeta_bounded`] in ulps of its terms: measured ≤ 10.1 on
/// 1,160 rods of cases I and II against the 320-bit references (tests/data/separatrix_truth*
/// .jsonl) and the double-double series (`zeta_energy_meets_its_bound`), ×3.
pub(crate) const ZETA_ENERGY_ULPS: f64 = 32.0;

/// The energy by the identity λ2/2 − a4 x − a5 y of docs/math.md §1 where its error bound allows,
/// else None. The identity subtracts a4·x + a5·y from λ2/2, both ≈ ‖F‖ on a nearly straight
/// rod under force, whose energy is orders of magnitude smaller: its error is (|a4| + |a5|)
/// times the pose error ([`Closed::pose_abs_error`]) plus the rounding of the sum.
#[inline]
pub(crate) fn energy_by_identity<T: Real>(
    c: &Closed<T>,
    a: &PlanarParams,
    tip: &PlanarPose,
) -> Result<Option<f64>, RodError> {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let e = energy_from_tip(a, tip);
    let rounding =
        4.0 * f64::EPSILON * (0.5 * a3 * a3 + a4.abs() + (a4 * tip.x).abs() + (a5 * tip.y).abs());
    let bound = (a4.abs() + a5.abs()) * c.pose_abs_error() + rounding;
    if !e.is_finite() {
        return Err(overflow());
    }
    Ok((bound <= ENERGY_REL_TOLERANCE * e.abs()).then_some(e))
}

/// The energy by the identity ([`energy_by_identity`], free) where its error bound allows,
/// else by ζ where its rounding does; None elsewhere (the other formulations' rows).
#[inline]
pub(crate) fn identity_or_zeta<T: Real>(
    c: &Closed<T>,
    a: &PlanarParams,
    tip: &PlanarPose,
) -> Result<Option<f64>, RodError> {
    if let Some(e) = energy_by_identity(c, a, tip)? {
        return Ok(Some(e));
    }
    // Case I below m = ½ (a nearly straight rod under compression, where the identity
    // cancels): ∫cn² in closed form, within 2.2e-11 of the double-double series on 4,000
    // log-scale rods (1.7e-14 on those under compression; tests: see
    // `small_m_compression_closed_form_meets_its_estimate`); near m = 1 its Z/m terms cancel.
    // Elsewhere (case I from m = ½ up to the separatrix, case II) it is taken where its
    // rounding, a few ulps of its terms, is below the tolerance (a rod with some bending
    // under a strong tension: the series there takes 100+ steps).
    if let Some((e, terms)) = c.energy_by_zeta_bounded() {
        let bound = ZETA_ENERGY_ULPS * f64::EPSILON * terms;
        if (c.case == Case::I && c.m.re() < 0.5) || bound <= ENERGY_REL_TOLERANCE * e.abs() {
            return Ok(Some(e));
        }
    }
    Ok(None)
}

/// The energy of a rod whose tip came from the closed form `c`, for the shape and the
/// evaluation near the separatrix, which hold the closed form already: [`identity_or_zeta`],
/// then what the energy rows after the closed form give (the expansion, the double-double
/// identity or series by the separatrix under a strong force, the f64 series).
#[inline]
pub(crate) fn closed_energy<T: Real>(
    c: &Closed<T>,
    a: &PlanarParams,
    tip: &PlanarPose,
) -> Result<f64, RodError> {
    if let Some(e) = identity_or_zeta(c, a, tip)? {
        return Ok(e);
    }
    if let Some(e) = small_angle::checked_energy(a) {
        return Ok(e);
    }
    let root_f = a[1].hypot(a[2]).sqrt();
    let e = if c.needs_precise_series() && root_f > SERIES_F64_TIP_MAX_ROOT_F {
        match extended::energy(a) {
            Some(e) => e,
            None => series_dd::<DdStandard>(a, false, SERIES_DD_MAX_ROOT_F)?
                .energy()
                .value(),
        }
    } else {
        series_f64(a, false)?.energy()
    };
    if e.is_finite() {
        Ok(e)
    } else {
        Err(overflow())
    }
}
