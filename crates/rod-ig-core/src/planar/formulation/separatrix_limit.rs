//! The separatrix limit in log form ([`crate::planar::soliton`]): a barely bent rod under a
//! strong force, every quantity from its lattice of solitons.

use super::super::soliton::{self, Lattice};
use super::super::taylor::pose_jac_from;

use super::super::{shape::case_without_closed, shape::Backend, stability};
use crate::planar::shape::PlanarRod;

use super::{finite_tip, full_accuracy, Evaluation, Precision};
use crate::scalar::Dual3;

use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};

/// The rod in the separatrix limit: asked before the closed form, whose phase is lost there
/// (1 − k² ≈ ρ² underflows).
pub(crate) struct SeparatrixLimit<'a> {
    a: &'a PlanarParams,
    lattice: Lattice<f64>,
}

impl<'a> SeparatrixLimit<'a> {
    /// The rod a if it is in the lattice's domain (a few comparisons for the rods that are not).
    #[inline]
    pub(crate) fn of(a: &'a PlanarParams) -> Option<Self> {
        if !soliton::may_apply(a[0], a[1], a[2]) {
            return None;
        }
        Self::build(a)
    }

    #[cold]
    fn build(a: &'a PlanarParams) -> Option<Self> {
        let lattice = Lattice::new(a[0], a[1], a[2])?;
        Some(SeparatrixLimit { a, lattice })
    }

    fn dual(&self) -> Option<Lattice<Dual3>> {
        let a = self.a;
        Lattice::new(
            Dual3::variable(a[0], 0),
            Dual3::variable(a[1], 1),
            Dual3::variable(a[2], 2),
        )
    }

    fn pose_and_jacobian_at(&self, t: f64) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        let lattice = self.dual().ok_or_else(crate::planar::closed::overflow)?;
        pose_jac_from(lattice.pose(t.clamp(0.0, 1.0)))
    }

    fn finite_energy(&self) -> Result<f64, RodError> {
        let e = self.lattice.energy();
        if e.is_finite() {
            Ok(e)
        } else {
            Err(crate::planar::closed::overflow())
        }
    }

    fn report(&self) -> Result<StabilityReport, RodError> {
        stability::lattice_report(self.a).unwrap_or_else(|| Err(crate::planar::closed::overflow()))
    }
}

impl SeparatrixLimit<'_> {
    pub(crate) fn tip(&self) -> Result<PlanarPose, RodError> {
        finite_tip(self.lattice.pose(1.0))
    }
    pub(crate) fn pose_and_jacobian(
        &self,
        t: f64,
        _: Precision,
    ) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        self.pose_and_jacobian_at(t)
    }
    pub(crate) fn energy(&self) -> Result<f64, RodError> {
        self.finite_energy()
    }
    pub(crate) fn stability(&self) -> Result<StabilityReport, RodError> {
        self.report()
    }
    pub(crate) fn evaluate(&self) -> Result<Evaluation, RodError> {
        let (tip, jacobian) = self.pose_and_jacobian_at(1.0)?;
        Ok(full_accuracy(
            tip,
            jacobian,
            self.finite_energy()?,
            self.report()?,
        ))
    }
    pub(crate) fn shape(&self) -> Result<PlanarRod, RodError> {
        let a = self.a;
        let tip = self.lattice.pose(1.0);
        PlanarRod::from_parts(
            a,
            case_without_closed(a),
            Backend::Separatrix(self.lattice),
            tip,
        )
    }
}
