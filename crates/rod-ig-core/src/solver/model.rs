//! What a rod model provides to the solvers: the forward map Υ(a), its Jacobian J(1, a), the
//! stability verdict with its margin, the elastic energy and the scale of its parameters.
//!
//! Three models implement [`RodModel`]: the planar closed forms ([`PlanarClosedForm`], paper
//! §2), the planar reference integrator ([`PlanarReference`], DOP853 on the ODE of paper eq. 2.9
//! with variational equations) and the 3-D rod ([`Spatial`], FINDINGS3D, DOP853). The
//! strategies of [`super`] are written once against this trait.

use super::IgError;
use crate::spatial::{SpatialPose, Stiffness};
use crate::{wrap_angle, PlanarPose, RodError, StabilityReport};
use nalgebra::{SMatrix, SVector, Vector3};

/// One evaluation of a model at a: everything a Newton iteration and a verdict need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelEvaluation<const N: usize, X> {
    /// Υ(a) = q(1, a).
    pub tip: X,
    /// J(1, a) (planar rows x, y, θ; 3-D rows the body twist (ω, v)).
    pub jacobian: SMatrix<f64, N, N>,
    /// Elastic energy.
    pub energy: f64,
    /// Stability verdict and normalised margin (FINDINGS §5).
    pub stability: StabilityReport,
    /// False when computed at an iteration's reduced accuracy: a converged iterate is then
    /// re-evaluated with [`RodModel::evaluate`] before it is returned.
    pub full_accuracy: bool,
}

/// A full-accuracy planar evaluation (closed form or series).
impl From<crate::planar::Evaluation> for ModelEvaluation<3, PlanarPose> {
    fn from(e: crate::planar::Evaluation) -> Self {
        Self {
            tip: e.tip,
            jacobian: e.jacobian,
            energy: e.energy,
            stability: e.stability,
            full_accuracy: true,
        }
    }
}

/// A full-accuracy 3-D evaluation (at the model's rtol).
impl From<crate::spatial::Evaluation3d> for ModelEvaluation<6, SpatialPose> {
    fn from(e: crate::spatial::Evaluation3d) -> Self {
        Self {
            tip: e.tip,
            jacobian: e.jacobian,
            energy: e.energy,
            stability: e.stability,
            full_accuracy: true,
        }
    }
}

/// A rod model: a ∈ ℝᴺ ↦ tip pose, with everything the inverse-geometry strategies need.
pub trait RodModel<const N: usize> {
    /// The tip pose type.
    type Pose: Copy + std::fmt::Debug + PartialEq;

    /// A short name for logs ("planar closed form", ...).
    fn name(&self) -> &'static str;

    /// Υ(a), the tip pose of the unit rod with base wrench a.
    fn tip(&self, a: &SVector<f64, N>) -> Result<Self::Pose, RodError>;

    /// Tip, J(1, a), energy and stability, at the model's full accuracy.
    fn evaluate(&self, a: &SVector<f64, N>) -> Result<ModelEvaluation<N, Self::Pose>, RodError>;

    /// As [`Self::evaluate`], for an iterate of a run that began at `start`: a model may use a
    /// cheaper accuracy there (setting `full_accuracy` false).
    fn evaluate_iterate(
        &self,
        a: &SVector<f64, N>,
        start: &SVector<f64, N>,
    ) -> Result<ModelEvaluation<N, Self::Pose>, RodError> {
        let _ = start;
        self.evaluate(a)
    }

    /// The stability verdict and margin alone.
    fn stability(&self, a: &SVector<f64, N>) -> Result<StabilityReport, RodError> {
        Ok(self.evaluate(a)?.stability)
    }

    /// The elastic energy alone.
    fn energy(&self, a: &SVector<f64, N>) -> Result<f64, RodError> {
        Ok(self.evaluate(a)?.energy)
    }

    /// Typical magnitude of each parameter: distances between rods are measured relative to
    /// it (1 + |a_i| / scale_i).
    fn param_scale(&self) -> SVector<f64, N>;

    /// (position error, orientation error) of `tip` from `target`.
    fn pose_error(&self, tip: &Self::Pose, target: &Self::Pose) -> (f64, f64);

    /// The Newton increment δa solving J(1, a) δa = (target − tip) to first order (paper eq.
    /// 3.1 with α = 1). `Err(det)` when J is numerically singular.
    fn newton_increment(
        &self,
        tip: &Self::Pose,
        jacobian: &SMatrix<f64, N, N>,
        target: &Self::Pose,
    ) -> Result<SVector<f64, N>, f64>;

