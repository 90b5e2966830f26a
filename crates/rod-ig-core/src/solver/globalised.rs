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
//!    stability boundary): μ grows tenfold until a step is accepted and shrinks tenfold after;
//! 3. **chord steps** near convergence (‖f‖ ≤ [`CHORD_MAX_NORM`]), where the problem offers
//!    its residual without J ([`Problem::evaluate_residual`]: the planar tip alone, at half
//!    the cost of tip and J; the 3-D rod does not, as its solves got slower with tip-only
//!    integrations, median 255 against 220 µs). The trial a − J⁻¹f keeps the last J, and is
//!    taken when it converged or divided ‖f‖ by 4 at least (Newton's fast phase, where the
//!    chord converges like ‖f‖ itself: Kelley, *Iterative Methods for Linear and Nonlinear
//!    Equations*, §5.4, the chord and Shamanskii methods). At most [`CHORD_MAX_STEPS`] in a
//!    row; the first trial that falls short ends them for the run, and the point reached is
//!    evaluated fully (or, when it left the stable set, the run goes back to the last fully
//!    evaluated one). Chord iterates are not checked against the stable set: every caller
//!    tests its converged point with the full stability test, and a chord step moves a by
//!    ~‖J⁻¹‖·‖f‖ ≤ 1e-2·‖J⁻¹‖.
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

    /// Whether [`Problem::evaluate_residual`] is offered (chord steps, module docs): where the
    /// residual alone is not much cheaper than [`Problem::evaluate`], not (the default).
    const OFFERS_RESIDUAL: bool = false;

    /// The trial point `a` (reached from an iterate of merit `from`) evaluated without its
    /// Jacobian, for chord steps (module docs): `jacobian` is the J the run keeps, to be stored
    /// in the iterate. `None` where `a` cannot be evaluated that way (or nothing is offered,
    /// the default): the run then stops taking chord steps.
    fn evaluate_residual(
        &mut self,
        _a: &SVector<f64, N>,
        _from: f64,
        _jacobian: &SMatrix<f64, N, N>,
    ) -> Result<Option<Iterate<N, Self::Data>>, IgError> {
        Ok(None)
    }
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
/// Merit at or below which the run tries chord steps (module docs). The planar and 3-D
/// residuals are tip errors of the unit rod (lengths and radians): at 1e-2, Newton from a
/// stable start is in its fast phase on the benchmark's targets, and a step that is not
/// costs one residual evaluation before the run goes back to full ones.
pub(crate) const CHORD_MAX_NORM: f64 = 1e-2;
/// Largest ‖f(trial)‖/‖f(a)‖ for which a chord trial that did not converge is taken.
const CHORD_CONTRACTION: f64 = 0.25;
/// Chord steps at most in a row.
pub(crate) const CHORD_MAX_STEPS: u32 = 3;

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
    /// Chord steps that led to `last` (module docs): when > 0, `last.jacobian` is J at the
    /// iterate before them, and `last.data` is the problem's residual-only evaluation.
    pub chord_steps: u32,
}

/// The chord steps' bookkeeping within one run.
struct Chord<const N: usize, D> {
    /// Still tried: the problem offered residual evaluations and no chord trial fell short.
    open: bool,
    /// The last fully evaluated iterate before the current chord steps.
    fresh: Option<(SVector<f64, N>, Iterate<N, D>)>,
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
        chord_steps: 0,
    };
    let mut mu = 0.0f64;
    let mut chord = Chord {
        open: true,
        fresh: None,
    };
    loop {
        if let Some(stop) = stop_before_step(problem, &state, settings) {
            state.stop = stop;
            return Ok(state);
        }
        if chord_step(problem, &mut state, &mut chord, settings)? {
            continue;
        }
        if state.chord_steps > 0 {
            refresh(problem, &mut state, &mut chord)?;
            continue;
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
    } else if crate::deadline::expired() {
        Some(Stop::Deadline)
    } else {
        None
    }
}

/// An accepted step: the new point, its evaluation and the step factor used.
type Accepted<const N: usize, D> = Option<(SVector<f64, N>, Iterate<N, D>, f64)>;

