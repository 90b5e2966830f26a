//! Equilibria of a planar rod, with or without weight, whose ends are pinned or free
//! (issue 52; [`crate::ends`]). Solved on the multiple-shooting formulation ([`Cable`]) with
//! the end conditions as its equations, and judged by the second variation with the natural
//! boundary conditions ([`SecondVariation`]).
//!
//! - **Free tip** (clamped base): n(1) = 0 fixes n(0) = w ĝ, and κ(1) = 0 leaves one equation
//!   in a3. Since m(0) = w ∫ (r × ĝ) dt and |r(t)| ≤ t, every root has |a3| ≤ w/2: the bracket
//!   is scanned (single shooting at w ≤ [`SCAN_WEIGHT`], where κ(1) keeps its digits), each
//!   sign change is bisected and polished by Newton on the nodes, then carried in load to the
//!   rod's weight when that is larger. Every root found is reported; the stable ones answer.
//! - **A held tip** (pinned, or clamped with a pinned base): the weightless rods through the
//!   target, found by the closed forms for base angles (pinned base) and tip angles (pinned
//!   tip) around the chord, are corrected on the end conditions at w = 0, then carried in load
//!   to the rod's weight with the tip held; then the same rods' bases turned toward gravity,
//!   corrected at the full weight directly.

use super::cable::{lift_near, Cable, CableError, FollowLimits, SecondVariation};
use super::{series, Gravity};

use crate::ends::{EndCondition, HeldEnds};
use crate::planar::ig::SolveOptions;
use crate::planar::model::PlanarClosedForm;
use crate::solver::InverseGeometry;

use crate::{PlanarParams, PlanarPose, RodError};
use std::f64::consts::FRAC_PI_4;

/// Up to this weight a free tip's κ(1)(a3) is scanned by single shooting at the rod's weight
/// (cond J(1) ≲ 1e7); above it the scan runs here and its roots are carried in load.
pub const SCAN_WEIGHT: f64 = 300.0;
/// Scan points per unit of w (the oracle's scans resolve every root at 20).
const SCAN_PER_WEIGHT: f64 = 24.0;
/// Fewest and most scan points.
const SCAN_POINTS: (usize, usize) = (400, 9000);
/// Angles tried around the chord at a pinned end (every π/4).
const ANGLES: usize = 8;
/// Time the closed forms' search may spend on one weightless seed.
const WEIGHTLESS_DEADLINE: std::time::Duration = std::time::Duration::from_millis(5);

/// Why held ends could not be solved.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HeldError {
    /// The target does not fit the tip's condition, or cannot be reached.
    #[error("{field}: {why}")]
    Target {
        /// The request field to change.
        field: &'static str,
        /// Why.
        why: String,
    },
    /// A followed rod left its branch: the continuation failed, or the rod it reached is not
    /// admitted (unstable, coiled).
    #[error("the held rod was lost on the way: {why}")]
    Lost {
        /// What stopped it.
        why: String,
    },
    /// No stable equilibrium was found.
    #[error(
        "no stable equilibrium found with {base} base and {tip} tip ({starts} starts{cut}){last}"
    )]
    NotFound {
        /// Base condition.
        base: EndCondition,
        /// Tip condition.
        tip: EndCondition,
        /// Starts tried.
        starts: u32,
        /// ", cut short by the deadline" when it passed.
        cut: &'static str,
        /// The last failure's reason (": …"), if any.
        last: String,
    },
}

/// One equilibrium with held ends.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldSolution {
    /// a = (κ(0), n(0)) in the base frame (a3 = 0 for a pinned base; n(0) = w ĝ for a free tip).
    pub a: PlanarParams,
    /// The rod's angle at the base θ(0) (0 unless the base is pinned).
    pub base_angle: f64,
    /// The tip (x, y, θ), θ unwrapped.
    pub tip: PlanarPose,
    /// κ(1) (0 at a pinned or free tip).
    pub tip_curvature: f64,
    /// Total energy (elastic + gravitational, and a free tip's load potential −P · r(1)).
    pub energy: f64,
    /// Elastic energy ½∫κ².
    pub elastic_energy: f64,
    /// The second variation with the natural boundary conditions.
    pub stability: SecondVariation,
    /// Full turns of the tangent.
    pub turns: u32,
    /// The centreline crosses itself.
    pub self_intersects: bool,
    /// The equilibrium's node states.
    pub cable: Cable,
}

