//! The classic fixed-step 4th-order Runge–Kutta method (Kutta 1901):
//! k₁ = f(t, y), k₂ = f(t + h/2, y + h k₁/2), k₃ = f(t + h/2, y + h k₂/2), k₄ = f(t + h, y + h k₃),
//! y ← y + h (k₁ + 2k₂ + 2k₃ + k₄)/6. Global error O(h⁴).

use super::OdeError;
use std::ops::ControlFlow;

/// Largest number of steps accepted by [`rk4_solve`] (a budget, not a tolerance).
pub const RK4_MAX_STEPS: u64 = 100_000_000;

/// One classic RK4 step of size `h` from (t, y).
#[inline]
pub fn rk4_step<const N: usize, F>(f: &mut F, t: f64, y: &[f64; N], h: f64) -> [f64; N]
where
    F: FnMut(f64, &[f64; N], &mut [f64; N]),
{
    let mut k1 = [0.0; N];
    let mut k2 = [0.0; N];
    let mut k3 = [0.0; N];
    let mut k4 = [0.0; N];
    f(t, y, &mut k1);
    let y2: [f64; N] = std::array::from_fn(|i| y[i] + 0.5 * h * k1[i]);
    f(t + 0.5 * h, &y2, &mut k2);
    let y3: [f64; N] = std::array::from_fn(|i| y[i] + 0.5 * h * k2[i]);
    f(t + 0.5 * h, &y3, &mut k3);
    let y4: [f64; N] = std::array::from_fn(|i| y[i] + h * k3[i]);
    f(t + h, &y4, &mut k4);
    std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// Integrates from t0 to t1 in `n_steps` equal RK4 steps and returns y(t1).
pub fn rk4_solve<const N: usize, F>(
    mut f: F,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    n_steps: u64,
) -> Result<[f64; N], OdeError>
where
    F: FnMut(f64, &[f64; N], &mut [f64; N]),
{
    let mut y = y0;
    rk4_solve_with(&mut f, t0, y0, t1, n_steps, |_, _, s| {
        y = *s;
        ControlFlow::Continue(())
    })?;
    Ok(y)
}

/// Integrates from t0 to t1 in `n_steps` equal RK4 steps, calling `observer(i, tᵢ, yᵢ)` after
/// every step i = 1..=n_steps (tᵢ = t0 + i h, the last one exactly t1). The observer may stop
/// the integration early with `ControlFlow::Break`. Errors on non-finite input, zero or more
/// than [`RK4_MAX_STEPS`] steps, or a non-finite state.
pub fn rk4_solve_with<const N: usize, F, O>(
    f: &mut F,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    n_steps: u64,
    mut observer: O,
) -> Result<[f64; N], OdeError>
where
    F: FnMut(f64, &[f64; N], &mut [f64; N]),
    O: FnMut(u64, f64, &[f64; N]) -> ControlFlow<()>,
{
    if !t0.is_finite() || !t1.is_finite() {
        return Err(OdeError::InvalidInput("non-finite time bounds".into()));
    }
    if n_steps == 0 || n_steps > RK4_MAX_STEPS {
        return Err(OdeError::InvalidInput(format!(
            "RK4 step count must be in 1..={RK4_MAX_STEPS} (got {n_steps})"
        )));
    }
    if y0.iter().any(|v| !v.is_finite()) {
        return Err(OdeError::NonFinite { t: t0 });
    }
    let h = (t1 - t0) / n_steps as f64;
    let mut y = y0;
    for i in 1..=n_steps {
        let t = t0 + (i - 1) as f64 * h;
        y = rk4_step(f, t, &y, h);
        let ti = if i == n_steps { t1 } else { t0 + i as f64 * h };
        if y.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t: ti });
        }
        if observer(i, ti, &y).is_break() {
            break;
        }
    }
    Ok(y)
}

/// Number of equal steps of size ≤ `dt` covering an interval of length `span`.
pub(crate) fn steps_for(span: f64, dt: f64) -> Result<u64, OdeError> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(OdeError::InvalidInput(format!(
            "dt must be finite and > 0 (got {dt})"
        )));
    }
    let n = (span.abs() / dt).ceil();
    if !(n <= RK4_MAX_STEPS as f64) {
        return Err(OdeError::InvalidInput(format!(
            "dt = {dt} needs more than {RK4_MAX_STEPS} steps"
        )));
    }
    Ok((n as u64).max(1))
}
