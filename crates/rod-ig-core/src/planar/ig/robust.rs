//! The robust solver: globalised Newton ([`super::local`]) multi-started from the initial guess
//! (brought into the stable set by weighted scaling if needed) and from the atlas entries nearest
//! the target; every converged point is checked with the stability test (docs/math.md §5) before it
//! is returned.
//!
//! Stages, each run only when the ones before found nothing: the box stage (the guess, the
//! model's starts, the box atlas), the polish of the best iterate, then beyond the box: Newton
//! from the second atlas's seeds and the branches of both atlases' seeds followed to the target
//! ([`crate::solver::branch_to`]). A failure says what was searched.

use super::{
    atlas, fronts, local, newton, newton::make_solution, straight, Failure, IgError, Solution,
    SolveOptions,
};
use crate::planar::model;

use crate::solver::{emit, Event, Searched, Termination};
use crate::{PlanarParams, PlanarPose};

/// Total start budget of one robust solve, unless `SolveOptions::max_starts` says otherwise.
pub(crate) const MAX_STARTS: usize = 48;
/// The polishing stage runs when the best residual is below this.
const POLISH_BELOW: f64 = 0.05;
/// Iteration budget of the polishing stage (at most the caller's `max_iterations`).
const POLISH_BUDGET: u32 = 300;
/// Iteration budget for the caller's initial guess, which may be far from the target: beyond
/// it, the atlas starts (a few iterations each) are the better bet.
const GUESS_BUDGET: u32 = 12;

/// Iteration budget per atlas start (the seeds are close: a few iterations suffice, and a start
/// that needs many is better replaced by the next one).
fn per_start_budget(options: &SolveOptions) -> u32 {
    options.max_iterations.clamp(1, 30)
}

/// Counters accumulated over the starts of one solve.
struct Counts {
    iterations: u32,
    evaluations: u32,
    /// Best residual reached by any start, and where.
    best: (f64, Option<PlanarParams>),
    /// Why the last start that did not produce a solution stopped.
    last_stop: Option<IgError>,
    /// Starts run (the observer's start index), branches followed included.
    starts: u32,
    /// Branches followed ([`by_continuation`]).
    branches: u32,
}

impl Default for Counts {
    fn default() -> Self {
        Self {
            iterations: 0,
            evaluations: 0,
            best: (f64::INFINITY, None),
            last_stop: None,
            starts: 0,
            branches: 0,
        }
    }
}

/// Newton from one start (with its optional predicted first step), its work added to `counts`.
fn run_counted(
    target: &PlanarPose,
    start: &atlas::Start,
    options: &SolveOptions,
    budget: u32,
    counts: &mut Counts,
) -> local::Local {
    let index = counts.starts;
    counts.starts += 1;
    emit(Event::StartBegun {
        index,
        a0_norm: start.a.norm(),
    });
    let r = local::solve_predicted(
        target,
        &start.a,
        start.predicted,
        options.alpha,
        budget,
        options.tolerance,
    );
    counts.iterations += r.iterations;
    counts.evaluations += r.evaluations;
    if r.found.is_none() {
        counts.last_stop = Some(r.stop.to_error(r.iterations));
    }
    emit(Event::StartEnded {
        index,
        termination: match r.found {
            Some(_) => Termination::Converged,
            None => r.stop.to_error(r.iterations).termination(),
        },
    });
    r
}

/// Runs one start (with its optional predicted first step); returns the verified stable
/// solution, if any.
fn try_start(
    target: &PlanarPose,
    start: &atlas::Start,
    options: &SolveOptions,
    budget: u32,
    counts: &mut Counts,
) -> Option<Solution> {
    let r = run_counted(target, start, options, budget, counts);
    if r.residual < counts.best.0 {
        counts.best = (r.residual, Some(r.last_a));
    }
    let (a, _) = r.found?;
    let (e, st) = newton::verify_with_stability(&a, target, options.tolerance)?;
    if !st.stable {
        return None;
    }
    let mut s = make_solution(&a, &e, true, st.margin, r.iterations);
    s.evaluations = r.evaluations;
    Some(s)
}

