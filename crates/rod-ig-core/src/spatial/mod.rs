//! The 3-D Kirchhoff rod (paper §2.1, Bretl & McCarthy 2014), by numerical integration.
//!
//! Model (docs/math.md §10, verified form of the paper's eq. 2.2): with m = (μ1, μ2, μ3),
//! f = (μ4, μ5, μ6), stiffnesses c = (c1, c2, c3) and body angular rate ω = m / c
//! (component-wise; u_i = μ_i / c_i),
//!
//! * m' = m × ω + f × e1, f' = f × ω, i.e.
//!   μ1' = μ2μ3(1/c3 − 1/c2), μ2' = μ6 + μ1μ3(1/c1 − 1/c3), μ3' = −μ5 + μ1μ2(1/c2 − 1/c1),
//!   μ4' = μ3μ5/c3 − μ2μ6/c2, μ5' = μ1μ6/c1 − μ3μ4/c3, μ6' = μ2μ4/c2 − μ1μ5/c1;
//! * R' = R (ω)×, p' = R e1 (body x is the tangent; R's columns are the body axes in the world
//!   frame), with R integrated as a unit quaternion q' = ½ q ⊗ (0, ω), renormalised on output;
//! * μ(0) = a, q(0) = identity.
//!
//! Sensitivity: column j of J(t, a) ∈ ℝ⁶ˣ⁶ is the body twist η_j = q⁻¹ ∂q/∂a_j = (ω, v) (rows
//! ω1, ω2, ω3, v1, v2, v3), integrated with the variational equations
//! δμ' = (∂μ'/∂μ) δμ, η' = δξ − ad_ξ η, where ξ = (ω, e1), δξ = (δm / c, 0) and
//! ad_(ω, v)(ω_η, v_η) = (ω × ω_η, ω × v_η − ω_η × v); η(0) = 0, δμ(0) = e_j.
//!
//! Stability ([`stability`]): the rule of docs/math.md §10, det J(t) > 0 at every t = i/2000 in
//! [0.02, 1]; for exact planar-subset inputs (a1 = a2 = a6 = 0) J is block-diagonal and the
//! in-plane and out-of-plane blocks are tested separately (their crossings could cancel in det).

// `!(x > y)` comparisons deliberately reject NaN; index loops mirror the formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod cable;
mod cable_search;
pub mod heavy;
mod heavy_model;
mod heavy_ode;
pub mod held;
pub mod ig;
mod model;
mod reduced;
mod stability;

pub use heavy_model::{carry, HeavySpatial};
pub use model::Spatial;
pub use stability::{
    det_leading_term, stability, stability_full_grid, stability_with, StabilityOptions,
    STABILITY_T_MIN,
};

use crate::ode::{solve, solve_dense, OdeOptions};
use crate::RodError;
use nalgebra::{Matrix6, Quaternion, UnitQuaternion, Vector3, Vector6};
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;

/// 3-D rod parameters a = μ(0) = (a1, a2, a3, a4, a5, a6): base moment (a1 twist, a2, a3
/// bending) and base force (a4 axial, a5, a6), body frame of the base, normalised units.
pub type SpatialParams = Vector6<f64>;

/// J(t, a) ∈ ℝ⁶ˣ⁶: column j = q⁻¹ ∂q/∂a_j as a body twist; rows (ω1, ω2, ω3, v1, v2, v3).
pub type SpatialJacobian = Matrix6<f64>;

/// Default relative tolerance for production use (tip, J, stability inside the solver).
pub const PRODUCTION_RTOL: f64 = 1e-8;
/// Relative tolerance used by the reference functions and the tests.
pub const REFERENCE_RTOL: f64 = 1e-12;
/// Step budget of every spatial integration.
pub const MAX_STEPS: u32 = 100_000;

/// Stiffnesses c1 (torsion), c2, c3 (bending), relative to the bending stiffness used to
/// normalise a. Default 1, 1, 1 (isotropic, as in the paper's eq. 2.3).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stiffness {
    /// Torsional stiffness (about the tangent, body x).
    pub c1: f64,
    /// Bending stiffness about body y.
    pub c2: f64,
    /// Bending stiffness about body z.
    pub c3: f64,
}

