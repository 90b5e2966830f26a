//! Inverse geometry of the 3-D rod: find a stable a ∈ ℝ⁶ whose tip q(1, a) is a target pose.
//!
//! Residual (paper §3.1, in the body frame): e(a) = (log(Rᵀ R*), Rᵀ(p* − p)) ∈ ℝ⁶ with
//! (p, R) = q(1, a); since q(a + δa) ≈ q exp(J δa), the Newton step is δa = J⁻¹ e (the paper's
//! p = −α J⁻¹ f with f = −e). Convergence: position error |p* − p| ≤ tol and rotation angle
//! ∠(R, R*) ≤ tol; the reported residual is their sum.
//!
//! This module is the 3-D model's search behind [`crate::solver`] ([`Spatial`] implements
//! [`InverseGeometry`]); the paper's Newton is the generic `crate::solver` one.
//!
//! * The robust search: the globalised Newton/LM of `solver::globalised` (backtracking
//!   on the merit |e|, trial points that leave the stable set rejected, Levenberg–Marquardt
//!   steps when Newton's fail, a cap on the step length), multi-started from a short list of
//!   stable seeds derived from the target. Every returned solution has passed the stability
//!   test.
//!
//! All loops are bounded (iterations × backtracking steps × starts).

use super::stability::evaluate_if_stable;
use super::Spatial;
use super::{Evaluation3d, SpatialParams, SpatialPose, StabilityOptions, Stiffness};
use crate::solver::globalised::{self, Iterate, Problem, Settings};
use crate::solver::{
    emit, Event, Failure, Found, IgError, InverseGeometry, Solution, SolveOptions, Termination,
    Verified, Work,
};
use nalgebra::{Matrix6, Vector3, Vector6};

/// Seeds tried at most by the robust search (the length of [`seeds_for`]'s list) unless
/// `SolveOptions::max_starts` says otherwise.
pub const DEFAULT_MAX_STARTS: u32 = 12;

/// The starts the 3-D search tries at most.
fn max_starts(options: &SolveOptions3d) -> usize {
    options.max_starts.unwrap_or(DEFAULT_MAX_STARTS).max(1) as usize
}

/// A 3-D solution.
pub type Solution3d = Solution<SpatialParams, SpatialPose>;
/// A failed 3-D solve.
pub type Failure3d = Failure<SpatialParams>;
/// Options of a 3-D solve.
pub type SolveOptions3d = SolveOptions<SpatialParams>;

/// Checks a 3-D target: finite, and ‖p*‖ ≤ 1 (the unit rod is inextensible).
pub fn check_target(target: &SpatialPose) -> Result<(), IgError> {
    let p = target.position;
    for (component, value) in [
        ("position.x", p.x),
        ("position.y", p.y),
        ("position.z", p.z),
    ] {
        if !value.is_finite() {
            return Err(IgError::NonFiniteTarget { component, value });
        }
    }
    if let Some(&value) = target.rotation.coords.iter().find(|v| !v.is_finite()) {
        return Err(IgError::NonFiniteTarget {
            component: "orientation",
            value,
        });
    }
    let distance = p.norm();
    if distance > 1.0 {
        return Err(IgError::Unreachable { distance });
    }
    Ok(())
}

struct Ctx<'a> {
    target: &'a SpatialPose,
    /// Current goal: the target, or an intermediate pose of the continuation.
    goal: SpatialPose,
    /// Tolerance on the current goal.
    goal_tol: f64,
    opts: &'a SolveOptions3d,
    model: &'a Spatial,
    /// Starts begun (for the observer's events).
    starts: u32,
    evaluations: u32,
    iterations: u32,
    best: (f64, Option<SpatialParams>),
}

enum EvalOutcome {
    Stable(Box<Evaluation3d>),
    Unstable,
}

/// Coarse stride of the stability scan on intermediate iterates: step ends only, no dense
/// output (the final answer is always re-checked with [`StabilityOptions::production`]).
const ITERATE_STRIDE: u32 = 0;
/// Loosest integration tolerance used far from the solution.
const LOOSE_RTOL: f64 = 1e-5;