/// What a search with held ends found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HeldSearch {
    /// The admitted (stable, within `max_turns`) equilibria, least energy first.
    pub solutions: Vec<HeldSolution>,
    /// Every distinct equilibrium found, stable or not, least energy first.
    pub equilibria: Vec<HeldSolution>,
    /// Starts tried.
    pub starts: u32,
    /// The deadline passed before every start was tried.
    pub cut_short: bool,
    /// Why the last start failed, when one did.
    pub last_failure: Option<String>,
}

impl HeldSolution {
    /// The wrenches the rod exerts on its grippers ([`crate::wrench`]): at a pinned end the
    /// moment is zero, at a free tip the whole wrench (minus a tip load, if any).
    pub fn wrenches(&self) -> crate::wrench::GripperWrenches<crate::wrench::PlanarWrench> {
        let l = self.cable.gravity().load();
        let n1 = [self.a[1] - l[0], self.a[2] - l[1]];
        crate::wrench::planar(&self.a, &self.tip, n1, self.tip_curvature)
    }
}

impl HeldSolution {
    /// The equilibrium `cable` (solved on its end conditions) with its energies (a free
    /// tip's load potential included), stability, turns and crossings; a pinned base's angle
    /// unwound into (−π, π].
    pub fn of(mut cable: Cable) -> Result<Self, RodError> {
        cable.unwind_base_angle();
        let tip = cable.tip()?;
        let (energy, elastic_energy) = cable.energies()?;
        // A tip load's potential: −P · r(1).
        let load = cable.tip_load();
        let energy = energy - (load[0] * tip.x + load[1] * tip.y);
        let shape = cable.shape(super::cable::SHAPE_CHECK_SAMPLES)?;
        Ok(HeldSolution {
            a: cable.params(),
            base_angle: cable.base_angle(),
            tip,
            tip_curvature: cable.tip_curvature()?,
            energy,
            elastic_energy,
            stability: cable.second_variation()?,
            turns: super::cable::turns_of(&shape),
            self_intersects: super::cable::self_intersects(&shape),
            cable,
        })
    }
}

/// The forward map of a rod held by `ends` (no search): the cable leaving the base at
/// `base_angle` with base wrench `a`, integrated from the base ([`Cable::held`]), a free tip
/// carrying `tip_load`. What it reports: [`HeldSolution`] (tip, energies, the second
/// variation with the natural conditions, turns, wrenches), J(1) = ∂(x, y, θ)(1)/∂(base
/// unknown, a4, a5) (first column ∂/∂a3 for a clamped base, ∂/∂θ(0) for a pinned one) and the
/// condition figure ‖J‖∞ · max(1, ‖a‖∞). Refused with the field named: a moment at a pinned
/// base (a3 ≠ 0), and for a free tip a base force other than w ĝ + `tip_load` (a free tip
/// holds no force: the rod's force is its weight and the load).
pub fn evaluate(
    base_angle: f64,
    a: &PlanarParams,
    gravity: &Gravity,
    ends: HeldEnds,
    tip_load: [f64; 2],
) -> Result<HeldEvaluation, HeldError> {
    let field = |field: &'static str, why: String| HeldError::Target { field, why };
    if ends.base() == EndCondition::Pinned && a[0] != 0.0 {
        return Err(field(
            "a",
            format!("a pinned base holds no moment: a3 must be 0 (got {})", a[0]),
        ));
    }
    if ends.base() == EndCondition::Clamped && base_angle != 0.0 {
        return Err(field(
            "base_angle",
            "a clamped base leaves along the base frame's x axis: base_angle must be 0".into(),
        ));
    }
    if ends.tip() == EndCondition::Free {
        let l = gravity.load();
        let need = [l[0] + tip_load[0], l[1] + tip_load[1]];
        let off = (a[1] - need[0]).abs().max((a[2] - need[1]).abs());
        if !(off <= 1e-9 * (1.0 + need[0].abs().max(need[1].abs()))) {
            return Err(field(
                "a",
                format!(
                    "a free tip holds no force: (a4, a5) must be w ĝ + tip_load = ({}, {}) (got ({}, {}))",
                    need[0], need[1], a[1], a[2]
                ),
            ));
        }
    } else if tip_load != [0.0; 2] {
        return Err(field(
            "tip_load",
            "a tip load needs a free tip (a held tip's gripper takes it)".into(),
        ));
    }
    let rod = |e: RodError| field("a", e.to_string());
    let mut cable = Cable::held(base_angle, a, gravity, ends).map_err(rod)?;
    if ends.tip() == EndCondition::Free {
        cable = cable.with_tip_load(tip_load).map_err(rod)?;
    }
    let jacobian = cable.jacobian().map_err(rod)?;
    let condition = jacobian.abs().row_sum().max() * a.amax().max(1.0);
    let solution = HeldSolution::of(cable).map_err(rod)?;
    Ok(HeldEvaluation {
        solution,
        jacobian,
        condition,
    })
}

