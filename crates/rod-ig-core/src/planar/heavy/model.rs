//! The heavy planar rod as a model of the solvers ([`RodModel`], [`InverseGeometry`]).
//!
//! Its robust search starts from the weightless rods that reach the target (the closed
//! forms' atlas and search, exact at w = 0) and follows each to the rod's weight:
//! first one damped Newton run from the weightless rod with the load shared between the two
//! grippers (a + (0, w ĝ/2): the symmetric share, exact for a level rod), then, where that
//! fails, a continuation in w (secant predictor, Newton corrector, det J(1) keeping its sign
//! so the branch is not left). Every returned rod passed the heavy rod's stability test.

use super::{Gravity, HeavyEvaluation};
use crate::planar::ig::SolveOptions;
use crate::planar::model::{residual, solve3};
use crate::planar::PlanarClosedForm;
use crate::solver::{
    relative_distance, Failure, Found, IgError, InverseGeometry, ModelEvaluation, RodModel,
    Solution, Verified, Work, DISTINCT,
};
use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError};
use nalgebra::{SMatrix, Vector3};

/// The planar rod under its own weight ([`super`]): with [`Gravity::NONE`] it is
/// [`PlanarClosedForm`] exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeavyPlanar {
    /// Weight and direction of gravity.
    pub gravity: Gravity,
}

impl HeavyPlanar {
    /// The model for `gravity`.
    pub fn new(gravity: Gravity) -> Self {
        Self { gravity }
    }

    /// Tip, J, energies and stability ([`super::evaluate`]).
    pub fn evaluate_heavy(&self, a: &PlanarParams) -> Result<HeavyEvaluation, RodError> {
        super::evaluate(a, &self.gravity)
    }
}

impl RodModel<3> for HeavyPlanar {
    type Pose = PlanarPose;

    fn name(&self) -> &'static str {
        "planar rod with weight"
    }

    fn tip(&self, a: &Vector3<f64>) -> Result<PlanarPose, RodError> {
        super::tip(a, &self.gravity)
    }

    fn evaluate(&self, a: &Vector3<f64>) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        let e = super::evaluate(a, &self.gravity)?;
        Ok(ModelEvaluation {
            tip: e.tip,
            jacobian: e.jacobian,
            energy: e.energy,
            stability: e.stability,
            full_accuracy: true,
        })
    }

    fn tip_and_jacobian(&self, a: &Vector3<f64>) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        super::tip_and_jacobian(a, &self.gravity)
    }

    fn energy(&self, a: &Vector3<f64>) -> Result<f64, RodError> {
        Ok(super::energy(a, &self.gravity)?.0)
    }

    fn param_scale(&self) -> Vector3<f64> {
        PlanarClosedForm.param_scale()
    }

    fn pose_error(&self, tip: &PlanarPose, target: &PlanarPose) -> (f64, f64) {
        PlanarClosedForm.pose_error(tip, target)
    }

    fn newton_increment(
        &self,
        tip: &PlanarPose,
        jacobian: &SMatrix<f64, 3, 3>,
        target: &PlanarPose,
    ) -> Result<Vector3<f64>, f64> {
        PlanarClosedForm.newton_increment(tip, jacobian, target)
    }

    fn check_target(&self, target: &PlanarPose) -> Result<(), IgError> {
        PlanarClosedForm.check_target(target)
    }

    fn canonical_target(&self, target: &PlanarPose) -> PlanarPose {
        PlanarClosedForm.canonical_target(target)
    }

    fn jacobian_det(&self, jacobian: &SMatrix<f64, 3, 3>) -> f64 {
        jacobian.determinant()
    }

    fn interpolate(&self, from: &PlanarPose, to: &PlanarPose, s: f64) -> PlanarPose {
        PlanarClosedForm.interpolate(from, to, s)
    }
}

