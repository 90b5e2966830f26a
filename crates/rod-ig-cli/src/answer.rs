//! The answer line of `solve` and `solve3d` (the CLI contract of issue #3 and its 3-D twin):
//! one shape for both, generic over how a and the tip are written.

use serde::Serialize;

/// One solve answer. On failure `a`, `tip` and `energy` are null and `reason` says why.
#[derive(Serialize)]
pub struct SolveAnswer<A, T> {
    success: bool,
    a: Option<A>,
    tip: Option<T>,
    stable: bool,
    iterations: u32,
    residual: f64,
    energy: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    position_error: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    orientation_error: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    stability_margin: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
    /// Every distinct stable solution found (`solve` with `"all": true`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solutions: Option<Vec<SolveAnswer<A, T>>>,
}

/// The numbers of a converged solve, as both solvers report them.
pub struct Converged<A, T> {
    /// Rod parameters a*.
    pub a: A,
    /// Tip reached.
    pub tip: T,
    /// Stability verdict of a*.
    pub stable: bool,
    /// Iterations used.
    pub iterations: u32,
    /// Solver residual.
    pub residual: f64,
    /// Elastic energy.
    pub energy: f64,
    /// Position error.
    pub position_error: f64,
    /// Orientation error (rad).
    pub orientation_error: f64,
    /// Stability margin.
    pub stability_margin: f64,
}

impl<A, T> SolveAnswer<A, T> {
    /// A successful answer.
    pub fn success(c: Converged<A, T>) -> Self {
        SolveAnswer {
            success: true,
            a: Some(c.a),
            tip: Some(c.tip),
            stable: c.stable,
            iterations: c.iterations,
            residual: c.residual,
            energy: Some(c.energy),
            position_error: Some(c.position_error),
            orientation_error: Some(c.orientation_error),
            stability_margin: Some(c.stability_margin),
            reason: None,
            solutions: None,
        }
    }

    /// A failed answer: work done and why.
    pub fn failure(iterations: u32, residual: f64, reason: String) -> Self {
        SolveAnswer {
            success: false,
            a: None,
            tip: None,
            stable: false,
            iterations,
            residual,
            energy: None,
            position_error: None,
            orientation_error: None,
            stability_margin: None,
            reason: Some(reason),
            solutions: None,
        }
    }
}