/// What [`evaluate`] reports of a held rod.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldEvaluation {
    /// The rod, its energies, stability (natural conditions), turns and node states.
    pub solution: HeldSolution,
    /// J(1) = ∂(x, y, θ)(1)/∂(a3 or θ(0), a4, a5), rows x, y, θ.
    pub jacobian: crate::PlanarJacobian,
    /// ‖J‖∞ · max(1, ‖a‖∞): the tip of an f64 `a` is uncertain by about this × 1.1e-16; above
    /// [`super::MAX_TRUSTED_CONDITION`] the verdict should not be trusted
    /// ([`HeldEvaluation::uncertain`]).
    pub condition: f64,
}

impl HeldEvaluation {
    /// The verdict is undecided: μ within its error, or, for a long cable (w above
    /// [`super::cable_search::LONG_CABLE_WEIGHT`]), the tip of this f64 `a` not determined by
    /// integration from the base (`condition` beyond [`super::MAX_TRUSTED_CONDITION`]), as
    /// [`super::evaluate`] says of a clamped rod.
    pub fn uncertain(&self) -> bool {
        let long = self.solution.cable.gravity().weight() > super::cable_search::LONG_CABLE_WEIGHT;
        self.solution.stability.uncertain()
            || (long && !(self.condition <= super::MAX_TRUSTED_CONDITION))
    }

    /// Stable with the natural conditions, and decided.
    pub fn stable(&self) -> bool {
        self.solution.stability.stable() && !self.uncertain()
    }
}

/// The target as the tip's condition needs it: a pose (clamped), a position (pinned, θ is
/// ignored), nothing (free).
fn checked_target(
    ends: HeldEnds,
    target: Option<&PlanarPose>,
) -> Result<Option<PlanarPose>, HeldError> {
    let refuse = |why: &str| {
        Err(HeldError::Target {
            field: "target",
            why: why.into(),
        })
    };
    match (ends.tip(), target) {
        (EndCondition::Free, None) => Ok(None),
        (EndCondition::Free, Some(_)) => {
            refuse("a free tip has no target: the cable hangs from its base")
        }
        (_, None) => refuse("a clamped or pinned tip needs a target"),
        (tip, Some(t)) => {
            let theta = if tip == EndCondition::Pinned {
                0.0
            } else {
                t.theta
            };
            if !(t.x.is_finite() && t.y.is_finite() && theta.is_finite()) {
                return refuse("the target must be finite");
            }
            let d = t.x.hypot(t.y);
            if d > 1.0 {
                return Err(HeldError::Target {
                    field: "target",
                    why: format!("unreachable: the tip is {d:.6} from the base, the rod is 1 long"),
                });
            }
            Ok(Some(PlanarPose::new(t.x, t.y, theta)))
        }
    }
}

/// The equilibria of the rod under `gravity` held by `ends`, its tip at `target` (a pose for
/// a clamped tip; a position for a pinned tip, θ ignored; `None` for a free tip). Stops at
/// the deadline in force; `options.max_turns` bounds the admitted turns (0: loop-free, and
/// the centreline must not cross itself).
pub fn equilibria(
    ends: HeldEnds,
    gravity: &Gravity,
    target: Option<&PlanarPose>,
    options: &SolveOptions,
) -> Result<HeldSearch, HeldError> {
    equilibria_with_tip_load(ends, gravity, [0.0; 2], target, options)
}