impl Ctx<'_> {
    /// Integration tolerance for an iterate with residual `res`: about 1e-3·res, within
    /// [opts.rtol, 1e-5] — far from the target, tip and J need few digits.
    fn rtol_for(&self, res: f64) -> f64 {
        let lo = self.model.rtol;
        (1e-3 * res).clamp(lo, LOOSE_RTOL.max(lo))
    }

    fn stab_options(&self, rtol: f64, verify: bool) -> StabilityOptions {
        if verify {
            StabilityOptions {
                rtol: self.model.rtol,
                ..StabilityOptions::production()
            }
        } else {
            StabilityOptions {
                rtol,
                atol: (rtol * 1e-2).max(1e-12),
                coarse_stride: ITERATE_STRIDE,
            }
        }
    }

    fn eval(&mut self, a: &SpatialParams, rtol: f64, verify: bool) -> Result<EvalOutcome, IgError> {
        if crate::deadline::expired() {
            return Err(IgError::Deadline {
                iteration: self.iterations,
            });
        }
        self.evaluations += 1;
        let so = self.stab_options(rtol, verify);
        match evaluate_if_stable(a, &self.model.stiffness, &so) {
            Ok((Some(ev), _)) => {
                let (pe, ang) = ev.tip.distance_to(self.target);
                if pe.hypot(ang) < self.best.0 {
                    self.best = (pe.hypot(ang), Some(*a));
                }
                Ok(EvalOutcome::Stable(Box::new(ev)))
            }
            Ok((None, _)) => Ok(EvalOutcome::Unstable),
            Err(e) => Err(IgError::of_evaluation(self.iterations, &e)),
        }
    }

    fn converged(&self, ev: &Evaluation3d) -> Option<(f64, f64)> {
        let (pe, ang) = ev.tip.distance_to(&self.goal);
        (pe <= self.goal_tol && ang <= self.goal_tol).then_some((pe, ang))
    }

    fn set_goal(&mut self, goal: SpatialPose, tol: f64) {
        self.goal = goal;
        self.goal_tol = tol;
    }

    fn final_goal(&mut self) {
        self.goal = *self.target;
        self.goal_tol = self.opts.tolerance;
    }

    /// The solution `a` (evaluated as `ev`) found by start number `start` (0-based).
    fn solution(&self, a: SpatialParams, ev: &Evaluation3d, start: u32) -> Solution3d {
        let verified = Verified {
            tip: ev.tip,
            errors: ev.tip.distance_to(self.target),
            energy: ev.energy,
            margin: ev.stability.margin,
        };
        let work = Work {
            iterations: self.iterations,
            evaluations: self.evaluations,
            starts: start + 1,
        };
        Solution {
            stable: ev.stability.stable,
            ..Solution::new(a, verified, work)
        }
    }

    fn failure(&self, reason: IgError) -> Failure3d {
        Failure {
            reason,
            iterations: self.iterations,
            residual: self.best.0,
            last_a: self.best.1,
            starts: self.starts,
            elapsed_us: 0.0,
        }
    }
}

/// Largest step ‖δa‖₂ the robust method takes at once.
fn step_cap(a: &SpatialParams) -> f64 {
    10.0 + 0.5 * a.norm()
}

/// Evaluations one start may use before the robust method moves on to the next seed.
const START_BUDGET: u32 = 40;

/// One run of the globalised Newton/LM ([`globalised`]) on the 3-D rod towards `ctx.goal`:
/// residual f = −e(a) (module docs), trials integrated at a tolerance adapted to the residual
/// and rejected when they leave the stable set, steps capped at [`step_cap`] in length.
struct SpatialSteps<'c, 'a> {
    ctx: &'c mut Ctx<'a>,
}

fn iterate(goal: &SpatialPose, ev: Box<Evaluation3d>) -> Iterate<6, Box<Evaluation3d>> {
    let e = ev.tip.body_error_to(goal);
    Iterate {
        f: -e,
        norm: e.norm(),
        jacobian: ev.jacobian,
        data: ev,
    }
}