impl Default for Stiffness {
    fn default() -> Self {
        Self {
            c1: 1.0,
            c2: 1.0,
            c3: 1.0,
        }
    }
}

/// Smallest accepted stiffness coefficient. The unit rod's equilibria depend only on the
/// ratios c_i / c_j; ratios beyond 1e12 make the Hamiltonian system so stiff that no answer
/// could be certified, so each coefficient is kept within [1e-6, 1e6].
pub const MIN_STIFFNESS: f64 = 1e-6;
/// Largest accepted stiffness coefficient ([`MIN_STIFFNESS`]).
pub const MAX_STIFFNESS: f64 = 1e6;

impl Stiffness {
    /// Checks that c1, c2, c3 are finite and > 0.
    pub fn validate(&self) -> Result<(), RodError> {
        for (i, c) in [self.c1, self.c2, self.c3].into_iter().enumerate() {
            if !c.is_finite() {
                return Err(RodError::NonFinite {
                    name: "stiffness",
                    index: i,
                    value: c,
                });
            }
            if !(MIN_STIFFNESS..=MAX_STIFFNESS).contains(&c) {
                return Err(RodError::OutOfDomain(format!(
                    "stiffness c{} must be in [{MIN_STIFFNESS:e}, {MAX_STIFFNESS:e}] (got {c})",
                    i + 1
                )));
            }
        }
        Ok(())
    }

    /// True when c2 = c3 (then μ1 is a first integral).
    pub fn is_bending_isotropic(&self) -> bool {
        self.c2 == self.c3
    }

    fn inv(&self) -> [f64; 3] {
        [1.0 / self.c1, 1.0 / self.c2, 1.0 / self.c3]
    }
}

/// A pose of the 3-D rod: position and orientation in the base frame.
///
/// Serialised as `{"position": [x, y, z], "quaternion": [qx, qy, qz, qw]}` with qw ≥ 0
/// (scalar last).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(into = "PoseRepr", try_from = "PoseRepr")]
pub struct SpatialPose {
    /// Position p.
    pub position: Vector3<f64>,
    /// Orientation R (columns = body axes in the world frame).
    pub rotation: UnitQuaternion<f64>,
}

#[derive(Serialize, Deserialize)]
struct PoseRepr {
    position: [f64; 3],
    quaternion: [f64; 4],
}

impl From<SpatialPose> for PoseRepr {
    fn from(p: SpatialPose) -> Self {
        let q = p.quaternion_xyzw();
        PoseRepr {
            position: [p.position.x, p.position.y, p.position.z],
            quaternion: q,
        }
    }
}

impl TryFrom<PoseRepr> for SpatialPose {
    type Error = String;
    fn try_from(r: PoseRepr) -> Result<Self, String> {
        let [x, y, z, w] = r.quaternion;
        SpatialPose::from_xyzw(Vector3::from(r.position), [x, y, z, w]).map_err(|e| e.to_string())
    }
}

impl Default for SpatialPose {
    fn default() -> Self {
        Self::identity()
    }
}

impl SpatialPose {
    /// The base pose (origin, identity rotation).
    pub fn identity() -> Self {
        Self {
            position: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
        }
    }

    /// A pose from a position and a quaternion given as (x, y, z, w) (any nonzero norm; it is
    /// normalised). Errors on non-finite input or a zero quaternion.
    pub fn from_xyzw(position: Vector3<f64>, xyzw: [f64; 4]) -> Result<Self, RodError> {
        RodError::check_finite("position", position.as_slice())?;
        RodError::check_finite("quaternion", &xyzw)?;
        let [x, y, z, w] = xyzw;
        let q = Quaternion::new(w, x, y, z);
        let n = q.norm();
        if !(n > 1e-12) || !n.is_finite() {
            return Err(RodError::OutOfDomain(
                "quaternion has (near) zero norm".into(),
            ));
        }
        Ok(Self {
            position,
            rotation: UnitQuaternion::new_normalize(q),
        })
    }

    /// The orientation as (x, y, z, w) with w ≥ 0.
    pub fn quaternion_xyzw(&self) -> [f64; 4] {
        let q = self.rotation.quaternion();
        let s = if q.w < 0.0 { -1.0 } else { 1.0 };
        [s * q.i, s * q.j, s * q.k, s * q.w]
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.position.iter().all(|v| v.is_finite())
            && self.rotation.coords.iter().all(|v| v.is_finite())
    }

