//! Double-double arithmetic for the closed forms: [`Dd`], a value held as an unevaluated sum
//! hi + lo of two f64 (106-bit significand, unit roundoff ≈ 2⁻¹⁰⁴ per operation here), and
//! [`DualDd`], its forward-mode dual number with three derivatives.
//!
//! Near the separatrix under a strong force the closed form's J loses ≈ 1/√m1 to cancellation
//! (m1 down to 1e-30): in f64 that is up to 1e-1, in double-double 1e-17. Running the same
//! generic code ([`crate::scalar::Real`]) with [`DualDd`] answers those rods in tens of
//! microseconds, where the double-double Taylor series took milliseconds and still had to be
//! cross-checked beyond √‖F‖ = 27.
//!
//! The algorithms are the classical ones: Knuth's TwoSum and Dekker's product (error-free
//! transformations), Dekker's division and Karp's square root, and for the elementary functions
//! an f64 first guess refined by one Newton step (atan2, ln, asinh) or argument reduction and a
//! Taylor series (sin/cos, exp). Accuracy: a few units of 2⁻¹⁰⁴ relative for
//! the arithmetic and of 2⁻¹⁰⁰ for the functions (tested below against identities and
//! constants known to 32 digits). Overflow of the Dekker split (|x| ≳ 1e300) gives NaN, which
//! the closed form reports as overflow.

use crate::dual::{Dual, DualScalar};
use crate::eft::{two_prod, two_sum};
#[cfg(test)]
use crate::scalar::Real;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Unit roundoff assumed for double-double arithmetic in error estimates: 2⁻¹⁰⁴ (the sloppy
/// operations here lose up to two bits of the 2⁻¹⁰⁶ of an exact double-double rounding).
pub const DD_EPSILON: f64 = 4.930_380_657_631_324e-32;

/// A double-double number hi + lo, |lo| ≤ ½ ulp(hi).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dd {
    /// The leading part: the value rounded to f64.
    pub hi: f64,
    /// The trailing part.
    pub lo: f64,
}

/// s + e = a + b exactly, assuming |a| ≥ |b| (Dekker's FastTwoSum).
#[inline]
fn quick_two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    Dd {
        hi: s,
        lo: b - (s - a),
    }
}

/// π to 106 bits.
const PI_DD: Dd = Dd {
    hi: std::f64::consts::PI,
    lo: 1.224_646_799_147_353_2e-16,
};
/// π/2 to 106 bits.
const FRAC_PI_2_DD: Dd = Dd {
    hi: std::f64::consts::FRAC_PI_2,
    lo: 6.123_233_995_736_766e-17,
};
/// ln 2 to 106 bits.
const LN_2_DD: Dd = Dd {
    hi: std::f64::consts::LN_2,
    lo: 2.319_046_813_846_299_6e-17,
};

impl Dd {
    /// An f64 as a double-double (exact).
    #[inline]
    pub const fn from_f64(v: f64) -> Self {
        Self { hi: v, lo: 0.0 }
    }

    /// The value rounded to f64.
    #[inline]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    #[inline]
    fn add_f64(self, b: f64) -> Self {
        let (s, e) = two_sum(self.hi, b);
        quick_two_sum(s, e + self.lo)
    }

    #[inline]
    fn mul_f64(self, b: f64) -> Self {
        let (p, e) = two_prod(self.hi, b);
        quick_two_sum(p, e + self.lo * b)
    }

    /// Division by an f64 (Dekker's long division, two correction steps).
    #[inline]
    fn div_f64(self, b: f64) -> Self {
        let q1 = self.hi / b;
        let r = self - Dd::from_f64(b).mul_f64(q1);
        let q2 = r.hi / b;
        let r = r - Dd::from_f64(b).mul_f64(q2);
        let q3 = r.hi / b;
        quick_two_sum(q1, q2).add_f64(q3)
    }

    /// Division by a small positive integer `n` (a series' k + 1): one Newton-corrected
    /// quotient, the remainder exact by Dekker's product; enough for a divisor exact in f64.
    #[inline]
    pub(crate) fn div_small_int(self, n: f64) -> Self {
        let q1 = self.hi / n;
        let (p, e) = two_prod(q1, n);
        let r = ((self.hi - p) - e + self.lo) / n;
        let (hi, lo) = two_sum(q1, r);
        Self { hi, lo }
    }

    /// Scaling by a power of two (exact).
    #[inline]
    fn scale(self, p: f64) -> Self {
        Self {
            hi: self.hi * p,
            lo: self.lo * p,
        }
    }

