//! Quasi-static motion: the rod held by the grippers follows its equilibrium branch as the tip
//! gripper moves, and snaps when that branch loses stability.
//!
//! Between the previous gripper pose b₀ and the next one b₁ the gripper moves along
//! b(s) = [`RodModel::interpolate`](b₀, b₁, s), s ∈ [0, 1]. [`BranchFollower::follow`] walks s
//! with a predictor–corrector: the tangent predictor δa = J(1, a)⁻¹ (b(s + Δs) − b(s)) (the
//! derivative of the branch a(s), since Υ(a(s)) = b(s)), then Newton corrections towards
//! b(s + Δs), accepted only if they contract (each step at most half the previous one: a step
//! that does not contract may be converging to another branch) and end at a stable rod. On
//! failure Δs is halved; on success doubled (at most the whole remaining segment).
//!
//! Along a continuous branch, stability can only be lost where det J(1, a) = 0 (a conjugate
//! point enters (0, 1] through t = 1: docs/math.md §5, paper §3.1), and there the branch folds: it
//! cannot be continued in s. So when Δs falls below [`MIN_STEP`] with the corrector failing,
//! the branch has ended at the last accepted rod: the **critical** rod and pose, located to
//! within [`MIN_STEP`] of the segment.
//!
//! **Snap rule.** At the critical pose the rod jumps, at fixed grippers, to another stable
//! equilibrium; the jump dissipates energy, so the rod settles into a stable equilibrium of
//! lower elastic energy. Among the stable equilibria at the pose just past the critical one
//! (`solve_all`) with energy below the critical rod's, the one nearest the critical rod
//! (relative parameter distance) is taken: the end of a descent of the energy from the
//! critical shape, which moves the rod the least. Then the motion goes on from there to b₁.
//! When no such equilibrium exists the rod is **lost** (`success: false`).
//!
//! **Out of time.** A move that runs out of its deadline keeps the last equilibrium reached
//! (an equilibrium of the branch, stable since det J(1, a) kept its sign) and says so:
//! `Deadline` with event `None`, [`Move::progress`] the fraction of the move done; the next
//! move starts from that rod. The corrector evaluates only Υ(a) and J(1, a); the full
//! stability test runs once, on the rod the move ends with.

use super::model::{relative_distance, ModelEvaluation, RodModel};
use super::{
    solve, solve_all, Failure, IgError, InverseGeometry, Solution, SolutionOf, SolveOptions,
    Verified, Work,
};
use nalgebra::{SMatrix, SVector};

/// Smallest continuation step, as a fraction of the gripper's move: the critical pose of a
/// snap is located to within this fraction (1/4096 of a 1 cm move is 2.4 µm).
pub const MIN_STEP: f64 = 1.0 / 4096.0;
/// Tolerance of the intermediate poses of the continuation (the last one uses the solve's
/// tolerance): loose enough to take long steps, tight enough that the predictor from an
/// intermediate rod stays within Newton's basin (its error adds O(1e-6) to O(Δs²)).
pub const SUBSTEP_TOLERANCE: f64 = 1e-6;
/// Newton corrections per continuation step: from the tangent predictor the error is O(Δs²)
/// and Newton converges quadratically, so a step that needs more is too long.
pub const CORRECTOR_ITERATIONS: u32 = 8;
/// Contraction required of successive Newton corrections (Kantorovich: in the basin of the
/// branch's own solution successive steps shrink at least geometrically).
const CONTRACTION: f64 = 0.5;
/// Most snaps followed within one move (each needs a fold and a lower-energy equilibrium).
pub const MAX_SNAPS: u32 = 8;
/// Largest relative distance (in the model's parameter scale) between the rod a stop of the
/// continuation settles on and the rod it stopped at for the two to be the same branch: past
/// a fold the rod jumps to another configuration, O(1) away.
const SAME_BRANCH: f64 = 0.05;