    /// The error twist e = (ω_e, v_e) from `self` to `target` in the body frame of `self`:
    /// ω_e = log(Rᵀ R*) (rotation vector), v_e = Rᵀ (p* − p). To first order
    /// q(a + δa) ≈ q exp(J δa), so Newton solves J δa = e.
    pub fn body_error_to(&self, target: &SpatialPose) -> Vector6<f64> {
        let rinv = self.rotation.inverse();
        let w = (rinv * target.rotation).scaled_axis();
        let v = rinv * (target.position - self.position);
        Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z)
    }

    /// Position error |p* − p| and rotation angle of Rᵀ R* (rad, in [0, π]).
    pub fn distance_to(&self, target: &SpatialPose) -> (f64, f64) {
        (
            (target.position - self.position).norm(),
            self.rotation.angle_to(&target.rotation),
        )
    }
}

/// The state of the rod at one t: internal wrench μ(t) (body frame) and pose q(t).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodState {
    /// Arc length t ∈ [0, 1].
    pub t: f64,
    /// μ(t) = (m, f) in the body frame.
    pub mu: Vector6<f64>,
    /// q(t).
    pub pose: SpatialPose,
    /// Elastic energy accumulated on [0, t]: ½∫ Σ μ_i²/c_i (i = 1..3).
    pub energy: f64,
}

// ---- state layout ----------------------------------------------------------------------------
// base: μ (0..6), p (6..9), quaternion (w, x, y, z) (9..13), energy (13)
// variational column j: δμ (14 + 12 j .. +6), η = (ω, v) (+6 .. +12)
pub(crate) const NB: usize = 14;
pub(crate) const NV: usize = NB + 72;

/// Rod right-hand side on the base state (module docs).
#[inline(always)]
pub(crate) fn base_rhs(ci: &[f64; 3], s: &[f64], ds: &mut [f64]) {
    let (m1, m2, m3, f1, f2, f3) = (s[0], s[1], s[2], s[3], s[4], s[5]);
    let (w1, w2, w3) = (m1 * ci[0], m2 * ci[1], m3 * ci[2]);
    // m' = m × ω + f × e1 ; f' = f × ω
    ds[0] = m2 * w3 - m3 * w2;
    ds[1] = m3 * w1 - m1 * w3 + f3;
    ds[2] = m1 * w2 - m2 * w1 - f2;
    ds[3] = f2 * w3 - f3 * w2;
    ds[4] = f3 * w1 - f1 * w3;
    ds[5] = f1 * w2 - f2 * w1;
    let (qw, qx, qy, qz) = (s[9], s[10], s[11], s[12]);
    // p' = R e1 (first column of R(q)), valid for |q| = 1.
    ds[6] = qw * qw + qx * qx - qy * qy - qz * qz;
    ds[7] = 2.0 * (qx * qy + qw * qz);
    ds[8] = 2.0 * (qx * qz - qw * qy);
    // q' = ½ q ⊗ (0, ω)
    ds[9] = -0.5 * (qx * w1 + qy * w2 + qz * w3);
    ds[10] = 0.5 * (qw * w1 + qy * w3 - qz * w2);
    ds[11] = 0.5 * (qw * w2 + qz * w1 - qx * w3);
    ds[12] = 0.5 * (qw * w3 + qx * w2 - qy * w1);
    ds[13] = 0.5 * (m1 * w1 + m2 * w2 + m3 * w3);
}

