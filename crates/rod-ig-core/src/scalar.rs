//! Scalars for the closed forms: the [`Real`] trait, implemented for `f64` and for every
//! forward-mode dual number [`crate::dual::Dual`] (value + gradient with respect to three
//! inputs): [`Dual3`] over f64, [`crate::dd::DualDd`] over double-double.
//!
//! The planar closed forms (docs/math.md §1–§3) are written once, generic over [`Real`]. Run with
//! `f64` they give the pose; run with [`Dual3`] seeded with the identity on a = (a3, a4, a5)
//! they give the pose and its exact Jacobian J = ∂q/∂a in one pass (no finite differences).
//! Branch decisions inside generic code are taken on [`Real::re`], the f64 value.

use crate::dual::{Dual, DualScalar};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real scalar usable by the closed forms: `f64` or a dual number.
///
/// Mixed arithmetic with `f64` on the right is part of the contract so that generic code can
/// write `x * 2.0`.
pub trait Real:
    Copy
    + std::fmt::Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// True for scalars that carry derivatives (dual numbers), false for `f64`.
    const HAS_DERIVATIVES: bool;
    /// True for arithmetic beyond f64 ([`crate::dd::DualDd`]): generic code then skips its
    /// f64 shortcuts (values computed in f64 with derivatives attached, f64 constants that are
    /// not exact) and runs its generic path with tolerances for that precision.
    const EXTENDED: bool = false;
    /// Unit roundoff of the arithmetic, for error estimates (`f64::EPSILON` unless extended).
    const EPSILON: f64 = f64::EPSILON;
    /// A constant (zero derivative).
    fn from_f64(v: f64) -> Self;
    /// π to the scalar's precision.
    fn pi() -> Self {
        Self::from_f64(std::f64::consts::PI)
    }
    /// The f64 value (the real part of a dual number).
    fn re(self) -> f64;
    /// The same number with its value replaced by `v` (derivatives kept): for a value computed
    /// more accurately than the arithmetic that produced the derivatives.
    fn with_re(self, v: f64) -> Self;
    /// Square root. For a dual number at value 0 the derivative is set to 0 (not ∞).
    fn sqrt(self) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Sine and cosine together.
    fn sin_cos(self) -> (Self, Self) {
        (self.sin(), self.cos())
    }
    /// Arcsine; the argument is clamped to [−1, 1] (derivative capped at the ends).
    fn asin(self) -> Self;
    /// Arctangent.
    fn atan(self) -> Self;
    /// Two-argument arctangent atan2(self, x), in (−π, π].
    fn atan2(self, x: Self) -> Self;
    /// atan2 with an absolute error ≤ 5e-16 instead of libm's correct rounding (see
    /// [`fast_atan2`]); several times cheaper.
    fn atan2_fast(self, x: Self) -> Self {
        self.atan2(x)
    }
    /// atan2 where only its derivatives are wanted (a Jacobian's entries, not the angle): dual
    /// numbers leave the value out (0), every other scalar computes [`Real::atan2_fast`].
    fn atan2_slope(self, x: Self) -> Self {
        self.atan2_fast(x)
    }
    /// Exponential.
    fn exp(self) -> Self;
    /// Natural logarithm.
    fn ln(self) -> Self;
    /// Hyperbolic tangent.
    fn tanh(self) -> Self;
    /// Hyperbolic sine.
    fn sinh(self) -> Self;
    /// Hyperbolic cosine.
    fn cosh(self) -> Self;
    /// Inverse hyperbolic sine.
    fn asinh(self) -> Self;
    /// Absolute value (derivative sign taken from the value; +1 at 0).
    fn abs(self) -> Self;
    /// Reciprocal 1/self.
    fn recip(self) -> Self {
        Self::from_f64(1.0) / self
    }
    /// True when the value and every derivative are finite.
    fn is_finite(self) -> bool;
}