impl Problem<6> for SpatialSteps<'_, '_> {
    type Data = Box<Evaluation3d>;

    fn evaluate(
        &mut self,
        a: &SpatialParams,
        from: f64,
    ) -> Result<Option<Iterate<6, Self::Data>>, IgError> {
        // The residual after a full step is ~0 near the solution: tighten with it.
        let rtol = self.ctx.rtol_for(from * 0.1);
        Ok(match self.ctx.eval(a, rtol, false)? {
            EvalOutcome::Stable(ev) => Some(iterate(&self.ctx.goal, ev)),
            EvalOutcome::Unstable => None,
        })
    }

    fn converged(&self, x: &Iterate<6, Self::Data>) -> bool {
        self.ctx.converged(&x.data).is_some()
    }

    fn step_scale(&self, a: &SpatialParams, p: &Vector6<f64>) -> f64 {
        p.norm() / step_cap(a)
    }

    fn solve(&self, m: &Matrix6<f64>, r: &Vector6<f64>) -> Option<Vector6<f64>> {
        m.lu().solve(r).filter(|x| x.iter().all(|v| v.is_finite()))
    }
}

/// Damped Newton towards `ctx.goal` from one stable start (module docs), using at most
/// `budget` evaluations. Iterates are integrated at a tolerance adapted to their residual. With
/// `verify`, a converged iterate is re-evaluated and re-checked for stability at the requested
/// accuracy before it is returned (iterations continue if it no longer meets the tolerance).
fn damped_newton(
    ctx: &mut Ctx,
    a0: SpatialParams,
    ev0: Box<Evaluation3d>,
    budget: u32,
    verify: bool,
) -> Result<(SpatialParams, Box<Evaluation3d>, u32), IgError> {
    let mut a = a0;
    let mut x = iterate(&ctx.goal, ev0);
    let mut it = 0;
    let budget_end = ctx.evaluations.saturating_add(budget);
    loop {
        let settings = Settings {
            alpha: ctx.opts.alpha,
            max_iterations: ctx.opts.max_iterations.saturating_sub(it),
            max_evaluations: budget_end.saturating_sub(ctx.evaluations),
        };
        let r = globalised::run(&mut SpatialSteps { ctx }, a, x, &settings)?;
        it += r.iterations;
        ctx.iterations += r.iterations;
        match r.stop {
            globalised::Stop::Converged if !verify => return Ok((r.a, r.last.data, it)),
            globalised::Stop::Converged => {
                // Verify at the requested accuracy with the fine stability scan.
                match ctx.eval(&r.a, ctx.model.rtol, true)? {
                    EvalOutcome::Stable(vev) if ctx.converged(&vev).is_some() => {
                        return Ok((r.a, vev, it))
                    }
                    EvalOutcome::Stable(vev) => {
                        a = r.a;
                        x = iterate(&ctx.goal, vev);
                    }
                    EvalOutcome::Unstable => {
                        return Err(IgError::LeftStableSet {
                            iteration: ctx.iterations,
                        })
                    }
                }
            }
            globalised::Stop::MaxIterations | globalised::Stop::Budget => {
                return Err(IgError::MaxIterations {
                    iterations: ctx.opts.max_iterations,
                })
            }
            globalised::Stop::Deadline => {
                return Err(IgError::Deadline {
                    iteration: ctx.iterations,
                })
            }
            globalised::Stop::Stalled if r.last_trial_rejected => {
                return Err(IgError::LeftStableSet {
                    iteration: ctx.iterations,
                })
            }
            globalised::Stop::Stalled => {
                return Err(IgError::Stalled {
                    iteration: ctx.iterations,
                })
            }
        }
    }
}

/// Evaluations one continuation sub-step may use.
const SUBSTEP_BUDGET: u32 = 10;
/// Tolerance on the intermediate goals of the continuation.
const SUBSTEP_TOL: f64 = 1e-3;
/// Smallest continuation step before giving up.
const MIN_DS: f64 = 1.0 / 256.0;

