//! Inverse geometry of long cables (w > [`LONG_CABLE_WEIGHT`]) on the multiple-shooting
//! formulation ([`super::cable`]): which rods the search starts from, how each is carried to
//! the target, and which answers it admits.
//!
//! Starts, in order: the caller's guess (corrected where it is, then moved to the target);
//! the catenary through the grippers with a tension layer at each clamp ([`super::catenary`]),
//! corrected by Newton at the full weight; every stable weightless rod through the target (the closed forms' search, loop-free ones
//! first, least energy under the weight to first order first), each carried from w = 0 to the rod's weight with the gripper
//! fixed; the same rods with the load shared by both grippers, a + (0, w ĝ/2), moved from
//! where they end to the target at the full weight; then the stable rods the single-shooting
//! search finds at w = 150, carried to the rod's weight, and the same with the extra load
//! shared, moved; up to w = 600 the single-shooting search's rods at the weight itself,
//! corrected; cables hanging from the base (the tension boundary layer's moment), moved to the
//! target; last, an atlas of cables drawn at the weight itself, the nearest tips moved. Each start may spend half of the time
//! left, and a branch whose tangent turns far beyond what is admitted is abandoned.
//! An answer is admitted when its second variation is positive (stable), it makes at most
//! `max_turns` turns and, when `max_turns` is 0, its centreline does not cross itself.

use super::cable::{lift_near, Cable, CableError, FollowLimits, SecondVariation};
use super::Gravity;
use crate::planar::ig::SolveOptions;
use crate::planar::model::PlanarClosedForm;

use crate::solver::{
    Failure, IgError, InverseGeometry, Objective, RodModel, Solution, Verified, Work,
};
use crate::{PlanarParams, PlanarPose, RodError};
use std::f64::consts::PI;
use std::sync::Mutex;

/// Above this weight the heavy planar rod is solved by multiple shooting (below it single
/// shooting keeps ≥ 6 digits of the tip from an f64 `a`: cond J(1) ≲ 1e8).
pub const LONG_CABLE_WEIGHT: f64 = 200.0;
/// The weight at which the search's last stage asks the single-shooting search.
const MODERATE_WEIGHT: f64 = 150.0;
/// Up to this weight the search also starts from the single-shooting search's rods (cond J(1)
/// ≲ 1e7 for the level cable: their node states are a start within Newton's basin).
const SINGLE_SHOOTING_STARTS_UP_TO: f64 = 600.0;
/// Draws of the atlas at the rod's weight (stage 7): a3 = ±10^U(0, 2), n(0) = s w ĝ plus
/// 10^U(0, log w) in a random direction (the family of `search_coverage long`).
const ATLAS_DRAWS: usize = 400;
/// Atlas rods moved to the target, nearest tips first. 12 → 24 took `search_coverage long
/// 300` seeds 51–53 from 896 to 898 of 900 (medians unchanged); 48 gained nothing more.
const ATLAS_STARTS: usize = 24;
/// Seed of the atlas's draws.
const ATLAS_SEED: u64 = 0x5eed_ca61e;
/// Share of the time left that one start may spend.
const START_SHARE: f64 = 0.5;
/// Weightless rods the search starts from, at most.
const MAX_WEIGHTLESS_STARTS: usize = 12;

/// A solved long cable and what the search checked of it.
#[derive(Clone, Debug, PartialEq)]
pub struct CableSolution {
    /// The equilibrium (node states).
    pub cable: Cable,
    /// Its tip, θ unwrapped.
    pub tip: PlanarPose,
    /// Total energy (elastic + gravitational).
    pub energy: f64,
    /// Elastic energy.
    pub elastic_energy: f64,
    /// The stability test.
    pub stability: SecondVariation,
    /// Full turns of the tangent along the rod.
    pub turns: u32,
    /// The centreline crosses itself.
    pub self_intersects: bool,
    /// Newton iterations and continuation steps spent on it.
    pub iterations: u32,
}

/// What a long-cable search found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CableSearch {
    /// The admitted solutions, least energy first.
    pub solutions: Vec<CableSolution>,
    /// Starts tried.
    pub starts: u32,
    /// Why the last start failed, when one did.
    pub last_failure: Option<String>,
    /// The deadline passed before every start was tried.
    pub cut_short: bool,
}

