//! The closed-form planar rod, generic over [`Real`] (FINDINGS §1–§3).
//!
//! [`Closed::new`] does everything that depends on a only (case selection, m, m1, r, phase,
//! Landen sequence, values at Γ0 = φ); [`Closed::pose`] then costs one descending-Landen
//! evaluation. With `T = Dual3` seeded with the identity on a, the same code yields J(t, a).

use crate::elliptic::{inverse_phase_zeta, Amplitude, Duplication, JacobiValues};
use crate::scalar::Real;

mod det_fields;
pub(crate) use det_fields::DetFrame;

/// Which closed form applies (decided on f64 values).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case {
    /// λ4 > 0: κ = ε√α3 cn(√F t + φ | m), m = α3/(4F), m1 = λ4/(F α3).
    I,
    /// λ4 < 0: κ = ε√α3 dn((√α3/2) t + φ | m), m = 4F/α3, m1 = −4λ4/α3².
    II,
    /// λ4 = 0 exactly, a3 ≠ 0: κ = ε√α3 sech(√F t + φ) (separatrix).
    III,
    /// a4 = a5 = 0, a3 ≠ 0: circle of curvature a3.
    Circle,
    /// a3 = a5 = 0: straight rod (any a4).
    Straight,
    /// Tiny force, m = 4F/α3 < 4e-8 (a limit of case II): the circle plus its first-order force
    /// terms. The neglected O(F²) terms are below 1e-16; J is exact to O(m), whereas the
    /// elliptic form's J loses ≈ 1e-16/m to cancellation in ∂(a4/F, a5/F)/∂a ~ 1/F.
    SmallForce,
}

/// Below this m = 4F/α3, case II is replaced by [`Case::SmallForce`].
const SMALL_FORCE_M: f64 = 4e-8;

/// Largest cancellation of λ4's terms (`lambda4_spread`) for which its computed sign, and so
/// the case, is trusted by [`Closed::conjugate_free`]: `lambda4_value` carries λ4 to ~ε² of
/// its terms (products exact, sums in double-double); 1e24 leaves 1e8 of room.
const THEOREM_MAX_SPREAD: f64 = 1e24;
/// Margin, relative to |φ| + r + K, by which a case-I rod's range of Γ must clear its
/// inflection points for [`Closed::conjugate_free`]: φ and K are accurate to ~1e-15 of that
/// size (inverse phase and AGM), and 1e-9 keeps a millionfold room.
const THEOREM_PHASE_MARGIN: f64 = 1e-9;
/// Smallest size of λ4's terms for which [`Closed::conjugate_free`] trusts its sign: below,
/// the squares lose digits to underflow.
const THEOREM_MIN_TERMS: f64 = 1e-280;
/// The sample times of [`Closed::dip_times`] (a fixed array: a scan would otherwise allocate).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct DipTimes {
    times: [f64; MAX_DIP_TIMES],
    len: usize,
}

impl DipTimes {
    /// The times, from the base.
    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.times[..self.len]
    }
}

/// Most sample times [`Closed::dip_times`] gives, from the base (a share of the scan's sample
/// budget; a rod with more periods has the grid alone beyond the eighth).
pub(crate) const MAX_DIP_TIMES: usize = 8;

/// Smallest m for which a form built without its phase ([`Closed::complete`]) leaves it out:
/// the small-m regimes (nearly straight rods under compression, near-circles) keep the form
/// their error estimates were measured on.
const PHASE_FREE_MIN_M: f64 = 0.01;
/// Smallest m1 = 1 − m for which a form built without its phase leaves it out: the
/// addition theorems' numerators cancel as m → 1, and case II's amplitude is unwrapped by its
/// mean slope π/(2K), which is unambiguous while 3·max|am(x) − πx/(2K)| < π (0.63π at
/// m = 0.999, by quadrature).
const PHASE_FREE_MIN_M1: f64 = 1e-3;

/// Whether a case I or II rod of parameter m (m1 = 1 − m) may leave out its phase and place
/// its poses by the addition theorems (f64 and dual numbers, not double-double). In dual
/// numbers the phase-free form costs about as many instructions as the phase it saves (q + J:
/// −3 % on the box), but Carlson's R_F and R_D are a chain of dependent square roots: q + J
/// takes 12 % less time without them. A form that keeps its phase (`evaluate`, for its scan
/// and energy) still places the tip by the addition theorems, so that both give the same bits.
fn phase_free_allowed<T: Real>(m: f64, m1: f64) -> bool {
    !T::EXTENDED && m >= PHASE_FREE_MIN_M && m1 >= PHASE_FREE_MIN_M1
}

/// Everything that depends on a only.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Closed<T: Real> {
    pub case: Case,
    eps: f64,
    pub a3: T,
    pub a4: T,
    pub a5: T,
    /// a4/F, a5/F.
    chat: T,
    shat: T,
    /// Γ = r t + φ.
    r: T,
    /// 1/r (cases I, II).
    inv_r: T,
    /// 2m/r (case I), 2/r (case II): coefficient of Z/m in ∫β1.
    zcoef: T,
    /// −√m/r (case I), 1/(m r) (case II): coefficient of the cn / dn difference in ∫β2.
    b2coef: T,
    /// √m sn φ (case I).
    y0: T,
    phi: T,
    /// √α3 (κ = ε √α3 cn/dn/sech Γ).
    sqa3: T,
    /// √m (case I), or 1 − δ/2 (case III).
    sqm: T,
    /// m (cases I, II) ; δ = 1 − m_I (case III; value 0, carries the derivative).
    pub(crate) m: T,
    /// Coefficient of t in ∫β1: m1 − m q (I), −q (II).
    lin: T,
    /// m1 = 1 − m (cases I, II), as computed from λ4.
    pub m1: f64,
    /// (a5² + a3²|a3²/4 + a4|)/|λ4| ≥ 1: how much the terms of λ4 cancel (≈ 1 for a rod with
    /// little bending near the separatrix, ~1/m1 for O(1) parameters tuned onto it).
    lambda4_spread: f64,
    /// The error estimate's constants, computed once (they were a tenth of a stability scan):
    /// ρ = max(|a3|, √F), and for cases I and II the m1 loss, 1/m and 1/√m.
    rho: f64,
    loss_m1: f64,
    inv_m: f64,
    inv_sqrt_m: f64,
    landen: Duplication<T>,
    /// Jacobi values at Γ0 = φ (cases I, II).
    j0: JacobiValues<T>,
    /// θ/(2ε) at t = 0: am φ (II), gd φ (III); unused in case I (see `pose`).
    th0: T,
    /// Case III: E(am φ) and cn φ (first order in δ).
    e0: T,
    /// φ and Z(φ) were left out ([`Closed::complete`] without the phase; then both 0): `pose`
    /// places Γ = r t + φ by the addition theorems ([`Closed::integrals_additive`]), and
    /// nothing that needs φ itself (stability, energy, curvature, the theorem) may be asked.
    phase_unknown: bool,
    /// Cases I and II where the addition theorems hold ([`phase_free_allowed`]): `pose`, and
    /// J(t) without the curvature, place Γ by them whether φ is known or not, so that a form
    /// built with its phase (`evaluate`) and one without (`tip_and_jacobian`) give the same
    /// tip and J bit for bit.
    additive: bool,
    /// Straight rod / circle: nothing else needed.
    _p: (),
}

/// First-order expansion of the Jacobi functions about m = 1 in δ = 1 − m (A&S 16.15.1–4),
/// with E(am u|m) = tanh u + (δ/2)(u − tanh u/2 − u sech² u/2). At δ = 0 these are the
/// separatrix forms of FINDINGS §3 case III; with a dual δ (value 0) they also carry the exact
/// first derivative across λ4 = 0. Returns (sn, cn, dn, E(am u)).
#[inline]
fn near_one<T: Real>(u: T, delta: T) -> (T, T, T, T) {
    let th = u.tanh();
    let se = u.cosh().recip();
    let sh = u.sinh();
    let q = delta * 0.25;
    let sn = th + q * (th - u * se * se);
    let cn = se - q * th * (sh - u * se);
    let dn = se + q * th * (sh + u * se);
    let e = th + delta * 0.5 * (u - th * 0.5 - u * se * se * 0.5);
    (sn, cn, dn, e)
}

/// λ4 = a5² − a3²(a3²/4 + a4) (FINDINGS §2) to about ε relative to itself: the two terms cancel
/// near the separatrix (λ4 = 0), and m1 ∝ λ4 sets every log-singular piece of the closed form
/// there (a = (2, 3, 4 + 1e-8): λ4 = 8e-8 from terms of 16, so f64 leaves it 4e-8 off and J(t)
/// 1.5e-6 off). Products by Dekker's exact two_prod, the sums in double-double; falls back to
/// f64 where the splitting would overflow (|a| ≳ 1e150: λ4 is then not near a cancellation
/// anyway, or the rod is beyond the fallbacks).
fn lambda4_value(a3: f64, a4: f64, a5: f64) -> f64 {
    use crate::eft::{two_prod, two_sum};
    let plain = a5 * a5 - a3 * a3 * (a3 * a3 * 0.25 + a4);
    if !(a3.abs().max(a5.abs()) < 1e150 && a4.abs() < 1e300) {
        return plain;
    }
    let (p, pe) = two_prod(a5, a5);
    let (s, se) = two_prod(a3, a3);
    // a3²/4 + a4 (a3²/4 exact: a power-of-two scaling)
    let (i, ie) = two_sum(s * 0.25, a4);
    let i_lo = ie + se * 0.25;
    let (q, qe) = two_prod(s, i);
    let q_lo = qe + s * i_lo + se * i;
    let (d, de) = two_sum(p, -q);
    let v = d + (de + pe - q_lo);
    if v.is_finite() {
        v
    } else {
        plain
    }
}

