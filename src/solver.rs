//! The one place where the node calls the math crate (`rod_ig_core`).
//!
//! Everything the node needs from the solver goes through [`RodSolver`]: warm-started
//! tracking of consecutive targets (`ig::Tracker`), one-off solves with per-request options
//! (`ig::solve`), and the sampled shape of the solution (`planar::PlanarRod`). Units here are
//! the solver's normalised units (unit rod length, unit bending stiffness); scaling to metres
//! happens in [`crate::convert`].

use rod_ig_core::ig::{self, Failure, Solution, SolveOptions, Tracker};
use rod_ig_core::planar::PlanarRod;
pub use rod_ig_core::{PlanarParams, PlanarPose};

use crate::params::Method;

/// Solver settings the node exposes as parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Robust or Newton.
    pub method: Method,
    /// Convergence tolerance (normalised position error and angle error).
    pub tolerance: f64,
    /// Iteration limit.
    pub max_iterations: u32,
}

/// A converged solve, normalised units.
#[derive(Clone, Debug)]
pub struct Solved {
    /// Base wrench a = (a3, a4, a5).
    pub a: PlanarParams,
    /// Tip pose reached (θ unwrapped).
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

impl From<Failure> for Failed {
    fn from(f: Failure) -> Self {
        Self {
            reason: f.reason.to_string(),
            iterations: f.iterations,
            residual: f.residual,
            last_a: f.last_a,
        }
    }
}

fn options(s: &SolverSettings, initial_guess: Option<PlanarParams>) -> SolveOptions {
    SolveOptions {
        method: match s.method {
            Method::Robust => ig::Method::Robust,
            Method::Newton => ig::Method::Newton,
        },
        tolerance: s.tolerance,
        max_iterations: s.max_iterations,
        initial_guess,
        ..SolveOptions::default()
    }
}

/// Inverse-geometry solver with warm start.
pub struct RodSolver {
    settings: SolverSettings,
    tracker: Tracker,
}

impl RodSolver {
    /// A solver with no warm start yet.
    pub fn new(settings: SolverSettings) -> Self {
        Self {
            settings,
            tracker: Tracker::new(options(&settings, None)),
        }
    }

    /// Builds the solver's tables now rather than on the first target.
    pub fn warm_up() {
        let _ = ig::warm_up();
    }

    /// Current settings.
    pub fn settings(&self) -> SolverSettings {
        self.settings
    }

    /// Changes the settings, keeping the warm start.
    pub fn set_settings(&mut self, settings: SolverSettings) {
        self.settings = settings;
        self.tracker = Tracker::new(options(&settings, self.tracker.last()));
    }

    /// Forgets the warm start.
    pub fn reset(&mut self) {
        self.tracker.reset();
    }

    /// Solves for `target` (normalised) and samples `samples` shape poses.
    ///
    /// Without `initial_guess` and `one_off` settings: warm-started from the previous solution
    /// (`ig::Tracker` for the robust method; the paper's Newton from the previous solution for
    /// `newton`), and this solution becomes the next warm start. With either: a one-off
    /// `ig::solve` that leaves the warm start untouched.
    pub fn solve(
        &mut self,
        target: &PlanarPose,
        initial_guess: Option<PlanarParams>,
        one_off: Option<SolverSettings>,
        samples: usize,
    ) -> Result<Solved, Failed> {
        let solution = if initial_guess.is_some() || one_off.is_some() {
            let s = one_off.unwrap_or(self.settings);
            ig::solve(target, &options(&s, initial_guess))?
        } else {
            match self.settings.method {
                Method::Robust => self.tracker.solve(target)?,
                Method::Newton => {
                    let s = ig::solve(target, &options(&self.settings, self.tracker.last()))?;
                    self.tracker = Tracker::new(options(&self.settings, Some(s.a)));
                    s
                }
            }
        };
        with_shape(&solution, samples)
    }
}

fn with_shape(s: &Solution, samples: usize) -> Result<Solved, Failed> {
    let rod = PlanarRod::new(&s.a).map_err(|e| Failed {
        reason: format!("cannot evaluate the solution's shape: {e}"),
        iterations: s.iterations,
        residual: s.residual,
        last_a: Some(s.a),
    })?;
    Ok(Solved {
        a: s.a,
        tip: s.tip,
        stable: s.stable,
        stability_margin: s.stability_margin,
        iterations: s.iterations,
        position_error: s.position_error,
        orientation_error: s.orientation_error,
        residual: s.residual,
        energy: s.energy,
        shape: rod.shape(samples),
    })
}
