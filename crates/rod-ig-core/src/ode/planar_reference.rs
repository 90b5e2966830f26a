//! Numerical reference for the planar rod: the ODE of the paper's eq. (2.9) with the planar
//! kinematics, integrated with DOP853, plus its variational equations.
//!
//! State s = (μ3, μ4, μ5, θ, x, y), s(0) = (a3, a4, a5, 0, 0, 0):
//! μ3' = −μ5, μ4' = μ3 μ5, μ5' = −μ3 μ4 (eq. 2.9), θ' = μ3 (κ = μ3, unit stiffness),
//! x' = cos θ, y' = sin θ.
//!
//! Variational equations: Φ(t) = ∂s(t)/∂a satisfies Φ' = (∂f/∂s) Φ, Φ(0) = [I₃; 0], and
//! J(t, a) = ∂(x, y, θ)(t)/∂(a3, a4, a5) is read from its rows x, y, θ (rows ordered as
//! [`PlanarPose`]; the shared oracle file orders them θ, x, y).
//!
//! Stability (Bretl & McCarthy 2014; docs/math.md §5): stable ⇔ det J(t) > 0 at every t of
//! the grid {i/2000} ∪ geomspace(1e-3, 0.05, 60), integrated at rtol 1e-12, atol 1e-30.

use super::dop853::{solve, solve_dense};
use super::rk4::{rk4_solve, rk4_solve_with, steps_for};
use super::OdeOptions;
use crate::conjugate::Stream;
use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};
use std::ops::ControlFlow;

/// Step budget of the adaptive reference integrations.
pub const MAX_STEPS: u32 = 200_000;
/// Relative tolerance of [`stability`] (docs/math.md §5).
pub const STABILITY_RTOL: f64 = 1e-12;
/// Absolute tolerance of [`stability`] (docs/math.md §5): tiny, so that the early entries of J,
/// which scale like t…t⁵, are controlled relatively.
pub const STABILITY_ATOL: f64 = 1e-30;
/// Smallest t at which the fixed-step [`rk4_stability`] tests det J (docs/math.md §5: absolute
/// rounding swamps det J below t ≈ 0.02).
pub const RK4_STABILITY_T_MIN: f64 = crate::STABILITY_T_MIN;
/// Smallest t entering the normalised margin `det_min` ([`crate::STABILITY_MARGIN_T_MIN`]).
pub const MARGIN_T_MIN: f64 = crate::STABILITY_MARGIN_T_MIN;

/// Planar rod right-hand side (eq. 2.9 + kinematics) on s = (μ3, μ4, μ5, θ, x, y).
#[inline(always)]
fn rod_rhs(s: &[f64], ds: &mut [f64]) {
    let (m3, m4, m5, th) = (s[0], s[1], s[2], s[3]);
    ds[0] = -m5;
    ds[1] = m3 * m5;
    ds[2] = -m3 * m4;
    ds[3] = m3;
    let (sn, cs) = th.sin_cos();
    ds[4] = cs;
    ds[5] = sn;
}

/// Rod + variational equations: s (6) followed by the three columns of Φ (6 each).
#[inline(always)]
fn var_rhs(s: &[f64; 24], ds: &mut [f64; 24]) {
    rod_rhs(&s[..6], &mut ds[..6]);
    let (m3, m4, m5, th) = (s[0], s[1], s[2], s[3]);
    let (sn, cs) = th.sin_cos();
    for j in 0..3 {
        let o = 6 + 6 * j;
        let (d3, d4, d5, dth) = (s[o], s[o + 1], s[o + 2], s[o + 3]);
        ds[o] = -d5;
        ds[o + 1] = m5 * d3 + m3 * d5;
        ds[o + 2] = -m4 * d3 - m3 * d4;
        ds[o + 3] = d3;
        ds[o + 4] = -sn * dth;
        ds[o + 5] = cs * dth;
    }
}

fn check_params(a: &PlanarParams) -> Result<(), RodError> {
    RodError::check_finite("a", a.as_slice())
}

fn check_t(t: f64) -> Result<(), RodError> {
    RodError::check_finite("t", &[t])?;
    if !(0.0..=1.0).contains(&t) {
        return Err(RodError::OutOfDomain(format!("t = {t} is outside [0, 1]")));
    }
    Ok(())
}

fn options(rtol: f64) -> Result<OdeOptions, RodError> {
    if !(rtol.is_finite() && rtol > 0.0) {
        return Err(RodError::OutOfDomain(format!(
            "rtol must be finite and > 0 (got {rtol})"
        )));
    }
    Ok(OdeOptions {
        rtol,
        atol: rtol * 1e-3,
        max_steps: MAX_STEPS,
        initial_step: None,
        max_step: f64::INFINITY,
        error_components: usize::MAX,
    })
}

