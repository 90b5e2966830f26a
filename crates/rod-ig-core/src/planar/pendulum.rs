//! A nearly straight rod under compression as a pendulum of exact frequency (issue 23).
//!
//! Under compression a4 = −w² the rod's angle obeys (docs/math.md §1)
//!
//! ```text
//! θ'' = a4 sin θ − a5 cos θ = −R sin(θ + φ),   R = √(a4² + a5²),  (R cos φ, R sin φ) = (w², a5),
//! ```
//!
//! a pendulum in ψ = θ + φ with ψ(0) = φ, ψ'(0) = a3. Its amplitude A is exact from the
//! energy: m = sin²(A/2) = a3²/(4R) + sin²(φ/2), and so is its angular frequency
//! Ω = √R·π/(2K(m)) (A&S 17.3.11, K(m) = π/2·(1 + m/4 + 9m²/64 + …)). The harmonic of that
//! frequency through ψ(0), ψ'(0),
//!
//! ```text
//! ψ(t) ≈ φ cos Ωt + (a3/Ω) sin Ωt,
//! ```
//!
//! is off by O(A³) (the third harmonic, A³/192, and the initial phase) for every t: with the
//! exact period there is no secular drift. The straight-rod linearisation of [`super::small_angle`]
//! runs at frequency w instead, and its phase error w·A²/16 per unit length accumulates over
//! the √|a4|/π wavelengths of a strongly compressed rod (its J error grows like A²·√|a4|: 4e-8
//! at |a4| = 1e4 and a bending of 1e-5, where this form is ≲ 1e-10 off).
//!
//! The pose follows from ψ' and P(t) = ∫₀ᵗ ψ'² by the equation's two exact integrals,
//! ∫sin ψ = −(ψ'(t) − a3)/R and R cos ψ = ½ψ'² − ½a3² + R cos φ:
//!
//! ```text
//! C = ∫cos ψ = t cos φ + (P − a3² t)/(2R),   S = ∫sin ψ = −(ψ' − a3)/R,
//! x = cos φ C + sin φ S,   y = cos φ S − sin φ C,   θ = ψ − φ,   ½∫κ² = ½P(1),
//! ```
//!
//! every term small where it is small (no difference of O(1) quantities), and J = ∂(x, y, θ)/∂a
//! by forward-mode dual numbers through the same formulas.

use crate::scalar::{Dual3, Real};

/// Constants of the a-priori truncation bounds in m = sin²(A/2) (module docs): J relative
/// (Frobenius) ≤ C·m, tip absolute ≤ C·m^{3/2}, energy relative ≤ C·m; measured against the
/// dual-number series (J, tip) and the double-double one (energy) on compressed rods
/// (`pendulum_bounds_hold`, |a4| from 1 to 1e5, a3 and a5 log-scale and exact zeros, t = 1
/// and inside the rod): 0.48, 0.18 and 0.16; ×4 or more.
const J_C: f64 = 2.0;
const TIP_C: f64 = 1.0;
const ENERGY_C: f64 = 0.75;

/// Rounding floors of J (relative), the tip (absolute) and the energy (relative), per unit of
/// the phase Ω (the phase Ωt carries a relative rounding of a few ε, an absolute one of a few
/// ε·Ω): measured 8.2e-14, 4.4e-17 and 2.2e-16 at m below 1e-22, where truncation is nil,
/// ×10 or more.
const J_ROUNDING: f64 = 1e-12;
const TIP_ROUNDING: f64 = 1e-15;
const ENERGY_ROUNDING: f64 = 2e-15;

/// Largest m at which the form is tried: the constants were measured up to there.
const MAX_M: f64 = 1e-4;
/// Compression range |a4| over which the constants were measured: below 1 the linearisation
/// of [`super::small_angle`] drifts by no more than its own O(Θ²), and this form's J is further
/// off (∂φ/∂a4 ∝ a5/a4² magnifies the harmonic's O(A²) error, 40·m at |a4| = 0.01).
const MIN_COMPRESSION: f64 = 1.0;
const MAX_COMPRESSION: f64 = 1e5;