/// [`equilibria`] with a point force `tip_load` (base frame, units of EI/L²) applied at a free
/// tip: a weight hanging from the cable's end, a cantilever's tip load. Refused for a held tip
/// (its gripper takes any load).
pub fn equilibria_with_tip_load(
    ends: HeldEnds,
    gravity: &Gravity,
    tip_load: [f64; 2],
    target: Option<&PlanarPose>,
    options: &SolveOptions,
) -> Result<HeldSearch, HeldError> {
    let target = checked_target(ends, target)?;
    if tip_load != [0.0; 2] && ends.tip() != EndCondition::Free {
        return Err(HeldError::Target {
            field: "tip_load",
            why: "a tip load needs a free tip (a held tip's gripper takes it)".into(),
        });
    }
    if !(tip_load
        .iter()
        .all(|v| v.is_finite() && v.abs() <= super::MAX_PARAM))
    {
        return Err(HeldError::Target {
            field: "tip_load",
            why: format!(
                "each component must be finite, |f| <= {:e}",
                super::MAX_PARAM
            ),
        });
    }
    let _deadline = crate::deadline::scope(options.deadline);
    let mut search = Search {
        ends,
        gravity: *gravity,
        tip_load,
        out: HeldSearch::default(),
        max_turns: options.max_turns,
    };
    match target {
        None => search.free_tip(),
        Some(t) => search.held_tip(&t, options),
    }
    search.out.cut_short |= crate::deadline::expired();
    let by_energy = |a: &HeldSolution, b: &HeldSolution| a.energy.total_cmp(&b.energy);
    search.out.equilibria.sort_by(by_energy);
    search.out.solutions.sort_by(by_energy);
    Ok(search.out)
}

/// Quasi-static motion with held ends: the rod `from` carried to `gravity` with its gripper
/// where it is, then moved along its branch to `target` (a clamped tip's pose, a pinned tip's
/// position; `None` for a free tip, which only follows gravity), by continuation on its node
/// states ([`Cable::carry_within`], [`Cable::move_within`]) within `options.deadline`. The rod
/// reached must be admitted as the search's answers are (stable with the natural conditions,
/// at most `options.max_turns` turns, loop-free without crossing); otherwise, or where the
/// continuation stops (a fold), [`HeldError::Lost`] says why.
pub fn follow(
    from: &HeldSolution,
    gravity: &Gravity,
    target: Option<&PlanarPose>,
    options: &SolveOptions,
) -> Result<HeldSolution, HeldError> {
    let ends = from.cable.ends();
    let target = checked_target(ends, target)?;
    let _deadline = crate::deadline::scope(options.deadline);
    let lost = |e: CableError| HeldError::Lost { why: e.to_string() };
    let limits = FollowLimits {
        max_theta_spread: std::f64::consts::TAU * (options.max_turns as f64 + 1.5),
        ..FollowLimits::default()
    };
    let mut cable = from.cable.clone();
    let tip = from.tip;
    // A pinned tip's θ is free: the goal pose keeps the rod's own (no equation asks it).
    let goal = |t: Option<PlanarPose>, theta: f64| match (ends.tip(), t) {
        (EndCondition::Clamped, Some(t)) => lift_near(&t, theta),
        (_, Some(t)) => PlanarPose::new(t.x, t.y, theta),
        (_, None) => PlanarPose::new(tip.x, tip.y, theta),
    };
    if cable.gravity() != gravity {
        cable
            .carry_within(gravity, &goal(None, tip.theta), &limits)
            .map_err(lost)?;
    }
    if target.is_some() {
        let theta = cable.tip().map_err(|e| lost(e.into()))?.theta;
        cable
            .move_within(&goal(target, theta), &limits)
            .map_err(lost)?;
    }
    let reached = HeldSolution::of(cable).map_err(|e| lost(e.into()))?;
    let admitted = reached.stability.stable()
        && reached.turns <= options.max_turns
        && (options.max_turns > 0 || !reached.self_intersects);
    if !admitted {
        return Err(HeldError::Lost {
            why: format!(
                "the rod reached is not admitted (stable: {}, turns: {})",
                reached.stability.stable(),
                reached.turns
            ),
        });
    }
    Ok(reached)
}

/// What happened to a held rod in one step of a motion ([`step`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeldEvent {
    /// It followed its branch (or, at the first step, was found afresh).
    None,
    /// Its branch ended: a fresh search found another admitted equilibrium.
    Snap,
    /// Its branch ended and no admitted equilibrium was found.
    Lost,
}

