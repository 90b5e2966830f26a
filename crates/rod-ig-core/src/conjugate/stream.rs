//! The scan of a rod integrated step by step: samples arrive in order of t, each with what the
//! step knows between its samples (an evaluator of the sign on the step, or nothing), and one
//! accumulator keeps the first crossing and the margin the way [`super::scan`] does.

use super::probe::{verdict, Scan, T_MARGIN};
use super::root::bisect_root;
use crate::StabilityReport;
use std::ops::ControlFlow;

/// Grid samples at t = T_MARGIN computed as i/N may round just below it: they count.
const WINDOW_SLACK: f64 = 1e-12;

/// The accumulator of a streamed scan.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stream {
    /// Last sample (t, sign) on the rod: the left end of the next crossing's bracket.
    prev: Option<(f64, f64)>,
    /// First crossing (sign ≤ 0).
    first: Option<f64>,
    /// g at the first non-positive sample and its t (the margin when that lies below the
    /// window).
    at_first: (f64, f64),
    /// Least g on the window and where.
    margin: f64,
    t_margin: f64,
}

impl Default for Stream {
    fn default() -> Self {
        Self::new()
    }
}

impl Stream {
    /// An empty scan.
    pub(crate) fn new() -> Self {
        Self {
            prev: None,
            first: None,
            at_first: (f64::NAN, f64::NAN),
            margin: f64::INFINITY,
            t_margin: 1.0,
        }
    }

    /// One sample known only by itself (a reference's grid): `sign` > 0 passes the rule (det J,
    /// or the smaller of two blocks' dets), `g` = det J/D0 enters the margin (NaN: it does not).
    /// The first non-positive sign is placed between the previous sample and this one by
    /// linear interpolation. Break at the first crossing.
    pub(crate) fn sample(&mut self, t: f64, sign: f64, g: f64) -> ControlFlow<()> {
        self.sample_with(t, sign, g, |tp, sp| {
            if sp > sign && sign.is_finite() {
                tp + (t - tp) * sp / (sp - sign)
            } else {
                t
            }
        })
    }

    /// [`Self::sample`] of det J(t) with the leading term D0(t): g = det/D0 where D0 > 0.
    pub(crate) fn sample_det(&mut self, t: f64, det: f64, lead: f64) -> ControlFlow<()> {
        self.sample(t, det, if lead > 0.0 { det / lead } else { f64::NAN })
    }

    /// One sample on a step whose sign is known anywhere on [`since`, t] (`sign_at`: dense
    /// output, a step's polynomial): the first crossing is located there by bisection to `tol`.
    /// Break at the first crossing.
    pub(crate) fn sample_on(
        &mut self,
        sign_at: &impl Fn(f64) -> f64,
        since: f64,
        (t, sign, g): (f64, f64, f64),
        tol: f64,
    ) -> ControlFlow<()> {
        self.sample_with(t, sign, g, |tp, _| {
            bisect_root(sign_at, tp.max(since).min(t), t, tol, 64)
        })
    }

    fn sample_with(
        &mut self,
        t: f64,
        sign: f64,
        g: f64,
        locate: impl FnOnce(f64, f64) -> f64,
    ) -> ControlFlow<()> {
        self.note(t, g);
        if self.first.is_none() && !(sign > 0.0) {
            self.first = Some(match self.prev {
                Some((tp, sp)) if sp > 0.0 => locate(tp, sp),
                _ => t,
            });
            self.at_first = (g, t);
            return ControlFlow::Break(());
        }
        self.prev = Some((t, sign));
        if self.first.is_some() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }

    /// g at t into the margin (in the window, finite or −∞).
    #[inline]
    fn note(&mut self, t: f64, g: f64) -> bool {
        if t >= T_MARGIN - WINDOW_SLACK && g < self.margin {
            self.margin = g;
            self.t_margin = t;
            return true;
        }
        false
    }

    /// A minimum of g refined between the samples of a step (`sign_at` valid on [`since`, t],
    /// `since` the sample left of it, where the sign is positive): lowers the margin if below
    /// it (true then); a dip to ≤ 0 there before any crossing becomes the first crossing,
    /// located by bisection on [`since`, t] to `tol`.
    pub(crate) fn offer_minimum(
        &mut self,
        sign_at: &impl Fn(f64) -> f64,
        since: f64,
        (t, g): (f64, f64),
        tol: f64,
    ) -> bool {
        if !(t >= T_MARGIN - WINDOW_SLACK && g < self.margin) {
            return false;
        }
        if self.first.is_none() && !(sign_at(t) > 0.0) {
            self.first = Some(bisect_root(sign_at, since.min(t), t, tol, 64));
            self.at_first = (g, t);
        }
        self.note(t, g)
    }

