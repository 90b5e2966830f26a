//! The closed form (docs/math.md §1–§3) as a formulation: its answers where its a-priori error
//! estimate holds, and the energy by the identity of docs/math.md §1 or by ζ where their bounds do.

use super::super::closed::{Closed, SeriesNeed, SEPARATRIX_M1};
use super::super::shape::Backend;
use crate::planar::shape::PlanarRod;

use super::super::stability;
use crate::planar::energy::{closed_energy, energy_by_identity, identity_or_zeta};
use crate::planar::taylor::series_dual;

use super::{full_accuracy, with_theorem, Answer, Evaluation, Need, Precision, Rod};
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

impl ClosedForm<'_, f64> {
    /// The closed form with everything that depends on a only precomputed, where its estimate
    /// holds.
    #[inline]
    pub(crate) fn shape(&self) -> Answer<PlanarRod> {
        (self.need() == Need::Closed).then(|| {
            let backend = Backend::Closed(*self.c);
            PlanarRod::from_parts(self.a, self.c.case, backend, self.c.pose(1.0))
        })
    }
    /// q(1) (docs/math.md §1–§3), where the estimate holds. Built without the phase, the tip is
    /// placed by the addition theorems (~18 % of q(1)); it may differ from the evaluation's in
    /// the last bits, both within the closed form's pose bound.
    #[inline(always)]
    pub(crate) fn tip(&self) -> Answer<PlanarPose> {
        (self.need() == Need::Closed).then(|| super::finite_tip(self.c.pose(1.0)))
    }
    /// The identity or ζ where their bounds hold ([`identity_or_zeta`]); the other rows
    /// elsewhere.
    #[inline]
    pub(crate) fn energy(&self) -> Answer<f64> {
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

impl ClosedForm<'_, Dual3> {
    /// q(t) and J(t) in forward-mode dual numbers, exact up to rounding, where the estimate
    /// holds at t (for a continuation's substep, within [`SUBSTEP_J_TOLERANCE`]).
    #[inline(always)]
    pub(crate) fn pose_and_jacobian(
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
    #[inline]
    pub(crate) fn stability_verdict(&self) -> Answer<StabilityVerdict> {
        stability::verdict_of(self.c, self.a).transpose()
    }
    #[inline]
    pub(crate) fn evaluate(&self) -> Answer<Evaluation> {
        (self.need() == Need::Closed).then(|| {
            evaluate_closed(self.c, self.a).map(|e| with_theorem(e, || self.c.theorem_verdict()))
        })
    }
}

/// The closed form's own stability scans (a row after the small-angle expansion's: on a
/// nearly straight rod the expansion decides, `stability::closed_report`).
pub(crate) struct ClosedScan<'c>(pub(crate) Rod<'c>);

impl ClosedScan<'_> {
    #[inline]
    pub(crate) fn stability(&self) -> Answer<StabilityReport> {
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
