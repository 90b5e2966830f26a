//! The separatrix limit in log form (issue 53, item 4): a barely bent rod under a strong
//! force as a lattice of pendulum solitons, exact where 1 − k² underflows.
//!
//! Under tension the rod's angle obeys θ'' = a4 sin θ − a5 cos θ (docs/math.md §1). With
//! R = ‖(a4, a5)‖, β = atan2(a5, a4) and ψ = θ − β it is the pendulum ψ'' = R sin ψ about its
//! *unstable* equilibrium ψ = 0, with ψ(0) = −β, ψ'(0) = a3. When the bending is tiny against
//! the force, ρ = max(|β|, |a3|/√R) ≪ 1, the orbit passes within ρ of the saddle: its Jacobi
//! parameter has 1 − k² ≈ ρ² (below f64's range at ρ = 1e-186), and every evaluation through
//! K(k) or sn(u | k) loses the phase. The exact identities
//!
//! ```text
//! dn(u | k) = (π/2K′) Σₙ sech(π(u − 2nK)/2K′),   cn(u | k) = (π/2kK′) Σₙ (−1)ⁿ sech(π(u − 2nK)/2K′)
//! ```
//!
//! (Whittaker & Watson §22.6 problems; the "soliton lattice") with K′ = π/2 + O(1 − k²) give
//! the curvature as a sum of solitons of the separatrix,
//!
//! ```text
//! ψ'(t) = 2√R Σₙ sₙ sech(√R (t − tₙ)),   relative error O(ρ²),
//! ```
//!
//! all of one sign sₙ for a rotation (h = a3² − 4R sin²(β/2) > 0, a non-inflectional rod) and
//! alternating for a libration (h < 0, inflectional). Near the base ψ ≈ A e^{√R t} + B e^{−√R t}
//! with A = (ψ(0) + a3/√R)/2, B = (ψ(0) − a3/√R)/2, which fixes the lattice *in log form*:
//!
//! ```text
//! √R t₁ = ln(4/|A|),  s₁ = sign A,      √R t₀ = −ln(4/|B|),  s₀ = −sign B,
//! √R (tₙ₊₁ − tₙ) = ln(16/|AB|)          (= 2K(k) to O(ρ²)),
//! ```
//!
//! so that no quantity smaller than ρ is ever formed. The pose follows from the pendulum's
//! two integrals, as in [`super::pendulum`]: ∫₀ᵗ sin ψ = (ψ'(t) − a3)/R and
//! ∫₀ᵗ cos ψ = t cos β + (a3² t − P(t))/(2R), with P(t) = ∫₀ᵗ ψ'² from the lattice of dn²
//!
//! ```text
//! P(t) = 4√R Σₙ [tanh √R(t − tₙ) − tanh(−√R tₙ)] + (h/2) t,     h/2 = −2R·AB,
//! ```
//!
//! θ(t) = Σₙ sₙ 4[arctan e^{√R(t − tₙ)} − arctan e^{−√R tₙ}], (x, y) = Rot(β)(∫cos ψ, ∫sin ψ),
//! and the energy ½P(1). Every difference of two nearly equal terms is taken in closed form
//! (e^{x₁} − e^{x₀} through expm1, arctan and tanh differences by their addition formulas), so
//! tiny quantities keep their relative accuracy. The neglected terms (the lattice's O(1 − k²),
//! the solitons beyond the nearest ones, the cubic mismatch at the base) are all O(ρ²)
//! relative: below [`MAX_BENDING`] they are under f64's rounding. J follows by forward-mode
//! dual numbers through the same formulas.

use crate::scalar::Real;

/// Largest bending ρ = max(|β|, |a3|/√R) taken: the neglected terms are O(ρ²) relative
/// (module docs), 1e-14 here, with room for their constants (measured ≤ 3·ρ² against the
/// exact pendulum, `tests/separatrix_limit.rs`).
pub(crate) const MAX_BENDING: f64 = 1e-7;

/// Smallest R: below, the rod never leaves the straight line (and the small-angle expansion
/// answers).
const MIN_FORCE: f64 = 1.0;

/// Largest √R: beyond ln(f64::MAX) J overflows (as for every f64 evaluation under tension).
const MAX_ROOT_FORCE: f64 = 709.0;

/// Smallest |A|, |B| taken: the smallest normal f64 (below, ln|A| of a subnormal loses digits).
const MIN_AMPLITUDE: f64 = f64::MIN_POSITIVE;

/// Largest cancellation (|ψ(0)| + |a3|/√R)/|2A| (or B) taken: A and B carry a relative
/// rounding of a few ε times this, which moves the solitons by as much (in units of 1/√R).
const MAX_CANCELLATION: f64 = 1e3;

/// At most this many solitons: the spacing is at least ln(16/ρ²) ≥ 35 in √R t, so √R ≤ 709
/// needs 22 at most.
const MAX_SOLITONS: usize = 24;

/// The most feature times [`Lattice::features`] returns (the scans' extra samples).
pub(crate) const MAX_FEATURES: usize = 8;

