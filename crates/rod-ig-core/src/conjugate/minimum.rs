//! The margin's minimum: refinement of the local minima of g between samples (with slopes
//! where the probe gives them), and a golden-section search for g known by values alone.

use super::cubic::{cubic_low, cubic_minimiser};
use super::probe::{Probe, MAX_SAMPLES, T_MARGIN};
use super::root::find_root;

/// The margin: min g over t ≥ T_MARGIN with the coarse minima that matter refined
/// ([`refine_min`]: those low enough to hide a dip below zero or to be the global minimum;
/// only the global one once a sign change is known). A minimum is an interval where g′ turns
/// from ≤ 0 to ≥ 0 where both ends carry slopes (its low estimated by the cubic through
/// them), else a sample below both neighbours. A dip below zero found between two samples
/// becomes the first sign change. Returns (margin, where).
pub(crate) fn refine_margin(
    g: &impl Fn(f64) -> Probe,
    ts: &[f64],
    ps: &[Probe],
    first: &mut Option<(f64, f64, f64)>,
) -> (f64, f64) {
    let mut margin = f64::INFINITY;
    let mut t_margin = 1.0;
    for (&t, p) in ts.iter().zip(ps) {
        if t >= T_MARGIN && p.v < margin {
            margin = p.v;
            t_margin = t;
        }
    }
    let cutoff = if first.is_some() {
        margin
    } else {
        2.0 * margin.max(0.0) + 0.05
    };
    let n = ts.len();
    // Per interval [t_i, t_i+1]: both ends carry slopes and g′ turns from ≤ 0 to ≥ 0 there
    // (NaN slopes fail both tests).
    let mut turns = [false; MAX_SAMPLES];
    for i in 0..n.saturating_sub(1) {
        turns[i] = ps[i].d <= 0.0 && ps[i + 1].d >= 0.0;
    }
    for i in 0..n.saturating_sub(1) {
        let found = if turns[i] {
            // A minimum inside [t_i, t_i+1] (its slopes say so).
            let (left, right) = ((ts[i], ps[i]), (ts[i + 1], ps[i + 1]));
            // (A NaN low is not below the cutoff.)
            let low_enough = cubic_low(left, right) <= cutoff;
            if ts[i + 1] < T_MARGIN || !low_enough {
                continue;
            }
            (i, refine_min_sloped(g, left, right))
        } else if i >= 1 && !turns[i - 1] {
            // A sample below both neighbours that no turn of the slopes beside it accounts
            // for (no slopes there, or two extrema between samples).
            let (v0, v1, v2) = (ps[i - 1].v, ps[i].v, ps[i + 1].v);
            if !(v1 <= v0 && v1 <= v2 && ts[i + 1] >= T_MARGIN && v1 <= cutoff) {
                continue;
            }
            let refined = refine_min(
                g,
                (ts[i - 1], ps[i - 1]),
                (ts[i], ps[i]),
                (ts[i + 1], ps[i + 1]),
            );
            (i - 1, refined)
        } else {
            continue;
        };
        let (k, (tm, pm)) = found;
        if tm < T_MARGIN || pm.v.is_nan() {
            continue;
        }
        if pm.v < margin {
            margin = pm.v;
            t_margin = tm;
        }
        if first.is_none() && pm.v <= 0.0 {
            // A dip below zero between two coarse samples.
            let tc = if ps[k].v > 0.0 {
                find_root(g, (ts[k], ps[k]), (tm, pm))
            } else {
                tm
            };
            *first = Some((tc, pm.v, tm));
        }
    }
    if first.is_none() {
        (margin, t_margin) = refine_window_ends(g, ts, ps, (margin, t_margin), first);
    }
    (margin, t_margin)
}

/// The margin's window ends (T_MARGIN, 1) where the lowest sample lies there and no slopes
/// say more: g may dip between it and the next sample (under a strong force the dips are
/// ~1/√‖F‖ wide, the grid 0.1). One probe a quarter of the way in; if it is lower, a refinement of the bracket it
/// makes (a dip found below zero becomes the first sign change).
pub(crate) fn refine_window_ends(
    g: &impl Fn(f64) -> Probe,
    ts: &[f64],
    ps: &[Probe],
    (mut margin, mut t_margin): (f64, f64),
    first: &mut Option<(f64, f64, f64)>,
) -> (f64, f64) {
    let n = ts.len();
    let Some(lo) = ts.iter().position(|&t| t >= T_MARGIN) else {
        return (margin, t_margin);
    };
    for (end, inner) in [(lo, lo + 1), (n - 1, n.wrapping_sub(2))] {
        if inner >= n || inner < lo || ps[end].v != margin || ps[inner].v <= ps[end].v {
            continue;
        }
        if ps[end].d.is_finite() && ps[inner].d.is_finite() {
            // The slopes have told already: a minimum inside was refined ([`refine_margin`]),
            // or g rises from the end.
            continue;
        }
        let tp = ts[end] + 0.25 * (ts[inner] - ts[end]);
        let pp = g(tp);
        // (NaN, no sign, is not lower.)
        if pp.v.is_nan() || pp.v >= ps[end].v {
            continue;
        }
        let (left, right) = if end < inner {
            ((ts[end], ps[end]), (ts[inner], ps[inner]))
        } else {
            ((ts[inner], ps[inner]), (ts[end], ps[end]))
        };
        let (tm, pm) = refine_min(g, left, (tp, pp), right);
        (margin, t_margin) = if pm.v < pp.v { (pm.v, tm) } else { (pp.v, tp) };
        if margin <= 0.0 && first.is_none() {
            let at_margin = if pm.v < pp.v { pm } else { pp };
            let tc = if left.1.v > 0.0 {
                find_root(g, left, (t_margin, at_margin))
            } else {
                t_margin
            };
            *first = Some((tc, margin, t_margin));
        }
    }
    (margin, t_margin)
}

