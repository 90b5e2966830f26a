//! Planar inverse geometry (paper §3): given a tip pose b = (x, y, θ) of the unit rod whose
//! base is at the identity, find a = (a3, a4, a5) such that the rod is a *stable* equilibrium
//! and Υ(a) = b, θ compared modulo 2π.
//!
//! Two methods:
//! - [`Method::Newton`], the paper's method (§3.1, eq. 3.1): a_{k+1} = a_k − α J(1, a_k)⁻¹ f(a_k)
//!   with f(a) = Υ(a) − b (angle wrapped), fixed step length α, from a given a0, at most N
//!   iterations, and the FINDINGS §8 protocol: an iterate fails as soon as it is unstable.
//! - [`Method::Robust`] (default): a globalised Newton (backtracking on ‖f‖, Levenberg–Marquardt
//!   steps when the Newton direction fails; steps that make det J(1, a) non-positive are
//!   rejected, since the stable set can only be left through det J(1, a) = 0), multi-started
//!   from a precomputed atlas of stable rods indexed by their tip (each seed carrying J⁻¹, so the
//!   first step is free), with small-angle starts for targets near full extension and a final
//!   polishing of the best iterate; the stability test (FINDINGS §5) is applied to every
//!   solution before it is returned. The caller's initial guess goes first when its residual is
//!   no larger than the nearest seed's (it then selects the solution branch).
//!
//! The atlas (~80 k seeds, ~10 MB) is built once per process on first use, in about half a
//! second; call [`warm_up`] at start-up to take that cost out of the first solve.
//!
//! [`solve_all`] lists the distinct stable solutions found; [`Objective::LeastEnergy`] returns the
//! least elastic energy among them. [`Tracker`] follows a stream of nearby targets.
//! [`mod@bench`] computes the benchmark figures (no I/O; the CLI prints them).

mod atlas;
pub mod bench;
pub(crate) mod deadline;
mod fronts;
mod local;
mod model;
mod newton;
mod robust;
mod scan;
mod straight;
mod tracker;

use crate::{PlanarParams, PlanarPose, RodError};
use thiserror::Error;

pub use tracker::Tracker;

/// Which solver [`solve`] runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// Globalised, multi-start Newton; returns only stable, verified solutions.
    #[default]
    Robust,
    /// The paper's fixed-step Newton (§3.1) with the FINDINGS §8 protocol.
    Newton,
}

/// Which of the solutions found is returned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Objective {
    /// The first stable solution found (fastest).
    #[default]
    FirstFound,
    /// The stable solution of least elastic energy ½∫κ² among those [`solve_all`] finds.
    LeastEnergy,
}

/// Options of [`solve`], [`solve_all`] and [`Tracker`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveOptions {
    /// Solver.
    pub method: Method,
    /// Newton step length α ∈ (0, 1] (paper §3.1). The robust solver starts its backtracking
    /// from this value.
    pub alpha: f64,
    /// Iteration budget (Newton: total; robust: per start).
    pub max_iterations: u32,
    /// Tolerance on the position error ‖(x, y) − (x*, y*)‖ and on the wrapped angle error.
    pub tolerance: f64,
    /// Initial guess a0. Required by the paper's method (when absent, [`Method::Newton`] starts
    /// from the nearest atlas entry); the robust solver tries it first.
    pub initial_guess: Option<PlanarParams>,
    /// Which solution to return.
    pub objective: Objective,
    /// Wall-time budget of one call ([`DEFAULT_DEADLINE`]; at most [`MAX_DEADLINE`]). Every
    /// loop of the solvers polls it; a solve that runs out returns [`IgError::Deadline`].
    pub deadline: std::time::Duration,
}

/// Default wall-time budget of one solve: 250 ms. The robust solver's p99.9 on the uniform box
/// is ≈ 2 ms (`rod-ig bench --only tails`); near full extension and under strong axial force an
/// evaluation costs up to a few ms (the double-double series), and a robust solve there may
/// need ~100 of them. 250 ms cuts only those and pathological requests.
pub const DEFAULT_DEADLINE: std::time::Duration = std::time::Duration::from_millis(250);
/// Largest accepted deadline (10 s): beyond, a request is a mistake, not a budget.
pub const MAX_DEADLINE: std::time::Duration = std::time::Duration::from_secs(10);
/// Largest accepted `max_iterations`: the paper's protocol uses 100, the robust solver ≤ 300
/// per start; 1e5 is far beyond any useful run and bounds the work even without a deadline.
pub const MAX_ITERATIONS_LIMIT: u32 = 100_000;
/// Smallest accepted tolerance: positions of the unit rod carry rounding errors of a few 1e-16
/// (and J-conditioned amplification), so a tolerance below 1e-14 cannot be met reliably.
pub const MIN_TOLERANCE: f64 = 1e-14;

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            method: Method::Robust,
            alpha: 1.0,
            max_iterations: 100,
            tolerance: 1e-6,
            initial_guess: None,
            objective: Objective::FirstFound,
            deadline: DEFAULT_DEADLINE,
        }
    }
}

