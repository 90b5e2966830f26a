//! What a solve returns: one [`Solution`] type, one [`Failure`] type and one error enum
//! ([`IgError`]) for every rod model, with a typed [`Termination`] reason.

use thiserror::Error;

/// A converged solve of the inverse geometry, for any rod model: `P` is the model's parameter
/// vector a (ℝ³ planar, ℝ⁶ 3-D), `X` its tip pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution<P, X> {
    /// The rod parameters a* = μ(0).
    pub a: P,
    /// Υ(a*) (planar: θ unwrapped, ∫κ).
    pub tip: X,
    /// Verdict of the stability test on a* (always true: every strategy returns only stable
    /// rods).
    pub stable: bool,
    /// Normalised stability margin g_min (docs/math.md §5; positive when stable, ≈ 1 when gently
    /// bent).
    pub stability_margin: f64,
    /// Newton iterations, summed over every start tried.
    pub iterations: u32,
    /// Position error ‖p(a*) − p*‖ (rod lengths).
    pub position_error: f64,
    /// Orientation error (rad): planar |wrap(θ − θ*)|, 3-D the rotation angle ∠(R, R*).
    pub orientation_error: f64,
    /// Residual ‖(position_error, orientation_error)‖₂ (planar: ‖f(a*)‖₂ with the angle
    /// wrapped, the same number).
    pub residual: f64,
    /// Elastic energy ½∫ μᵀC⁻¹μ (planar ½∫κ²).
    pub energy: f64,
    /// Evaluations of the model (tip and Jacobian), line-search trials included, over every
    /// start.
    pub evaluations: u32,
    /// Number of starts tried (1 for the paper's Newton and a tracker warm start).
    pub starts: u32,
    /// Wall time of the solve, µs.
    pub elapsed_us: f64,
    /// The search the objective asks for ran to its end. Always true for the first-found
    /// objective; false when the deadline passed before the least-energy search had tried
    /// every start (the rod is stable and on target, but one of less energy may exist).
    pub complete: bool,
}

/// The work a search did, kept in one state and copied into its outcome.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    /// Newton iterations (accepted steps).
    pub iterations: u32,
    /// Evaluations of the model, trials included.
    pub evaluations: u32,
    /// Starts tried.
    pub starts: u32,
}

/// The evaluation a solution is built from: its tip, its (position, orientation) errors to
/// the target, its energy and stability margin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verified<X> {
    /// Υ(a*).
    pub tip: X,
    /// (position error, orientation error) to the target.
    pub errors: (f64, f64),
    /// Elastic energy.
    pub energy: f64,
    /// Normalised stability margin (the rod passed the stability test).
    pub margin: f64,
}

impl<P, X> Solution<P, X> {
    /// A stable solution `a` evaluated as `v` after `work`: the one place a solution is
    /// assembled (the residual is ‖errors‖₂; the wall time is set by the entry point that
    /// times the call).
    pub fn new(a: P, v: Verified<X>, work: Work) -> Self {
        let (position_error, orientation_error) = v.errors;
        Solution {
            a,
            tip: v.tip,
            stable: true,
            stability_margin: v.margin,
            iterations: work.iterations,
            position_error,
            orientation_error,
            residual: position_error.hypot(orientation_error),
            energy: v.energy,
            evaluations: work.evaluations,
            starts: work.starts.max(1),
            elapsed_us: 0.0,
            complete: true,
        }
    }
}

/// Why a solve ended, as a small copyable code (for logs, metrics and the CLI's
/// `termination` field). [`IgError::termination`] maps every error to one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Termination {
    /// The residual met the tolerance at a stable rod.
    Converged,
    /// The target, the initial guess or an option was rejected before any work.
    InvalidInput,
    /// The target is out of the rod's reach.
    Unreachable,
    /// The iteration budget ran out.
    IterationLimit,
    /// The wall-time budget ran out.
    Deadline,
    /// J(1, a) was singular: no Newton step.
    Singular,
    /// An iterate left the stable set (paper's protocol, docs/math.md §8), or every trial step did.
    LeftStableSet,
    /// The line search found no decrease of the residual.
    Stalled,
    /// No start of a multi-start strategy reached a stable solution.
    NoStableSolution,
    /// The model could not be evaluated (non-finite values, overflow, integration failure).
    EvaluationFailed,
}

