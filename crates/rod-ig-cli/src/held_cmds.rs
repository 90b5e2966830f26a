//! `rod-ig solve` with pinned or free ends (`base_condition`, `tip_condition`): JSON in, JSON
//! out; the search is `rod_ig_core::planar::heavy::held`.

use crate::jsonl::{self, ObjectiveName};
use crate::planar_cmds::{gravity_of, MAX_TURNS};
use rod_ig_core::ends::{EndCondition, HeldEnds};
use rod_ig_core::planar::heavy::held::{self, HeldSolution};
use rod_ig_core::planar::ig::SolveOptions;
use rod_ig_core::wrench::PlanarWrench;
use rod_ig_core::PlanarPose;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::time::{Duration, Instant};

/// Default time budget of a request with held ends (its search tries more starts).
pub const DEFAULT_HELD_DEADLINE: Duration = Duration::from_millis(1000);

/// Answers one `solve` line: with a pinned or free end here, else the clamped solver
/// ([`crate::planar_cmds::solve_line`], `verbose`: its events on stderr).
pub fn solve_line(line: &str, verbose: bool) -> Result<Value, String> {
    let value: Value = jsonl::parse(line)?;
    match held_ends_of(&value)? {
        Some(ends) => solve_held(line, ends),
        None => crate::planar_cmds::solve_line(line, verbose),
    }
}

/// Answers one `forward` line: with a pinned or free end here ([`forward_held`]), else the
/// clamped rod's ([`crate::planar_cmds::forward_line`]).
pub fn forward_line(line: &str) -> Result<Value, String> {
    let value: Value = jsonl::parse(line)?;
    match held_ends_of(&value)? {
        Some(ends) => forward_held(line, ends),
        None => crate::planar_cmds::forward_line(line),
    }
}

/// One `forward` request with held ends.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeldForwardRequest {
    /// (a3, a4, a5): a3 = 0 for a pinned base; (a4, a5) = w ĝ + tip_load for a free tip.
    a: [f64; 3],
    /// θ(0) of a pinned base (default 0).
    base_angle: Option<f64>,
    #[allow(dead_code)] // read by `held_ends_of`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `held_ends_of`
    tip_condition: Option<Value>,
    weight: Option<f64>,
    gravity: Option<[f64; 2]>,
    tip_load: Option<[f64; 2]>,
}

/// One `forward` answer with held ends: the clamped answer's fields, the margin and verdict
/// those of the second variation with the natural conditions.
#[derive(Serialize)]
struct HeldForwardAnswer {
    tip: PlanarPose,
    /// Rows x, y, θ; columns a3 (θ(0) for a pinned base), a4, a5.
    jacobian: [[f64; 3]; 3],
    stable: bool,
    energy: f64,
    elastic_energy: f64,
    /// μ / μ₀ of the second variation with the natural conditions.
    stability_margin: f64,
    stability_uncertain: bool,
    /// ‖J‖∞ · max(1, ‖a‖∞) (with weight above 200 and beyond 1e9: uncertain).
    condition: f64,
    base_angle: f64,
    turns: u32,
    self_intersects: bool,
    base_wrench: PlanarWrench,
    tip_wrench: PlanarWrench,
    base_condition: EndCondition,
    tip_condition: EndCondition,
}

/// Answers one `forward` line whose ends are `ends` (not both clamped).
pub fn forward_held(line: &str, ends: HeldEnds) -> Result<Value, String> {
    let request: HeldForwardRequest = jsonl::parse(line)?;
    let g = gravity_of(request.weight, request.gravity)?;
    let a = rod_ig_core::PlanarParams::from(request.a);
    let e = held::evaluate(
        request.base_angle.unwrap_or(0.0),
        &a,
        &g,
        ends,
        request.tip_load.unwrap_or([0.0; 2]),
    )
    .map_err(|e| e.to_string())?;
    let s = &e.solution;
    let w = s.wrenches();
    jsonl::to_value(&HeldForwardAnswer {
        tip: s.tip,
        jacobian: std::array::from_fn(|r| std::array::from_fn(|c| e.jacobian[(r, c)])),
        stable: e.stable(),
        energy: s.energy,
        elastic_energy: s.elastic_energy,
        stability_margin: s.stability.normalised(),
        stability_uncertain: e.uncertain(),
        condition: e.condition,
        base_angle: s.base_angle,
        turns: s.turns,
        self_intersects: s.self_intersects,
        base_wrench: w.base,
        tip_wrench: w.tip,
        base_condition: ends.base(),
        tip_condition: ends.tip(),
    })
}

