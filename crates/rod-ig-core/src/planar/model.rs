//! The planar rod as a model of the solvers ([`RodModel`], paper §2 and §3.1): the closed
//! forms ([`PlanarClosedForm`]) and the reference integrator ([`PlanarReference`], DOP853 on the
//! ODE of paper eq. 2.9 with variational equations), the target check, the residual
//! f(a) = Υ(a) − b (paper §3.1; the only residual of the planar solvers) and what their
//! iterations evaluate.

use crate::solver::{IgError, ModelEvaluation, RodModel};
use crate::{wrap_angle, PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};
use nalgebra::{SMatrix, Vector3};

/// Checks the target: finite, and ‖(x, y)‖ < 1 (the unit rod is inextensible; the straight rod
/// at distance 1 is unstable, docs/math.md §5).
pub fn check_target(target: &PlanarPose) -> Result<(), IgError> {
    for (component, value) in [("x", target.x), ("y", target.y), ("theta", target.theta)] {
        if !value.is_finite() {
            return Err(IgError::NonFiniteTarget { component, value });
        }
    }
    let distance = target.x.hypot(target.y);
    if distance >= 1.0 {
        return Err(IgError::Unreachable { distance });
    }
    Ok(())
}

/// Solves J p = r. `None` when J is numerically singular: |det J| below 1e-14 times the
/// product of its column norms (Hadamard bound), or a non-finite result.
pub(crate) fn solve3(j: &PlanarJacobian, r: &Vector3<f64>) -> Result<Vector3<f64>, f64> {
    let det = j.determinant();
    let hadamard = j.column(0).norm() * j.column(1).norm() * j.column(2).norm();
    if !(det.is_finite() && hadamard.is_finite()) || det.abs() <= 1e-14 * hadamard || det == 0.0 {
        return Err(det);
    }
    // Cramer's rule via the adjugate: exact enough for a well-conditioned 3×3 and branch-free.
    let c0 = j.column(0);
    let c1 = j.column(1);
    let c2 = j.column(2);
    let x0 = r.dot(&c1.cross(&c2)) / det;
    let x1 = c0.dot(&r.cross(&c2)) / det;
    let x2 = c0.dot(&c1.cross(r)) / det;
    let p = Vector3::new(x0, x1, x2);
    if p.iter().all(|v| v.is_finite()) {
        Ok(p)
    } else {
        Err(det)
    }
}

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
        if crate::planar::entry::needs_precise_iterations(a0) {
            Self::Precise
        } else {
            Self::Fast
        }
    }
}

/// Υ(a) and J(1, a) (rows x, y, θ; columns a3, a4, a5), for iterations (see [`Precision`] and
/// `planar::tip_and_jacobian_for_iteration`).
#[inline]
pub(crate) fn tip_and_jacobian_for_iteration(
    a: &PlanarParams,
    precision: Precision,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    crate::planar::entry::tip_and_jacobian_for_iteration(a, precision == Precision::Precise)
}

/// Υ(a), J(1, a), energy and the stability test at full accuracy from one precomputation.
#[inline]
pub(crate) fn evaluate_precise(
    a: &PlanarParams,
) -> Result<crate::planar::entry::Evaluation, RodError> {
    crate::planar::entry::evaluate(a)
}

/// Elastic energy ½∫κ² from the tip, by the identity of docs/math.md §1:
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

/// An iterate of a run from `start` by the closed forms at the precision that start needs
/// ([`Precision`]); stability by the full docs/math.md §5 test.
fn evaluate_iterate(
    a: &PlanarParams,
    start: &PlanarParams,
) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
    let (tip, jacobian) = tip_and_jacobian_for_iteration(a, Precision::for_start(start))?;
    Ok(ModelEvaluation {
        tip,
        jacobian,
        energy: energy_from_tip(a, &tip),
        stability: super::stability(a)?,
        full_accuracy: false,
    })
}

/// J δa = r for the planar 3×3 J: `Err(det)` when |det J| is below 1e-14 times the product of
/// its column norms (Hadamard bound) or the result is not finite.
pub(crate) fn planar_increment(
    jacobian: &SMatrix<f64, 3, 3>,
    r: &Vector3<f64>,
) -> Result<Vector3<f64>, f64> {
    solve3(jacobian, r)
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
    let f = residual(tip, target);
    (f[0].hypot(f[1]), f[2].abs())
}

/// The pose geometry every planar model shares (the tip pose (x, y, θ), the residual of paper
/// §3.1 with the angle wrapped): the same methods in each planar model's `RodModel` impl.
macro_rules! planar_geometry {
    () => {
        fn param_scale(&self) -> Vector3<f64> {
            Vector3::from(PLANAR_SCALE)
        }

        fn is_straight(&self, a: &Vector3<f64>) -> bool {
            a[0] == 0.0 && a[2] == 0.0
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
            planar_increment(jacobian, &-residual(tip, target))
        }

        fn check_target(&self, target: &PlanarPose) -> Result<(), IgError> {
            check_target(target)
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
        crate::planar::entry::tip(a)
    }

    fn tip_and_jacobian(&self, a: &Vector3<f64>) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        crate::planar::entry::tip_and_jacobian(a)
    }

    fn tip_and_jacobian_for_substep(
        &self,
        a: &Vector3<f64>,
    ) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        crate::planar::entry::tip_and_jacobian_for_substep(a)
    }

    fn evaluate(&self, a: &Vector3<f64>) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        crate::planar::entry::evaluate(a)
    }

    fn evaluate_iterate(
        &self,
        a: &Vector3<f64>,
        start: &Vector3<f64>,
    ) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        evaluate_iterate(a, start)
    }

    fn stability(&self, a: &Vector3<f64>) -> Result<StabilityReport, RodError> {
        crate::planar::entry::stability(a)
    }

    fn energy(&self, a: &Vector3<f64>) -> Result<f64, RodError> {
        crate::planar::entry::energy(a)
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

    fn tip_and_jacobian(&self, a: &Vector3<f64>) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        crate::ode::planar_reference::tip_and_jacobian(a, self.rtol)
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