fn initial_var(a: &PlanarParams) -> [f64; 24] {
    let mut s = [0.0; 24];
    s[0] = a[0];
    s[1] = a[1];
    s[2] = a[2];
    for j in 0..3 {
        s[6 + 6 * j + j] = 1.0;
    }
    s
}

fn pose_of(s: &[f64]) -> PlanarPose {
    PlanarPose::new(s[4], s[5], s[3])
}

/// J(t) = ∂(x, y, θ)/∂(a3, a4, a5) read from the variational state.
fn jac_of(s: &[f64; 24]) -> PlanarJacobian {
    let mut j = PlanarJacobian::zeros();
    for c in 0..3 {
        let o = 6 + 6 * c;
        j[(0, c)] = s[o + 4];
        j[(1, c)] = s[o + 5];
        j[(2, c)] = s[o + 3];
    }
    j
}

fn finite_or_overflow(v: &[f64]) -> Result<(), RodError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(RodError::Overflow("non-finite rod state".into()))
    }
}

/// Tip pose q(1) and J(1, a), by DOP853 at relative tolerance `rtol` (atol = 1e-3·rtol) on the
/// rod ODE and its variational equations (module docs).
pub fn tip_and_jacobian(
    a: &PlanarParams,
    rtol: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jacobian(a, 1.0, rtol)
}

/// Tip pose q(1) and J(1, a) with a pure relative tolerance (atol = 1e-300), as the oracle's
/// reference integration (data/oracle/README.md): tiny a give tiny entries of J (O(|a|²)),
/// which an absolute tolerance would not resolve.
pub fn tip_and_jacobian_relative(
    a: &PlanarParams,
    rtol: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    check_params(a)?;
    let mut opts = options(rtol)?;
    opts.atol = PURE_RELATIVE_ATOL;
    let (s, _) = solve(|_, s, ds| var_rhs(s, ds), 0.0, initial_var(a), 1.0, &opts)?;
    finite_or_overflow(&s)?;
    Ok((pose_of(&s), jac_of(&s)))
}

/// Absolute tolerance of the pure-relative integrations (the smallest normal f64 order).
const PURE_RELATIVE_ATOL: f64 = 1e-300;

/// Pose q(t) and J(t, a) for t ∈ [0, 1], by DOP853 at relative tolerance `rtol`.
pub fn pose_and_jacobian(
    a: &PlanarParams,
    t: f64,
    rtol: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    check_params(a)?;
    check_t(t)?;
    let opts = options(rtol)?;
    let s0 = initial_var(a);
    if t == 0.0 {
        return Ok((pose_of(&s0), jac_of(&s0)));
    }
    let (s, _) = solve(|_, s, ds| var_rhs(s, ds), 0.0, s0, t, &opts)?;
    finite_or_overflow(&s)?;
    Ok((pose_of(&s), jac_of(&s)))
}

/// Poses q(tᵢ) at the given t ∈ [0, 1] (any order), by one DOP853 pass with dense output at
/// relative tolerance `rtol`. The result is in the order of `ts`.
pub fn shape(a: &PlanarParams, ts: &[f64], rtol: f64) -> Result<Vec<PlanarPose>, RodError> {
    check_params(a)?;
    for &t in ts {
        check_t(t)?;
    }
    let opts = options(rtol)?;
    let mut order: Vec<usize> = (0..ts.len()).collect();
    order.sort_by(|&i, &j| ts[i].total_cmp(&ts[j]));
    let sorted: Vec<f64> = order.iter().map(|&i| ts[i]).collect();
    let mut out = vec![PlanarPose::default(); ts.len()];
    let y0 = [a[0], a[1], a[2], 0.0, 0.0, 0.0];
    solve_dense(
        |_, s: &[f64; 6], ds: &mut [f64; 6]| rod_rhs(s, ds),
        0.0,
        y0,
        &sorted,
        &opts,
        |k, _, s| {
            out[order[k]] = pose_of(s);
            ControlFlow::Continue(())
        },
    )?;
    for p in &out {
        if !p.is_finite() {
            return Err(RodError::Overflow("non-finite rod state".into()));
        }
    }
    Ok(out)
}

/// Elastic energy ½∫₀¹ κ² dt (κ = μ3), integrated as an extra quadrature state at relative
/// tolerance `rtol`. (docs/math.md §1: it equals λ2/2 − a4 x(1) − a5 y(1).)
pub fn energy(a: &PlanarParams, rtol: f64) -> Result<f64, RodError> {
    check_params(a)?;
    let opts = options(rtol)?;
    let y0 = [a[0], a[1], a[2], 0.0, 0.0, 0.0, 0.0];
    let (s, _) = solve(
        |_, s: &[f64; 7], ds: &mut [f64; 7]| {
            rod_rhs(&s[..6], &mut ds[..6]);
            ds[6] = 0.5 * s[0] * s[0];
        },
        0.0,
        y0,
        1.0,
        &opts,
    )?;
    finite_or_overflow(&s)?;
    Ok(s[6])
}