impl Termination {
    /// The snake_case name used in JSON answers and logs.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::InvalidInput => "invalid_input",
            Self::Unreachable => "unreachable",
            Self::IterationLimit => "iteration_limit",
            Self::Deadline => "deadline",
            Self::Singular => "singular",
            Self::LeftStableSet => "left_stable_set",
            Self::Stalled => "stalled",
            Self::NoStableSolution => "no_stable_solution",
            Self::EvaluationFailed => "evaluation_failed",
        }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Why an inverse-geometry solve failed (every model, every strategy).
#[derive(Clone, Debug, PartialEq, Error)]
pub enum IgError {
    /// A target coordinate is NaN or infinite.
    #[error("target {component} is not finite ({value})")]
    NonFiniteTarget {
        /// "x", "y", "theta" (planar); "position", "orientation" (3-D).
        component: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The target position is out of the inextensible unit rod's reach.
    #[error("target is unreachable: distance {distance} from the base is >= 1, the rod length")]
    Unreachable {
        /// ‖p*‖.
        distance: f64,
    },
    /// The initial guess has a non-finite component.
    #[error("initial guess a0[{index}] is not finite ({value})")]
    NonFiniteGuess {
        /// Component index (planar: 0 = a3; 3-D: 0 = a1).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The options are unusable (e.g. α ∉ (0, 1], tolerance below the rounding bound).
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
    /// The line search found no decrease of the residual along the Newton direction.
    #[error("no decrease of the residual along the Newton direction at iteration {iteration}")]
    Stalled {
        /// Iteration at which it happened.
        iteration: u32,
    },
    /// The residual did not reach the tolerance within the iteration budget.
    #[error("no convergence within {iterations} iterations")]
    MaxIterations {
        /// The budget.
        iterations: u32,
    },
    /// An evaluation of the rod failed (the model refused the parameters) or gave non-finite
    /// values.
    #[error("rod evaluation failed at iteration {iteration}: {detail}")]
    Evaluation {
        /// Iteration at which it happened.
        iteration: u32,
        /// What failed.
        detail: String,
    },
    /// The solve's deadline ([`super::SolveOptions::deadline`]) passed before it converged.
    #[error("deadline reached after {iteration} iterations without convergence")]
    Deadline {
        /// Iterations spent.
        iteration: u32,
    },
    /// A multi-start strategy found no stable solution from any of its starts.
    #[error(
        "no stable solution found from {starts} starts (the search's starts reached none; this \
         does not prove that none exists){}",
        last.as_ref().map(|l| format!("; last start: {l}")).unwrap_or_default()
    )]
    NoStableSolution {
        /// Starts tried.
        starts: u32,
        /// Why the last start failed, when known.
        last: Option<Box<IgError>>,
    },
    /// The planar robust search ran every start and followed every branch it had without
    /// reaching a stable rod: what it searched (a stable rod outside that search may exist).
    #[error("{0}")]
    SearchExhausted(Box<Searched>),
    /// The long-cable search (multiple shooting, w > 200) admitted no rod: none of its starts
    /// reached a stable rod within the admitted turns. Not a proof that none exists.
    #[error(
        "no stable rod with at most {max_turns} turns found by {starts} starts of the \
         long-cable search{}{}",
        if *cut_short { " before its deadline passed" } else { "" },
        last.as_ref().map(|l| format!("; last start: {l}")).unwrap_or_default()
    )]
    NoAdmittedRod {
        /// Starts tried (weightless rods carried in load, seeds moved to the target).
        starts: u32,
        /// The `max_turns` the search admitted.
        max_turns: u32,
        /// The deadline cut the search.
        cut_short: bool,
        /// Why the last start failed, when known.
        last: Option<String>,
    },
}

