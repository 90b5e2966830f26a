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
//!
//! The scan itself (crossings, margin, verdict) is the crate's one [`crate::conjugate::Stream`];
//! what is the heavy rod's own is det J on a step, a polynomial, and its error bound.

use super::series::{horner, Step, ORDER};
use crate::conjugate::{golden_min, undecided, Stream};
use crate::{StabilityReport, STABILITY_T_MIN};

const N: usize = ORDER + 1;
/// Samples of det J per step (besides its end): a step spans at most ~1.5/ω, where det J
/// oscillates at most once or twice, so 16 samples bracket every dip the grid of the
/// reference (2,000 points) would see.
const SAMPLES: usize = 16;
/// Smallest t of the margin ([`crate::STABILITY_MARGIN_T_MIN`]).
pub(crate) const MARGIN_T_MIN: f64 = crate::STABILITY_MARGIN_T_MIN;
/// Width to which a conjugate point is located on a step's polynomial (bisection: its sign is
/// all the polynomial is trusted for there).
const ROOT_TOL: f64 = 1e-12;
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
    stream: Stream,
    /// The error bound of g where the margin was refined (det J's bound over D0 there).
    g_error: f64,
}

impl Scan {
    pub(crate) fn new(a3: f64, a5: f64, load_across: f64) -> Self {
        Self {
            lead: [a3 * a3, a5 * a5, load_across * load_across],
            steps: 0,
            stream: Stream::new(),
            g_error: 0.0,
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

    /// Scans one step: its samples' signs (the margin is refined, not sampled: the step's
    /// least sample is refined by golden section between its neighbours, and that minimum is
    /// offered with its error bound).
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
        let sign_at = |t: f64| horner(&det, t - s.t0);
        let mut best: Option<(usize, f64)> = None;
        let taus: [f64; SAMPLES + 1] =
            std::array::from_fn(|i| tau_lo + (s.h - tau_lo) * i as f64 / SAMPLES as f64);
        let since = s.t0 + tau_lo;
        for (i, &tau) in taus.iter().enumerate() {
            let t = s.t0 + tau;
            let _ =
                self.stream
                    .sample_on(&sign_at, since, (t, horner(&det, tau), f64::NAN), ROOT_TOL);
            if t >= MARGIN_T_MIN && best.is_none_or(|(_, v)| g(tau) < v) {
                best = Some((i, g(tau)));
            }
        }
        let Some((i, _)) = best else { return };
        // Refine the step's least sample between its neighbours (golden section on g).
        let lo = taus[i.saturating_sub(1)].max(MARGIN_T_MIN - s.t0);
        let hi = taus[(i + 1).min(SAMPLES)];
        let tau = golden_min(&g, lo, hi).max(lo);
        if self
            .stream
            .offer_minimum(&sign_at, s.t0 + lo, (s.t0 + tau, g(tau)), ROOT_TOL)
        {
            let j = s.jacobian_at(tau);
            let rel = J_REL_PER_STEP * self.steps as f64;
            let column = |c: usize| j.iter().map(|r| r[c].abs()).fold(0.0, f64::max) * rel;
            let (_, err) =
                crate::types::det_and_error_by_column(&j, [column(0), column(1), column(2)]);
            self.g_error = err / self.leading_term(s.t0 + tau);
        }
    }

    /// The report after the last step.
    pub(crate) fn report(self) -> StabilityReport {
        if self.degenerate() {
            return undecided();
        }
        self.stream.report(self.g_error)
    }
}
