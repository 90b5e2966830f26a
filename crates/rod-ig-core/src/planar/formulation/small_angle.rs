//! The small-angle expansion and the pendulum (`planar::small_angle`, `planar::pendulum`) as a
//! formulation: nearly straight rods, where their a-priori bounds hold.

use super::super::shape::Backend;

use super::super::{small_angle, stability};
use crate::planar::shape::PlanarRod;

use super::{finite_tip, full_accuracy, with_theorem, Answer, Evaluation, Need};
use super::{Precision, Rod};
use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};

/// A nearly straight rod by the small-angle expansion (or, under compression, the pendulum of
/// exact frequency). Its tip, J and evaluation answer where the closed form declined (on a
/// nearly straight rod the closed form's x row is swamped by rounding); its energy wherever
/// its bound holds (the question of the energy asks it first: the identity cancels there).
pub(crate) struct SmallAngle<'c>(pub(crate) Rod<'c>);

impl SmallAngle<'_> {
    /// Whether the closed form declined at t (the expansion stands in for it).
    fn declined_at(&self, t: f64) -> bool {
        !matches!(self.0.need_at(t), Need::Closed | Need::NoClosedForm)
    }
}

impl SmallAngle<'_> {
    pub(crate) fn tip(&self) -> Answer<PlanarPose> {
        if !self.declined_at(1.0) {
            return None;
        }
        small_angle::checked_tip(self.0.a).map(finite_tip)
    }
    pub(crate) fn pose_and_jacobian(
        &self,
        t: f64,
        _: Precision,
    ) -> Answer<(PlanarPose, PlanarJacobian)> {
        if !self.declined_at(t) {
            return None;
        }
        small_angle::checked_pose_and_jacobian(self.0.a, t).map(Ok)
    }
    pub(crate) fn energy(&self) -> Answer<f64> {
        small_angle::checked_energy(self.0.a).map(Ok)
    }
    /// Where the closed form declined and no series can run (beyond √‖F‖ = ln(f64::MAX), a
    /// nearly straight rod under compression).
    pub(crate) fn shape(&self) -> Answer<PlanarRod> {
        let a = self.0.a;
        let beyond_series =
            crate::scalar::fast_hypot(a[1], a[2]).sqrt() > crate::planar::taylor::LN_F64_MAX;
        if self.0.need == Need::Closed || !beyond_series {
            return None;
        }
        let tip = small_angle::checked_tip(a)?;
        Some(PlanarRod::from_parts(
            a,
            self.0.case(),
            Backend::SmallAngle,
            tip,
        ))
    }
    /// The stability of a nearly straight rod from the expansion's det J, where its bounds
    /// decide the verdict with certainty (`stability::small_angle_report`), before any scan.
    pub(crate) fn stability(&self) -> Answer<StabilityReport> {
        let report = stability::small_angle_report(self.0.a).transpose()?;
        Some(report.map(|r| match self.0.closed {
            Some(c) => stability::with_theorem(r, || c.theorem_verdict()),
            None => stability::with_theorem(r, || super::series::theorem_verdict(self.0.a)),
        }))
    }
    pub(crate) fn evaluate(&self) -> Answer<Evaluation> {
        if !self.declined_at(1.0) {
            return None;
        }
        let e = evaluate_small_angle(self.0.a).transpose()?;
        Some(e.map(|e| match self.0.closed {
            Some(c) => with_theorem(e, || c.theorem_verdict()),
            None => e,
        }))
    }
}

/// The evaluation of a nearly straight rod by the small-angle expansion, where every part of it
/// is within its tolerance; None elsewhere.
fn evaluate_small_angle(a: &PlanarParams) -> Result<Option<Evaluation>, RodError> {
    let th = small_angle::effective_angle(a[0], a[1], a[2]);
    let Some((tip, jacobian)) = small_angle::checked_pose_and_jacobian_at(a, 1.0, th) else {
        return Ok(None);
    };
    let Some(energy) = small_angle::checked_energy_at(a, th) else {
        return Ok(None);
    };
    let Some(stability) = stability::small_angle_report(a)? else {
        return Ok(None);
    };
    Ok(Some(full_accuracy(tip, jacobian, energy, stability)))
}