/// Step 3 (tried first near convergence): one chord step, taken (true) or not.
fn chord_step<const N: usize, P: Problem<N>>(
    problem: &mut P,
    state: &mut Run<N, P::Data>,
    chord: &mut Chord<N, P::Data>,
    settings: &Settings,
) -> Result<bool, IgError> {
    if !P::OFFERS_RESIDUAL
        || !chord.open
        || state.chord_steps >= CHORD_MAX_STEPS
        || state.last.norm.is_nan()
        || state.last.norm > CHORD_MAX_NORM
        || state.evaluations >= settings.max_evaluations
    {
        return Ok(false);
    }
    let jacobian = state.last.jacobian;
    let Some(p) = problem.solve(&jacobian, &state.last.f) else {
        return Ok(false);
    };
    let trial = state.a - p / problem.step_scale(&state.a, &p).max(1.0);
    let Some(mut x) = problem.evaluate_residual(&trial, state.last.norm, &jacobian)? else {
        chord.open = false;
        return Ok(false);
    };
    state.evaluations += 1;
    let contracted = x.norm <= CHORD_CONTRACTION * state.last.norm;
    if !contracted && !problem.converged(&x) {
        chord.open = false;
        return Ok(false);
    }
    x.jacobian = jacobian;
    state.iterations += 1;
    emit(Event::Iteration {
        iteration: state.iterations,
        residual: state.last.norm,
        step: (trial - state.a).norm(),
        alpha: 1.0,
    });
    let from = std::mem::replace(&mut state.a, trial);
    let before = std::mem::replace(&mut state.last, x);
    if state.chord_steps == 0 {
        chord.fresh = Some((from, before));
    }
    state.chord_steps += 1;
    Ok(true)
}