/// Starts in order: the initial guess (brought into the stable set by weighted scaling if it
/// is not stable), then the target cell's short list of atlas seeds, then seeds in widening
/// neighbourhoods, nearest first. The guess goes first when its residual ‖Υ(a0) − b‖ is no
/// larger than the nearest seed's (a good hint, e.g. a previous solution, also selects the
/// solution branch); a far guess (larger residual) is tried after the short list.
struct Starts<'t> {
    target: &'t PlanarPose,
    atlas: &'static atlas::Atlas,
    guess: Option<PlanarParams>,
    guess_first: bool,
    buf: Vec<(f64, u32)>,
    pos: usize,
    /// 0: short list not yet loaded; r ≥ 1: neighbourhood radius loaded.
    stage: usize,
    served: Vec<u32>,
    /// Model-based starts ([`ModelStarts`]): before the atlas, after the short list, and at
    /// the end.
    model: ModelStarts,
}

/// Most small-angle starts ([`straight`]) and strong-tension starts ([`fronts`]) per solve.
const MODEL_STARTS: usize = 4;

/// The model-based starts for `target`, in the order they are served:
/// - `first`: small-angle starts ([`straight`]) with cheap f64 iterations, served before any
///   atlas seed: near full extension the atlas (a grid over the paper's box) has few seeds in
///   Newton's basin, and the model's start for a gently bent rod converges in a few steps;
/// - `early`: strong-tension starts ([`fronts`]; double-double iterations, a few ms each, but
///   only where the target fits the model), served after the target cell's short list;
/// - `late`: small-angle starts under strong tension, served after every atlas seed. Those
///   come from targets so close to full extension that the small-angle model has roots up to
///   a4 = 1e4; iterated precisely, they would spend the deadline that the atlas seeds after
///   them need (seen: 5 % of log-scale targets near full extension lost to the deadline).
///
/// Each is computed when first needed: most solves end at the first small-angle start or
/// before.
struct ModelStarts {
    straight: straight::Roots,
    /// Small-angle starts served so far (at most [`MODEL_STARTS`] in all).
    served_straight: usize,
    early: Option<Vec<PlanarParams>>,
    /// Small-angle starts that need precise iterations, in the order found.
    late: std::collections::VecDeque<PlanarParams>,
}

impl ModelStarts {
    fn new(target: &PlanarPose) -> Self {
        ModelStarts {
            straight: straight::roots(target),
            served_straight: 0,
            early: None,
            late: Default::default(),
        }
    }

    /// The next small-angle start iterated in f64 (those needing precise iterations are put
    /// aside for [`Self::late`]).
    fn first(&mut self) -> Option<PlanarParams> {
        while self.served_straight < MODEL_STARTS {
            let a = self.straight.next()?;
            self.served_straight += 1;
            if crate::planar::entry::needs_precise_iterations(&a) {
                self.late.push_back(a);
            } else {
                return Some(a);
            }
        }
        None
    }

    fn early(&mut self, target: &PlanarPose) -> Option<PlanarParams> {
        self.early
            .get_or_insert_with(|| {
                let mut e = fronts::starts(target, MODEL_STARTS);
                e.reverse();
                e
            })
            .pop()
    }

    fn late(&mut self) -> Option<PlanarParams> {
        while self.served_straight < MODEL_STARTS {
            let Some(a) = self.straight.next() else { break };
            self.served_straight += 1;
            self.late.push_back(a);
        }
        self.late.pop_front()
    }
}

impl<'t> Starts<'t> {
    fn new(target: &'t PlanarPose, atlas: &'static atlas::Atlas, options: &SolveOptions) -> Self {
        // The guess: used as is when det J(1, a0) > 0 (the local solver's requirement; an
        // unstable guess of even index is caught by the final stability test), else brought into
        // the stable set by weighted scaling.
        let guess_eval = |g: &PlanarParams| {
            model::tip_and_jacobian_for_iteration(g, model::Precision::for_start(g))
                .ok()
                .map(|(tip, j)| (model::residual(&tip, target).norm(), j.determinant()))
        };
        let mut guess = None;
        let mut guess_residual = f64::INFINITY;
        if let Some(g) = options.initial_guess {
            match guess_eval(&g) {
                Some((r, det)) if det > 0.0 && r.is_finite() => {
                    guess = Some(g);
                    guess_residual = r;
                }
                _ => {
                    if let Some(p) = local::pull_into_stable(&g) {
                        if let Some((r, det)) = guess_eval(&p) {
                            if det > 0.0 && r.is_finite() {
                                guess = Some(p);
                                guess_residual = r;
                            }
                        }
                    }
                }
            }
        }
        let mut s = Self {
            target,
            atlas,
            guess,
            guess_first: true,
            buf: Vec::new(),
            pos: 0,
            stage: 0,
            // Most solves serve a few starts: one allocation for them.
            served: Vec::with_capacity(8),
            model: ModelStarts::new(target),
        };
        if guess.is_some() {
            atlas.near_list(target, &mut s.buf);
            s.stage = 1;
            let seed_residual = s
                .buf
                .first()
                .map(|&(_, k)| atlas.seed_residual(k, target))
                .unwrap_or(f64::INFINITY);
            s.guess_first = guess_residual <= seed_residual;
        }
        s
    }