/// Rod + variational right-hand side (module docs).
#[inline(always)]
pub(crate) fn var_rhs(ci: &[f64; 3], s: &[f64; NV], ds: &mut [f64; NV]) {
    base_rhs(ci, &s[..NB], &mut ds[..NB]);
    let (m1, m2, m3, f1, f2, f3) = (s[0], s[1], s[2], s[3], s[4], s[5]);
    let (w1, w2, w3) = (m1 * ci[0], m2 * ci[1], m3 * ci[2]);
    for j in 0..6 {
        let o = NB + 12 * j;
        let (dm1, dm2, dm3, df1, df2, df3) =
            (s[o], s[o + 1], s[o + 2], s[o + 3], s[o + 4], s[o + 5]);
        let (dw1, dw2, dw3) = (dm1 * ci[0], dm2 * ci[1], dm3 * ci[2]);
        // δm' = δm × ω + m × δω + δf × e1 ; δf' = δf × ω + f × δω
        ds[o] = dm2 * w3 - dm3 * w2 + m2 * dw3 - m3 * dw2;
        ds[o + 1] = dm3 * w1 - dm1 * w3 + m3 * dw1 - m1 * dw3 + df3;
        ds[o + 2] = dm1 * w2 - dm2 * w1 + m1 * dw2 - m2 * dw1 - df2;
        ds[o + 3] = df2 * w3 - df3 * w2 + f2 * dw3 - f3 * dw2;
        ds[o + 4] = df3 * w1 - df1 * w3 + f3 * dw1 - f1 * dw3;
        ds[o + 5] = df1 * w2 - df2 * w1 + f1 * dw2 - f2 * dw1;
        // η' = δξ − ad_ξ η, ξ = (ω, e1): ω_η' = δω − ω × ω_η ; v_η' = −ω × v_η + ω_η × e1
        let (a1, a2, a3, b1, b2, b3) =
            (s[o + 6], s[o + 7], s[o + 8], s[o + 9], s[o + 10], s[o + 11]);
        ds[o + 6] = dw1 - (w2 * a3 - w3 * a2);
        ds[o + 7] = dw2 - (w3 * a1 - w1 * a3);
        ds[o + 8] = dw3 - (w1 * a2 - w2 * a1);
        ds[o + 9] = -(w2 * b3 - w3 * b2);
        ds[o + 10] = -(w3 * b1 - w1 * b3) + a3;
        ds[o + 11] = -(w1 * b2 - w2 * b1) - a2;
    }
}

pub(crate) fn check_params(a: &SpatialParams, k: &Stiffness) -> Result<(), RodError> {
    RodError::check_finite("a", a.as_slice())?;
    k.validate()
}

pub(crate) fn check_rtol(rtol: f64) -> Result<(), RodError> {
    if rtol.is_finite() && rtol > 0.0 {
        Ok(())
    } else {
        Err(RodError::OutOfDomain(format!(
            "rtol must be finite and > 0 (got {rtol})"
        )))
    }
}

pub(crate) fn options(rtol: f64, atol: f64) -> OdeOptions {
    OdeOptions {
        rtol,
        atol,
        max_steps: MAX_STEPS,
        initial_step: None,
        max_step: f64::INFINITY,
        error_components: usize::MAX,
    }
}

/// Integration options for parameters `a`: as [`options`], with a first step of
/// min(0.03, 1/(1 + |a|∞)) instead of the generic heuristic (which the zero initial
/// variational entries drive down to ~1e-5, costing ~3 ramp-up steps).
pub(crate) fn options_for(a: &SpatialParams, rtol: f64, atol: f64) -> OdeOptions {
    OdeOptions {
        initial_step: Some((1.0 / (1.0 + a.amax())).min(0.03)),
        ..options(rtol, atol)
    }
}

/// Absolute tolerance paired with `rtol` for tip and J: atol = max(1e-2·rtol, 1e-16)
/// (entries of J at t = 1 are O(1e-3..1)).
pub(crate) fn default_atol(rtol: f64) -> f64 {
    (rtol * 1e-2).max(1e-16)
}

pub(crate) fn initial_base(a: &SpatialParams) -> [f64; NB] {
    let mut s = [0.0; NB];
    s[..6].copy_from_slice(a.as_slice());
    s[9] = 1.0;
    s
}

pub(crate) fn initial_var(a: &SpatialParams) -> [f64; NV] {
    let mut s = [0.0; NV];
    s[..NB].copy_from_slice(&initial_base(a));
    for j in 0..6 {
        s[NB + 12 * j + j] = 1.0;
    }
    s
}

pub(crate) fn pose_of(s: &[f64]) -> SpatialPose {
    pose_from_parts([s[9], s[10], s[11], s[12]], [s[6], s[7], s[8]])
}

