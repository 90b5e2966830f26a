//! How a solve is run: the strategy ([`Method`], [`Objective`]), its knobs, and their limits.

use super::IgError;
use std::time::Duration;

/// Which iteration a solve runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// Globalised, multi-start Newton; returns only stable, verified solutions.
    #[default]
    Robust,
    /// The paper's fixed-step Newton (§3.1, eq. 3.1) from one guess, with the docs/math.md §8
    /// protocol (the run fails as soon as an iterate is unstable).
    Newton,
}

/// Which of the solutions found is returned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Objective {
    /// The first stable solution found (fastest).
    #[default]
    FirstFound,
    /// The stable solution of least elastic energy among those [`super::solve_all`] finds.
    LeastEnergy,
}

/// Options of [`super::solve`] and [`super::solve_all`] for a model with parameters `P`.
/// `SolveOptions::default()` exists for the planar (`Vector3`) and 3-D (`Vector6`)
/// parameters; they differ only in the default deadline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveOptions<P> {
    /// Solver.
    pub method: Method,
    /// Newton step length α ∈ (0, 1] (paper §3.1). The robust solver starts its backtracking
    /// from this value.
    pub alpha: f64,
    /// Iteration budget of one run from one start: Newton, the run; the robust search, each of
    /// its Newton starts (the final polish of the best iterate included). A branch that the
    /// planar search's last stage follows is bounded by its steps instead
    /// ([`crate::planar::ig::BRANCH_STEPS`]). In [1, [`MAX_ITERATIONS_LIMIT`]].
    pub max_iterations: u32,
    /// Tolerance on the position error and on the orientation error (rod lengths, rad). In
    /// [[`MIN_TOLERANCE`], [`MAX_TOLERANCE`]].
    pub tolerance: f64,
    /// Initial guess a0. Required by [`Method::Newton`] (without one, it starts from the
    /// model's default start); the robust solver tries it first.
    pub initial_guess: Option<P>,
    /// Which solution to return.
    pub objective: Objective,
    /// Wall-time budget of one call (at most [`MAX_DEADLINE`]). Every loop of the solvers polls
    /// it; a solve that runs out returns [`IgError::Deadline`].
    pub deadline: Duration,
    /// Starts the robust search tries at most (≥ 1); `None`: the model's search's default
    /// (planar 48, 3-D 12). A setting of the search, not of the model.
    pub max_starts: Option<u32>,
    /// Most full turns of the tangent an answer may make (0, the default: loop-free, and the
    /// centreline must not cross itself). Applied by the long-cable search (planar, w > 200:
    /// [`crate::planar::heavy::cable_search`]); the other searches do not filter by it yet.
    pub max_turns: u32,
}

/// Default wall-time budget of one planar solve: 250 ms. The robust solver's p99.9 on the
/// uniform box is ≈ 2 ms (`rod-ig bench --only tails`); near full extension and under strong
/// axial force an evaluation costs up to a few ms (the double-double series), and a robust
/// solve there may need ~100 of them. 250 ms cuts only those and pathological requests.
pub const DEFAULT_DEADLINE: Duration = Duration::from_millis(250);
/// Default wall-time budget of one 3-D solve: 1 s. The robust 3-D solve takes 0.3 ms median,
/// 1.2 ms p90 on random stable rods (`rod-ig bench --only spatial`); each evaluation integrates
/// 44 variational states, so a hard target may need a few hundred ms.
pub const DEFAULT_DEADLINE_3D: Duration = Duration::from_secs(1);
/// Largest accepted deadline (10 s): beyond, a request is a mistake, not a budget.
pub const MAX_DEADLINE: Duration = Duration::from_secs(10);
/// Largest accepted `max_iterations`: the paper's protocol uses 100, the robust solver ≤ 300
/// per start; 1e5 is far beyond any useful run and bounds the work even without a deadline.
pub const MAX_ITERATIONS_LIMIT: u32 = 100_000;
/// Smallest accepted tolerance: positions of the unit rod carry rounding errors of a few 1e-16
/// (and J-conditioned amplification), so a tolerance below 1e-14 cannot be met reliably.
pub const MIN_TOLERANCE: f64 = 1e-14;
/// Largest accepted tolerance: 1e-2 of the rod length (1 cm on a 1 m cable) and 10 mrad.
/// Beyond it "converged" would call a rod a solution whose tip visibly misses the target.
pub const MAX_TOLERANCE: f64 = 1e-2;
/// Default tolerance: 1e-6 of the rod length (1 µm on a 1 m cable) and 1 µrad.
pub const DEFAULT_TOLERANCE: f64 = 1e-6;
/// Default iteration budget: the paper's protocol (docs/math.md §8).
pub const DEFAULT_MAX_ITERATIONS: u32 = 100;

impl<P> SolveOptions<P> {
    /// The defaults with the given deadline.
    pub const fn with_deadline(deadline: Duration) -> Self {
        Self {
            method: Method::Robust,
            alpha: 1.0,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            tolerance: DEFAULT_TOLERANCE,
            initial_guess: None,
            objective: Objective::FirstFound,
            deadline,
            max_starts: None,
            max_turns: 0,
        }
    }
}

impl Default for SolveOptions<nalgebra::Vector3<f64>> {
    fn default() -> Self {
        Self::with_deadline(DEFAULT_DEADLINE)
    }
}

impl Default for SolveOptions<nalgebra::Vector6<f64>> {
    fn default() -> Self {
        Self::with_deadline(DEFAULT_DEADLINE_3D)
    }
}

/// Checks the options against their documented limits (every solve does this first; a front
/// end may call it to refuse a request before any work).
pub fn check_options<const N: usize>(
    options: &SolveOptions<nalgebra::SVector<f64, N>>,
) -> Result<(), IgError> {
    if !(options.alpha > 0.0 && options.alpha <= 1.0) {
        return Err(IgError::InvalidOptions(format!(
            "alpha = {} is not in (0, 1]",
            options.alpha
        )));
    }
    if !(options.tolerance >= MIN_TOLERANCE && options.tolerance <= MAX_TOLERANCE) {
        return Err(IgError::InvalidOptions(format!(
            "tolerance = {:e} is not in [{MIN_TOLERANCE:e} (rounding bound), {MAX_TOLERANCE:e}]",
            options.tolerance
        )));
    }
    if !(1..=MAX_ITERATIONS_LIMIT).contains(&options.max_iterations) {
        return Err(IgError::InvalidOptions(format!(
            "max_iterations = {} is not in [1, {MAX_ITERATIONS_LIMIT}]",
            options.max_iterations
        )));
    }
    if options.deadline.is_zero() || options.deadline > MAX_DEADLINE {
        return Err(IgError::InvalidOptions(format!(
            "deadline = {:?} is not in (0, {MAX_DEADLINE:?}]",
            options.deadline
        )));
    }
    if options.max_starts == Some(0) {
        return Err(IgError::InvalidOptions("max_starts must be >= 1".into()));
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