/// Which answers the search admits (the default: loop-free).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Admission {
    /// Most turns of the tangent (0: loop-free, the default).
    pub max_turns: u32,
}

impl Admission {
    /// What `options` admit (`max_turns`).
    pub fn of(options: &SolveOptions) -> Self {
        Self {
            max_turns: options.max_turns,
        }
    }

    fn admits(&self, s: &CableSolution) -> bool {
        s.stability.stable()
            && s.turns <= self.max_turns
            && (self.max_turns > 0 || !s.self_intersects)
    }
}

/// [`finish`] of a rod reached in `iterations`, as a search's error.
fn finished((cable, iterations): (Cable, u32)) -> Result<CableSolution, CableError> {
    finish(cable, iterations).map_err(CableError::from)
}

fn finish(cable: Cable, iterations: u32) -> Result<CableSolution, RodError> {
    let tip = cable.tip()?;
    let (energy, elastic_energy) = cable.energies()?;
    let stability = cable.second_variation()?;
    let shape = cable.shape(super::cable::SHAPE_CHECK_SAMPLES)?;
    Ok(CableSolution {
        turns: super::cable::turns_of(&shape),
        self_intersects: super::cable::self_intersects(&shape),
        cable,
        tip,
        energy,
        elastic_energy,
        stability,
        iterations,
    })
}

/// The running state of one search: what it found and admits.
struct Searcher<'a> {
    target: &'a PlanarPose,
    gravity: &'a Gravity,
    admission: Admission,
    /// A branch whose tangent turns far beyond what is admitted is abandoned early.
    limits: FollowLimits,
    first_only: bool,
    out: CableSearch,
}

