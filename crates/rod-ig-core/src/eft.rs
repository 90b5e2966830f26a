//! Error-free transformations of f64 arithmetic (Knuth's TwoSum, Dekker's product): the exact
//! rounding error of a sum or product as a second f64. Shared by the double-double series
//! (`planar::taylor`) and the exact angle reduction (`angle`).

/// a + b = s + e exactly, s = fl(a + b) (Knuth's TwoSum, no branch).
#[inline]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// a = hi + lo with hi holding the top 26 bits (Dekker's splitting, constant 2²⁷ + 1).
#[inline]
fn split(a: f64) -> (f64, f64) {
    let t = 134_217_729.0 * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

/// a·b = p + e exactly, p = fl(a·b) (Dekker's product; no FMA needed).
#[inline]
pub(crate) fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}
