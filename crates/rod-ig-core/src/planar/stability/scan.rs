//! The one scan of g(t) = det J(t)/leading term, written once over a probe: sampling on a
//! wavelength grid, the first sign change located to 1e-7, local minima refined for the margin.

use super::T_MARGIN;
use crate::RodError;

/// What a scan of g found.
#[derive(Clone, Copy, Debug)]
pub(super) struct Scan {
    /// First sign change (det ≤ 0).
    pub(super) first: Option<f64>,
    /// min g over t ≥ T_MARGIN (or the negative value at a sign change below it).
    pub(super) margin: f64,
    /// Where the margin was found.
    pub(super) t_margin: f64,
}

/// One evaluation of g for [`scan`]: its value (NaN: no sign, the sample is dropped) and its
/// slope g′(t), NaN where the source gives none (the series, the short series and the
/// double-double closed form).
#[derive(Clone, Copy, Debug)]
pub(super) struct Probe {
    pub(super) v: f64,
    pub(super) d: f64,
}

/// A value-only g as a [`scan`] probe (no slope).
pub(super) fn value_only(g: impl Fn(f64) -> f64) -> impl Fn(f64) -> Probe {
    move |t| Probe {
        v: g(t),
        d: f64::NAN,
    }
}

/// Scan of g on [t0, 1] with spacing ≈ `h_target`, root finding on the first sign change and
/// refinement of local minima for the margin (with g′ where the probe gives it).
pub(super) fn scan(
    g: &impl Fn(f64) -> Probe,
    t0: f64,
    h_target: f64,
    (a3, a5): (f64, f64),
    extra: &[f64],
) -> Result<Scan, RodError> {
    let mut ts = [0.0f64; MAX_SAMPLES];
    let np = sample_times_into(&mut ts, t0, h_target, (a3, a5), extra);
    let mut ps = [Probe { v: 0.0, d: 0.0 }; MAX_SAMPLES];
    // NaN: g's sign there is rounding where det J > 0 is known ([`closed_scan`]); dropped.
    let mut kept = 0;
    for i in 0..np {
        let (t, p) = (ts[i], g(ts[i]));
        if p.v.is_nan() {
            continue;
        }
        if p.v.is_infinite() {
            return Err(RodError::Overflow(
                "stability: det J(t) is not finite (parameters too large)".into(),
            ));
        }
        ts[kept] = t;
        ps[kept] = p;
        kept += 1;
    }
    let (ts, ps) = (&ts[..kept], &ps[..kept]);
    // First sign change (det ≤ 0), and the value seen there.
    let mut first = first_sign_change(g, ts, ps);
    let (mut margin, mut t_margin) = refine_margin(g, ts, ps, &mut first);
    if let Some((_, neg_value, neg_t)) = first.filter(|_| margin >= 0.0) {
        // The sign change lies below T_MARGIN: report the negative value seen there.
        margin = neg_value.min(0.0);
        t_margin = neg_t;
    }
    if !margin.is_finite() {
        margin = 0.0;
    }
    Ok(Scan {
        first: first.map(|f| f.0),
        margin,
        t_margin,
    })
}

/// The sample times: a grid of spacing ≈ `h_target` on [t0, 1], T_MARGIN, three times
/// around t* = √(33600/8640)|a3/a5|, and `extra` (at most [`MAX_EXTRA_SAMPLES`]), sorted;
/// returns them and their number.
pub(super) fn sample_times(
    t0: f64,
    h_target: f64,
    (a3, a5): (f64, f64),
    extra: &[f64],
) -> ([f64; MAX_SAMPLES], usize) {
    let mut ts = [0.0f64; MAX_SAMPLES];
    let np = sample_times_into(&mut ts, t0, h_target, (a3, a5), extra);
    (ts, np)
}