impl Searcher<'_> {
    /// True when the search should stop: the deadline passed (noted), or the first admitted
    /// rod is all that was asked.
    fn done(&mut self) -> bool {
        if crate::deadline::expired() {
            self.out.cut_short = true;
            return true;
        }
        self.first_only && !self.out.solutions.is_empty()
    }

    /// Runs one start (with half of the time left) and admits its rod, if any.
    fn start(&mut self, run: impl FnOnce(&Self) -> Result<(Cable, u32), CableError>) {
        self.start_finished(|s| run(s).and_then(finished));
    }

    /// [`Self::start`] for a run that finishes its rod itself ([`from_guess`]).
    fn start_finished(&mut self, run: impl FnOnce(&Self) -> Result<CableSolution, CableError>) {
        self.out.starts += 1;
        let _share = crate::deadline::share_of_remaining(START_SHARE);
        let r = run(self);
        let out = &mut self.out;
        match r {
            Ok(s) if self.admission.admits(&s) => {
                let scale = 1e-6 * (1.0 + s.cable.params().amax());
                if !out
                    .solutions
                    .iter()
                    .any(|o| (o.cable.params() - s.cable.params()).amax() <= scale)
                {
                    remember(&s.cable);
                    out.solutions.push(s);
                }
            }
            Ok(s) => {
                out.last_failure = Some(format!(
                    "a rod was found but not admitted (stable: {}, turns: {}, crosses itself: {})",
                    s.stability.stable(),
                    s.turns,
                    s.self_intersects
                ))
            }
            Err(e) => out.last_failure = Some(e.to_string()),
        }
    }

    /// Stage 4 (module docs): the moderate-weight rods, carried, then moved with the extra
    /// load shared.
    fn moderate_starts(&mut self, options: &SolveOptions) {
        let mut moderate_rods = Vec::new();
        if !self.done() {
            if let Ok(moderate) = self
                .gravity
                .with_weight(MODERATE_WEIGHT.min(self.gravity.weight()))
            {
                let found = super::HeavyPlanar::new(moderate).robust_all(self.target, options);
                moderate_rods = found.solutions.iter().map(|r| r.a).collect();
                for a in &moderate_rods {
                    if self.done() {
                        break;
                    }
                    self.start(|s| carried(a, &moderate, s.gravity, s.target, &s.limits));
                }
            }
        }
        let extra = self.gravity.weight() - MODERATE_WEIGHT.min(self.gravity.weight());
        for a in &moderate_rods {
            if self.done() {
                break;
            }
            let l = self.gravity.direction();
            let seed =
                PlanarParams::new(a[0], a[1] + 0.5 * extra * l[0], a[2] + 0.5 * extra * l[1]);
            self.start(|s| moved(&seed, s.gravity, s.target, &s.limits));
        }
    }

    /// Stage 5: a little above w = 200, the single-shooting search's rods, corrected.
    fn single_shooting_starts(&mut self, options: &SolveOptions) {
        if self.gravity.weight() <= SINGLE_SHOOTING_STARTS_UP_TO && !self.done() {
            let found =
                super::HeavyPlanar::new(*self.gravity).single_shooting_all(self.target, options);
            for rod in found.solutions {
                if self.done() {
                    break;
                }
                self.start(|s| corrected(&rod.a, s.gravity, s.target));
            }
        }
    }

    /// Stage 7: an atlas of cables at the rod's weight (module docs): the loop-free rods of
    /// [`ATLAS_DRAWS`] seeded draws, the [`ATLAS_STARTS`] whose tips are nearest the target
    /// moved there. The draws are the same on every call (a fixed seed): answers repeat.
    fn atlas_starts(&mut self) {
        if self.done() {
            return;
        }
        let mut rng = crate::rng::SplitMix64::new(ATLAS_SEED);
        let l = self.gravity.load();
        let w = self.gravity.weight();
        let mut near: Vec<(f64, Cable)> = Vec::new();
        for _ in 0..ATLAS_DRAWS {
            if crate::deadline::expired() {
                break;
            }
            let share = rng.range(0.0, 1.0);
            let (psi, mag) = (rng.range(-PI, PI), 10f64.powf(rng.range(0.0, w.log10())));
            let a = PlanarParams::new(
                rng.signed_pow10(0.0, 2.0),
                share * l[0] + mag * psi.cos(),
                share * l[1] + mag * psi.sin(),
            );
            let Ok(c) = Cable::from_params(&a, self.gravity) else {
                continue;
            };
            let Ok(tip) = c.tip() else { continue };
            if c.node_theta_spread() > self.limits.max_theta_spread || tip.x.hypot(tip.y) >= 1.0 {
                continue;
            }
            let d = (tip.x - self.target.x).hypot(tip.y - self.target.y)
                + 0.2 * crate::wrap_angle(tip.theta - self.target.theta).abs();
            near.push((d, c));
        }
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, c) in near.into_iter().take(ATLAS_STARTS) {
            if self.done() {
                break;
            }
            self.start(|s| {
                let mut c = c;
                let steps = c.move_within(s.target, &s.limits)?;
                Ok((c, steps))
            });
        }
    }

    /// Stage 8, where no start reached an admitted rod: a tree of cables in the gripper's pose
    /// space ([`super::cable_tree`]) grown from a stable hanging cable toward the target, each
    /// of its rods stable and admitted: it goes around the folds that stopped every
    /// continuation straight to the target (a 2-D path where the others are lines).
    fn tree_start(&mut self) {
        if self.done() || !self.out.solutions.is_empty() {
            return;
        }
        let Some(root) = tree_root(self.gravity, self.target, self.admission) else {
            return;
        };
        let admission = self.admission;
        self.start(|s| {
            let admit = |c: &Cable| admitted_margin(c, admission);
            match super::cable_tree::path_to(root, 1.0, s.target, admit) {
                Ok(path) => {
                    let steps = path.len() as u32;
                    let last = path.into_iter().last().map(|state| state.cable);
                    last.map(|c| (c, steps)).ok_or(CableError::Singular)
                }
                Err(super::cable_tree::NotReached { edges }) => Err(CableError::Lost {
                    weight: s.gravity.weight(),
                    target_weight: s.gravity.weight(),
                    why: format!(
                        "a tree of {edges} gripper moves from a hanging cable did not reach the \
                         target"
                    ),
                }),
            }
        });
    }

    /// Stage 6: cables hanging from the base, moved to the target.
    fn hanging_starts(&mut self) {
        for seed in hanging_seeds(self.gravity) {
            if self.done() {
                break;
            }
            self.start(|s| moved(&seed, s.gravity, s.target, &s.limits));
        }
    }
}