/// The rod's pendulum (module docs): R, (cos φ, sin φ), φ, Ω and a3.
struct Pendulum<T> {
    r: T,
    cos_phi: T,
    sin_phi: T,
    phi: T,
    omega: T,
    a3: T,
}

/// m = sin²(A/2) of the rod's pendulum (module docs), in the measured compression; NaN
/// elsewhere.
#[cfg(test)]
pub(crate) fn amplitude_m(a3: f64, a4: f64, a5: f64) -> f64 {
    if !in_measured_compression(a4) {
        return f64::NAN;
    }
    pendulum_of(a3, a4, a5).1
}

/// The pendulum and its m.
fn pendulum_of<T: Real>(a3: T, a4: T, a5: T) -> (Pendulum<T>, f64) {
    let w2 = -a4;
    let r = (w2 * w2 + a5 * a5).sqrt();
    let (cos_phi, sin_phi) = (w2 / r, a5 / r);
    let phi = a5.atan2(w2);
    // sin²(φ/2) = sin²φ/(2(1 + cos φ)): no cancellation at small φ.
    let m = a3 * a3 / (r * 4.0) + sin_phi * sin_phi / ((cos_phi + 1.0) * 2.0);
    // π/(2K(m)) = 1 − m/4 − 5m²/64 − O(m³): m ≤ 1e-4 leaves 5e-14 of the phase per wavelength
    // before ×Ω ≤ 316, i.e. below the J rounding floor; at the m where J is taken (≲ 3e-9)
    // the O(m³) term is below 1e-25.
    let omega = r.sqrt() * (-(m * 0.25 + m * m * (5.0 / 64.0)) + 1.0);
    let m_value = m.re();
    (
        Pendulum {
            r,
            cos_phi,
            sin_phi,
            phi,
            omega,
            a3,
        },
        m_value,
    )
}

/// ∫₀ᵗ sin²(Ωs) ds = (u − sin u)/(4Ω), u = 2Ωt; by its Maclaurin series below u = 0.1 (the
/// difference cancels there), error below u¹¹/4e7 relative.
fn integral_sin_squared<T: Real>(omega: T, t: f64) -> T {
    let u = omega * (2.0 * t);
    let diff = if u.re().abs() < 0.1 {
        let u2 = u * u;
        u * u2 * (((u2 * (-1.0 / 362_880.0) + 1.0 / 5040.0) * u2 - 1.0 / 120.0) * u2 + 1.0 / 6.0)
    } else {
        u - u.sin()
    };
    diff / (omega * 4.0)
}

/// (x, y, θ)(t) and P(t) = ∫₀ᵗψ'² of the pendulum (module docs).
fn pose_of<T: Real>(p: &Pendulum<T>, t: f64) -> ([T; 3], T) {
    let phase = p.omega * t;
    let s = phase.sin();
    let half = (phase * 0.5).sin();
    let one_minus_c = half * half * 2.0;
    let phi_omega = p.phi * p.omega;
    let theta = p.a3 * s / p.omega - p.phi * one_minus_c;
    // ψ' − a3 = −a3(1 − cos Ωt) − φΩ sin Ωt.
    let dpsi_minus_a3 = -(p.a3 * one_minus_c) - phi_omega * s;
    // P − a3² t = (φ²Ω² − a3²)∫sin²Ωs − a3 φ sin²Ωt.
    let p_minus = (phi_omega * phi_omega - p.a3 * p.a3) * integral_sin_squared(p.omega, t)
        - p.a3 * p.phi * s * s;
    let d = p_minus / (p.r * 2.0);
    let big_s = -dpsi_minus_a3 / p.r;
    // x = t cos²φ + cos φ D + sin φ S = t − (t sin²φ − cos φ D − sin φ S).
    let x = -(p.sin_phi * p.sin_phi * t - p.cos_phi * d - p.sin_phi * big_s) + t;
    let y = p.cos_phi * big_s - p.sin_phi * (p.cos_phi * t + d);
    let big_p = p_minus + p.a3 * p.a3 * t;
    ([x, y, theta], big_p)
}