    /// Square root (Karp's trick: one Newton step on the f64 root); 0 at 0, NaN below.
    pub fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return Dd::from_f64(if self.hi == 0.0 { 0.0 } else { f64::NAN });
        }
        let x = 1.0 / self.hi.sqrt();
        let y = self.hi * x;
        let (p, e) = two_prod(y, y);
        let d = ((self.hi - p) - e + self.lo) * (x * 0.5);
        quick_two_sum(y, d)
    }

    /// (sin x, cos x): reduction by multiples of π/2 and Taylor series on |r| ≤ π/4.
    pub fn sin_cos(self) -> (Self, Self) {
        if !self.hi.is_finite() {
            return (Dd::from_f64(f64::NAN), Dd::from_f64(f64::NAN));
        }
        let k = (self.hi / std::f64::consts::FRAC_PI_2).round();
        let r = self - FRAC_PI_2_DD.mul_f64(k);
        // sin r = Σ (−1)ⁱ r^(2i+1)/(2i+1)!, cos r = Σ (−1)ⁱ r^(2i)/(2i)! (|r| ≤ 0.79: 15 terms
        // each leave < 1e-34).
        let r2 = r * r;
        let (mut s, mut c) = (Dd::from_f64(0.0), Dd::from_f64(0.0));
        for i in (0..15).rev() {
            let n = (2 * i) as f64;
            s = (s * r2).div_f64(-(n + 2.0) * (n + 3.0)) + Dd::from_f64(1.0);
            c = (c * r2).div_f64(-(n + 1.0) * (n + 2.0)) + Dd::from_f64(1.0);
        }
        let s = s * r;
        match (k as i64).rem_euclid(4) {
            0 => (s, c),
            1 => (c, -s),
            2 => (-s, -c),
            _ => (-c, s),
        }
    }

    /// eˣ: x = k ln 2 + r, e^r by a Taylor series on r/1024 and ten squarings.
    pub fn exp(self) -> Self {
        if self.hi > 709.0 {
            return Dd::from_f64(f64::INFINITY);
        }
        if self.hi < -745.0 {
            return Dd::from_f64(0.0);
        }
        if self.hi.is_nan() {
            return self;
        }
        let k = (self.hi / std::f64::consts::LN_2).round();
        let r = (self - LN_2_DD.mul_f64(k)).scale(1.0 / 1024.0);
        // e^r − 1 = Σ_{n≥1} rⁿ/n! (|r| ≤ 3.4e-4: 10 terms leave < 1e-40)
        let mut s = Dd::from_f64(0.0);
        for n in (1..=10).rev() {
            s = (s * r + Dd::from_f64(1.0)).div_f64(n as f64);
        }
        let mut s = s * r;
        // (1 + s)² − 1 = 2s + s², ten times
        for _ in 0..10 {
            s = s.scale(2.0) + s * s;
        }
        let e = s + Dd::from_f64(1.0);
        // 2^k in two steps so that k down to −1074 stays representable
        let half = (k * 0.5).trunc();
        e.scale(2f64.powi(half as i32))
            .scale(2f64.powi((k - half) as i32))
    }

    /// ln x: one Newton step y + x e^(−y) − 1 on the f64 logarithm.
    pub fn ln(self) -> Self {
        if self.hi.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || !self.hi.is_finite() {
            return Dd::from_f64(self.hi.ln());
        }
        let y = Dd::from_f64(self.hi.ln());
        y + self * (-y).exp() - Dd::from_f64(1.0)
    }

    /// atan2(y, x) in (−π, π]: one Newton step on the f64 angle z,
    /// z + (y cos z − x sin z)/(x cos z + y sin z).
    pub fn atan2(self, x: Self) -> Self {
        let y = self;
        let z = y.hi.atan2(x.hi);
        if (y.hi == 0.0 && x.hi == 0.0) || !z.is_finite() {
            return Dd::from_f64(z);
        }
        let zd = Dd::from_f64(z);
        let (s, c) = zd.sin_cos();
        zd + (y * c - x * s) / (x * c + y * s)
    }

    /// sinh x: Taylor series for |x| < ½, (eˣ − e⁻ˣ)/2 above.
    pub fn sinh(self) -> Self {
        if self.hi.abs() < 0.5 {
            let x2 = self * self;
            let mut s = Dd::from_f64(0.0);
            for i in (0..14).rev() {
                let n = (2 * i) as f64;
                s = (s * x2).div_f64((n + 2.0) * (n + 3.0)) + Dd::from_f64(1.0);
            }
            return s * self;
        }
        let e = self.exp();
        (e - e.recip()).scale(0.5)
    }

    /// cosh x = (eˣ + e⁻ˣ)/2.
    pub fn cosh(self) -> Self {
        let e = self.abs().exp();
        (e + e.recip()).scale(0.5)
    }

    /// tanh x = sinh x / cosh x (±1 beyond |x| = 40).
    pub fn tanh(self) -> Self {
        if self.hi.abs() > 40.0 {
            return Dd::from_f64(self.hi.signum());
        }
        self.sinh() / self.cosh()
    }

    /// asinh x: one Newton step y − (sinh y − x)/cosh y on the f64 value.
    pub fn asinh(self) -> Self {
        let y = Dd::from_f64(self.hi.asinh());
        if !y.hi.is_finite() || y.hi == 0.0 {
            return y;
        }
        y - (y.sinh() - self) / y.cosh()
    }

    /// |x|.
    #[inline]
    pub fn abs(self) -> Self {
        if self.hi < 0.0 {
            -self
        } else {
            self
        }
    }

    /// 1/x.
    #[inline]
    pub fn recip(self) -> Self {
        Dd::from_f64(1.0) / self
    }
}