/// A pose from an integrated quaternion (w, x, y, z), renormalised (identity if degenerate),
/// and a position.
pub(crate) fn pose_from_parts(wxyz: [f64; 4], position: [f64; 3]) -> SpatialPose {
    let q = Quaternion::new(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
    let n = q.norm();
    let rotation = if n.is_finite() && n > 0.0 {
        UnitQuaternion::new_unchecked(q / n)
    } else {
        UnitQuaternion::identity()
    };
    SpatialPose {
        position: Vector3::from(position),
        rotation,
    }
}

pub(crate) fn jac_of(s: &[f64]) -> SpatialJacobian {
    let mut j = SpatialJacobian::zeros();
    for c in 0..6 {
        let o = NB + 12 * c + 6;
        for r in 0..6 {
            j[(r, c)] = s[o + r];
        }
    }
    j
}

pub(crate) fn state_of(t: f64, s: &[f64]) -> RodState {
    RodState {
        t,
        mu: Vector6::from_column_slice(&s[..6]),
        pose: pose_of(s),
        energy: s[13],
    }
}

fn finite(s: &[f64]) -> Result<(), RodError> {
    if s.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(RodError::Overflow("non-finite rod state".into()))
    }
}

fn check_t(t: f64) -> Result<(), RodError> {
    RodError::check_finite("t", &[t])?;
    if (0.0..=1.0).contains(&t) {
        Ok(())
    } else {
        Err(RodError::OutOfDomain(format!("t = {t} is outside [0, 1]")))
    }
}

/// True when this CPU runs the AVX2 build of the 3-D integrations (same results, about a
/// third fewer instructions; `crate::simd`).
pub fn uses_avx2() -> bool {
    crate::simd::has_avx2()
}

/// Tip pose q(1), by DOP853 at relative tolerance `rtol` (atol = max(1e-3·rtol, 1e-16)),
/// integrating (q, p) with μ recovered from the conserved world wrench (see `reduced`).
pub fn tip(a: &SpatialParams, k: &Stiffness, rtol: f64) -> Result<SpatialPose, RodError> {
    check_params(a, k)?;
    check_rtol(rtol)?;
    let ci = k.inv();
    let ap = reduced::params(a);
    const M: usize = reduced::NRB;
    let s =
        reduced::integrate::<M, false>(&ci, &ap, 1.0, &options_for(a, rtol, default_atol(rtol)))?;
    finite(&s)?;
    Ok(reduced::pose(&s))
}

/// Pose q(t) and J(t, a) for t ∈ [0, 1] (module docs), DOP853 at relative tolerance `rtol`,
/// on the reduced formulation (q, p and 6 variational values per parameter; μ from the
/// conserved world wrench — mathematically identical to the μ-form, see
/// [`reference_pose_and_jacobian`]).
pub fn pose_and_jacobian(
    a: &SpatialParams,
    k: &Stiffness,
    t: f64,
    rtol: f64,
) -> Result<(SpatialPose, SpatialJacobian), RodError> {
    check_params(a, k)?;
    check_rtol(rtol)?;
    check_t(t)?;
    const M: usize = reduced::NR;
    let s0 = reduced::initial::<M>();
    if t == 0.0 {
        return Ok((reduced::pose(&s0), reduced::jac(&s0)));
    }
    let ci = k.inv();
    let ap = reduced::params(a);
    let s = reduced::integrate::<M, true>(&ci, &ap, t, &options_for(a, rtol, default_atol(rtol)))?;
    finite(&s)?;
    Ok((reduced::pose(&s), reduced::jac(&s)))
}

/// Pose q(t) and J(t, a) from the literal μ-form of docs/math.md §10: μ' equations in components,
/// quaternion, p, and the variational equations δμ' = (∂μ'/∂μ)δμ, η' = δξ − ad_ξ η
/// (86 values). Slower; kept as the cross-check of [`pose_and_jacobian`].
pub fn reference_pose_and_jacobian(
    a: &SpatialParams,
    k: &Stiffness,
    t: f64,
    rtol: f64,
) -> Result<(SpatialPose, SpatialJacobian), RodError> {
    check_params(a, k)?;
    check_rtol(rtol)?;
    check_t(t)?;
    let s0 = initial_var(a);
    if t == 0.0 {
        return Ok((pose_of(&s0), jac_of(&s0)));
    }
    let ci = k.inv();
    let (s, _) = solve(
        |_, s: &[f64; NV], ds: &mut [f64; NV]| var_rhs(&ci, s, ds),
        0.0,
        s0,
        t,
        &options_for(a, rtol, default_atol(rtol)),
    )?;
    finite(&s)?;
    Ok((pose_of(&s), jac_of(&s)))
}

