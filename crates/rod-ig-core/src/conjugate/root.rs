//! Root finding for the first conjugate point: where g turns from positive to ≤ 0 inside a
//! bracket, to [`ROOT_TOL`].

use super::cubic::HermiteCubic;
use super::probe::Probe;

/// Bracket width to which a conjugate point is located.
pub(crate) const ROOT_TOL: f64 = 1e-7;

/// Steps of [`find_root`] with slopes before the rest of the bracket goes to the regula falsi.
pub(crate) const ROOT_SLOPE_STEPS: usize = 8;

/// The root of g in (t0, t1), g(t0) > 0 ≥ g(t1), to [`ROOT_TOL`] (the end where g ≤ 0). Where
/// both ends carry values and slopes: the root of the cubic Hermite interpolant through them
/// ([`hermite_root`], always inside the bracket), kept 0.4·ROOT_TOL inside so that once an
/// end holds the root to that, the next sample lands past it and closes the bracket: ~3
/// samples from a grid interval of 0.1, where the regula falsi takes ~6. Elsewhere, and for
/// what [`ROOT_SLOPE_STEPS`] steps leave, the regula falsi ([`regula_falsi`]).
pub(crate) fn find_root(
    g: &impl Fn(f64) -> Probe,
    (t0, p0): (f64, Probe),
    (t1, p1): (f64, Probe),
) -> f64 {
    let (mut lo, mut plo, mut hi, mut phi) = (t0, p0, t1, p1);
    for _ in 0..ROOT_SLOPE_STEPS {
        if hi - lo <= ROOT_TOL {
            return hi;
        }
        let finite = [plo.v, plo.d, phi.v, phi.d].iter().all(|v| v.is_finite());
        if !(finite && plo.v > 0.0 && phi.v <= 0.0) {
            break;
        }
        let t = hermite_root((lo, plo), (hi, phi));
        let t = if t.is_finite() {
            t.clamp(lo + 0.4 * ROOT_TOL, hi - 0.4 * ROOT_TOL)
        } else {
            0.5 * (lo + hi)
        };
        let p = g(t);
        if p.v == 0.0 {
            return t;
        }
        // NaN: a sign known positive ([`scan`]).
        if p.v > 0.0 || p.v.is_nan() {
            (lo, plo) = (t, p);
        } else {
            (hi, phi) = (t, p);
        }
    }
    if hi - lo <= ROOT_TOL {
        return hi;
    }
    regula_falsi(&|t| g(t).v, lo, plo.v, hi, phi.v)
}

/// A root in (t0, t1) of the cubic Hermite interpolant through (t0, g0, g0′), (t1, g1, g1′)
/// with g0 > 0 ≥ g1 (so one exists): safeguarded Newton steps on the cubic from the regula
/// falsi point, bisection where a step leaves the bracket, to 1e-3 of [`ROOT_TOL`].
pub(crate) fn hermite_root((t0, p0): (f64, Probe), (t1, p1): (f64, Probe)) -> f64 {
    let h = t1 - t0;
    let cubic = HermiteCubic::new((t0, p0), (t1, p1));
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let mut s = p0.v / (p0.v - p1.v);
    for _ in 0..12 {
        let v = cubic.at(s);
        if v > 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        let next = s - v / cubic.slope(s);
        let next = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        let step = (next - s).abs();
        s = next;
        if step * h < 1e-3 * ROOT_TOL {
            break;
        }
    }
    t0 + s * h
}

/// Illinois regula falsi for the root of g in (t0, t1) with g(t0) > 0 ≥ g(t1).
pub(crate) fn regula_falsi(g: &impl Fn(f64) -> f64, t0: f64, g0: f64, t1: f64, g1: f64) -> f64 {
    let (mut lo, mut glo, mut hi, mut ghi) = (t0, g0, t1, g1);
    let mut side = 0i8;
    for _ in 0..24 {
        if hi - lo <= 1e-7 {
            break;
        }
        let mut t = (lo * ghi - hi * glo) / (ghi - glo);
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let gt = g(t);
        // NaN: a sign known positive ([`scan`]).
        if gt > 0.0 || gt.is_nan() {
            if side == -1 {
                ghi *= anderson_bjorck(gt, glo);
            }
            lo = t;
            glo = gt;
            side = -1;
        } else {
            if side == 1 {
                glo *= anderson_bjorck(gt, ghi);
            }
            hi = t;
            ghi = gt;
            side = 1;
        }
        if gt == 0.0 {
            return t;
        }
    }
    // Illinois stalls on a g growing like e^{2√‖F‖ t} (under a tension of 71,306 it stopped
    // 0.003 past the root): bisection finishes the bracket.
    for _ in 0..32 {
        if hi - lo <= 1e-7 {
            break;
        }
        let t = 0.5 * (lo + hi);
        let gt = g(t);
        if gt > 0.0 || gt.is_nan() {
            lo = t;
        } else {
            hi = t;
        }
    }
    hi
}

/// The factor on the value kept at the end of the bracket that did not move twice in a row
/// (Anderson & Björck 1973): 1 − g_new/g_old for the end that moved, ½ (Illinois) where that
/// is not in (0, 1).
pub(crate) fn anderson_bjorck(g_new: f64, g_old: f64) -> f64 {
    let m = 1.0 - g_new / g_old;
    if m > 0.0 && m < 1.0 {
        m
    } else {
        0.5
    }
}

/// The crossing of g in (lo, hi) with g(lo) > 0 ≥ g(hi) by bisection until the bracket is
/// below `tol` (at most `max_steps` halvings; for g known only by samples of an integration's
/// dense output or polynomial, where bisection's sign tests are all that is trusted). Returns
/// the end where g ≤ 0.
pub(crate) fn bisect_root(
    g: &impl Fn(f64) -> f64,
    mut lo: f64,
    mut hi: f64,
    tol: f64,
    max_steps: usize,
) -> f64 {
    for _ in 0..max_steps {
        if hi - lo <= tol {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if g(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}
