//! Inverse geometry of the 3-D rod: find a stable a ∈ ℝ⁶ whose tip q(1, a) is a target pose.
//!
//! Residual (paper §3.1, in the body frame): e(a) = (log(Rᵀ R*), Rᵀ(p* − p)) ∈ ℝ⁶ with
//! (p, R) = q(1, a); since q(a + δa) ≈ q exp(J δa), the Newton step is δa = J⁻¹ e (the paper's
//! p = −α J⁻¹ f with f = −e). Convergence: position error |p* − p| ≤ tol and rotation angle
//! ∠(R, R*) ≤ tol; the reported residual is their sum.
//!
//! * [`Method3d::Newton`]: the paper's iteration a ← a + α J⁻¹ e from one guess; as in the
//!   paper's protocol (FINDINGS §8) it fails as soon as an iterate is unstable.
//! * [`Method3d::Robust`]: damped Newton with backtracking (the merit |e|² must decrease, and
//!   trial points that leave the stable set are rejected), a Levenberg–Marquardt fallback when J
//!   is singular, a cap on the step length, and multi-start from a short list of stable seeds
//!   derived from the target. Every returned solution has passed the stability test.
//!
//! All loops are bounded (iterations × backtracking steps × starts).

use super::stability::evaluate_if_stable;
use super::{
    check_rtol, Evaluation3d, SpatialParams, SpatialPose, StabilityOptions, Stiffness,
    PRODUCTION_RTOL,
};
use crate::RodError;
use nalgebra::{Matrix6, Vector3, Vector6};
use thiserror::Error;

/// Which iteration to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method3d {
    /// Damped, stability-preserving Newton with multi-start (default).
    #[default]
    Robust,
    /// The paper's fixed-step Newton from one guess.
    Newton,
}

/// Options of [`solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveOptions3d {
    /// Iteration to run.
    pub method: Method3d,
    /// Newton step length α ∈ (0, 1] (paper §3.1); the robust method starts its line search here.
    pub alpha: f64,
    /// Iteration limit per start.
    pub max_iterations: u32,
    /// Tolerance on the position error (rod lengths) and on the rotation angle (rad).
    pub tolerance: f64,
    /// Starting point (tried first by the robust method; required by nothing).
    pub initial_guess: Option<SpatialParams>,
    /// Rod stiffnesses.
    pub stiffness: Stiffness,
    /// Relative tolerance of the integrations (default [`PRODUCTION_RTOL`] = 1e-8).
    pub rtol: f64,
    /// Robust method: number of seeds tried at most.
    pub max_starts: u32,
    /// Wall-time budget of one call ([`DEFAULT_DEADLINE_3D`], at most
    /// [`crate::ig::MAX_DEADLINE`]); every evaluation polls it.
    pub deadline: std::time::Duration,
}

/// Default wall-time budget of one 3-D solve: 1 s. The robust 3-D solve takes 0.3 ms median,
/// 1.2 ms p90 on random stable rods (`rod-ig bench --only spatial`); each evaluation integrates
/// 44 variational states, so a hard target may need a few hundred ms.
pub const DEFAULT_DEADLINE_3D: std::time::Duration = std::time::Duration::from_secs(1);

impl Default for SolveOptions3d {
    fn default() -> Self {
        Self {
            method: Method3d::Robust,
            alpha: 1.0,
            max_iterations: 100,
            tolerance: 1e-6,
            initial_guess: None,
            stiffness: Stiffness::default(),
            rtol: PRODUCTION_RTOL,
            max_starts: 12,
            deadline: DEFAULT_DEADLINE_3D,
        }
    }
}

/// A converged, stable solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution3d {
    /// Parameters a = μ(0).
    pub a: SpatialParams,
    /// Tip pose q(1, a).
    pub tip: SpatialPose,
    /// Stability verdict (always true for the robust method).
    pub stable: bool,
    /// Normalised stability margin ([`super::det_leading_term`]).
    pub stability_margin: f64,
    /// Newton iterations of the successful start.
    pub iterations: u32,
    /// Rod integrations used in total (all starts).
    pub evaluations: u32,
    /// Index of the successful start (0 = first seed).
    pub start: u32,
    /// |p* − p|.
    pub position_error: f64,
    /// ∠(R, R*) in rad.
    pub orientation_error: f64,
    /// position_error + orientation_error.
    pub residual: f64,
    /// Elastic energy ½∫ Σ μ_i²/c_i.
    pub energy: f64,
}