/// The end conditions a request names, when either is not `"clamped"` (`None`: the paper's
/// rod, answered by the clamped solver exactly as before). Refusals name the field.
pub fn held_ends_of(request: &Value) -> Result<Option<HeldEnds>, String> {
    let read = |field: &'static str| -> Result<EndCondition, String> {
        match request.get(field) {
            None | Some(Value::Null) => Ok(EndCondition::Clamped),
            Some(Value::String(s)) => s.parse().map_err(|_| {
                format!("{field} must be \"clamped\", \"pinned\" or \"free\" (got {s:?})")
            }),
            Some(other) => Err(format!(
                "{field} must be \"clamped\", \"pinned\" or \"free\" (got {other})"
            )),
        }
    };
    let ends = HeldEnds::new(read("base_condition")?, read("tip_condition")?)
        .map_err(|e| e.to_string())?;
    Ok((!ends.both_clamped()).then_some(ends))
}

/// The target of a held tip: a pose (clamped tip), a position (pinned tip; a theta is
/// refused), absent for a free tip.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeldTarget {
    x: f64,
    y: f64,
    theta: Option<f64>,
}

/// One `solve` request with held ends.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeldRequest {
    target: Option<HeldTarget>,
    #[allow(dead_code)] // read by `held_ends_of`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `held_ends_of`
    tip_condition: Option<Value>,
    /// "least_energy" (the default) or "first": both answer the least-energy rod found.
    #[allow(dead_code)]
    objective: Option<ObjectiveName>,
    #[serde(default)]
    all: bool,
    deadline_ms: Option<f64>,
    weight: Option<f64>,
    gravity: Option<[f64; 2]>,
    max_turns: Option<u32>,
    /// A point force at a free tip, base frame (units of EI/L²).
    tip_load: Option<[f64; 2]>,
}

/// One rod of a held answer.
#[derive(Serialize)]
struct HeldRod {
    a: [f64; 3],
    /// θ(0), the rod's angle at a pinned base (0 for a clamped one).
    base_angle: f64,
    tip: PlanarPose,
    stable: bool,
    energy: f64,
    elastic_energy: f64,
    /// μ / μ₀ of the second variation with the natural conditions.
    stability_margin: f64,
    turns: u32,
    base_wrench: PlanarWrench,
    tip_wrench: PlanarWrench,
    /// Distance from the tip to the target's position (held tips).
    #[serde(skip_serializing_if = "Option::is_none")]
    position_error: Option<f64>,
}

/// One held answer (planar `R` = [`HeldRod`], or a 3-D rod): the least-energy rod (or why
/// none), and with `all` every stable one.
#[derive(Serialize)]
pub(crate) struct HeldAnswer<R> {
    success: bool,
    #[serde(flatten)]
    rod: Option<R>,
    base_condition: EndCondition,
    tip_condition: EndCondition,
    termination: &'static str,
    starts: u32,
    elapsed_ms: f64,
    complete: bool,
    /// Equilibria found that are not admitted (unstable, or looped beyond `max_turns`).
    rejected: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    solutions: Option<Vec<R>>,
}

impl<R> HeldAnswer<R> {
    /// The answer of a search held by `ends`: its best rod `rod` (None: it found none, and
    /// `reason` says why), with `all` the list `solutions`, `rejected` equilibria not admitted,
    /// after `starts` starts, `cut_short` by its deadline or not, begun at `started`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        ends: HeldEnds,
        rod: Option<R>,
        solutions: Option<Vec<R>>,
        rejected: usize,
        starts: u32,
        cut_short: bool,
        reason: impl FnOnce() -> String,
        started: Instant,
    ) -> Self {
        let termination = match (rod.is_some(), cut_short) {
            (true, _) => "converged",
            (false, true) => "deadline",
            (false, false) => "no_stable_solution",
        };
        HeldAnswer {
            success: rod.is_some(),
            reason: rod.is_none().then(reason),
            rod,
            base_condition: ends.base(),
            tip_condition: ends.tip(),
            termination,
            starts,
            elapsed_ms: started.elapsed().as_secs_f64() * 1e3,
            complete: !cut_short,
            rejected,
            solutions,
        }
    }
}

