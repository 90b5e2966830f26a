//! Continuation in a distributed load (the rod's weight), written once for every model that
//! has one ([`LoadedModel`]): the planar and 3-D rods with weight.
//!
//! A rod on target under one load is followed to another load with the gripper fixed: the
//! load moves on the straight line between the two, in substeps of at most [`MAX_LOAD_STEP`]
//! (the rod's response is about half of it), each a secant prediction corrected by a damped
//! Newton whose iterates keep the sign of det J(1) (so the branch is not left) and must land
//! near the prediction (a far landing may be another branch). The search of a heavy rod
//! starts from the weightless rods that reach the target: each is tried first by one Newton
//! run from the weightless rod with the load shared by the two grippers, then by this
//! continuation from zero load.

use super::{branch_to, relative_distance, DISTINCT};
use super::{
    Failure, FailureOf, IgError, InverseGeometry, RodModel, Solution, SolutionOf, SolveOptions,
    Verified, Work,
};
use crate::RodError;
use nalgebra::SVector;

/// A rod model carrying a distributed load that continuation can vary.
pub trait LoadedModel<const N: usize>: RodModel<N> + Sized {
    /// The model whose load is (1 − s) × `from`'s + s × self's (same stiffness, same rod).
    fn blend(&self, from: &Self, s: f64) -> Result<Self, RodError>;
    /// |load − from's load| (weight per unit length, normalised).
    fn load_change(&self, from: &Self) -> f64;
    /// The change of a that carries half of the change of load from `from` to self (each
    /// gripper takes half: exact for a symmetric rod), the first substep's predictor.
    fn shared_load_step(&self, from: &Self) -> SVector<f64, N>;
}

/// Newton iterations of one corrector run.
const CORRECTOR_ITERATIONS: u32 = 8;
/// Tolerance of the continuation's intermediate rods.
const SUBSTEP_TOLERANCE: f64 = 1e-6;
/// Smallest continuation step, as a fraction of the whole change of load.
const MIN_FRACTION: f64 = 1.0 / 65536.0;
/// Largest change of the load in one substep.
pub const MAX_LOAD_STEP: f64 = 10.0;
/// Largest relative distance (scale 1) of a corrected substep from its prediction.
const MAX_CORRECTION: f64 = 0.3;
/// Halvings of a Newton step in the line search.
const LINE_SEARCH: u32 = 10;
/// Continuation steps of the last stage, a heavy rod carried to the target along its branch
/// (each at most a few corrections; the deadline bounds them too).
const BRANCH_STEPS: u32 = 1024;
/// Heavy rods the last stage carries along their branches: the shared-load rods of the first
/// starts tried, then the model's default start.
const BRANCH_STARTS: usize = 3;
/// Share of the time left that one start of the search may spend.
const START_SHARE: f64 = 0.5;

/// The search's running state: target, options, the work done and the last error.
pub(crate) struct Search<'a, const N: usize, M: RodModel<N>> {
    target: M::Pose,
    options: &'a SolveOptions<SVector<f64, N>>,
    pub(crate) work: Work,
    last_error: Option<IgError>,
}

impl<'a, const N: usize, M: LoadedModel<N>> Search<'a, N, M> {
    pub(crate) fn new(target: M::Pose, options: &'a SolveOptions<SVector<f64, N>>) -> Self {
        Self {
            target,
            options,
            work: Work::default(),
            last_error: None,
        }
    }

    pub(crate) fn out_of_time(&self) -> bool {
        crate::deadline::expired()
    }

    fn residual(&self, model: &M, tip: &M::Pose) -> f64 {
        let (p, o) = model.pose_error(tip, &self.target);
        p.hypot(o)
    }

    fn converged(&self, model: &M, tip: &M::Pose, tol: f64) -> bool {
        let (p, o) = model.pose_error(tip, &self.target);
        p <= tol && o <= tol
    }

    fn eval(
        &mut self,
        model: &M,
        a: &SVector<f64, N>,
    ) -> Option<(M::Pose, nalgebra::SMatrix<f64, N, N>)> {
        self.work.evaluations += 1;
        match model.tip_and_jacobian(a) {
            Ok(v) => Some(v),
            Err(e) => {
                self.last_error = Some(IgError::of_evaluation(self.work.iterations, &e));
                None
            }
        }
    }