/// What happened to the rod during one gripper move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BranchEvent<P, X> {
    /// The rod stayed on its branch (or this was the first pose: a fresh solve).
    None,
    /// The branch lost stability (fold) at the `critical` gripper pose; the rod snapped to
    /// another stable equilibrium (module docs: the snap rule) and followed it to the target.
    Snap {
        /// The gripper pose where the branch ended.
        critical: X,
        /// The last stable rod of the old branch.
        critical_a: P,
        /// Elastic energy released by the snap (critical rod minus the rod it settled into).
        energy_released: f64,
        /// Snaps during this move (1 unless the new branch folded too).
        snaps: u32,
    },
    /// No stable equilibrium to follow or snap into: the rod's state is unknown.
    Lost,
    /// The rod was held straight (a neutral equilibrium, det J ≡ 0) and buckled on this first
    /// move: it took the least-energy stable rod the search found at the target, ties (mirror
    /// images, when both are found) broken toward the rod whose first non-zero parameter is
    /// positive (planar: a3 > 0). The search is deterministic: the same move buckles the same
    /// way every time.
    Buckle,
}

impl<P, X> BranchEvent<P, X> {
    /// "none", "snap", "lost" or "buckle" (the CLI's and the node's `event` field).
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Snap { .. } => "snap",
            Self::Lost => "lost",
            Self::Buckle => "buckle",
        }
    }
}

/// One move of the gripper: the rod it ends with (or why not) and what happened on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct Move<P, X> {
    /// The equilibrium at the target (stable, within the tolerance), or the failure.
    pub result: Result<Solution<P, X>, Failure<P>>,
    /// Branch event of the move.
    pub event: BranchEvent<P, X>,
    /// How far along the gripper's path the rod was followed (1 when the target was reached; on
    /// a deadline the fraction at which the rod kept, [`BranchFollower::rod`], is held).
    pub progress: f64,
}

/// The rod held by the grippers: an equilibrium, its gripper pose and J(1, a) (whose
/// determinant's sign marks its branch's side of the stability boundary).
#[derive(Clone, Copy, Debug)]
struct Held<const N: usize, X> {
    a: SVector<f64, N>,
    tip: X,
    jacobian: SMatrix<f64, N, N>,
}

impl<const N: usize, X> Held<N, X> {
    fn of(a: SVector<f64, N>, e: ModelEvaluation<N, X>) -> Self {
        Self {
            a,
            tip: e.tip,
            jacobian: e.jacobian,
        }
    }
}

/// The stable rod `a0`'s branch followed, without snapping, as its gripper moves from `a0`'s
/// tip to `target` ([`RodModel::interpolate`]): the rod of that branch at `target`, or `None`
/// when the branch folds first (or cannot be evaluated) or the deadline passes. The robust
/// searches' last stage: a branch reaches targets whose rods are too sensitive for Newton's
/// basin to hold any seed (issue 42). The rod returned has det J(1, a) of `a0`'s sign but is
/// not stability-tested: the caller does the full test. At most `max_steps` continuation
/// steps, each of at most [`CORRECTOR_ITERATIONS`] + 1 corrections.
pub(crate) fn branch_to<const N: usize, M: InverseGeometry<N>>(
    model: M,
    options: &SolveOptions<SVector<f64, N>>,
    max_steps: u32,
    a0: &SVector<f64, N>,
    target: &M::Pose,
    work: &mut Work,
) -> Option<SVector<f64, N>> {
    let (tip, jacobian) = model.tip_and_jacobian(a0).ok()?;
    work.evaluations += 1;
    let follower = BranchFollower {
        model,
        options: *options,
        held: None,
        straight: None,
        step_cap: max_steps,
    };
    let held = Held {
        a: *a0,
        tip,
        jacobian,
    };
    follower
        .continue_to(&held, target, work)
        .ok()
        .map(|end| end.a)
}

