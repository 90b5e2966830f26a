//! One forward-mode dual number, [`Dual<S>`]: a value and its gradient with respect to three
//! inputs, generic over the scalar that carries them. [`crate::scalar::Dual3`] is `Dual<f64>`
//! (J in the same pass as the pose), [`crate::dd::DualDd`] is `Dual<Dd>` (the same closed
//! forms and series in double-double where f64 cancels).
//!
//! The chain rule is written once here (the arithmetic) and in `scalar.rs` (the elementary
//! functions, [`crate::scalar::Real`] for every `Dual<S>`); what differs between the scalars is
//! only their own arithmetic and functions, which each provides through [`DualScalar`]. Every
//! operation applies the chain rule exactly; there is no heap allocation.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// What a dual number needs of the scalar it carries: ring arithmetic, mixed arithmetic with
/// f64 and the elementary functions, each to the scalar's own precision.
///
/// The few operations whose rounding differs by scalar are methods here so that each keeps
/// its cheapest exact form (f64 divides once and multiplies by the reciprocal; double-double
/// divides in full).
pub trait DualScalar:
    Copy
    + std::fmt::Debug
    + Default
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// Beyond f64 ([`crate::scalar::Real::EXTENDED`]).
    const EXTENDED: bool;
    /// Unit roundoff ([`crate::scalar::Real::EPSILON`]).
    const EPSILON: f64;
    /// An f64, exactly.
    fn from_f64(v: f64) -> Self;
    /// The leading f64 (the value for f64, the high part for double-double): branch decisions.
    fn leading(self) -> f64;
    /// The value rounded to f64.
    fn to_f64(self) -> f64;
    /// π to the scalar's precision.
    fn pi() -> Self;
    /// self + v.
    fn add_f64(self, v: f64) -> Self;
    /// self · v.
    fn mul_f64(self, v: f64) -> Self;
    /// self / v.
    fn div_f64(self, v: f64) -> Self;
    /// (self / d, 1 / d).
    fn quotient_and_recip(self, d: Self) -> (Self, Self);
    /// 1 / self.
    fn recip(self) -> Self;
    /// √self (0 at 0).
    fn sqrt(self) -> Self;
    /// (sin, cos).
    fn sin_cos(self) -> (Self, Self);
    /// asin of the argument clamped to [−1, 1], and its slope 1/√(1 − x²) (0 at ±1).
    fn asin_and_slope(self) -> (Self, Self);
    /// atan.
    fn atan(self) -> Self;
    /// atan2(self, x).
    fn atan2(self, x: Self) -> Self;
    /// atan2 to ≤ 5e-16 absolute where that is cheaper ([`crate::scalar::fast_atan2`]).
    fn atan2_fast(self, x: Self) -> Self {
        self.atan2(x)
    }
    /// eˣ.
    fn exp(self) -> Self;
    /// ln x.
    fn ln(self) -> Self;
    /// tanh.
    fn tanh(self) -> Self;
    /// sinh.
    fn sinh(self) -> Self;
    /// cosh.
    fn cosh(self) -> Self;
    /// asinh.
    fn asinh(self) -> Self;
    /// Finite.
    fn is_finite(self) -> bool;
}

/// Forward-mode dual number: a value `v` and its gradient `g` with respect to three inputs,
/// both in the scalar `S`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dual<S> {
    /// Value.
    pub v: S,
    /// Gradient ∂v/∂(p0, p1, p2).
    pub g: [S; 3],
}