    /// Checks that `target` is finite and within reach.
    fn check_target(&self, target: &Self::Pose) -> Result<(), IgError>;

    /// The target as every solver sees it, reported errors included: planar angles reduced
    /// exactly to (−π, π] ([`crate::wrap_angle`]), so that θ = 3.7e11 solves exactly as its
    /// reduction does (a residual θ_tip − θ_target would round away the low bits first).
    fn canonical_target(&self, target: &Self::Pose) -> Self::Pose {
        *target
    }

    /// det J(1, a): its sign changes exactly where a branch of equilibria folds (and where
    /// stability can be lost along it, FINDINGS §5).
    fn jacobian_det(&self, jacobian: &SMatrix<f64, N, N>) -> f64;

    /// The pose a fraction `s` ∈ [0, 1] of the way from `from` to `to` along the shortest
    /// motion (planar: straight line and shortest wrapped rotation; 3-D: straight line and
    /// slerp): the gripper path between two targets.
    fn interpolate(&self, from: &Self::Pose, to: &Self::Pose, s: f64) -> Self::Pose;

    /// Checks the model's own settings (stiffness, integration tolerance).
    fn check_settings(&self) -> Result<(), IgError> {
        Ok(())
    }
}

/// Distance between two rods, relative to the model's parameter scale: Σ |aᵢ − bᵢ| / (sᵢ +
/// |aᵢ|). Two solutions closer than [`DISTINCT`] are the same.
pub fn relative_distance<const N: usize>(
    a: &SVector<f64, N>,
    b: &SVector<f64, N>,
    scale: &SVector<f64, N>,
) -> f64 {
    (0..N)
        .map(|i| (a[i] - b[i]).abs() / (scale[i] + a[i].abs()))
        .sum()
}

/// Solutions closer than this ([`relative_distance`]) are one: converged solutions carry
/// errors ~ tolerance × ‖J⁻¹‖ ≲ 1e-5 relative at the default tolerance, distinct equilibria
/// of one target differ by O(1).
pub const DISTINCT: f64 = 1e-4;

/// J δa = r for the planar 3×3 J: `Err(det)` when |det J| is below 1e-14 times the product of
/// its column norms (Hadamard bound) or the result is not finite.
pub(crate) fn planar_increment(
    jacobian: &SMatrix<f64, 3, 3>,
    r: &Vector3<f64>,
) -> Result<Vector3<f64>, f64> {
    crate::ig::solve_linear3(jacobian, r)
}

/// Planar residual target − tip with the angle wrapped (paper §3.1: f = Υ(a) − b).
fn planar_error(tip: &PlanarPose, target: &PlanarPose) -> Vector3<f64> {
    Vector3::new(
        target.x - tip.x,
        target.y - tip.y,
        wrap_angle(target.theta - tip.theta),
    )
}

/// The planar rod by the closed forms of paper §2 (with the series and error-estimated
/// fallbacks of [`crate::planar`]): the production model, microseconds per evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanarClosedForm;

/// The planar rod by the reference integrator ([`crate::ode::planar_reference`]): DOP853 at
/// relative tolerance `rtol` on paper eq. 2.9 with its variational equations. Slower (~100×);
/// independent of the closed forms, hence the cross-check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarReference {
    /// Relative tolerance of the integrations.
    pub rtol: f64,
}

impl Default for PlanarReference {
    fn default() -> Self {
        Self { rtol: 1e-12 }
    }
}

/// Parameter scale of the planar rod: 1 for the moment and both forces, so that distances are
/// relative for |aᵢ| ≫ 1 and absolute near the relaxed rod (a = 0, where every component is
/// O(1) at unit length and stiffness).
const PLANAR_SCALE: [f64; 3] = [1.0, 1.0, 1.0];

fn planar_check_target(target: &PlanarPose) -> Result<(), IgError> {
    crate::ig::check_target(target)
}

/// Planar gripper motion: position on the segment, angle turned the short way (θ stays
/// unwrapped from `from`).
fn planar_interpolate(from: &PlanarPose, to: &PlanarPose, s: f64) -> PlanarPose {
    PlanarPose::new(
        from.x + (to.x - from.x) * s,
        from.y + (to.y - from.y) * s,
        from.theta + wrap_angle(to.theta - from.theta) * s,
    )
}

fn planar_pose_error(tip: &PlanarPose, target: &PlanarPose) -> (f64, f64) {
    let f = planar_error(tip, target);
    (f[0].hypot(f[1]), f[2].abs())
}

