//! The stability scan of the heavy planar rod: det J(t) as a polynomial on every step of the
//! series, its sign on [`crate::STABILITY_T_MIN`, 1] and its normalised minimum on [0.05, 1].
//!
//! Rule (docs/math.md §5, generalised Jacobi condition with a distributed load: Borum & Bretl
//! 2014; Till & Rucker 2017): stable ⇔ det J(t) > 0 on (0, 1]. Near the base
//! det J(t) = D0(t)(1 + O(t)) > 0 with
//! D0(t) = t⁹ (a3²/8640 + a5² t²/33600 + (w ĝ_y)² t⁴/388800)
//! (the leading terms of the weightless rod, docs/math.md §5, plus the one gravity across the rod
//! adds, which is the only one left when a3 = a5 = 0: det J ~ t¹³), so the scan starts at
//! t = 0.02 where f64 resolves det J, and the margin is min over t ∈ [0.05, 1] of
//! g(t) = det J(t) / D0(t) (the normalisation of `shared/oracle/gravity_public.jsonl`).

use super::series::{horner, Step, ORDER};
use crate::{StabilityReport, STABILITY_T_MIN};

const N: usize = ORDER + 1;
/// Samples of det J per step (besides its end): a step spans at most ~1.5/ω, where det J
/// oscillates at most once or twice, so 16 samples bracket every dip the grid of the
/// reference (2,000 points) would see.
const SAMPLES: usize = 16;
/// Smallest t of the margin ([`crate::STABILITY_MARGIN_T_MIN`]).
pub(crate) const MARGIN_T_MIN: f64 = crate::STABILITY_MARGIN_T_MIN;
/// Relative error of an entry of J per integration step, measured against DOP853 at rtol
/// 1e-13 (worst 3e-14 over the tests' families) with a factor 10 of headroom.
const J_REL_PER_STEP: f64 = 3e-13;

/// The truncated product of two polynomials.
fn product(a: &[f64; N], b: &[f64; N]) -> [f64; N] {
    let mut out = [0.0; N];
    for (k, o) in out.iter_mut().enumerate() {
        let mut s = 0.0;
        for i in 0..=k {
            s += a[i] * b[k - i];
        }
        *o = s;
    }
    out
}

fn difference(a: [f64; N], b: [f64; N]) -> [f64; N] {
    let mut out = a;
    for (o, v) in out.iter_mut().zip(b) {
        *o -= v;
    }
    out
}

/// Column j of a coefficient-major variational series.
fn column(v: &[[f64; 4]; N], j: usize) -> [f64; N] {
    std::array::from_fn(|k| v[k][j])
}

/// det J(t0 + τ) as a polynomial in τ, truncated to the series' order (rows x, y, θ).
fn det_polynomial(s: &Step) -> [f64; N] {
    let cols = |v: &[[f64; 4]; N]| [column(v, 0), column(v, 1), column(v, 2)];
    let (x, y, th) = (cols(&s.dx), cols(&s.dy), cols(&s.dtheta));
    let m0 = difference(product(&y[1], &th[2]), product(&y[2], &th[1]));
    let m1 = difference(product(&y[0], &th[2]), product(&y[2], &th[0]));
    let m2 = difference(product(&y[0], &th[1]), product(&y[1], &th[0]));
    let mut det = difference(product(&x[0], &m0), product(&x[1], &m1));
    for (d, v) in det.iter_mut().zip(product(&x[2], &m2)) {
        *d += v;
    }
    det
}

/// Accumulates the verdict over the steps of one integration.
#[derive(Clone, Copy)]
pub(crate) struct Scan {
    /// a3², a5², (w ĝ_y)² of D0.
    lead: [f64; 3],
    steps: usize,
    /// Last sample (t, det) on [T_MIN, 1].
    prev: Option<(f64, f64)>,
    first_conjugate: Option<f64>,
    /// Least g(t) on [0.05, 1], its det J and that det's error bound.
    min_g: f64,
    min_det: f64,
    min_err: f64,
}