fn rod_of(s: &HeldSolution, target: Option<&PlanarPose>) -> HeldRod {
    let w = s.wrenches();
    HeldRod {
        a: [s.a[0], s.a[1], s.a[2]],
        base_angle: s.base_angle,
        tip: s.tip,
        stable: s.stability.stable(),
        energy: s.energy,
        elastic_energy: s.elastic_energy,
        stability_margin: s.stability.normalised(),
        turns: s.turns,
        base_wrench: w.base,
        tip_wrench: w.tip,
        position_error: target.map(|t| (s.tip.x - t.x).hypot(s.tip.y - t.y)),
    }
}

/// Answers one `solve` line whose ends are `ends` (not both clamped).
pub fn solve_held(line: &str, ends: HeldEnds) -> Result<Value, String> {
    let started = Instant::now();
    let request: HeldRequest = jsonl::parse(line)?;
    let target = target_of(ends, request.target)?;
    let options = options_of(request.deadline_ms, request.max_turns)?;
    let g = gravity_of(request.weight, request.gravity)?;
    let tip_load = request.tip_load.unwrap_or([0.0; 2]);
    let found = held::equilibria_with_tip_load(ends, &g, tip_load, target.as_ref(), &options)
        .map_err(|e| e.to_string())?;
    jsonl::to_value(&answer_of(
        ends,
        &found,
        target.as_ref(),
        request.all,
        started,
    ))
}

/// The target a request gives for a tip held by `ends` (refusals name the field).
fn target_of(ends: HeldEnds, target: Option<HeldTarget>) -> Result<Option<PlanarPose>, String> {
    match (ends.tip(), target) {
        (EndCondition::Pinned, Some(HeldTarget { theta: Some(_), .. })) => Err(
            "target: a pinned tip's target is {\"x\", \"y\"} (its angle is free: no theta)".into(),
        ),
        (EndCondition::Clamped, Some(HeldTarget { theta: None, .. })) => {
            Err("target: a clamped tip needs theta".into())
        }
        (_, t) => Ok(t.map(|t| PlanarPose::new(t.x, t.y, t.theta.unwrap_or(0.0)))),
    }
}

/// The options of a held request: `deadline_ms` (default [`DEFAULT_HELD_DEADLINE`]) and
/// `max_turns` (default 0).
fn options_of(deadline_ms: Option<f64>, max_turns: Option<u32>) -> Result<SolveOptions, String> {
    let max_turns = max_turns.unwrap_or(0);
    if max_turns > MAX_TURNS {
        return Err(format!(
            "max_turns must be in [0, {MAX_TURNS}] (got {max_turns})"
        ));
    }
    Ok(SolveOptions {
        deadline: match deadline_ms {
            Some(ms) => jsonl::deadline_from_ms(ms)?,
            None => DEFAULT_HELD_DEADLINE,
        },
        max_turns,
        ..SolveOptions::default()
    })
}

/// The answer to a held search that `found` what it found.
fn answer_of(
    ends: HeldEnds,
    found: &held::HeldSearch,
    target: Option<&PlanarPose>,
    all: bool,
    started: Instant,
) -> HeldAnswer<HeldRod> {
    HeldAnswer::new(
        ends,
        found.solutions.first().map(|s| rod_of(s, target)),
        all.then(|| found.solutions.iter().map(|s| rod_of(s, target)).collect()),
        found.equilibria.len() - found.solutions.len(),
        found.starts,
        found.cut_short,
        || held::not_found(ends, found).to_string(),
        started,
    )
}

/// A `track` stream whose grippers hold the rod by pinned or free ends: the ends of its first
/// line, the stream's gravity and the rod held.
#[derive(Default)]
pub struct HeldTrack {
    ends: Option<HeldEnds>,
    gravity: Option<rod_ig_core::planar::heavy::Gravity>,
    held: Option<HeldSolution>,
}

/// One `track` line with held ends: the same fields as `solve`'s, `weight` and `gravity`
/// carried over from the lines before.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeldTrackRequest {
    target: Option<HeldTarget>,
    #[allow(dead_code)] // read by `held_ends_of`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `held_ends_of`
    tip_condition: Option<Value>,
    deadline_ms: Option<f64>,
    weight: Option<f64>,
    gravity: Option<[f64; 2]>,
    max_turns: Option<u32>,
}

