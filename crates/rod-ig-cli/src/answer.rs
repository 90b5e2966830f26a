//! The answer line of `solve` and `solve3d` (the CLI contract of issue #3 and its 3-D twin):
//! one shape for both, built from the solver crate's one `Solution` type, and one request
//! handler ([`answer`]) for every rod model.

use nalgebra::SVector;
use rod_ig_core::solver::{
    self, observe, BranchEvent, Event, Failure, InverseGeometry, IterationLog, Move, Solution,
    SolveOptions,
};
use serde::Serialize;
use std::io::Write;

/// One solve answer. On failure `a`, `tip` and `energy` are null and `reason` says why.
#[derive(Serialize)]
pub struct SolveAnswer<A, T> {
    success: bool,
    a: Option<A>,
    tip: Option<T>,
    stable: bool,
    iterations: u32,
    residual: f64,
    energy: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    position_error: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    orientation_error: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    stability_margin: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
    /// Why the solve ended ("converged", "deadline", "no_stable_solution", ...): the typed
    /// termination reason of the solver.
    termination: &'static str,
    /// Starts tried (multi-start strategies; 1 for Newton).
    starts: u32,
    /// Wall time of the request (ms), from its parsed options to its answer.
    elapsed_ms: f64,
    /// The search the request asked for ran to its end: false when the deadline cut a
    /// least-energy search or the `all` list (a lower-energy rod, or more rods, may exist).
    complete: bool,
    /// Every distinct stable solution found (`"all": true`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solutions: Option<Vec<SolveAnswer<A, T>>>,
}

impl<A, T> SolveAnswer<A, T> {
    /// A successful answer, a and the tip written by `a_of` and `tip_of`.
    pub fn success<P, X>(
        s: &Solution<P, X>,
        a_of: impl Fn(&P) -> A,
        tip_of: impl Fn(&X) -> T,
    ) -> Self {
        SolveAnswer {
            success: true,
            a: Some(a_of(&s.a)),
            tip: Some(tip_of(&s.tip)),
            stable: s.stable,
            iterations: s.iterations,
            residual: s.residual,
            energy: Some(s.energy),
            position_error: Some(s.position_error),
            orientation_error: Some(s.orientation_error),
            stability_margin: Some(s.stability_margin),
            reason: None,
            termination: solver::Termination::Converged.as_str(),
            starts: s.starts,
            elapsed_ms: s.elapsed_us / 1e3,
            complete: s.complete,
            solutions: None,
        }
    }

    /// A failed answer: work done and why.
    pub fn failure(
        iterations: u32,
        residual: f64,
        reason: String,
        termination: solver::Termination,
    ) -> Self {
        SolveAnswer {
            success: false,
            a: None,
            tip: None,
            stable: false,
            iterations,
            residual,
            energy: None,
            position_error: None,
            orientation_error: None,
            stability_margin: None,
            reason: Some(reason),
            termination: termination.as_str(),
            starts: 0,
            elapsed_ms: 0.0,
            complete: true,
            solutions: None,
        }
    }
}

impl<A, T> SolveAnswer<A, T> {
    /// The answer to the solver's failure `f` (its reason, termination and starts).
    pub fn from_failure<P>(f: &Failure<P>) -> Self {
        Self::failure(
            f.iterations,
            f.residual,
            f.reason.to_string(),
            f.termination(),
        )
        .with_starts(f.starts)
    }

    /// The answer with its wall time set from the solver's measure (µs).
    pub fn with_elapsed_us(mut self, us: f64) -> Self {
        self.elapsed_ms = us / 1e3;
        self
    }

    /// The same answer with the number of starts the search tried.
    pub fn with_starts(mut self, starts: u32) -> Self {
        self.starts = starts;
        self
    }
}

/// A `track` or `track3d` answer: the `solve` fields plus what happened to the held rod.
#[derive(Serialize)]
pub struct MoveAnswer<A, T> {
    #[serde(flatten)]
    pub solve: SolveAnswer<A, T>,
    /// "none", "snap", "lost" or "buckle".
    pub event: &'static str,
    /// After a snap: the gripper pose where the branch ended.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub critical: Option<T>,
    /// After a snap: the last stable rod of the old branch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub critical_a: Option<A>,
    /// After a snap: the elastic energy it released.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_released: Option<f64>,
    /// How far along the gripper's path the rod was followed (1 when the target was reached;
    /// on a deadline, where the rod now held is).
    pub progress: f64,
    /// The rod held after this line (null once lost): on a deadline, the last equilibrium
    /// reached, from which the next line goes on.
    pub held_a: Option<A>,
}