/// [`sample_times`] written into `ts` (the scan's own array: returned by value, the 112 times
/// were copied); returns their number.
pub(super) fn sample_times_into(
    ts: &mut [f64; MAX_SAMPLES],
    t0: f64,
    h_target: f64,
    (a3, a5): (f64, f64),
    extra: &[f64],
) -> usize {
    let n = ((1.0 - t0) / h_target).ceil().max(1.0) as usize;
    let n = n.min(MAX_SAMPLES - 4 - MAX_EXTRA_SAMPLES);
    let h = (1.0 - t0) / n as f64;
    let mut np = n + 1;
    for (i, t) in ts.iter_mut().enumerate().take(np) {
        *t = if i == n { 1.0 } else { t0 + i as f64 * h };
    }
    // The normalisation t⁹(a3²/8640 + a5²t²/33600) changes regime at t*, where g often has a
    // narrow dip: sample around it too (for the margin). The margin's window starts at
    // T_MARGIN, where g is often smallest (|a3| ≪ |a5|): sample it exactly.
    let ts_star = if a5 != 0.0 {
        (33600.0f64 / 8640.0).sqrt() * (a3 / a5).abs()
    } else {
        f64::NAN
    };
    let fixed = [T_MARGIN, ts_star * 0.7, ts_star, ts_star * 1.4];
    for &t in fixed.iter().chain(extra.iter().take(MAX_EXTRA_SAMPLES)) {
        if t > t0 && t < 1.0 && np < ts.len() {
            // insert keeping ts sorted
            let mut k = np;
            while k > 0 && ts[k - 1] > t {
                ts[k] = ts[k - 1];
                k -= 1;
            }
            ts[k] = t;
            np += 1;
        }
    }
    np
}

/// The first sign change of g over the samples (det ≤ 0): (where, located by [`find_root`],
/// the negative value sampled, its time).
pub(super) fn first_sign_change(
    g: &impl Fn(f64) -> Probe,
    ts: &[f64],
    ps: &[Probe],
) -> Option<(f64, f64, f64)> {
    let i = ps.iter().position(|p| p.v <= 0.0)?;
    let t = if i == 0 {
        ts[0]
    } else {
        find_root(g, (ts[i - 1], ps[i - 1]), (ts[i], ps[i]))
    };
    Some((t, ps[i].v, ts[i]))
}