impl<S: DualScalar> Dual<S> {
    /// A dual number from its value and gradient.
    #[inline]
    pub const fn new(v: S, g: [S; 3]) -> Self {
        Self { v, g }
    }
    /// A constant (zero gradient).
    #[inline]
    pub const fn constant(v: S) -> Self {
        Self { v, g: [S::ZERO; 3] }
    }
    /// The i-th independent variable at value `v` (gradient = i-th unit vector); `i` ≥ 3 gives
    /// a constant.
    #[inline]
    pub fn variable(v: f64, i: usize) -> Self {
        let mut g = [S::ZERO; 3];
        if let Some(gi) = g.get_mut(i) {
            *gi = S::ONE;
        }
        Self {
            v: S::from_f64(v),
            g,
        }
    }
    /// The value and the gradient rounded to f64.
    #[inline]
    pub fn to_f64(self) -> (f64, [f64; 3]) {
        (
            self.v.to_f64(),
            [self.g[0].to_f64(), self.g[1].to_f64(), self.g[2].to_f64()],
        )
    }
    /// f with value `v` and derivative `d` (chain rule).
    #[inline]
    pub(crate) fn chain(self, v: S, d: S) -> Self {
        Self {
            v,
            g: [d * self.g[0], d * self.g[1], d * self.g[2]],
        }
    }
    /// atan2(self, x) with the given value: d atan2(y, x) = (x dy − y dx)/(x² + y²).
    #[inline]
    pub(crate) fn atan2_with(self, x: Self, value: S) -> Self {
        let y = self;
        let r2 = x.v * x.v + y.v * y.v;
        let inv = if r2.leading() > 0.0 {
            r2.recip()
        } else {
            S::ZERO
        };
        Self {
            v: value,
            g: [
                (x.v * y.g[0] - y.v * x.g[0]) * inv,
                (x.v * y.g[1] - y.v * x.g[1]) * inv,
                (x.v * y.g[2] - y.v * x.g[2]) * inv,
            ],
        }
    }
}

impl<S: DualScalar> Add for Dual<S> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            g: [self.g[0] + o.g[0], self.g[1] + o.g[1], self.g[2] + o.g[2]],
        }
    }
}
impl<S: DualScalar> Sub for Dual<S> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            g: [self.g[0] - o.g[0], self.g[1] - o.g[1], self.g[2] - o.g[2]],
        }
    }
}
impl<S: DualScalar> Mul for Dual<S> {
    type Output = Self;
    /// The product rule.
    #[inline]
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            g: [
                self.g[0] * o.v + self.v * o.g[0],
                self.g[1] * o.v + self.v * o.g[1],
                self.g[2] * o.v + self.v * o.g[2],
            ],
        }
    }
}
impl<S: DualScalar> Div for Dual<S> {
    type Output = Self;
    /// The quotient rule: d(a/b) = (da − (a/b) db)/b.
    #[inline]
    fn div(self, o: Self) -> Self {
        let (v, inv) = self.v.quotient_and_recip(o.v);
        Self {
            v,
            g: [
                (self.g[0] - v * o.g[0]) * inv,
                (self.g[1] - v * o.g[1]) * inv,
                (self.g[2] - v * o.g[2]) * inv,
            ],
        }
    }
}
impl<S: DualScalar> Neg for Dual<S> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            v: -self.v,
            g: [-self.g[0], -self.g[1], -self.g[2]],
        }
    }
}
impl<S: DualScalar> Add<f64> for Dual<S> {
    type Output = Self;
    #[inline]
    fn add(self, o: f64) -> Self {
        Self {
            v: self.v.add_f64(o),
            g: self.g,
        }
    }
}
impl<S: DualScalar> Sub<f64> for Dual<S> {
    type Output = Self;
    #[inline]
    fn sub(self, o: f64) -> Self {
        self + (-o)
    }
}
impl<S: DualScalar> Mul<f64> for Dual<S> {
    type Output = Self;
    #[inline]
    fn mul(self, o: f64) -> Self {
        Self {
            v: self.v.mul_f64(o),
            g: [
                self.g[0].mul_f64(o),
                self.g[1].mul_f64(o),
                self.g[2].mul_f64(o),
            ],
        }
    }
}
impl<S: DualScalar> Div<f64> for Dual<S> {
    type Output = Self;
    /// Each part by the scalar's own division ([`DualScalar::div_f64`]).
    #[inline]
    fn div(self, o: f64) -> Self {
        Self {
            v: self.v.div_f64(o),
            g: [
                self.g[0].div_f64(o),
                self.g[1].div_f64(o),
                self.g[2].div_f64(o),
            ],
        }
    }
}
impl<S: DualScalar> AddAssign for Dual<S> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<S: DualScalar> SubAssign for Dual<S> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
impl<S: DualScalar> MulAssign for Dual<S> {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}