/// Tip pose q(1) and J(1, a) (module docs), DOP853 at relative tolerance `rtol`
/// ([`PRODUCTION_RTOL`] = 1e-8 for solver use, [`REFERENCE_RTOL`] = 1e-12 for tests).
pub fn tip_and_jacobian(
    a: &SpatialParams,
    k: &Stiffness,
    rtol: f64,
) -> Result<(SpatialPose, SpatialJacobian), RodError> {
    pose_and_jacobian(a, k, 1.0, rtol)
}

/// Rod states (μ, pose, energy) at the given t ∈ [0, 1] (any order; results in the order of
/// `ts`), one DOP853 pass with dense output at relative tolerance `rtol`.
pub fn states(
    a: &SpatialParams,
    k: &Stiffness,
    ts: &[f64],
    rtol: f64,
) -> Result<Vec<RodState>, RodError> {
    check_params(a, k)?;
    check_rtol(rtol)?;
    for &t in ts {
        check_t(t)?;
    }
    let ci = k.inv();
    let mut order: Vec<usize> = (0..ts.len()).collect();
    order.sort_by(|&i, &j| ts[i].total_cmp(&ts[j]));
    let sorted: Vec<f64> = order.iter().map(|&i| ts[i]).collect();
    let s0 = initial_base(a);
    let mut out = vec![state_of(0.0, &s0); ts.len()];
    let mut bad = false;
    solve_dense(
        |_, s: &[f64; NB], ds: &mut [f64; NB]| base_rhs(&ci, s, ds),
        0.0,
        s0,
        &sorted,
        &options_for(a, rtol, default_atol(rtol)),
        |i, t, s| {
            if s.iter().any(|v| !v.is_finite()) {
                bad = true;
                return ControlFlow::Break(());
            }
            out[order[i]] = state_of(t, s);
            ControlFlow::Continue(())
        },
    )?;
    if bad {
        return Err(RodError::Overflow("non-finite rod state".into()));
    }
    Ok(out)
}

/// The rod shape at t_i = i/(samples − 1), i = 0..samples (samples ≥ 2), integrated at
/// rtol 1e-10 with dense output.
pub fn shape(
    a: &SpatialParams,
    k: &Stiffness,
    samples: usize,
) -> Result<Vec<SpatialPose>, RodError> {
    if samples < 2 {
        return Err(RodError::OutOfDomain(format!(
            "shape needs at least 2 samples (got {samples})"
        )));
    }
    if samples > 1_000_000 {
        return Err(RodError::OutOfDomain(format!(
            "too many samples ({samples})"
        )));
    }
    let ts: Vec<f64> = (0..samples)
        .map(|i| i as f64 / (samples - 1) as f64)
        .collect();
    Ok(states(a, k, &ts, 1e-10)?
        .into_iter()
        .map(|s| s.pose)
        .collect())
}

/// Elastic energy ½∫₀¹ Σ_{i≤3} c_i u_i² = ½∫₀¹ Σ μ_i²/c_i, integrated at relative tolerance
/// `rtol` (paper §2.1, E_el).
pub fn energy(a: &SpatialParams, k: &Stiffness, rtol: f64) -> Result<f64, RodError> {
    Ok(states(a, k, &[1.0], rtol)?[0].energy)
}

/// Tip, J(1, a), energy (½∫ Σ μ_i²/c_i) and the stability verdict (coarse scan with refinement,
/// [`stability_with`]) from one integration: the solvers' evaluation type
/// ([`crate::solver::ModelEvaluation`]) for the 3-D rod.
pub type Evaluation3d = crate::solver::ModelEvaluation<6, SpatialPose>;

/// Tip, J(1, a), energy and stability from a single dense integration at relative tolerance
/// `opts.rtol` and absolute tolerance `opts.atol` (see [`StabilityOptions`]).
pub fn evaluate(
    a: &SpatialParams,
    k: &Stiffness,
    opts: &StabilityOptions,
) -> Result<Evaluation3d, RodError> {
    stability::evaluate_impl(a, k, opts)
}
