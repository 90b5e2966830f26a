//! Numerical reference for the planar rod with weight: DOP853 on the body-frame equations, an
//! independent formulation of [`crate::planar::heavy`] (which integrates the world-frame force
//! n(t) = n(0) − w t ĝ by Taylor series).
//!
//! State s = (μ3, μ4, μ5, θ, x, y, e, p), s(0) = (a3, a4, a5, 0, 0, 0, 0, 0), with the body-frame
//! force (μ4, μ5) = Rᵀ n and γ = Rᵀ ĝ = (cos θ g_x + sin θ g_y, −sin θ g_x + cos θ g_y):
//! μ3' = −μ5, μ4' = μ3 μ5 − w γ_x, μ5' = −μ3 μ4 − w γ_y, θ' = μ3, x' = cos θ, y' = sin θ,
//! e' = μ3²/2 (elastic energy), p' = −w ĝ · r (potential energy).
//!
//! Variational equations for J(t) = ∂(x, y, θ)/∂(a3, a4, a5): dμ3' = −dμ5,
//! dμ4' = μ5 dμ3 + μ3 dμ5 − w γ_y dθ, dμ5' = −μ4 dμ3 − μ3 dμ4 + w γ_x dθ, dθ' = dμ3,
//! dx' = −sin θ dθ, dy' = cos θ dθ.
//!
//! Stability as `shared/oracle/gravity_public.jsonl` defines it: det J(t) > 0 on the grid of
//! docs/math.md §5 ({i/2000} ∪ geomspace(1e-3, 0.05, 60)), margin = min over grid t ≥ 0.05 of
//! det J(t)/D0(t), D0(t) = t⁹(a3²/8640 + a5²t²/33600 + (w ĝ_y)²t⁴/388800).

use super::dop853::{solve, solve_dense};
use super::OdeOptions;
use crate::planar::heavy::Gravity;
use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};
use std::ops::ControlFlow;

const NS: usize = 8;
const NV: usize = NS + 18;

fn rhs(w: f64, g: [f64; 2], s: &[f64; NV], ds: &mut [f64; NV], var: bool) {
    let (m3, m4, m5, th) = (s[0], s[1], s[2], s[3]);
    let (sn, cs) = th.sin_cos();
    let gamma = [cs * g[0] + sn * g[1], -sn * g[0] + cs * g[1]];
    ds[0] = -m5;
    ds[1] = m3 * m5 - w * gamma[0];
    ds[2] = -m3 * m4 - w * gamma[1];
    ds[3] = m3;
    ds[4] = cs;
    ds[5] = sn;
    ds[6] = 0.5 * m3 * m3;
    ds[7] = -w * (g[0] * s[4] + g[1] * s[5]);
    if !var {
        return;
    }
    for j in 0..3 {
        let o = NS + 6 * j;
        let (d3, d4, d5, dth) = (s[o], s[o + 1], s[o + 2], s[o + 3]);
        ds[o] = -d5;
        ds[o + 1] = m5 * d3 + m3 * d5 - w * gamma[1] * dth;
        ds[o + 2] = -m4 * d3 - m3 * d4 + w * gamma[0] * dth;
        ds[o + 3] = d3;
        ds[o + 4] = -sn * dth;
        ds[o + 5] = cs * dth;
    }
}

fn initial(a: &PlanarParams) -> [f64; NV] {
    let mut s = [0.0; NV];
    s[..3].copy_from_slice(a.as_slice());
    for j in 0..3 {
        s[NS + 6 * j + j] = 1.0;
    }
    s
}

fn jacobian_of(s: &[f64; NV]) -> PlanarJacobian {
    let mut j = PlanarJacobian::zeros();
    for c in 0..3 {
        let o = NS + 6 * c;
        j[(0, c)] = s[o + 4];
        j[(1, c)] = s[o + 5];
        j[(2, c)] = s[o + 3];
    }
    j
}

fn opts(rtol: f64) -> OdeOptions {
    OdeOptions {
        rtol,
        atol: 1e-300,
        max_steps: 400_000,
        initial_step: None,
        max_step: f64::INFINITY,
        error_components: usize::MAX,
    }
}

/// The reference's answer for one rod.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeavyReference {
    /// q(1).
    pub tip: PlanarPose,
    /// J(1, a).
    pub jacobian: PlanarJacobian,
    /// Elastic + potential energy.
    pub energy: f64,
    /// Elastic energy.
    pub elastic_energy: f64,
    /// Verdict and margin on the grid (module docs).
    pub stability: StabilityReport,
}

/// Tip, J(1, a) and energies at relative tolerance `rtol` (pure relative: atol 1e-300).
pub fn tip_and_jacobian(
    a: &PlanarParams,
    g: &Gravity,
    rtol: f64,
) -> Result<(PlanarPose, PlanarJacobian, f64, f64), RodError> {
    RodError::check_finite("a", a.as_slice())?;
    let (w, d) = (g.weight(), g.direction());
    let (s, _) = solve(
        |_, s, ds| rhs(w, d, s, ds, true),
        0.0,
        initial(a),
        1.0,
        &opts(rtol),
    )?;
    if !s.iter().all(|v| v.is_finite()) {
        return Err(RodError::Overflow("non-finite reference state".into()));
    }
    Ok((
        PlanarPose::new(s[4], s[5], s[3]),
        jacobian_of(&s),
        s[6] + s[7],
        s[6],
    ))
}

/// D0(t) of the margin (module docs).
pub fn det_leading_term(a: &PlanarParams, g: &Gravity, t: f64) -> f64 {
    let cross = g.load()[1];
    t.powi(9)
        * (a[0] * a[0] / 8640.0
            + a[2] * a[2] * t * t / 33600.0
            + cross * cross * t.powi(4) / 388800.0)
}

/// Everything at rtol 1e-12 (the oracle's tolerance), stability on the grid of docs/math.md §5.
pub fn evaluate(a: &PlanarParams, g: &Gravity) -> Result<HeavyReference, RodError> {
    let rtol = 1e-12;
    let (tip, jacobian, energy, elastic_energy) = tip_and_jacobian(a, g, rtol)?;
    let grid = super::planar_reference::stability_grid();
    let (w, d) = (g.weight(), g.direction());
    let mut scan = crate::conjugate::Stream::new();
    solve_dense(
        |_, s, ds| rhs(w, d, s, ds, true),
        0.0,
        initial(a),
        &grid,
        &opts(rtol),
        |_, t, s| {
            let _ = scan.sample_det(t, jacobian_of(s).determinant(), det_leading_term(a, g, t));
            ControlFlow::Continue(())
        },
    )?;
    Ok(HeavyReference {
        tip,
        jacobian,
        energy,
        elastic_energy,
        stability: scan.exact_report(),
    })
}