/// The margin: min g over t ≥ T_MARGIN with the coarse minima that matter refined
/// ([`refine_min`]: those low enough to hide a dip below zero or to be the global minimum;
/// only the global one once a sign change is known). A minimum is an interval where g′ turns
/// from ≤ 0 to ≥ 0 where both ends carry slopes (its low estimated by the cubic through
/// them), else a sample below both neighbours. A dip below zero found between two samples
/// becomes the first sign change. Returns (margin, where).
pub(super) fn refine_margin(
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

/// The lowest value on [l, r] of the cubic Hermite interpolant through g and g′ at both ends
/// (g′(l) ≤ 0 ≤ g′(r)): its minimiser by Nocedal & Wright's eq. 3.59.
pub(super) fn cubic_low((l, pl): (f64, Probe), (r, pr): (f64, Probe)) -> f64 {
    let t = cubic_minimiser((l, pl), (r, pr));
    let cubic = HermiteCubic::new((l, pl), (r, pr));
    let v = cubic.at((t - l) / (r - l));
    v.min(pl.v).min(pr.v)
}

/// The cubic Hermite interpolant through (t0, g0, g0′), (t1, g1, g1′) in s = (t − t0)/h:
/// g0 + m0 s + c2 s² + c3 s³ with m = g′h.
pub(super) struct HermiteCubic {
    pub(super) g0: f64,
    pub(super) m0: f64,
    pub(super) c2: f64,
    pub(super) c3: f64,
}

impl HermiteCubic {
    fn new((t0, p0): (f64, Probe), (t1, p1): (f64, Probe)) -> Self {
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
    fn at(&self, s: f64) -> f64 {
        self.g0 + s * (self.m0 + s * (self.c2 + s * self.c3))
    }

    /// Its derivative in s at s.
    fn slope(&self, s: f64) -> f64 {
        self.m0 + s * (2.0 * self.c2 + s * 3.0 * self.c3)
    }
}

/// The minimiser in (l, r) of the cubic Hermite interpolant through g and g′ at both ends
/// (Nocedal & Wright, Numerical Optimization, eq. 3.59); the midpoint where that fails.
pub(super) fn cubic_minimiser((l, pl): (f64, Probe), (r, pr): (f64, Probe)) -> f64 {
    let d1 = pl.d + pr.d - 3.0 * (pl.v - pr.v) / (l - r);
    let d2 = (d1 * d1 - pl.d * pr.d).sqrt();
    let t = r - (r - l) * (pr.d + d2 - d1) / (pr.d - pl.d + 2.0 * d2);
    if t > l && t < r {
        t
    } else {
        0.5 * (l + r)
    }
}

/// The margin's window ends (T_MARGIN, 1) where the lowest sample lies there and no slopes
/// say more: g may dip between it and the next sample (under a strong force the dips are
/// ~1/√‖F‖ wide, the grid 0.1). One probe a quarter of the way in; if it is lower, a refinement of the bracket it
/// makes (a dip found below zero becomes the first sign change).
pub(super) fn refine_window_ends(
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

/// Sample budget of one scan (coarse grid, T_MARGIN, three samples around t* and the extra
/// ones).
pub(super) const MAX_SAMPLES: usize = 112;
/// Most extra sample times a scan takes (`Closed::dip_times`).
pub(super) const MAX_EXTRA_SAMPLES: usize = crate::planar::closed::MAX_DIP_TIMES;

/// Illinois regula falsi for the root of g in (t0, t1) with g(t0) > 0 ≥ g(t1).
pub(super) fn regula_falsi(g: &impl Fn(f64) -> f64, t0: f64, g0: f64, t1: f64, g1: f64) -> f64 {
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
pub(super) fn anderson_bjorck(g_new: f64, g_old: f64) -> f64 {
    let m = 1.0 - g_new / g_old;
    if m > 0.0 && m < 1.0 {
        m
    } else {
        0.5
    }
}

/// Bracket width to which a conjugate point is located.
pub(super) const ROOT_TOL: f64 = 1e-7;
/// Steps of [`find_root`] with slopes before the rest of the bracket goes to the regula falsi.
pub(super) const ROOT_SLOPE_STEPS: usize = 8;

/// The root of g in (t0, t1), g(t0) > 0 ≥ g(t1), to [`ROOT_TOL`] (the end where g ≤ 0). Where
/// both ends carry values and slopes: the root of the cubic Hermite interpolant through them
/// ([`hermite_root`], always inside the bracket), kept 0.4·ROOT_TOL inside so that once an
/// end holds the root to that, the next sample lands past it and closes the bracket: ~3
/// samples from a grid interval of 0.1, where the regula falsi takes ~6. Elsewhere, and for
/// what [`ROOT_SLOPE_STEPS`] steps leave, the regula falsi ([`regula_falsi`]).
pub(super) fn find_root(
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
pub(super) fn hermite_root((t0, p0): (f64, Probe), (t1, p1): (f64, Probe)) -> f64 {
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

/// Improvement of a refined minimum, relative to max(|g|, 1), below which [`refine_min`] stops
/// (with slopes; the parabolic steps stop at a bracket of 1e-4, ~1e-9 of g).
pub(super) const MIN_GAIN_REL: f64 = 1e-10;

/// A local minimum of g bracketed by t0 < t1 < t2 with g(t1) ≤ g(t0), g(t2): (where, g
/// there), the lowest sample seen. With slopes at all three, cubic Hermite steps on the half
/// where g′ changes sign ([`refine_min_sloped`]); otherwise parabolic steps.
pub(super) fn refine_min(
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
pub(super) fn refine_min_sloped(
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
pub(super) fn refine_min_parabolic(
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