/// A solution of the inverse geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution {
    /// The rod parameters a* = μ(0).
    pub a: PlanarParams,
    /// Υ(a*), θ unwrapped (∫κ).
    pub tip: PlanarPose,
    /// Verdict of the stability test on a* (always true for the robust solver).
    pub stable: bool,
    /// The stability margin (FINDINGS §5 `det_min`; positive when stable).
    pub stability_margin: f64,
    /// Newton iterations (robust: summed over every start tried).
    pub iterations: u32,
    /// ‖(x, y)(a*) − (x, y)_target‖.
    pub position_error: f64,
    /// |wrap(θ(a*) − θ_target)|.
    pub orientation_error: f64,
    /// ‖f(a*)‖₂ with the angle wrapped.
    pub residual: f64,
    /// Elastic energy ½∫κ² (FINDINGS §1 identity).
    pub energy: f64,
    /// Evaluations of Υ(a) and J(1, a), line-search trials included (robust: over every start).
    pub evaluations: u32,
    /// Number of starts tried (1 for Newton and for a tracker warm start).
    pub starts: u32,
    /// Wall time of the solve, µs.
    pub elapsed_us: f64,
}

/// Why an inverse-geometry solve failed.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum IgError {
    /// A target coordinate is NaN or infinite.
    #[error("target {component} is not finite ({value})")]
    NonFiniteTarget {
        /// "x", "y" or "theta".
        component: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The target position is at or beyond the reach of the inextensible unit rod
    /// (‖(x, y)‖ ≥ 1; distance 1 is only the straight rod, which is not a stable equilibrium).
    #[error("target is unreachable: distance {distance} from the base is >= 1, the rod length")]
    Unreachable {
        /// ‖(x, y)‖ of the target.
        distance: f64,
    },
    /// The initial guess has a non-finite component.
    #[error("initial guess a0[{index}] is not finite ({value})")]
    NonFiniteGuess {
        /// Component index (0 = a3).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The options are unusable (e.g. α ∉ (0, 1], tolerance ≤ 0).
    #[error("invalid options: {0}")]
    InvalidOptions(String),
    /// J(1, a) is singular at an iterate: the Newton step is undefined.
    #[error("Jacobian J(1, a) is singular at iteration {iteration} (|det| = {det:e})")]
    SingularJacobian {
        /// Iteration at which it happened.
        iteration: u32,
        /// det J(1, a) there.
        det: f64,
    },
    /// An iterate is not a stable equilibrium (det J(t, a) ≤ 0 somewhere on (0, 1]).
    #[error("iterate {iteration} left the stable set (det J(t, a) <= 0 on (0, 1])")]
    LeftStableSet {
        /// Iteration of the first unstable iterate (0 = the initial guess).
        iteration: u32,
    },
    /// The residual did not reach the tolerance within the iteration budget.
    #[error("no convergence within {iterations} iterations")]
    MaxIterations {
        /// The budget.
        iterations: u32,
    },
    /// The forward map or the residual became non-finite.
    #[error("non-finite values at iteration {iteration}: {detail}")]
    NonFinite {
        /// Iteration at which it happened.
        iteration: u32,
        /// What was non-finite.
        detail: String,
    },
    /// The solve's deadline ([`SolveOptions::deadline`]) passed before it converged.
    #[error("deadline reached after {iteration} iterations without convergence")]
    Deadline {
        /// Iterations spent.
        iteration: u32,
    },
    /// The robust solver found no stable solution from any of its starts.
    #[error("no stable solution found from {starts} starts (target may be outside the stable workspace)")]
    NoStableSolution {
        /// Starts tried.
        starts: u32,
    },
    /// A forward evaluation failed.
    #[error("rod evaluation failed: {0}")]
    Evaluation(#[from] RodError),
}

/// A failed solve: the reason and where the solver stopped.
#[derive(Clone, Debug, PartialEq, Error)]
#[error("{reason} (after {iterations} iterations, residual {residual:e})")]
pub struct Failure {
    /// Why.
    pub reason: IgError,
    /// Iterations spent.
    pub iterations: u32,
    /// ‖f‖ at the last evaluated iterate (robust solver: the smallest reached by any start;
    /// ∞ when none was evaluated).
    pub residual: f64,
    /// The last iterate (robust solver: where that smallest residual was reached, possibly a
    /// converged but unstable point), when there was one.
    pub last_a: Option<PlanarParams>,
    /// Wall time, µs.
    pub elapsed_us: f64,
}

impl Failure {
    pub(crate) fn early(reason: IgError) -> Self {
        Self {
            reason,
            iterations: 0,
            residual: f64::INFINITY,
            last_a: None,
            elapsed_us: 0.0,
        }
    }
}

/// Checks the target: finite, and ‖(x, y)‖ < 1 (the unit rod is inextensible; the straight rod
/// at distance 1 is unstable, FINDINGS §5).
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

fn check_options(options: &SolveOptions) -> Result<(), IgError> {
    if !(options.alpha > 0.0 && options.alpha <= 1.0) {
        return Err(IgError::InvalidOptions(format!(
            "alpha = {} is not in (0, 1]",
            options.alpha
        )));
    }
    if !(options.tolerance >= MIN_TOLERANCE && options.tolerance.is_finite()) {
        return Err(IgError::InvalidOptions(format!(
            "tolerance = {:e} is not a finite number >= {MIN_TOLERANCE:e} (rounding bound)",
            options.tolerance
        )));
    }
    if options.max_iterations > MAX_ITERATIONS_LIMIT {
        return Err(IgError::InvalidOptions(format!(
            "max_iterations = {} exceeds the limit {MAX_ITERATIONS_LIMIT}",
            options.max_iterations
        )));
    }
    if options.deadline.is_zero() || options.deadline > MAX_DEADLINE {
        return Err(IgError::InvalidOptions(format!(
            "deadline = {:?} is not in (0, {MAX_DEADLINE:?}]",
            options.deadline
        )));
    }
    if let Some(a0) = options.initial_guess {
        if let Some(index) = a0.iter().position(|v| !v.is_finite()) {
            return Err(IgError::NonFiniteGuess {
                index,
                value: a0[index],
            });
        }
    }
    Ok(())
}

/// Solves the inverse geometry for `target` (unit rod, base at the identity).
///
/// With [`Method::Robust`] every returned solution is stable (checked by the FINDINGS §5 test)
/// and within `tolerance` of the target in position and in wrapped angle.
/// With [`Method::Newton`] this is the paper's fixed-step Newton (§3.1) under the FINDINGS §8
/// protocol; its result is stable too, since every iterate is tested.
pub fn solve(target: &PlanarPose, options: &SolveOptions) -> Result<Solution, Failure> {
    let t0 = std::time::Instant::now();
    let stamp = |mut r: Result<Solution, Failure>| {
        let us = t0.elapsed().as_secs_f64() * 1e6;
        match &mut r {
            Ok(s) => s.elapsed_us = us,
            Err(f) => f.elapsed_us = us,
        }
        r
    };
    if let Err(e) = check_target(target).and_then(|_| check_options(options)) {
        return stamp(Err(Failure::early(e)));
    }
    // The atlas is built once per process (≈ 0.5 s): not part of any request's budget.
    let _ = atlas::get();
    let _deadline = deadline::scope(options.deadline);
    let r = match (options.method, options.objective) {
        (Method::Newton, _) => {
            let a0 = match options.initial_guess {
                Some(a0) => a0,
                None => match atlas::nearest(target) {
                    Some(a0) => a0,
                    None => {
                        return stamp(Err(Failure::early(IgError::NoStableSolution { starts: 0 })))
                    }
                },
            };
            newton::solve(
                target,
                &a0,
                options.alpha,
                options.max_iterations,
                options.tolerance,
            )
        }
        (Method::Robust, Objective::FirstFound) => robust::solve(target, options),
        (Method::Robust, Objective::LeastEnergy) => {
            // The first-found search first (its wider start list and polishing find a solution
            // wherever the default objective does), then every start of the target's cell with
            // the time left; the least energy among all of them.
            let first = robust::solve(target, options);
            let all = robust::solve_all(target, options, None);
            let (iterations, evaluations, starts) = (all.iterations, all.evaluations, all.starts);
            let best = all
                .solutions
                .into_iter()
                .chain(first.as_ref().ok().copied())
                .min_by(|a, b| a.energy.total_cmp(&b.energy));
            match (best, first) {
                (Some(mut s), first) => {
                    let (fi, fe, fs) = first
                        .as_ref()
                        .map_or((0, 0, 0), |f| (f.iterations, f.evaluations, f.starts));
                    s.iterations = iterations + fi;
                    s.evaluations = evaluations + fe;
                    s.starts = starts + fs;
                    Ok(s)
                }
                (None, first) => first,
            }
        }
    };
    stamp(r)
}

/// All distinct stable solutions the robust solver finds for `target` (multi-start from the
/// initial guess, if any, and from every atlas entry near the target), sorted by energy.
/// Empty when the target is invalid or none is found.
pub fn solve_all(target: &PlanarPose, options: &SolveOptions) -> Vec<Solution> {
    if check_target(target).is_err() || check_options(options).is_err() {
        return Vec::new();
    }
    let _ = atlas::get();
    let _deadline = deadline::scope(options.deadline);
    let mut v = robust::solve_all(target, options, None).solutions;
    if v.is_empty() {
        // As for least energy: the first-found strategy's wider search, so that "all" is
        // never empty where `solve` succeeds.
        if let Ok(s) = robust::solve(target, options) {
            v.push(s);
        }
    }
    v.sort_by(|a, b| a.energy.total_cmp(&b.energy));
    v
}

/// Builds the solver's atlas of stable rods now (it is otherwise built lazily, once per process,
/// on the first robust solve; this takes a few tens of milliseconds). Returns its number of
/// entries.
pub fn warm_up() -> usize {
    atlas::get().len()
}
