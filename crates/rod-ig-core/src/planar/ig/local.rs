//! Globalised Newton from one start (the robust solver's inner loop).
//!
//! Newton direction p = −J(1, a)⁻¹ f(a) (paper eq. 3.1), then backtracking on the merit ‖f‖
//! (Armijo-type sufficient decrease), with two safeguards:
//! - a trust box on the step in parameter space (|Δa3| ≤ 4, |Δa4|, |Δa5| ≤ 40), so that one
//!   step cannot jump across several solution branches;
//! - a trial is rejected when det J(1, a) ≤ 0. Along a continuous path in a, a conjugate point
//!   can only enter (0, 1] through t = 1 (the index of the second variation changes only when
//!   det J(1, a) = 0), so the sign of det J(1, a) — free with the Jacobian — is the cheap guard
//!   that keeps short steps inside the stable set A_stable (paper §3.1). The full test of
//!   FINDINGS §5 is applied to the converged point by the caller.
//!
//! The weighted scaling a ↦ (s a3, s² a4, s² a5) maps the rod on [0, s] to the unit rod, so
//! det J(t, a(s)) has the sign of det J(s t, a): scaling by s < t₁ (the first conjugate time)
//! brings any a into the stable set ([`pull_into_stable`]).

use super::newton::{eval, Eval};
use super::scan;
use crate::planar::model::solve3;
use crate::planar::model::Precision;
use crate::solver::{emit, Event};
use crate::{PlanarParams, PlanarPose};

/// Outcome of one local solve.
pub(crate) struct Local {
    /// Converged point and its evaluation (not yet checked by the full stability test).
    pub found: Option<(PlanarParams, Eval)>,
    /// Accepted Newton steps.
    pub iterations: u32,
    /// Evaluations of Υ and J.
    pub evaluations: u32,
    /// ‖f‖ at the last accepted iterate.
    pub residual: f64,
    /// Last accepted iterate.
    pub last_a: PlanarParams,
    /// Why it stopped without converging.
    pub stop: Stop,
}

/// Why a local solve stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stop {
    Converged,
    /// Start is non-finite or not in the stable set (det J(1, a0) ≤ 0).
    BadStart,
    /// Backtracking found no acceptable step.
    Stalled,
    MaxIterations,
    /// The solve's deadline passed.
    Deadline,
}

impl Stop {
    /// The error a start that stopped this way reports (through the robust solver's
    /// `NoStableSolution::last`) after `iterations` iterations.
    pub(crate) fn to_error(self, iterations: u32) -> super::IgError {
        use super::IgError;
        match self {
            // A converged point that failed the verification or the full stability test.
            Stop::Converged | Stop::BadStart => IgError::LeftStableSet {
                iteration: iterations,
            },
            Stop::Stalled => IgError::Stalled {
                iteration: iterations,
            },
            Stop::MaxIterations => IgError::MaxIterations { iterations },
            Stop::Deadline => IgError::Deadline {
                iteration: iterations,
            },
        }
    }
}

/// Half-width in a3 of the box a step may move in (trust region of one Newton/LM step). a3 is
/// a moment and a4, a5 forces: the paper's sampling box is |a3| ≤ 2π, |a4|, |a5| ≤ 100, so
/// the box keeps the same ratio of about 1:10 ([`MAX_DA45`]), ~2/3 and ~2/5 of each half-range.
/// An engineering choice, not a derivation: it bounds how far one step can jump across
/// branches while leaving Newton's full step free in the interior of the box.
pub(crate) const MAX_DA3: f64 = 4.0;
/// Trials of the backtracking on the Newton direction before switching to LM steps.
const NEWTON_TRIALS: usize = 5;
/// LM trials (μ × 10 each) per iteration.
const LM_TRIALS: usize = 10;
/// Half-width in a4 and a5 of the box a step may move in (see [`MAX_DA3`]).
pub(crate) const MAX_DA45: f64 = 40.0;