/// Why the 3-D solver failed.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum IgError3d {
    /// The target has a non-finite component.
    #[error("target is not finite")]
    NonFiniteTarget,
    /// The target position is farther than the rod length (1).
    #[error("target out of reach: |p| = {distance} > 1")]
    Unreachable {
        /// |p*|.
        distance: f64,
    },
    /// Invalid options (α, tolerance, rtol, stiffness).
    #[error("invalid options: {0}")]
    InvalidOptions(String),
    /// J(1, a) is singular (Newton).
    #[error("singular Jacobian")]
    SingularJacobian,
    /// An iterate (Newton) or every trial step (robust) left the stable set.
    #[error("iterate left the stable set")]
    LeftStableSet,
    /// The line search found no decrease of the residual.
    #[error("no decrease of the residual along the Newton direction")]
    Stalled,
    /// The iteration limit was reached.
    #[error("iteration limit reached")]
    MaxIterations,
    /// The deadline ([`SolveOptions3d::deadline`]) passed before convergence.
    #[error("deadline reached without convergence")]
    Deadline,
    /// An integration failed or produced non-finite values.
    #[error("rod evaluation failed: {0}")]
    Evaluation(String),
    /// No start of the robust method reached a stable solution.
    #[error("no stable solution found from {starts} starts (last: {last})")]
    NoStableSolution {
        /// Starts tried.
        starts: u32,
        /// The failure of the last start.
        last: Box<IgError3d>,
    },
}

/// A failed solve: reason, work done, and the best iterate seen.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure3d {
    /// Why.
    pub reason: IgError3d,
    /// Iterations (all starts).
    pub iterations: u32,
    /// Smallest residual (position + angle) seen, ∞ if none.
    pub residual: f64,
    /// The iterate with that residual.
    pub last_a: Option<SpatialParams>,
}

impl std::fmt::Display for Failure3d {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} after {} iterations (best residual {:e})",
            self.reason, self.iterations, self.residual
        )
    }
}

impl std::error::Error for Failure3d {}