const LN_4: f64 = 2.0 * std::f64::consts::LN_2;

/// The rod as a lattice of separatrix solitons (module docs).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lattice<T> {
    root_r: T,
    r: T,
    cos_b: T,
    sin_b: T,
    a3: T,
    half_h: T,
    /// √R tₙ, the soliton before the base first.
    centres: [T; MAX_SOLITONS],
    signs: [f64; MAX_SOLITONS],
    len: usize,
    rotation: bool,
}

/// Whether a = (a3, a4, a5) is in the lattice's domain before A and B are formed (cheap: a
/// few comparisons for the rods that are not).
#[inline]
pub(crate) fn may_apply(a3: f64, a4: f64, a5: f64) -> bool {
    a4 > 0.0
        && a5.abs() <= MAX_BENDING * a4
        && a3 * a3 <= MAX_BENDING * MAX_BENDING * a4 * 1.000_001
        && (MIN_FORCE..=MAX_ROOT_FORCE * MAX_ROOT_FORCE).contains(&a4)
}

impl<T: Real> Lattice<T> {
    /// The lattice of the rod a, or `None` outside its domain (module docs, [`MAX_BENDING`],
    /// [`MAX_CANCELLATION`]).
    pub(crate) fn new(a3: T, a4: T, a5: T) -> Option<Self> {
        if !may_apply(a3.re(), a4.re(), a5.re()) {
            return None;
        }
        let r = (a4 * a4 + a5 * a5).sqrt();
        let root_r = r.sqrt();
        let beta = a5.atan2(a4);
        let u = a3 / root_r;
        let (b_re, u_re) = (beta.re().abs(), u.re().abs());
        if b_re.max(u_re) > MAX_BENDING || root_r.re() > MAX_ROOT_FORCE {
            return None;
        }
        let big_a = (u - beta) * 0.5;
        let big_b = (-beta - u) * 0.5;
        let (ar, br) = (big_a.re().abs(), big_b.re().abs());
        let scale = 0.5 * (b_re + u_re);
        if ar.min(br) < MIN_AMPLITUDE || scale > MAX_CANCELLATION * ar.min(br) {
            return None;
        }
        let (ln_a, ln_b) = (big_a.abs().ln(), big_b.abs().ln());
        let spacing = -ln_a - ln_b + 2.0 * LN_4;
        let (s1, s0) = (big_a.re().signum(), -big_b.re().signum());
        let rotation = s1 == s0;
        let mut centres = [T::from_f64(0.0); MAX_SOLITONS];
        let mut signs = [0.0; MAX_SOLITONS];
        centres[0] = ln_b - LN_4;
        signs[0] = s0;
        let first = -ln_a + LN_4;
        let mut len = 1;
        while len < MAX_SOLITONS {
            let c = first + spacing * ((len - 1) as f64);
            centres[len] = c;
            let alternate = if rotation || len % 2 == 1 { 1.0 } else { -1.0 };
            signs[len] = s1 * alternate;
            len += 1;
            // The first soliton past the tip is the last one that counts (module docs).
            if c.re() > root_r.re() {
                break;
            }
        }
        let sin_cos = beta.sin_cos();
        Some(Lattice {
            root_r,
            r,
            cos_b: sin_cos.1,
            sin_b: sin_cos.0,
            a3,
            half_h: r * big_a * big_b * -2.0,
            centres,
            signs,
            len,
            rotation,
        })
    }

    /// Where a scan of the rod must look (in t ∈ (0, 1)): its solitons' centres and, for an
    /// inflectional rod, the inflection points between them; at most [`MAX_FEATURES`].
    pub(crate) fn features(&self) -> ([f64; MAX_FEATURES], usize) {
        let mut out = [0.0; MAX_FEATURES];
        let mut n = 0;
        let root_r = self.root_r.re();
        for i in 0..self.len {
            let c = self.centres[i].re() / root_r;
            let next = self.centres.get(i + 1).filter(|_| i + 1 < self.len);
            let mid = next.map(|m| 0.5 * (c + m.re() / root_r));
            let inflection = mid.filter(|_| !self.rotation);
            for t in std::iter::once(c).chain(inflection) {
                if t > 0.0 && t < 1.0 && n < MAX_FEATURES {
                    out[n] = t;
                    n += 1;
                }
            }
        }
        (out, n)
    }

    /// Curvature κ(t) = ψ'(t).
    pub(crate) fn curvature(&self, t: f64) -> T {
        let x = self.root_r * t;
        let mut sum = T::from_f64(0.0);
        for i in 0..self.len {
            sum += sech(x - self.centres[i]) * self.signs[i];
        }
        self.root_r * sum * 2.0
    }

    /// P(t) = ∫₀ᵗ κ² (module docs).
    fn bending_integral(&self, t: f64) -> T {
        let x = self.root_r * t;
        let mut sum = T::from_f64(0.0);
        for i in 0..self.len {
            let c = self.centres[i];
            sum += tanh_difference(-c, x - c);
        }
        self.root_r * sum * 4.0 + self.half_h * t
    }

