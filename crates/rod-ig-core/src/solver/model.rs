//! What a rod model provides to the solvers: the forward map Υ(a), its Jacobian J(1, a), the
//! stability verdict with its margin, the elastic energy and the scale of its parameters.
//!
//! Each model lives beside its physics and implements [`RodModel`] there: the planar closed
//! forms and the planar reference integrator in `crate::planar::model`, the 3-D rod in
//! `crate::spatial::model`. The strategies of [`super`] are written once against this trait.

use super::IgError;
use crate::{RodError, StabilityReport};
use nalgebra::{SMatrix, SVector};

/// One evaluation of a model at a: everything a Newton iteration and a verdict need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelEvaluation<const N: usize, X> {
    /// Υ(a) = q(1, a).
    pub tip: X,
    /// J(1, a) (planar rows x, y, θ; 3-D rows the body twist (ω, v)).
    pub jacobian: SMatrix<f64, N, N>,
    /// Elastic energy.
    pub energy: f64,
    /// Stability verdict and normalised margin (docs/math.md §5).
    pub stability: StabilityReport,
    /// False when computed at an iteration's reduced accuracy: a converged iterate is then
    /// re-evaluated with [`RodModel::evaluate`] before it is returned.
    pub full_accuracy: bool,
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

    /// Υ(a) and J(1, a) alone (no energy, no stability test): what a continuation's corrector
    /// needs, whose iterates stay on one branch by the sign of det J(1, a).
    fn tip_and_jacobian(
        &self,
        a: &SVector<f64, N>,
    ) -> Result<(Self::Pose, SMatrix<f64, N, N>), RodError> {
        self.evaluate(a).map(|e| (e.tip, e.jacobian))
    }

    /// Υ(a) and J(1, a) for the intermediate poses of a continuation, whose tolerance is
    /// [`crate::solver::continuation::SUBSTEP_TOLERANCE`] (1e-6): a model may use a cheaper
    /// evaluation there when its error is certified far below that. The end of a move is
    /// always verified with [`Self::tip_and_jacobian`] and [`Self::evaluate`].
    fn tip_and_jacobian_for_substep(
        &self,
        a: &SVector<f64, N>,
    ) -> Result<(Self::Pose, SMatrix<f64, N, N>), RodError> {
        self.tip_and_jacobian(a)
    }

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
    /// stability can be lost along it, docs/math.md §5).
    fn jacobian_det(&self, jacobian: &SMatrix<f64, N, N>) -> f64;

    /// The pose a fraction `s` ∈ [0, 1] of the way from `from` to `to` along the shortest
    /// motion (planar: straight line and shortest wrapped rotation; 3-D: straight line and
    /// slerp): the gripper path between two targets.
    fn interpolate(&self, from: &Self::Pose, to: &Self::Pose, s: f64) -> Self::Pose;

    /// True for the exactly straight rod of this model: a neutral equilibrium (det J(t) ≡ 0,
    /// the verdict `uncertain`) that a gripper may still hold at rest, and from which the first
    /// move buckles ([`crate::solver::BranchFollower`]).
    fn is_straight(&self, a: &SVector<f64, N>) -> bool {
        let _ = a;
        false
    }

    /// One corrector step of the branch follower ([`crate::solver::BranchFollower`]) taken by
    /// the model itself: the rod of `from`'s branch whose tip is at `goal` (within
    /// `tolerance`), with its tip and J(1, a), `Some(None)` when the step fails (too long, or
    /// across a fold), `None` when the model leaves the step to the generic Newton in a (the
    /// default). A model whose `a` does not fix its rod to the accuracy asked (the long
    /// cables' node states) follows its branch in its own unknowns.
    #[allow(clippy::type_complexity)]
    fn branch_step(
        &self,
        from: &SVector<f64, N>,
        goal: &Self::Pose,
        tolerance: f64,
    ) -> Option<Option<(SVector<f64, N>, Self::Pose, nalgebra::SMatrix<f64, N, N>)>> {
        let _ = (from, goal, tolerance);
        None
    }

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
