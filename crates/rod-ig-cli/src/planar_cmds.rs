//! `rod-ig forward`, `rod-ig solve` and `rod-ig shape`: JSON in, JSON out, no math here.

use crate::answer::answer;
use crate::jsonl::{self, Knobs, MethodName, ObjectiveName};
use rod_ig_core::planar::ig::{self, SolveOptions};
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::{planar, PlanarParams, PlanarPose};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::io::Write;

/// One `rod-ig forward` request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ForwardRequest {
    a: [f64; 3],
}

/// One `rod-ig forward` answer (the CLI contract of issue #2, plus the stability margin).
#[derive(Serialize)]
struct ForwardAnswer {
    tip: PlanarPose,
    /// Rows x, y, θ; columns a3, a4, a5.
    jacobian: [[f64; 3]; 3],
    stable: bool,
    energy: f64,
    /// Normalised g_min of FINDINGS §5 (≈ 1 for a gently bent rod).
    stability_margin: f64,
    /// The margin is within its rounding-error bound: the verdict is undecided (`stable` is
    /// false then). Always true for the exactly straight rod.
    stability_uncertain: bool,
}

fn rows(j: &rod_ig_core::PlanarJacobian) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| j[(r, c)]))
}

/// Answers one `forward` line.
pub fn forward_line(line: &str) -> Result<Value, String> {
    let request: ForwardRequest = jsonl::parse(line)?;
    let a = PlanarParams::from(request.a);
    let e = planar::evaluate(&a).map_err(|e| e.to_string())?;
    jsonl::to_value(&ForwardAnswer {
        tip: e.tip,
        jacobian: rows(&e.jacobian),
        stable: e.stability.stable,
        energy: e.energy,
        stability_margin: e.stability.margin,
        stability_uncertain: e.stability.uncertain,
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
    #[serde(default)]
    objective: ObjectiveName,
    /// When true, also list every distinct stable solution found (`solutions`).
    #[serde(default)]
    all: bool,
    /// Wall-time budget of the request in ms (default 250, at most 10000).
    deadline_ms: Option<f64>,
}

/// Answers one `solve` line (`verbose`: the solver's events on stderr).
pub fn solve_line(line: &str, verbose: bool) -> Result<Value, String> {
    let request: SolveRequest = jsonl::parse(line)?;
    let knobs = Knobs {
        method: request.method,
        objective: request.objective,
        alpha: request.alpha,
        max_iterations: request.max_iterations,
        tolerance: request.tolerance,
        deadline_ms: request.deadline_ms,
        a0: request.a0.map(PlanarParams::from),
    };
    let options = jsonl::solve_options(knobs, SolveOptions::default())?;
    jsonl::to_value(&answer(
        &PlanarClosedForm,
        &request.target,
        &options,
        request.all,
        verbose,
        |a| [a[0], a[1], a[2]],
        |tip| *tip,
    ))
}

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

/// Samples the rod `a` at `samples` points from the base to the tip.
pub fn sample_shape(a: [f64; 3], samples: usize) -> Result<Vec<PlanarPose>, String> {
    check_samples(samples)?;
    let rod = planar::PlanarRod::new(&PlanarParams::from(a)).map_err(|e| e.to_string())?;
    Ok(rod.shape(samples))
}

/// Writes the rod `a` as one JSON line {"a": [..], "poses": [{"x", "y", "theta"}, ..]} with
/// `samples` poses from the base to the tip, each written as it is computed (the same poses
/// as [`planar::PlanarRod::shape`], in memory independent of `samples`).
pub fn write_shape_line(out: &mut impl Write, a: [f64; 3], samples: usize) -> Result<(), String> {
    check_samples(samples)?;
    let rod = planar::PlanarRod::new(&PlanarParams::from(a)).map_err(|e| e.to_string())?;
    let io = |e: std::io::Error| e.to_string();
    write!(out, "{{\"a\":").map_err(io)?;
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
    out.write_all(b"]}\n").map_err(io)
}

/// Every distinct stable solution found for the target (x, y, θ), least energy first.
pub fn all_stable_solutions(x: f64, y: f64, theta: f64) -> Result<Vec<[f64; 3]>, String> {
    let target = PlanarPose::new(x, y, theta);
    // A one-shot drawing: build the atlas first rather than charge it to the search's deadline.
    ig::warm_up();
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
pub fn drawn_rod(a: [f64; 3], poses: Vec<PlanarPose>) -> crate::svg::DrawnRod {
    let params = PlanarParams::from(a);
    let (energy, stable) = match planar::evaluate(&params) {
        Ok(e) => (e.energy, e.stability.stable),
        Err(_) => (f64::NAN, false),
    };
    crate::svg::DrawnRod {
        poses,
        label: format!(
            "a = ({:.3}, {:.3}, {:.3})   energy {:.3}   {}",
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
    }
}