    /// Next start, and whether it is the caller's guess.
    fn next(&mut self) -> Option<(atlas::Start, bool)> {
        let as_start = |g: PlanarParams| {
            (
                atlas::Start {
                    a: g,
                    predicted: None,
                },
                true,
            )
        };
        if self.guess_first {
            if let Some(g) = self.guess.take() {
                return Some(as_start(g));
            }
        }
        let as_model_start = |a| Some((atlas::Start { a, predicted: None }, false));
        if let Some(a) = self.model.first() {
            return as_model_start(a);
        }
        let atlas = self.atlas;
        loop {
            while self.pos < self.buf.len() {
                let k = self.buf[self.pos].1;
                self.pos += 1;
                if !self.served.contains(&k) {
                    self.served.push(k);
                    return Some((atlas.start(k, self.target), false));
                }
            }
            // The current list is exhausted: a far guess comes after the short list, then the
            // small-angle starts of a target near full extension.
            if let Some(g) = self.guess.take() {
                return Some(as_start(g));
            }
            if self.stage >= 1 {
                if let Some(a) = self.model.early(self.target) {
                    return as_model_start(a);
                }
                if self.stage >= 3 {
                    return self.model.late().and_then(as_model_start);
                }
            }
            self.buf.clear();
            if self.stage == 0 {
                atlas.near_list(self.target, &mut self.buf);
            } else {
                atlas.candidates(self.target, self.stage, &mut self.buf);
            }
            self.stage += 1;
            self.pos = 0;
        }
    }
}

/// The failure of a solve whose deadline passed, with the work done so far.
fn deadline_failure(counts: &Counts) -> Failure {
    Failure {
        reason: IgError::Deadline {
            iteration: counts.iterations,
        },
        iterations: counts.iterations,
        residual: counts.best.0,
        last_a: counts.best.1,
        starts: counts.starts,
        elapsed_us: 0.0,
    }
}

pub(crate) fn solve(target: &PlanarPose, options: &SolveOptions) -> Result<Solution, Failure> {
    let t0 = std::time::Instant::now();
    let mut counts = Counts::default();
    // The atlas is built on first use, in steps charged to this call's deadline.
    let Some(atlas) = atlas::get(atlas::Tier::Box) else {
        return Err(deadline_failure(&counts));
    };
    let limit = options.max_starts.map(|m| m.max(1) as usize);
    let box_starts = limit.unwrap_or(MAX_STARTS);
    if let Some(done) = box_stage(target, atlas, options, box_starts, &mut counts) {
        return done;
    }
    if let Some(s) = polish_stage(target, options, &mut counts) {
        return Ok(s);
    }
    let left = limit.map_or(BEYOND_STARTS + BRANCH_STARTS, |m| {
        m.saturating_sub(counts.starts as usize)
    });
    if left > 0 {
        if let Some(done) = beyond_stage(target, atlas, options, left, &mut counts) {
            return done;
        }
    }
    Err(Failure {
        reason: IgError::SearchExhausted(Box::new(Searched {
            starts: counts.starts - counts.branches,
            branches: counts.branches,
            a3_max: atlas::SEED_A3_MAX,
            a45_max: atlas::SEED_A45_MAX,
            elapsed_ms: t0.elapsed().as_secs_f64() * 1e3,
            last: counts.last_stop,
        })),
        iterations: counts.iterations,
        residual: counts.best.0,
        last_a: counts.best.1,
        starts: counts.starts,
        elapsed_us: 0.0,
    })
}

/// A stage's end: `Some` when the solve is over (a solution, or the deadline).
type StageEnd = Option<Result<Solution, Failure>>;