/// m near 1 (m1 < 1/2) as 1 − m1. Both formulas for m are exact, but m's derivatives from
/// its own formula (α3/(4F) in case I, 4F/α3 in case II) are differences of O(1/F) terms
/// that cancel to O(m1): their rounding, ε/F, is then amplified by the ~1/m1 sensitivity of
/// K, E and the phase near the separatrix (the ∂/∂a4 column of J was lost, e.g. 1.49 for
/// 3.8e-5 at m1 = 9e-26). 1 − m1 carries m1's derivatives, which come from λ4 without
/// cancellation.
#[inline]
fn complement_near_one<T: Real>(m: T, m1: T) -> T {
    if m1.re() < 0.5 {
        T::from_f64(1.0) - m1
    } else {
        m
    }
}

/// Integrals S1 = ∫₀ᵗ C, S2 = ∫₀ᵗ S1, S3 = ∫₀ᵗ S2 of the linearised straight rod
/// δμ3'' = a4 δμ3 (C = cosh(√a4 t) or cos(√−a4 t)); series for |a4 t²| < 1.
fn straight_integrals<T: Real>(a4: T, t: f64) -> (T, T, T) {
    let z = a4 * (t * t);
    if z.re().abs() < 1.0 {
        // S1 = t Σ z^k/(2k+1)!, S2 = t² Σ z^k/(2k+2)!, S3 = t³ Σ z^k/(2k+3)!
        let one = T::from_f64(1.0);
        let (mut f1, mut f2, mut f3) = (T::from_f64(0.0), T::from_f64(0.0), T::from_f64(0.0));
        let mut zk = one;
        let mut fact = 1.0; // (2k)!
        for k in 0..20 {
            let kk = k as f64;
            let c1 = 1.0 / (fact * (2.0 * kk + 1.0));
            let c2 = c1 / (2.0 * kk + 2.0);
            let c3 = c2 / (2.0 * kk + 3.0);
            f1 += zk * c1;
            f2 += zk * c2;
            f3 += zk * c3;
            zk *= z;
            fact *= (2.0 * kk + 1.0) * (2.0 * kk + 2.0);
        }
        (f1 * t, f2 * (t * t), f3 * (t * t * t))
    } else if a4.re() > 0.0 {
        let w = a4.sqrt();
        let wt = w * t;
        let s1 = wt.sinh() / w;
        (s1, (wt.cosh() - 1.0) / a4, (s1 - t) / a4)
    } else {
        let w = (-a4).sqrt();
        let wt = w * t;
        let s1 = wt.sin() / w;
        (s1, (wt.cos() - 1.0) / a4, (s1 - t) / a4)
    }
}

/// First-order force terms about the circle κ ≡ c (a4 = a5 = 0):
/// returns (θ4, θ5, x4, x5, y4, y5) = ∂(θ, x, y)/∂(a4, a5) at the circle, by the
/// linearisation δμ3' = δa4 sin θ0 − δa5 cos θ0, θ0 = c t. Series in τ = c t for |τ| < 1.
fn circle_force_terms<T: Real>(c: T, t: f64) -> [T; 6] {
    let tau = c * t;
    let t2 = t * t;
    let t3 = t2 * t;
    if tau.re().abs() < 1.0 {
        let tt = tau * tau;
        let zero = T::from_f64(0.0);
        let (mut a, mut b, mut x4, mut y4, mut x5, mut y5) = (zero, zero, zero, zero, zero, zero);
        // Σ over powers τ^{2j}, j = 0..; coefficients from the Taylor series (see docs).
        let mut p = T::from_f64(1.0); // τ^{2j}
        let mut f = [1.0f64; 40]; // factorials
        for i in 1..40 {
            f[i] = f[i - 1] * i as f64;
        }
        for j in 0..16usize {
            let jf = j as f64;
            let sgn = if j % 2 == 0 { 1.0 } else { -1.0 };
            // A/τ = Σ_{k≥1} (−1)^{k+1} τ^{2k−2}/(2k+1)!, k = j+1
            a += p * (sgn / f[2 * j + 3]);
            // B = Σ_{k≥1} (−1)^{k+1} τ^{2k−2}/(2k)!, k = j+1
            b += p * (sgn / f[2 * j + 2]);
            // X4 = Σ_{k≥2} (−1)^k [(1 + 2^{2k−1})/(2k+1)! − 1/(2k)!] τ^{2k−2}, k = j+2 → τ^{2j+2}
            {
                let k = jf + 2.0;
                let kk = j + 2;
                let cf = (1.0 + 2f64.powf(2.0 * k - 1.0)) / f[2 * kk + 1] - 1.0 / f[2 * kk];
                x4 += p * tt * (sgn * cf);
            }
            // Y4/τ = Σ_{j'≥2} (−1)^{j'} (1 + 4^{j'−1} − 2j')/(2j')! τ^{2j'−4}, j' = j+2
            {
                let jj = j + 2;
                let jjf = jj as f64;
                let cf = (1.0 + 4f64.powf(jjf - 1.0) - 2.0 * jjf) / f[2 * jj];
                y4 += p * (sgn * cf);
            }
            // X5/τ = Σ_{j'≥2} (−1)^{j'+1}(1 − 4^{j'−1})/(2j')! τ^{2j'−4}
            {
                let jj = j + 2;
                let jjf = jj as f64;
                let cf = -(1.0 - 4f64.powf(jjf - 1.0)) / f[2 * jj];
                x5 += p * (sgn * cf);
            }
            // Y5 = Σ_{k≥1} (−1)^k (1 − 2^{2k−1})/(2k+1)! τ^{2k−2}, k = j+1
            {
                let kk = j + 1;
                let cf = -(1.0 - 2f64.powf(2.0 * kk as f64 - 1.0)) / f[2 * kk + 1];
                y5 += p * (sgn * cf);
            }
            p *= tt;
        }
        [
            tau * a * t2,
            -b * t2,
            -x4 * t3,
            x5 * tau * t3,
            y4 * tau * t3,
            -y5 * t3,
        ]
    } else {
        let (s, co) = tau.sin_cos();
        let s2 = (tau * 2.0).sin();
        let tau2 = tau * tau;
        let tau3 = tau2 * tau;
        let a = (tau - s) / tau2;
        let b = (-co + 1.0) / tau2;
        let x4 = (s - tau * co - tau * 0.5 + s2 * 0.25) / tau3;
        let y4 = (tau * s + co - 1.0 - s * s * 0.5) / tau3;
        let x5 = (-co + 1.0 - s * s * 0.5) / tau3;
        let y5 = (s - tau * 0.5 - s2 * 0.25) / tau3;
        [a * t2, -b * t2, -x4 * t3, x5 * t3, y4 * t3, -y5 * t3]
    }
}

/// Below this m1 a closed form by the separatrix is built only under √F ≤ ln(f64::MAX) (below
/// about 1e-205 the phase's Carlson integrals overflowed before they were scaled, which kept
/// such rods out of the closed form).
const DEEP_SEPARATRIX_M1: f64 = 1e-200;

