//! The entry points of the planar evaluation (re-exported by `planar`): each asks its question
//! of the one dispatcher ([`super::dispatch`]), which alone decides which formulation answers.
//! The solvers' own evaluations (a cheaper tip for chord steps, J at an iteration's or a
//! substep's precision) are here too, so that every evaluation of a rod starts in one file.

use super::closed::{Closed, SeriesNeed};
use super::dispatch::{self, check_params, series_first};
pub use super::formulation::Evaluation;
use super::formulation::Precision;
use super::shape::PlanarRod;

use crate::{
    PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport, StabilityVerdict,
};

/// q(1, a) from the f64 closed form without its phase, where its error estimate needs no
/// series (as in [`tip`]); `None` elsewhere (series rods, overflow). The solvers' chord steps
/// evaluate their trials with it: half the instructions of q + J there (1.8k against 3.6k on
/// the paper's box), and no slower path where the estimate fails.
pub(crate) fn tip_by_closed_form(a: &PlanarParams) -> Option<PlanarPose> {
    if check_params(a).is_err() || series_first(a) {
        return None;
    }
    let mut closed = Closed::<f64>::straight(a[0], a[1], a[2]);
    if !closed.complete(a[0], a[1], a[2], false) || closed.needs_series() != SeriesNeed::None {
        return None;
    }
    let [x, y, theta] = closed.pose(1.0);
    let tip = PlanarPose::new(x, y, theta);
    tip.is_finite().then_some(tip)
}

/// Tip pose q(1, a): the closed form (docs/math.md §1–§3), or the Taylor series for nearly
/// straight, gently bent and tiny rods and wherever the closed form's error estimate fails.
/// In cases I and II with m1, m ≥ 1e-3, 1e-2 the closed form places the tip by the addition
/// theorems without computing its phase (~18 % fewer instructions on the paper's box), so it
/// may differ from [`evaluate`]'s tip in the last bits (both within the closed form's pose
/// bound, `tip_without_the_phase_within_the_pose_bound`).
pub fn tip(a: &PlanarParams) -> Result<PlanarPose, RodError> {
    dispatch::tip(a)
}

/// Pose q(t, a) and J(t, a) = ∂q(t)/∂a (rows x, y, θ; columns a3, a4, a5), exact up to
/// rounding: the closed form evaluated in forward-mode dual numbers, or, for nearly straight,
/// gently bent and tiny rods (ρ ≤ 0.25) and wherever the closed form's error estimate fails
/// (near the separatrix, at small m, gently bent rods: see `Closed::needs_series`),
/// the Taylor series in dual numbers (double-double where rounding grows like e^{√‖F‖}).
/// docs/math.md §4 asks for such a fallback.
pub fn pose_and_jacobian(
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    RodError::check_finite("t", &[t])?;
    dispatch::pose_and_jacobian(a, t)
}

/// Largest estimated error (ε·e^{√‖F‖}) of the f64 series for which a solver's iterations
/// use it: beyond (√‖F‖ ≳ 22), the f64 tip has fewer than six correct digits and Newton steps
/// from it are noise (strong-tension rods, a4 ~ 1e3, were left unsolved).
const ITERATION_F64_MAX_ERROR: f64 = 1e-6;

/// Whether iterations near `a` need the double-double series near the separatrix
/// (ε·e^{√‖F‖} > [`ITERATION_F64_MAX_ERROR`]). Solvers decide this once per start, from the
/// start: a start in the strong-tension regime iterates precisely (a few ms per evaluation),
/// while an iterate that wanders there from an ordinary start keeps the cheap f64 evaluation
/// and fails fast instead of spending the deadline.
pub(crate) fn needs_precise_iterations(a: &PlanarParams) -> bool {
    crate::scalar::fast_hypot(a[1], a[2]).sqrt().exp() * f64::EPSILON > ITERATION_F64_MAX_ERROR
}

/// q(1) and J(1, a) for the iterations of a solver: as [`tip_and_jacobian`] except on
/// ill-conditioned rods (near the separatrix) when `precise` is false, where the f64 series
/// replaces the double-double one (≈ 100× cheaper, errors ε·e^{√‖F‖}, see
/// [`needs_precise_iterations`]). Solvers verify their answer with [`tip_and_jacobian`].
pub(crate) fn tip_and_jacobian_for_iteration(
    a: &PlanarParams,
    precise: bool,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    let precision = if precise {
        Precision::Answer
    } else {
        Precision::Iteration
    };
    dispatch::solver_tip_and_jacobian(a, precision)
}