impl HeldEvent {
    /// "none", "snap" or "lost": the name the CLI, Python and the node report.
    pub fn as_str(self) -> &'static str {
        match self {
            HeldEvent::None => "none",
            HeldEvent::Snap => "snap",
            HeldEvent::Lost => "lost",
        }
    }
}

/// One step of a quasi-static motion of a rod held by `ends` (`tip_load` at a free tip): the
/// rod `held` now (None at the first step or after a loss) is followed along its branch to
/// `gravity` and `target` ([`follow`], event none); where that fails, or at the first step,
/// the equilibria are searched afresh, least energy first (event snap after a failed follow,
/// lost when none is admitted). The rod held next is the search's first solution.
pub fn step(
    held: Option<&HeldSolution>,
    ends: HeldEnds,
    gravity: &Gravity,
    tip_load: [f64; 2],
    target: Option<&PlanarPose>,
    options: &SolveOptions,
) -> Result<(HeldEvent, HeldSearch), HeldError> {
    let followed = held.map(|h| follow(h, gravity, target, options));
    if let Some(Ok(s)) = followed {
        let found = HeldSearch {
            solutions: vec![s.clone()],
            equilibria: vec![s],
            starts: 1,
            ..HeldSearch::default()
        };
        return Ok((HeldEvent::None, found));
    }
    let found = equilibria_with_tip_load(ends, gravity, tip_load, target, options)?;
    let event = match (followed.is_some(), found.solutions.is_empty()) {
        (false, _) => HeldEvent::None,
        (true, false) => HeldEvent::Snap,
        (true, true) => HeldEvent::Lost,
    };
    Ok((event, found))
}

/// The least-energy admitted equilibrium of [`equilibria`], or why there is none.
pub fn least_energy(
    ends: HeldEnds,
    gravity: &Gravity,
    target: Option<&PlanarPose>,
    options: &SolveOptions,
) -> Result<(HeldSolution, HeldSearch), HeldError> {
    best_of(ends, equilibria(ends, gravity, target, options)?)
}

/// The least-energy admitted equilibrium a search `found` (with `ends`), or why there is none.
pub fn best_of(ends: HeldEnds, found: HeldSearch) -> Result<(HeldSolution, HeldSearch), HeldError> {
    match found.solutions.first() {
        Some(s) => Ok((s.clone(), found)),
        None => Err(not_found(ends, &found)),
    }
}

/// Why a search found no admitted equilibrium.
pub fn not_found(ends: HeldEnds, found: &HeldSearch) -> HeldError {
    HeldError::NotFound {
        base: ends.base(),
        tip: ends.tip(),
        starts: found.starts,
        cut: if found.cut_short {
            ", cut short by the deadline"
        } else {
            ""
        },
        last: found
            .last_failure
            .as_ref()
            .map(|w| format!(": {w}"))
            .unwrap_or_default(),
    }
}

struct Search {
    ends: HeldEnds,
    gravity: Gravity,
    /// The point force at a free tip (zero otherwise).
    tip_load: [f64; 2],
    out: HeldSearch,
    max_turns: u32,
}

impl Search {
    fn admits(&self, s: &HeldSolution) -> bool {
        s.stability.stable()
            && s.turns <= self.max_turns
            && (self.max_turns > 0 || !s.self_intersects)
    }

    /// Finishes a start's cable and keeps it when it is new.
    fn keep(&mut self, reached: Result<Cable, CableError>) {
        self.out.starts += 1;
        let s = match reached.and_then(|c| HeldSolution::of(c).map_err(CableError::from)) {
            Ok(s) => s,
            Err(e) => {
                self.out.last_failure = Some(e.to_string());
                return;
            }
        };
        let scale = 1e-6 * (1.0 + s.a.amax());
        let same = |o: &HeldSolution| {
            (o.a - s.a).amax() <= scale
                && crate::wrap_angle(o.base_angle - s.base_angle).abs() <= 1e-6
        };
        if self.out.equilibria.iter().any(same) {
            return;
        }
        if self.admits(&s) {
            self.out.solutions.push(s.clone());
        } else {
            self.out.last_failure = Some(format!(
                "an equilibrium was found but not admitted (stable: {}, turns: {}, crosses \
                 itself: {})",
                s.stability.stable(),
                s.turns,
                s.self_intersects
            ));
        }
        self.out.equilibria.push(s);
    }