/// Below this m1 (near the separatrix) the closed form's J error is estimated by
/// [`SEPARATRIX_J_ULPS`]/√m1 instead of 1/m1: with m's derivatives taken from m1's (see
/// `complement_near_one`) the remaining loss grows like 1/√m1 — the rod lingers by the
/// hyperbolic straight equilibrium over a phase ≈ K(m) ≈ ln(4/√m1), where its J entries are
/// e^{−K} ≈ √m1 times the O(1) elliptic pieces they are differences of.
pub(crate) const SEPARATRIX_M1: f64 = 1e-7;
/// Near the separatrix (m1 < [`SEPARATRIX_M1`]) the relative J error of the closed form is
/// estimated as ε·s(ρ)·(1/m + this/√m1). Measured against the rigorous 320-bit reference
/// (scripts/gen_separatrix_truth.py, 940 rods with m1 from 1e-30 to 1e-7 and ρ from 0.1 to
/// 100) and the double-double series (18,000 rods, ρ ≤ 12): error·√m1/(ε·s(ρ)) ≤ 0.42 (ρ ≤ 12)
/// and ≤ 0.71 (ρ ≥ 28); this is that, ×3.
pub(crate) const SEPARATRIX_J_ULPS: f64 = 2.0;
/// Constant of the phase factor of the separatrix J estimate
/// (`Closed::separatrix_phase_factor`): against the 320-bit references (427 rods of
/// tests/data/separatrix_truth*.jsonl with m1 < 1e-7) the closed form's J error is within
/// e^{2.8}·e^{d−K} = 16·e^{d−K} of the phase-blind estimate wherever it is above 1e-13; ×3.
pub(crate) const SEPARATRIX_PHASE_C: f64 = 50.0;
/// Largest √‖F‖ of those references: beyond, the phase-blind estimate stands.
const SEPARATRIX_PHASE_MAX_ROOT_F: f64 = 100.0;
/// Largest phase-blind J estimate that the phase factor may lower: rods whose ends sit in a
/// lingering phase with m1 ≲ 1e-25 (estimates of 1e-3) keep the phase-blind estimate, and with
/// it the double-double series or a refusal. One such reference rod (a4 = 6603, m1 = 3.5e-26,
/// estimate 2.4e-3) has a J within 1e-8 of the 320-bit reference at its phase, but the stability
/// scan's verdict on it is wrong: its forward map stays refused.
const SEPARATRIX_PHASE_MAX_BLIND: f64 = 1e-5;
/// Largest (a5² + a3²|a3²/4 + a4|)/(F α3) (the terms of m1 before they cancel) for which the
/// separatrix estimates apply: the rigorous-reference samples (little bending under a force)
/// reach 8.3e-7.
pub(crate) const SEPARATRIX_TERMS_MAX: f64 = 1e-6;
/// Near the separatrix the pose error is estimated with this in place of 1/m1 (measured ≤ 226 ε
/// for ρ ≥ 1 and ≤ 374 ε/ρ below, same samples: 16·(1 + 40) covers both ×2.9).
const SEPARATRIX_POSE_LOSS: f64 = 40.0;
/// Largest J error estimate accepted from the closed form near the separatrix when no
/// certified fallback exists (√‖F‖ beyond what the double-double series certifies): ten times
/// inside the 1e-6 that issue 9 asks of J, instead of [`CLOSED_J_TOLERANCE`]'s hundred.
pub(crate) const CLOSED_J_LAST_RESORT: f64 = 1e-7;
/// Largest √‖F‖ for which the double-double series is certified: rounding and truncation
/// (≤ 1e-22 per step) made near the hyperbolic straight equilibrium grow by up to e^{√‖F‖},
/// ≤ 5e-11 here. Beyond (measured: tips off by 0.25 and J by 100 % at √‖F‖ ≈ 50–100 and
/// m1 < 1e-19), the closed form answers where its estimate holds, or where it agrees with a
/// tighter double-double series (`planar::cross_checked_tip`), else a clear error.
pub(crate) const SERIES_DD_MAX_ROOT_F: f64 = 27.0;
/// Below this m (cases I and II, above the [`Case::SmallForce`] switch) the dual-number
/// derivatives lose ≈ 1e-16/m to cancellation in ∂(a4/F, a5/F, √α3)/∂a (near-straight rods
/// under compression, near-circles); det J, whose x-row is then O(√m), cannot be trusted.
pub(crate) const SMALL_M: f64 = 1e-6;
/// Case I at small m (a nearly straight rod oscillating about the force under compression):
/// J's relative error (Frobenius) is at most ε·this·max(1, ρ)/√m, far below the ε/m of the
/// general estimate (its x row, O(√m), is not accurate relative to itself: det J still needs
/// the series, see [`Closed::det_needs_series`]). Measured against the double-double series on
/// 3,000 log-scale rods (a4 from −1 to −1e4, |a3|, |a5| from 1e-6 to 1, m from 4e-17 to 0.16):
/// error·√m/(ε·max(1, ρ)) ≤ 4.1, its tip within 1.2e-15; this is that, ×3.
pub(crate) const SMALL_M_I_ULPS: f64 = 12.0;
/// Beyond max(a3², |a4|, |a5|) > 1e6 the ODE fallback is too slow (≈ √1e6 wavelengths) and the
/// closed form's J is kept in every regime.
const REFERENCE_MAX_SCALE: f64 = 1e6;
/// Case III: the first-order δ terms grow like e^|Γ|; beyond this |Γ| they cancel badly.
const SEPARATRIX_GAMMA: f64 = 8.0;

/// Largest error accepted from the f64 series near the separatrix (ε·e^{√‖F‖}); beyond it the
/// double-double series runs (√‖F‖ ≳ 12). Two decades below the 1e-9 tip accuracy target, for
/// the few hundred steps' worth of accumulated rounding.
const SERIES_F64_ERROR: f64 = 1e-11;

/// How the closed form must be replaced where its error estimate fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SeriesNeed {
    /// The closed form is accurate.
    None,
    /// Cancellation in the closed form only: the f64 series is accurate.
    Cancellation,
    /// Near the separatrix: exponential growth of rounding; double-double series.
    IllConditioned,
}

/// Relative accuracy of the closed form's J entries away from its thin regimes (oracle agreement
/// 8.2e-11 relative over 2000 box cases, rounded up).
pub(crate) const CLOSED_J_REL: f64 = 1e-10;

/// Largest estimated relative error of J ([`Closed::jacobian_rel_error`], cancellation part)
/// for which the closed form is used; beyond, the Taylor series (exact to ~1e-14). 100× inside
/// the 1e-6 that issue 9 asks of J, so that det J and Newton steps built on it keep their
/// digits.
pub(crate) const CLOSED_J_TOLERANCE: f64 = 1e-8;

/// Growth of the J cancellation loss on gently bent rods, ε·(1/m + 1/m1)·K/ρ³: measured against
/// the Taylor series on 400,000 log-scale rods with ρ ∈ [0.03, 4] (issue 9 sample), the worst
/// ratio error/(ε·(1/m + 1/m1)/ρ³) is 170–330 in every ρ bucket; K is that, ×3.
pub(crate) const CANCELLATION_RHO3: f64 = 1000.0;

/// Pose error of the closed form in ulps: measured ≤ 7·ε·(1 + 1/m + 1/m1) for ρ ≥ 0.5 and
/// ≤ 6·ε·(1 + 1/m + 1/m1)/ρ below (same sample, against the Taylor series and, where the f64
/// series is itself ill-conditioned, the double-double one); ×2.
pub(crate) const CLOSED_POSE_ULPS: f64 = 16.0;

/// Largest phase |Γ| = r + |φ| of the Jacobi functions the closed form accepts: their
/// argument carries an absolute rounding error ~ε|Γ|, which at 1e9 is ~1e-7 rad, the edge of
/// the 1e-6 accuracy the solvers need; beyond, the rod is left to the fallbacks.
const MAX_PHASE: f64 = 1e9;

/// The invariants of a rod's base wrench that select and parametrise its case (FINDINGS §2):
/// F = ‖(a4, a5)‖, F ± a4 (each without cancellation), α3 = a3² + 2(F + a4) and
/// λ4 = a5² − a3²(a3²/4 + a4).
#[derive(Clone, Copy)]
struct Invariants<T> {
    f: T,
    fp: T,
    fm: T,
    alpha3: T,
    lambda4: T,
}

/// A J error estimate floored at the base accuracy [`CLOSED_J_REL`] (infinite when not finite).
fn floored_j_error(e: f64) -> f64 {
    if e.is_finite() {
        e.max(CLOSED_J_REL)
    } else {
        f64::INFINITY
    }
}

impl<T: Real> Closed<T> {
    /// A-priori estimate of the relative error (Frobenius) of J(t, a): the base accuracy
    /// [`CLOSED_J_REL`], or, when larger, the cancellation loss ε·(1/m + L(m1))·s(ρ) of cases I
    /// and II, with L = 1/m1, or [`SEPARATRIX_J_ULPS`]/√m1 near the separatrix (m1 <
    /// [`SEPARATRIX_M1`]); 1/m is the loss at small m ([`SMALL_M`]) and s(ρ) = max(1,
    /// [`CANCELLATION_RHO3`]/ρ³) the growth of that loss on gently bent rods of curvature scale
    /// ρ; [`Case::SmallForce`] adds its truncation O(m). At t < 1: the part [0, t] of the rod
    /// is a rod of length t, i.e. a unit rod of curvature scale ρt with the same m and m1, so
    /// s(ρ) becomes s(ρt) (J(t) of a strongly bent rod is as hard near t = 0 as J(1) of a
    /// gently bent one).
    pub fn jacobian_rel_error_at(&self, t: f64) -> f64 {
        let e = match self.case {
            Case::I | Case::II => self.cancellation_loss(t) * f64::EPSILON,
            Case::SmallForce => self.rho_spread(t) * f64::EPSILON + self.m.re(),
            _ => 0.0,
        };
        floored_j_error(e)
    }

    /// The estimate of J(1)'s relative error that decides whether the closed form answers it:
    /// [`Self::jacobian_rel_error_at`] at t = 1 with the phase factor of
    /// [`Self::end_cancellation_loss`] (cases I and II; the phase-blind estimate otherwise).
    #[cfg(test)]
    pub(crate) fn end_jacobian_rel_error(&self) -> f64 {
        match self.case {
            Case::I | Case::II => floored_j_error(self.end_cancellation_loss() * f64::EPSILON),
            _ => self.jacobian_rel_error_at(1.0),
        }
    }

    /// The phase-blind estimate of J(1)'s relative error in the scalar's own unit roundoff
    /// ([`Real::EPSILON`]): for the double-double closed form, whose rounding follows the same
    /// cancellation model at 2⁻¹⁰⁴ (measured in `planar::extended`).
    pub(crate) fn end_jacobian_rel_error_own(&self) -> f64 {
        floored_j_error(self.cancellation_loss(1.0) * T::EPSILON)
    }