/// The solution `s` found by the search so far, with its work.
fn found_after(mut s: Solution, counts: &Counts) -> Solution {
    s.iterations = counts.iterations;
    s.evaluations = counts.evaluations;
    s.starts = counts.starts;
    s
}

/// The first stage: the guess, the model's starts and the box atlas's seeds
/// ([`Starts`]), at most `max_starts` of them.
fn box_stage(
    target: &PlanarPose,
    atlas: &'static atlas::Atlas,
    options: &SolveOptions,
    max_starts: usize,
    counts: &mut Counts,
) -> StageEnd {
    let mut starts = Starts::new(target, atlas, options);
    let budget = per_start_budget(options);
    while (counts.starts as usize) < max_starts {
        if crate::deadline::expired() {
            return Some(Err(deadline_failure(counts)));
        }
        let (start, is_guess) = starts.next()?;
        let b = if is_guess {
            budget.min(GUESS_BUDGET)
        } else {
            budget
        };
        if let Some(s) = try_start(target, &start, options, b, counts) {
            return Some(Ok(found_after(s, counts)));
        }
    }
    None
}

/// The most promising iterate (smallest residual over every start) polished with a long run
/// of the globalised Newton / LM steps. Near the separatrix λ4 = 0 and near folds,
/// convergence there is linear and slow but steady.
fn polish_stage(
    target: &PlanarPose,
    options: &SolveOptions,
    counts: &mut Counts,
) -> Option<Solution> {
    let (r, Some(a)) = counts.best else {
        return None;
    };
    if r >= POLISH_BELOW {
        return None;
    }
    let start = atlas::Start { a, predicted: None };
    let budget = POLISH_BUDGET.min(options.max_iterations);
    try_start(target, &start, options, budget, counts).map(|s| found_after(s, counts))
}

/// Beyond the box: the second atlas's seeds nearest the target, then the branches of both
/// atlases' seeds, `left` starts in all.
fn beyond_stage(
    target: &PlanarPose,
    atlas: &'static atlas::Atlas,
    options: &SolveOptions,
    left: usize,
    counts: &mut Counts,
) -> StageEnd {
    // Built on first need, in steps charged to this call's deadline, like the box atlas.
    let Some(beyond) = atlas::get(atlas::Tier::Beyond) else {
        return Some(Err(deadline_failure(counts)));
    };
    let mut list = Vec::new();
    beyond.near_list(target, &mut list);
    beyond.candidates(target, 1, &mut list);
    let mut served = Vec::new();
    let budget = per_start_budget(options);
    for &(_, k) in &list {
        if served.len() >= BEYOND_STARTS.min(left) {
            break;
        }
        if served.contains(&k) {
            continue;
        }
        served.push(k);
        if crate::deadline::expired() {
            return Some(Err(deadline_failure(counts)));
        }
        if let Some(s) = try_start(target, &beyond.start(k, target), options, budget, counts) {
            return Some(Ok(found_after(s, counts)));
        }
    }
    let branches = BRANCH_STARTS.min(left - served.len());
    if let Some(s) = by_continuation(target, &[atlas, beyond], options, branches, counts) {
        return Some(Ok(found_after(s, counts)));
    }
    crate::deadline::expired().then(|| Err(deadline_failure(counts)))
}

/// Newton starts from the beyond-the-box atlas (its short list, then its seeds one cell away).
const BEYOND_STARTS: usize = 24;
/// Seeds whose branches the continuation stage follows at most.
const BRANCH_STARTS: usize = 64;
/// Continuation steps per branch the robust search's last stage follows (each at most
/// [`crate::solver::CORRECTOR_ITERATIONS`] + 1 corrections): the bound of such a start, for
/// which `SolveOptions::max_iterations` (a Newton run's budget) is not meant. 4,096 steps
/// cover the whole move at the continuation's smallest step ([`crate::solver::MIN_STEP`]);
/// at 1,000 the search found 13 fewer of 600 workspace targets.
pub const BRANCH_STEPS: u32 = 4096;
/// Cells around the target's whose seeds the continuation stage follows.
const BRANCH_RADIUS: usize = 3;

