//! The closed form (docs/math.md §1–§3) as a formulation: its answers where its a-priori error
//! estimate holds, and the energy by the identity of docs/math.md §1 or by ζ where their bounds do.

use super::super::closed::{Case, Closed, SeriesNeed, SEPARATRIX_M1, SERIES_DD_MAX_ROOT_F};
use super::super::shape::Backend;
use super::super::taylor::Gradient;
use crate::planar::shape::PlanarRod;

use super::super::{extended, small_angle, stability};
use crate::planar::closed::overflow;
use crate::planar::taylor::{series_dd, series_dual, series_f64};

use super::{
    full_accuracy, with_theorem, Answer, Evaluation, Formulation, Need, Precision, Rod,
    SERIES_F64_TIP_MAX_ROOT_F,
};
use crate::scalar::{Dual3, Real};
use crate::StabilityVerdict;

use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};

/// The closed form of the rod, built by the dispatcher: in f64 for the tip and the energy, in
/// dual numbers seeded with the identity on a for J, the stability and the evaluation.
pub(crate) struct ClosedForm<'c, T: Real> {
    /// The closed form (borrowed where it was built: ≈ 1 KB, never moved).
    pub(crate) c: &'c Closed<T>,
    /// The parameters a.
    pub(crate) a: &'c PlanarParams,
    /// What its estimate says at t = 1 ([`Need::at`]), once asked: the rows after it reuse it.
    pub(crate) need: std::cell::Cell<Option<Need>>,
}

impl<'c, T: Real> ClosedForm<'c, T> {
    /// The closed form `c` of a.
    #[inline]
    pub(crate) fn new(c: &'c Closed<T>, a: &'c PlanarParams) -> Self {
        Self {
            c,
            a,
            need: std::cell::Cell::new(None),
        }
    }

    /// [`Need::at`] t = 1, computed once.
    #[inline]
    pub(crate) fn need(&self) -> Need {
        match self.need.get() {
            Some(need) => need,
            None => {
                let need = Need::at(self.c, 1.0);
                self.need.set(Some(need));
                need
            }
        }
    }

    /// [`Need::at`] t.
    fn need_at(&self, t: f64) -> Need {
        if t < 1.0 {
            Need::at(self.c, t)
        } else {
            self.need()
        }
    }
}

impl Formulation for ClosedForm<'_, f64> {
    /// The closed form with everything that depends on a only precomputed, where its estimate
    /// holds.
    fn shape(&self) -> Answer<PlanarRod> {
        (self.need() == Need::Closed).then(|| {
            let backend = Backend::Closed(*self.c);
            PlanarRod::from_parts(self.a, self.c.case, backend, self.c.pose(1.0))
        })
    }
    /// q(1) (docs/math.md §1–§3), where the estimate holds. Built without the phase, the tip is
    /// placed by the addition theorems (~18 % of q(1)); it may differ from the evaluation's in
    /// the last bits, both within the closed form's pose bound.
    fn tip(&self) -> Answer<PlanarPose> {
        (self.need() == Need::Closed).then(|| super::finite_tip(self.c.pose(1.0)))
    }
    /// The identity or ζ where their bounds hold ([`identity_or_zeta`]); the other rows
    /// elsewhere.
    fn energy(&self) -> Answer<f64> {
        if self.need() != Need::Closed {
            return None;
        }
        let [x, y, theta] = self.c.pose(1.0);
        identity_or_zeta(self.c, self.a, &PlanarPose::new(x, y, theta)).transpose()
    }
}

/// Largest estimated relative error of the closed form's J (its cancellation estimate) for
/// which a continuation's intermediate step uses it: 100× inside the steps' 1e-6 tolerance.
/// Strongly tensioned rods (a4 ≈ 600) have estimates of 1e-8 to 2e-8, just past the 1e-8 of
/// an answer ([`super::CLOSED_J_TOLERANCE`]), and agree with the double-double series to
/// 1e-14; the series costs 3 ms there, the closed form under 1 µs.
pub(crate) const SUBSTEP_J_TOLERANCE: f64 = 1e-8 * 100.0;

impl Formulation for ClosedForm<'_, Dual3> {
    /// q(t) and J(t) in forward-mode dual numbers, exact up to rounding, where the estimate
    /// holds at t (for a continuation's substep, within [`SUBSTEP_J_TOLERANCE`]).
    fn pose_and_jacobian(
        &self,
        t: f64,
        precision: Precision,
    ) -> Answer<(PlanarPose, PlanarJacobian)> {
        let within = self.need_at(t) == Need::Closed
            || (precision == Precision::Substep && self.c.accurate_within(SUBSTEP_J_TOLERANCE));
        within.then(|| crate::planar::taylor::pose_jac_from(self.c.pose(t)))
    }
    /// The verdict where a theorem, the sign of det J(1) or the scan from the theorem's
    /// conjugate-free time decides ([`stability::verdict_of`]); the stability rows elsewhere.
    fn stability_verdict(&self) -> Answer<StabilityVerdict> {
        stability::verdict_of(self.c, self.a).transpose()
    }
    fn evaluate(&self) -> Answer<Evaluation> {
        (self.need() == Need::Closed).then(|| {
            evaluate_closed(self.c, self.a).map(|e| with_theorem(e, || self.c.theorem_verdict()))
        })
    }
}

