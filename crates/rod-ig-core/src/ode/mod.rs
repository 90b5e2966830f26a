//! Numerical integration of ordinary differential equations, and the planar ODE reference.
//!
//! - [`dop853`]: adaptive Dormand–Prince 8(5,3) with step-size control on (rtol, atol), a step
//!   budget, and 7th-order dense output at requested times (Hairer, Nørsett & Wanner,
//!   *Solving ODEs I*, §II.5, §II.10).
//! - [`rk4`]: the classic fixed-step 4th-order Runge–Kutta method (the paper's baseline).
//! - [`planar_reference`]: the planar Kirchhoff rod (paper eq. 2.9 with θ' = μ3, x' = cos θ,
//!   y' = sin θ) and its variational equations, integrated numerically: the reference against
//!   which the closed forms are checked.
//!
//! States are fixed-size arrays `[f64; N]`, right-hand sides are closures
//! `FnMut(t, &y, &mut dy)`; nothing is allocated per step.

// `!(x > y)` comparisons deliberately reject NaN; index loops mirror the formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod dop853;
pub mod heavy_reference;
pub mod planar_reference;
pub mod rk4;

pub use dop853::{solve, solve_dense, DenseStep, Dop853};
pub use rk4::{rk4_solve, rk4_solve_with, rk4_step};

use crate::RodError;
use thiserror::Error;

/// Why an integration failed.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum OdeError {
    /// The step budget (`OdeOptions::max_steps` attempted steps) ran out before the end time.
    #[error("step budget exhausted after {steps} steps at t = {t}")]
    StepBudget {
        /// Attempted steps (accepted and rejected).
        steps: u32,
        /// Time reached.
        t: f64,
    },
    /// The step size fell below the resolution of t (typically a state that keeps overflowing).
    #[error("step size underflow (h = {h}) at t = {t}")]
    StepSizeUnderflow {
        /// Time reached.
        t: f64,
        /// Step size.
        h: f64,
    },
    /// The initial state or its derivative is not finite.
    #[error("non-finite state or derivative at t = {t}")]
    NonFinite {
        /// Time.
        t: f64,
    },
    /// Invalid tolerances, times or step count.
    #[error("invalid integration input: {0}")]
    InvalidInput(String),
    /// The deadline in force ([`crate::deadline`]) passed: the integration was abandoned.
    #[error("deadline passed at t = {t}")]
    Deadline {
        /// Time reached.
        t: f64,
    },
}

impl From<OdeError> for RodError {
    fn from(e: OdeError) -> Self {
        match e {
            OdeError::Deadline { t } => RodError::Deadline { t },
            e => RodError::Integration(e.to_string()),
        }
    }
}

/// Options of the adaptive integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdeOptions {
    /// Relative tolerance (> 0; values below 1e-15 are raised to 1e-15).
    pub rtol: f64,
    /// Absolute tolerance (≥ 0). The weight of component i is atol + rtol·max(|yᵢ|, |yᵢ_new|).
    pub atol: f64,
    /// Maximum number of attempted steps (accepted + rejected) before giving up.
    pub max_steps: u32,
    /// Initial step size; `None` uses Hairer's starting-step heuristic.
    pub initial_step: Option<f64>,
    /// Largest allowed step size (> 0; infinity for none).
    pub max_step: f64,
    /// Only the first `error_components` components enter the error norm (the rest, e.g.
    /// variational equations, ride along on the same steps); `usize::MAX` = all.
    pub error_components: usize,
}

impl Default for OdeOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-12,
            max_steps: 100_000,
            initial_step: None,
            max_step: f64::INFINITY,
            error_components: usize::MAX,
        }
    }
}

impl OdeOptions {
    /// Options with the given tolerances and the default budget.
    pub fn with_tolerances(rtol: f64, atol: f64) -> Self {
        Self {
            rtol,
            atol,
            ..Self::default()
        }
    }

    /// Checks the tolerances and limits; clamps rtol to ≥ 1e-15.
    pub(crate) fn validate(&self) -> Result<(), OdeError> {
        if !(self.rtol.is_finite() && self.rtol > 0.0) {
            return Err(OdeError::InvalidInput(format!(
                "rtol must be finite and > 0 (got {})",
                self.rtol
            )));
        }
        if !(self.atol.is_finite() && self.atol >= 0.0) {
            return Err(OdeError::InvalidInput(format!(
                "atol must be finite and >= 0 (got {})",
                self.atol
            )));
        }
        if self.max_step.is_nan() || self.max_step <= 0.0 {
            return Err(OdeError::InvalidInput("max_step must be > 0".into()));
        }
        Ok(())
    }

    /// The error weight of a component whose value goes from `a` to `b` over a step:
    /// atol + rtol·max(|a|, |b|).
    #[inline(always)]
    pub(crate) fn weight(&self, a: f64, b: f64) -> f64 {
        self.atol + self.rtol * a.abs().max(b.abs())
    }

    pub(crate) fn sanitized(mut self) -> Self {
        if self.rtol.is_finite() && self.rtol > 0.0 && self.rtol < 1e-15 {
            self.rtol = 1e-15;
        }
        self
    }
}

/// Work counters of an integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OdeStats {
    /// Right-hand-side evaluations.
    pub evaluations: u32,
    /// Attempted steps.
    pub attempts: u32,
    /// Accepted steps.
    pub accepted: u32,
    /// Rejected steps.
    pub rejected: u32,
}