    /// Free tip: the roots of κ(1)(a3) on |a3| ≤ w/2 + |P| (module docs).
    fn free_tip(&mut self) {
        let w = self.gravity.weight();
        let scan = if w > SCAN_WEIGHT {
            self.gravity
                .with_weight(SCAN_WEIGHT)
                .unwrap_or(self.gravity)
        } else {
            self.gravity
        };
        let dummy = PlanarPose::new(0.0, 0.0, 0.0);
        let load = self.tip_load;
        for a3 in free_tip_roots(&scan, load) {
            if crate::deadline::expired() {
                return;
            }
            let target = self.gravity;
            let ends = self.ends;
            self.keep((|| {
                let c = Cable::held(0.0, &PlanarParams::new(a3, 0.0, 0.0), &scan, ends)?;
                let mut c = c.with_tip_load(load)?;
                c.solve(&dummy)?;
                if scan != target {
                    c.carry_within(&target, &dummy, &FollowLimits::default())?;
                }
                Ok(c)
            })());
        }
    }

    /// A held tip (module docs).
    fn held_tip(&mut self, target: &PlanarPose, options: &SolveOptions) {
        // The closed forms' atlas, built (once per process) within this request's deadline
        // rather than in the seeds' short ones.
        let _ = crate::planar::ig::atlas::get(crate::planar::ig::atlas::Tier::Box);
        let limits = FollowLimits {
            max_theta_spread: std::f64::consts::TAU * (self.max_turns as f64 + 1.5),
            ..FollowLimits::default()
        };
        self.heavy_starts(target, false);
        let mut seeds: Vec<(Cable, PlanarPose)> = Vec::new();
        for (theta0, theta1) in angle_pairs(self.ends, target) {
            for a in weightless_rods(theta0, theta1, target, options) {
                if crate::deadline::expired() {
                    return;
                }
                let Some(seed) = self.released(theta0, &a, target) else {
                    continue;
                };
                if seeds.iter().any(|(s, _)| s.close_to(&seed.0)) {
                    continue;
                }
                // Carried from w = 0 to the rod's weight with the tip held.
                let (mut c, lifted) = seed.clone();
                let g = self.gravity;
                self.keep(c.carry_within(&g, &lifted, &limits).map(|_| c));
                seeds.push(seed);
            }
        }
        // The same rods at the full weight, the load shared by both ends, corrected directly.
        let l = self.gravity.load();
        for (c, lifted) in &seeds {
            if crate::deadline::expired() {
                return;
            }
            let a = c.params();
            let shared = PlanarParams::new(a[0], a[1] + 0.5 * l[0], a[2] + 0.5 * l[1]);
            let (g, ends, theta0) = (self.gravity, self.ends, c.base_angle());
            self.keep((|| {
                let mut c = Cable::held(theta0, &shared, &g, ends)?;
                c.solve(lifted)?;
                Ok(c)
            })());
        }
        // Nothing yet: the heavy search again, each angle pair with its share of the time left
        // (nearly taut rods under tension need more than the first pass's budget).
        if self.out.solutions.is_empty() {
            self.heavy_starts(target, true);
        }
    }

    /// The weightless clamped rod (base angle `theta0`, base wrench `a`) on target, its
    /// moments released into this search's ends at w = 0, and the target its tip is held at.
    fn released(
        &self,
        theta0: f64,
        a: &PlanarParams,
        target: &PlanarPose,
    ) -> Option<(Cable, PlanarPose)> {
        let weightless = self.gravity.with_weight(0.0).unwrap_or(Gravity::NONE);
        let c = Cable::held(theta0, a, &weightless, HeldEnds::CLAMPED).ok()?;
        self.release(c, target)
    }

    /// The clamped cable `c` corrected on target (at its own tip angle where the tip is
    /// pinned), its moments released into this search's ends; and the target its tip is held at.
    fn release(&self, mut c: Cable, target: &PlanarPose) -> Option<(Cable, PlanarPose)> {
        let tip = c.tip().ok()?;
        // The clamped rod is corrected on its own tip angle (a pinned tip's target has none).
        let lifted = if self.ends.tip() == EndCondition::Pinned {
            PlanarPose::new(target.x, target.y, tip.theta)
        } else {
            lift_near(target, tip.theta)
        };
        c.solve(&lifted).ok()?;
        c.release_into(self.ends, &lifted).ok()?;
        Some((c, lifted))
    }

