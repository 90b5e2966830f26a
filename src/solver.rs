//! The one place where the node calls the math crate (`rod_ig_core`).
//!
//! Everything the node needs from the solver goes through [`RodSolver`]: warm-started
//! tracking of consecutive targets, one-off solves from an explicit initial guess, and the
//! sampled shape of the solution. Units here are the solver's normalised units (unit rod
//! length, unit bending stiffness); scaling to metres happens in [`crate::convert`].

pub use rod_ig_core::{PlanarParams, PlanarPose};

use crate::params::Method;

/// Solver settings the node exposes as parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Robust or Newton.
    pub method: Method,
    /// Convergence tolerance.
    pub tolerance: f64,
    /// Iteration limit.
    pub max_iterations: u32,
}

/// A converged solve, normalised units.
#[derive(Clone, Debug)]
pub struct Solved {
    /// Base wrench a = (a3, a4, a5).
    pub a: PlanarParams,
    /// Tip pose reached.
    pub tip: PlanarPose,
    /// Stable equilibrium.
    pub stable: bool,
    /// Normalised stability margin.
    pub stability_margin: f64,
    /// Iterations used.
    pub iterations: u32,
    /// |tip − target| (normalised length).
    pub position_error: f64,
    /// Wrapped |θ_tip − θ_target| (rad).
    pub orientation_error: f64,
    /// Solver residual.
    pub residual: f64,
    /// ½∫κ² (normalised).
    pub energy: f64,
    /// `samples` poses from t = 0 to t = 1.
    pub shape: Vec<PlanarPose>,
}

/// A failed solve.
#[derive(Clone, Debug)]
pub struct Failed {
    /// Why (the solver's own message).
    pub reason: String,
    /// Iterations used.
    pub iterations: u32,
    /// Last residual.
    pub residual: f64,
    /// Last iterate, when there was one.
    pub last_a: Option<PlanarParams>,
}

/// Inverse-geometry solver with warm start (TEMPORARY placeholder: see `solve`).
pub struct RodSolver {
    settings: SolverSettings,
    previous: Option<PlanarParams>,
}

impl RodSolver {
    /// A solver with no warm start yet.
    pub fn new(settings: SolverSettings) -> Self {
        Self {
            settings,
            previous: None,
        }
    }

    /// Current settings.
    pub fn settings(&self) -> SolverSettings {
        self.settings
    }

    /// Changes the settings (keeps the warm start).
    pub fn set_settings(&mut self, settings: SolverSettings) {
        self.settings = settings;
    }

    /// Forgets the warm start.
    pub fn reset(&mut self) {
        self.previous = None;
    }

    /// Solves for `target` (normalised), warm-starting from the previous solution and keeping
    /// this one as the next warm start; or, with `initial_guess`, starting there with
    /// `settings` and leaving the warm start untouched. Samples `samples` shape poses.
    pub fn solve(
        &mut self,
        target: &PlanarPose,
        initial_guess: Option<PlanarParams>,
        settings: Option<SolverSettings>,
        samples: usize,
    ) -> Result<Solved, Failed> {
        // TEMPORARY placeholder until rod_ig_core::ig lands: a cubic Hermite curve from the
        // base to the target (not an elastica; a = 0). Replaced by ig::Tracker / ig::solve.
        let _ = (initial_guess, settings);
        if !target.is_finite() {
            return Err(Failed {
                reason: "non-finite target".into(),
                iterations: 0,
                residual: f64::NAN,
                last_a: None,
            });
        }
        let d = (target.x * target.x + target.y * target.y).sqrt();
        let (p0, p1) = ((0.0, 0.0), (target.x, target.y));
        let (m0, m1) = ((d, 0.0), (d * target.theta.cos(), d * target.theta.sin()));
        let n = samples.max(2);
        let shape = (0..n)
            .map(|i| {
                let t = i as f64 / (n - 1) as f64;
                let (h00, h10, h01, h11) = (
                    2.0 * t * t * t - 3.0 * t * t + 1.0,
                    t * t * t - 2.0 * t * t + t,
                    -2.0 * t * t * t + 3.0 * t * t,
                    t * t * t - t * t,
                );
                let (d00, d10, d01, d11) = (
                    6.0 * t * t - 6.0 * t,
                    3.0 * t * t - 4.0 * t + 1.0,
                    -6.0 * t * t + 6.0 * t,
                    3.0 * t * t - 2.0 * t,
                );
                let x = h00 * p0.0 + h10 * m0.0 + h01 * p1.0 + h11 * m1.0;
                let y = h00 * p0.1 + h10 * m0.1 + h01 * p1.1 + h11 * m1.1;
                let dx = d00 * p0.0 + d10 * m0.0 + d01 * p1.0 + d11 * m1.0;
                let dy = d00 * p0.1 + d10 * m0.1 + d01 * p1.1 + d11 * m1.1;
                let th = if i == 0 {
                    0.0
                } else if i == n - 1 {
                    target.theta
                } else {
                    dy.atan2(dx)
                };
                PlanarPose::new(x, y, th)
            })
            .collect::<Vec<_>>();
        let a = PlanarParams::zeros();
        self.previous = Some(a);
        Ok(Solved {
            a,
            tip: *target,
            stable: true,
            stability_margin: 1.0,
            iterations: 0,
            position_error: 0.0,
            orientation_error: 0.0,
            residual: 0.0,
            energy: 0.0,
            shape,
        })
    }
}