/// λ2/2 − a4 x(1) − a5 y(1) with λ2 = a3² + 2a4 (docs/math.md §1).
pub(crate) fn energy_from_tip(a: &PlanarParams, tip: &PlanarPose) -> f64 {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    0.5 * a3 * a3 + a4 - a4 * tip.x - a5 * tip.y
}

/// Relative accuracy asked of the energy: issue 9 asks 1e-8; 10× inside, with a bound that
/// is itself ≥ 2× the measured error.
pub(crate) const ENERGY_REL_TOLERANCE: f64 = 1e-9;

/// Rounding of [`Closed::energy_by_zeta_bounded`] in ulps of its terms: measured ≤ 10.1 on
/// 1,160 rods of cases I and II against the 320-bit references (tests/data/separatrix_truth*
/// .jsonl) and the double-double series (`zeta_energy_meets_its_bound`), ×3.
pub(crate) const ZETA_ENERGY_ULPS: f64 = 32.0;

/// The energy by the identity λ2/2 − a4 x − a5 y of docs/math.md §1 where its error bound allows,
/// else None. The identity subtracts a4·x + a5·y from λ2/2, both ≈ ‖F‖ on a nearly straight
/// rod under force, whose energy is orders of magnitude smaller: its error is (|a4| + |a5|)
/// times the pose error ([`Closed::pose_abs_error`]) plus the rounding of the sum.
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

/// The closed form's own stability scans (a row after the small-angle expansion's: on a
/// nearly straight rod the expansion decides, `stability::closed_report`).
pub(crate) struct ClosedScan<'c>(pub(crate) Rod<'c>);

impl Formulation for ClosedScan<'_> {
    fn stability(&self) -> Answer<StabilityReport> {
        let c = self.0.closed?;
        let need = match self.0.need {
            Need::Closed => SeriesNeed::None,
            Need::IllConditioned => SeriesNeed::IllConditioned,
            Need::Cancellation | Need::NoClosedForm => SeriesNeed::Cancellation,
        };
        let report = stability::closed_report(c, self.0.a, need, self.0.precise_series);
        let report = report.transpose()?;
        Some(report.map(|r| stability::with_theorem(r, || c.theorem_verdict())))
    }
}

/// The energy by the identity ([`energy_by_identity`], free) where its error bound allows,
/// else by ζ where its rounding does; None elsewhere (the other formulations' rows).
fn identity_or_zeta<T: Real>(
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
            None => series_dd::<false>(a, false, SERIES_DD_MAX_ROOT_F)?
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

/// The evaluation on the closed form where its estimate holds at t = 1, with the stability
/// verdict of the scans alone. By the separatrix, where the identity cancels, the energy and
/// det J(t) come from one dense series.
fn evaluate_closed(c: &Closed<Dual3>, a: &PlanarParams) -> Result<Evaluation, RodError> {
    let (tip, jacobian) = crate::planar::taylor::pose_jac_from(c.pose(1.0))?;
    let near_separatrix = c.m1 < SEPARATRIX_M1
        && !c.needs_precise_series()
        && energy_by_identity(c, a, &tip)?.is_none();
    if near_separatrix {
        // A nearly straight rod under a force near the separatrix: its energy and
        // det J(t) both need the series (the identity cancels, the x row of J is below
        // the closed form's error floor); one dense series serves both. The tip and J
        // stay the closed form's, identical to `tip_and_jacobian`'s. Where the
        // small-angle limit decides stability, the energy needs no dense series (the
        // zeta form, or the series' values only).
        if let Some(stability) = stability::small_angle_report(a)? {
            return Ok(full_accuracy(
                tip,
                jacobian,
                closed_energy(c, a, &tip)?,
                stability,
            ));
        }
        let rod = series_dual(a, true)?;
        return Ok(full_accuracy(
            tip,
            jacobian,
            rod.energy().v,
            stability::stability_of_dense_series(a, &rod)?,
        ));
    }
    let energy = closed_energy(c, a, &tip)?;
    let stability = stability::stability_of(c, a)?;
    Ok(full_accuracy(tip, jacobian, energy, stability))
}