    /// The phase-blind estimate of J(t)'s relative error (Frobenius) in the scalar's own unit
    /// roundoff, floored at [`CLOSED_J_REL`] scaled to it (the double-double closed form's
    /// stability scan).
    pub(crate) fn jacobian_rel_error_own_at(&self, t: f64) -> f64 {
        let floor = CLOSED_J_REL * (T::EPSILON / f64::EPSILON);
        let e = self.cancellation_loss(t) * T::EPSILON;
        if e.is_finite() {
            e.max(floor)
        } else {
            f64::INFINITY
        }
    }

    /// (1/m + L(m1))·s(ρt) for cases I and II, s(ρt) alone otherwise (in units of ε).
    fn cancellation_loss(&self, t: f64) -> f64 {
        self.cancellation_loss_with(t, self.loss_m1)
    }

    /// [`Self::cancellation_loss`] of J(1) alone, where the rod's end is near a loop
    /// ([`Self::separatrix_phase_factor`]): the estimate that decides whether the closed form
    /// answers q(1) and J(1). The stability scans keep the phase-blind estimate at every t:
    /// det J(t) cancels beyond J's own error, and the phase factor was measured on J(1) only.
    fn end_cancellation_loss(&self) -> f64 {
        let blind = self.cancellation_loss(1.0);
        // Tested cheapest first: every closed-form rod asks this (`needs_series`).
        if self.near_separatrix_weakly_bent()
            && blind * f64::EPSILON <= SEPARATRIX_PHASE_MAX_BLIND
            && crate::scalar::fast_hypot(self.a4.re(), self.a5.re()).sqrt()
                <= SEPARATRIX_PHASE_MAX_ROOT_F
        {
            self.cancellation_loss_with(1.0, self.loss_m1 * self.separatrix_phase_factor(1.0))
        } else {
            blind
        }
    }

    /// (1/m + `loss_m1`)·s(ρt) for cases I and II (see [`Self::cancellation_loss`]).
    fn cancellation_loss_with(&self, t: f64, loss_m1: f64) -> f64 {
        let loss = match self.case {
            Case::I => {
                let small_m = SMALL_M_I_ULPS * (self.rho * t).max(1.0) * self.inv_sqrt_m;
                loss_m1 + self.inv_m.min(small_m)
            }
            Case::II => loss_m1 + self.inv_m,
            _ => 1.0,
        };
        loss * self.rho_spread(t)
    }

    /// min(1, [`SEPARATRIX_PHASE_C`]·e^{d−K}) near the separatrix, d the distance of the
    /// phase Γ(t) = r t + φ from the nearest loop centre (Γ ≡ 0 mod 2K, where cn and dn peak).
    /// The 1/√m1 ≈ e^K/4 loss of [`SEPARATRIX_J_ULPS`] is that of a rod whose end lingers
    /// half-way between two loops, where its J entries have decayed to e^{−K} of the O(1)
    /// elliptic pieces they are differences of; an end at distance d from a loop has decayed by
    /// e^{−d} only.
    fn separatrix_phase_factor(&self, t: f64) -> f64 {
        let k = self.landen.k().re();
        let phase = (self.r * t + self.phi).re().rem_euclid(2.0 * k);
        let d = phase.min(2.0 * k - phase);
        let factor = (SEPARATRIX_PHASE_C * (d - k).exp()).min(1.0);
        if factor.is_nan() {
            1.0
        } else {
            factor
        }
    }

    /// Whether det J(t) must come from the series although J may not: at small m (cases I and
    /// II, m < [`SMALL_M`]) J's x row is O(√m) and not accurate relative to itself.
    pub fn det_needs_series(&self) -> bool {
        matches!(self.case, Case::I | Case::II) && self.m.re() < SMALL_M
    }

    /// Near the separatrix with little bending: m1 < [`SEPARATRIX_M1`] and the terms of λ4
    /// small too (c·m1 ≤ [`SEPARATRIX_TERMS_MAX`], c = `lambda4_spread`), the regime where the
    /// separatrix estimates were measured. O(1) parameters tuned onto the separatrix (a = (2, 3,
    /// 4 + 1e-8): terms of λ4 ~ 16, c·m1 = 0.16) keep the 1/m1 estimate, hence the series.
    fn near_separatrix_weakly_bent(&self) -> bool {
        self.m1 < SEPARATRIX_M1 && self.lambda4_spread * self.m1 <= SEPARATRIX_TERMS_MAX
    }

    /// The m1 part of J's cancellation loss: 1/m1, or near the separatrix with little bending
    /// [`SEPARATRIX_J_ULPS`]/√m1.
    fn m1_loss_j(&self) -> f64 {
        if self.near_separatrix_weakly_bent() {
            SEPARATRIX_J_ULPS / self.m1.sqrt()
        } else {
            1.0 / self.m1
        }
    }

    /// The m1 part of the pose's loss: 1/m1, or near the separatrix with little bending
    /// [`SEPARATRIX_POSE_LOSS`].
    fn m1_loss_pose(&self) -> f64 {
        if self.near_separatrix_weakly_bent() {
            SEPARATRIX_POSE_LOSS
        } else {
            1.0 / self.m1
        }
    }

    /// s(ρt) = max(1, [`CANCELLATION_RHO3`]/(ρt)³), ρ = max(|a3|, √F): the closed form's
    /// quantities are O(1) in the rod's own scale, while the entries of J of a gently bent rod
    /// are O(ρ)..O(ρ³) smaller than the terms they are differences of.
    fn rho_spread(&self, t: f64) -> f64 {
        let rho = self.curvature_scale() * t;
        (CANCELLATION_RHO3 / (rho * rho * rho)).max(1.0)
    }

    /// ρ = max(|a3|, √F), the rod's curvature scale.
    fn curvature_scale(&self) -> f64 {
        self.rho
    }

    /// A-priori bound on the absolute error of the pose (x, y, θ) at any t ∈ [0, 1]:
    /// [`CLOSED_POSE_ULPS`]·ε·(1 + (1/m + 1/m1))·max(1, 1/ρ) (cases I and II; the other cases
    /// without the m terms).
    pub fn pose_abs_error(&self) -> f64 {
        let rho = self.curvature_scale();
        let loss = match self.case {
            Case::I | Case::II => self.m1_loss_pose() + 1.0 / self.m.re(),
            _ => 0.0,
        };
        CLOSED_POSE_ULPS * T::EPSILON * (1.0 + loss) * rho.recip().max(1.0)
    }

    /// True when J (and det J) from this closed form may be off by more than
    /// [`CLOSED_J_TOLERANCE`]: where its cancellation estimate (`jacobian_rel_error_at`)
    /// exceeds it (near the separatrix by 2/√m1, at small m by 1/m, on gently bent rods by
    /// 1/ρ³), at small m (1e-6 > m: near-straight rods under compression, near-circles above
    /// the small-force switch) and in case III with |Γ| > 8 somewhere on [0, 1]. Callers then
    /// take the pose, J and the stability test from the Taylor series (FINDINGS §4: "fall back
    /// to an ODE"), unless max(a3², |a4|, |a5|) > 1e6; see `needs_series` for which one.
    pub fn needs_reference(&self) -> bool {
        self.needs_series() != SeriesNeed::None
    }

    /// Why (and how) the closed form must be replaced by the series: near the separatrix the
    /// rod lingers by the hyperbolic straight equilibrium, where rounding grows exponentially
    /// (ill-conditioned: double-double series); at small m the loss is plain cancellation in the
    /// closed form (f64 series).
    ///
    /// Near the separatrix under a force beyond what the double-double series certifies
    /// (√‖F‖ > [`SERIES_DD_MAX_ROOT_F`]) the closed form is kept while its estimate is within
    /// [`CLOSED_J_LAST_RESORT`]; beyond, `IllConditioned` leads to a cross-check of the closed
    /// form against a tighter double-double series, which answers or refuses clearly.
    pub fn needs_series(&self) -> SeriesNeed {
        if !self.needs_reference_by_estimate() {
            SeriesNeed::None
        } else if self.needs_precise_series() {
            let root_f = crate::scalar::fast_hypot(self.a4.re(), self.a5.re()).sqrt();
            if root_f > SERIES_DD_MAX_ROOT_F
                && matches!(self.case, Case::I | Case::II)
                && self.end_cancellation_loss() * f64::EPSILON <= CLOSED_J_LAST_RESORT
            {
                SeriesNeed::None
            } else {
                SeriesNeed::IllConditioned
            }
        } else {
            SeriesNeed::Cancellation
        }
    }

    /// Whether a series standing in for this closed form must be the double-double one: near
    /// the separatrix, where f64 rounding grows like e^{√‖F‖} beyond [`SERIES_F64_ERROR`].
    pub fn needs_precise_series(&self) -> bool {
        (self.case == Case::III || self.m1 < SEPARATRIX_M1)
            && self.rounding_amplification() * f64::EPSILON > SERIES_F64_ERROR
    }

    /// Growth of a rounding error made along the rod near the separatrix: the linearisation
    /// about the hyperbolic straight equilibrium grows like e^{√‖F‖ t}, so at most e^{√‖F‖}
    /// over the unit rod.
    fn rounding_amplification(&self) -> f64 {
        crate::scalar::fast_hypot(self.a4.re(), self.a5.re())
            .sqrt()
            .exp()
    }