impl Add for Dd {
    type Output = Self;
    /// The accurate (IEEE-style) double-double sum.
    #[inline]
    fn add(self, b: Self) -> Self {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let r = quick_two_sum(s, e + t);
        quick_two_sum(r.hi, r.lo + f)
    }
}
impl Neg for Dd {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}
impl Sub for Dd {
    type Output = Self;
    #[inline]
    fn sub(self, b: Self) -> Self {
        self + (-b)
    }
}
impl Mul for Dd {
    type Output = Self;
    #[inline]
    fn mul(self, b: Self) -> Self {
        let (p, e) = two_prod(self.hi, b.hi);
        quick_two_sum(p, e + (self.hi * b.lo + self.lo * b.hi))
    }
}
impl Div for Dd {
    type Output = Self;
    /// Dekker's long division with two correction steps.
    #[inline]
    fn div(self, b: Self) -> Self {
        let q1 = self.hi / b.hi;
        let r = self - b.mul_f64(q1);
        let q2 = r.hi / b.hi;
        let r = r - b.mul_f64(q2);
        let q3 = r.hi / b.hi;
        quick_two_sum(q1, q2).add_f64(q3)
    }
}

/// Forward-mode dual number over [`Dd`]: a value and its gradient with respect to three
/// inputs, every part in double-double. The [`crate::scalar::Real`] implementation that the closed forms run
/// on for rods where f64 cancels ([`crate::scalar::Real::EXTENDED`]); the chain rule is [`crate::dual`]'s.
pub type DualDd = Dual<Dd>;

impl DualScalar for Dd {
    const ZERO: Self = Dd::from_f64(0.0);
    const ONE: Self = Dd::from_f64(1.0);
    const EXTENDED: bool = true;
    const EPSILON: f64 = DD_EPSILON;
    #[inline]
    fn from_f64(v: f64) -> Self {
        Dd::from_f64(v)
    }
    #[inline]
    fn leading(self) -> f64 {
        self.hi
    }
    #[inline]
    fn to_f64(self) -> f64 {
        Dd::to_f64(self)
    }
    #[inline]
    fn pi() -> Self {
        PI_DD
    }
    #[inline]
    fn add_f64(self, v: f64) -> Self {
        Dd::add_f64(self, v)
    }
    #[inline]
    fn mul_f64(self, v: f64) -> Self {
        Dd::mul_f64(self, v)
    }
    /// A true division (generic code writes x / 3.0 for exact thirds).
    #[inline]
    fn div_f64(self, v: f64) -> Self {
        Dd::div_f64(self, v)
    }
    #[inline]
    fn quotient_and_recip(self, d: Self) -> (Self, Self) {
        (self / d, d.recip())
    }
    #[inline]
    fn recip(self) -> Self {
        Dd::recip(self)
    }
    fn sqrt(self) -> Self {
        Dd::sqrt(self)
    }
    fn sin_cos(self) -> (Self, Self) {
        Dd::sin_cos(self)
    }
    fn asin_and_slope(self) -> (Self, Self) {
        let one = Dd::from_f64(1.0);
        let x = if self.hi > 1.0 {
            one
        } else if self.hi < -1.0 {
            -one
        } else {
            self
        };
        let w = ((one - x) * (one + x)).sqrt();
        let d = if w.hi > 0.0 { w.recip() } else { Dd::default() };
        (x.atan2(w), d)
    }
    fn atan(self) -> Self {
        Dd::atan2(self, Dd::from_f64(1.0))
    }
    fn atan2(self, x: Self) -> Self {
        Dd::atan2(self, x)
    }
    fn exp(self) -> Self {
        Dd::exp(self)
    }
    fn ln(self) -> Self {
        Dd::ln(self)
    }
    fn tanh(self) -> Self {
        Dd::tanh(self)
    }
    fn sinh(self) -> Self {
        Dd::sinh(self)
    }
    fn cosh(self) -> Self {
        Dd::cosh(self)
    }
    fn asinh(self) -> Self {
        Dd::asinh(self)
    }
    fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |a − b| in units of |b| (b ≠ 0), computed in double-double.
    fn rel(a: Dd, b: Dd) -> f64 {
        ((a - b).to_f64() / b.to_f64()).abs()
    }