/// Whether a4 is a compression from [`MIN_COMPRESSION`] to [`MAX_COMPRESSION`], where the
/// constants were measured (false for NaN).
fn in_measured_compression(a4: f64) -> bool {
    (MIN_COMPRESSION..=MAX_COMPRESSION).contains(&-a4)
}

/// Whether m is within [`MAX_M`], where the constants were measured (false for NaN).
fn in_measured_amplitude(m: f64) -> bool {
    (0.0..=MAX_M).contains(&m)
}

/// The rod's pendulum and its m where the constants were measured (see
/// [`in_measured_compression`], [`in_measured_amplitude`]); None elsewhere.
fn measured_pendulum<T: Real>(a3: T, a4: T, a5: T) -> Option<(Pendulum<T>, f64)> {
    if !in_measured_compression(a4.re()) {
        return None;
    }
    let (p, m) = pendulum_of(a3, a4, a5);
    in_measured_amplitude(m).then_some((p, m))
}

/// q(t) and J(t) of a compressed nearly straight rod by its pendulum, with a-priori bounds.
pub(crate) struct PoseAndJacobian {
    /// (x, y, θ).
    pub pose: [f64; 3],
    /// ∂(x, y, θ)/∂(a3, a4, a5), rows x, y, θ.
    pub jacobian: [[f64; 3]; 3],
    /// Bound of J's relative (Frobenius) error, truncation and rounding.
    pub jacobian_error: f64,
    /// Bound of the pose's absolute error (rod lengths, rad), truncation and rounding.
    pub pose_error: f64,
}

/// Pose q(t), J(t) and their a-priori error bounds of a compressed nearly straight rod
/// (module docs); None outside the measured domain or where a value is not finite.
pub(crate) fn pose_and_jacobian(a3: f64, a4: f64, a5: f64, t: f64) -> Option<PoseAndJacobian> {
    let (p, m) = measured_pendulum(
        Dual3::variable(a3, 0),
        Dual3::variable(a4, 1),
        Dual3::variable(a5, 2),
    )?;
    let (pose, _) = pose_of(&p, t);
    let phase = p.omega.v * t.abs().max(1.0);
    let values = pose.map(|q| q.v);
    let jacobian = [pose[0].g, pose[1].g, pose[2].g];
    let finite = values
        .iter()
        .chain(jacobian.iter().flatten())
        .all(|v| v.is_finite());
    finite.then_some(PoseAndJacobian {
        pose: values,
        jacobian,
        jacobian_error: J_C * m + J_ROUNDING * (1.0 + phase),
        pose_error: TIP_C * m * m.sqrt() + TIP_ROUNDING * (1.0 + phase),
    })
}

/// The tip q(1) and its a-priori absolute error bound (see [`pose_and_jacobian`]).
pub(crate) fn tip(a3: f64, a4: f64, a5: f64) -> Option<([f64; 3], f64)> {
    let (p, m) = measured_pendulum(a3, a4, a5)?;
    let (pose, _) = pose_of(&p, 1.0);
    let error = TIP_C * m * m.sqrt() + TIP_ROUNDING * (1.0 + p.omega);
    pose.iter().all(|v| v.is_finite()).then_some((pose, error))
}

/// ½∫₀¹κ² = ½P(1) and its a-priori relative error bound (see [`pose_and_jacobian`]).
pub(crate) fn energy(a3: f64, a4: f64, a5: f64) -> Option<(f64, f64)> {
    let (p, m) = measured_pendulum(a3, a4, a5)?;
    let (_, big_p) = pose_of(&p, 1.0);
    let e = 0.5 * big_p;
    let error = ENERGY_C * m + ENERGY_ROUNDING * (1.0 + p.omega);
    (e.is_finite() && e > 0.0).then_some((e, error))
}