    /// Whether the closed form's J(1) is within `j_tolerance` (relative) by its own estimate, in
    /// the cases where that estimate is the cancellation one (I and II, m not tiny): a looser
    /// bound than [`CLOSED_J_TOLERANCE`], for uses that need fewer digits.
    pub(crate) fn accurate_within(&self, j_tolerance: f64) -> bool {
        let (a3, a4, a5) = (self.a3.re(), self.a4.re(), self.a5.re());
        (a3 * a3).max(a4.abs()).max(a5.abs()) <= REFERENCE_MAX_SCALE
            && matches!(self.case, Case::I | Case::II)
            && (self.case == Case::I || self.m.re() >= SMALL_M)
            && self.end_cancellation_loss() * f64::EPSILON <= j_tolerance
    }

    fn needs_reference_by_estimate(&self) -> bool {
        let (a3, a4, a5) = (self.a3.re(), self.a4.re(), self.a5.re());
        if (a3 * a3).max(a4.abs()).max(a5.abs()) > REFERENCE_MAX_SCALE {
            // the ODE would need too many steps; keep the closed form's J
            return false;
        }
        match self.case {
            // Case I at small m: its own estimate ([`SMALL_M_I_ULPS`]) decides.
            Case::I => self.end_cancellation_loss() * f64::EPSILON > CLOSED_J_TOLERANCE,
            Case::II => {
                self.m.re() < SMALL_M
                    || self.end_cancellation_loss() * f64::EPSILON > CLOSED_J_TOLERANCE
            }
            Case::SmallForce => self.rho_spread(1.0) * f64::EPSILON > CLOSED_J_TOLERANCE,
            Case::III => {
                let (p, r) = (self.phi.re(), self.r.re());
                p.abs().max((p + r).abs()) > SEPARATRIX_GAMMA
            }
            _ => false,
        }
    }

    /// The exactly straight rod's form (case [`Case::Straight`]), every field set: the start
    /// of [`Self::new`] and [`Self::complete`], which fill in the others' constants.
    pub(crate) fn straight(a3: T, a4: T, a5: T) -> Self {
        let zero = T::from_f64(0.0);
        let one = T::from_f64(1.0);
        let eps = if a3.re() < 0.0 { -1.0 } else { 1.0 };
        let dummy_landen = Duplication::placeholder();
        let dummy_j = JacobiValues {
            sn: zero,
            cn: one,
            dn: one,
            am: zero,
            zm: zero,
        };
        Self {
            case: Case::Straight,
            eps,
            a3,
            a4,
            a5,
            chat: one,
            shat: zero,
            r: zero,
            inv_r: zero,
            zcoef: zero,
            b2coef: zero,
            y0: zero,
            phi: zero,
            sqa3: zero,
            sqm: one,
            m: zero,
            lin: zero,
            m1: 1.0,
            lambda4_spread: 1.0,
            rho: a3
                .re()
                .abs()
                .max(crate::scalar::fast_hypot(a4.re(), a5.re()).sqrt()),
            loss_m1: 0.0,
            inv_m: 0.0,
            inv_sqrt_m: 0.0,
            landen: dummy_landen,
            j0: dummy_j,
            th0: zero,
            e0: zero,
            phase_unknown: false,
            additive: false,
            _p: (),
        }
    }

    /// Precomputes the closed form for a = (a3, a4, a5) (FINDINGS §2 table and phase).
    /// Returns None when an intermediate quantity is not finite (overflow).
    pub fn new(a3: T, a4: T, a5: T) -> Option<Self> {
        Self::build(a3, a4, a5, true)
    }

    /// As [`Self::new`], for the pose alone ([`Self::complete`] without the phase; the hot
    /// paths call that directly).
    #[cfg(test)]
    pub fn new_phase_free(a3: T, a4: T, a5: T) -> Option<Self> {
        Self::build(a3, a4, a5, false)
    }

    /// Whether this form was built without its phase ([`Self::new_phase_free`]).
    #[cfg(test)]
    pub(crate) fn phase_unknown(&self) -> bool {
        self.phase_unknown
    }

    /// This form with Γ placed directly at r t + φ, not by the addition theorems (the
    /// reference the addition theorems are tested against).
    #[cfg(test)]
    pub(crate) fn with_direct_poses(mut self) -> Self {
        assert!(
            !self.phase_unknown,
            "a form without its phase has no direct poses"
        );
        self.additive = false;
        self
    }

    fn build(a3: T, a4: T, a5: T, with_phase: bool) -> Option<Self> {
        let mut s = Self::straight(a3, a4, a5);
        s.complete(a3, a4, a5, with_phase).then_some(s)
    }

    /// Completes the straight rod's form from [`Self::straight`] into the form for a, in
    /// place: false when an intermediate quantity is not finite (the form is then not to be
    /// used). Without the phase (`with_phase` false: for the pose alone, no stability scan,
    /// energy, curvature or theorem, which need φ), in f64 and dual numbers where
    /// m ∈ [[`PHASE_FREE_MIN_M`], 1 − [`PHASE_FREE_MIN_M1`]] (cases I and II), the phase
    /// φ = F(am φ | m) is not computed (Carlson's R_F and R_D, ~20 % of q(1) and of q + J in
    /// time) and `pose` places Γ = r t + φ by the addition theorems from the base's sn, cn, dn,
    /// which are algebraic in a; elsewhere it is. A form built with its phase places its
    /// poses by the addition theorems there too (not the curvature's), so both give the same
    /// bits.
    /// The hot paths build the form in their own variable this way,
    /// `let mut c = Closed::straight(a3, a4, a5); if c.complete(a3, a4, a5, true) { .. }`:
    /// [`Self::new`]'s `Option` costs a copy of the whole form out of the builder (~450 bytes
    /// in f64, 5 % of q(1); ~1 KB in dual numbers).
    pub(crate) fn complete(&mut self, a3: T, a4: T, a5: T, with_phase: bool) -> bool {
        self.complete_or_none(a3, a4, a5, with_phase).is_some()
    }

    fn complete_or_none(&mut self, a3: T, a4: T, a5: T, with_phase: bool) -> Option<()> {
        let s = self;
        let (a3r, a4r, a5r) = (a3.re(), a4.re(), a5.re());
        if a3r == 0.0 && a5r == 0.0 {
            return Some(());
        }
        if a4r == 0.0 && a5r == 0.0 {
            s.case = Case::Circle;
            return Some(());
        }
        // F without overflow or underflow of the squares: scaled by max(|a4|, |a5|) outside
        // [1e-150, 1e150] only (the divisions sat on q(1)'s chain of dependent operations).
        let scale = a4r.abs().max(a5r.abs());
        let f = if (1e-150..1e150).contains(&scale) {
            (a4 * a4 + a5 * a5).sqrt()
        } else {
            let (u4, u5) = (a4 / scale, a5 / scale);
            (u4 * u4 + u5 * u5).sqrt() * scale
        };
        // F ± a4 without cancellation (FINDINGS §2).
        let (fp, fm) = if a4r >= 0.0 {
            let fp = f + a4;
            (fp, a5 * a5 / fp)
        } else {
            let fm = f - a4;
            (a5 * a5 / fm, fm)
        };
        let a3s = a3 * a3;
        let alpha3 = a3s + fp * 2.0;
        let lambda4 = a5 * a5 - a3s * (a3s * 0.25 + a4);
        // Double-double arithmetic already carries λ4 to ~2⁻¹⁰⁴ of its terms.
        let lambda4 = if T::EXTENDED {
            lambda4
        } else {
            lambda4.with_re(lambda4_value(a3r, a4r, a5r))
        };
        s.chat = a4 / f;
        s.shat = a5 / f;
        s.sqa3 = alpha3.sqrt();
        let l4 = lambda4.re();
        s.lambda4_spread =
            ((a5r * a5r + a3r * a3r * (a3r * a3r * 0.25 + a4r).abs()) / l4.abs()).max(1.0);
        if !(f.re().is_finite() && alpha3.re().is_finite() && l4.is_finite()) {
            return None;
        }
        let invariants = Invariants {
            f,
            fp,
            fm,
            alpha3,
            lambda4,
        };
        if l4 > 0.0 {
            s.init_case_i(&invariants, with_phase)?;
        } else if l4 < 0.0 {
            s.init_case_ii(&invariants, with_phase)?;
            if s.case == Case::SmallForce {
                return Some(());
            }
        } else {
            s.init_case_iii(&invariants);
        }
        if matches!(s.case, Case::I | Case::II)
            && s.m1 < DEEP_SEPARATRIX_M1
            && f.re().sqrt() > f64::MAX.ln()
        {
            // Deep by the separatrix under a force beyond f64's e^{√F}: J overflows whatever
            // the form, and the loops outnumber what the phase resolves (left to the refusal
            // of the fallbacks).
            return None;
        }
        if matches!(s.case, Case::I | Case::II) {
            let m = s.m.re();
            s.loss_m1 = s.m1_loss_j();
            s.inv_m = m.recip();
            s.inv_sqrt_m = m.sqrt().recip();
        }
        s.is_valid().then_some(())
    }

    /// Phase pair (sn φ, cn φ) of cases I and III: cn φ = |a3|/√α3,
    /// sn φ = sgn(ε a5)√(2(F+a4)/α3).
    fn phase_i(&self, fp: T, fm: T, alpha3: T) -> (T, T) {
        let (a3, a5, eps) = (self.a3, self.a5, self.eps);
        let c = a3 * eps / self.sqa3;
        let sn = if self.a4.re() < 0.0 {
            a5 * eps * (fm * alpha3 / 2.0).sqrt().recip()
        } else {
            let sg = if a5.re() < 0.0 { -eps } else { eps };
            (fp * 2.0 / alpha3).sqrt() * sg
        };
        (sn, c)
    }

