//! The 3-D rod as a model of the solvers ([`RodModel`], docs/math.md §10).

use super::{SpatialPose, Stiffness};
use crate::solver::{IgError, ModelEvaluation, RodModel};
use crate::RodError;
use nalgebra::{SMatrix, SVector};

/// The 3-D rod (docs/math.md §10) by DOP853 on the Hamiltonian system with its variational
/// equations, for stiffnesses `stiffness` at relative tolerance `rtol`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spatial {
    /// Torsion and bending stiffnesses (c1, c2, c3).
    pub stiffness: Stiffness,
    /// Relative tolerance of the integrations ([`crate::spatial::PRODUCTION_RTOL`] by
    /// default).
    pub rtol: f64,
}

impl Default for Spatial {
    fn default() -> Self {
        Self {
            stiffness: Stiffness::default(),
            rtol: crate::spatial::PRODUCTION_RTOL,
        }
    }
}

impl Spatial {
    /// The 3-D model with stiffnesses `stiffness` and the default tolerance.
    pub fn with_stiffness(stiffness: Stiffness) -> Self {
        Self {
            stiffness,
            ..Self::default()
        }
    }
}

impl RodModel<6> for Spatial {
    type Pose = SpatialPose;

    fn name(&self) -> &'static str {
        "3-D integrator"
    }

    fn tip(&self, a: &SVector<f64, 6>) -> Result<SpatialPose, RodError> {
        crate::spatial::tip(a, &self.stiffness, self.rtol)
    }

    fn evaluate(&self, a: &SVector<f64, 6>) -> Result<ModelEvaluation<6, SpatialPose>, RodError> {
        let options = crate::spatial::StabilityOptions {
            rtol: self.rtol,
            ..crate::spatial::StabilityOptions::production()
        };
        crate::spatial::evaluate(a, &self.stiffness, &options)
    }

    fn tip_and_jacobian(
        &self,
        a: &SVector<f64, 6>,
    ) -> Result<(SpatialPose, SMatrix<f64, 6, 6>), RodError> {
        super::tip_and_jacobian(a, &self.stiffness, self.rtol)
    }

    fn energy(&self, a: &SVector<f64, 6>) -> Result<f64, RodError> {
        crate::spatial::energy(a, &self.stiffness, self.rtol)
    }

    /// Moments scale with the stiffnesses, forces with the bending stiffness (see
    /// [`crate::spatial::ig::seeds_for`]).
    fn param_scale(&self) -> SVector<f64, 6> {
        let k = &self.stiffness;
        let bending = 0.5 * (k.c2 + k.c3);
        SVector::<f64, 6>::new(k.c1, k.c2, k.c3, bending, bending, bending)
    }

    fn pose_error(&self, tip: &SpatialPose, target: &SpatialPose) -> (f64, f64) {
        tip.distance_to(target)
    }

    fn is_straight(&self, a: &SVector<f64, 6>) -> bool {
        a[1] == 0.0 && a[2] == 0.0 && a[4] == 0.0 && a[5] == 0.0
    }

    fn newton_increment(
        &self,
        tip: &SpatialPose,
        jacobian: &SMatrix<f64, 6, 6>,
        target: &SpatialPose,
    ) -> Result<SVector<f64, 6>, f64> {
        let e = tip.body_error_to(target);
        match jacobian.lu().solve(&e) {
            Some(d) if d.iter().all(|v| v.is_finite()) => Ok(d),
            _ => Err(jacobian.determinant()),
        }
    }

    fn check_target(&self, target: &SpatialPose) -> Result<(), IgError> {
        crate::spatial::ig::check_target(target)
    }

    fn jacobian_det(&self, jacobian: &SMatrix<f64, 6, 6>) -> f64 {
        jacobian.determinant()
    }

    fn interpolate(&self, from: &SpatialPose, to: &SpatialPose, s: f64) -> SpatialPose {
        SpatialPose {
            position: from.position + (to.position - from.position) * s,
            rotation: from.rotation.slerp(&to.rotation, s),
        }
    }

    fn check_settings(&self) -> Result<(), IgError> {
        if !(self.rtol.is_finite() && (1e-14..=1e-3).contains(&self.rtol)) {
            return Err(IgError::InvalidOptions(format!(
                "rtol = {:e} is not in [1e-14, 1e-3]",
                self.rtol
            )));
        }
        self.stiffness
            .validate()
            .map_err(|e| IgError::InvalidOptions(e.to_string()))?;
        Ok(())
    }
}
