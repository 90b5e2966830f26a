//! The robust solver: globalised Newton ([`super::local`]) multi-started from the initial guess
//! (brought into the stable set by weighted scaling if needed) and from the atlas entries nearest
//! the target; every converged point is checked with the stability test (FINDINGS §5) before it
//! is returned.

use super::{atlas, local, model, newton::make_solution, Failure, IgError, Solution, SolveOptions};
use crate::{PlanarParams, PlanarPose};

/// Total start budget of one robust solve.
const MAX_STARTS: usize = 48;

/// Iteration budget per start (the atlas seeds are close: a few iterations suffice, and a start
/// that needs many is better replaced by the next one).
fn per_start_budget(options: &SolveOptions) -> u32 {
    options.max_iterations.clamp(1, 30)
}

/// Runs one start; returns the verified stable solution, if any.
pub(crate) fn try_start(
    target: &PlanarPose,
    a0: &PlanarParams,
    options: &SolveOptions,
    budget: u32,
    iterations: &mut u32,
    evaluations: &mut u32,
) -> Option<Solution> {
    let r = local::solve(target, a0, options.alpha, budget, options.tolerance);
    *iterations += r.iterations;
    *evaluations += r.evaluations;
    let (a, e) = r.found?;
    let st = model::stability(&a).ok()?;
    if !st.stable {
        return None;
    }
    Some(make_solution(&a, &e, true, st.margin, r.iterations))
}

/// Starts in order: the initial guess, then atlas seeds by increasing tip distance, widening the
/// search radius when the near cells are exhausted.
struct Starts<'t> {
    target: &'t PlanarPose,
    guess: Option<PlanarParams>,
    buf: Vec<(f64, PlanarParams)>,
    pos: usize,
    radius: usize,
    served: Vec<PlanarParams>,
}

impl<'t> Starts<'t> {
    fn new(target: &'t PlanarPose, options: &SolveOptions) -> Self {
        let guess = options
            .initial_guess
            .and_then(|g| local::pull_into_stable(&g));
        Self {
            target,
            guess,
            buf: Vec::new(),
            pos: 0,
            radius: 0,
            served: Vec::new(),
        }
    }

    fn next(&mut self) -> Option<PlanarParams> {
        if let Some(g) = self.guess.take() {
            return Some(g);
        }
        loop {
            while self.pos < self.buf.len() {
                let a = self.buf[self.pos].1;
                self.pos += 1;
                if !self.served.contains(&a) {
                    self.served.push(a);
                    return Some(a);
                }
            }
            if self.radius >= 3 {
                return None;
            }
            // Widen the search (the wider list contains the served seeds again: skipped).
            self.radius += 1;
            self.buf.clear();
            atlas::get().candidates(self.target, self.radius, &mut self.buf);
            self.pos = 0;
        }
    }
}

pub(crate) fn solve(target: &PlanarPose, options: &SolveOptions) -> Result<Solution, Failure> {
    let mut iterations = 0;
    let mut evaluations = 0;
    let mut starts = Starts::new(target, options);
    let budget = per_start_budget(options);
    let mut n = 0;
    while n < MAX_STARTS {
        let Some(a0) = starts.next() else { break };
        n += 1;
        if let Some(mut s) = try_start(
            target,
            &a0,
            options,
            budget,
            &mut iterations,
            &mut evaluations,
        ) {
            s.iterations = iterations;
            s.evaluations = evaluations;
            s.starts = n as u32;
            return Ok(s);
        }
    }
    Err(Failure {
        reason: IgError::NoStableSolution { starts: n as u32 },
        iterations,
        residual: f64::INFINITY,
        last_a: None,
        elapsed_us: 0.0,
    })
}

pub(crate) struct All {
    pub solutions: Vec<Solution>,
    pub iterations: u32,
    pub evaluations: u32,
    pub starts: u32,
}

/// Distinct: parameters differ by more than 1e-4 relative in the scaled metric.
fn distinct(a: &PlanarParams, b: &PlanarParams) -> bool {
    let d = (a[0] - b[0]).abs() / (1.0 + a[0].abs())
        + (a[1] - b[1]).abs() / (1.0 + a[1].abs())
        + (a[2] - b[2]).abs() / (1.0 + a[2].abs());
    d > 1e-4
}

pub(crate) fn solve_all(target: &PlanarPose, options: &SolveOptions) -> All {
    let mut iterations = 0;
    let mut evaluations = 0;
    let budget = per_start_budget(options);
    let mut list = Vec::new();
    if let Some(g) = options
        .initial_guess
        .and_then(|g| local::pull_into_stable(&g))
    {
        list.push((0.0, g));
    }
    atlas::get().candidates(target, 1, &mut list);
    let mut solutions: Vec<Solution> = Vec::new();
    let mut starts = 0;
    for (_, a0) in list.iter().take(200) {
        starts += 1;
        let r = local::solve(target, a0, options.alpha, budget, options.tolerance);
        iterations += r.iterations;
        evaluations += r.evaluations;
        let Some((a, e)) = r.found else { continue };
        if solutions.iter().any(|s| !distinct(&s.a, &a)) {
            continue;
        }
        let Ok(st) = model::stability(&a) else {
            continue;
        };
        if st.stable {
            let mut sol = make_solution(&a, &e, true, st.margin, r.iterations);
            sol.evaluations = r.evaluations;
            solutions.push(sol);
        }
    }
    All {
        solutions,
        iterations,
        evaluations,
        starts,
    }
}
