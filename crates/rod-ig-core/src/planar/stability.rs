//! Fast stability test on the closed form (FINDINGS §5).

use super::closed::{Case, Closed};
use crate::scalar::Dual3;
use crate::{PlanarParams, RodError, StabilityReport};

/// Below this t the closed-form det J is dominated by rounding; it is positive there by its
/// leading term (FINDINGS §5).
const T_MIN: f64 = 0.02;
/// Smallest t entering the margin `det_min` (FINDINGS §5).
const T_MARGIN: f64 = 0.05;

/// det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) (FINDINGS §5), from the dual-number closed form.
fn normalised_det(c: &Closed<Dual3>, a3: f64, a5: f64, t: f64) -> f64 {
    let [x, y, th] = c.pose(t);
    let (r0, r1, r2) = (x.g, y.g, th.g);
    let det = r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) - r0[1] * (r1[0] * r2[2] - r1[2] * r2[0])
        + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0]);
    let t2 = t * t;
    let t9 = t2 * t2 * t2 * t2 * t;
    det / (t9 * (a3 * a3 / 8640.0 + a5 * a5 * t2 / 33600.0))
}

/// Scan of g(t) = normalised det on [T_MIN, 1] with spacing ≈ wavelength/4, regula falsi on
/// the first sign change and parabolic refinement of local minima for the margin.
pub(crate) fn stability_of(
    c: &Closed<Dual3>,
    a: &PlanarParams,
) -> Result<StabilityReport, RodError> {
    if c.case == Case::Straight {
        return Ok(StabilityReport {
            stable: false,
            margin: 0.0,
            first_conjugate_t: None,
        });
    }
    if c.needs_reference() {
        return crate::ode::planar_reference::stability(a);
    }
    let (a3, a5) = (a[0], a[2]);
    let g = |t: f64| normalised_det(c, a3, a5, t);
    let wl = c.wavelength();
    // No conjugate point comes before a fraction of the half-wavelength, and there the
    // closed-form det J (≈ t⁹) is swamped by rounding: start the scan at t0.
    let t0 = (0.1 * wl).clamp(T_MIN, T_MARGIN);
    let h_target = (0.25 * wl).clamp(0.01, 0.1);
    let n = ((1.0 - t0) / h_target).ceil().max(1.0) as usize;
    let h = (1.0 - t0) / n as f64;
    let mut ts = [0.0f64; 112];
    let mut gs = [0.0f64; 112];
    let mut np = n + 1;
    for (i, t) in ts.iter_mut().enumerate().take(np) {
        *t = if i == n { 1.0 } else { t0 + i as f64 * h };
    }
    // The normalisation t⁹(a3²/8640 + a5²t²/33600) changes regime at t* = √(33600/8640)|a3/a5|,
    // where g often has a narrow dip: sample around it too (for the margin).
    if a5 != 0.0 {
        let ts_star = (33600.0f64 / 8640.0).sqrt() * (a3 / a5).abs();
        for f in [0.7, 1.0, 1.4] {
            let t = ts_star * f;
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
    }
    for i in 0..np {
        let t = ts[i];
        gs[i] = g(t);
        if !gs[i].is_finite() {
            return Err(RodError::Overflow(
                "stability: det J(t) is not finite (parameters too large)".into(),
            ));
        }
    }
    // First sign change (det ≤ 0).
    let mut first: Option<f64> = None;
    let mut neg_value = f64::INFINITY;
    for i in 0..np {
        if gs[i] <= 0.0 {
            neg_value = gs[i];
            first = Some(if i == 0 {
                ts[0]
            } else {
                regula_falsi(&g, ts[i - 1], gs[i - 1], ts[i], gs[i])
            });
            break;
        }
    }
    // Margin: min over t ≥ T_MARGIN, with local minima refined by parabolic steps.
    let mut margin = f64::INFINITY;
    for i in 0..np {
        if ts[i] >= T_MARGIN {
            margin = margin.min(gs[i]);
        }
    }
    // Refine the coarse minima that matter: those low enough to hide a dip below zero or to
    // be the global minimum (only the global one once a sign change is known).
    let coarse_min = margin;
    let cutoff = if first.is_some() {
        coarse_min
    } else {
        2.0 * coarse_min.max(0.0) + 0.05
    };
    for i in 1..np.saturating_sub(1) {
        if gs[i] <= gs[i - 1] && gs[i] <= gs[i + 1] && ts[i + 1] >= T_MARGIN && gs[i] <= cutoff {
            let (tm, gm) = refine_min(&g, ts[i - 1], ts[i], ts[i + 1], gs[i - 1], gs[i], gs[i + 1]);
            if tm >= T_MARGIN {
                margin = margin.min(gm);
                if first.is_none() && gm <= 0.0 {
                    // A dip below zero between two coarse samples.
                    let tc = if gs[i - 1] > 0.0 {
                        regula_falsi(&g, ts[i - 1], gs[i - 1], tm, gm)
                    } else {
                        tm
                    };
                    first = Some(tc);
                    neg_value = gm;
                }
            }
        }
    }
    if first.is_some() && margin >= 0.0 {
        margin = neg_value.min(0.0);
    }
    if !margin.is_finite() {
        margin = 0.0;
    }
    Ok(StabilityReport {
        stable: first.is_none(),
        margin,
        first_conjugate_t: first,
    })
}

/// Illinois regula falsi for the root of g in (t0, t1) with g(t0) > 0 ≥ g(t1).
fn regula_falsi(g: &impl Fn(f64) -> f64, t0: f64, g0: f64, t1: f64, g1: f64) -> f64 {
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
        if gt > 0.0 {
            lo = t;
            glo = gt;
            if side == -1 {
                ghi *= 0.5;
            }
            side = -1;
        } else {
            hi = t;
            ghi = gt;
            if side == 1 {
                glo *= 0.5;
            }
            side = 1;
        }
        if gt == 0.0 {
            return t;
        }
    }
    hi
}

/// A few parabolic steps towards the minimum of g bracketed by (t0, t1, t2).
fn refine_min(
    g: &impl Fn(f64) -> f64,
    t0: f64,
    t1: f64,
    t2: f64,
    g0: f64,
    g1: f64,
    g2: f64,
) -> (f64, f64) {
    let (mut a, mut b, mut c) = (t0, t1, t2);
    let (mut fa, mut fb, mut fc) = (g0, g1, g2);
    for _ in 0..6 {
        if c - a < 1e-4 {
            break;
        }
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
        let ft = g(t);
        if ft < fb {
            if t < b {
                c = b;
                fc = fb;
            } else {
                a = b;
                fa = fb;
            }
            b = t;
            fb = ft;
        } else if t < b {
            a = t;
            fa = ft;
        } else {
            c = t;
            fc = ft;
        }
    }
    (b, fb)
}