/// What an exhausted search searched ([`IgError::SearchExhausted`]).
#[derive(Clone, Debug, PartialEq, Error)]
#[error(
    "no stable rod found by {starts} Newton starts from stable rods with |a3| <= {a3_max}, \
     |a4|, |a5| <= {a45_max} and {branches} of their branches followed to the target, in \
     {elapsed_ms:.1} ms{}",
    last.as_ref().map(|l| format!("; last start: {l}")).unwrap_or_default()
)]
pub struct Searched {
    /// Newton starts run.
    pub starts: u32,
    /// Branches followed from stable seeds toward the target.
    pub branches: u32,
    /// Largest |a3| of the seeds.
    pub a3_max: f64,
    /// Largest |a4| and |a5| of the seeds.
    pub a45_max: f64,
    /// Time the search took, ms.
    pub elapsed_ms: f64,
    /// Why the last Newton start failed, when known.
    pub last: Option<IgError>,
}

impl IgError {
    /// The error of an evaluation that failed at `iteration`: [`IgError::Deadline`] when the
    /// deadline cut it ([`crate::RodError::Deadline`]), else [`IgError::Evaluation`] with the
    /// detail.
    pub fn of_evaluation(iteration: u32, error: &crate::RodError) -> Self {
        match error {
            crate::RodError::Deadline { .. } => Self::Deadline { iteration },
            e => Self::Evaluation {
                iteration,
                detail: e.to_string(),
            },
        }
    }

    /// The typed termination reason of this error.
    pub fn termination(&self) -> Termination {
        match self {
            Self::NonFiniteTarget { .. }
            | Self::NonFiniteGuess { .. }
            | Self::InvalidOptions(_) => Termination::InvalidInput,
            Self::Unreachable { .. } => Termination::Unreachable,
            Self::SingularJacobian { .. } => Termination::Singular,
            Self::LeftStableSet { .. } => Termination::LeftStableSet,
            Self::Stalled { .. } => Termination::Stalled,
            Self::MaxIterations { .. } => Termination::IterationLimit,
            Self::Deadline { .. } => Termination::Deadline,
            Self::NoStableSolution { .. } | Self::SearchExhausted(_) => {
                Termination::NoStableSolution
            }
            Self::NoAdmittedRod {
                cut_short: true, ..
            } => Termination::Deadline,
            Self::NoAdmittedRod { .. } => Termination::NoStableSolution,
            Self::Evaluation { .. } => Termination::EvaluationFailed,
        }
    }
}

/// A failed solve: the reason and where the solver stopped (`P`: the model's parameters).
#[derive(Clone, Debug, PartialEq, Error)]
#[error("{reason} (after {iterations} iterations, residual {residual:e})")]
pub struct Failure<P> {
    /// Why.
    pub reason: IgError,
    /// Iterations spent (every start).
    pub iterations: u32,
    /// Residual ‖(position error, orientation error)‖₂ at the best iterate seen (∞ when none
    /// was evaluated).
    pub residual: f64,
    /// That best iterate (possibly a converged but unstable point), when there was one.
    pub last_a: Option<P>,
    /// Starts tried (Newton runs from distinct initial points, branches followed included).
    pub starts: u32,
    /// Wall time, µs.
    pub elapsed_us: f64,
}

impl<P> Failure<P> {
    /// A failure before any work (invalid input).
    pub fn early(reason: IgError) -> Self {
        Self {
            reason,
            iterations: 0,
            residual: f64::INFINITY,
            last_a: None,
            starts: 0,
            elapsed_us: 0.0,
        }
    }

    /// The typed termination reason.
    pub fn termination(&self) -> Termination {
        self.reason.termination()
    }
}
