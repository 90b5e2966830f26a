//! `rod-ig forward`, `rod-ig solve` and `rod-ig shape`: JSON in, JSON out, no math here.

use crate::answer::answer;
use crate::jsonl::{self, Knobs, MethodName, ObjectiveName};
use rod_ig_core::planar::heavy::{self, Gravity, HeavyPlanar};
use rod_ig_core::planar::ig::{self, SolveOptions};
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::wrench::PlanarWrench;
use rod_ig_core::{planar, PlanarParams, PlanarPose};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::io::Write;

/// One `rod-ig forward` request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ForwardRequest {
    a: [f64; 3],
    /// Dimensionless weight w = ρgAL³/EI (default 0: the weightless rod).
    weight: Option<f64>,
    /// Direction of gravity in the base frame (default [0, -1]).
    gravity: Option<[f64; 2]>,
    /// "clamped" (the default) here; `held_cmds::forward_line` answers "pinned" and "free".
    #[allow(dead_code)] // read by `held_cmds::forward_line`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `held_cmds::forward_line`
    tip_condition: Option<Value>,
}

/// The gravity of a request: `weight` (default 0) along `gravity` (default −y, normalised).
pub fn gravity_of(weight: Option<f64>, gravity: Option<[f64; 2]>) -> Result<Gravity, String> {
    Gravity::new(weight.unwrap_or(0.0), gravity.unwrap_or([0.0, -1.0])).map_err(|e| e.to_string())
}

/// One `rod-ig forward` answer (the CLI contract of issue #2, plus the stability margin).
#[derive(Serialize)]
struct ForwardAnswer {
    tip: PlanarPose,
    /// Rows x, y, θ; columns a3, a4, a5.
    jacobian: [[f64; 3]; 3],
    stable: bool,
    energy: f64,
    /// Normalised g_min of docs/math.md §5 (≈ 1 for a gently bent rod).
    stability_margin: f64,
    /// The margin is within its rounding-error bound: the verdict is undecided (`stable` is
    /// false then). Always true for the exactly straight rod.
    stability_uncertain: bool,
    /// With weight: the elastic part of `energy` (which is elastic + gravitational).
    #[serde(skip_serializing_if = "Option::is_none")]
    elastic_energy: Option<f64>,
    /// With weight: the internal force at the tip, n(1) = (a4, a5) − w ĝ.
    #[serde(skip_serializing_if = "Option::is_none")]
    tip_force: Option<[f64; 2]>,
    /// With weight: ‖J(1)‖∞ · max(1, ‖a‖∞), the tip's sensitivity to a relative rounding of
    /// a (the tip is uncertain by about condition × 1.1e-16; above weight 200 and 1e9 the
    /// verdict is `stability_uncertain`).
    #[serde(skip_serializing_if = "Option::is_none")]
    condition: Option<f64>,
    /// The wrench the rod exerts on the base gripper, in the base frame (`rod_ig_core::wrench`).
    #[serde(skip_serializing_if = "Option::is_none")]
    base_wrench: Option<PlanarWrench>,
    /// The wrench the rod exerts on the tip gripper, in the tip frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    tip_wrench: Option<PlanarWrench>,
}

fn rows(j: &rod_ig_core::PlanarJacobian) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| j[(r, c)]))
}

/// Answers one `forward` line.
pub fn forward_line(line: &str) -> Result<Value, String> {
    let request: ForwardRequest = jsonl::parse(line)?;
    let a = PlanarParams::from(request.a);
    let g = gravity_of(request.weight, request.gravity)?;
    let e = heavy::evaluate(&a, &g).map_err(|e| e.to_string())?;
    // Without a `weight` field the answer is the weightless contract's, byte for byte.
    let heavy = request.weight.is_some();
    let wrenches = if g.is_weightless() {
        let k1 = rod_ig_core::wrench::weightless_tip_curvature(&a, &e.tip);
        Some(rod_ig_core::wrench::planar(&a, &e.tip, [a[1], a[2]], k1))
    } else {
        heavy::wrenches(&a, &g).ok()
    };
    jsonl::to_value(&ForwardAnswer {
        tip: e.tip,
        jacobian: rows(&e.jacobian),
        stable: e.stability.stable,
        energy: e.energy,
        stability_margin: e.stability.margin,
        stability_uncertain: e.stability.uncertain,
        elastic_energy: heavy.then_some(e.elastic_energy),
        tip_force: heavy.then(|| g.tip_force(&a)),
        condition: heavy.then_some(e.condition),
        base_wrench: wrenches.map(|w| w.base),
        tip_wrench: wrenches.map(|w| w.tip),
    })
}