/// Why a continuation stopped before the target.
enum Stop<const N: usize, X> {
    /// The branch folded: the last stable rod, at gripper pose fraction `s`.
    Fold(Held<N, X>, f64),
    /// The deadline passed: the last rod reached, at gripper pose fraction `s`.
    Deadline(Held<N, X>, f64),
}

/// Follows the rod's equilibrium branch as the gripper moves (module docs). Works for every
/// model (planar and 3-D).
#[derive(Clone, Debug)]
pub struct BranchFollower<const N: usize, M: RodModel<N>> {
    model: M,
    options: SolveOptions<SVector<f64, N>>,
    held: Option<Held<N, M::Pose>>,
    /// The straight rod held at rest (a and its tip) before the first move buckles it.
    straight: Option<(SVector<f64, N>, M::Pose)>,
    /// Continuation steps (tried, each at most [`CORRECTOR_ITERATIONS`] + 1 corrections) one
    /// move may take ([`branch_to`]: the search's `max_iterations`; a follower: unbounded but
    /// by its deadline).
    step_cap: u32,
}

impl<const N: usize, M: InverseGeometry<N>> BranchFollower<N, M> {
    /// A follower with no rod yet: the first [`Self::follow`] is a fresh solve with `options`.
    pub fn new(model: M, options: SolveOptions<SVector<f64, N>>) -> Self {
        Self {
            model,
            options,
            held: None,
            straight: None,
            step_cap: u32::MAX,
        }
    }

    /// A follower holding the rod `a0` (the gripper is at its tip). Fails when `a0` is not a
    /// stable equilibrium (a held rod must be one), except for the exactly straight rod
    /// ([`RodModel::is_straight`], e.g. a = 0, the rod at rest): a neutral equilibrium the
    /// first move buckles ([`BranchEvent::Buckle`]).
    pub fn holding(
        model: M,
        options: SolveOptions<SVector<f64, N>>,
        a0: SVector<f64, N>,
    ) -> Result<Self, IgError> {
        if let Some(index) = a0.iter().position(|v| !v.is_finite()) {
            return Err(IgError::NonFiniteGuess {
                index,
                value: a0[index],
            });
        }
        let eval = model
            .evaluate(&a0)
            .map_err(|e| IgError::of_evaluation(0, &e))?;
        if !eval.stability.stable {
            if eval.stability.uncertain && model.is_straight(&a0) {
                return Ok(Self {
                    model,
                    options,
                    held: None,
                    straight: Some((a0, eval.tip)),
                    step_cap: u32::MAX,
                });
            }
            return Err(IgError::LeftStableSet { iteration: 0 });
        }
        Ok(Self {
            model,
            options,
            held: Some(Held::of(a0, eval)),
            straight: None,
            step_cap: u32::MAX,
        })
    }

    /// Changes the options of the next moves (the rod stays held).
    pub fn set_options(&mut self, options: SolveOptions<SVector<f64, N>>) {
        self.options = options;
    }

    /// The rod held now, if any.
    pub fn rod(&self) -> Option<SVector<f64, N>> {
        self.held.map(|h| h.a).or(self.straight.map(|s| s.0))
    }

