//! The paper's inverse geometry (§3.1) for any [`RodModel`]: Newton's method with a fixed
//! step length α, a_{k+1} = a_k + α δa_k with J(1, a_k) δa_k = b − Υ(a_k) (eq. 3.1; 3-D: the
//! body-frame twist error), from one guess.
//!
//! Protocol of docs/math.md §8: every iterate (a0 included) must be a stable equilibrium
//! (det J(t, a) > 0 on (0, 1]); the run fails as soon as one is not. Convergence: position
//! error and orientation error both ≤ tolerance, confirmed at the model's full accuracy. A NaN
//! residual never counts as converged.

use super::model::{ModelEvaluation, RodModel};
use super::observer::{emit, Event};
use super::{
    Failure, FailureOf, IgError, Solution, SolutionOf, SolveOptions, Termination, Verified, Work,
};
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
    let mut k: u32 = 0;
    loop {
        let fail = |reason, residual| Failure {
            reason,
            iterations: k,
            residual,
            last_a: Some(a),
            starts: 1,
            elapsed_us: 0.0,
        };
        if crate::deadline::expired() {
            return Err(fail(IgError::Deadline { iteration: k }, residual));
        }
        evaluations += 1;
        let (e, errors) =
            stable_iterate(model, target, &a, a0, k).map_err(|r| fail(r, residual))?;
        residual = errors.0.hypot(errors.1);
        if errors.0 <= options.tolerance && errors.1 <= options.tolerance {
            if let Some(mut s) = verified(model, target, &a, e, options, &mut evaluations) {
                s.iterations = k;
                s.evaluations = evaluations;
                return Ok(s);
            }
        }
        if k >= options.max_iterations {
            let iterations = options.max_iterations;
            return Err(fail(IgError::MaxIterations { iterations }, residual));
        }
        let d = model
            .newton_increment(&e.tip, &e.jacobian, target)
            .map_err(|det| fail(IgError::SingularJacobian { iteration: k, det }, residual))?;
        a += options.alpha * d;
        k += 1;
        emit(Event::Iteration {
            iteration: k,
            residual,
            step: options.alpha * d.norm(),
            alpha: options.alpha,
        });
    }
}

/// An iterate's evaluation with its (position, orientation) errors.
type Checked<const N: usize, X> = (ModelEvaluation<N, X>, (f64, f64));

/// Iterate `k` evaluated (at the precision the run from `a0` uses) with its (position,
/// orientation) errors; an error when it is not finite or not stable (docs/math.md §8: the run
/// fails as soon as an iterate is unstable).
fn stable_iterate<const N: usize, M: RodModel<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    a: &SVector<f64, N>,
    a0: &SVector<f64, N>,
    k: u32,
) -> Result<Checked<N, M::Pose>, IgError> {
    let e = model
        .evaluate_iterate(a, a0)
        .map_err(|err| IgError::of_evaluation(k, &err))?;
    let errors = model.pose_error(&e.tip, target);
    if !(errors.0.hypot(errors.1).is_finite() && e.jacobian.iter().all(|v| v.is_finite())) {
        return Err(IgError::Evaluation {
            iteration: k,
            detail: "Υ(a), J(1, a) or the residual is not finite".to_string(),
        });
    }
    if !e.stability.stable {
        return Err(IgError::LeftStableSet { iteration: k });
    }
    Ok((e, errors))
}

/// The converged iterate `a` as a solution, confirmed at the model's full accuracy (one more
/// evaluation when the iterate's was cheaper): `None` when it no longer meets the tolerance or
/// is not stable there.
fn verified<const N: usize, M: RodModel<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    a: &SVector<f64, N>,
    e: ModelEvaluation<N, M::Pose>,
    options: &SolveOptions<SVector<f64, N>>,
    evaluations: &mut u32,
) -> Option<SolutionOf<N, M>> {
    let v = if e.full_accuracy {
        e
    } else {
        *evaluations += 1;
        model.evaluate(a).ok()?
    };
    let (pe, oe) = model.pose_error(&v.tip, target);
    let verified = Verified {
        tip: v.tip,
        errors: (pe, oe),
        energy: v.energy,
        margin: v.stability.margin,
    };
    let work = Work {
        iterations: 0,
        evaluations: *evaluations,
        starts: 1,
    };
    (pe <= options.tolerance && oe <= options.tolerance && v.stability.stable)
        .then(|| Solution::new(*a, verified, work))
}