impl Scan {
    pub(crate) fn new(a3: f64, a5: f64, load_across: f64) -> Self {
        Self {
            lead: [a3 * a3, a5 * a5, load_across * load_across],
            steps: 0,
            prev: None,
            first_conjugate: None,
            min_g: f64::INFINITY,
            min_det: f64::INFINITY,
            min_err: 0.0,
        }
    }

    /// D0(t), the leading term of det J near the base (module docs).
    pub(crate) fn leading_term(&self, t: f64) -> f64 {
        let t2 = t * t;
        let t9 = t2 * t2 * t2 * t2 * t;
        t9 * (self.lead[0] / 8640.0 + t2 * (self.lead[1] / 33600.0 + t2 * self.lead[2] / 388800.0))
    }

    /// True when D0 ≡ 0: the straight rod along its force and gravity (det J ≡ 0).
    pub(crate) fn degenerate(&self) -> bool {
        self.lead == [0.0; 3]
    }

    /// Scans one step.
    pub(crate) fn push(&mut self, s: &Step) {
        self.steps += 1;
        let t_end = s.t0 + s.h;
        if t_end < STABILITY_T_MIN {
            return;
        }
        let det = det_polynomial(s);
        let tau_lo = (STABILITY_T_MIN - s.t0).max(0.0);
        let lead = Self { ..*self };
        let g = |tau: f64| horner(&det, tau) / lead.leading_term(s.t0 + tau);
        let mut best: Option<(usize, f64)> = None;
        let taus: [f64; SAMPLES + 1] =
            std::array::from_fn(|i| tau_lo + (s.h - tau_lo) * i as f64 / SAMPLES as f64);
        for (i, &tau) in taus.iter().enumerate() {
            let t = s.t0 + tau;
            let d = horner(&det, tau);
            if self.first_conjugate.is_none() && !(d > 0.0) {
                let lo = self.prev.map_or(tau_lo, |(tp, _)| (tp - s.t0).max(tau_lo));
                self.first_conjugate = Some(s.t0 + root(&det, lo, tau));
            }
            self.prev = Some((t, d));
            if t >= MARGIN_T_MIN && best.is_none_or(|(_, v)| g(tau) < v) {
                best = Some((i, g(tau)));
            }
        }
        let Some((i, _)) = best else { return };
        // Refine the step's least sample between its neighbours (golden section on g).
        let lo = taus[i.saturating_sub(1)].max(MARGIN_T_MIN - s.t0);
        let hi = taus[(i + 1).min(SAMPLES)];
        let tau = golden_min(&g, lo, hi).max(lo);
        let gv = g(tau);
        if gv < self.min_g {
            if self.first_conjugate.is_none() && !(horner(&det, tau) > 0.0) {
                self.first_conjugate = Some(s.t0 + root(&det, lo, tau));
            }
            self.min_g = gv;
            let j = s.jacobian_at(tau);
            let rel = J_REL_PER_STEP * self.steps as f64;
            let column = |c: usize| j.iter().map(|r| r[c].abs()).fold(0.0, f64::max) * rel;
            let (d, err) =
                crate::types::det_and_error_by_column(&j, [column(0), column(1), column(2)]);
            self.min_det = d;
            self.min_err = err;
        }
    }

    /// The report after the last step.
    pub(crate) fn report(self) -> StabilityReport {
        if self.degenerate() {
            return StabilityReport {
                stable: false,
                margin: 0.0,
                first_conjugate_t: None,
                uncertain: true,
            };
        }
        let margin = if self.min_g.is_finite() {
            self.min_g
        } else {
            0.0
        };
        let uncertain = !(self.min_det.abs() > self.min_err);
        let stable = self.first_conjugate.is_none() && !uncertain;
        StabilityReport {
            stable,
            margin,
            first_conjugate_t: if uncertain {
                None
            } else {
                self.first_conjugate
            },
            uncertain,
        }
    }
}

/// A root of the polynomial `p` on [lo, hi] where p(lo) > 0 ≥ p(hi) (bisection, then the
/// secant's last digits; the bracket is kept).
fn root(p: &[f64; N], mut lo: f64, mut hi: f64) -> f64 {
    if !(horner(p, lo) > 0.0) {
        return lo;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if horner(p, mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The minimum of f on [lo, hi] by golden-section search (f unimodal there by the sampling).
fn golden_min(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
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
