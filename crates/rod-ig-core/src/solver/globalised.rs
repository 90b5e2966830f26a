//! The globalised Newton / Levenberg–Marquardt iteration, written once for every model's
//! search (the planar local solver behind the atlas starts, the 3-D damped Newton).
//!
//! From an evaluated iterate a with residual f(a) = Υ(a) − b (in the model's error
//! coordinates) and J = J(1, a):
//! 1. **Newton direction** p = J⁻¹ f (paper eq. 3.1), limited to the problem's step box, then
//!    backtracking on the merit ‖f‖ with sufficient decrease ‖f(a − λp)‖ ≤ (1 − 1e-4 λ)‖f(a)‖;
//!    a rejected trial shrinks λ by the minimiser of the quadratic model of ‖f‖² along the step
//!    (bounded to [0.1 λ, 0.5 λ]), or by 0.3 when it left the stable set or failed;
//! 2. **Levenberg–Marquardt** steps (JᵀJ + μ diag(JᵀJ)) p = Jᵀ f when no Newton trial is
//!    accepted (J ill-conditioned near a fold det J = 0, where Newton steps point across the
//!    stability boundary): μ grows tenfold until a step is accepted and shrinks tenfold after.
//!
//! Trial points that leave the stable set are rejected by the problem ([`Problem::evaluate`]
//! returns `None`), so every accepted iterate stays on the start's side of the boundary.

use super::{emit, Event, IgError};
use nalgebra::{SMatrix, SVector};

/// One evaluated iterate.
pub(crate) struct Iterate<const N: usize, D> {
    /// f(a) = Υ(a) − b in the model's error coordinates.
    pub f: SVector<f64, N>,
    /// ‖f(a)‖₂: the merit.
    pub norm: f64,
    /// J(1, a) in the same coordinates.
    pub jacobian: SMatrix<f64, N, N>,
    /// The model's own evaluation, handed back with the result.
    pub data: D,
}

/// What a run needs from the model's search.
pub(crate) trait Problem<const N: usize> {
    /// The model's evaluation kept with each iterate.
    type Data;

    /// Evaluates the trial point `a` (reached from an iterate of merit `from`): `Ok(None)` when
    /// it is rejected (outside the stable set, or not evaluable), `Err` to stop the run.
    fn evaluate(
        &mut self,
        a: &SVector<f64, N>,
        from: f64,
    ) -> Result<Option<Iterate<N, Self::Data>>, IgError>;

    /// The iterate meets the tolerance.
    fn converged(&self, x: &Iterate<N, Self::Data>) -> bool;

    /// The divisor (≥ 1) that brings the step `p` from `a` within the region one step may
    /// cover (a trust box in the model's parameter scale): 1 when `p` is inside.
    fn step_scale(&self, a: &SVector<f64, N>, p: &SVector<f64, N>) -> f64;

    /// Solves m x = r; `None` when m is numerically singular or x is not finite.
    fn solve(&self, m: &SMatrix<f64, N, N>, r: &SVector<f64, N>) -> Option<SVector<f64, N>>;
}

/// The knobs of one run.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Settings {
    /// First step length of the backtracking (the paper's α ∈ (0, 1]).
    pub alpha: f64,
    /// Accepted steps at most.
    pub max_iterations: u32,
    /// Evaluations at most (trials included).
    pub max_evaluations: u32,
}

/// Trials of the backtracking on the Newton direction before switching to LM steps.
pub(crate) const NEWTON_TRIALS: usize = 5;
/// LM trials (μ × [`LM_GROW`] each) per iteration.
pub(crate) const LM_TRIALS: usize = 10;
/// First damping μ of the LM steps (relative to diag(JᵀJ)).
const LM_INITIAL_MU: f64 = 1e-3;
/// Factor on μ after a rejected LM trial.
const LM_GROW: f64 = 10.0;
/// Factor on μ after an accepted LM step.
const LM_SHRINK: f64 = 0.1;
/// Sufficient decrease of the merit (Armijo constant).
const ARMIJO: f64 = 1e-4;
/// Step factor after a trial that left the stable set or failed.
const REJECTED_SHRINK: f64 = 0.3;

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stop {
    /// The last iterate meets the tolerance.
    Converged,
    /// No acceptable step: neither backtracking nor LM decreased the merit.
    Stalled,
    /// `max_iterations` accepted steps.
    MaxIterations,
    /// `max_evaluations` evaluations.
    Budget,
    /// The solve's deadline passed.
    Deadline,
}

/// The outcome of one run.
pub(crate) struct Run<const N: usize, D> {
    /// The last accepted iterate and its evaluation.
    pub a: SVector<f64, N>,
    pub last: Iterate<N, D>,
    /// Accepted steps.
    pub iterations: u32,
    /// Evaluations (trials included, the start's excluded).
    pub evaluations: u32,
    /// Why it ended.
    pub stop: Stop,
    /// Whether the last rejected trial left the stable set (for the caller's reason).
    pub last_trial_rejected: bool,
}