    fn dd(hi: f64, lo: f64) -> Dd {
        quick_two_sum(hi, lo)
    }

    /// Constants known to 32 digits (e, √2, π/4 by atan 1, ln 10): within 1e-30 relative.
    #[test]
    fn functions_match_known_constants() {
        let one = Dd::from_f64(1.0);
        // e = 2.71828182845904523536028747135266…
        let e = dd(std::f64::consts::E, 1.445_646_891_729_250_2e-16);
        assert!(rel(one.exp(), e) < 1e-30, "{:e}", rel(one.exp(), e));
        let sqrt2 = dd(std::f64::consts::SQRT_2, -9.667_293_313_452_913e-17);
        let two = Dd::from_f64(2.0);
        assert!(rel(two.sqrt(), sqrt2) < 1e-31);
        let quarter_pi = PI_DD.scale(0.25);
        assert!(rel(one.atan2(one), quarter_pi) < 1e-31);
        let ln10 = dd(std::f64::consts::LN_10, -2.170_756_223_382_249_4e-16);
        assert!(rel(Dd::from_f64(10.0).ln(), ln10) < 1e-30);
    }

    /// Identities over seven decades of arguments and both signs: sin² + cos² = 1,
    /// atan2(sin z, cos z) = z, ln eˣ = x, asinh sinh x = x, x·(1/x) = 1, (√x)² = x,
    /// (x/3)·3 = x, cosh² − sinh² = 1 (relative to cosh²).
    #[test]
    fn identities_hold_to_double_double_accuracy() {
        let mut rng = crate::rng::SplitMix64::new(7);
        for _ in 0..2000 {
            let x = Dd::from_f64(rng.signed_pow10(-4.0, 2.5))
                + Dd::from_f64(rng.signed_pow10(-24.0, -20.0));
            let one = Dd::from_f64(1.0);
            let (s, c) = x.sin_cos();
            assert!(((s * s + c * c) - one).to_f64().abs() < 1e-30, "{x:?}");
            if x.hi.abs() < 3.0 {
                assert!(rel(s.atan2(c), x) < 1e-29, "{x:?}");
            }
            if x.hi.abs() < 300.0 {
                assert!(rel(x.exp().ln(), x) < 1e-28 / x.hi.abs().min(1.0), "{x:?}");
                let sh = x.sinh();
                assert!(rel(sh.asinh(), x) < 1e-29, "{x:?}");
                let ch = x.cosh();
                assert!(
                    ((ch * ch - sh * sh) - one).to_f64().abs() < 1e-29 * (ch * ch).hi,
                    "{x:?}"
                );
            }
            assert!(rel(x * x.recip(), one) < 1e-31);
            let ax = x.abs();
            let q = rel(ax.sqrt() * ax.sqrt(), ax);
            assert!(q < 2e-31, "{q:e} {ax:?}");
            assert!(rel(x.div_f64(3.0).mul_f64(3.0), x) < 1e-31);
        }
    }

    /// The dual number's derivatives against the f64 [`crate::scalar::Dual3`] rules (same
    /// formulas, so only rounding differs).
    #[test]
    fn derivatives_agree_with_dual3() {
        use crate::scalar::Dual3;
        let x = 0.37;
        let d = DualDd::variable(x, 1);
        let f = Dual3::variable(x, 1);
        let pairs: [(DualDd, Dual3); 8] = [
            (d.sin() * d.exp(), f.sin() * f.exp()),
            (d.atan2(d * d + 1.0), f.atan2(f * f + 1.0)),
            (d.asin(), f.asin()),
            (d.sqrt() / 3.0, f.sqrt() / 3.0),
            (d.ln().tanh(), f.ln().tanh()),
            (d.asinh() - d.cosh(), f.asinh() - f.cosh()),
            (d.sinh().recip(), f.sinh().recip()),
            (d.atan() * DualDd::pi(), f.atan() * std::f64::consts::PI),
        ];
        for (a, b) in pairs {
            let (v, g) = a.to_f64();
            assert!((v - b.v).abs() <= 4e-16 * b.v.abs(), "{v} {}", b.v);
            assert!(
                (g[1] - b.g[1]).abs() <= 4e-15 * b.g[1].abs(),
                "{g:?} {:?}",
                b.g
            );
            assert_eq!(g[0], 0.0);
        }
    }
}