/// Continuation (homotopy) in the target: from the stable rod `a0` with tip q0, track
/// q(s) = (p0 + s (p* − p0), R0 exp(s log(R0ᵀ R*))) for s: 0 → 1 with damped Newton on each
/// intermediate goal, halving the s-step on failure and doubling it on success. It follows a
/// path of stable rods, which plain Newton from a distant seed may jump off.
fn continuation(
    ctx: &mut Ctx,
    a0: SpatialParams,
    ev0: Box<Evaluation3d>,
) -> Result<(SpatialParams, Box<Evaluation3d>, u32), IgError> {
    let q0 = ev0.tip;
    let dp = ctx.target.position - q0.position;
    let dr = (q0.rotation.inverse() * ctx.target.rotation).scaled_axis();
    let (mut a, mut ev) = (a0, ev0);
    let (mut s, mut ds) = (0.0f64, 0.25f64);
    let mut its = 0;
    let mut last = IgError::Stalled {
        iteration: ctx.iterations,
    };
    for _ in 0..64 {
        let s_new = (s + ds).min(1.0);
        let last_step = s_new >= 1.0;
        if last_step {
            ctx.final_goal();
        } else {
            let goal = SpatialPose {
                position: q0.position + dp * s_new,
                rotation: q0.rotation * nalgebra::UnitQuaternion::from_scaled_axis(dr * s_new),
            };
            ctx.set_goal(goal, SUBSTEP_TOL);
        }
        let budget = if last_step {
            START_BUDGET
        } else {
            SUBSTEP_BUDGET
        };
        match damped_newton(ctx, a, ev.clone(), budget, last_step) {
            Ok((a2, ev2, it)) => {
                its += it;
                if last_step {
                    return Ok((a2, ev2, its));
                }
                a = a2;
                ev = ev2;
                s = s_new;
                ds = (ds * 2.0).min(0.5);
            }
            Err(e @ IgError::Evaluation { .. }) => return Err(e),
            Err(e) => {
                last = e;
                ds *= 0.5;
                if ds < MIN_DS {
                    break;
                }
            }
        }
    }
    ctx.final_goal();
    Err(last)
}

/// Stable seeds already evaluated, reused by the continuation.
type StableSeeds = Vec<(SpatialParams, Box<Evaluation3d>)>;

/// Damped Newton from the seed `a0` (evaluated at `rtol0`): the solution, or `None` with the
/// reason in `last`. Stable seeds are remembered in `stable_seeds`.
fn attempt_plain(
    ctx: &mut Ctx,
    a0: SpatialParams,
    rtol0: f64,
    stable_seeds: &mut StableSeeds,
    last: &mut IgError,
) -> Option<(SpatialParams, Box<Evaluation3d>, u32)> {
    let index = ctx.starts;
    ctx.starts += 1;
    emit(Event::StartBegun {
        index,
        a0_norm: a0.norm(),
    });
    let r = attempt_plain_inner(ctx, a0, rtol0, stable_seeds, last);
    emit(Event::StartEnded {
        index,
        termination: match &r {
            Some(_) => Termination::Converged,
            None => last.termination(),
        },
    });
    r
}

fn attempt_plain_inner(
    ctx: &mut Ctx,
    a0: SpatialParams,
    rtol0: f64,
    stable_seeds: &mut StableSeeds,
    last: &mut IgError,
) -> Option<(SpatialParams, Box<Evaluation3d>, u32)> {
    let ev0 = match ctx.eval(&a0, rtol0, false) {
        Ok(EvalOutcome::Stable(ev)) => ev,
        Ok(EvalOutcome::Unstable) => {
            *last = IgError::LeftStableSet {
                iteration: ctx.iterations,
            };
            return None;
        }
        Err(e) => {
            *last = e;
            return None;
        }
    };
    stable_seeds.push((a0, ev0.clone()));
    ctx.final_goal();
    match damped_newton(ctx, a0, ev0, START_BUDGET, true) {
        Ok(r) => Some(r),
        Err(e) => {
            *last = e;
            None
        }
    }
}

/// Number of seeds tried by plain damped Newton before the first continuation attempt.
const PLAIN_FIRST: usize = 4;