/// The last stage: the branches of the atlas seeds nearest the target (within
/// [`BRANCH_RADIUS`] cells, one seed per branch, at most `branches`), each followed as its tip
/// moves straight to the target ([`crate::solver::branch_to`]). Where the stable rods at the
/// target are so sensitive (|J| ~ 500) that no seed lies in Newton's basin, a branch through a
/// seed still leads there. Each branch counts as a start.
fn by_continuation(
    target: &PlanarPose,
    atlases: &[&'static atlas::Atlas],
    options: &SolveOptions,
    branches: usize,
    counts: &mut Counts,
) -> Option<Solution> {
    let mut candidates: Vec<(f64, PlanarParams)> = Vec::new();
    let mut found = Vec::new();
    for atlas in atlases {
        found.clear();
        atlas.candidates(target, BRANCH_RADIUS, &mut found);
        candidates.extend(
            found
                .iter()
                .map(|&(d, k)| (d, atlas.seed_params(k as usize))),
        );
    }
    candidates.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut followed: Vec<PlanarParams> = Vec::new();
    for (_, a0) in candidates {
        if crate::deadline::expired() || followed.len() >= branches {
            break;
        }
        if followed
            .iter()
            .any(|b| atlas::same_branch(&(*b).into(), &a0.into()))
        {
            continue;
        }
        followed.push(a0);
        let index = counts.starts;
        counts.starts += 1;
        counts.branches += 1;
        emit(Event::StartBegun {
            index,
            a0_norm: a0.norm(),
        });
        let mut work = crate::solver::Work::default();
        let model = crate::planar::model::PlanarClosedForm;
        let end = crate::solver::branch_to(model, options, BRANCH_STEPS, &a0, target, &mut work);
        counts.iterations += work.iterations;
        counts.evaluations += work.evaluations;
        let verified = end.and_then(|a| {
            let (e, st) = newton::verify_with_stability(&a, target, options.tolerance)?;
            st.stable
                .then(|| make_solution(&a, &e, true, st.margin, work.iterations))
        });
        emit(Event::StartEnded {
            index,
            termination: match verified {
                Some(_) => Termination::Converged,
                None => Termination::NoStableSolution,
            },
        });
        if verified.is_some() {
            return verified;
        }
    }
    None
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

/// Every start of the initial guess and of the atlas seeds within one cell of the target (at
/// most 200); the distinct stable solutions.
///
/// `total_budget`: stop starting new runs once this many iterations were spent in total and at
/// least one solution is known (the tracker's cold start: it must respect `max_iterations`).
pub(crate) fn solve_all(
    target: &PlanarPose,
    options: &SolveOptions,
    total_budget: Option<u32>,
) -> All {
    let mut counts = Counts::default();
    let budget = per_start_budget(options);
    let Some(atlas) = atlas::get(atlas::Tier::Box) else {
        return All {
            solutions: Vec::new(),
            iterations: 0,
            evaluations: 0,
            starts: 0,
        };
    };
    let mut list: Vec<atlas::Start> = Vec::new();
    if let Some(g) = options
        .initial_guess
        .and_then(|g| local::pull_into_stable(&g))
    {
        list.push(atlas::Start {
            a: g,
            predicted: None,
        });
    }
    let mut idx = Vec::new();
    atlas.candidates(target, 1, &mut idx);
    list.extend(idx.iter().take(200).map(|&(_, k)| atlas.start(k, target)));
    let mut model = ModelStarts::new(target);
    let firsts: Vec<_> = std::iter::from_fn(|| model.first()).collect();
    let earlies: Vec<_> = std::iter::from_fn(|| model.early(target)).collect();
    let lates: Vec<_> = std::iter::from_fn(|| model.late()).collect();
    list.extend(
        firsts
            .into_iter()
            .chain(earlies)
            .chain(lates)
            .map(|a| atlas::Start { a, predicted: None }),
    );
    let mut solutions: Vec<Solution> = Vec::new();
    let mut starts = 0;
    for start in &list {
        if crate::deadline::expired() {
            break;
        }
        if total_budget.is_some_and(|b| counts.iterations >= b) && !solutions.is_empty() {
            break;
        }
        starts += 1;
        let r = run_counted(target, start, options, budget, &mut counts);
        let Some((a, _)) = r.found else { continue };
        if solutions.iter().any(|s| !distinct(&s.a, &a)) {
            continue;
        }
        let Some((e, st)) = newton::verify_with_stability(&a, target, options.tolerance) else {
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
        iterations: counts.iterations,
        evaluations: counts.evaluations,
        starts,
    }
}