/// The stability grid of docs/math.md §5: {i/2000, i = 1..2000} ∪ geomspace(1e-3, 0.05, 60),
/// sorted, without duplicates.
pub fn stability_grid() -> Vec<f64> {
    let mut g: Vec<f64> = (1..=2000).map(|i| i as f64 / 2000.0).collect();
    let (lo, hi) = (1e-3f64, 0.05f64);
    let ratio = (hi / lo).ln();
    for k in 0..60 {
        g.push(lo * (ratio * k as f64 / 59.0).exp());
    }
    g.sort_by(f64::total_cmp);
    g.dedup();
    g
}

/// Leading small-t term of det J (docs/math.md §5, [`crate::planar_det_leading_term`]).
pub fn det_leading_term(a: &PlanarParams, t: f64) -> f64 {
    crate::planar_det_leading_term(a[0], a[2], t)
}

fn straight_rod(a: &PlanarParams) -> Option<StabilityReport> {
    // docs/math.md §5: the x-row of J vanishes identically; det ≡ 0: undecidable.
    (a[0] == 0.0 && a[2] == 0.0).then(crate::conjugate::undecided)
}

/// Stability by the rule of docs/math.md §5: det J(t, a) > 0 at every t of [`stability_grid`],
/// with J integrated at rtol 1e-12, atol 1e-30 and read by dense output. The margin is
/// `det_min` = min over grid t ≥ 0.05 of det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) (the scan stops
/// at the first non-positive det, so for unstable rods the margin is the value there). The
/// straight rod (a3 = a5 = 0) is unstable with margin 0.
pub fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    check_params(a)?;
    if let Some(r) = straight_rod(a) {
        return Ok(r);
    }
    let opts = OdeOptions {
        rtol: STABILITY_RTOL,
        atol: STABILITY_ATOL,
        max_steps: MAX_STEPS,
        initial_step: None,
        max_step: f64::INFINITY,
        error_components: usize::MAX,
    };
    let grid = stability_grid();
    let mut scan = Stream::new();
    let mut nonfinite = false;
    solve_dense(
        |_, s, ds| var_rhs(s, ds),
        0.0,
        initial_var(a),
        &grid,
        &opts,
        |_, t, s| {
            let det = jac_of(s).determinant();
            if !det.is_finite() {
                nonfinite = true;
                return ControlFlow::Break(());
            }
            scan.sample_det(t, det, det_leading_term(a, t))
        },
    )?;
    if nonfinite {
        return Err(RodError::Overflow("non-finite Jacobian".into()));
    }
    Ok(scan.exact_report())
}

/// The paper's baseline: tip pose by classic RK4 with fixed step ≤ `dt` (n = ⌈1/dt⌉ equal
/// steps; the paper compares against dt = 1e-4).
pub fn rk4_tip(a: &PlanarParams, dt: f64) -> Result<PlanarPose, RodError> {
    check_params(a)?;
    let n = steps_for(1.0, dt)?;
    let y0 = [a[0], a[1], a[2], 0.0, 0.0, 0.0];
    let s = rk4_solve(
        |_, s: &[f64; 6], ds: &mut [f64; 6]| rod_rhs(s, ds),
        0.0,
        y0,
        1.0,
        n,
    )?;
    Ok(pose_of(&s))
}

/// The paper's baseline: tip pose and J(1, a) by classic RK4 on the rod + variational
/// equations, fixed step ≤ `dt`.
pub fn rk4_tip_and_jacobian(
    a: &PlanarParams,
    dt: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    check_params(a)?;
    let n = steps_for(1.0, dt)?;
    let s = rk4_solve(|_, s, ds| var_rhs(s, ds), 0.0, initial_var(a), 1.0, n)?;
    Ok((pose_of(&s), jac_of(&s)))
}

/// The paper's baseline stability test: RK4 with fixed step ≤ `dt` on the variational
/// equations, det J checked after every step with t ≥ 0.02 ([`RK4_STABILITY_T_MIN`]); margin
/// normalised as in [`stability`].
pub fn rk4_stability(a: &PlanarParams, dt: f64) -> Result<StabilityReport, RodError> {
    check_params(a)?;
    let n = steps_for(1.0, dt)?;
    if let Some(r) = straight_rod(a) {
        return Ok(r);
    }
    let mut scan = Stream::new();
    let mut f = |_: f64, s: &[f64; 24], ds: &mut [f64; 24]| var_rhs(s, ds);
    rk4_solve_with(&mut f, 0.0, initial_var(a), 1.0, n, |_, t, s| {
        if t < RK4_STABILITY_T_MIN {
            return ControlFlow::Continue(());
        }
        scan.sample_det(t, jac_of(s).determinant(), det_leading_term(a, t))
    })?;
    Ok(scan.exact_report())
}