/// Runs the iteration from the evaluated start (`a0`, `x0`). `Err` only from the problem.
pub(crate) fn run<const N: usize, P: Problem<N>>(
    problem: &mut P,
    a0: SVector<f64, N>,
    x0: Iterate<N, P::Data>,
    settings: &Settings,
) -> Result<Run<N, P::Data>, IgError> {
    let alpha = if settings.alpha > 0.0 && settings.alpha <= 1.0 {
        settings.alpha
    } else {
        1.0
    };
    let mut state = Run {
        a: a0,
        last: x0,
        iterations: 0,
        evaluations: 0,
        stop: Stop::Stalled,
        last_trial_rejected: false,
    };
    let mut mu = 0.0f64;
    loop {
        if let Some(stop) = stop_before_step(problem, &state, settings) {
            state.stop = stop;
            return Ok(state);
        }
        let accepted = match newton_step(problem, &mut state, alpha, settings)? {
            Some(step) => Some(step),
            None => lm_step(problem, &mut state, &mut mu, settings)?,
        };
        let Some((a, x, factor)) = accepted else {
            state.stop = Stop::Stalled;
            return Ok(state);
        };
        state.iterations += 1;
        emit(Event::Iteration {
            iteration: state.iterations,
            residual: state.last.norm,
            step: (a - state.a).norm(),
            alpha: factor,
        });
        state.a = a;
        state.last = x;
    }
}

/// Why the run stops before its next step, if it does.
fn stop_before_step<const N: usize, P: Problem<N>>(
    problem: &P,
    state: &Run<N, P::Data>,
    settings: &Settings,
) -> Option<Stop> {
    if problem.converged(&state.last) {
        Some(Stop::Converged)
    } else if state.iterations >= settings.max_iterations {
        Some(Stop::MaxIterations)
    } else if state.evaluations >= settings.max_evaluations {
        Some(Stop::Budget)
    } else if super::deadline::expired() {
        Some(Stop::Deadline)
    } else {
        None
    }
}

/// An accepted step: the new point, its evaluation and the step factor used.
type Accepted<const N: usize, D> = Option<(SVector<f64, N>, Iterate<N, D>, f64)>;

/// Step 1: the Newton direction with backtracking.
fn newton_step<const N: usize, P: Problem<N>>(
    problem: &mut P,
    state: &mut Run<N, P::Data>,
    alpha: f64,
    settings: &Settings,
) -> Result<Accepted<N, P::Data>, IgError> {
    let Some(p) = problem.solve(&state.last.jacobian, &state.last.f) else {
        return Ok(None);
    };
    // The trust region shortens the whole step: the backtracking starts at that length.
    let mut lambda = alpha / problem.step_scale(&state.a, &p).max(1.0);
    let norm = state.last.norm;
    for _ in 0..NEWTON_TRIALS {
        if state.evaluations >= settings.max_evaluations {
            break;
        }
        let trial = state.a - lambda * p;
        state.evaluations += 1;
        match problem.evaluate(&trial, norm)? {
            Some(x) if x.norm <= (1.0 - ARMIJO * lambda) * norm => {
                state.last_trial_rejected = false;
                return Ok(Some((trial, x, lambda)));
            }
            Some(x) if x.norm.is_finite() => {
                // Quadratic model of ‖f‖² along the step: φ(λ) ≈ φ0 − 2λφ0 + cλ² (the
                // Newton direction has slope −2φ0 for φ = ‖f‖²); its minimiser, bounded.
                state.last_trial_rejected = false;
                let (phi0, phil) = (norm * norm, x.norm * x.norm);
                let c = (phil - phi0 + 2.0 * lambda * phi0) / (lambda * lambda);
                let next = if c > 0.0 { phi0 / c } else { 0.5 * lambda };
                lambda = next.clamp(0.1 * lambda, 0.5 * lambda);
            }
            other => {
                state.last_trial_rejected = other.is_none();
                lambda *= REJECTED_SHRINK;
            }
        }
    }
    Ok(None)
}

/// Step 2: Levenberg–Marquardt steps, μ growing until one is accepted.
fn lm_step<const N: usize, P: Problem<N>>(
    problem: &mut P,
    state: &mut Run<N, P::Data>,
    mu: &mut f64,
    settings: &Settings,
) -> Result<Accepted<N, P::Data>, IgError> {
    let j = &state.last.jacobian;
    let jtj = j.transpose() * j;
    let g = j.transpose() * state.last.f;
    let dmax = jtj.diagonal().max();
    let diag = jtj.diagonal().map(|v| v.max(1e-12 * dmax));
    if mu.is_nan() || *mu <= 0.0 {
        *mu = LM_INITIAL_MU;
    }
    let norm = state.last.norm;
    for _ in 0..LM_TRIALS {
        if state.evaluations >= settings.max_evaluations {
            break;
        }
        let mut m = jtj;
        for q in 0..N {
            m[(q, q)] += *mu * diag[q];
        }
        let Some(p) = problem.solve(&m, &g) else {
            *mu *= LM_GROW;
            continue;
        };
        let trial = state.a - p / problem.step_scale(&state.a, &p).max(1.0);
        state.evaluations += 1;
        match problem.evaluate(&trial, norm)? {
            Some(x) if x.norm <= (1.0 - ARMIJO) * norm => {
                state.last_trial_rejected = false;
                *mu *= LM_SHRINK;
                return Ok(Some((trial, x, 1.0)));
            }
            other => state.last_trial_rejected = other.is_none(),
        }
        *mu *= LM_GROW;
    }
    Ok(None)
}