    /// The first crossing so far.
    pub(crate) fn first(&self) -> Option<f64> {
        self.first
    }

    /// What the scan found: the first crossing, the margin (g at the first non-positive
    /// sample, capped at 0, where the crossing lies below the window; 0 where nothing entered
    /// it) and where.
    pub(crate) fn scan(&self) -> Scan {
        let (mut margin, mut t_margin) = (self.margin, self.t_margin);
        if self.first.is_some() && !(margin < 0.0) {
            let (g, t) = self.at_first;
            margin = if g.is_finite() { g.min(0.0) } else { 0.0 };
            t_margin = t;
        }
        if !margin.is_finite() {
            margin = 0.0;
        }
        Scan {
            first: self.first,
            margin,
            t_margin,
        }
    }

    /// The verdict with the error bound of g at the margin ([`verdict`]).
    pub(crate) fn report(&self, g_error: f64) -> StabilityReport {
        verdict(self.scan(), g_error)
    }

    /// The verdict of a reference, whose samples are taken as exact: stable iff no crossing.
    pub(crate) fn exact_report(&self) -> StabilityReport {
        let s = self.scan();
        StabilityReport {
            stable: s.first.is_none(),
            margin: s.margin,
            first_conjugate_t: s.first,
            uncertain: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sampled g with one dip below zero: the crossing by linear interpolation on samples
    /// alone, by bisection on a step's evaluator, the margin's minimum, and Break there.
    #[test]
    fn crossings_and_margin() {
        let g = |t: f64| (t - 0.6) * (t - 0.9); // < 0 on (0.6, 0.9)
        let mut by_samples = Stream::new();
        let mut on_step = Stream::new();
        let mut broke = (None, None);
        for i in 1..=20 {
            let t = i as f64 / 20.0;
            if by_samples.sample(t, g(t), g(t)).is_break() && broke.0.is_none() {
                broke.0 = Some(t);
            }
            if on_step
                .sample_on(&g, 0.0, (t, g(t), g(t)), 1e-12)
                .is_break()
                && broke.1.is_none()
            {
                broke.1 = Some(t);
            }
        }
        assert_eq!(broke, (Some(0.6), Some(0.6)));
        // 0.6 is a sample where g = 0 (to rounding): both place the crossing there.
        assert!((by_samples.first().unwrap() - 0.6).abs() < 1e-12);
        assert!((on_step.first().unwrap() - 0.6).abs() < 1e-12);
        let s = on_step.scan();
        assert!(s.margin <= 0.0 && s.margin > -0.03, "{s:?}");
        // Between samples: g(t) = (t − 0.62)(t − 0.9) crosses at 0.62, sampled at 0.6, 0.65.
        let h = |t: f64| (t - 0.62) * (t - 0.9);
        let mut a = Stream::new();
        let mut b = Stream::new();
        for i in 1..=20 {
            let t = i as f64 / 20.0;
            let _ = a.sample(t, h(t), h(t));
            let _ = b.sample_on(&h, 0.0, (t, h(t), h(t)), 1e-12);
        }
        let (fa, fb) = (a.first().unwrap(), b.first().unwrap());
        assert!((fb - 0.62).abs() < 1e-11, "{fb}");
        assert!((fa - 0.62).abs() < 5e-3 && fa != fb, "{fa}");
        assert!(!a.exact_report().stable && b.report(0.0).first_conjugate_t == Some(fb));
    }

    /// A crossing below the margin's window reports g there (≤ 0); no sample in the window and
    /// no crossing gives margin 0; a refined minimum lowers the margin and can become the
    /// first crossing.
    #[test]
    fn window_rules() {
        let mut s = Stream::new();
        let _ = s.sample(0.03, 1.0, 2.0);
        let _ = s.sample(0.04, -1.0, -0.5);
        assert_eq!(s.scan().margin, -0.5);
        assert_eq!(Stream::new().scan().margin, 0.0);
        let g = |t: f64| (t - 0.5).powi(2) - 1e-4; // dips to −1e-4 at 0.5, between samples
        let mut m = Stream::new();
        for t in [0.2, 0.4, 0.6, 0.8] {
            let _ = m.sample_on(&g, 0.0, (t, g(t), g(t)), 1e-12);
        }
        assert!(m.first().is_none() && m.scan().margin > 0.0);
        assert!(m.offer_minimum(&g, 0.4, (0.5, g(0.5)), 1e-12));
        assert!((m.first().unwrap() - 0.49).abs() < 1e-11);
        assert_eq!(m.scan().margin, g(0.5));
        assert!(!m.offer_minimum(&g, 0.4, (0.55, g(0.55)), 1e-12));
    }
}