    /// The gripper pose the rod is held at now, if any.
    pub fn gripper(&self) -> Option<M::Pose> {
        self.held.map(|h| h.tip).or(self.straight.map(|s| s.1))
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Moves the gripper to `target` and returns the rod it ends with. Without a held rod: a
    /// fresh [`solve`] (event `None`). After `Lost` the follower holds nothing.
    pub fn follow(&mut self, target: &M::Pose) -> Move<SVector<f64, N>, M::Pose> {
        let t0 = std::time::Instant::now();
        let mut m = self.follow_inner(target);
        let us = t0.elapsed().as_secs_f64() * 1e6;
        match &mut m.result {
            Ok(s) => s.elapsed_us = us,
            Err(f) => f.elapsed_us = us,
        }
        m
    }

    fn follow_inner(&mut self, target: &M::Pose) -> Move<SVector<f64, N>, M::Pose> {
        let Some(held) = self.held else {
            if self.straight.is_some() {
                return self.buckle(target);
            }
            return self.fresh_solve(target);
        };
        if let Err(e) = self
            .model
            .check_target(target)
            .and_then(|_| super::check_options(&self.options))
            .and_then(|_| self.model.check_settings())
        {
            // An invalid request changes nothing: the rod is still held where it was.
            return Move {
                result: Err(Failure::early(e)),
                event: BranchEvent::None,
                progress: 0.0,
            };
        }
        let target = &self.model.canonical_target(target);
        let _deadline = crate::deadline::scope(self.options.deadline);
        let mut work = Work::default();
        let mut current = held;
        let mut first_snap: Option<(M::Pose, SVector<f64, N>, f64)> = None;
        let mut snaps = 0;
        // The fraction of the whole move done before `current`'s segment began.
        let mut done = 0.0;
        loop {
            match self.continue_to(&current, target, &mut work) {
                Ok(end) => return self.arrived(end, target, &work, first_snap, snaps),
                Err(Stop::Deadline(at, s)) => {
                    // Out of time mid-move: the rod reached so far is an equilibrium of the
                    // branch (stable by the det J(1, a) sign it kept), so it stays held.
                    self.held = Some(at);
                    let progress = 1.0 - (1.0 - done) * (1.0 - s);
                    return self.out_of_time(&at, target, &work, progress);
                }
                Err(Stop::Fold(critical, s)) => {
                    let critical_energy = self.model.energy(&critical.a).unwrap_or(f64::NAN);
                    // Just past the fold; when no stable rod is there (the straight path of
                    // the gripper may cross poses no stable rod reaches), at the target.
                    let settled = self
                        .snap(&current, &critical, critical_energy, s, target, snaps + 1)
                        .or_else(|| {
                            (snaps < MAX_SNAPS)
                                .then(|| self.settle(&critical, critical_energy, target))
                                .flatten()
                        });
                    let Some((settled, energy)) = settled else {
                        self.held = None;
                        let e = IgError::NoStableSolution {
                            starts: work.starts,
                            last: Some(Box::new(IgError::LeftStableSet {
                                iteration: work.iterations,
                            })),
                        };
                        return self.lost(e, &work, critical.a);
                    };
                    // A stop that settles on the branch it was following (the rod nearest
                    // the critical one, within SAME_BRANCH) was no fold, only a turn of the
                    // branch too sharp for the corrector at the smallest step: no snap, and
                    // the continuation goes on from there.
                    let scale = self.model.param_scale();
                    let jump = relative_distance(&settled.a, &critical.a, &scale);
                    if jump > SAME_BRANCH {
                        snaps += 1;
                        if first_snap.is_none() {
                            first_snap = Some((critical.tip, critical.a, critical_energy - energy));
                        }
                    }
                    done = 1.0 - (1.0 - done) * (1.0 - (s + 2.0 * MIN_STEP).min(1.0));
                    current = settled;
                }
            }
        }
    }

    /// The move reached its target with `end`: verified at full accuracy (energy, stability)
    /// and held; the event says whether the rod snapped on the way.
    fn arrived(
        &mut self,
        end: Held<N, M::Pose>,
        target: &M::Pose,
        work: &Work,
        first_snap: Option<(M::Pose, SVector<f64, N>, f64)>,
        snaps: u32,
    ) -> Move<SVector<f64, N>, M::Pose> {
        let (end, eval, first_snap, snaps) = match self.model.evaluate(&end.a) {
            Ok(e) if e.stability.stable => (end, e, first_snap, snaps),
            // The branch's stability is tracked by the sign of det J(1, a); a rod that fails
            // the full test at the end passed a fold between two steps (det J(1, a) changed
            // sign twice): the rod snapped on the way, and settles at the target as at any
            // fold. Lost only when no stable rod of lower energy is there.
            other => {
                let energy = match &other {
                    Ok(e) => e.energy,
                    Err(_) => self.model.energy(&end.a).unwrap_or(f64::INFINITY),
                };
                let Some((settled, settled_energy)) = self.settle(&end, energy, target) else {
                    self.held = None;
                    let e = IgError::LeftStableSet {
                        iteration: work.iterations,
                    };
                    return self.lost(e, work, end.a);
                };
                let Ok(eval) = self.model.evaluate(&settled.a) else {
                    self.held = None;
                    let e = IgError::LeftStableSet {
                        iteration: work.iterations,
                    };
                    return self.lost(e, work, end.a);
                };
                let snap = first_snap.or(Some((end.tip, end.a, energy - settled_energy)));
                (settled, eval, snap, snaps + 1)
            }
        };
        self.held = Some(end);
        let event = match first_snap {
            None => BranchEvent::None,
            Some((critical, critical_a, released)) => BranchEvent::Snap {
                critical,
                critical_a,
                energy_released: released,
                snaps,
            },
        };
        Move {
            result: Ok(self.solution(&end, &eval, target, work)),
            event,
            progress: 1.0,
        }
    }

    /// The deadline passed with the rod `at` held, a fraction `progress` of the way.
    fn out_of_time(
        &self,
        at: &Held<N, M::Pose>,
        target: &M::Pose,
        work: &Work,
        progress: f64,
    ) -> Move<SVector<f64, N>, M::Pose> {
        let (pe, oe) = self.model.pose_error(&at.tip, target);
        Move {
            result: Err(Failure {
                reason: IgError::Deadline {
                    iteration: work.iterations,
                },
                iterations: work.iterations,
                residual: pe.hypot(oe),
                last_a: Some(at.a),
                starts: work.starts,
                elapsed_us: 0.0,
            }),
            event: BranchEvent::None,
            progress,
        }
    }

    /// Without a held rod: a fresh solve, whose rod is then held (event `None`, or `Lost`).
    /// The first move from the straight rod ([`BranchEvent::Buckle`]): the least-energy stable
    /// rod found at the target, ties broken toward the first non-zero parameter being positive.
    /// The straight rod stays held when the move fails on its input or its deadline.
    fn buckle(&mut self, target: &M::Pose) -> Move<SVector<f64, N>, M::Pose> {
        let least = SolveOptions {
            objective: super::Objective::LeastEnergy,
            ..self.options
        };
        // One deadline for both searches.
        let _deadline = crate::deadline::scope(self.options.deadline);
        let first = solve(&self.model, target, &least);
        let all = super::solve_all(&self.model, target, &least);
        let result = match first {
            Ok(s) => {
                let lowest = all.iter().map(|o| o.energy).fold(s.energy, f64::min);
                let tie = 1e-9 * (1.0 + lowest.abs());
                let leftmost = |a: &SVector<f64, N>| {
                    a.iter().find(|v| v.abs() > 1e-12).is_some_and(|v| *v > 0.0)
                };
                let chosen = all
                    .iter()
                    .chain(std::iter::once(&s))
                    .filter(|o| o.energy <= lowest + tie)
                    .max_by_key(|o| leftmost(&o.a))
                    .copied()
                    .unwrap_or(s);
                Ok(chosen)
            }
            Err(f) => Err(f),
        };
        match &result {
            Ok(s) => {
                self.straight = None;
                self.held = self
                    .model
                    .tip_and_jacobian(&s.a)
                    .ok()
                    .map(|(tip, jacobian)| Held {
                        a: s.a,
                        tip,
                        jacobian,
                    });
            }
            Err(f) if f.termination() == super::Termination::Deadline => {}
            Err(f) if f.termination() == super::Termination::InvalidInput => {}
            Err(_) => self.straight = None,
        }
        let (event, progress) = match &result {
            Ok(_) => (BranchEvent::Buckle, 1.0),
            Err(_) if self.straight.is_some() => (BranchEvent::None, 0.0),
            Err(_) => (BranchEvent::Lost, 0.0),
        };
        Move {
            result,
            event,
            progress,
        }
    }

    fn fresh_solve(&mut self, target: &M::Pose) -> Move<SVector<f64, N>, M::Pose> {
        let result = solve(&self.model, target, &self.options);
        self.held = result.as_ref().ok().and_then(|s| {
            let (tip, jacobian) = self.model.tip_and_jacobian(&s.a).ok()?;
            Some(Held {
                a: s.a,
                tip,
                jacobian,
            })
        });
        let (event, progress) = match result {
            Ok(_) => (BranchEvent::None, 1.0),
            Err(_) => (BranchEvent::Lost, 0.0),
        };
        Move {
            result,
            event,
            progress,
        }
    }

    /// The rod the branch snaps to when it folds at `critical` (of energy `critical_energy`),
    /// a fraction `s` of the way from `current`'s gripper pose to `target`: settled just past
    /// the fold (module docs), with its energy; `None` after [`MAX_SNAPS`] snaps in one move or
    /// when no stable rod is found there.
    fn snap(
        &self,
        current: &Held<N, M::Pose>,
        critical: &Held<N, M::Pose>,
        critical_energy: f64,
        s: f64,
        target: &M::Pose,
        snaps: u32,
    ) -> Option<(Held<N, M::Pose>, f64)> {
        if snaps > MAX_SNAPS {
            return None;
        }
        let past = self
            .model
            .interpolate(&current.tip, target, (s + 2.0 * MIN_STEP).min(1.0));
        self.settle(critical, critical_energy, &past)
    }

    fn lost(
        &self,
        reason: IgError,
        work: &Work,
        last: SVector<f64, N>,
    ) -> Move<SVector<f64, N>, M::Pose> {
        Move {
            result: Err(Failure {
                reason,
                iterations: work.iterations,
                residual: f64::INFINITY,
                last_a: Some(last),
                starts: work.starts,
                elapsed_us: 0.0,
            }),
            event: BranchEvent::Lost,
            progress: 0.0,
        }
    }

    /// The snap rule (module docs): the stable equilibrium at `pose` with energy below the
    /// critical rod's, nearest to it.
    fn settle(
        &self,
        critical: &Held<N, M::Pose>,
        critical_energy: f64,
        pose: &M::Pose,
    ) -> Option<(Held<N, M::Pose>, f64)> {
        let options = SolveOptions {
            initial_guess: None,
            ..self.options
        };
        let candidates = solve_all(&self.model, pose, &options);
        let scale = self.model.param_scale();
        let nearest = |lower_only: bool| {
            candidates
                .iter()
                .filter(|c| !lower_only || c.energy < critical_energy)
                .min_by(|p, q| {
                    relative_distance(&p.a, &critical.a, &scale).total_cmp(&relative_distance(
                        &q.a,
                        &critical.a,
                        &scale,
                    ))
                })
        };
        // The rule's rod; when rounding puts every stable rod there at or above the critical
        // energy (a fold of nearly equal energies), the nearest stable rod: the rod is lost
        // only when no stable equilibrium is found at the pose at all.
        let best = nearest(true).or_else(|| nearest(false))?;
        let eval = self.model.evaluate(&best.a).ok()?;
        eval.stability
            .stable
            .then_some((Held::of(best.a, eval), best.energy))
    }

    /// Predictor–corrector from `held` (at its gripper pose) to `target` (module docs).
    fn continue_to(
        &self,
        held: &Held<N, M::Pose>,
        target: &M::Pose,
        work: &mut Work,
    ) -> Result<Held<N, M::Pose>, Stop<N, M::Pose>> {
        let start = held.tip;
        let mut current = *held;
        let (mut s, mut ds) = (0.0f64, 1.0f64);
        // Whether the last step was taken at the first try: a step that succeeds only after
        // halving keeps its length for the next one instead of doubling (doubling there
        // fails again: one wasted corrector run per step, each a few ms on strongly
        // tensioned rods).
        let mut first_try = true;
        let mut steps = 0;
        while s < 1.0 {
            if crate::deadline::expired() {
                return Err(Stop::Deadline(current, s));
            }
            if steps >= self.step_cap {
                return Err(Stop::Fold(current, s));
            }
            steps += 1;
            let s_new = (s + ds).min(1.0);
            let last = s_new >= 1.0;
            let goal = if last {
                *target
            } else {
                self.model.interpolate(&start, target, s_new)
            };
            let tolerance = if last {
                self.options.tolerance
            } else {
                SUBSTEP_TOLERANCE.max(self.options.tolerance)
            };
            if last && s > 0.0 {
                // The last step is corrected at full accuracy, from a rod re-evaluated so.
                (current.tip, current.jacobian) = match self.model.tip_and_jacobian(&current.a) {
                    Ok(q) => q,
                    Err(_) => return Err(Stop::Fold(current, s)),
                };
            }
            match self.correct(&current, &goal, tolerance, !last, work) {
                Some(next) => {
                    current = next;
                    s = s_new;
                    if first_try {
                        ds = (2.0 * ds).min(1.0);
                    }
                    first_try = true;
                }
                None => {
                    first_try = false;
                    ds *= 0.5;
                    if ds < MIN_STEP {
                        return Err(Stop::Fold(current, s));
                    }
                }
            }
        }
        Ok(current)
    }

    /// Tangent predictor and contracting Newton corrections from `from` to `goal`: the rod
    /// reached if it meets `tolerance` without crossing det J(1, a) = 0 (the only way off the
    /// stable branch, module docs), so that no iterate needs the full stability test.
    fn correct(
        &self,
        from: &Held<N, M::Pose>,
        goal: &M::Pose,
        tolerance: f64,
        substep: bool,
        work: &mut Work,
    ) -> Option<Held<N, M::Pose>> {
        if let Some(step) = self.model.branch_step(&from.a, goal, tolerance) {
            work.iterations += 1;
            work.evaluations += 1;
            return step.map(|(a, tip, jacobian)| Held { a, tip, jacobian });
        }
        let side = self.model.jacobian_det(&from.jacobian);
        let mut x = *from;
        let mut previous_step = f64::INFINITY;
        for _ in 0..=CORRECTOR_ITERATIONS {
            if crate::deadline::expired() {
                return None;
            }
            let (pe, oe) = self.model.pose_error(&x.tip, goal);
            if pe <= tolerance && oe <= tolerance {
                return Some(x);
            }
            let d = self
                .model
                .newton_increment(&x.tip, &x.jacobian, goal)
                .ok()?;
            let step = d.norm();
            if step > CONTRACTION * previous_step {
                return None;
            }
            previous_step = step;
            x.a += d;
            work.iterations += 1;
            work.evaluations += 1;
            (x.tip, x.jacobian) = if substep {
                self.model.tip_and_jacobian_for_substep(&x.a).ok()?
            } else {
                self.model.tip_and_jacobian(&x.a).ok()?
            };
            // A sign change of det J(1, a) means the step crossed the fold.
            if self.model.jacobian_det(&x.jacobian) * side <= 0.0 {
                return None;
            }
        }
        None
    }

    fn solution(
        &self,
        end: &Held<N, M::Pose>,
        eval: &ModelEvaluation<N, M::Pose>,
        target: &M::Pose,
        work: &Work,
    ) -> SolutionOf<N, M> {
        let verified = Verified {
            tip: eval.tip,
            errors: self.model.pose_error(&eval.tip, target),
            energy: eval.energy,
            margin: eval.stability.margin,
        };
        Solution::new(end.a, verified, *work)
    }
}