impl Real for f64 {
    const HAS_DERIVATIVES: bool = false;
    #[inline]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline]
    fn re(self) -> f64 {
        self
    }
    #[inline]
    fn with_re(self, v: f64) -> Self {
        v
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn sin(self) -> Self {
        f64::sin(self)
    }
    #[inline]
    fn cos(self) -> Self {
        f64::cos(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
    #[inline]
    fn asin(self) -> Self {
        f64::asin(self.clamp(-1.0, 1.0))
    }
    #[inline]
    fn atan(self) -> Self {
        f64::atan(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
    #[inline]
    fn atan2_fast(self, x: Self) -> Self {
        fast_atan2(self, x)
    }
    #[inline]
    fn exp(self) -> Self {
        f64::exp(self)
    }
    #[inline]
    fn ln(self) -> Self {
        f64::ln(self)
    }
    #[inline]
    fn tanh(self) -> Self {
        f64::tanh(self)
    }
    #[inline]
    fn sinh(self) -> Self {
        f64::sinh(self)
    }
    #[inline]
    fn cosh(self) -> Self {
        f64::cosh(self)
    }
    #[inline]
    fn asinh(self) -> Self {
        f64::asinh(self)
    }
    #[inline]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline]
    fn recip(self) -> Self {
        1.0 / self
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

/// (−1)ᵏ/(2k + 1), k = 0..14: Maclaurin coefficients of atan z / z.
const ATAN_COEFFS: [f64; 15] = [
    1.0,
    -1.0 / 3.0,
    1.0 / 5.0,
    -1.0 / 7.0,
    1.0 / 9.0,
    -1.0 / 11.0,
    1.0 / 13.0,
    -1.0 / 15.0,
    1.0 / 17.0,
    -1.0 / 19.0,
    1.0 / 21.0,
    -1.0 / 23.0,
    1.0 / 25.0,
    -1.0 / 27.0,
    1.0 / 29.0,
];

/// √(x² + y²) by one square root where the squares can neither overflow nor underflow
/// (within ≈ 1.5 ulp; libm's `hypot`, which guards every range, cost ~80 instructions, 7 % of
/// the tip): for the scales and thresholds the closed form decides on, not for its values.
#[inline]
pub fn fast_hypot(x: f64, y: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let (big, small) = if ax >= ay { (ax, ay) } else { (ay, ax) };
    if big < 1e150 && (small > 1e-150 || small == 0.0) {
        (x * x + y * y).sqrt()
    } else {
        x.hypot(y)
    }
}

/// x rounded to the nearest integer, halves away from zero: exactly `f64::round`, without its
/// call into compiler-builtins (the x86-64 baseline has no rounding instruction; ~24
/// instructions a call, once per Jacobi evaluation). Below 2⁵² the truncation by integer
/// conversion is exact; at and above it (and for NaN) x is returned as `round` would.
#[inline]
pub fn fast_round(x: f64) -> f64 {
    const EXACT: f64 = 4_503_599_627_370_496.0; // 2⁵²: every f64 from here on is an integer
    if x.is_nan() || x.abs() >= EXACT {
        return x;
    }
    let t = x as i64 as f64;
    let frac = x - t; // exact
    if frac >= 0.5 {
        t + 1.0
    } else if frac <= -0.5 {
        t - 1.0
    } else {
        // −0.4 rounds to −0.0, as `round` does.
        t.copysign(x)
    }
}

/// atan2(y, x) in (−π, π] by octant reduction to t = min/max ∈ [0, 1], the shift
/// atan t = π/6 + atan((√3 t − 1)/(t + √3)) for t > tan(π/12), and the Maclaurin series of
/// atan on |z| ≤ tan(π/12) (15 terms: truncation ≤ 4e-18). Absolute error ≤ 5e-16. Zeros,
/// infinities and NaN are passed to libm.
#[inline]
pub fn fast_atan2(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_6, PI};
    const TAN_PI_12: f64 = 0.267_949_192_431_122_7;
    const SQRT3: f64 = 1.732_050_807_568_877_2;
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    if den == 0.0 || !den.is_finite() {
        return y.atan2(x);
    }
    let t = num / den;
    let (z, off) = if t > TAN_PI_12 {
        ((t * SQRT3 - 1.0) / (t + SQRT3), FRAC_PI_6)
    } else {
        (t, 0.0)
    };
    // atan z = z + z³ Q(z²): Q (13th degree) by Estrin's scheme, four levels of independent
    // products where Horner chains fourteen (~15 % of q(1) in time); z is added last, as in
    // Horner, so that the leading term is not rounded into the others.
    let c = &ATAN_COEFFS;
    let z2 = z * z;
    let (z4, z3) = (z2 * z2, z2 * z);
    let z8 = z4 * z4;
    let pair = |i: usize| c[i] + c[i + 1] * z2;
    let b0 = pair(1) + pair(3) * z4;
    let b1 = pair(5) + pair(7) * z4;
    let b2 = pair(9) + pair(11) * z4;
    let b3 = pair(13);
    let q = (b0 + b1 * z8) + (b2 + b3 * z8) * (z8 * z8);
    let mut r = off + (z + z3 * q);
    if swap {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y.is_sign_negative() {
        -r
    } else {
        r
    }
}

/// Forward-mode dual number over f64: a value and its gradient with respect to three inputs
/// (the chain rule is written once, in [`crate::dual`]).
pub type Dual3 = Dual<f64>;

impl DualScalar for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const EXTENDED: bool = false;
    const EPSILON: f64 = f64::EPSILON;
    #[inline]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline]
    fn leading(self) -> f64 {
        self
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn pi() -> Self {
        std::f64::consts::PI
    }
    #[inline]
    fn add_f64(self, v: f64) -> Self {
        self + v
    }
    #[inline]
    fn mul_f64(self, v: f64) -> Self {
        self * v
    }
    /// By the reciprocal (one division for the value and the three derivatives).
    #[inline]
    fn div_f64(self, v: f64) -> Self {
        self * (1.0 / v)
    }
    #[inline]
    fn quotient_and_recip(self, d: Self) -> (Self, Self) {
        let inv = 1.0 / d;
        (self * inv, inv)
    }
    #[inline]
    fn recip(self) -> Self {
        1.0 / self
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
    #[inline]
    fn asin_and_slope(self) -> (Self, Self) {
        let x = self.clamp(-1.0, 1.0);
        let w = (1.0 - x * x).sqrt();
        (x.asin(), if w > 0.0 { 1.0 / w } else { 0.0 })
    }
    #[inline]
    fn atan(self) -> Self {
        f64::atan(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
    #[inline]
    fn atan2_fast(self, x: Self) -> Self {
        fast_atan2(self, x)
    }
    #[inline]
    fn exp(self) -> Self {
        f64::exp(self)
    }
    #[inline]
    fn ln(self) -> Self {
        f64::ln(self)
    }
    #[inline]
    fn tanh(self) -> Self {
        f64::tanh(self)
    }
    #[inline]
    fn sinh(self) -> Self {
        f64::sinh(self)
    }
    #[inline]
    fn cosh(self) -> Self {
        f64::cosh(self)
    }
    #[inline]
    fn asinh(self) -> Self {
        f64::asinh(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

/// The elementary functions of every dual number, by the chain rule on its scalar's own.
impl<S: DualScalar> Real for Dual<S> {
    const HAS_DERIVATIVES: bool = true;
    const EXTENDED: bool = S::EXTENDED;
    const EPSILON: f64 = S::EPSILON;
    #[inline]
    fn from_f64(v: f64) -> Self {
        Self::constant(S::from_f64(v))
    }
    #[inline]
    fn pi() -> Self {
        Self::constant(S::pi())
    }
    #[inline]
    fn re(self) -> f64 {
        self.v.leading()
    }
    /// Replaces the value by an f64: for a double-double scalar only for values known to f64
    /// accuracy (generic code that runs on it must not call this; see [`Real::EXTENDED`]).
    #[inline]
    fn with_re(self, v: f64) -> Self {
        Self {
            v: S::from_f64(v),
            g: self.g,
        }
    }
    #[inline]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        let d = if s.leading() > 0.0 {
            s.recip().mul_f64(0.5)
        } else {
            S::ZERO
        };
        self.chain(s, d)
    }
    #[inline]
    fn sin(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.chain(s, c)
    }
    #[inline]
    fn cos(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.chain(c, -s)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c), self.chain(c, -s))
    }
    #[inline]
    fn asin(self) -> Self {
        let (v, d) = self.v.asin_and_slope();
        self.chain(v, d)
    }
    #[inline]
    fn atan(self) -> Self {
        self.chain(self.v.atan(), (S::ONE + self.v * self.v).recip())
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        self.atan2_with(x, self.v.atan2(x.v))
    }
    #[inline]
    fn atan2_slope(self, x: Self) -> Self {
        self.atan2_with(x, S::ZERO)
    }
    #[inline]
    fn atan2_fast(self, x: Self) -> Self {
        self.atan2_with(x, self.v.atan2_fast(x.v))
    }
    #[inline]
    fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e)
    }
    #[inline]
    fn ln(self) -> Self {
        self.chain(self.v.ln(), self.v.recip())
    }
    #[inline]
    fn tanh(self) -> Self {
        let t = self.v.tanh();
        self.chain(t, S::ONE - t * t)
    }
    #[inline]
    fn sinh(self) -> Self {
        self.chain(self.v.sinh(), self.v.cosh())
    }
    #[inline]
    fn cosh(self) -> Self {
        self.chain(self.v.cosh(), self.v.sinh())
    }
    #[inline]
    fn asinh(self) -> Self {
        let d = (S::ONE + self.v * self.v).sqrt().recip();
        self.chain(self.v.asinh(), d)
    }
    #[inline]
    fn abs(self) -> Self {
        if self.v.leading() < 0.0 {
            -self
        } else {
            self
        }
    }
    #[inline]
    fn recip(self) -> Self {
        let inv = self.v.recip();
        self.chain(inv, -(inv * inv))
    }
    #[inline]
    fn is_finite(self) -> bool {
        self.v.is_finite() && self.g.iter().all(|x| x.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type F1 = fn(Dual3) -> Dual3;
    type G1 = fn(f64) -> f64;

    fn check(name: &str, fd: F1, ff: G1, x: f64) {
        let d = fd(Dual3::new(x, [1.0, -2.0, 0.5]));
        let h = 1e-6 * x.abs().max(1.0);
        let num = (ff(x + h) - ff(x - h)) / (2.0 * h);
        let tol = 1e-7 * num.abs().max(1.0);
        assert!(
            (d.v - ff(x)).abs() <= 1e-15 * ff(x).abs().max(1.0),
            "{name} value at {x}"
        );
        assert!(
            (d.g[0] - num).abs() <= tol,
            "{name}'({x}) = {} vs fd {num}",
            d.g[0]
        );
        assert!((d.g[1] + 2.0 * num).abs() <= 2.0 * tol, "{name} grad[1]");
        assert!((d.g[2] - 0.5 * num).abs() <= tol, "{name} grad[2]");
    }

    #[test]
    fn unary_rules_match_finite_differences() {
        for &x in &[-2.3, -0.7, -0.1, 0.3, 0.9, 1.7, 4.2] {
            check("sin", |d| d.sin(), f64::sin, x);
            check("cos", |d| d.cos(), f64::cos, x);
            check("atan", |d| d.atan(), f64::atan, x);
            check("exp", |d| d.exp(), f64::exp, x);
            check("tanh", |d| d.tanh(), f64::tanh, x);
            check("sinh", |d| d.sinh(), f64::sinh, x);
            check("cosh", |d| d.cosh(), f64::cosh, x);
            check("asinh", |d| d.asinh(), f64::asinh, x);
            check("recip", |d| d.recip(), |v| 1.0 / v, x);
            check("sq", |d| d * d, |v| v * v, x);
            check("cube/3", |d| d * d * d / 3.0, |v| v * v * v / 3.0, x);
            check(
                "affine",
                |d| (d + 1.5) * 2.0 - 0.25,
                |v| (v + 1.5) * 2.0 - 0.25,
                x,
            );
            check("abs", |d| d.abs(), f64::abs, x);
        }
        for &x in &[0.05, 0.3, 0.9, 1.7, 4.2] {
            check("sqrt", |d| d.sqrt(), f64::sqrt, x);
            check("ln", |d| d.ln(), f64::ln, x);
        }
        for &x in &[-0.95, -0.4, 0.0, 0.3, 0.9] {
            check("asin", |d| d.asin(), f64::asin, x);
        }
    }

    #[test]
    fn binary_rules_match_finite_differences() {
        let pts = [(0.3, 1.2), (-0.7, 0.4), (2.0, -1.5), (-1.0, -0.2)];
        for &(y, x) in &pts {
            let dy = Dual3::variable(y, 0);
            let dx = Dual3::variable(x, 1);
            let h = 1e-6;
            type B = fn(f64, f64) -> f64;
            let fs: [(Dual3, B); 5] = [
                (dy.atan2(dx), f64::atan2),
                (dy / dx, |a, b| a / b),
                (dy * dx, |a, b| a * b),
                (dy - dx, |a, b| a - b),
                (dy + dx, |a, b| a + b),
            ];
            for (d, f) in fs {
                let gy = (f(y + h, x) - f(y - h, x)) / (2.0 * h);
                let gx = (f(y, x + h) - f(y, x - h)) / (2.0 * h);
                assert!((d.v - f(y, x)).abs() < 1e-15);
                assert!((d.g[0] - gy).abs() < 1e-7 * gy.abs().max(1.0));
                assert!((d.g[1] - gx).abs() < 1e-7 * gx.abs().max(1.0));
                assert_eq!(d.g[2], 0.0);
            }
        }
    }

    /// Bit for bit `f64::round` on the edges (halves, the last fractional ulps, 2⁵², signed
    /// zeros, infinities, NaN) and on 200,000 log-scale values of both signs with the half
    /// nearest each.
    #[test]
    fn fast_round_is_round() {
        let two52 = 4_503_599_627_370_496.0f64;
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.4,
            -0.4,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            two52 - 0.5,
            -(two52 - 0.5),
            two52,
            -two52,
            two52 + 1.0,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            9.2e18,
            -9.3e18,
        ];
        let mut r = crate::rng::SplitMix64::new(17);
        for _ in 0..200_000 {
            let x = r.signed_pow10(-8.0, 17.0);
            xs.push(x);
            xs.push(x.floor() + 0.5);
        }
        for x in xs {
            let (got, want) = (fast_round(x), x.round());
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "fast_round({x:e}) = {got:e}, round = {want:e}"
            );
        }
    }

    #[test]
    fn fast_atan2_matches_libm() {
        let mut state: u64 = 12345;
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst = 0.0f64;
        for i in 0..400_000 {
            let sc = 10f64.powf(-20.0 + 40.0 * next());
            let (y, x) = if i % 4 == 0 {
                // near the octant and reduction boundaries
                let a = std::f64::consts::PI * ((next() * 24.0).round() / 12.0 - 1.0);
                let a = a + (next() - 0.5) * 1e-6;
                (a.sin() * sc, a.cos() * sc)
            } else {
                ((next() - 0.5) * sc, (next() - 0.5) * sc)
            };
            let e = (fast_atan2(y, x) - y.atan2(x)).abs();
            worst = worst.max(e);
            assert!(e <= 5e-16, "atan2({y}, {x}): {e:e}");
        }
        for (y, x) in [
            (0.0, 0.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
        ] {
            assert_eq!(fast_atan2(y, x).to_bits(), y.atan2(x).to_bits(), "{y} {x}");
        }
        assert!(fast_atan2(f64::NAN, 1.0).is_nan());
        eprintln!("fast_atan2 worst {worst:e}");
    }

    #[test]
    fn degenerate_points_stay_finite() {
        assert_eq!(Dual3::variable(0.0, 0).sqrt(), Dual3::constant(0.0));
        assert!(Dual3::variable(1.0, 0).asin().is_finite());
        assert!(Dual3::variable(0.0, 0)
            .atan2(Dual3::variable(0.0, 1))
            .is_finite());
        assert!(Dual3::variable(2.0, 5).g.iter().all(|&g| g == 0.0));
    }
}