/// q(1) and J(1, a) for the intermediate poses of a continuation
/// (`RodModel::tip_and_jacobian_for_substep`): the closed form wherever its error estimate is
/// within 100× an answer's tolerance ([`Precision::Substep`]), else [`tip_and_jacobian`].
pub(crate) fn tip_and_jacobian_for_substep(
    a: &PlanarParams,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    dispatch::solver_tip_and_jacobian(a, Precision::Substep)
}

/// Tip pose q(1, a) and J(1, a) (see [`pose_and_jacobian`]).
pub fn tip_and_jacobian(a: &PlanarParams) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jacobian(a, 1.0)
}

/// Stability of the equilibrium a (Bretl & McCarthy; docs/math.md §5): stable iff det J(t, a) > 0
/// on (0, 1]. g(t) = det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) is scanned on a grid whose spacing
/// follows the rod's wavelength (from t = 0.02 on the closed form, 0.01 on the series; below,
/// det J > 0 by its leading term), sign changes are located to 1e-7 and local minima refined;
/// on the closed form every sample also gives g′(t) (d det J/dt = det[J_x; J_y; ∂κ/∂a]), which
/// finds minima between samples and steers those refinements (half-wavelength grid). The margin is docs/math.md §5 `det_min`, min over t ∈ [0.05, 1] of g; the report is
/// `uncertain` when it lies within its error bound (the closed form first hands such rods to
/// the series). The straight rod (a3 = a5 = 0) has det J ≡ 0: uncertain, margin 0.
///
/// Theory settles what rounding cannot (Sachkov, "Conjugate points in Euler's elastic
/// problem", 2008): a rod whose curvature keeps its sign (λ4 < 0, circles, or λ4 > 0 with no
/// inflection point on (0, 1]) has no conjugate point, so it is reported stable and certain,
/// its margin the scan's (floored at 0). Negative values of g within their error bound
/// before the first conjugate point can come are rounding and carry no sign in the scan.
pub fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    dispatch::stability(a)
}

/// The stability verdict alone: the outcome of [`stability`]`(a)?.`[`verdict`](
/// StabilityReport::verdict)`()` (equal on 14,000 rods of six families), without the margin
/// or the conjugate point, for callers that only keep or reject a rod (a planner sampling
/// configurations, a stable-target generator). Where a theorem or the sign of det J(1)
/// decides (64 % of the paper's box) it skips the scan, and elsewhere scans only from the
/// first inflection point on (so it may decide a rod whose full scan is uncertain only
/// before that point, where the theorem rules out a conjugate point): ~3× faster on the box
/// (`rod-ig bench`, "stability test, verdict").
///
/// ```
/// use rod_ig_core::{planar, PlanarParams, StabilityVerdict};
/// let a = PlanarParams::new(2.0, -10.0, 5.0);
/// assert_eq!(planar::stability_verdict(&a)?, StabilityVerdict::Stable);
/// assert_eq!(planar::stability_verdict(&a)?, planar::stability(&a)?.verdict());
/// # Ok::<(), rod_ig_core::RodError>(())
/// ```
pub fn stability_verdict(a: &PlanarParams) -> Result<StabilityVerdict, RodError> {
    dispatch::verdict(a)
}

/// Elastic energy ½∫₀¹κ² (docs/math.md §1 identity λ2/2 − a4 x(1) − a5 y(1) where its bound holds;
/// the small-angle expansion, ζ or the series elsewhere).
pub fn energy(a: &PlanarParams) -> Result<f64, RodError> {
    dispatch::energy(a)
}

/// Tip, J(1, a), energy and stability in one call (one precomputation shared by all).
pub fn evaluate(a: &PlanarParams) -> Result<Evaluation, RodError> {
    dispatch::evaluation(a)
}

impl PlanarRod {
    /// Precomputes the rod for a. Errors: [`RodError::NonFinite`] if a component of a is NaN
    /// or ±∞; every refusal of [`evaluate`](crate::planar::evaluate) (one domain: beyond ‖(a4, a5)‖ = 625 the full
    /// evaluation runs first, and its tip is the shape's); [`RodError::Overflow`] where the
    /// shape cannot be represented in f64 (its series beyond √‖(a4, a5)‖ = ln(f64::MAX), the
    /// one kind of rod forward answers and the shape does not: `tests/domain.rs`).
    pub fn new(a: &PlanarParams) -> Result<Self, RodError> {
        // Forward's refusals are the shape's too (one domain; NaN and ±∞ count as beyond, and
        // the evaluation refuses them); its tip is the shape's.
        let known = if dispatch::beyond_ordinary_force(a) {
            Some(dispatch::domain_evaluation(a)?)
        } else {
            None
        };
        let rod = dispatch::shape(a)?;
        Ok(match known {
            Some(e) => rod.with_tip(e.tip),
            None => rod,
        })
    }
}