/// Improvement of a refined minimum, relative to max(|g|, 1), below which [`refine_min`] stops
/// (with slopes; the parabolic steps stop at a bracket of 1e-4, ~1e-9 of g).
pub(crate) const MIN_GAIN_REL: f64 = 1e-10;

/// A local minimum of g bracketed by t0 < t1 < t2 with g(t1) ≤ g(t0), g(t2): (where, g
/// there), the lowest sample seen. With slopes at all three, cubic Hermite steps on the half
/// where g′ changes sign ([`refine_min_sloped`]); otherwise parabolic steps.
pub(crate) fn refine_min(
    g: &impl Fn(f64) -> Probe,
    (t0, p0): (f64, Probe),
    (t1, p1): (f64, Probe),
    (t2, p2): (f64, Probe),
) -> (f64, Probe) {
    if p0.d.is_finite() && p1.d.is_finite() && p2.d.is_finite() {
        let (left, right) = if p1.d <= 0.0 {
            ((t1, p1), (t2, p2))
        } else {
            ((t0, p0), (t1, p1))
        };
        if left.1.d <= 0.0 && right.1.d >= 0.0 {
            return refine_min_sloped(g, left, right);
        }
    }
    refine_min_parabolic(g, (t0, p0), (t1, p1), (t2, p2))
}

/// The minimum of g on [l, r] where g′(l) ≤ 0 ≤ g′(r), by the minimiser of the cubic Hermite
/// interpolant (Nocedal & Wright, Numerical Optimization, eq. 3.59) until the gain the slope
/// predicts, g′²/(2g″), falls below [`MIN_GAIN_REL`]; the lowest sample seen.
pub(crate) fn refine_min_sloped(
    g: &impl Fn(f64) -> Probe,
    (mut l, mut pl): (f64, Probe),
    (mut r, mut pr): (f64, Probe),
) -> (f64, Probe) {
    let mut best = if pl.v <= pr.v { (l, pl) } else { (r, pr) };
    for _ in 0..6 {
        if r - l < 1e-9 {
            break;
        }
        let t = cubic_minimiser((l, pl), (r, pr));
        let p = g(t);
        if !(p.v.is_finite() && p.d.is_finite()) {
            break;
        }
        if p.v < best.1.v {
            best = (t, p);
        }
        if p.d <= 0.0 {
            (l, pl) = (t, p);
        } else {
            (r, pr) = (t, p);
        }
        let curvature = (pr.d - pl.d) / (r - l);
        if curvature > 0.0 && p.d * p.d / (2.0 * curvature) <= MIN_GAIN_REL * p.v.abs().max(1.0) {
            break;
        }
    }
    best
}

/// Parabolic steps on a bracketed minimum (values alone), to a bracket of 1e-4.
pub(crate) fn refine_min_parabolic(
    g: &impl Fn(f64) -> Probe,
    (t0, p0): (f64, Probe),
    (t1, p1): (f64, Probe),
    (t2, p2): (f64, Probe),
) -> (f64, Probe) {
    let (mut a, mut b, mut c) = (t0, t1, t2);
    let (mut fa, mut fc) = (p0.v, p2.v);
    let mut pb = p1;
    for _ in 0..6 {
        if c - a < 1e-4 {
            break;
        }
        let fb = pb.v;
        let p = (b - a) * (b - a) * (fb - fc) - (b - c) * (b - c) * (fb - fa);
        let q = (b - a) * (fb - fc) - (b - c) * (fb - fa);
        if q == 0.0 {
            break;
        }
        let mut t = b - 0.5 * p / q;
        if !(t > a && t < c) || (t - b).abs() < 1e-9 {
            if (t - b).abs() < 1e-9 {
                break;
            }
            t = 0.5 * (b + if b - a > c - b { a } else { c });
        }
        let pt = g(t);
        let ft = pt.v;
        if ft < fb {
            if t < b {
                c = b;
                fc = fb;
            } else {
                a = b;
                fa = fb;
            }
            b = t;
            pb = pt;
        } else if t < b {
            a = t;
            fa = ft;
        } else {
            c = t;
            fc = ft;
        }
    }
    (b, pb)
}

/// The minimum of f on [lo, hi] by golden-section search (24 steps: the bracket shrinks to
/// 1e-5 of its width; f unimodal there by the sampling that bracketed it).
pub(crate) fn golden_min(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    const R: f64 = 0.618_033_988_749_894_8;
    if !(hi > lo) {
        return lo;
    }
    let mut x1 = hi - R * (hi - lo);
    let mut x2 = lo + R * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..24 {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - R * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + R * (hi - lo);
            f2 = f(x2);
        }
    }
    if f1 < f2 {
        x1
    } else {
        x2
    }
}
