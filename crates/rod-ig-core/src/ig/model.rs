//! The forward maps the solvers use, behind one small seam so that the backend (closed forms
//! of `crate::planar`, or the numerical reference) is switched in one place.
//!
//! Everything here works on the unit rod in the paper's units: Υ(a) = q(1) (paper eq. 2.11 at
//! t = 1), J(1, a) (paper §2.2.3), and the stability test of FINDINGS §5.

use crate::{wrap_angle, PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};
use nalgebra::Vector3;

/// How a solver's iterations evaluate rods near the separatrix, chosen once per start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Precision {
    /// The f64 series: errors up to ε·e^{√‖F‖} (≤ 1e-6 where starts choose it).
    Fast,
    /// The double-double series where the f64 one would lose more than 1e-6: for starts under
    /// strong tension.
    Precise,
}

impl Precision {
    /// The precision iterations from `a0` need (`planar::needs_precise_iterations`).
    pub(crate) fn for_start(a0: &PlanarParams) -> Self {
        if crate::planar::needs_precise_iterations(a0) {
            Self::Precise
        } else {
            Self::Fast
        }
    }
}

/// Υ(a) and J(1, a) (rows x, y, θ; columns a3, a4, a5), for iterations (see [`Precision`] and
/// `planar::tip_and_jacobian_for_iteration`).
#[inline]
pub(crate) fn tip_and_jacobian(
    a: &PlanarParams,
    precision: Precision,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    crate::planar::tip_and_jacobian_for_iteration(a, precision == Precision::Precise)
}

/// Υ(a) and J(1, a) at full accuracy: for the verification of an answer.
#[inline]
pub(crate) fn tip_and_jacobian_precise(
    a: &PlanarParams,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    backend::tip_and_jacobian(a)
}

/// Υ(a), J(1, a), energy and the stability test at full accuracy from one precomputation.
#[inline]
pub(crate) fn evaluate_precise(a: &PlanarParams) -> Result<crate::planar::Evaluation, RodError> {
    backend::evaluate(a)
}

/// The stability verdict of FINDINGS §5 (det J(t, a) > 0 on (0, 1]).
#[inline]
pub(crate) fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    backend::stability(a)
}

/// Elastic energy ½∫κ² from the tip, by the identity of FINDINGS §1:
/// E = λ2/2 − a4·x(1) − a5·y(1), λ2 = a3² + 2a4.
#[inline]
pub(crate) fn energy_from_tip(a: &PlanarParams, tip: &PlanarPose) -> f64 {
    0.5 * (a[0] * a[0] + 2.0 * a[1]) - a[1] * tip.x - a[2] * tip.y
}

/// Residual f(a) = Υ(a) − b with the angle component wrapped to (−π, π] (paper §3.1).
#[inline]
pub(crate) fn residual(tip: &PlanarPose, target: &PlanarPose) -> Vector3<f64> {
    Vector3::new(
        tip.x - target.x,
        tip.y - target.y,
        wrap_angle(tip.theta - target.theta),
    )
}

mod backend {
    // Closed forms (crate::planar): the production backend. The numerical reference
    // (crate::ode::planar_reference, same signatures with an rtol) can be swapped in here.
    use super::*;
    #[inline]
    pub(super) fn tip_and_jacobian(
        a: &PlanarParams,
    ) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        crate::planar::tip_and_jacobian(a)
    }
    #[inline]
    pub(super) fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
        crate::planar::stability(a)
    }
    #[inline]
    pub(super) fn evaluate(a: &PlanarParams) -> Result<crate::planar::Evaluation, RodError> {
        crate::planar::evaluate(a)
    }
}
