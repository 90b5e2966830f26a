//! The one stability scan (docs/math.md §5 and §10): the sampling of g(t) = det J(t)/D0(t)
//! (D0 the rod's small-t leading term), the root finding that places the first conjugate point,
//! the refinement of the margin min g on [[`T_MARGIN`], 1] and the verdict with its error bound.
//! Written once over what a rod gives: a probe g(t) anywhere on [t0, 1] ([`scan`]: the planar
//! closed forms and series), or step by step as an integration produces it ([`Stream`]: the
//! heavy rod's series, the 3-D rod's dense output, the ODE references' grids).
//!
//! The rule is the Jacobi condition: stable ⇔ det J(t) > 0 on (0, 1] (Bretl & McCarthy 2014,
//! docs/math.md §5); a rod whose det J vanishes identically (straight along its force) is
//! [`undecided`].

// NaN is a value here (g without a sign): `!(x > 0.0)` says "not known positive" on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod cubic;
mod minimum;
mod probe;
mod root;
mod stream;

#[cfg(test)]
mod tests;

pub(crate) use minimum::{golden_min, refine_margin};
pub(crate) use probe::{
    undecided, value_only, verdict, Probe, Scan, MAX_EXTRA_SAMPLES, MAX_SAMPLES, T_MARGIN,
};
pub(crate) use root::find_root;
pub(crate) use stream::Stream;

use crate::RodError;

/// Scan of g on [t0, 1] with spacing ≈ `h_target`, root finding on the first sign change and
/// refinement of local minima for the margin (with g′ where the probe gives it).
pub(crate) fn scan(
    g: &impl Fn(f64) -> Probe,
    t0: f64,
    h_target: f64,
    around: [f64; 3],
    extra: &[f64],
) -> Result<Scan, RodError> {
    let mut ts = [0.0f64; MAX_SAMPLES];
    let np = sample_times_into(&mut ts, t0, h_target, around, extra);
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

/// The sample times: a grid of spacing ≈ `h_target` on [t0, 1], T_MARGIN, the three times
/// `around` (NaN: none; the planar rod's t* where its normalisation changes regime), and `extra` (at most [`MAX_EXTRA_SAMPLES`]), sorted;
/// returns them and their number.
pub(crate) fn sample_times(
    t0: f64,
    h_target: f64,
    around: [f64; 3],
    extra: &[f64],
) -> ([f64; MAX_SAMPLES], usize) {
    let mut ts = [0.0f64; MAX_SAMPLES];
    let np = sample_times_into(&mut ts, t0, h_target, around, extra);
    (ts, np)
}

/// [`sample_times`] written into `ts` (the scan's own array: returned by value, the 112 times
/// were copied); returns their number.
pub(crate) fn sample_times_into(
    ts: &mut [f64; MAX_SAMPLES],
    t0: f64,
    h_target: f64,
    around: [f64; 3],
    extra: &[f64],
) -> usize {
    let n = ((1.0 - t0) / h_target).ceil().max(1.0) as usize;
    let n = n.min(MAX_SAMPLES - 4 - MAX_EXTRA_SAMPLES);
    let h = (1.0 - t0) / n as f64;
    let mut np = n + 1;
    for (i, t) in ts.iter_mut().enumerate().take(np) {
        *t = if i == n { 1.0 } else { t0 + i as f64 * h };
    }
    // The margin's window starts at T_MARGIN, where g is often smallest: sample it exactly;
    // and where the rod's normalisation changes regime (`around`).
    let fixed = [T_MARGIN, around[0], around[1], around[2]];
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
pub(crate) fn first_sign_change(
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