/// One `rod-ig solve` request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SolveRequest {
    target: PlanarPose,
    a0: Option<[f64; 3]>,
    #[serde(default)]
    method: MethodName,
    alpha: Option<f64>,
    max_iterations: Option<u32>,
    tolerance: Option<f64>,
    /// Default: "least_energy" with weight (the hanging cable a user sees), else "first".
    objective: Option<ObjectiveName>,
    /// When true, also list every distinct stable solution found (`solutions`).
    #[serde(default)]
    all: bool,
    /// Wall-time budget of the request in ms (default 250, at most 10000).
    deadline_ms: Option<f64>,
    /// Dimensionless weight w (default 0).
    weight: Option<f64>,
    /// Direction of gravity in the base frame (default [0, -1]).
    gravity: Option<[f64; 2]>,
    /// Most full turns of the tangent an answer may make (default 0: loop-free). Applied by
    /// the long-cable search (weight > 200).
    max_turns: Option<u32>,
    /// "clamped" (the default) here; `held_cmds::solve_line` answers "pinned" and "free".
    #[allow(dead_code)] // read by `held_cmds::solve_line`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `held_cmds::solve_line`
    tip_condition: Option<Value>,
}

/// Answers one `solve` line (`verbose`: the solver's events on stderr).
pub fn solve_line(line: &str, verbose: bool) -> Result<Value, String> {
    let request: SolveRequest = jsonl::parse(line)?;
    let knobs = Knobs {
        method: request.method,
        objective: request
            .objective
            .unwrap_or(if request.weight.is_some_and(|w| w > 0.0) {
                ObjectiveName::LeastEnergy
            } else {
                ObjectiveName::First
            }),
        alpha: request.alpha,
        max_iterations: request.max_iterations,
        tolerance: request.tolerance,
        deadline_ms: request.deadline_ms,
        a0: request.a0.map(PlanarParams::from),
    };
    let mut options = jsonl::solve_options(knobs, SolveOptions::default())?;
    if let Some(turns) = request.max_turns {
        if turns > MAX_TURNS {
            return Err(format!(
                "max_turns must be in [0, {MAX_TURNS}] (got {turns})"
            ));
        }
        options.max_turns = turns;
    }
    let g = gravity_of(request.weight, request.gravity)?;
    let mut value = if g.is_weightless() {
        jsonl::to_value(&answer(
            &PlanarClosedForm,
            &request.target,
            &options,
            request.all,
            verbose,
            |a| [a[0], a[1], a[2]],
            |tip| *tip,
        ))?
    } else {
        jsonl::to_value(&answer(
            &HeavyPlanar::new(g),
            &request.target,
            &options,
            request.all,
            verbose,
            |a| [a[0], a[1], a[2]],
            |tip| *tip,
        ))?
    };
    with_rod_fields(&mut value, &g);
    Ok(value)
}

/// Adds `turns` (full turns of the tangent along the rod, on 401 samples; 0 for a loop-free
/// cable, heavy answers only) and the gripper wrenches to a planar answer and its `solutions`.
fn with_rod_fields(value: &mut Value, g: &Gravity) {
    jsonl::with_fields_of_a(value, |a| {
        let Ok([a3, a4, a5]) = <[f64; 3]>::try_from(a) else {
            return Vec::new();
        };
        let a = PlanarParams::new(a3, a4, a5);
        let mut fields = wrench_fields(&a, g);
        if !g.is_weightless() {
            if let Ok(shape) = heavy::shape(&a, g, heavy::cable::SHAPE_CHECK_SAMPLES) {
                fields.push(("turns", heavy::cable::turns_of(&shape).into()));
            }
        }
        fields
    });
}

/// `base_wrench` and `tip_wrench` of the planar rod a under g (none where they cannot be
/// evaluated).
pub fn wrench_fields(a: &PlanarParams, g: &Gravity) -> Vec<(&'static str, Value)> {
    jsonl::wrench_fields(heavy::wrenches(a, g).ok())
}

/// Largest accepted `max_turns` (a coil of 100 turns is no cable a gripper holds).
pub const MAX_TURNS: u32 = 100;

/// Most samples `shape` draws per rod: 1e6 poses are ≈ 24 MB of f64 and far beyond any screen
/// or path message; larger requests are a mistake (issue 9: 1e12 aborted, 2⁶⁴ − 1 panicked).
pub const MAX_SHAPE_SAMPLES: usize = 1_000_000;

/// Checks a `--samples` value (2 to [`MAX_SHAPE_SAMPLES`]).
pub fn check_samples(samples: usize) -> Result<(), String> {
    if (2..=MAX_SHAPE_SAMPLES).contains(&samples) {
        Ok(())
    } else {
        Err(format!(
            "--samples must be between 2 and {MAX_SHAPE_SAMPLES}, got {samples}"
        ))
    }
}