/// Newton iterations of one corrector run (a substep of the continuation).
const CORRECTOR_ITERATIONS: u32 = 8;
/// Tolerance of the continuation's intermediate rods.
const SUBSTEP_TOLERANCE: f64 = 1e-6;
/// Smallest continuation step, as a fraction of the whole change of load.
const MIN_FRACTION: f64 = 1.0 / 65536.0;
/// Largest change of the load w ĝ in one continuation substep.
const MAX_LOAD_STEP: f64 = 10.0;
/// Largest relative distance (scale 1) of a corrected substep from its prediction.
const MAX_CORRECTION: f64 = 0.3;
/// Halvings of a Newton step in the line search.
const LINE_SEARCH: u32 = 10;

/// The search's running state: the deadline, the budget and the work done.
struct Search<'a> {
    target: PlanarPose,
    options: &'a SolveOptions,
    work: Work,
    last_error: Option<IgError>,
}

fn norm(r: &Vector3<f64>) -> f64 {
    r.norm()
}

impl Search<'_> {
    fn out_of_time(&self) -> bool {
        crate::solver::deadline::expired()
    }

    /// Damped Newton on the rod of weight `g` from `a0` to `tol` (the residual may only
    /// decrease; det J(1) keeps the sign it had at `a0` when `keep_sign`).
    fn newton(
        &mut self,
        g: &Gravity,
        a0: &PlanarParams,
        tol: f64,
        max: u32,
    ) -> Option<PlanarParams> {
        let mut a = *a0;
        let (mut tip, mut jac) = self.eval(g, &a)?;
        let sign = jac.determinant().signum();
        for _ in 0..max {
            let r = residual(&tip, &self.target);
            if r[0].hypot(r[1]) <= tol && r[2].abs() <= tol {
                return Some(a);
            }
            if self.out_of_time() {
                self.last_error = Some(IgError::Deadline {
                    iteration: self.work.iterations,
                });
                return None;
            }
            let step = solve3(&jac, &-r).ok()?;
            let mut lambda = 1.0;
            let mut accepted = None;
            for _ in 0..LINE_SEARCH {
                let trial = a + step * lambda;
                if let Some((t, j)) = self.eval(g, &trial) {
                    if norm(&residual(&t, &self.target)) < norm(&r)
                        && j.determinant().signum() == sign
                    {
                        accepted = Some((trial, t, j));
                        break;
                    }
                }
                lambda *= 0.5;
            }
            let (na, nt, nj) = accepted?;
            self.work.iterations += 1;
            (a, tip, jac) = (na, nt, nj);
        }
        let r = residual(&tip, &self.target);
        (r[0].hypot(r[1]) <= tol && r[2].abs() <= tol).then_some(a)
    }

    fn eval(&mut self, g: &Gravity, a: &PlanarParams) -> Option<(PlanarPose, PlanarJacobian)> {
        self.work.evaluations += 1;
        match super::tip_and_jacobian(a, g) {
            Ok(v) => Some(v),
            Err(e) => {
                self.last_error = Some(IgError::Evaluation {
                    iteration: self.work.iterations,
                    detail: e.to_string(),
                });
                None
            }
        }
    }

    /// Follows the rod `a0`, on target under `from`, to the gravity `to`: the load w ĝ moves
    /// on the straight line between the two (a change of weight, or the base gripper turning).
    fn continuation(
        &mut self,
        from: &Gravity,
        to: &Gravity,
        a0: &PlanarParams,
    ) -> Option<PlanarParams> {
        let (l0, l1) = (from.load(), to.load());
        let load_at = |s: f64| [l0[0] + (l1[0] - l0[0]) * s, l0[1] + (l1[1] - l0[1]) * s];
        let (mut s, mut a) = (0.0f64, *a0);
        let mut prev: Option<(f64, PlanarParams)> = None;
        // Substeps change the load by at most MAX_LOAD_STEP (the rod's response is ~ half of it).
        let change = (l1[0] - l0[0]).hypot(l1[1] - l0[1]);
        let max_ds = (MAX_LOAD_STEP / change).min(0.5);
        let mut ds = 0.5 * max_ds;
        while s < 1.0 {
            if self.out_of_time() {
                return None;
            }
            let s1 = (s + ds).min(1.0);
            let guess = match prev {
                Some((sp, ap)) if s > sp => a + (a - ap) * ((s1 - s) / (s - sp)),
                _ => {
                    // The symmetric share of the load's change.
                    let d = [l1[0] - l0[0], l1[1] - l0[1]];
                    a + Vector3::new(0.0, 0.5 * d[0], 0.5 * d[1]) * (s1 - s)
                }
            };
            let gs = Gravity::from_load(load_at(s1), to.direction()).ok()?;
            // A corrector that lands far from its predictor may have jumped to another branch.
            let corrected = self
                .newton(&gs, &guess, SUBSTEP_TOLERANCE, CORRECTOR_ITERATIONS)
                .filter(|next| {
                    relative_distance(next, &guess, &Vector3::repeat(1.0)) <= MAX_CORRECTION
                });
            match corrected {
                Some(next) => {
                    prev = Some((s, a));
                    (s, a) = (s1, next);
                    ds = (ds * 1.5).min(max_ds);
                }
                None => {
                    ds *= 0.5;
                    if ds < MIN_FRACTION {
                        return None;
                    }
                }
            }
        }
        Some(a)
    }

    /// The rod `a` polished to the tolerance and verified stable, as a solution.
    fn finish(
        &mut self,
        g: &Gravity,
        a: &PlanarParams,
    ) -> Option<Solution<PlanarParams, PlanarPose>> {
        let tol = self.options.tolerance;
        let a = self.newton(g, a, tol, self.options.max_iterations)?;
        self.work.evaluations += 1;
        let e = match super::evaluate(&a, g) {
            Ok(e) => e,
            Err(err) => {
                self.last_error = Some(IgError::Evaluation {
                    iteration: self.work.iterations,
                    detail: err.to_string(),
                });
                return None;
            }
        };
        if !e.stability.stable {
            self.last_error = Some(IgError::LeftStableSet {
                iteration: self.work.iterations,
            });
            return None;
        }
        let errors = PlanarClosedForm.pose_error(&e.tip, &self.target);
        if errors.0 > tol || errors.1 > tol {
            return None;
        }
        let v = Verified {
            tip: e.tip,
            errors,
            energy: e.energy,
            margin: e.stability.margin,
        };
        Some(Solution::new(a, v, self.work))
    }

    /// One weightless start followed to the weight: direct first, then by continuation.
    fn follow(
        &mut self,
        g: &Gravity,
        a0: &PlanarParams,
    ) -> Option<Solution<PlanarParams, PlanarPose>> {
        self.work.starts += 1;
        let l = g.load();
        let shared = a0 + Vector3::new(0.0, 0.5 * l[0], 0.5 * l[1]);
        if let Some(a) = self.newton(g, &shared, SUBSTEP_TOLERANCE, 2 * CORRECTOR_ITERATIONS) {
            if let Some(s) = self.finish(g, &a) {
                return Some(s);
            }
        }
        let a = self.continuation(&Gravity::NONE, g, a0)?;
        self.finish(g, &a)
    }

    fn failure(self) -> Failure<PlanarParams> {
        let reason = if self.out_of_time() {
            IgError::Deadline {
                iteration: self.work.iterations,
            }
        } else {
            IgError::NoStableSolution {
                starts: self.work.starts,
                last: self.last_error.map(Box::new),
            }
        };
        Failure {
            reason,
            iterations: self.work.iterations,
            residual: f64::INFINITY,
            last_a: None,
            elapsed_us: 0.0,
        }
    }
}

