//! One inverse-geometry API for every rod model.
//!
//! - **Models** ([`RodModel`]): what a rod provides — Υ(a), J(1, a), the stability verdict with
//!   its margin, the energy, the parameter scale. Each model lives beside its physics:
//!   [`PlanarClosedForm`](crate::planar::PlanarClosedForm) (paper §2),
//!   [`PlanarReference`](crate::planar::PlanarReference) (the reference integrator) and
//!   [`Spatial`](crate::spatial::Spatial) (the 3-D rod). This module knows none of them.
//! - **Strategies**, chosen by [`SolveOptions`]: the paper's Newton with step length α
//!   ([`Method::Newton`], written once for every model), the robust multi-start search
//!   ([`Method::Robust`], each model's [`InverseGeometry::robust`]), the least-energy
//!   objective and the list of all solutions ([`solve_all`]), both written once on top of the
//!   model's search; a deadline on every call.
//! - **Outcomes**: one [`Solution`], one [`Failure`] with one error enum [`IgError`] and its
//!   typed [`Termination`].
//! - **Observers** ([`observe`]): watch the starts and iterations of any solve.
//!
//! ```
//! use rod_ig_core::solver::{self, SolveOptions};
//! use rod_ig_core::planar::PlanarClosedForm;
//! use rod_ig_core::spatial::Spatial;
//! use rod_ig_core::spatial::SpatialPose;
//! use rod_ig_core::PlanarPose;
//!
//! // Planar: the closed forms (the atlas of stable rods built first, outside the deadline).
//! rod_ig_core::planar::ig::warm_up();
//! let s = solver::solve(&PlanarClosedForm, &PlanarPose::new(0.5, 0.4, 1.0), &SolveOptions::default())
//!     .expect("a reachable target");
//! assert!(s.stable && s.position_error <= 1e-6);
//!
//! // 3-D: the same call on another model.
//! let target = SpatialPose::from_xyzw([0.6, 0.2, 0.3].into(), [0.1, 0.2, 0.3, 0.9]).unwrap();
//! let s = solver::solve(&Spatial::default(), &target, &SolveOptions::default()).unwrap();
//! assert!(s.stable && s.orientation_error <= 1e-6);
//! ```

mod continuation;
pub(crate) mod globalised;
pub mod load;
mod model;
pub(crate) mod newton;
mod observer;
mod options;
mod outcome;

pub(crate) use continuation::branch_to;
pub use continuation::{
    BranchEvent, BranchFollower, Move, CORRECTOR_ITERATIONS, MAX_SNAPS, MIN_STEP, SUBSTEP_TOLERANCE,
};
pub use model::{relative_distance, ModelEvaluation, RodModel, DISTINCT};
pub(crate) use observer::emit;
pub use observer::{observe, Counters, Event, IterationLog, Observer};
pub use options::{
    check_options, Method, Objective, SolveOptions, DEFAULT_DEADLINE, DEFAULT_DEADLINE_3D,
    DEFAULT_MAX_ITERATIONS, DEFAULT_TOLERANCE, MAX_DEADLINE, MAX_ITERATIONS_LIMIT, MAX_TOLERANCE,
    MIN_TOLERANCE,
};
pub use outcome::{Failure, IgError, Searched, Solution, Termination, Verified, Work};

use nalgebra::SVector;

/// The solution type of model `M`.
pub type SolutionOf<const N: usize, M> = Solution<SVector<f64, N>, <M as RodModel<N>>::Pose>;
/// The failure type of an N-parameter model.
pub type FailureOf<const N: usize> = Failure<SVector<f64, N>>;

/// Every distinct stable solution a model's search found, and the work it took.
#[derive(Clone, Debug, PartialEq)]
pub struct Found<P, X> {
    /// The solutions, unsorted.
    pub solutions: Vec<Solution<P, X>>,
    /// Newton iterations over every start.
    pub iterations: u32,
    /// Evaluations over every start.
    pub evaluations: u32,
    /// Starts tried.
    pub starts: u32,
}

/// A model's own multi-start search (its seeds, globalisation and verification): the part of
/// the robust strategy that depends on the model. The strategies of this module call it with
/// the deadline and observer already in place.
pub trait InverseGeometry<const N: usize>: RodModel<N> {
    /// The first stable solution the model's robust search finds; every returned solution
    /// passed the model's stability test and meets the tolerance.
    fn robust(
        &self,
        target: &Self::Pose,
        options: &SolveOptions<SVector<f64, N>>,
    ) -> Result<SolutionOf<N, Self>, FailureOf<N>>;

    /// Every distinct stable solution reachable from the model's starts near the target.
    fn robust_all(
        &self,
        target: &Self::Pose,
        options: &SolveOptions<SVector<f64, N>>,
    ) -> Found<SVector<f64, N>, Self::Pose>;

    /// The start of the paper's Newton when the caller gives none.
    fn default_start(&self, target: &Self::Pose) -> Option<SVector<f64, N>>;

    /// The paper's Newton from `a0` ([`Method::Newton`]): the generic Newton on this model,
    /// unless the model iterates on another formulation (the long cables' node states).
    fn newton(
        &self,
        target: &Self::Pose,
        a0: &SVector<f64, N>,
        options: &SolveOptions<SVector<f64, N>>,
    ) -> Result<SolutionOf<N, Self>, FailureOf<N>> {
        newton::solve(self, target, a0, options)
    }
}

/// The paper's Newton on `model` ([`InverseGeometry::newton`]'s default), for a model that
/// overrides it and falls back to it.
pub fn newton_solve<const N: usize, M: RodModel<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    a0: &SVector<f64, N>,
    options: &SolveOptions<SVector<f64, N>>,
) -> Result<SolutionOf<N, M>, FailureOf<N>> {
    newton::solve(model, target, a0, options)
}