/// Searches the stable equilibria of the cable under `gravity` whose tip is at `target`
/// (module docs). With [`Objective::FirstFound`] it stops at the first admitted one.
pub fn search(
    target: &PlanarPose,
    gravity: &Gravity,
    options: &SolveOptions,
    admission: Admission,
) -> CableSearch {
    let mut s = Searcher {
        target,
        gravity,
        admission,
        limits: limits_of(admission),
        first_only: options.objective == Objective::FirstFound,
        out: CableSearch::default(),
    };
    // 1. The caller's guess.
    if let Some(a0) = options.initial_guess {
        s.start_finished(|s| from_guess(&a0, s.gravity, s.target, s.admission));
    }
    // 1b. The catenary through the grippers with its tension layers, at the full weight.
    if !s.done() {
        s.start(|s| catenary_seeded(s.gravity, s.target));
    }
    // 2. and 3. The weightless rods through the target: carried in load, then shared-load
    // seeds moved to the target.
    let weightless = Gravity::new(0.0, gravity.direction()).unwrap_or(Gravity::NONE);
    let rods = if s.done() {
        Vec::new()
    } else {
        weightless_rods(target, options, gravity)
    };
    for a in &rods {
        if s.done() {
            break;
        }
        s.start(|s| carried(a, &weightless, s.gravity, s.target, &s.limits));
    }
    for a in &rods {
        if s.done() {
            break;
        }
        s.start(|s| seed_moved(a, s.gravity, s.target, &s.limits));
    }
    s.moderate_starts(options);
    s.single_shooting_starts(options);
    s.hanging_starts();
    s.atlas_starts();
    s.tree_start();
    s.done();
    sorted(s.out)
}

/// The second variation's normalised margin of `c` when `admission` admits it (stable, within
/// the admitted turns, not crossing itself where no turn is admitted).
fn admitted_margin(c: &Cable, admission: Admission) -> Option<f64> {
    let turns_ok = c.turns().is_ok_and(|t| t <= admission.max_turns);
    let crossing_ok = admission.max_turns > 0 || c.self_intersects() == Ok(false);
    match c.second_variation() {
        Ok(sv) if sv.stable() && turns_ok && crossing_ok => Some(sv.normalised()),
        _ => None,
    }
}

/// The root of the last stage's tree: the catenary through grippers 0.8 apart on the chord
/// toward the target (else level), corrected at the full weight and admitted.
fn tree_root(gravity: &Gravity, target: &PlanarPose, admission: Admission) -> Option<Cable> {
    let r = target.x.hypot(target.y);
    let mut roots = vec![PlanarPose::new(0.8, 0.0, 0.0)];
    if r > 0.3 {
        let k = 0.8 / r;
        roots.insert(0, PlanarPose::new(k * target.x, k * target.y, target.theta));
    }
    roots.into_iter().find_map(|p| {
        let (c, _) = catenary_seeded(gravity, &p).ok()?;
        admitted_margin(&c, admission).map(|_| c)
    })
}

/// Rods hanging from the clamped base under their weight: n(0) = s w ĝ (s = 1: the tip
/// gripper holds nothing; ½: half of the weight; 0: all of it) and the base moment of the
/// tension boundary layer that turns the tangent from the clamp's direction toward gravity's
/// by Δ, κ(0) = 2 √(T) sin(Δ/2) with T = max(s, ½) w (the elastica's first integral
/// ½κ² = T (1 − cos Δ)).
fn hanging_seeds(gravity: &Gravity) -> Vec<PlanarParams> {
    let l = gravity.load();
    let g = gravity.direction();
    let turn = g[1].atan2(g[0]);
    [1.0, 0.5, 0.0]
        .iter()
        .map(|&share: &f64| {
            let tension = share.max(0.5) * gravity.weight();
            let kappa = 2.0 * tension.sqrt() * (0.5 * turn).sin();
            PlanarParams::new(kappa, share * l[0], share * l[1])
        })
        .collect()
}

/// The continuation limits of `admission`: a branch whose tangent turns more than 1.5 turns
/// beyond the admitted ones is dropped.
fn limits_of(admission: Admission) -> FollowLimits {
    FollowLimits {
        max_theta_spread: std::f64::consts::TAU * (admission.max_turns as f64 + 1.5),
        ..FollowLimits::default()
    }
}

fn sorted(mut out: CableSearch) -> CableSearch {
    out.solutions.sort_by(|a, b| a.energy.total_cmp(&b.energy));
    out
}