/// Runs the globalised Newton from `a0` for at most `max_iterations` accepted steps.
pub(crate) fn solve(
    target: &PlanarPose,
    a0: &PlanarParams,
    alpha: f64,
    max_iterations: u32,
    tolerance: f64,
) -> Local {
    solve_predicted(target, a0, None, alpha, max_iterations, tolerance)
}

/// As [`solve`], with an optional predicted first iterate `(a1, r0)`: a Newton step from `a0`
/// computed from an already known J(1, a0) (atlas seed, previous tracking solution), where `r0`
/// is the known (or estimated) ‖f(a0)‖. It is taken when it is in A_stable's det J(1) > 0 side
/// and decreases the residual below `r0`; otherwise the solve starts from `a0`. A taken
/// prediction counts as one iteration.
pub(crate) fn solve_predicted(
    target: &PlanarPose,
    a0: &PlanarParams,
    predicted: Option<(PlanarParams, f64)>,
    alpha: f64,
    max_iterations: u32,
    tolerance: f64,
) -> Local {
    if let Some((a1, r0)) = predicted {
        if max_iterations > 0 {
            if let Some(e1) = eval(&a1, target, Precision::for_start(a0)) {
                if e1.jac.determinant() > 0.0 && e1.norm < (1.0 - 1e-4) * r0 {
                    emit(Event::Iteration {
                        iteration: 1,
                        residual: r0,
                        step: (a1 - a0).norm(),
                        alpha: 1.0,
                    });
                    let precision = Precision::for_start(a0);
                    let mut out = run(
                        target,
                        a1,
                        e1,
                        precision,
                        alpha,
                        max_iterations - 1,
                        tolerance,
                    );
                    out.iterations += 1;
                    out.evaluations += 1;
                    return out;
                }
            }
            let mut out = solve(target, a0, alpha, max_iterations, tolerance);
            out.evaluations += 1;
            return out;
        }
    }
    let out = Local {
        found: None,
        iterations: 0,
        evaluations: 1,
        residual: f64::INFINITY,
        last_a: *a0,
        stop: Stop::BadStart,
    };
    let precision = Precision::for_start(a0);
    match eval(a0, target, precision) {
        Some(e) if e.jac.determinant() > 0.0 => {
            let mut out = run(target, *a0, e, precision, alpha, max_iterations, tolerance);
            out.evaluations += 1;
            out
        }
        _ => out,
    }
}