/// After chord steps that ended short of convergence: the point reached evaluated fully, so
/// that Newton and LM steps have its J; when it left the stable set (or cannot be
/// evaluated), the run goes back to the last fully evaluated iterate.
fn refresh<const N: usize, P: Problem<N>>(
    problem: &mut P,
    state: &mut Run<N, P::Data>,
    chord: &mut Chord<N, P::Data>,
) -> Result<(), IgError> {
    state.chord_steps = 0;
    state.evaluations += 1;
    let fresh = chord.fresh.take();
    match problem.evaluate(&state.a, state.last.norm)? {
        Some(x) => state.last = x,
        None => {
            if let Some((a, x)) = fresh {
                state.a = a;
                state.last = x;
            }
        }
    }
    Ok(())
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    /// f(a) = (a0² + a1 − 3, a0 + a1³ − 9), root a* = (1, 2): a toy with the chord steps' two
    /// evaluations counted apart. `evaluate` refuses points with a0 > `reject` (a stable
    /// set's boundary); residual-only evaluations fail (not finite) from the `fail_from`-th on
    /// (a chord trial that falls short).
    struct Toy {
        reject: f64,
        fail_from: u32,
        full: u32,
        residual_only: u32,
    }

    fn toy_f(a: &Vector2<f64>) -> Vector2<f64> {
        Vector2::new(a[0] * a[0] + a[1] - 3.0, a[0] + a[1].powi(3) - 9.0)
    }

    fn toy_j(a: &Vector2<f64>) -> Matrix2<f64> {
        Matrix2::new(2.0 * a[0], 1.0, 1.0, 3.0 * a[1] * a[1])
    }

    const TOL: f64 = 1e-12;

    impl Problem<2> for Toy {
        type Data = ();
        const OFFERS_RESIDUAL: bool = true;

        fn evaluate(
            &mut self,
            a: &Vector2<f64>,
            _from: f64,
        ) -> Result<Option<Iterate<2, ()>>, IgError> {
            self.full += 1;
            if a[0] > self.reject {
                return Ok(None);
            }
            let f = toy_f(a);
            Ok(Some(Iterate {
                f,
                norm: f.norm(),
                jacobian: toy_j(a),
                data: (),
            }))
        }

        fn converged(&self, x: &Iterate<2, ()>) -> bool {
            x.norm <= TOL
        }

        fn step_scale(&self, _a: &Vector2<f64>, _p: &Vector2<f64>) -> f64 {
            1.0
        }

        fn solve(&self, m: &Matrix2<f64>, r: &Vector2<f64>) -> Option<Vector2<f64>> {
            m.lu().solve(r)
        }

        fn evaluate_residual(
            &mut self,
            a: &Vector2<f64>,
            _from: f64,
            jacobian: &Matrix2<f64>,
        ) -> Result<Option<Iterate<2, ()>>, IgError> {
            let scale = if self.residual_only >= self.fail_from {
                f64::INFINITY
            } else {
                1.0
            };
            self.residual_only += 1;
            let f = toy_f(a) * scale;
            Ok(Some(Iterate {
                f,
                norm: f.norm(),
                jacobian: *jacobian,
                data: (),
            }))
        }
    }

    /// Residual-only evaluations offered (and sound) from the `fail_from`-th on.
    fn toy(fail_from: u32) -> Toy {
        Toy {
            reject: f64::INFINITY,
            fail_from,
            full: 0,
            residual_only: 0,
        }
    }

    fn run_toy(p: &mut Toy, a0: Vector2<f64>) -> Run<2, ()> {
        let x0 = p.evaluate(&a0, f64::INFINITY).unwrap().unwrap();
        let settings = Settings {
            alpha: 1.0,
            max_iterations: 50,
            max_evaluations: 200,
        };
        run(p, a0, x0, &settings).unwrap()
    }

    #[test]
    fn chord_steps_reach_the_same_root_with_fewer_full_evaluations() {
        let a0 = Vector2::new(1.3, 1.7);
        // Failing from the first on, residual-only evaluations end the chord steps at once: the
        // run is Newton's, one residual-only evaluation aside.
        let (mut newton, mut chord) = (toy(0), toy(u32::MAX));
        let (rn, rc) = (run_toy(&mut newton, a0), run_toy(&mut chord, a0));
        assert_eq!(rn.stop, Stop::Converged);
        assert_eq!(rc.stop, Stop::Converged);
        assert_eq!(rn.chord_steps, 0);
        assert!(rc.chord_steps >= 1, "no chord step taken");
        // Both within the tolerance of the root (1, 2): J is well conditioned there (‖J⁻¹‖ < 1).
        for r in [&rn, &rc] {
            assert!(
                (r.a - Vector2::new(1.0, 2.0)).norm() <= 10.0 * TOL,
                "{:?}",
                r.a
            );
        }
        // Residual-only evaluations replace full ones near the root, one for one at most.
        assert!(
            chord.full < newton.full,
            "{} vs {}",
            chord.full,
            newton.full
        );
        assert!(chord.full + chord.residual_only <= newton.full + CHORD_MAX_STEPS);
    }

    #[test]
    fn a_chord_trial_that_falls_short_hands_back_to_newton() {
        // Residual-only evaluations that fail never show the contraction: the first chord
        // trial ends them, and Newton converges on full evaluations.
        let mut p = toy(0);
        let r = run_toy(&mut p, Vector2::new(1.3, 1.7));
        assert_eq!(r.stop, Stop::Converged);
        assert_eq!(r.chord_steps, 0);
        assert_eq!(
            p.residual_only, 1,
            "chord trials after the first that fell short"
        );
        assert!((r.a - Vector2::new(1.0, 2.0)).norm() <= 10.0 * TOL);
    }

    #[test]
    fn a_chord_point_outside_the_stable_set_goes_back_to_the_last_full_iterate() {
        // `evaluate` refuses a0 > 0.999 (the stable set's boundary, short of the root (1, 2)).
        // The first chord trial, from (0.99, 2.01), lands past it (residual-only evaluations do
        // not check it) and is taken; the second falls short (its evaluation fails). The
        // refresh of the chord point is refused: the run goes back to the last full iterate
        // and ends on the stable side, its last iterate a full one.
        let reject = 1.0 - 1e-3;
        let mut p = Toy { reject, ..toy(1) };
        let r = run_toy(&mut p, Vector2::new(0.99, 2.01));
        assert_eq!(p.residual_only, 2);
        assert_eq!(r.chord_steps, 0);
        assert!(r.a[0] <= reject, "{:?}", r.a);
        assert_ne!(r.stop, Stop::Converged);
    }
}