impl<A, T> MoveAnswer<A, T> {
    /// The answer to the follower's move `m`, the rod it holds after it being `held`.
    pub fn of<P, X: Copy>(
        m: &Move<P, X>,
        held: Option<&P>,
        a_of: impl Fn(&P) -> A,
        tip_of: impl Fn(&X) -> T,
    ) -> Self {
        let solve = match &m.result {
            Ok(s) => SolveAnswer::success(s, &a_of, &tip_of),
            Err(f) => SolveAnswer::from_failure(f).with_elapsed_us(f.elapsed_us),
        };
        let mut answer = MoveAnswer {
            solve,
            event: m.event.as_str(),
            critical: None,
            critical_a: None,
            energy_released: None,
            progress: m.progress,
            held_a: held.map(&a_of),
        };
        if let BranchEvent::Snap {
            critical,
            critical_a,
            energy_released,
            ..
        } = &m.event
        {
            answer.critical = Some(tip_of(critical));
            answer.critical_a = Some(a_of(critical_a));
            answer.energy_released = Some(*energy_released);
        }
        answer
    }
}

/// Solves one request on `model` and writes the answer: the solve with `options`, then, with
/// `all`, every distinct stable solution (`solutions`, least energy first). With `verbose`,
/// the solver's events (starts, iterations, end) go to stderr as JSON lines.
pub fn answer<const N: usize, M, A, T>(
    model: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
    all: bool,
    verbose: bool,
    a_of: impl Fn(&SVector<f64, N>) -> A,
    tip_of: impl Fn(&M::Pose) -> T,
) -> SolveAnswer<A, T>
where
    M: InverseGeometry<N>,
{
    let t0 = std::time::Instant::now();
    let run = || {
        // One deadline for the request: the list of `all` gets the time the solve left.
        let _deadline = rod_ig_core::deadline::scope(options.deadline);
        let first = solver::solve(model, target, options);
        let every = all.then(|| solver::solve_every(model, target, options));
        (first, every)
    };
    let (first, every) = if verbose {
        let (r, log) = observe(IterationLog::default(), run);
        // Diagnostics only: a closed or full stderr must not cost the answer on stdout
        // (eprintln! would panic and exit 101), so write errors are dropped.
        let mut err = std::io::stderr().lock();
        for event in &log.events {
            let _ = writeln!(err, "{}", event_json(event));
        }
        r
    } else {
        run()
    };
    let mut answer = match &first {
        Ok(s) => SolveAnswer::success(s, &a_of, &tip_of),
        Err(f) => SolveAnswer::from_failure(f),
    };
    answer.elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
    if let Some(solver::Every {
        solutions,
        complete,
    }) = every
    {
        if solutions.is_empty() && answer.success {
            // solve_all includes the first-found answer, so this is unreachable in practice;
            // guarded so that success never comes with an empty list.
            answer = SolveAnswer::failure(
                answer.iterations,
                f64::INFINITY,
                "no stable solution found".into(),
                solver::Termination::NoStableSolution,
            );
        }
        answer.complete &= complete;
        answer.solutions = Some(
            solutions
                .iter()
                .map(|s| SolveAnswer::success(s, &a_of, &tip_of))
                .collect(),
        );
    }
    answer
}

/// One observer event as a JSON line for `--verbose`.
fn event_json(event: &Event) -> serde_json::Value {
    match *event {
        Event::StartBegun { index, a0_norm } => {
            serde_json::json!({"event": "start", "index": index, "a0_norm": a0_norm})
        }
        Event::Iteration {
            iteration,
            residual,
            step,
            alpha,
        } => serde_json::json!({
            "event": "iteration", "iteration": iteration, "residual": residual,
            "step": step, "alpha": alpha
        }),
        Event::StartEnded { index, termination } => serde_json::json!({
            "event": "start_end", "index": index, "termination": termination.as_str()
        }),
        Event::Finished {
            termination,
            iterations,
            starts,
            elapsed_us,
        } => serde_json::json!({
            "event": "finished", "termination": termination.as_str(),
            "iterations": iterations, "starts": starts, "elapsed_us": elapsed_us
        }),
    }
}