/// The pose geometry every planar model shares (the tip pose (x, y, θ), the residual of paper
/// §3.1 with the angle wrapped): the same methods in each planar model's `RodModel` impl.
macro_rules! planar_geometry {
    () => {
        fn param_scale(&self) -> Vector3<f64> {
            Vector3::from(PLANAR_SCALE)
        }

        fn pose_error(&self, tip: &PlanarPose, target: &PlanarPose) -> (f64, f64) {
            planar_pose_error(tip, target)
        }

        fn newton_increment(
            &self,
            tip: &PlanarPose,
            jacobian: &SMatrix<f64, 3, 3>,
            target: &PlanarPose,
        ) -> Result<Vector3<f64>, f64> {
            planar_increment(jacobian, &planar_error(tip, target))
        }

        fn check_target(&self, target: &PlanarPose) -> Result<(), IgError> {
            planar_check_target(target)
        }

        fn canonical_target(&self, target: &PlanarPose) -> PlanarPose {
            PlanarPose::new(target.x, target.y, wrap_angle(target.theta))
        }

        fn interpolate(&self, from: &PlanarPose, to: &PlanarPose, s: f64) -> PlanarPose {
            planar_interpolate(from, to, s)
        }

        fn jacobian_det(&self, jacobian: &SMatrix<f64, 3, 3>) -> f64 {
            jacobian.determinant()
        }
    };
}

impl RodModel<3> for PlanarClosedForm {
    type Pose = PlanarPose;

    fn name(&self) -> &'static str {
        "planar closed form"
    }

    fn tip(&self, a: &Vector3<f64>) -> Result<PlanarPose, RodError> {
        crate::planar::tip(a)
    }

    fn evaluate(&self, a: &Vector3<f64>) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        crate::planar::evaluate(a).map(ModelEvaluation::from)
    }

    fn evaluate_iterate(
        &self,
        a: &Vector3<f64>,
        start: &Vector3<f64>,
    ) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        crate::ig::evaluate_iterate(a, start)
    }

    fn stability(&self, a: &Vector3<f64>) -> Result<StabilityReport, RodError> {
        crate::planar::stability(a)
    }

    fn energy(&self, a: &Vector3<f64>) -> Result<f64, RodError> {
        crate::planar::energy(a)
    }

    planar_geometry!();
}

impl RodModel<3> for PlanarReference {
    type Pose = PlanarPose;

    fn name(&self) -> &'static str {
        "planar reference integrator"
    }

    fn tip(&self, a: &Vector3<f64>) -> Result<PlanarPose, RodError> {
        Ok(crate::ode::planar_reference::tip_and_jacobian(a, self.rtol)?.0)
    }

    fn evaluate(&self, a: &Vector3<f64>) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        use crate::ode::planar_reference as reference;
        let (tip, jacobian) = reference::tip_and_jacobian(a, self.rtol)?;
        Ok(ModelEvaluation {
            tip,
            jacobian,
            energy: reference::energy(a, self.rtol)?,
            stability: reference::stability(a)?,
            full_accuracy: true,
        })
    }

    planar_geometry!();

    fn check_settings(&self) -> Result<(), IgError> {
        if self.rtol.is_finite() && (1e-14..=1e-3).contains(&self.rtol) {
            Ok(())
        } else {
            Err(IgError::InvalidOptions(format!(
                "rtol = {:e} is not in [1e-14, 1e-3]",
                self.rtol
            )))
        }
    }
}

/// The 3-D rod (FINDINGS3D) by DOP853 on the Hamiltonian system with its variational
/// equations, for stiffnesses `stiffness` at relative tolerance `rtol`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spatial {
    /// Torsion and bending stiffnesses (c1, c2, c3).
    pub stiffness: Stiffness,
    /// Relative tolerance of the integrations ([`crate::spatial::PRODUCTION_RTOL`] by
    /// default).
    pub rtol: f64,
    /// Robust strategy: number of seeds tried at most ([`crate::spatial::ig::seeds_for`]).
    pub max_starts: u32,
}

impl Default for Spatial {
    fn default() -> Self {
        Self {
            stiffness: Stiffness::default(),
            rtol: crate::spatial::PRODUCTION_RTOL,
            max_starts: crate::spatial::ig::DEFAULT_MAX_STARTS,
        }
    }
}

impl Spatial {
    /// The 3-D model with stiffnesses `stiffness` and the default tolerance and starts.
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
        crate::spatial::evaluate(a, &self.stiffness, &options).map(ModelEvaluation::from)
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
        if self.max_starts == 0 {
            return Err(IgError::InvalidOptions("max_starts must be >= 1".into()));
        }
        Ok(())
    }
}