impl HeldTrack {
    /// Answers one `track` line held by `ends`: the rod held moved along its branch to the
    /// line's target (and gravity) with the event "none"; where its branch ends, a fresh search
    /// and the event "snap"; where none is found, "lost" (success false). The first line
    /// solves afresh; every line must name the first line's ends.
    pub fn line(&mut self, line: &str, ends: HeldEnds) -> Result<Value, String> {
        let started = Instant::now();
        if let Some(first) = self.ends.filter(|e| *e != ends) {
            let field = if first.base() != ends.base() {
                "base_condition"
            } else {
                "tip_condition"
            };
            return Err(format!(
                "{field}: a track stream keeps the ends of its first line ({} base, {} tip)",
                first.base().name(),
                first.tip().name()
            ));
        }
        let request: HeldTrackRequest = jsonl::parse(line)?;
        let target = target_of(ends, request.target)?;
        let options = options_of(request.deadline_ms, request.max_turns)?;
        let previous = self.gravity.unwrap_or_default();
        let g = rod_ig_core::planar::heavy::Gravity::new(
            request.weight.unwrap_or(previous.weight()),
            request.gravity.unwrap_or(previous.direction()),
        )
        .map_err(|e| e.to_string())?;
        self.ends = Some(ends);
        self.gravity = Some(g);
        let (event, found) = held::step(
            self.held.as_ref(),
            ends,
            &g,
            [0.0; 2],
            target.as_ref(),
            &options,
        )
        .map_err(|e| e.to_string())?;
        self.held = found.solutions.first().cloned();
        let mut value = jsonl::to_value(&answer_of(ends, &found, target.as_ref(), false, started))?;
        if let Some(map) = value.as_object_mut() {
            map.insert("event".into(), event.as_str().into());
        }
        Ok(value)
    }
}

/// A rod held by pinned or free ends, sampled for `rod-ig shape`.
pub struct HeldShape {
    /// Its base wrench (a3 = 0 at a pinned base).
    pub a: [f64; 3],
    /// θ(0).
    pub base_angle: f64,
    /// `samples` poses from base to tip.
    pub poses: Vec<PlanarPose>,
    /// Stable with the natural conditions (and decided).
    pub stable: bool,
    /// Total energy.
    pub energy: f64,
}

/// How `rod-ig shape` draws rods held by pinned or free ends.
pub struct HeldShapeRequest<'a> {
    /// The ends (not both clamped).
    pub ends: HeldEnds,
    /// Rods by their base wrench (`--a`), each leaving the base at `base_angle`.
    pub params: &'a [[f64; 3]],
    /// θ(0) of the `--a` rods (pinned base).
    pub base_angle: f64,
    /// A free tip's point load.
    pub tip_load: [f64; 2],
    /// `--target`: every stable equilibrium held through it (a free tip: the rod hanging from
    /// its base, any target ignored).
    pub target: Option<PlanarPose>,
    /// Samples per rod.
    pub samples: usize,
}

/// The rods of `request` under `g`, each sampled (the held forward map for `--a` rods, the
/// held-ends search's stable equilibria for `--target`).
pub fn held_shapes(
    request: &HeldShapeRequest,
    g: &rod_ig_core::planar::heavy::Gravity,
) -> Result<Vec<HeldShape>, String> {
    crate::planar_cmds::check_samples(request.samples)?;
    let shaped = |s: &HeldSolution, stable: bool| -> Result<HeldShape, String> {
        Ok(HeldShape {
            a: [s.a[0], s.a[1], s.a[2]],
            base_angle: s.base_angle,
            poses: s.cable.shape(request.samples).map_err(|e| e.to_string())?,
            stable,
            energy: s.energy,
        })
    };
    let mut out = Vec::new();
    for a in request.params {
        let a = rod_ig_core::PlanarParams::from(*a);
        let e = held::evaluate(request.base_angle, &a, g, request.ends, request.tip_load)
            .map_err(|e| e.to_string())?;
        out.push(shaped(&e.solution, e.stable())?);
    }
    let free = request.ends.tip() == EndCondition::Free;
    if request.target.is_some() || (free && request.params.is_empty()) {
        let options = SolveOptions {
            deadline: DEFAULT_HELD_DEADLINE,
            ..SolveOptions::default()
        };
        let target = request.target.filter(|_| !free);
        let found = held::equilibria_with_tip_load(
            request.ends,
            g,
            request.tip_load,
            target.as_ref(),
            &options,
        )
        .map_err(|e| e.to_string())?;
        for s in &found.solutions {
            out.push(shaped(s, true)?);
        }
    }
    Ok(out)
}
