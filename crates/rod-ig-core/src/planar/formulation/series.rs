//! The Taylor series (docs/math.md §4's fallback) as a formulation: gently bent rods, closed forms
//! that overflow, and rods whose closed-form J cancels.

use super::super::closed::Closed;
use super::super::shape::Backend;
use crate::planar::shape::PlanarRod;

use super::super::stability;
use crate::planar::taylor::{pose_jac_from, series_dual, series_f64, series_pose_and_jac};

use super::{finite_tip, full_accuracy, with_theorem, Evaluation};
use super::{Precision, Rod};
use crate::StabilityVerdict;

use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};

/// The Taylor series of the rod in f64 (dual numbers for J): the last row of the table, it
/// answers whatever reaches it (gently bent rods, closed forms that overflow, closed-form J
/// that cancels; by the separatrix, a solver's iterations). Its own refusals are its step
/// budget and its overflow.
pub(crate) struct Series<'c>(pub(crate) Rod<'c>);

impl Series<'_> {
    pub(crate) fn tip(&self) -> Result<PlanarPose, RodError> {
        series_f64(self.0.a, false).and_then(|r| finite_tip(r.tip()))
    }
    pub(crate) fn pose_and_jacobian(
        &self,
        t: f64,
        _: Precision,
    ) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        series_pose_and_jac(self.0.a, t)
    }
    /// ½∫κ² integrated along (the identity cancels on a nearly straight rod under force).
    pub(crate) fn energy(&self) -> Result<f64, RodError> {
        let e = series_f64(self.0.a, false).map(|r| r.energy());
        e.and_then(|e| {
            if e.is_finite() {
                Ok(e)
            } else {
                Err(crate::planar::closed::overflow())
            }
        })
    }
    /// The series scan (the small-angle row before it declined), with the theorem that
    /// decides where the series runs out of steps.
    pub(crate) fn stability(&self) -> Result<StabilityReport, RodError> {
        let a = self.0.a;
        match self.0.closed {
            Some(c) => stability::series_report_after_closed(c, a)
                .map(|r| stability::with_theorem(r, || c.theorem_verdict())),
            None => stability::series_after_small_angle(a, None, None, None)
                .map(|r| stability::with_theorem(r, || theorem_verdict(a))),
        }
    }
    /// The dense f64 series (or the expansion where the series cannot run).
    pub(crate) fn shape(&self) -> Result<PlanarRod, RodError> {
        let a = self.0.a;
        self.0.series_shape(|backend| match backend {
            Backend::Series(r) => Ok(r.tip()),
            _ => super::super::small_angle::checked_tip(a)
                .ok_or_else(crate::planar::closed::overflow),
        })
    }
    /// With the theorem of the rod's closed form where one was built, else of its f64 one.
    pub(crate) fn evaluate(&self) -> Result<Evaluation, RodError> {
        let e = evaluate_series(self.0.a);
        e.map(|e| match self.0.closed {
            Some(c) => with_theorem(e, || c.theorem_verdict()),
            None => with_theorem(e, || theorem_verdict(self.0.a)),
        })
    }
}

/// The evaluation on the Taylor series (one dense integration serves all four quantities).
fn evaluate_series(a: &PlanarParams) -> Result<Evaluation, RodError> {
    // Where the small-angle limit decides stability, the scan needs no dense output.
    let small_angle = stability::small_angle_report(a)?;
    let rod = series_dual(a, small_angle.is_none())?;
    let (tip, jacobian) = pose_jac_from(rod.tip())?;
    let energy = rod.energy().v;
    let stability = match small_angle {
        Some(report) => report,
        None => stability::stability_of_dense_series(a, &rod)?,
    };
    Ok(full_accuracy(tip, jacobian, energy, stability))
}

/// [`Closed::theorem_verdict`] of a rod whose closed form was not built (None where it
/// cannot be).
pub(crate) fn theorem_verdict(a: &PlanarParams) -> Option<StabilityVerdict> {
    Closed::<f64>::new(a[0], a[1], a[2]).and_then(|c| c.theorem_verdict())
}
