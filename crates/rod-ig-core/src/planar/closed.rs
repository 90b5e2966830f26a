//! The closed-form planar rod, generic over [`Real`] (docs/math.md §1–§3).
//!
//! [`Closed::new`] does everything that depends on a only (case selection, m, m1, r, phase,
//! Landen sequence, values at Γ0 = φ); [`Closed::pose`] then costs one descending-Landen
//! evaluation. With `T = Dual3` seeded with the identity on a, the same code yields J(t, a).

use crate::elliptic::{inverse_phase_zeta, Amplitude, Duplication, JacobiValues};
use crate::scalar::Real;

mod det_fields;
mod estimates;
mod theorems;
pub(crate) use det_fields::DetFrame;
pub(crate) use estimates::{
    SeriesNeed, CLOSED_J_REL, CLOSED_J_TOLERANCE, ENERGY_REL_TOLERANCE, SEPARATRIX_M1,
    SERIES_DD_MAX_ROOT_F,
};
use estimates::{DEEP_SEPARATRIX_M1, MAX_PHASE};

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
const _: () = assert!(MAX_DIP_TIMES <= crate::conjugate::MAX_EXTRA_SAMPLES);

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
/// separatrix forms of docs/math.md §3 case III; with a dual δ (value 0) they also carry the exact
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

/// λ4 = a5² − a3²(a3²/4 + a4) (docs/math.md §2) to about ε relative to itself: the two terms cancel
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

/// The invariants of a rod's base wrench that select and parametrise its case (docs/math.md §2):
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

    /// Precomputes the closed form for a = (a3, a4, a5) (docs/math.md §2 table and phase).
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
        // F ± a4 without cancellation (docs/math.md §2).
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

    /// Case I (λ4 > 0, docs/math.md §2): parameter m = α3/(4F), r = √F.
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

    /// Case II (λ4 < 0, docs/math.md §2): parameter m = 4F/α3, r = √α3 / 2; tiny m is the
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
    /// δ = 1 − m carried for the derivatives (docs/math.md §2 table).
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
        // δ = 1 − m_I = λ4/(F α3): value 0, derivative carried (docs/math.md §2 table).
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

    /// Curvature κ(t) = μ3(t) (docs/math.md §2 table).
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

    /// Case II: ∫β2 = −(dn − dn0)/(m r) (docs/math.md §3) from sn Γ, dn Γ, in the form that does
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

    /// Pose (x, y, θ)(t) with θ unwrapped (docs/math.md §1 position formulas, §3 integrals):
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

/// The refusal of a closed form whose intermediate quantities exceed f64.
pub(crate) fn overflow() -> crate::RodError {
    crate::RodError::Overflow("closed form of the planar rod: parameters too large for f64".into())
}

/// The closed form in dual numbers seeded with the identity on a (so that it carries J); None
/// where an intermediate quantity overflows.
pub(crate) fn seeded_closed(a: &crate::PlanarParams) -> Option<Closed<crate::scalar::Dual3>> {
    Closed::new(
        crate::scalar::Dual3::variable(a[0], 0),
        crate::scalar::Dual3::variable(a[1], 1),
        crate::scalar::Dual3::variable(a[2], 2),
    )
}