/// The stable weightless rods through `target`, loop-free first, then by their energy under
/// `gravity` to first order in w (the elastic energy plus w ∫(−ĝ · r) dt of the weightless
/// shape: of two mirror images, the one that sags with gravity first).
fn weightless_rods(
    target: &PlanarPose,
    options: &SolveOptions,
    gravity: &Gravity,
) -> Vec<PlanarParams> {
    let mut sols = PlanarClosedForm.robust_all(target, options).solutions;
    if let Ok(s) = PlanarClosedForm.robust(target, options) {
        sols.push(s);
    }
    let g = gravity.direction();
    let mut keyed: Vec<(bool, f64, PlanarParams)> = sols
        .into_iter()
        .filter_map(|s| {
            let shape = crate::planar::shape::PlanarRod::new(&s.a)
                .ok()?
                .shape(super::cable::SHAPE_CHECK_SAMPLES);
            let coiled =
                super::cable::turns_of(&shape) > 0 || super::cable::self_intersects(&shape);
            let h = 1.0 / (shape.len() - 1) as f64;
            let height = |p: &PlanarPose| -(g[0] * p.x + g[1] * p.y);
            let potential: f64 = shape
                .windows(2)
                .map(|w| 0.5 * h * (height(&w[0]) + height(&w[1])))
                .sum();
            Some((coiled, s.energy + gravity.weight() * potential, s.a))
        })
        .collect();
    keyed.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    keyed.dedup_by(|a, b| (a.2 - b.2).amax() <= 1e-6 * (1.0 + b.2.amax()));
    keyed
        .into_iter()
        .take(MAX_WEIGHTLESS_STARTS)
        .map(|k| k.2)
        .collect()
}

/// The weightless rod `a` carried from zero load to `gravity` with the gripper at `target`.
fn carried(
    a: &PlanarParams,
    from: &Gravity,
    gravity: &Gravity,
    target: &PlanarPose,
    limits: &FollowLimits,
) -> Result<(Cable, u32), CableError> {
    let mut c = Cable::from_params(a, from)?;
    let lifted = lift_near(target, c.tip()?.theta);
    let it = c.solve(&lifted)? as u32;
    let steps = c.carry_within(gravity, &lifted, limits)?;
    Ok((c, it + steps))
}

/// The catenary seed ([`super::catenary`]) corrected on the target by Newton at the full
/// weight.
fn catenary_seeded(gravity: &Gravity, target: &PlanarPose) -> Result<(Cable, u32), CableError> {
    let Some((mut c, lifted)) = super::catenary::seed(target, gravity)? else {
        return Err(CableError::Rod(RodError::OutOfDomain(
            "no catenary through the target (a vertical or taut chord)".into(),
        )));
    };
    let it = c.solve(&lifted)?;
    Ok((c, it as u32))
}

/// The rod a + (0, w ĝ / 2) at the full weight (each gripper holding half of it), moved from
/// where it ends to `target`.
fn seed_moved(
    a: &PlanarParams,
    gravity: &Gravity,
    target: &PlanarPose,
    limits: &FollowLimits,
) -> Result<(Cable, u32), CableError> {
    let l = gravity.load();
    let seed = PlanarParams::new(a[0], a[1] + 0.5 * l[0], a[2] + 0.5 * l[1]);
    moved(&seed, gravity, target, limits)
}

/// Newton from the caller's `a0` alone ([`crate::solver::Method::Newton`] above w = 200): the
/// cable `a0` integrates to, corrected on the target where it is (else moved there); the
/// answer must be admitted.
pub fn newton(
    target: &PlanarPose,
    gravity: &Gravity,
    a0: &PlanarParams,
    options: &SolveOptions,
) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
    let admission = Admission::of(options);
    let reached = from_guess(a0, gravity, target, admission);
    one_start_outcome(
        reached,
        target,
        admission,
        |s| admission.admits(s),
        "the rod reached is not admitted (unstable or coiled)",
    )
}

/// The answer of a single-start run (`newton`, `carry`): the rod `reached`, finished and
/// remembered when `accepted`, else the failure with `rejected` (or the error) as its last
/// start's reason.
fn one_start_outcome(
    reached: Result<CableSolution, CableError>,
    target: &PlanarPose,
    admission: Admission,
    accepted: impl Fn(&CableSolution) -> bool,
    rejected: &str,
) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
    let mut out = CableSearch {
        starts: 1,
        ..CableSearch::default()
    };
    match reached {
        Ok(s) if accepted(&s) => {
            remember(&s.cable);
            out.solutions.push(s);
        }
        Ok(_) => out.last_failure = Some(rejected.into()),
        Err(e) => out.last_failure = Some(e.to_string()),
    }
    out.cut_short = crate::deadline::expired();
    match out.solutions.first() {
        Some(s) => Ok(solution_of(s, target, &out)),
        None => Err(failure_of(&out, admission)),
    }
}