/// Carries the stable rod `a`, which holds the tip gripper at `gripper` under gravity `from`, to
/// gravity `to` with the gripper fixed: the equilibrium branch followed as the weight or the
/// direction of gravity changes (the base gripper turning). The rod returned passed the
/// stability test under `to`. Fails where the branch folds or loses stability on the way (the
/// rod would snap), or on the deadline of `options`.
pub fn carry(
    a: &PlanarParams,
    from: &Gravity,
    to: &Gravity,
    gripper: &PlanarPose,
    options: &SolveOptions,
) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
    let _deadline = crate::solver::deadline::scope(options.deadline);
    let mut search = Search {
        target: *gripper,
        options,
        work: Work::default(),
        last_error: None,
    };
    search.work.starts = 1;
    let carried = search.continuation(from, to, a);
    match carried.and_then(|a| search.finish(to, &a)) {
        Some(s) => Ok(s),
        None => Err(search.failure()),
    }
}

/// The weightless rods the search starts from, in order: the caller's guess, the weightless
/// robust search's first rod (one call of a few µs), then, only when `all` or when those fail,
/// every stable weightless solution (least energy first).
struct Starts<'a> {
    target: &'a PlanarPose,
    options: &'a SolveOptions,
    queue: Vec<PlanarParams>,
    stage: u8,
}

