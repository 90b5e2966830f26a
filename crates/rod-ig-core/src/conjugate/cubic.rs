//! The cubic Hermite interpolant through two samples of g with their slopes, and its minimum.

use super::probe::Probe;

/// The lowest value on [l, r] of the cubic Hermite interpolant through g and g′ at both ends
/// (g′(l) ≤ 0 ≤ g′(r)): its minimiser by Nocedal & Wright's eq. 3.59.
pub(crate) fn cubic_low((l, pl): (f64, Probe), (r, pr): (f64, Probe)) -> f64 {
    let t = cubic_minimiser((l, pl), (r, pr));
    let cubic = HermiteCubic::new((l, pl), (r, pr));
    let v = cubic.at((t - l) / (r - l));
    v.min(pl.v).min(pr.v)
}

/// The cubic Hermite interpolant through (t0, g0, g0′), (t1, g1, g1′) in s = (t − t0)/h:
/// g0 + m0 s + c2 s² + c3 s³ with m = g′h.
pub(crate) struct HermiteCubic {
    pub(crate) g0: f64,
    pub(crate) m0: f64,
    pub(crate) c2: f64,
    pub(crate) c3: f64,
}

impl HermiteCubic {
    pub(crate) fn new((t0, p0): (f64, Probe), (t1, p1): (f64, Probe)) -> Self {
        let h = t1 - t0;
        let (m0, m1) = (p0.d * h, p1.d * h);
        Self {
            g0: p0.v,
            m0,
            c2: 3.0 * (p1.v - p0.v) - 2.0 * m0 - m1,
            c3: 2.0 * (p0.v - p1.v) + m0 + m1,
        }
    }

    /// Its value at s.
    pub(crate) fn at(&self, s: f64) -> f64 {
        self.g0 + s * (self.m0 + s * (self.c2 + s * self.c3))
    }

    /// Its derivative in s at s.
    pub(crate) fn slope(&self, s: f64) -> f64 {
        self.m0 + s * (2.0 * self.c2 + s * 3.0 * self.c3)
    }
}

/// The minimiser in (l, r) of the cubic Hermite interpolant through g and g′ at both ends
/// (Nocedal & Wright, Numerical Optimization, eq. 3.59); the midpoint where that fails.
pub(crate) fn cubic_minimiser((l, pl): (f64, Probe), (r, pr): (f64, Probe)) -> f64 {
    let d1 = pl.d + pr.d - 3.0 * (pl.v - pr.v) / (l - r);
    let d2 = (d1 * d1 - pl.d * pr.d).sqrt();
    let t = r - (r - l) * (pr.d + d2 - d1) / (pr.d - pl.d + 2.0 * d2);
    if t > l && t < r {
        t
    } else {
        0.5 * (l + r)
    }
}
