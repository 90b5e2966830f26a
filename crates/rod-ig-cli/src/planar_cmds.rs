//! `rod-ig forward`, `rod-ig solve` and `rod-ig shape`: JSON in, JSON out, no math here.

use crate::answer::{Converged, SolveAnswer};
use crate::jsonl;
use rod_ig_core::ig::{self, Method, Objective, SolveOptions};
use rod_ig_core::{planar, PlanarParams, PlanarPose};
use serde::{Deserialize, Serialize};
use serde_json::Value;

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

/// Solver choice as spelled in requests.
#[derive(Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "snake_case")]
enum MethodName {
    #[default]
    Robust,
    Newton,
}

/// Objective as spelled in requests.
#[derive(Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "snake_case")]
enum ObjectiveName {
    #[default]
    First,
    LeastEnergy,
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
    /// Wall-time budget of the request in ms (default 50, at most 10000).
    deadline_ms: Option<f64>,
}

type PlanarAnswer = SolveAnswer<[f64; 3], PlanarPose>;

fn answer_of(s: &ig::Solution) -> PlanarAnswer {
    SolveAnswer::success(Converged {
        a: [s.a[0], s.a[1], s.a[2]],
        tip: s.tip,
        stable: s.stable,
        iterations: s.iterations,
        residual: s.residual,
        energy: s.energy,
        position_error: s.position_error,
        orientation_error: s.orientation_error,
        stability_margin: s.stability_margin,
    })
}

fn options(request: &SolveRequest) -> Result<SolveOptions, String> {
    let mut options = SolveOptions {
        method: match request.method {
            MethodName::Robust => Method::Robust,
            MethodName::Newton => Method::Newton,
        },
        objective: match request.objective {
            ObjectiveName::First => Objective::FirstFound,
            ObjectiveName::LeastEnergy => Objective::LeastEnergy,
        },
        ..SolveOptions::default()
    };
    jsonl::apply_newton_knobs(
        (request.alpha, request.max_iterations, request.tolerance),
        (
            &mut options.alpha,
            &mut options.max_iterations,
            &mut options.tolerance,
        ),
    )?;
    if let Some(ms) = request.deadline_ms {
        options.deadline = jsonl::deadline_from_ms(ms)?;
    }
    if let Some(a0) = request.a0 {
        options.initial_guess = Some(PlanarParams::from(a0));
    }
    if matches!(options.method, Method::Newton) && options.initial_guess.is_none() {
        return Err(jsonl::NEWTON_NEEDS_A0.to_string());
    }
    Ok(options)
}

/// Answers one `solve` line.
pub fn solve_line(line: &str) -> Result<Value, String> {
    let request: SolveRequest = jsonl::parse(line)?;
    let options = options(&request)?;
    let first = ig::solve(&request.target, &options);
    let mut answer = match &first {
        Ok(s) => answer_of(s),
        Err(f) => PlanarAnswer::failure(f.iterations, f.residual, f.reason.to_string()),
    };
    if request.all {
        let mut all = ig::solve_all(&request.target, &options);
        if let Ok(s) = &first {
            // The answer itself is one of the solutions (solve_all's cell search may have
            // missed the branch the first-found search reached).
            if !all
                .iter()
                .any(|o| (o.a - s.a).norm() <= 1e-6 * (1.0 + s.a.norm()))
            {
                all.push(*s);
            }
        }
        if all.is_empty() {
            answer = PlanarAnswer::failure(0, f64::INFINITY, "no stable solution found".into());
        }
        answer.solutions = Some(all.iter().map(answer_of).collect());
    }
    jsonl::to_value(&answer)
}

/// Most samples `shape` draws per rod: 1e6 poses are ≈ 24 MB of f64 and far beyond any screen
/// or path message; larger requests are a mistake (issue 9: 1e12 aborted, 2⁶⁴ − 1 panicked).
pub const MAX_SHAPE_SAMPLES: usize = 1_000_000;

/// Samples the rod `a` at `samples` points from the base to the tip.
pub fn sample_shape(a: [f64; 3], samples: usize) -> Result<Vec<PlanarPose>, String> {
    if !(2..=MAX_SHAPE_SAMPLES).contains(&samples) {
        return Err(format!(
            "--samples must be between 2 and {MAX_SHAPE_SAMPLES}, got {samples}"
        ));
    }
    let rod = planar::PlanarRod::new(&PlanarParams::from(a)).map_err(|e| e.to_string())?;
    Ok(rod.shape(samples))
}

/// Every distinct stable solution found for the target (x, y, θ), least energy first.
pub fn all_stable_solutions(x: f64, y: f64, theta: f64) -> Result<Vec<[f64; 3]>, String> {
    let target = PlanarPose::new(x, y, theta);
    let mut found = ig::solve_all(&target, &SolveOptions::default());
    if found.is_empty() {
        return match ig::solve(&target, &SolveOptions::default()) {
            Ok(s) => Ok(vec![[s.a[0], s.a[1], s.a[2]]]),
            Err(f) => Err(format!("no stable rod reaches the target: {}", f.reason)),
        };
    }
    found.sort_by(|p, q| p.energy.total_cmp(&q.energy));
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
