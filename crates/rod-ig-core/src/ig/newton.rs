//! The paper's inverse geometry (§3.1): Newton's method with a fixed step length α,
//! p_k = −α J(1, a_k)⁻¹ f(a_k), a_{k+1} = a_k + p_k (eq. 3.1), f(a) = Υ(a) − b.
//!
//! Protocol of FINDINGS §8: every iterate (a0 included) must be a stable equilibrium
//! (det J(t, a) > 0 on (0, 1]); the run fails as soon as one is not. Convergence: position
//! error and wrapped angle error both ≤ tolerance. A NaN residual never counts as converged.

use super::model::Precision;
use super::{model, Failure, IgError, Solution};
use crate::{PlanarJacobian, PlanarParams, PlanarPose};
use nalgebra::Vector3;

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

/// One evaluated iterate.
pub(crate) struct Eval {
    pub tip: PlanarPose,
    pub jac: PlanarJacobian,
    pub f: Vector3<f64>,
    pub pos_err: f64,
    pub ang_err: f64,
    pub norm: f64,
}

pub(crate) fn eval(a: &PlanarParams, target: &PlanarPose, precision: Precision) -> Option<Eval> {
    eval_from(model::tip_and_jacobian(a, precision).ok()?, target)
}

/// The converged iterate `a` re-evaluated at full accuracy: Some when it still meets the
/// tolerance (iterations may use a cheaper evaluation on ill-conditioned rods).
pub(crate) fn verify(a: &PlanarParams, target: &PlanarPose, tolerance: f64) -> Option<Eval> {
    let e = eval_from(model::tip_and_jacobian_precise(a).ok()?, target)?;
    (e.pos_err <= tolerance && e.ang_err <= tolerance).then_some(e)
}

fn eval_from((tip, jac): (PlanarPose, PlanarJacobian), target: &PlanarPose) -> Option<Eval> {
    let f = model::residual(&tip, target);
    if !(f.iter().all(|v| v.is_finite()) && jac.iter().all(|v| v.is_finite())) {
        return None;
    }
    let pos_err = f[0].hypot(f[1]);
    let ang_err = f[2].abs();
    Some(Eval {
        tip,
        jac,
        f,
        pos_err,
        ang_err,
        norm: f.norm(),
    })
}

pub(crate) fn make_solution(
    a: &PlanarParams,
    e: &Eval,
    stable: bool,
    margin: f64,
    iterations: u32,
) -> Solution {
    Solution {
        a: *a,
        tip: e.tip,
        stable,
        stability_margin: margin,
        iterations,
        position_error: e.pos_err,
        orientation_error: e.ang_err,
        residual: e.norm,
        energy: model::energy_from_tip(a, &e.tip),
        evaluations: iterations + 1,
        starts: 1,
        elapsed_us: 0.0,
    }
}

/// The paper's Newton (§3.1) from `a0`, FINDINGS §8 protocol. `iterations` counts Newton steps
/// taken (0 when a0 already solves the problem).
pub(crate) fn solve(
    target: &PlanarPose,
    a0: &PlanarParams,
    alpha: f64,
    max_iterations: u32,
    tolerance: f64,
) -> Result<Solution, Failure> {
    let mut a = *a0;
    let precision = Precision::for_start(a0);
    let mut last_res = f64::INFINITY;
    let fail = |reason, k, res, a| Failure {
        reason,
        iterations: k,
        residual: res,
        last_a: Some(a),
        elapsed_us: 0.0,
    };
    let mut k: u32 = 0;
    loop {
        if super::deadline::expired() {
            return Err(fail(IgError::Deadline { iteration: k }, k, last_res, a));
        }
        let e = match eval(&a, target, precision) {
            Some(e) => e,
            None => {
                return Err(fail(
                    IgError::NonFinite {
                        iteration: k,
                        detail: "Υ(a), J(1, a) or the residual is not finite".into(),
                    },
                    k,
                    last_res,
                    a,
                ))
            }
        };
        last_res = e.norm;
        let st = match model::stability(&a) {
            Ok(s) => s,
            Err(err) => {
                return Err(fail(
                    IgError::NonFinite {
                        iteration: k,
                        detail: format!("stability test failed: {err}"),
                    },
                    k,
                    last_res,
                    a,
                ))
            }
        };
        if !st.stable {
            return Err(fail(
                IgError::LeftStableSet { iteration: k },
                k,
                last_res,
                a,
            ));
        }
        if e.pos_err <= tolerance && e.ang_err <= tolerance {
            if let Some(e) = verify(&a, target, tolerance) {
                return Ok(make_solution(&a, &e, true, st.margin, k));
            }
        }
        if k >= max_iterations {
            return Err(fail(
                IgError::MaxIterations {
                    iterations: max_iterations,
                },
                k,
                last_res,
                a,
            ));
        }
        match solve3(&e.jac, &e.f) {
            Ok(p) => a -= alpha * p,
            Err(det) => {
                return Err(fail(
                    IgError::SingularJacobian { iteration: k, det },
                    k,
                    last_res,
                    a,
                ))
            }
        }
        k += 1;
    }
}