/// Samples the rod `a` under `g` at `samples` points from the base to the tip.
pub fn sample_shape(a: [f64; 3], g: &Gravity, samples: usize) -> Result<Vec<PlanarPose>, String> {
    check_samples(samples)?;
    heavy::shape(&PlanarParams::from(a), g, samples).map_err(|e| e.to_string())
}

/// The fixed text around a shape line's values (kept out of the function, whose braces the
/// layering check counts).
const SHAPE_LINE_OPEN: &[u8] = b"{\"a\":";
const SHAPE_LINE_CLOSE: &[u8] = b"]}\n";

/// Writes the rod `a` as one JSON line {"a": [..], "poses": [{"x", "y", "theta"}, ..]} with
/// `samples` poses from the base to the tip, each written as it is computed (the same poses
/// as [`planar::PlanarRod::shape`], in memory independent of `samples`).
pub fn write_shape_line(
    out: &mut impl Write,
    a: [f64; 3],
    g: &Gravity,
    samples: usize,
) -> Result<(), String> {
    check_samples(samples)?;
    if !g.is_weightless() {
        return write_heavy_shape_line(out, a, g, samples);
    }
    let rod = planar::PlanarRod::new(&PlanarParams::from(a)).map_err(|e| e.to_string())?;
    let io = |e: std::io::Error| e.to_string();
    out.write_all(SHAPE_LINE_OPEN).map_err(io)?;
    serde_json::to_writer(&mut *out, &a).map_err(|e| e.to_string())?;
    write!(out, ",\"poses\":[").map_err(io)?;
    let last = samples - 1;
    for i in 0..samples {
        let pose = if i == last {
            rod.tip()
        } else {
            rod.pose(i as f64 / last as f64)
        };
        if i > 0 {
            out.write_all(b",").map_err(io)?;
        }
        serde_json::to_writer(&mut *out, &pose).map_err(|e| e.to_string())?;
    }
    out.write_all(SHAPE_LINE_CLOSE).map_err(io)
}

/// [`write_shape_line`] for a rod with weight: its poses come from one integration (24 bytes
/// each, at most 24 MB).
fn write_heavy_shape_line(
    out: &mut impl Write,
    a: [f64; 3],
    g: &Gravity,
    samples: usize,
) -> Result<(), String> {
    #[derive(Serialize)]
    struct Line {
        a: [f64; 3],
        poses: Vec<PlanarPose>,
    }
    let poses = sample_shape(a, g, samples)?;
    serde_json::to_writer(&mut *out, &Line { a, poses }).map_err(|e| e.to_string())?;
    out.write_all(b"\n").map_err(|e| e.to_string())
}

/// Every distinct stable solution found for the target (x, y, θ) under `g`, least energy first.
pub fn all_stable_solutions(
    x: f64,
    y: f64,
    theta: f64,
    g: &Gravity,
) -> Result<Vec<[f64; 3]>, String> {
    let target = PlanarPose::new(x, y, theta);
    // A one-shot drawing: build the atlas first rather than charge it to the search's deadline.
    ig::warm_up();
    if !g.is_weightless() {
        let found = rod_ig_core::solver::solve_all(
            &HeavyPlanar::new(*g),
            &target,
            &SolveOptions::default(),
        );
        if found.is_empty() {
            return Err("no stable rod with this weight reaches the target".into());
        }
        return Ok(found.iter().map(|s| [s.a[0], s.a[1], s.a[2]]).collect());
    }
    let found = ig::solve_all(&target, &SolveOptions::default());
    if found.is_empty() {
        // Say why: the first-found search's own reason.
        return match ig::solve(&target, &SolveOptions::default()) {
            Ok(s) => Ok(vec![[s.a[0], s.a[1], s.a[2]]]),
            Err(f) => Err(format!("no stable rod reaches the target: {}", f.reason)),
        };
    }
    Ok(found.iter().map(|s| [s.a[0], s.a[1], s.a[2]]).collect())
}

/// A rod ready to draw, labelled with its parameters, energy and stability.
/// `muted`: drawn thin and grey (the weightless rods beside heavy ones).
pub fn drawn_rod(
    a: [f64; 3],
    g: &Gravity,
    poses: Vec<PlanarPose>,
    muted: bool,
) -> crate::svg::DrawnRod {
    let params = PlanarParams::from(a);
    let (energy, stable) = match heavy::evaluate(&params, g) {
        Ok(e) => (e.energy, e.stability.stable),
        Err(_) => (f64::NAN, false),
    };
    let weight = if g.is_weightless() {
        String::new()
    } else {
        format!("   weight {}", g.weight())
    };
    crate::svg::DrawnRod {
        poses,
        label: format!(
            "a = ({:.3}, {:.3}, {:.3}){weight}   energy {:.3}   {}",
            a[0],
            a[1],
            a[2],
            energy,
            if stable {
                "stable"
            } else {
                "unstable (dashed)"
            }
        ),
        dashed: !stable,
        muted,
    }
}