impl Iterator for Starts<'_> {
    type Item = PlanarParams;
    fn next(&mut self) -> Option<PlanarParams> {
        while self.queue.is_empty() && self.stage < 3 {
            self.stage += 1;
            match self.stage {
                1 => self.queue.extend(self.options.initial_guess),
                2 => self.queue.extend(
                    PlanarClosedForm
                        .robust(self.target, self.options)
                        .map(|s| s.a),
                ),
                _ => {
                    let mut sols = PlanarClosedForm
                        .robust_all(self.target, self.options)
                        .solutions;
                    sols.sort_by(|a, b| b.energy.total_cmp(&a.energy));
                    self.queue.extend(sols.into_iter().map(|s| s.a));
                }
            }
        }
        self.queue.pop()
    }
}

fn weightless_starts<'a>(target: &'a PlanarPose, options: &'a SolveOptions) -> Starts<'a> {
    Starts {
        target,
        options,
        queue: Vec::new(),
        stage: 0,
    }
}

impl InverseGeometry<3> for HeavyPlanar {
    fn robust(
        &self,
        target: &PlanarPose,
        options: &SolveOptions,
    ) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
        if self.gravity.is_weightless() {
            return PlanarClosedForm.robust(target, options);
        }
        let mut search = Search {
            target: *target,
            options,
            work: Work::default(),
            last_error: None,
        };
        for a0 in weightless_starts(target, options) {
            if let Some(s) = search.follow(&self.gravity, &a0) {
                return Ok(s);
            }
            if search.out_of_time() {
                break;
            }
        }
        Err(search.failure())
    }

    fn robust_all(
        &self,
        target: &PlanarPose,
        options: &SolveOptions,
    ) -> Found<PlanarParams, PlanarPose> {
        if self.gravity.is_weightless() {
            return PlanarClosedForm.robust_all(target, options);
        }
        let mut search = Search {
            target: *target,
            options,
            work: Work::default(),
            last_error: None,
        };
        let scale = self.param_scale();
        let mut solutions: Vec<Solution<PlanarParams, PlanarPose>> = Vec::new();
        let mut tried: Vec<PlanarParams> = Vec::new();
        for a0 in weightless_starts(target, options) {
            if search.out_of_time() {
                break;
            }
            if tried
                .iter()
                .any(|t| relative_distance(t, &a0, &scale) <= DISTINCT)
            {
                continue;
            }
            tried.push(a0);
            if let Some(s) = search.follow(&self.gravity, &a0) {
                if solutions
                    .iter()
                    .all(|o| relative_distance(&o.a, &s.a, &scale) > DISTINCT)
                {
                    solutions.push(s);
                }
            }
        }
        Found {
            solutions,
            iterations: search.work.iterations,
            evaluations: search.work.evaluations,
            starts: search.work.starts,
        }
    }

    fn default_start(&self, target: &PlanarPose) -> Option<PlanarParams> {
        let a = PlanarClosedForm.default_start(target)?;
        let l = self.gravity.load();
        Some(a + Vector3::new(0.0, 0.5 * l[0], 0.5 * l[1]))
    }
}