    /// Case I (λ4 > 0, FINDINGS §2): parameter m = α3/(4F), r = √F.
    fn init_case_i(&mut self, inv: &Invariants<T>, with_phase: bool) -> Option<()> {
        let Invariants {
            f,
            fp,
            fm,
            alpha3,
            lambda4,
        } = *inv;
        let zero = T::from_f64(0.0);
        self.case = Case::I;
        let m1 = lambda4 / (f * alpha3);
        let m = complement_near_one(alpha3 / (f * 4.0), m1);
        // Built in place: a local moved into the field was a ~200-byte memcpy.
        self.landen = Duplication::new(m, m1);
        let landen = &self.landen;
        if !landen.converged() {
            return None;
        }
        let (sn, cn) = self.phase_i(fp, fm, alpha3);
        self.additive = phase_free_allowed::<T>(m.re(), m1.re());
        self.phase_unknown = !with_phase && self.additive;
        let (phi, zm0) = if self.phase_unknown {
            (zero, zero)
        } else {
            inverse_phase_zeta(sn, cn, m1, landen.k(), landen.d_over_k())
        };
        self.r = f.sqrt();
        self.phi = phi;
        self.m = m;
        self.m1 = m1.re();
        self.sqm = m.sqrt();
        self.lin = m1 - m * landen.q();
        let dn = (m1 + m * cn * cn).sqrt();
        self.j0 = JacobiValues {
            sn,
            cn,
            dn,
            am: zero, // unused in case I
            zm: zm0,
        };
        // θ0/(2ε) = atan2(√m sn φ, dn φ) is folded into the single atan2 of `pose`.
        self.inv_r = self.r.recip();
        self.zcoef = m * self.inv_r * 2.0;
        self.b2coef = -self.sqm * self.inv_r;
        self.y0 = self.sqm * sn;
        Some(())
    }

    /// Case II (λ4 < 0, FINDINGS §2): parameter m = 4F/α3, r = √α3 / 2; tiny m is the
    /// small-force series ([`Case::SmallForce`]).
    fn init_case_ii(&mut self, inv: &Invariants<T>, with_phase: bool) -> Option<()> {
        let Invariants {
            f,
            fp,
            fm,
            alpha3,
            lambda4,
        } = *inv;
        let (a5, eps) = (self.a5, self.eps);
        let a4r = self.a4.re();
        let sqa3 = self.sqa3;
        self.case = Case::II;
        let m = f * 4.0 / alpha3;
        if m.re() < SMALL_FORCE_M {
            self.case = Case::SmallForce;
            // Not used by the small-force formulas: kept for the error estimate (J is exact
            // to O(m) there).
            self.m = m;
            return Some(());
        }
        let m1 = -lambda4 * 4.0 / (alpha3 * alpha3);
        let m = complement_near_one(m, m1);
        self.landen = Duplication::new(m, m1);
        let landen = &self.landen;
        if !landen.converged() {
            return None;
        }
        let two_f = f * 2.0;
        let (sn, cn) = if a4r <= 0.0 {
            (a5 * eps / (two_f * fm).sqrt(), (fm / two_f).sqrt())
        } else {
            ((fp / two_f).sqrt(), a5 * eps / (two_f * fp).sqrt())
        };
        self.additive = phase_free_allowed::<T>(m.re(), m1.re());
        self.phase_unknown = !with_phase && self.additive;
        let (phi, zm0) = if self.phase_unknown {
            let zero = T::from_f64(0.0);
            (zero, zero)
        } else {
            inverse_phase_zeta(sn, cn, m1, landen.k(), landen.d_over_k())
        };
        self.r = sqa3 * 0.5;
        self.phi = phi;
        self.m = m;
        self.m1 = m1.re();
        self.lin = -landen.q();
        let dn = (m1 + m * cn * cn).sqrt();
        // φ ∈ (−2K, 2K) ⇒ am φ = atan2(sn, cn) ∈ (−π, π)
        let am = sn.atan2_fast(cn);
        self.j0 = JacobiValues {
            sn,
            cn,
            dn,
            am,
            zm: zm0,
        };
        self.th0 = am;
        self.inv_r = self.r.recip();
        self.zcoef = self.inv_r * 2.0;
        self.b2coef = (m * self.r).recip();
        Some(())
    }

    /// Case III (λ4 = 0, the separatrix): the m → 1 limit with its first-order term in
    /// δ = 1 − m carried for the derivatives (FINDINGS §2 table).
    fn init_case_iii(&mut self, inv: &Invariants<T>) {
        let Invariants {
            f,
            fp,
            fm,
            alpha3,
            lambda4,
        } = *inv;
        let one = T::from_f64(1.0);
        let zero = T::from_f64(0.0);
        self.case = Case::III;
        // δ = 1 − m_I = λ4/(F α3): value 0, derivative carried (FINDINGS §2 table).
        let delta = lambda4 / (f * alpha3);
        let (sn, cn) = self.phase_i(fp, fm, alpha3);
        let ratio = sn / cn;
        let phi0 = ratio.asinh();
        // F(ψ|1 − δ) ≈ asinh(tan ψ) − (δ/4)(tan ψ sec ψ − asinh(tan ψ)).
        let phi = phi0 - delta * 0.25 * (ratio / cn - phi0);
        self.r = f.sqrt();
        self.phi = phi;
        self.m = delta;
        self.sqm = one - delta * 0.5;
        let (sn0, cn0, dn0, e0) = near_one(phi, delta);
        self.j0 = JacobiValues {
            sn: sn0,
            cn: cn0,
            dn: dn0,
            am: zero,
            zm: zero,
        };
        self.th0 = (self.sqm * sn0).atan2(dn0);
        self.e0 = e0;
    }

    /// False when a field of the constructed rod is not finite or the phase is lost. (Takes
    /// `&self`: a by-value check copied the ~1 kB dual-number form once more per construction.)
    fn is_valid(&self) -> bool {
        let s = self;
        let fields = [
            s.phi, s.r, s.sqa3, s.chat, s.shat, s.lin, s.sqm, s.th0, s.e0, s.j0.sn, s.j0.cn,
            s.j0.dn, s.j0.zm,
        ];
        if s.r.re() + s.phi.re().abs() > MAX_PHASE {
            return false;
        }
        if !fields.iter().all(|v| v.re().is_finite())
            || s.r.re().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        {
            return false;
        }
        true
    }

    /// A t_free such that a theorem rules out any conjugate point on (0, t_free), so that det J
    /// cannot vanish there whatever the rounding of a scan: infinite where there is none at
    /// all, 0 where nothing is known. Sachkov, "Conjugate points in Euler's elastic problem"
    /// (J. Dyn. Control Syst. 14, 2008; arXiv:0705.1003): non-inflectional elasticae (case II
    /// and its small-force limit, κ ∝ dn > 0) and circles have no conjugate point, and on an
    /// inflectional one (case I, κ ∝ cn Γ) the first conjugate point lies after its first
    /// inflection point (Γ = K(2j + 1), t > 0).
    ///
    /// The case must be sure (λ4 far above its rounding, [`THEOREM_MAX_SPREAD`]); the separatrix
    /// (case III, λ4 = 0 as computed) is left to the scan, since a λ4 rounded to zero may hide
    /// an inflectional rod. In case I the inflection is taken [`THEOREM_PHASE_MARGIN`] early for
    /// the rounding of φ and K. A rod starting exactly at an inflection point (a3 = 0) gets the
    /// next one: the conjugate time is continuous in the phase, and for a base just past an
    /// inflection the bound is that next one (checked on the 320-bit references).
    pub(crate) fn conjugate_free_until(&self) -> f64 {
        let (a3, sign_sure) = (self.a3.re(), self.case_is_sure());
        match self.case {
            Case::II | Case::SmallForce if sign_sure => f64::INFINITY,
            Case::Circle => f64::INFINITY,
            Case::I if sign_sure => {
                let (k, phi, r, margin) = self.phase_and_margin();
                let (below, above) = self.inflections_around_base();
                // a3 = 0: φ is an inflection, rounded to either side of it.
                let next = if a3 == 0.0 && phi - below > margin {
                    above + 2.0 * k
                } else {
                    above
                };
                let t = (next - phi - margin) / r;
                if t.is_finite() {
                    t.max(0.0)
                } else {
                    0.0
                }
            }
            _ => 0.0,
        }
    }

    /// A t_conj such that a theorem places a conjugate point on (0, t_conj]: on an
    /// inflectional rod (case I) the first conjugate point lies between its first and third
    /// inflection points (Sachkov 2008, as [`Self::conjugate_free_until`]). Infinite where
    /// nothing is known. The third inflection after the base is taken [`THEOREM_PHASE_MARGIN`]
    /// late for the rounding of φ and K, and one inflection later where the base lies within
    /// that margin before an inflection (φ rounded to the wrong side of it would miscount by
    /// one; a base exactly at an inflection, a3 = 0, counts the next one as first, the later
    /// of the two counts).
    pub(crate) fn conjugate_by(&self) -> f64 {
        if self.case != Case::I || !self.case_is_sure() {
            return f64::INFINITY;
        }
        let (k, phi, r, margin) = self.phase_and_margin();
        let (_, above) = self.inflections_around_base();
        let later = if above - phi <= margin { 6.0 } else { 4.0 };
        let t = (above + later * k + margin - phi) / r;
        if t.is_finite() {
            t
        } else {
            f64::INFINITY
        }
    }