fn check<const N: usize, M: InverseGeometry<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
) -> Result<(), IgError> {
    model.check_target(target)?;
    check_options(options)?;
    model.check_settings()
}

/// Solves the inverse geometry of `model` for `target` (unit rod, base at the identity).
///
/// With [`Method::Robust`] every returned solution is stable (the model's stability test)
/// and within `tolerance` of the target in position and orientation; with
/// [`Objective::LeastEnergy`] it is the least energetic of the solutions found. With
/// [`Method::Newton`] this is the paper's fixed-step Newton (§3.1) under the docs/math.md §8
/// protocol; its result is stable too, since every iterate is tested. No call runs past
/// `options.deadline`.
pub fn solve<const N: usize, M: InverseGeometry<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
) -> Result<SolutionOf<N, M>, FailureOf<N>> {
    let t0 = std::time::Instant::now();
    let result = match check(model, target, options) {
        Err(e) => Err(Failure::early(e)),
        Ok(()) => {
            let _deadline = crate::deadline::scope(options.deadline);
            dispatch(model, &model.canonical_target(target), options)
        }
    };
    let elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
    let (termination, iterations, starts) = match &result {
        Ok(s) => (Termination::Converged, s.iterations, s.starts),
        Err(f) => (f.termination(), f.iterations, f.starts),
    };
    emit(Event::Finished {
        termination,
        iterations,
        starts,
        elapsed_us,
    });
    match result {
        Ok(mut s) => {
            s.elapsed_us = elapsed_us;
            Ok(s)
        }
        Err(mut f) => {
            f.elapsed_us = elapsed_us;
            Err(f)
        }
    }
}

fn dispatch<const N: usize, M: InverseGeometry<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
) -> Result<SolutionOf<N, M>, FailureOf<N>> {
    match (options.method, options.objective) {
        (Method::Newton, _) => {
            let Some(a0) = options
                .initial_guess
                .or_else(|| model.default_start(target))
            else {
                // No default start: the model's tables were not ready within the deadline, or
                // it has none for this target.
                let reason = if crate::deadline::expired() {
                    IgError::Deadline { iteration: 0 }
                } else {
                    IgError::NoStableSolution {
                        starts: 0,
                        last: None,
                    }
                };
                return Err(Failure::early(reason));
            };
            model.newton(target, &a0, options)
        }
        (Method::Robust, Objective::FirstFound) => model.robust(target, options),
        (Method::Robust, Objective::LeastEnergy) => {
            // The first-found search first (its wider start list and polishing find a solution
            // wherever the default objective does), then every start near the target with the
            // time left; the least energy among all of them.
            let first = model.robust(target, options);
            let all = model.robust_all(target, options);
            let (fi, fe, fs) = first
                .as_ref()
                .map_or((0, 0, 0), |f| (f.iterations, f.evaluations, f.starts));
            let best = all
                .solutions
                .into_iter()
                .chain(first.as_ref().ok().copied())
                .min_by(|a, b| a.energy.total_cmp(&b.energy));
            // Read once both searches returned: a deadline passed by then may have cut them.
            let complete = !crate::deadline::expired();
            match best {
                Some(mut s) => {
                    s.iterations = all.iterations + fi;
                    s.evaluations = all.evaluations + fe;
                    s.starts = all.starts + fs;
                    // A search that cannot prove it found every rod says so itself.
                    s.complete = complete && s.complete;
                    Ok(s)
                }
                None => first,
            }
        }
    }
}

/// Every distinct stable solution a search found ([`solve_every`]), least energy first.
#[derive(Clone, Debug, PartialEq)]
pub struct Every<P, X> {
    /// The solutions, sorted by energy.
    pub solutions: Vec<Solution<P, X>>,
    /// The search tried every start: false when the deadline passed before it was known to
    /// have finished (solutions may be missing from the list).
    pub complete: bool,
}

/// All distinct stable solutions found for `target` ([`solve_every`] without its `complete`
/// flag).
pub fn solve_all<const N: usize, M: InverseGeometry<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
) -> Vec<SolutionOf<N, M>> {
    solve_every(model, target, options).solutions
}

/// All distinct stable solutions found for `target` (the model's starts near the target, the
/// initial guess first if any), sorted by energy, and whether the search ran to its end.
/// Never empty where [`solve`] with the same options succeeds (its solution is included);
/// empty when the target or options are invalid or no stable solution is found.
pub fn solve_every<const N: usize, M: InverseGeometry<N> + ?Sized>(
    model: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
) -> Every<SVector<f64, N>, M::Pose> {
    if check(model, target, options).is_err() {
        return Every {
            solutions: Vec::new(),
            complete: true,
        };
    }
    let t0 = std::time::Instant::now();
    let _deadline = crate::deadline::scope(options.deadline);
    let target = &model.canonical_target(target);
    let found = model.robust_all(target, options);
    let mut solutions = found.solutions;
    let mut iterations = found.iterations;
    let mut starts = found.starts;
    // The first-found search's wider start list may reach a branch the local search missed.
    if let Ok(s) = model.robust(target, options) {
        iterations += s.iterations;
        starts += s.starts;
        let scale = model.param_scale();
        if solutions
            .iter()
            .all(|o| relative_distance(&o.a, &s.a, &scale) > DISTINCT)
        {
            solutions.push(s);
        }
    }
    solutions.sort_by(|a, b| a.energy.total_cmp(&b.energy));
    let complete = !crate::deadline::expired();
    emit(Event::Finished {
        termination: if solutions.is_empty() {
            Termination::NoStableSolution
        } else {
            Termination::Converged
        },
        iterations,
        starts,
        elapsed_us: t0.elapsed().as_secs_f64() * 1e6,
    });
    Every {
        solutions,
        complete,
    }
}