/// The iteration proper, from an evaluated start (`evaluations` excludes the start's), every
/// evaluation at the start's `precision`.
fn run(
    target: &PlanarPose,
    a0: PlanarParams,
    e0: Eval,
    precision: Precision,
    alpha: f64,
    max_iterations: u32,
    tolerance: f64,
) -> Local {
    let mut out = Local {
        found: None,
        iterations: 0,
        evaluations: 0,
        residual: e0.norm,
        last_a: a0,
        stop: Stop::BadStart,
    };
    let mut a = a0;
    let mut e = e0;
    let mut mu = 0.0f64;
    let alpha = if alpha > 0.0 && alpha <= 1.0 {
        alpha
    } else {
        1.0
    };
    loop {
        if e.pos_err <= tolerance && e.ang_err <= tolerance {
            out.stop = Stop::Converged;
            out.found = Some((a, e));
            return out;
        }
        if out.iterations >= max_iterations {
            out.stop = Stop::MaxIterations;
            return out;
        }
        if crate::solver::deadline::expired() {
            out.stop = Stop::Deadline;
            return out;
        }
        let mut accepted = None;
        // 1. Newton direction with backtracking (paper eq. 3.1, globalised).
        if let Ok(p) = solve3(&e.jac, &e.f) {
            let size = (p[0].abs() / MAX_DA3)
                .max(p[1].abs() / MAX_DA45)
                .max(p[2].abs() / MAX_DA45);
            let mut lambda = if size > 1.0 { alpha / size } else { alpha };
            for _ in 0..NEWTON_TRIALS {
                let trial = a - lambda * p;
                out.evaluations += 1;
                if let Some(et) = eval(&trial, target, precision) {
                    if et.jac.determinant() > 0.0 && et.norm <= (1.0 - 1e-4 * lambda) * e.norm {
                        accepted = Some((trial, et, lambda));
                        break;
                    }
                    // Quadratic model of ‖f‖² along the step: φ(λ) ≈ φ0 − 2λφ0 + cλ² (the
                    // Newton direction has slope −2φ0 for φ = ‖f‖²); its minimiser, bounded.
                    let phi0 = e.norm * e.norm;
                    let phil = et.norm * et.norm;
                    if phil.is_finite() && et.jac.determinant() > 0.0 {
                        let c = (phil - phi0 + 2.0 * lambda * phi0) / (lambda * lambda);
                        let lnew = if c > 0.0 { phi0 / c } else { 0.5 * lambda };
                        lambda = lnew.clamp(0.1 * lambda, 0.5 * lambda);
                        continue;
                    }
                }
                lambda *= 0.3;
            }
        }
        // 2. Levenberg–Marquardt steps (JᵀJ + μ diag(JᵀJ)) p = Jᵀf when the Newton direction
        //    fails (ill-conditioned J near the fold det J(1, a) = 0, where Newton steps point
        //    across the stability boundary): μ grows until a step is accepted.
        if accepted.is_none() {
            let jtj = e.jac.transpose() * e.jac;
            let g = e.jac.transpose() * e.f;
            let dmax = jtj.diagonal().max();
            let diag = jtj.diagonal().map(|v| v.max(1e-12 * dmax));
            if mu.is_nan() || mu <= 0.0 {
                mu = 1e-3;
            }
            for _ in 0..LM_TRIALS {
                let mut m = jtj;
                for q in 0..3 {
                    m[(q, q)] += mu * diag[q];
                }
                let Ok(p) = solve3(&m, &g) else {
                    mu *= 10.0;
                    continue;
                };
                let size = (p[0].abs() / MAX_DA3)
                    .max(p[1].abs() / MAX_DA45)
                    .max(p[2].abs() / MAX_DA45);
                let p = if size > 1.0 { p / size } else { p };
                let trial = a - p;
                out.evaluations += 1;
                if let Some(et) = eval(&trial, target, precision) {
                    if et.jac.determinant() > 0.0 && et.norm <= (1.0 - 1e-4) * e.norm {
                        accepted = Some((trial, et, 1.0));
                        mu *= 0.1;
                        break;
                    }
                }
                mu *= 10.0;
            }
        }
        match accepted {
            Some((na, ne, factor)) => {
                out.iterations += 1;
                emit(Event::Iteration {
                    iteration: out.iterations,
                    residual: e.norm,
                    step: (na - a).norm(),
                    alpha: factor,
                });
                a = na;
                e = ne;
                out.residual = e.norm;
                out.last_a = a;
            }
            None => {
                out.stop = Stop::Stalled;
                return out;
            }
        }
    }
}

/// Brings `a` into the stable set by the weighted scaling a ↦ (s a3, s² a4, s² a5) with
/// s = 0.9 t₁, t₁ the first conjugate time of `a` (FINDINGS §5 rule on an RK4 scan).
/// Returns `a` unchanged when it is already stable, `None` when the scan fails.
pub(crate) fn pull_into_stable(a: &PlanarParams) -> Option<PlanarParams> {
    let s = scan::scan(a, scan::steps_for(a, 8.0))?;
    match s.first_conjugate_t {
        None if s.stable => Some(*a),
        Some(t1) => {
            let s = 0.9 * t1;
            Some(PlanarParams::new(s * a[0], s * s * a[1], s * s * a[2]))
        }
        None => None,
    }
}