fn robust(ctx: &mut Ctx) -> Result<Solution3d, Failure3d> {
    let mut list: Vec<SpatialParams> = Vec::with_capacity(16);
    if let Some(g) = ctx.opts.initial_guess {
        list.push(g);
    }
    list.extend(seeds_for(ctx.target, &ctx.model.stiffness));
    list.truncate(max_starts(ctx.opts));
    let mut last = IgError::LeftStableSet {
        iteration: ctx.iterations,
    };
    let mut tried: u32 = 0;
    let rtol0 = LOOSE_RTOL.max(ctx.model.rtol);
    // Stable seeds (evaluated lazily), reused by the continuation.
    let mut stable_seeds: StableSeeds = Vec::new();
    let n_first = PLAIN_FIRST.min(list.len());
    for (i, a0) in list.iter().take(n_first).enumerate() {
        tried += 1;
        if let Some((a, ev, _)) = attempt_plain(ctx, *a0, rtol0, &mut stable_seeds, &mut last) {
            return Ok(ctx.solution(a, &ev, i as u32));
        }
    }
    // Continuation from the closest stable rod seen so far.
    if let Some(ab) = ctx.best.1 {
        tried += 1;
        if let Ok(EvalOutcome::Stable(evb)) = ctx.eval(&ab, rtol0, false) {
            match continuation(ctx, ab, evb) {
                Ok((a, ev, _)) => return Ok(ctx.solution(a, &ev, tried - 1)),
                Err(e) => last = e,
            }
        }
    }
    for a0 in list.iter().skip(n_first) {
        tried += 1;
        if let Some((a, ev, _)) = attempt_plain(ctx, *a0, rtol0, &mut stable_seeds, &mut last) {
            return Ok(ctx.solution(a, &ev, tried - 1));
        }
    }
    // Continuation from the first stable seeds.
    for (a0, ev0) in stable_seeds.into_iter().take(2) {
        tried += 1;
        match continuation(ctx, a0, ev0) {
            Ok((a, ev, _)) => return Ok(ctx.solution(a, &ev, tried - 1)),
            Err(e) => last = e,
        }
    }
    if matches!(last, IgError::Deadline { .. }) {
        // Every start after the deadline ended at once: the deadline is the reason.
        return Err(ctx.failure(last));
    }
    Err(ctx.failure(IgError::NoStableSolution {
        starts: tried,
        last: Some(Box::new(last)),
    }))
}

impl Ctx<'_> {
    fn new<'a>(model: &'a Spatial, target: &'a SpatialPose, opts: &'a SolveOptions3d) -> Ctx<'a> {
        Ctx {
            target,
            goal: *target,
            goal_tol: opts.tolerance,
            opts,
            model,
            starts: 0,
            evaluations: 0,
            iterations: 0,
            best: (f64::INFINITY, None),
        }
    }
}

impl InverseGeometry<6> for Spatial {
    /// Damped Newton from the seeds (continuation when plain Newton fails), module docs.
    fn robust(
        &self,
        target: &SpatialPose,
        options: &SolveOptions3d,
    ) -> Result<Solution3d, Failure3d> {
        robust(&mut Ctx::new(self, target, options))
    }

    /// Damped Newton from the initial guess and every seed, each run to the end; the distinct
    /// stable solutions.
    fn robust_all(
        &self,
        target: &SpatialPose,
        options: &SolveOptions3d,
    ) -> Found<SpatialParams, SpatialPose> {
        let mut ctx = Ctx::new(self, target, options);
        let mut list: Vec<SpatialParams> = options.initial_guess.into_iter().collect();
        list.extend(seeds_for(target, &self.stiffness));
        list.truncate(max_starts(options) + usize::from(options.initial_guess.is_some()));
        let rtol0 = LOOSE_RTOL.max(self.rtol);
        let scale = crate::solver::RodModel::param_scale(self);
        let mut solutions: Vec<Solution3d> = Vec::new();
        let (mut seeds, mut last) = (Vec::new(), IgError::LeftStableSet { iteration: 0 });
        for a0 in list {
            if crate::deadline::expired() {
                break;
            }
            if let Some((a, ev, _)) = attempt_plain(&mut ctx, a0, rtol0, &mut seeds, &mut last) {
                if solutions.iter().all(|s| {
                    crate::solver::relative_distance(&s.a, &a, &scale) > crate::solver::DISTINCT
                }) {
                    let starts = ctx.starts;
                    solutions.push(ctx.solution(a, &ev, starts - 1));
                }
            }
        }
        Found {
            solutions,
            iterations: ctx.iterations,
            evaluations: ctx.evaluations,
            starts: ctx.starts,
        }
    }