    /// True when a theorem places a conjugate point on (0, 1] ([`Self::conjugate_by`]): the
    /// rod is unstable.
    pub(crate) fn conjugate_certain(&self) -> bool {
        self.conjugate_by() <= 1.0
    }

    /// The verdict a theorem gives, where one does: stable where no conjugate point can lie
    /// on (0, 1] ([`Self::conjugate_free`]), unstable where one must
    /// ([`Self::conjugate_certain`]).
    pub(crate) fn theorem_verdict(&self) -> Option<crate::StabilityVerdict> {
        if self.conjugate_free() {
            Some(crate::StabilityVerdict::Stable)
        } else if self.conjugate_certain() {
            Some(crate::StabilityVerdict::Unstable)
        } else {
            None
        }
    }

    /// K, φ, r (f64 values) and the margin [`THEOREM_PHASE_MARGIN`]·(|φ| + r + K) by which a
    /// bound on Γ is taken early for their rounding.
    fn phase_and_margin(&self) -> (f64, f64, f64, f64) {
        let (k, phi, r) = (self.landen.k().re(), self.phi.re(), self.r.re());
        (k, phi, r, THEOREM_PHASE_MARGIN * (phi.abs() + r + k))
    }

    /// True when λ4's sign, and so the case, is sure: its terms' squares of normal size
    /// (relative rounding) and λ4 far above its rounding ([`THEOREM_MAX_SPREAD`]).
    fn case_is_sure(&self) -> bool {
        let (a3, a4, a5) = (self.a3.re(), self.a4.re(), self.a5.re());
        let terms = a5 * a5 + a3 * a3 * (a3 * a3 * 0.25 + a4).abs();
        self.lambda4_spread < THEOREM_MAX_SPREAD && terms >= THEOREM_MIN_TERMS
    }

    /// True when no conjugate point can lie on (0, 1] ([`Self::conjugate_free_until`]).
    pub(crate) fn conjugate_free(&self) -> bool {
        self.conjugate_free_until() > 1.0
    }

    /// A t before which no conjugate point was ever seen: as [`Self::conjugate_free_until`],
    /// but in case I the measured bound Γ-span ≥ 2K whatever the phase (the theorem's first
    /// inflection can come arbitrarily soon after the base). Measured against the DOP853
    /// reference on 40 values of m × 200 phases (the smallest span 2K·(1 + ~0.2/K), tending to
    /// 2K as m → 1 with the base just before an inflection; exactly 4K below m ≈ 0.8) and on
    /// the 320-bit references (≥ 2K·1.0008). Not a theorem: it only tells the scan which signs
    /// of g within their error bound are rounding ([`super::stability`]), never a verdict.
    pub(crate) fn conjugate_span_bound(&self) -> f64 {
        let proven = self.conjugate_free_until();
        if self.case != Case::I || !self.case_is_sure() {
            return proven;
        }
        let (k, _, r, margin) = self.phase_and_margin();
        let t = (2.0 * k - margin) / r;
        if t.is_finite() {
            proven.max(t)
        } else {
            proven
        }
    }

    /// The t ∈ (0, 1) where Γ = K(2j + 1) (cases I and II; at most [`MAX_DIP_TIMES`], from the base): the
    /// inflection points (κ ∝ cn) or the straightest points between loops (κ ∝ dn), where
    /// they are needed: where a scan of this `spacing` in t samples Γ more coarsely than 1.
    /// Near the separatrix g has narrow dips there (width ~1 in Γ, the loops' scale, where the
    /// grid's quarter period is K/2): on 5 reference rods whose scanned margin was 12–74 %
    /// above the reference's, the dense minimum sat within 0.03 K of such a point.
    pub(crate) fn dip_times(&self, spacing: f64) -> DipTimes {
        let mut out = DipTimes::default();
        let (k, phi, r) = (self.landen.k().re(), self.phi.re(), self.r.re());
        if !matches!(self.case, Case::I | Case::II) || r * spacing <= 1.0 {
            return out;
        }
        let (_, mut gamma) = self.inflections_around_base();
        while out.len < MAX_DIP_TIMES {
            let t = (gamma - phi) / r;
            // NaN ends the loop too.
            if t.partial_cmp(&1.0) != Some(std::cmp::Ordering::Less) {
                break;
            }
            out.times[out.len] = t;
            out.len += 1;
            gamma += 2.0 * k;
        }
        out
    }

    /// Γ of the last point Γ = K(2j + 1) (case I: an inflection, cn Γ = 0) at or below the
    /// base's φ, and of the next one above it.
    fn inflections_around_base(&self) -> (f64, f64) {
        let (k, phi) = (self.landen.k().re(), self.phi.re());
        let below = k * (2.0 * ((phi - k) / (2.0 * k)).floor() + 1.0);
        (below, below + 2.0 * k)
    }

    /// A length in t over which the shape (and det J) changes appreciably: the half-period
    /// 2K/r of cn in Γ = r t + φ (I), the period 2K/r of dn (II), π/√F (III), π/|a3|
    /// (circle); 1 for the straight rod.
    pub fn wavelength(&self) -> f64 {
        let l = match self.case {
            Case::I | Case::II => 2.0 * self.landen.k().re() / self.r.re(),
            Case::III => std::f64::consts::PI / self.r.re(),
            Case::Circle | Case::SmallForce => std::f64::consts::PI / self.a3.re().abs(),
            Case::Straight => 1.0,
        };
        if l.is_finite() && l > 0.0 {
            l
        } else {
            1.0
        }
    }

    /// Curvature κ(t) = μ3(t) (FINDINGS §2 table).
    pub fn curvature(&self, t: f64) -> T {
        match self.case {
            Case::Straight => self.a3 * 0.0,
            Case::Circle => self.a3,
            Case::SmallForce => {
                // δμ3 = a4 (1 − cos τ)/c − a5 sin τ/c, τ = c t
                let c = self.a3;
                let (sn, cs) = (c * t).sin_cos();
                c + (self.a4 * (-cs + 1.0) - self.a5 * sn) / c
            }
            Case::I => {
                let j = self.landen.eval(self.r * t + self.phi, false);
                self.sqa3 * j.cn * self.eps
            }
            Case::II => {
                let j = self.landen.eval(self.r * t + self.phi, false);
                self.sqa3 * j.dn * self.eps
            }
            Case::III => {
                let (_, cn, _, _) = near_one(self.r * t + self.phi, self.m);
                self.sqa3 * cn * self.eps
            }
        }
    }

    /// ½∫₀¹κ² by the Jacobi zeta function, free of the cancellation of the identity
    /// λ2/2 − a4 x − a5 y on nearly straight rods. Case I, κ = ε√α3 cn(rt + φ|m):
    /// ½α3 [(Z(Γ1) − Z(φ))/(m r) + (1 − q)/2], from ∫cn² du = Z(u)/m + u(1 − D/K) (A&S 17.4.28,
    /// 16.26.1; D/K = (1 + q)/2). Case II, κ = ε√α3 dn, r = √α3/2: ½α3 [(Z(Γ1) − Z(φ))/r + m1 +
    /// m(1 − q)/2], from ∫dn² du = E(am u) = Z(u) + u E/K (A&S 17.4.28) with E/K = 1 − m D/K.
    /// None in the other cases.
    ///
    /// Returned with the size of its terms, ½α3[(K + |Z(Γ1)/m| + |Z(φ)/m|)·s/r + 1] with
    /// s = 1 (case I) or m (case II); Z/m is evaluated as u·D/K − D(u) with |u| ≲ K: its
    /// rounding is a few ulps of that, which near m = 1 with little bending is far above the
    /// energy itself (the terms cancel).
    pub fn energy_by_zeta_bounded(&self) -> Option<(f64, f64)> {
        let scale = match self.case {
            Case::I => 1.0,
            Case::II => self.m.re(),
            _ => return None,
        };
        let r = self.r.re();
        let zm1 = self.landen.eval(self.r + self.phi, false).zm.re();
        let zm0 = self.j0.zm.re();
        let q = self.landen.q().re();
        let alpha3 = self.sqa3.re() * self.sqa3.re();
        let linear = if self.case == Case::I {
            (1.0 - q) * 0.5
        } else {
            self.m1 + scale * (1.0 - q) * 0.5
        };
        let energy = 0.5 * alpha3 * (scale * (zm1 - zm0) / r + linear);
        let terms =
            0.5 * alpha3 * ((self.landen.k().re() + zm1.abs() + zm0.abs()) * scale / r + 1.0);
        Some((energy, terms))
    }

    /// Case I: (y, x) whose atan2 is θ/(2ε) at Γ from sn Γ, dn Γ: atan2(√m sn, dn) at Γ minus
    /// that at the base, as one rotated pair (x0, x1 = dn > 0, so both angles lie in (−π/2,
    /// π/2) and one atan2 gives the difference exactly).
    #[inline(always)]
    fn turn_from_base_i(&self, sn: T, dn: T) -> (T, T) {
        let (y1, x1) = (self.sqm * sn, dn);
        let (y0, x0) = (self.y0, self.j0.dn);
        (y1 * x0 - x1 * y0, x1 * x0 + y1 * y0)
    }