    /// The pose (x, y, θ)(t), t ∈ [0, 1].
    pub(crate) fn pose(&self, t: f64) -> [T; 3] {
        let x = self.root_r * t;
        let mut theta = T::from_f64(0.0);
        for i in 0..self.len {
            let c = self.centres[i];
            theta += arctan_exp_difference(-c, x - c) * self.signs[i];
        }
        let int_sin = (self.curvature(t) - self.a3) / self.r;
        let int_cos =
            self.cos_b * t + (self.a3 * self.a3 * t - self.bending_integral(t)) / (self.r * 2.0);
        [
            self.cos_b * int_cos - self.sin_b * int_sin,
            self.sin_b * int_cos + self.cos_b * int_sin,
            theta,
        ]
    }

    /// Elastic energy ½∫₀¹κ².
    pub(crate) fn energy(&self) -> T {
        self.bending_integral(1.0) * 0.5
    }

    /// The inflection points (κ = 0) on (0, 1]: between consecutive solitons of opposite signs.
    pub(crate) fn inflections(&self) -> usize {
        if self.rotation {
            return 0;
        }
        let end = self.root_r.re();
        (0..self.len - 1)
            .map(|i| 0.5 * (self.centres[i].re() + self.centres[i + 1].re()))
            .filter(|&m| m > 0.0 && m <= end)
            .count()
    }
}

/// e^x − 1 with the value of `f64::exp_m1` (no cancellation) and the derivative e^x.
fn expm1<T: Real>(x: T) -> T {
    (x.exp() - 1.0).with_re(x.re().exp_m1())
}

/// e^{x1} − e^{x0} for x1 ≥ x0, without cancellation or a needless underflow.
fn exp_difference<T: Real>(x0: T, x1: T) -> T {
    let d = x1 - x0;
    if d.re() > 0.5 {
        x1.exp() * -expm1(-d)
    } else {
        x0.exp() * expm1(d)
    }
}

/// 4[arctan e^{x1} − arctan e^{x0}] for x1 ≥ x0, by the addition formula on the side where
/// the exponentials are small (arctan e^x = π/2 − arctan e^{−x}).
fn arctan_exp_difference<T: Real>(x0: T, x1: T) -> T {
    let q = if (x0 + x1).re() <= 0.0 {
        exp_difference(x0, x1) / ((x0 + x1).exp() + 1.0)
    } else {
        exp_difference(-x1, -x0) / ((-x0 - x1).exp() + 1.0)
    };
    q.atan() * 4.0
}

/// tanh x1 − tanh x0 for x1 ≥ x0, without cancellation where both are near ±1.
fn tanh_difference<T: Real>(x0: T, x1: T) -> T {
    if x0.re() >= 0.0 {
        let (e0, e1) = ((x0 * -2.0).exp(), (x1 * -2.0).exp());
        exp_difference(x1 * -2.0, x0 * -2.0) * 2.0 / ((e0 + 1.0) * (e1 + 1.0))
    } else if x1.re() <= 0.0 {
        let (e0, e1) = ((x0 * 2.0).exp(), (x1 * 2.0).exp());
        exp_difference(x0 * 2.0, x1 * 2.0) * 2.0 / ((e0 + 1.0) * (e1 + 1.0))
    } else {
        // tanh x = ±(1 − 2q/(1 + q)), q = e^{−2|x|}: through q its derivative keeps its digits
        // where 1 − tanh² would be rounding.
        let (q0, q1) = ((x0 * 2.0).exp(), (x1 * -2.0).exp());
        -(q1 * 2.0 / (q1 + 1.0)) - q0 * 2.0 / (q0 + 1.0) + 2.0
    }
}

/// sech x = 2e^{−|x|}/(1 + e^{−2|x|}), finite for every x.
fn sech<T: Real>(x: T) -> T {
    let e = (-x.abs()).exp();
    e * 2.0 / (e * e + 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lattice's base values are the rod's: θ(0) = 0 and κ(0) = a3.
    #[test]
    fn the_lattice_starts_at_the_base() {
        for &(a3, a4, a5) in &[
            (1e-186, 246788.0, 0.0),
            (-3e-20, 4.0e4, 2e-19),
            (1e-40, 1e4, -3e-12),
        ] {
            let l = Lattice::new(a3, a4, a5).expect("in the domain");
            let p = l.pose(0.0);
            let scale = a3.abs().max(a5.abs());
            assert!(p.iter().all(|v| v.abs() <= 1e-12 * scale), "{p:?}");
            // κ(0) = √R(|A| − |B|) cancels where |a3|/√R ≪ |β|: exact to the terms' size.
            let k0 = l.curvature(0.0);
            let terms = a3.abs() + a4.sqrt() * (a5 / a4).abs();
            assert!((k0 - a3).abs() <= 1e-12 * terms, "{k0} vs {a3}");
        }
    }
}