struct Ctx<'a> {
    target: &'a SpatialPose,
    /// Current goal: the target, or an intermediate pose of the continuation.
    goal: SpatialPose,
    /// Tolerance on the current goal.
    goal_tol: f64,
    opts: &'a SolveOptions3d,
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
        let lo = self.opts.rtol;
        (1e-3 * res).clamp(lo, LOOSE_RTOL.max(lo))
    }

    fn stab_options(&self, rtol: f64, verify: bool) -> StabilityOptions {
        if verify {
            StabilityOptions {
                rtol: self.opts.rtol,
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

    fn eval(
        &mut self,
        a: &SpatialParams,
        rtol: f64,
        verify: bool,
    ) -> Result<EvalOutcome, IgError3d> {
        if crate::ig::deadline::expired() {
            return Err(IgError3d::Deadline);
        }
        self.evaluations += 1;
        let so = self.stab_options(rtol, verify);
        match evaluate_if_stable(a, &self.opts.stiffness, &so) {
            Ok((Some(ev), _)) => {
                let (pe, ang) = ev.tip.distance_to(self.target);
                if pe + ang < self.best.0 {
                    self.best = (pe + ang, Some(*a));
                }
                Ok(EvalOutcome::Stable(Box::new(ev)))
            }
            Ok((None, _)) => Ok(EvalOutcome::Unstable),
            Err(RodError::Integration(m)) | Err(RodError::Overflow(m)) => {
                Err(IgError3d::Evaluation(m))
            }
            Err(e) => Err(IgError3d::Evaluation(e.to_string())),
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

    fn solution(&self, a: SpatialParams, ev: &Evaluation3d, it: u32, start: u32) -> Solution3d {
        let (pe, ang) = ev.tip.distance_to(self.target);
        Solution3d {
            a,
            tip: ev.tip,
            stable: ev.stability.stable,
            stability_margin: ev.stability.margin,
            iterations: it,
            evaluations: self.evaluations,
            start,
            position_error: pe,
            orientation_error: ang,
            residual: pe + ang,
            energy: ev.energy,
        }
    }

    fn failure(&self, reason: IgError3d) -> Failure3d {
        Failure3d {
            reason,
            iterations: self.iterations,
            residual: self.best.0,
            last_a: self.best.1,
        }
    }
}

/// Newton direction: J d = e by LU; Levenberg–Marquardt (JᵀJ + λI) d = Jᵀ e when J is
/// (numerically) singular.
fn newton_direction(j: &Matrix6<f64>, e: &Vector6<f64>, allow_lm: bool) -> Option<Vector6<f64>> {
    if let Some(d) = j.lu().solve(e) {
        if d.iter().all(|v| v.is_finite()) {
            return Some(d);
        }
    }
    if !allow_lm {
        return None;
    }
    let jt = j.transpose();
    let jtj = jt * j;
    let lambda = 1e-6 * jtj.trace().max(1e-12);
    let m = jtj + Matrix6::identity() * lambda;
    m.cholesky()
        .map(|c| c.solve(&(jt * e)))
        .filter(|d| d.iter().all(|v| v.is_finite()))
}

fn validate(target: &SpatialPose, opts: &SolveOptions3d) -> Result<(), IgError3d> {
    if !target.is_finite() {
        return Err(IgError3d::NonFiniteTarget);
    }
    let dist = target.position.norm();
    if dist > 1.0 {
        return Err(IgError3d::Unreachable { distance: dist });
    }
    if !(opts.alpha.is_finite() && opts.alpha > 0.0 && opts.alpha <= 1.0) {
        return Err(IgError3d::InvalidOptions(format!(
            "alpha must be in (0, 1] (got {})",
            opts.alpha
        )));
    }
    if !(opts.tolerance.is_finite() && opts.tolerance >= crate::ig::MIN_TOLERANCE) {
        return Err(IgError3d::InvalidOptions(format!(
            "tolerance must be a finite number >= {:e} (got {:e})",
            crate::ig::MIN_TOLERANCE,
            opts.tolerance
        )));
    }
    if opts.max_iterations > crate::ig::MAX_ITERATIONS_LIMIT {
        return Err(IgError3d::InvalidOptions(format!(
            "max_iterations = {} exceeds the limit {}",
            opts.max_iterations,
            crate::ig::MAX_ITERATIONS_LIMIT
        )));
    }
    if opts.deadline.is_zero() || opts.deadline > crate::ig::MAX_DEADLINE {
        return Err(IgError3d::InvalidOptions(format!(
            "deadline = {:?} is not in (0, {:?}]",
            opts.deadline,
            crate::ig::MAX_DEADLINE
        )));
    }
    if let Some(g) = &opts.initial_guess {
        if g.iter().any(|v| !v.is_finite()) {
            return Err(IgError3d::InvalidOptions(
                "initial guess is not finite".into(),
            ));
        }
    }
    check_rtol(opts.rtol).map_err(|e| IgError3d::InvalidOptions(e.to_string()))?;
    opts.stiffness
        .validate()
        .map_err(|e| IgError3d::InvalidOptions(e.to_string()))
}

/// Solves the 3-D inverse geometry for `target` (base frame, unit rod length).
///
/// Errors are typed ([`IgError3d`]) and carry the best iterate seen; the work is bounded by
/// `max_iterations` per start (each with at most 12 trial evaluations) and `max_starts`.
pub fn solve(target: &SpatialPose, options: &SolveOptions3d) -> Result<Solution3d, Failure3d> {
    let mut ctx = Ctx {
        target,
        goal: *target,
        goal_tol: options.tolerance,
        opts: options,
        evaluations: 0,
        iterations: 0,
        best: (f64::INFINITY, None),
    };
    if let Err(e) = validate(target, options) {
        return Err(ctx.failure(e));
    }
    let _deadline = crate::ig::deadline::scope(options.deadline);
    match options.method {
        Method3d::Newton => {
            let a0 = options
                .initial_guess
                .unwrap_or_else(|| seeds_for(target, &options.stiffness)[0]);
            newton(&mut ctx, a0).map_err(|e| ctx.failure(e))
        }
        Method3d::Robust => robust(&mut ctx),
    }
}

/// The paper's Newton iteration a ← a + α J⁻¹ e, failing when an iterate is unstable.
fn newton(ctx: &mut Ctx, a0: SpatialParams) -> Result<Solution3d, IgError3d> {
    let mut a = a0;
    let mut ev = match ctx.eval(&a, ctx.opts.rtol, true)? {
        EvalOutcome::Stable(ev) => ev,
        EvalOutcome::Unstable => return Err(IgError3d::LeftStableSet),
    };
    for it in 0..=ctx.opts.max_iterations {
        if ctx.converged(&ev).is_some() {
            return Ok(ctx.solution(a, &ev, it, 0));
        }
        if it == ctx.opts.max_iterations {
            break;
        }
        ctx.iterations += 1;
        let e = ev.tip.body_error_to(ctx.target);
        let d = newton_direction(&ev.jacobian, &e, false).ok_or(IgError3d::SingularJacobian)?;
        a += ctx.opts.alpha * d;
        ev = match ctx.eval(&a, ctx.opts.rtol, true)? {
            EvalOutcome::Stable(ev) => ev,
            EvalOutcome::Unstable => return Err(IgError3d::LeftStableSet),
        };
    }
    Err(IgError3d::MaxIterations)
}

/// Largest step ‖δa‖₂ the robust method takes at once.
fn step_cap(a: &SpatialParams) -> f64 {
    10.0 + 0.5 * a.norm()
}

const MAX_BACKTRACK: u32 = 12;
/// Evaluations one start may use before the robust method moves on to the next seed.
const START_BUDGET: u32 = 40;

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
) -> Result<(SpatialParams, Box<Evaluation3d>, u32), IgError3d> {
    let mut a = a0;
    let mut ev = ev0;
    let mut e = ev.tip.body_error_to(&ctx.goal);
    let mut merit = e.norm_squared();
    let mut it = 0;
    let budget_end = ctx.evaluations.saturating_add(budget);
    loop {
        if ctx.converged(&ev).is_some() {
            if !verify {
                return Ok((a, ev, it));
            }
            // Verify at the requested accuracy with the fine stability scan.
            match ctx.eval(&a, ctx.opts.rtol, true)? {
                EvalOutcome::Stable(vev) => {
                    if ctx.converged(&vev).is_some() {
                        return Ok((a, vev, it));
                    }
                    ev = vev;
                    e = ev.tip.body_error_to(&ctx.goal);
                    merit = e.norm_squared();
                }
                EvalOutcome::Unstable => return Err(IgError3d::LeftStableSet),
            }
        }
        if it >= ctx.opts.max_iterations || ctx.evaluations >= budget_end {
            return Err(IgError3d::MaxIterations);
        }
        it += 1;
        ctx.iterations += 1;
        let Some(mut d) = newton_direction(&ev.jacobian, &e, true) else {
            return Err(IgError3d::SingularJacobian);
        };
        let n = d.norm();
        let cap = step_cap(&a);
        if n > cap {
            d *= cap / n;
        }
        let mut alpha = ctx.opts.alpha;
        let mut accepted = None;
        let mut last_unstable = false;
        // Predicted residual after a full step is ~0 near the solution: tighten with it.
        let trial_rtol = ctx.rtol_for(merit.sqrt() * 0.1);
        for _ in 0..MAX_BACKTRACK {
            let trial = a + alpha * d;
            match ctx.eval(&trial, trial_rtol, false)? {
                EvalOutcome::Stable(tev) => {
                    let te = tev.tip.body_error_to(&ctx.goal);
                    let tm = te.norm_squared();
                    if tm < (1.0 - 1e-4 * alpha) * merit || ctx.converged(&tev).is_some() {
                        accepted = Some((trial, tev, te, tm));
                        break;
                    }
                    last_unstable = false;
                }
                EvalOutcome::Unstable => last_unstable = true,
            }
            if ctx.evaluations >= budget_end {
                break;
            }
            alpha *= 0.5;
        }
        match accepted {
            Some((ta, tev, te, tm)) => {
                a = ta;
                ev = tev;
                e = te;
                merit = tm;
            }
            None => {
                return Err(if last_unstable {
                    IgError3d::LeftStableSet
                } else {
                    IgError3d::Stalled
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
) -> Result<(SpatialParams, Box<Evaluation3d>, u32), IgError3d> {
    let q0 = ev0.tip;
    let dp = ctx.target.position - q0.position;
    let dr = (q0.rotation.inverse() * ctx.target.rotation).scaled_axis();
    let (mut a, mut ev) = (a0, ev0);
    let (mut s, mut ds) = (0.0f64, 0.25f64);
    let mut its = 0;
    let mut last = IgError3d::Stalled;
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
            Err(e @ IgError3d::Evaluation(_)) => return Err(e),
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

/// Number of seeds tried by plain damped Newton before the first continuation attempt.
const PLAIN_FIRST: usize = 4;

fn robust(ctx: &mut Ctx) -> Result<Solution3d, Failure3d> {
    let mut list: Vec<SpatialParams> = Vec::with_capacity(16);
    if let Some(g) = ctx.opts.initial_guess {
        list.push(g);
    }
    list.extend(seeds_for(ctx.target, &ctx.opts.stiffness));
    list.truncate(ctx.opts.max_starts.max(1) as usize);
    let mut last = IgError3d::LeftStableSet;
    let mut tried: u32 = 0;
    let rtol0 = LOOSE_RTOL.max(ctx.opts.rtol);
    // Stable seeds (evaluated lazily), reused by the continuation.
    let mut stable_seeds: Vec<(SpatialParams, Box<Evaluation3d>)> = Vec::new();
    let attempt_plain = |ctx: &mut Ctx,
                         a0: SpatialParams,
                         stable_seeds: &mut Vec<(SpatialParams, Box<Evaluation3d>)>,
                         last: &mut IgError3d|
     -> Option<(SpatialParams, Box<Evaluation3d>, u32)> {
        let ev0 = match ctx.eval(&a0, rtol0, false) {
            Ok(EvalOutcome::Stable(ev)) => ev,
            Ok(EvalOutcome::Unstable) => {
                *last = IgError3d::LeftStableSet;
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
    };
    let n_first = PLAIN_FIRST.min(list.len());
    for (i, a0) in list.iter().take(n_first).enumerate() {
        tried += 1;
        if let Some((a, ev, it)) = attempt_plain(ctx, *a0, &mut stable_seeds, &mut last) {
            return Ok(ctx.solution(a, &ev, it, i as u32));
        }
    }
    // Continuation from the closest stable rod seen so far.
    if let Some(ab) = ctx.best.1 {
        tried += 1;
        if let Ok(EvalOutcome::Stable(evb)) = ctx.eval(&ab, rtol0, false) {
            match continuation(ctx, ab, evb) {
                Ok((a, ev, it)) => return Ok(ctx.solution(a, &ev, it, tried - 1)),
                Err(e) => last = e,
            }
        }
    }
    for a0 in list.iter().skip(n_first) {
        tried += 1;
        if let Some((a, ev, it)) = attempt_plain(ctx, *a0, &mut stable_seeds, &mut last) {
            return Ok(ctx.solution(a, &ev, it, tried - 1));
        }
    }
    // Continuation from the first stable seeds.
    for (a0, ev0) in stable_seeds.into_iter().take(2) {
        tried += 1;
        match continuation(ctx, a0, ev0) {
            Ok((a, ev, it)) => return Ok(ctx.solution(a, &ev, it, tried - 1)),
            Err(e) => last = e,
        }
    }
    Err(ctx.failure(IgError3d::NoStableSolution {
        starts: tried,
        last: Box::new(last),
    }))
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

pub use crate::rng::SplitMix64;

/// Half-widths of the random-target box: |a1..3| ≤ 5, |a4..6| ≤ 30 (FINDINGS3D: ≈ 70 % stable,
/// straddles the Euler load 4π² and the twist limit 8.99).
pub const TARGET_BOX: (f64, f64) = (5.0, 30.0);

/// `n` random stable rods from [`TARGET_BOX`] (rejection sampling with the production
/// stability test, at most 100·n draws) and their tips.
pub fn random_targets(n: usize, seed: u64, k: &Stiffness) -> Vec<(SpatialParams, SpatialPose)> {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::with_capacity(n);
    let (m, f) = TARGET_BOX;
    let opts = StabilityOptions::production();
    for _ in 0..n.saturating_mul(100) {
        if out.len() >= n {
            break;
        }
        let a = SpatialParams::from_fn(|i, _| {
            let h = if i < 3 { m } else { f };
            rng.range(-h, h)
        });
        if let Ok(ev) = super::evaluate(&a, k, &opts) {
            if ev.stability.stable {
                out.push((a, ev.tip));
            }
        }
    }
    out
}

/// Success rate and timings of the robust solver on random reachable targets.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchmarkReport3d {
    /// Targets attempted.
    pub targets: usize,
    /// Solves that returned a stable solution within tolerance.
    pub successes: usize,
    /// successes / targets.
    pub success_rate: f64,
    /// Median wall time per solve (µs).
    pub median_us: f64,
    /// 90th percentile wall time (µs).
    pub p90_us: f64,
    /// Largest wall time (µs).
    pub max_us: f64,
    /// Mean Newton iterations of the successful solves.
    pub mean_iterations: f64,
    /// Mean rod integrations per solve.
    pub mean_evaluations: f64,
    /// Successful solves that needed more than one start.
    pub restarts_used: usize,
    /// Failure reasons (Display strings) with counts.
    pub failures: Vec<(String, usize)>,
}

/// Runs the robust solver (default options) on `n` random stable targets ([`random_targets`])
/// and returns the success rate and timings (no I/O; the CLI prints them).
pub fn benchmark_random_targets(n: usize, seed: u64) -> BenchmarkReport3d {
    let k = Stiffness::default();
    let targets = random_targets(n, seed, &k);
    let opts = SolveOptions3d::default();
    let mut times = Vec::with_capacity(targets.len());
    let mut successes = 0;
    let mut iters = 0u64;
    let mut evals = 0u64;
    let mut restarts = 0;
    let mut failures: Vec<(String, usize)> = Vec::new();
    for (_, target) in &targets {
        let t0 = std::time::Instant::now();
        let r = solve(target, &opts);
        times.push(t0.elapsed().as_secs_f64() * 1e6);
        match r {
            Ok(sol) if sol.stable => {
                successes += 1;
                iters += sol.iterations as u64;
                evals += sol.evaluations as u64;
                if sol.start > 0 {
                    restarts += 1;
                }
            }
            Ok(_) => failures.push(("unstable solution".into(), 1)),
            Err(f) => {
                let key = match &f.reason {
                    IgError3d::NoStableSolution { last, .. } => {
                        format!("no stable solution ({last})")
                    }
                    other => other.to_string(),
                };
                failures.push((key, 1));
            }
        }
    }
    let mut merged: Vec<(String, usize)> = Vec::new();
    for (k, c) in failures {
        match merged.iter_mut().find(|(m, _)| *m == k) {
            Some(e) => e.1 += c,
            None => merged.push((k, c)),
        }
    }
    times.sort_by(f64::total_cmp);
    let pct = |p: f64| -> f64 {
        if times.is_empty() {
            0.0
        } else {
            times[((times.len() - 1) as f64 * p).round() as usize]
        }
    };
    let m = targets.len();
    BenchmarkReport3d {
        targets: m,
        successes,
        success_rate: if m > 0 {
            successes as f64 / m as f64
        } else {
            0.0
        },
        median_us: pct(0.5),
        p90_us: pct(0.9),
        max_us: times.last().copied().unwrap_or(0.0),
        mean_iterations: if successes > 0 {
            iters as f64 / successes as f64
        } else {
            0.0
        },
        mean_evaluations: if successes > 0 {
            evals as f64 / successes as f64
        } else {
            0.0
        },
        restarts_used: restarts,
        failures: merged,
    }
}