    fn default_start(&self, target: &SpatialPose) -> Option<SpatialParams> {
        seeds_for(target, &self.stiffness).first().copied()
    }
}

/// Starting points for the target, most promising first:
/// 1. a constant-curvature arc through the target position (moment 2∠(e1, p*) about
///    e1 × p*, no force);
/// 2. a force-free rod with the target orientation (moment log R*);
/// 3. their mean, then small fixed perturbations of 1 and 2 (bending moments of both signs,
///    axial tension), which are stable seeds for the usual targets.
///
/// Exact straight configurations (zero bending moment) are nudged, since straight rods are
/// unstable by the det J rule.
/// [`seeds`] for a rod of stiffness `k`: the unit-stiffness seeds are curvatures, so the
/// moments scale by c1, c2, c3 and the forces by the bending stiffness (c2 + c3)/2 (a force
/// F on a rod of bending stiffness EI bends it like F/EI on the unit rod).
pub fn seeds_for(target: &SpatialPose, k: &Stiffness) -> Vec<SpatialParams> {
    let bending = 0.5 * (k.c2 + k.c3);
    seeds(target)
        .into_iter()
        .map(|a| {
            SpatialParams::new(
                a[0] * k.c1,
                a[1] * k.c2,
                a[2] * k.c3,
                a[3] * bending,
                a[4] * bending,
                a[5] * bending,
            )
        })
        .collect()
}

/// Seeds of the robust method for the unit-stiffness rod (see [`seeds_for`]).
pub fn seeds(target: &SpatialPose) -> Vec<SpatialParams> {
    let p = target.position;
    let e1 = Vector3::x();
    let pn = p.norm();
    let arc = if pn > 1e-9 {
        let axis = e1.cross(&p);
        let an = axis.norm();
        let ang = axis.norm().atan2(p.x); // ∠(e1, p)
        if an > 1e-12 {
            axis / an * (2.0 * ang)
        } else if p.x < 0.0 {
            Vector3::new(0.0, 0.0, 2.0 * std::f64::consts::PI)
        } else {
            Vector3::zeros()
        }
    } else {
        Vector3::new(0.0, 0.0, 2.0 * std::f64::consts::PI)
    };
    let rot = target.rotation.scaled_axis();
    let nudge = |m: Vector3<f64>| -> Vector3<f64> {
        if m.y.abs() + m.z.abs() < 1e-3 {
            m + Vector3::new(0.0, 0.0, 0.3)
        } else {
            m
        }
    };
    let mk = |m: Vector3<f64>, f: Vector3<f64>| {
        let m = nudge(m);
        SpatialParams::new(m.x, m.y, m.z, f.x, f.y, f.z)
    };
    let z = Vector3::zeros();
    let mid = 0.5 * (arc + rot);
    vec![
        mk(arc, z),
        mk(rot, z),
        mk(mid, z),
        mk(arc + Vector3::new(rot.x, 0.0, 0.0), z),
        mk(arc * 0.5, Vector3::new(2.0, 0.0, 0.0)),
        mk(rot, Vector3::new(5.0, 0.0, 0.0)),
        mk(Vector3::new(0.0, 1.0, 1.0), z),
        mk(Vector3::new(0.0, -1.0, 1.0), z),
        mk(Vector3::new(0.0, 1.0, -1.0), z),
        mk(Vector3::new(0.0, -1.0, -1.0), z),
        mk(arc, Vector3::new(-5.0, 0.0, 0.0)),
        mk(rot * 0.5, z),
    ]
}
