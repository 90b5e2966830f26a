//! The paper's inverse geometry (§3.1) for any [`RodModel`]: Newton's method with a fixed
//! step length α, a_{k+1} = a_k + α δa_k with J(1, a_k) δa_k = b − Υ(a_k) (eq. 3.1; 3-D: the
//! body-frame twist error), from one guess.
//!
//! Protocol of FINDINGS §8: every iterate (a0 included) must be a stable equilibrium
//! (det J(t, a) > 0 on (0, 1]); the run fails as soon as one is not. Convergence: position
//! error and orientation error both ≤ tolerance, confirmed at the model's full accuracy. A NaN
//! residual never counts as converged.

use super::model::RodModel;
use super::observer::{emit, Event};
use super::{Failure, FailureOf, IgError, Solution, SolutionOf, SolveOptions, Termination};
use nalgebra::SVector;

/// The paper's Newton from `a0` (the deadline and observer of the enclosing scope apply).
/// `iterations` counts Newton steps taken (0 when a0 already solves the problem).
pub(crate) fn solve<const N: usize, M: RodModel<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    a0: &SVector<f64, N>,
    options: &SolveOptions<SVector<f64, N>>,
) -> Result<SolutionOf<N, M>, FailureOf<N>> {
    emit(Event::StartBegun {
        index: 0,
        a0_norm: a0.norm(),
    });
    let r = run(model, target, a0, options);
    emit(Event::StartEnded {
        index: 0,
        termination: match &r {
            Ok(_) => Termination::Converged,
            Err(f) => f.reason.termination(),
        },
    });
    r
}

fn run<const N: usize, M: RodModel<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    a0: &SVector<f64, N>,
    options: &SolveOptions<SVector<f64, N>>,
) -> Result<SolutionOf<N, M>, FailureOf<N>> {
    let mut a = *a0;
    let mut residual = f64::INFINITY;
    let mut evaluations = 0;
    let fail = |reason, k, residual, a| Failure {
        reason,
        iterations: k,
        residual,
        last_a: Some(a),
        elapsed_us: 0.0,
    };
    let mut k: u32 = 0;
    loop {
        if crate::solver::deadline::expired() {
            return Err(fail(IgError::Deadline { iteration: k }, k, residual, a));
        }
        evaluations += 1;
        let e = match model.evaluate_iterate(&a, a0) {
            Ok(e) => e,
            Err(err) => {
                let detail = format!("evaluation of iterate failed: {err}");
                let reason = IgError::NonFinite {
                    iteration: k,
                    detail,
                };
                return Err(fail(reason, k, residual, a));
            }
        };
        let (position_error, orientation_error) = model.pose_error(&e.tip, target);
        residual = position_error.hypot(orientation_error);
        let finite = residual.is_finite() && e.jacobian.iter().all(|v| v.is_finite());
        if !finite {
            let detail = "Υ(a), J(1, a) or the residual is not finite".to_string();
            let reason = IgError::NonFinite {
                iteration: k,
                detail,
            };
            return Err(fail(reason, k, residual, a));
        }
        if !e.stability.stable {
            return Err(fail(
                IgError::LeftStableSet { iteration: k },
                k,
                residual,
                a,
            ));
        }
        if position_error <= options.tolerance && orientation_error <= options.tolerance {
            let verified = if e.full_accuracy {
                Some(e)
            } else {
                evaluations += 1;
                model.evaluate(&a).ok()
            };
            if let Some(v) = verified {
                let (pe, oe) = model.pose_error(&v.tip, target);
                if pe <= options.tolerance && oe <= options.tolerance && v.stability.stable {
                    return Ok(Solution {
                        a,
                        tip: v.tip,
                        stable: true,
                        stability_margin: v.stability.margin,
                        iterations: k,
                        position_error: pe,
                        orientation_error: oe,
                        residual: pe.hypot(oe),
                        energy: v.energy,
                        evaluations,
                        starts: 1,
                        elapsed_us: 0.0,
                    });
                }
            }
        }
        if k >= options.max_iterations {
            let reason = IgError::MaxIterations {
                iterations: options.max_iterations,
            };
            return Err(fail(reason, k, residual, a));
        }
        match model.newton_increment(&e.tip, &e.jacobian, target) {
            Ok(d) => {
                a += options.alpha * d;
                k += 1;
                emit(Event::Iteration {
                    iteration: k,
                    residual,
                    step: options.alpha * d.norm(),
                    alpha: options.alpha,
                });
            }
            Err(det) => {
                let reason = IgError::SingularJacobian { iteration: k, det };
                return Err(fail(reason, k, residual, a));
            }
        }
    }
}
