//! The crate's error type for evaluation of the rod maps.

use thiserror::Error;

/// Why a rod quantity could not be evaluated.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum RodError {
    /// An input was NaN or infinite.
    #[error("input {name}[{index}] is not finite ({value})")]
    NonFinite {
        /// Which input (e.g. "a", "t").
        name: &'static str,
        /// Index of the component within that input.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// An argument is outside its domain (e.g. t outside [0, 1], zero samples).
    #[error("{0}")]
    OutOfDomain(String),
    /// Intermediate values overflowed (inputs far too large for f64 arithmetic).
    #[error("numerical overflow: {0}")]
    Overflow(String),
    /// A numerical integration did not reach its tolerance within its step budget.
    #[error("integration failed: {0}")]
    Integration(String),
    /// The deadline in force ([`crate::deadline`]) passed during the evaluation, which was
    /// abandoned at arc length `t`.
    #[error("deadline passed at t = {t}: evaluation abandoned")]
    Deadline {
        /// Arc length reached.
        t: f64,
    },
}

impl RodError {
    /// Checks that every component of `values` is finite.
    pub fn check_finite(name: &'static str, values: &[f64]) -> Result<(), RodError> {
        match values.iter().position(|v| !v.is_finite()) {
            Some(index) => Err(RodError::NonFinite {
                name,
                index,
                value: values[index],
            }),
            None => Ok(()),
        }
    }
}