    /// Damped Newton on `model` from `a0` to `tol`: the residual only decreases and det J(1)
    /// keeps the sign it had at `a0`.
    fn newton(
        &mut self,
        model: &M,
        a0: &SVector<f64, N>,
        tol: f64,
        max: u32,
    ) -> Option<SVector<f64, N>> {
        let mut a = *a0;
        let (mut tip, mut jac) = self.eval(model, &a)?;
        let sign = model.jacobian_det(&jac).signum();
        for _ in 0..max {
            if self.converged(model, &tip, tol) {
                return Some(a);
            }
            if self.out_of_time() {
                self.last_error = Some(IgError::Deadline {
                    iteration: self.work.iterations,
                });
                return None;
            }
            let step = model.newton_increment(&tip, &jac, &self.target).ok()?;
            let r = self.residual(model, &tip);
            let mut lambda = 1.0;
            let mut accepted = None;
            for _ in 0..LINE_SEARCH {
                let trial = a + step * lambda;
                if let Some((t, j)) = self.eval(model, &trial) {
                    if self.residual(model, &t) < r && model.jacobian_det(&j).signum() == sign {
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
        self.converged(model, &tip, tol).then_some(a)
    }

    /// Follows the rod `a0`, on target under `from`'s load, to `to`'s (module docs).
    pub(crate) fn continuation(
        &mut self,
        from: &M,
        to: &M,
        a0: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        let (mut s, mut a) = (0.0f64, *a0);
        let mut prev: Option<(f64, SVector<f64, N>)> = None;
        let max_ds = (MAX_LOAD_STEP / to.load_change(from)).min(0.5);
        let mut ds = 0.5 * max_ds;
        let share = to.shared_load_step(from);
        while s < 1.0 {
            if self.out_of_time() {
                return None;
            }
            let s1 = (s + ds).min(1.0);
            let guess = match prev {
                Some((sp, ap)) if s > sp => a + (a - ap) * ((s1 - s) / (s - sp)),
                _ => a + share * (s1 - s),
            };
            let model = to.blend(from, s1).ok()?;
            let unit = SVector::<f64, N>::repeat(1.0);
            let corrected = self
                .newton(&model, &guess, SUBSTEP_TOLERANCE, CORRECTOR_ITERATIONS)
                .filter(|next| relative_distance(next, &guess, &unit) <= MAX_CORRECTION);
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

    /// The rod `a` polished to the tolerance on `model` and verified stable, as a solution.
    pub(crate) fn finish(&mut self, model: &M, a: &SVector<f64, N>) -> Option<SolutionOf<N, M>> {
        let tol = self.options.tolerance;
        let a = self.newton(model, a, tol, self.options.max_iterations)?;
        self.work.evaluations += 1;
        let e = match model.evaluate(&a) {
            Ok(e) => e,
            Err(err) => {
                self.last_error = Some(IgError::of_evaluation(self.work.iterations, &err));
                return None;
            }
        };
        if !e.stability.stable {
            self.last_error = Some(IgError::LeftStableSet {
                iteration: self.work.iterations,
            });
            return None;
        }
        let errors = model.pose_error(&e.tip, &self.target);
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

    /// One weightless start `a0` (on target under `weightless`) followed to `heavy`: one
    /// Newton run from the shared load first, then the continuation.
    pub(crate) fn follow(
        &mut self,
        weightless: &M,
        heavy: &M,
        a0: &SVector<f64, N>,
    ) -> Option<SolutionOf<N, M>> {
        self.work.starts += 1;
        let shared = a0 + heavy.shared_load_step(weightless);
        if let Some(a) = self.newton(heavy, &shared, SUBSTEP_TOLERANCE, 2 * CORRECTOR_ITERATIONS) {
            if let Some(s) = self.finish(heavy, &a) {
                return Some(s);
            }
        }
        let a = self.continuation(weightless, heavy, a0)?;
        self.finish(heavy, &a)
    }

    /// The failure after every start: the deadline, or what was searched and the last error.
    pub(crate) fn failure(self) -> FailureOf<N> {
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
            starts: self.work.starts,
            elapsed_us: 0.0,
        }
    }
}

impl<const N: usize, M: LoadedModel<N> + InverseGeometry<N> + Copy> Search<'_, N, M> {
    /// The heavy rod `a` (anywhere: its tip need not be on target) carried to the target along
    /// its branch as the gripper moves there from its tip ([`branch_to`]: continuation in the
    /// target, where continuation in the load failed), then polished and tested.
    fn along_branch(&mut self, heavy: &M, a: &SVector<f64, N>) -> Option<SolutionOf<N, M>> {
        self.work.starts += 1;
        let end = branch_to(
            *heavy,
            self.options,
            BRANCH_STEPS,
            a,
            &self.target,
            &mut self.work,
        )?;
        self.finish(heavy, &end)
    }
}

/// The first stable heavy rod followed from `starts` (weightless rods on target under
/// `weightless`), or why none was.
pub(crate) fn first<const N: usize, M: LoadedModel<N> + InverseGeometry<N> + Copy>(
    weightless: &M,
    heavy: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
    starts: impl Iterator<Item = SVector<f64, N>>,
) -> Result<SolutionOf<N, M>, FailureOf<N>> {
    let (found, search) = search_from(weightless, heavy, target, options, starts, false);
    found.into_iter().next().ok_or_else(|| search.failure())
}

/// Every distinct stable heavy rod followed from `starts`, and the work it took.
pub(crate) fn every<const N: usize, M: LoadedModel<N> + InverseGeometry<N> + Copy>(
    weightless: &M,
    heavy: &M,
    target: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
    starts: impl Iterator<Item = SVector<f64, N>>,
) -> super::Found<SVector<f64, N>, M::Pose> {
    let (solutions, search) = search_from(weightless, heavy, target, options, starts, true);
    super::Found {
        solutions,
        iterations: search.work.iterations,
        evaluations: search.work.evaluations,
        starts: search.work.starts,
    }
}

/// The first stable heavy rod followed from `starts` (weightless rods on target), or every
/// distinct one when `all`. Where none is found, the last stage carries heavy rods to the
/// target along their branches ([`Search::along_branch`]): the shared-load rods of the first
/// [`BRANCH_STARTS`] starts, then the model's default start (which needs no weightless rod on
/// target: the weightless search can miss a target that a heavy rod reaches).
fn search_from<'a, const N: usize, M: LoadedModel<N> + InverseGeometry<N> + Copy>(
    weightless: &M,
    heavy: &M,
    target: &M::Pose,
    options: &'a SolveOptions<SVector<f64, N>>,
    starts: impl Iterator<Item = SVector<f64, N>>,
    all: bool,
) -> (Vec<SolutionOf<N, M>>, Search<'a, N, M>) {
    let mut search = Search::new(*target, options);
    let scale = heavy.param_scale();
    let (mut solutions, mut tried) = (
        Vec::<SolutionOf<N, M>>::new(),
        Vec::<SVector<f64, N>>::new(),
    );
    for a0 in starts {
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
        // Half of the time left to each start: a start whose continuation crawls (a rod deep
        // in tension, evaluations of ms) leaves time to the others and to the last stage.
        let slice = crate::deadline::share_of_remaining(START_SHARE);
        let followed = search.follow(weightless, heavy, &a0);
        drop(slice);
        if let Some(s) = followed {
            if solutions
                .iter()
                .all(|o| relative_distance(&o.a, &s.a, &scale) > DISTINCT)
            {
                solutions.push(s);
            }
            if !all {
                break;
            }
        }
    }
    if solutions.is_empty() {
        let share = heavy.shared_load_step(weightless);
        let carried = tried.iter().take(BRANCH_STARTS).map(|a0| a0 + share);
        for a in carried.chain(heavy.default_start(target)) {
            if search.out_of_time() {
                break;
            }
            let slice = crate::deadline::share_of_remaining(START_SHARE);
            let carried = search.along_branch(heavy, &a);
            drop(slice);
            if let Some(s) = carried {
                solutions.push(s);
                break;
            }
        }
    }
    (solutions, search)
}

/// Carries the stable rod `a`, which holds the tip gripper at `gripper` under `from`'s load,
/// to `to`'s load with the gripper fixed (module docs). The rod returned passed the stability
/// test under `to`; fails where the branch folds or loses stability on the way (the rod would
/// snap), or on the deadline of `options`.
pub fn carry<const N: usize, M: LoadedModel<N>>(
    from: &M,
    to: &M,
    a: &SVector<f64, N>,
    gripper: &M::Pose,
    options: &SolveOptions<SVector<f64, N>>,
) -> Result<SolutionOf<N, M>, FailureOf<N>> {
    let _deadline = crate::deadline::scope(options.deadline);
    let mut search = Search::new(*gripper, options);
    search.work.starts = 1;
    let carried = search.continuation(from, to, a);
    match carried.and_then(|a| search.finish(to, &a)) {
        Some(s) => Ok(s),
        None => Err(search.failure()),
    }
}