    /// The first stage with weight (and, `patient`, the last where nothing was found, each
    /// pair with its share of the time left): at each (base, tip) angle pair the heavy clamped search
    /// (in the frame turned by the base angle, gravity turned back) at the rod's own weight,
    /// its moments released at that weight. A long cable (w > 200) is taken only with an
    /// unturned base, from the node states its search remembered.
    fn heavy_starts(&mut self, target: &PlanarPose, patient: bool) {
        if self.gravity.is_weightless() {
            return;
        }
        let pairs = angle_pairs(self.ends, target);
        let count = pairs.len();
        let w = self.gravity.weight();
        let long = w > super::cable_search::LONG_CABLE_WEIGHT;
        let dir = self.gravity.direction();
        for (i, (theta0, theta1)) in pairs.into_iter().enumerate() {
            if crate::deadline::expired() {
                return;
            }
            if long && theta0 != 0.0 {
                continue;
            }
            // The patient pass: this pair's share of the time left, at most 1/4 of it.
            let _share = patient
                .then(|| crate::deadline::share_of_remaining(1.0 / (count - i).max(4) as f64));
            let (s, c) = theta0.sin_cos();
            let Ok(local_g) = Gravity::new(w, [c * dir[0] + s * dir[1], -s * dir[0] + c * dir[1]])
            else {
                continue;
            };
            let local = PlanarPose::new(
                c * target.x + s * target.y,
                -s * target.x + c * target.y,
                crate::wrap_angle(theta1 - theta0),
            );
            let opts = SolveOptions {
                deadline: match (patient, long) {
                    (true, _) => crate::planar::ig::MAX_DEADLINE,
                    (false, true) => HEAVY_DEADLINE * 10,
                    (false, false) => HEAVY_DEADLINE,
                },
                objective: crate::solver::Objective::FirstFound,
                ..SolveOptions::default()
            };
            let Ok(sol) = crate::solver::solve(&super::HeavyPlanar::new(local_g), &local, &opts)
            else {
                continue;
            };
            let a = sol.a;
            let cable = if long {
                super::cable_search::recall(&a, &local_g)
            } else {
                let turned = PlanarParams::new(a[0], c * a[1] - s * a[2], s * a[1] + c * a[2]);
                Cable::held(theta0, &turned, &self.gravity, HeldEnds::CLAMPED).ok()
            };
            match cable.and_then(|cable| self.release(cable, target)) {
                Some((released, _)) => self.keep(Ok(released)),
                None => self.out.starts += 1,
            }
        }
    }
}

/// Time the heavy clamped search may spend at one angle pair (ten times that for a long cable).
const HEAVY_DEADLINE: std::time::Duration = std::time::Duration::from_millis(20);

/// κ(1) of the clamped rod with base moment `a3` and a free tip carrying `load`
/// (n(0) = w ĝ + load), by single shooting.
fn free_tip_curvature(a3: f64, gravity: &Gravity, load: [f64; 2]) -> Option<f64> {
    let l = gravity.load();
    let a = PlanarParams::new(a3, l[0] + load[0], l[1] + load[1]);
    series::integrate(&gravity.problem(&a), false, |_| true)
        .ok()
        .map(|end| end.kappa)
        .filter(|k| k.is_finite())
}