    /// Case II: ∫β2 = −(dn − dn0)/(m r) (FINDINGS §3) from sn Γ, dn Γ, in the form that does
    /// not cancel: through sn² − sn0² = (dn0² − dn²)/m for small m, directly for m ≥ ½ (dn,
    /// computed with relative accuracy, is tiny near the separatrix while sn ≈ 1).
    #[inline(always)]
    fn dn_integral_ii(&self, sn: T, dn: T) -> T {
        if self.m.re() >= 0.5 {
            (self.j0.dn - dn) * self.b2coef
        } else {
            (sn * sn - self.j0.sn * self.j0.sn) * self.inv_r / (dn + self.j0.dn)
        }
    }

    /// (∫β1, ∫β2, θ/(2ε)) at t of a form built without its phase (cases I and II,
    /// [`Self::complete`]): with u = r t and v = φ, the Jacobi functions at Γ = u + v by
    /// the addition theorems (A&S 16.17.1–3), with the cancellation-free denominator
    /// Δ = 1 − m sn²u sn²v = cn²u + sn²u dn²v, from those at u and the base's sn v, cn v,
    /// dn v (algebraic in a); Z(u + v) − Z(v) = Z(u) − m sn u sn v sn(u + v) (A&S 17.4.35).
    /// Case II's am(Γ) − am(v) is am(u) plus the principal angle of
    /// e^{i am Γ} e^{−i am u} e^{−i am v} (that sum lies in (−π, π), see [`PHASE_FREE_MIN_M1`]).
    /// Without `THETA_VALUE`, θ's derivatives alone (the same bits, as in `pose_with`).
    fn integrals_additive<const THETA_VALUE: bool>(&self, t: f64) -> (T, T, T) {
        let ii = self.case == Case::II;
        let amp = match (ii, THETA_VALUE) {
            (false, _) => Amplitude::None,
            (true, true) => Amplitude::Value,
            (true, false) => Amplitude::SlopeOnly,
        };
        let ju = self.landen.eval_amplitude(self.r * t, amp);
        let (su, cu, du) = (ju.sn, ju.cn, ju.dn);
        let (sv, cv, dv) = (self.j0.sn, self.j0.cn, self.j0.dn);
        let inv = (cu * cu + su * su * dv * dv).recip();
        let sg = (su * cv * dv + sv * cu * du) * inv;
        let cg = (cu * cv - su * sv * du * dv) * inv;
        let dg = (du * dv - self.m * su * sv * cu * cv) * inv;
        let ib1 = self.lin * t + (ju.zm - su * sv * sg) * self.zcoef;
        if !ii {
            let ib2 = (cg - cv) * self.b2coef;
            let (y, x) = self.turn_from_base_i(sg, dg);
            let ht = if THETA_VALUE {
                y.atan2_fast(x)
            } else {
                y.atan2_slope(x)
            };
            return (ib1, ib2, ht);
        }
        let ib2 = self.dn_integral_ii(sg, dg);
        // e^{i am Γ}·conj(e^{i am u})·conj(e^{i am v}), with e^{i am x} = cn x + i sn x.
        let (re1, im1) = (cg * cu + sg * su, sg * cu - cg * su);
        let (re2, im2) = (re1 * cv + im1 * sv, im1 * cv - re1 * sv);
        let turn = if THETA_VALUE {
            im2.atan2_fast(re2)
        } else {
            im2.atan2_slope(re2)
        };
        (ib1, ib2, ju.am + turn)
    }

    /// Pose (x, y, θ)(t) with θ unwrapped (FINDINGS §1 position formulas, §3 integrals):
    /// x = −(a4/F)∫β1 + 2ε(a5/F)∫β2, y = −(a5/F)∫β1 − 2ε(a4/F)∫β2.
    ///
    /// A form built without its phase ([`Self::complete`]) places Γ by the addition
    /// theorems instead ([`Self::integrals_additive`]).
    pub fn pose(&self, t: f64) -> [T; 3] {
        self.pose_with::<true, false>(t).0
    }

    /// [`Self::pose`] for its derivatives alone (J(t)): θ's value is left out in cases I and
    /// II (an arctangent per call, ~5 % of a stability scan's sample), every derivative the
    /// same bit for bit. x and y keep their values.
    pub fn pose_for_jacobian(&self, t: f64) -> [T; 3] {
        self.pose_with::<false, false>(t).0
    }

    /// [`Self::pose_for_jacobian`] and the curvature κ(t) from the same Jacobi values (cases
    /// I, II and III; NaN in the others and on a form built without its phase): with dual
    /// numbers ∂κ/∂a, which gives d det J/dt = det[J_x; J_y; ∂κ/∂a] (the rows x', y' of J' =
    /// ∂(cos θ, sin θ, κ)/∂a are multiples of the θ row, so they add nothing).
    pub fn pose_and_curvature_for_jacobian(&self, t: f64) -> ([T; 3], T) {
        self.pose_with::<false, true>(t)
    }

    /// [`Self::pose`] with θ's value (`THETA_VALUE`) or its derivatives alone, and the
    /// curvature if `CURVATURE` (else NaN); constants so that each build folds the choices
    /// away.
    #[inline(always)]
    fn pose_with<const THETA_VALUE: bool, const CURVATURE: bool>(&self, t: f64) -> ([T; 3], T) {
        let unknown = T::from_f64(f64::NAN);
        if t == 0.0 {
            // the base is clamped at the identity: q(0) = 0 and J(0) = 0 exactly
            let zero = T::from_f64(0.0);
            return ([zero, zero, zero], unknown);
        }
        let eps = self.eps;
        let (ib1, ib2, half_theta, kappa) = match self.case {
            Case::Straight => {
                let (s1, s2, s3) = straight_integrals(self.a4, t);
                let zero = self.a3 * 0.0;
                if !(s1.re().is_finite() && s2.re().is_finite() && s3.re().is_finite()) {
                    // Values are exact (θ = y = 0, x = t); only derivatives overflow.
                    let big = T::from_f64(f64::INFINITY);
                    let th = if T::HAS_DERIVATIVES { zero + big } else { zero };
                    return ([zero + t, th, th], unknown);
                }
                let th = self.a3 * s1 - self.a5 * s2;
                let y = self.a3 * s2 - self.a5 * s3;
                return ([zero + t, y, th], unknown);
            }
            Case::Circle | Case::SmallForce => {
                let c = self.a3;
                let tau = c * t;
                let (sn, _) = tau.sin_cos();
                let h = (tau * 0.5).sin();
                let x = sn / c;
                let y = h * h * 2.0 / c;
                let th = tau;
                if T::HAS_DERIVATIVES || self.case == Case::SmallForce {
                    let d = circle_force_terms(c, t);
                    return (
                        [
                            x + self.a4 * d[2] + self.a5 * d[3],
                            y + self.a4 * d[4] + self.a5 * d[5],
                            th + self.a4 * d[0] + self.a5 * d[1],
                        ],
                        unknown,
                    );
                }
                return ([x, y, th], unknown);
            }
            // The curvature needs Γ itself: the phase's form answers it directly.
            Case::I | Case::II if self.phase_unknown || (self.additive && !CURVATURE) => {
                let (ib1, ib2, ht) = self.integrals_additive::<THETA_VALUE>(t);
                (ib1, ib2, ht, unknown)
            }
            Case::I => {
                let j = self.landen.eval(self.r * t + self.phi, false);
                let ib1 = self.lin * t + (j.zm - self.j0.zm) * self.zcoef;
                let ib2 = (j.cn - self.j0.cn) * self.b2coef;
                let (y, x) = self.turn_from_base_i(j.sn, j.dn);
                let ht = if THETA_VALUE {
                    y.atan2_fast(x)
                } else {
                    y.atan2_slope(x)
                };
                let kappa = if CURVATURE {
                    self.sqa3 * j.cn * self.eps
                } else {
                    unknown
                };
                (ib1, ib2, ht, kappa)
            }
            Case::II => {
                let amp = if THETA_VALUE {
                    Amplitude::Value
                } else {
                    Amplitude::SlopeOnly
                };
                let j = self.landen.eval_amplitude(self.r * t + self.phi, amp);
                let ib1 = self.lin * t + (j.zm - self.j0.zm) * self.zcoef;
                let ib2 = self.dn_integral_ii(j.sn, j.dn);
                let kappa = if CURVATURE {
                    self.sqa3 * j.dn * self.eps
                } else {
                    unknown
                };
                (ib1, ib2, j.am - self.th0, kappa)
            }
            Case::III => {
                let u = self.r * t + self.phi;
                let (sn, cn, dn, e) = near_one(u, self.m);
                let ib1 = (e - self.e0) * 2.0 / self.r - t;
                let ib2 = -self.sqm * (cn - self.j0.cn) / self.r;
                let ht = (self.sqm * sn).atan2(dn) - self.th0;
                let kappa = if CURVATURE {
                    self.sqa3 * cn * self.eps
                } else {
                    unknown
                };
                (ib1, ib2, ht, kappa)
            }
        };
        let x = -self.chat * ib1 + self.shat * ib2 * (2.0 * eps);
        let y = -self.shat * ib1 - self.chat * ib2 * (2.0 * eps);
        ([x, y, half_theta * (2.0 * eps)], kappa)
    }
}