/// The rod `a` under `gravity` corrected on `target` where it ends (θ lifted to its turn).
fn corrected(
    a: &PlanarParams,
    gravity: &Gravity,
    target: &PlanarPose,
) -> Result<(Cable, u32), CableError> {
    let mut c = Cable::from_params(a, gravity)?;
    let lifted = lift_near(target, c.tip()?.theta);
    let it = c.solve(&lifted)?;
    Ok((c, it as u32))
}

/// The rod `a` under `gravity`, moved from where it ends to `target`.
fn moved(
    a: &PlanarParams,
    gravity: &Gravity,
    target: &PlanarPose,
    limits: &FollowLimits,
) -> Result<(Cable, u32), CableError> {
    let mut c = Cable::from_params(a, gravity)?;
    let steps = c.move_within(target, limits)?;
    Ok((c, steps))
}

/// The caller's guess: a rod a solver returned is moved from where it is to the target along
/// its branch. Another `a0` is tried three ways, and the first rod `admission` admits is
/// returned (else the last one reached, for the caller to reject with its reason): the cable
/// `a0` integrates to, corrected on the target where it is; the perfect cable under a0's force
/// with its clamp layers (at large w the integrated cable has lost its digits), corrected; the
/// integrated cable moved to the target.
fn from_guess(
    a0: &PlanarParams,
    gravity: &Gravity,
    target: &PlanarPose,
    admission: Admission,
) -> Result<CableSolution, CableError> {
    let limits = limits_of(admission);
    // A rod a solver returned: its node states, moved to the target (tracking).
    if let Some(mut c) = recall(a0, gravity) {
        let steps = c.move_within(target, &limits)?;
        return finished((c, steps));
    }
    let integrated = Cable::from_params(a0, gravity)?;
    let lifted = lift_near(target, integrated.tip()?.theta);
    let direct = || {
        let mut c = integrated.clone();
        c.solve(&lifted).map(|it| (c, it as u32))
    };
    let force_seeded = || match super::catenary::seed_with_force([a0[1], a0[2]], target, gravity)? {
        Some((mut c, lifted)) => c.solve(&lifted).map(|it| (c, it as u32)),
        None => Err(CableError::Singular),
    };
    let moved = || {
        let mut c = integrated.clone();
        c.move_within(target, &limits).map(|steps| (c, steps))
    };
    let tries: [&dyn Fn() -> Result<(Cable, u32), CableError>; 3] =
        [&direct, &force_seeded, &moved];
    let mut last = Err(CableError::Singular);
    for attempt in tries {
        // Each rod reached is finished once: its verdict decides, and the caller keeps it.
        let reached = attempt().and_then(finished);
        if reached.as_ref().is_ok_and(|s| admission.admits(s)) {
            return reached;
        }
        if reached.is_ok() || last.is_err() {
            last = reached;
        }
    }
    last
}

/// Cables the solvers returned, remembered so that the shape, energy and stability of an
/// answer's `a` come from its node states (an f64 `a` alone does not reproduce the rod at
/// large w): the last [`REMEMBERED`] of the process.
static SOLVED: Mutex<Vec<Cable>> = Mutex::new(Vec::new());
/// Cables remembered.
pub const REMEMBERED: usize = 256;

pub(crate) fn remember(c: &Cable) {
    if let Ok(mut v) = SOLVED.lock() {
        if v.iter().any(|o| o.same_rod(c)) {
            return;
        }
        if v.len() >= REMEMBERED {
            v.remove(0);
        }
        v.push(c.clone());
    }
}

/// The cable a solve returned with base wrench exactly `a` under `gravity`, if remembered.
pub fn recall(a: &PlanarParams, gravity: &Gravity) -> Option<Cable> {
    let v = SOLVED.lock().ok()?;
    v.iter()
        .rev()
        .find(|c| c.params() == *a && c.gravity() == gravity)
        .cloned()
}