/// The roots of κ(1)(a3) of a free tip carrying `load` on |a3| ≤ w/2 + |load| (the moment
/// balance about the base: |r(t)| ≤ t), found by a uniform scan and bisection (no weight and
/// no load: the straight rod, a3 = 0).
pub fn free_tip_roots(gravity: &Gravity, load: [f64; 2]) -> Vec<f64> {
    let w = gravity.weight();
    let bound = 0.5 * w + load[0].hypot(load[1]);
    if bound == 0.0 {
        return vec![0.0];
    }
    let n = ((SCAN_PER_WEIGHT * 2.0 * bound) as usize).clamp(SCAN_POINTS.0, SCAN_POINTS.1);
    let a3_at = |i: usize| -bound + 2.0 * bound * i as f64 / n as f64;
    let curvature = |a3: f64| free_tip_curvature(a3, gravity, load);
    let mut roots = Vec::new();
    let mut prev: Option<(f64, f64)> = None;
    for i in 0..=n {
        if crate::deadline::expired() {
            break;
        }
        let a3 = a3_at(i);
        let Some(k) = curvature(a3) else {
            prev = None;
            continue;
        };
        if k == 0.0 {
            roots.push(a3);
        } else if let Some((a_prev, k_prev)) = prev {
            if k_prev != 0.0 && k.signum() != k_prev.signum() {
                if let Some(r) = bisect(a_prev, k_prev, a3, &curvature) {
                    roots.push(r);
                }
            }
        }
        prev = Some((a3, k));
    }
    roots
}

/// Bisection of κ(1) on [lo, hi] (κ(1)(lo) = `k_lo`, of the other sign at hi).
fn bisect(
    mut lo: f64,
    k_lo: f64,
    mut hi: f64,
    curvature: &impl Fn(f64) -> Option<f64>,
) -> Option<f64> {
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let k = curvature(mid)?;
        if k.signum() == k_lo.signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The (base, tip) angles of the weightless clamped rods the search starts from, most
/// promising first: a clamped end keeps its own angle, a pinned end tries the chord's
/// direction χ plus k π/4; first come the angles symmetric about the chord (θ0 + θ1 = 2χ: with
/// both ends pinned every such pair, as the weightless pinned–pinned elastica is symmetric
/// about its chord; with one end pinned the arc of a circle, the nearly taut rod's).
fn angle_pairs(ends: HeldEnds, target: &PlanarPose) -> Vec<(f64, f64)> {
    let chord = target.y.atan2(target.x);
    let turned = |k: usize| crate::wrap_angle(chord + FRAC_PI_4 * k as f64);
    let around = |condition: EndCondition, own: f64| -> Vec<f64> {
        if condition == EndCondition::Clamped {
            vec![own]
        } else {
            (0..ANGLES).map(turned).collect()
        }
    };
    let mut pairs = Vec::new();
    match (ends.base(), ends.tip()) {
        (EndCondition::Pinned, EndCondition::Pinned) => {
            pairs.extend((0..ANGLES).map(|k| (turned(k), 2.0 * chord - turned(k))));
        }
        // The arc of a circle through the target: the nearly taut rod's tip angle.
        (EndCondition::Clamped, EndCondition::Pinned) => pairs.push((0.0, 2.0 * chord)),
        (EndCondition::Pinned, EndCondition::Clamped) => {
            pairs.push((2.0 * chord - target.theta, target.theta))
        }
        _ => {}
    }
    for theta0 in around(ends.base(), 0.0) {
        for theta1 in around(ends.tip(), target.theta) {
            if !pairs.contains(&(theta0, theta1)) {
                pairs.push((theta0, theta1));
            }
        }
    }
    pairs
}

/// The weightless rods (a in the base gripper's frame) from the base at angle `theta0` to
/// `target` at tip angle `theta1`: the closed forms' stable solutions (`robust_all` and
/// `robust`, within [`WEIGHTLESS_DEADLINE`]) in the frame turned by `theta0`.
fn weightless_rods(
    theta0: f64,
    theta1: f64,
    target: &PlanarPose,
    options: &SolveOptions,
) -> Vec<PlanarParams> {
    let opts = SolveOptions {
        initial_guess: None,
        deadline: WEIGHTLESS_DEADLINE.min(options.deadline),
        ..*options
    };
    let (s, c) = theta0.sin_cos();
    let local = PlanarPose::new(
        c * target.x + s * target.y,
        -s * target.x + c * target.y,
        crate::wrap_angle(theta1 - theta0),
    );
    let _deadline = crate::deadline::scope(opts.deadline);
    let mut found = PlanarClosedForm.robust_all(&local, &opts).solutions;
    found.extend(PlanarClosedForm.robust(&local, &opts).ok());
    // The force turned back into the base gripper's frame.
    found
        .into_iter()
        .map(|sol| {
            let a = sol.a;
            PlanarParams::new(a[0], c * a[1] - s * a[2], s * a[1] + c * a[2])
        })
        .collect()
}
