//! Planar inverse geometry (paper §3): given a tip pose b = (x, y, θ) of the unit rod whose
//! base is at the identity, find a = (a3, a4, a5) such that the rod is a *stable* equilibrium
//! and Υ(a) = b, θ compared modulo 2π.
//!
//! Two methods:
//! - [`Method::Newton`], the paper's method (§3.1, eq. 3.1): a_{k+1} = a_k − α J(1, a_k)⁻¹ f(a_k)
//!   with f(a) = Υ(a) − b (angle wrapped), fixed step length α, from a given a0, at most N
//!   iterations, and the docs/math.md §8 protocol: an iterate fails as soon as it is unstable.
//! - [`Method::Robust`] (default): a globalised Newton (backtracking on ‖f‖, Levenberg–Marquardt
//!   steps when the Newton direction fails; steps that make det J(1, a) non-positive are
//!   rejected, since the stable set can only be left through det J(1, a) = 0), multi-started
//!   from a precomputed atlas of stable rods indexed by their tip (each seed carrying J⁻¹, so the
//!   first step is free), with small-angle starts for targets near full extension and a final
//!   polishing of the best iterate; where that fails, Newton from a second atlas of the rods
//!   beyond the box (|a3| ≤ 36, |a4|, |a5| ≤ 300), then the branches of the seeds nearest the
//!   target followed to it ([`BRANCH_STEPS`]). The stability test (docs/math.md §5) is applied to
//!   every solution before it is returned. The caller's initial guess goes first when its
//!   residual is no larger than the nearest seed's (it then selects the solution branch). A
//!   failure says what was searched ([`IgError::SearchExhausted`]).
//!
//! The atlases (~78 k and ~98 k seeds, ~20 MB) are built once per process on first need, in
//! steps charged to the deadline of the call that needs them; call [`warm_up`] at start-up to
//! take that cost (≈ 0.45 s on two cores) out of the first solves.
//!
//! [`solve_all`] lists the distinct stable solutions found; [`Objective::LeastEnergy`] returns the
//! least elastic energy among them. [`Tracker`] follows a stream of nearby targets.

pub(crate) mod atlas;
mod fronts;
mod local;
mod newton;
mod robust;
mod scan;
mod straight;
mod tracker;

use crate::planar::model::{PlanarClosedForm, PlanarReference};
use crate::solver::{Found, InverseGeometry};
use crate::{PlanarParams, PlanarPose};

pub use robust::BRANCH_STEPS;
pub use tracker::Tracker;

/// The inverse-geometry error of every model ([`crate::solver::IgError`]).
pub use crate::solver::IgError;
pub use crate::solver::{
    Method, Objective, Termination, DEFAULT_DEADLINE, MAX_DEADLINE, MAX_ITERATIONS_LIMIT,
    MAX_TOLERANCE, MIN_TOLERANCE,
};

/// Options of the planar [`solve`], [`solve_all`] and [`Tracker`].
pub type SolveOptions = crate::solver::SolveOptions<PlanarParams>;
/// A planar solution ([`crate::solver::Solution`] with a ∈ ℝ³ and the planar tip pose).
pub type Solution = crate::solver::Solution<PlanarParams, PlanarPose>;
/// A failed planar solve.
pub type Failure = crate::solver::Failure<PlanarParams>;

pub use crate::planar::model::check_target;

/// Solves the planar inverse geometry for `target` with the closed forms: shorthand for
/// [`crate::solver::solve`] on [`PlanarClosedForm`].
///
/// With [`Method::Robust`] every returned solution is stable (checked by the docs/math.md §5 test)
/// and within `tolerance` of the target in position and in wrapped angle.
/// With [`Method::Newton`] this is the paper's fixed-step Newton (§3.1) under the docs/math.md §8
/// protocol; its result is stable too, since every iterate is tested.
pub fn solve(target: &PlanarPose, options: &SolveOptions) -> Result<Solution, Failure> {
    crate::solver::solve(&PlanarClosedForm, target, options)
}

/// All distinct stable solutions found for `target`, least energy first: shorthand for
/// [`crate::solver::solve_all`] on [`PlanarClosedForm`].
pub fn solve_all(target: &PlanarPose, options: &SolveOptions) -> Vec<Solution> {
    crate::solver::solve_all(&PlanarClosedForm, target, options)
}

fn found(all: robust::All) -> Found<PlanarParams, PlanarPose> {
    Found {
        solutions: all.solutions,
        iterations: all.iterations,
        evaluations: all.evaluations,
        starts: all.starts,
    }
}

impl InverseGeometry<3> for PlanarClosedForm {
    fn robust(&self, target: &PlanarPose, options: &SolveOptions) -> Result<Solution, Failure> {
        robust::solve(target, options)
    }

    fn robust_all(
        &self,
        target: &PlanarPose,
        options: &SolveOptions,
    ) -> Found<PlanarParams, PlanarPose> {
        found(robust::solve_all(target, options, None))
    }

    fn default_start(&self, target: &PlanarPose) -> Option<PlanarParams> {
        atlas::nearest(target)
    }
}

/// The closed-form answer polished by the reference integrator: the paper's Newton (α = 1) on
/// [`PlanarReference`] from `s.a`, so that the returned rod solves the reference model's
/// equations to the tolerance and passes its stability test.
fn polish_by_reference(
    model: &PlanarReference,
    target: &PlanarPose,
    s: &Solution,
    options: &SolveOptions,
) -> Result<Solution, Failure> {
    let newton_options = SolveOptions {
        alpha: 1.0,
        max_iterations: options.max_iterations.min(REFERENCE_POLISH_ITERATIONS),
        ..*options
    };
    let mut p = crate::solver::newton::solve(model, target, &s.a, &newton_options)?;
    p.iterations += s.iterations;
    p.evaluations += s.evaluations;
    p.starts = s.starts;
    Ok(p)
}

/// Newton steps of the reference polish: the closed-form answer is within ~1e-12 of the
/// reference one, so one or two steps of quadratic convergence suffice; 8 allows for a loose
/// reference `rtol`.
const REFERENCE_POLISH_ITERATIONS: u32 = 8;

impl InverseGeometry<3> for PlanarReference {
    /// The closed forms' robust search (its atlas and starts), then the answer polished and
    /// verified by the reference integrator.
    fn robust(&self, target: &PlanarPose, options: &SolveOptions) -> Result<Solution, Failure> {
        let s = robust::solve(target, options)?;
        polish_by_reference(self, target, &s, options)
    }

    fn robust_all(
        &self,
        target: &PlanarPose,
        options: &SolveOptions,
    ) -> Found<PlanarParams, PlanarPose> {
        let mut f = found(robust::solve_all(target, options, None));
        f.solutions = f
            .solutions
            .iter()
            .filter_map(|s| polish_by_reference(self, target, s, options).ok())
            .collect();
        f
    }

    fn default_start(&self, target: &PlanarPose) -> Option<PlanarParams> {
        atlas::nearest(target)
    }
}

/// Builds the solver's two atlases of stable rods now, whatever the time it takes (≈ 0.45 s on
/// two cores). Returns their number of entries.
///
/// Without it the box atlas is built on the first robust solve, and the one beyond the box
/// on the first solve that needs it, in steps of ≈ 0.5 ms charged to that call's deadline: a
/// first call with a short deadline returns
/// [`Termination::Deadline`] and the next calls resume the build. A process that serves
/// requests calls this at start-up (or on a background thread: requests share the build).
pub fn warm_up() -> usize {
    atlas::get_blocking(atlas::Tier::Box).len() + atlas::get_blocking(atlas::Tier::Beyond).len()
}