/// The solver's [`Solution`] of a cable on `target` after `search`'s work.
pub fn solution_of(
    s: &CableSolution,
    target: &PlanarPose,
    search: &CableSearch,
) -> Solution<PlanarParams, PlanarPose> {
    let (position_error, orientation_error) = PlanarClosedForm.pose_error(&s.tip, target);
    let mut out = Solution::new(
        s.cable.params(),
        Verified {
            tip: s.tip,
            errors: (position_error, orientation_error),
            energy: s.energy,
            margin: s.stability.normalised(),
        },
        Work {
            iterations: s.iterations,
            evaluations: s.iterations,
            starts: search.starts,
        },
    );
    out.complete = false;
    out
}

/// The solver's [`Failure`] of a search that admitted nothing.
pub fn failure_of(search: &CableSearch, admission: Admission) -> Failure<PlanarParams> {
    let reason = if search.cut_short && search.starts == 0 {
        IgError::Deadline { iteration: 0 }
    } else {
        IgError::NoAdmittedRod {
            starts: search.starts,
            max_turns: admission.max_turns,
            cut_short: search.cut_short,
            last: search.last_failure.clone(),
        }
    };
    Failure {
        starts: search.starts,
        ..Failure::early(reason)
    }
}

/// The cable of the rod `a` under `gravity`: the one a solver returned (its node states), or,
/// at a weight single shooting keeps its digits (≤ [`LONG_CABLE_WEIGHT`]), the one `a`
/// integrates to, corrected on `target`.
fn cable_of(a: &PlanarParams, gravity: &Gravity, target: &PlanarPose) -> Option<Cable> {
    if let Some(c) = recall(a, gravity) {
        return Some(c);
    }
    if gravity.weight() > LONG_CABLE_WEIGHT {
        return None;
    }
    let mut c = Cable::from_params(a, gravity).ok()?;
    let lifted = lift_near(target, c.tip().ok()?.theta);
    c.solve(&lifted).ok()?;
    Some(c)
}

/// One corrector step of the branch follower on a long cable's node states
/// ([`crate::solver::RodModel::branch_step`]): the rod of `from`'s branch with its tip at
/// `goal`, when Newton reaches it in a few iterations, near `from`, on the same side of the
/// fold (the sign of the Newton matrix's determinant); `None` otherwise. The rod reached is
/// remembered, so that the follower's later evaluations of its `a` use its node states.
pub fn branch_step(
    from: &PlanarParams,
    gravity: &Gravity,
    goal: &PlanarPose,
    tolerance: f64,
) -> Option<(PlanarParams, PlanarPose, crate::PlanarJacobian)> {
    let c = recall(from, gravity)?;
    let here = c.tip().ok()?;
    let side = c.matrix_sign(&here).ok()?;
    let mut next = c.clone();
    let goal = lift_near(goal, here.theta);
    let (iterations, sign) = next.solve_with_sign(&goal).ok()?;
    let tip = next.tip().ok()?;
    let (pe, oe) = PlanarClosedForm.pose_error(&tip, &goal);
    if iterations > 8 || sign != side || !next.close_to(&c) || pe > tolerance || oe > tolerance {
        return None;
    }
    remember(&next);
    Some((next.params(), tip, next.jacobian().ok()?))
}

/// [`super::carry`] above w = 200: the held rod's cable carried in load on its node states.
pub fn carry(
    a: &PlanarParams,
    from: &Gravity,
    to: &Gravity,
    gripper: &PlanarPose,
    options: &SolveOptions,
) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
    let _deadline = crate::deadline::scope(options.deadline);
    let admission = Admission::of(options);
    let carried = match cable_of(a, from, gripper) {
        None => Err(CableError::Lost {
            weight: from.weight(),
            target_weight: to.weight(),
            why: "the held rod's node states are not known (an `a` a solver returned at this \
                  weight, or one at weight <= 200, is needed)"
                .into(),
        }),
        Some(mut c) => {
            let lifted = lift_near(gripper, c.tip().map(|t| t.theta).unwrap_or(gripper.theta));
            c.carry_within(to, &lifted, &limits_of(admission))
                .and_then(|steps| finished((c, steps)))
        }
    };
    one_start_outcome(
        carried,
        gripper,
        admission,
        |s| s.stability.stable(),
        "the carried rod is unstable",
    )
}
