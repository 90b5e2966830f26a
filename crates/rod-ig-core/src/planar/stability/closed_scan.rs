//! Stability scans on the closed form (docs/math.md §5), with the short series, the small-m
//! scan and the margin certification where its own error estimate fails.

use super::around;
use super::closed_g::{
    normalised_det, normalised_det_extended, normalised_det_sloped, normalised_det_value,
};
use super::series::{
    certified_verdict, normalisation_scaled, normalised_det_of, normalised_det_series,
    scaled_jacobian, scaled_series_jacobian, series_after_small_angle,
};
use super::small_angle_scan::{
    small_angle_prefix, small_angle_report, SMALL_ANGLE_MAX_TRUNCATION, SMALL_ANGLE_TRUNCATION_C,
};
use super::{
    straight_report, COARSE_AMPLIFIED, COARSE_ENTRY_REL, SERIES_ENTRY_REL, SERIES_SPACING,
    SIGMA_RAY, T_MARGIN, T_MIN,
};
use crate::conjugate::{sample_times, scan, value_only, verdict, Probe, Scan};
use crate::dd::DualDd;

use crate::planar::closed::{Case, Closed, DetFrame, SeriesNeed};
use crate::planar::small_angle;

use crate::planar::taylor::{CoarseDual3, Gradient, TaylorRod};
use crate::planar_det_leading_term as normalisation;
use crate::scalar::Dual3;

use crate::types::det3;
use crate::{PlanarParams, RodError, StabilityReport, StabilityVerdict};

/// Stability on the closed form (docs/math.md §5), with the series where the closed form's own
/// error estimate fails.
pub(crate) fn stability_of(
    c: &Closed<Dual3>,
    a: &PlanarParams,
) -> Result<StabilityReport, RodError> {
    stability_of_with(c, a, None)
}

/// [`stability_of`] with the rod's closed form in double-double when the caller has built it
/// already (`planar::extended::seeded_within_reach`; built here when needed otherwise). For
/// the evaluation, which holds one closed form (and one double-double form) for all its parts:
/// the stability rows of the dispatcher's table (`planar/dispatch.rs`) in its order, each
/// piece the one its row asks: [`small_angle_report`], [`closed_report`], [`precise_scan`],
/// [`series_report_after_closed`].
pub(crate) fn stability_of_with(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    extended: Option<&Closed<DualDd>>,
) -> Result<StabilityReport, RodError> {
    if let Some(report) = small_angle_report(a)? {
        return Ok(report);
    }
    let precise = c.needs_precise_series();
    if let Some(report) = closed_report(c, a, c.needs_series(), precise)? {
        return Ok(report);
    }
    if precise {
        return precise_scan(c, a, extended);
    }
    series_report_after_closed(c, a)
}

/// The closed form's own stability report (the closed-scan row of the dispatcher's table,
/// asked after the small-angle expansion declined): the straight rod's; the closed scan where
/// a theorem decides and no series can reach the tip; the small-m scan where det J needs the
/// series but its certification holds; the closed scan where the closed form's estimate holds
/// and the scan is certain. None elsewhere: by the separatrix (`precise`: the double-double
/// scans), where the closed form's J needs the series, where the small-m certification or the
/// closed scan cannot decide (the series scan).
pub(crate) fn closed_report(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    need: SeriesNeed,
    precise: bool,
) -> Result<Option<StabilityReport>, RodError> {
    if c.case == Case::Straight {
        return Ok(Some(straight_report()));
    }
    if precise {
        return Ok(None);
    }
    // A theorem decides the verdict (circles, case II) and no series can reach the tip: the
    // closed scan's margin stands, uncertain or not (a near-circle of ~10⁴ turns under a small
    // force ran out of series steps here).
    if series_out_of_reach(a) && c.theorem_verdict().is_some() {
        return closed_scan(c, a, false, None).map(Some);
    }
    if c.det_needs_series() {
        return small_m_scan(c, a);
    }
    if need != SeriesNeed::None {
        return Ok(None);
    }
    // Uncertain: the closed form's error bound covers the margin; the series' entries are
    // accurate relative to themselves (the series row).
    let report = closed_scan(c, a, false, None)?;
    Ok((!report.uncertain).then_some(report))
}

/// The series scan of a rod whose closed form was built and declined (the series row of the
/// table), unless the series runs out of steps on a rod whose verdict a theorem decides: then
/// the closed scan's report, its margin possibly uncertain ([`or_theorem`]).
pub(crate) fn series_report_after_closed(
    c: &Closed<Dual3>,
    a: &PlanarParams,
) -> Result<StabilityReport, RodError> {
    let series = series_after_small_angle(a, None, Some(c.wavelength()), None);
    or_theorem(c, a, series)
}

/// The stability of a rod by the separatrix under a strong force. There the closed form's
/// J(t) entries far below ‖J‖ (the x row while the rod lingers by the straight equilibrium)
/// are not accurate relative to themselves: with entry-wise error bounds two verdicts in 720
/// were wrong on the rigorous reference (scripts/references/gen_separatrix_truth.py). The scan bounds
/// every entry norm-wise and hands what it cannot decide to a second pass in double-double,
/// then to the double-double series.
pub(crate) fn precise_scan(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    extended: Option<&Closed<DualDd>>,
) -> Result<StabilityReport, RodError> {
    let report = closed_scan(c, a, true, None)?;
    if !report.uncertain {
        return Ok(report);
    }
    // Again with the closed form in double-double where the f64 one is far off (a rod
    // lingering by the straight equilibrium before its loop, where the f64 values are noise
    // of either sign): 150–480 µs where the double-double series takes 3–9 ms.
    let mut undecided = None;
    let built;
    let dd = match extended {
        Some(dd) => Some(dd),
        None => {
            built = crate::planar::extended::seeded_within_reach(a);
            built.as_ref()
        }
    };
    if let Some(dd) = dd {
        let report = closed_scan(c, a, true, Some(dd))?;
        if !report.uncertain {
            return Ok(report);
        }
        undecided = Some(report);
    }
    // Beyond the double-double series' reach the verdict stays uncertain (with the second
    // pass's margin), rather than refusing a rod whose forward map is certified.
    if let Some(report) = undecided {
        if a[1].hypot(a[2]).sqrt() > crate::planar::stability::STABILITY_DD_MAX_ROOT_F {
            return Ok(report);
        }
    }
    series_after_small_angle(a, None, Some(c.wavelength()), Some(c))
}

/// The series' report, unless it ran out of steps on a rod whose verdict a theorem decides:
/// then the closed scan's (scanned now), its margin possibly uncertain.
fn or_theorem(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    series: Result<StabilityReport, RodError>,
) -> Result<StabilityReport, RodError> {
    match series {
        Err(RodError::Integration(_)) if c.theorem_verdict().is_some() => {
            closed_scan(c, a, false, None)
        }
        answer => answer,
    }
}

/// Radians of turning the f64 series covers per step, at least (measured 1.7–1.9 on circles
/// and near-circles): beyond, [`or_theorem`] catches the series running out of steps.
const SERIES_RADIANS_PER_STEP: f64 = 4.0;

/// Whether the f64 series would spend its whole step budget before the tip: its steps are
/// ≈ 1/ρ long, so a rod of curvature scale ρ needs ≈ ρ/1.9 of them. Where a theorem decides the
/// verdict (circles, case II) such a rod keeps the closed scan's report, its margin uncertain,
/// instead of failing after ~0.1 s of integration ([`crate::planar::taylor::curvature_scale`]).
pub(super) fn series_out_of_reach(a: &PlanarParams) -> bool {
    crate::planar::taylor::curvature_scale(a)
        > SERIES_RADIANS_PER_STEP * crate::planar::taylor::SERIES_MAX_STEPS as f64
}

/// Farthest t to which [`small_m_scan`] builds its certifying series: beyond, the whole-rod
/// series scan costs hardly more.
pub(super) const SMALL_M_CERTIFY_MAX_T: f64 = 0.5;
/// Largest relative disagreement between the closed form's g and the series' at the points
/// [`small_m_scan`] certifies (measured: ≲ 1e-5 on nearly straight rods under compression).
pub(super) const SMALL_M_AGREEMENT: f64 = 1e-3;

/// Stability at small m (a nearly straight rod under compression, often many wavelengths)
/// without the whole-rod series: the closed form's g(t) locates the sign changes and the
/// margin (its values agree with the series' to ~1e-6 there, although its error bound, set by
/// the O(√m) x row of J, cannot certify them), and the f64 series from the base to the first
/// negative sample and to t_margin certifies those two values (bounded as in the series scan,
/// and within [`SMALL_M_AGREEMENT`] of the closed form's). None where the certification does
/// not hold or would reach beyond [`SMALL_M_CERTIFY_MAX_T`]: the caller scans the series.
pub(super) fn small_m_scan(
    c: &Closed<Dual3>,
    a: &PlanarParams,
) -> Result<Option<StabilityReport>, RodError> {
    let (a3, a5) = (a[0], a[2]);
    if a3.abs().max(a5.abs()) < SIGMA_RAY {
        return Ok(None);
    }
    let wl = c.wavelength();
    let t0 = (0.1 * wl).clamp(T_MIN, T_MARGIN);
    let spacing = (0.25 * wl).clamp(1e-3, SERIES_SPACING);
    let closed = |t: f64| normalised_det_value(c, a3, a5, t);
    let s = scan(&value_only(closed), t0, spacing, around(a3, a5), &[])?;
    // The first sample past the sign change where g < 0: the unstable verdict's witness.
    let witness = match s.first {
        None => None,
        Some(first) => {
            let (ts, np) = sample_times(t0, spacing, around(a3, a5), &[]);
            let t = ts[..np]
                .iter()
                .copied()
                .find(|&t| t >= first && closed(t) < 0.0);
            let Some(t) = t else {
                return Ok(None);
            };
            Some(t)
        }
    };
    let t_end = witness.unwrap_or(0.0).max(s.t_margin);
    if t_end > SMALL_M_CERTIFY_MAX_T {
        return Ok(None);
    }
    let Ok(rod) = TaylorRod::new_to(
        Dual3::variable(a3, 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a5, 2),
        t_end,
        crate::planar::taylor::SERIES_MAX_STEPS,
        true,
    ) else {
        return Ok(None);
    };
    // Certified: decided by the series' bound and within SMALL_M_AGREEMENT of the closed form.
    let certified = |t: f64| {
        let (v, e) = normalised_det_series(&rod, a3, a5, t);
        let agree = (v - closed(t)).abs() <= SMALL_M_AGREEMENT * v.abs() + e;
        (v.is_finite() && v.abs() > e && agree).then_some(v)
    };
    let Some(margin) = certified(s.t_margin) else {
        return Ok(None);
    };
    if let Some(t) = witness {
        if !certified(t).is_some_and(|v| v < 0.0) {
            return Ok(None);
        }
    }
    let margin = if s.first.is_some() && s.margin >= 0.0 {
        // The sign change lies below T_MARGIN: the scan reports the negative value seen there.
        s.margin
    } else {
        margin
    };
    Ok(Some(StabilityReport {
        stable: s.first.is_none() && margin > 0.0,
        margin,
        first_conjugate_t: s.first,
        uncertain: false,
    }))
}

/// g's value for [`scan`], but NaN (no sign: the scan drops it) where g ≤ 0 lies within its
/// error bound before `t_free`, where no conjugate point can come yet
/// (`Closed::conjugate_span_bound`): that sign is rounding. Under a strong tension the
/// norm-wise scan's noise there put "conjugate points" at t ≈ 0.1 on rods whose first one is
/// at 0.8 (320-bit references).
pub(super) fn signs_where_possible(
    g: &impl Fn(f64) -> (f64, f64, f64),
    t_free: f64,
) -> impl Fn(f64) -> Probe + '_ {
    move |t| {
        let (v, e, d) = g(t);
        if t < t_free && v <= 0.0 && -v <= e {
            Probe { v: f64::NAN, d }
        } else {
            Probe { v, d }
        }
    }
}

/// Where the closed-form scan takes g(t) from: the closed form where its bound is within
/// [`CLOSED_G_ERROR`], else (double-double pass) the small-angle prefix or the double-double
/// closed form, else the small-angle prefix or the short series from the base.
pub(super) struct ClosedSamples<'a> {
    pub(super) c: &'a Closed<Dual3>,
    pub(super) a: &'a PlanarParams,
    pub(super) norm_wise: bool,
    pub(super) dd: Option<&'a Closed<DualDd>>,
    pub(super) start: ShortSeries,
    pub(super) root_f: f64,
    /// The Jacobi fields' det J ([`Closed::det_frame`]), tried first at every sample it covers.
    pub(super) frame: Option<DetFrame>,
}

impl ClosedSamples<'_> {
    /// g(t), its bound and its slope (NaN where the value does not come from the f64 closed
    /// form within its acceptance). Inline: called from the scan's root and minimum searches,
    /// which live in `crate::conjugate` (another codegen unit).
    #[inline]
    fn eval(&self, t: f64) -> (f64, f64, f64) {
        let (a, a3, a5, root_f) = (self.a, self.a[0], self.a[2], self.root_f);
        // Relative to |g| where g is large: under a strong tension g reaches 1e4 between the
        // base and the margin, its bound 1e-3 of that, and the short series would otherwise be
        // extended there (~100 µs) for samples far above the margin that cannot change it.
        let accepted = |v: f64, e: f64| e <= CLOSED_G_ERROR * v.abs().max(1.0);
        if let Some(frame) = self.frame.as_ref().filter(|f| f.covers(t)) {
            let s = self.c.det_sample(frame, t);
            let n = normalisation(a3, a5, t);
            let (v, e) = (s.det / n, s.error / n);
            if accepted(v, e) {
                let log_slope = crate::types::planar_det_leading_term_log_slope(a3, a5, t);
                return (v, e, s.slope / n - v * log_slope);
            }
        }
        let (v, e, slope) = normalised_det_sloped(self.c, a3, a5, t, self.norm_wise);
        if accepted(v, e) {
            return (v, e, slope);
        }
        if let Some(dd) = self.dd {
            // The double-double pass: the small-angle prefix where its bound holds, else the
            // double-double closed form (its value, with its own norm-wise bound).
            if let Some((v0, e0, d0)) = small_angle_prefix(a, t) {
                if e0 <= CLOSED_G_ERROR * v0.abs().max(1.0) {
                    return (v0, e0, d0);
                }
            }
            if root_f * t > SHORT_SERIES_REACH {
                let (v, e) = normalised_det_extended(dd, a3, a5, t);
                return (v, e, f64::NAN);
            }
        }
        // Past here g is off by more than its acceptance; its slope is not used.
        if self.norm_wise && root_f * t > SHORT_SERIES_REACH {
            return (v, e, f64::NAN);
        }
        if let Some((v0, e0, d0)) = small_angle_prefix(a, t) {
            if e0 <= CLOSED_G_ERROR * v0.abs().max(1.0) {
                return (v0, e0, d0);
            }
        }
        self.start.normalised_det(t).unwrap_or((v, e, f64::NAN))
    }
}

/// The scan of g on the closed form (a short series near the base); the report, uncertain
/// where the error bound covers the margin (`norm_wise`: see [`normalised_det`]).
pub(super) fn closed_scan(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    norm_wise: bool,
    dd: Option<&Closed<DualDd>>,
) -> Result<StabilityReport, RodError> {
    closed_scan_from(c, a, norm_wise, dd, 0.0)
}

/// [`closed_scan`] over [max(t0, from), 1] only: for a verdict where a theorem rules out any
/// conjugate point before `from` ([`verdict_of`]; the margin it reports is that range's).
pub(super) fn closed_scan_from(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    norm_wise: bool,
    dd: Option<&Closed<DualDd>>,
    from: f64,
) -> Result<StabilityReport, RodError> {
    let (a3, a5) = (a[0], a[2]);
    // At small t the entries of J(t) are O(t)..O(t³) and the closed form's absolute error
    // floor swamps det J ∝ t⁹: there g comes from a short Taylor series from the base,
    // which is accurate relative to itself (one low-order step for t ≲ 0.2). Norm-wise
    // (near the separatrix under a force) g grows like e^{2√‖F‖ t}, and the closed form's
    // value is taken where it is accurate relative to itself.
    let samples = ClosedSamples {
        c,
        a,
        norm_wise,
        dd,
        start: ShortSeries::for_scan(a, norm_wise),
        root_f: crate::scalar::fast_hypot(a[1], a[2]).sqrt(),
        frame: c.det_frame(),
    };
    let recorded = Recorded::new(|t| samples.eval(t));
    let sloped = |t: f64| recorded.eval(t);
    let g = |t: f64| {
        let (v, e, _) = recorded.eval(t);
        (v, e)
    };
    let wl = c.wavelength();
    // No conjugate point comes before a fraction of the half-wavelength, and there the
    // closed-form det J (≈ t⁹) is swamped by rounding: start the scan at t0.
    let t0 = (0.1 * wl).clamp(T_MIN, T_MARGIN).max(from);
    let spacing = if norm_wise {
        (0.25 * wl).clamp(0.01, 0.1)
    } else {
        (SLOPED_SPACING * wl).clamp(0.01, SLOPED_MAX_SPACING)
    };
    let s = scan(
        &signs_where_possible(&sloped, c.conjugate_span_bound()),
        t0,
        spacing,
        around(a3, a5),
        c.dip_times(spacing).as_slice(),
    )?;
    if !norm_wise {
        return Ok(verdict(s, recorded.at(s.t_margin).1));
    }
    // Norm-wise (near the separatrix under a strong force) the closed form's value is far
    // off where its bound is large, and an unstable verdict needs a sample past the first sign
    // change where g < 0 beyond its bound; the margin of a stable one is certified at t_margin
    // (by the closed form's bound or the f64 series, [`certify_margin`]). Between, where the
    // bound exceeds g by orders of magnitude, g ~ e^{2√‖F‖ t} is huge and the closed form's
    // sign is kept: measured against the 320-bit references (tests/separatrix_truth.rs, 760
    // rods) every verdict so reached is right, where the double-double scan called 30 of 1,429
    // stable rods of issue 23's tiny-bending sample "unstable" with a certain verdict.
    if s.first.is_some() {
        return Ok(certified_verdict(s, &g, (t0, spacing, a3, a5)));
    }
    let report = verdict(s, recorded.at(s.t_margin).1);
    if !report.uncertain {
        return Ok(report);
    }
    // It compares against g at t_margin, which the scan has already evaluated.
    Ok(certify_margin(a, s, &|t| recorded.at(t)).unwrap_or(report))
}

/// Grid spacing of the closed-form scan off the separatrix, in wavelengths, and its cap. Every
/// closed-form sample there carries g′ ([`normalised_det_sloped`]), so minima between samples
/// are found from the slopes' signs and the cubic through them ([`refine_margin`]): half a
/// wavelength keeps the margins as close to a dense scan as a quarter does (6,000 rods of
/// `slope_test_rod` against the series on 6,000 points each: worst excess 0.9 % for both, 0.74 %
/// once the small-angle prefix gave slopes too, where the value-only scan at a quarter
/// wavelength, capped at 0.1, was 5.1 % above; at 0.75 wavelength it is 10 %). The norm-wise scan keeps a quarter, capped at 0.1: its verdicts
/// were measured on that grid against the 320-bit references.
pub(super) const SLOPED_SPACING: f64 = 0.5;
/// See [`SLOPED_SPACING`].
pub(super) const SLOPED_MAX_SPACING: f64 = 0.3;

/// g with the evaluations it has made kept, so that the margin's error bound, read at
/// t_margin after the scan, costs a lookup ([`Self::at`]) instead of one more pose in dual
/// numbers: −2.2 % instructions per box stability test, net of the recording. Only that
/// read-back looks up (looking up every evaluation cost more than it saved).
pub(super) struct Recorded<G> {
    pub(super) g: G,
    pub(super) seen: std::cell::RefCell<Evaluations>,
}

/// Up to [`RECORDED`] (t, g, its bound, its slope), and how many are filled.
pub(super) type Evaluations = ([(f64, f64, f64, f64); RECORDED], usize);

/// Evaluations a [`Recorded`] keeps (a box scan makes ~22; later ones are recomputed).
pub(super) const RECORDED: usize = 48;

impl<G: Fn(f64) -> (f64, f64, f64)> Recorded<G> {
    fn new(g: G) -> Self {
        Self {
            g,
            seen: std::cell::RefCell::new(([(0.0, 0.0, 0.0, 0.0); RECORDED], 0)),
        }
    }

    /// g(t), its bound and its slope, computed and recorded.
    #[inline]
    fn eval(&self, t: f64) -> (f64, f64, f64) {
        let (v, e, d) = (self.g)(t);
        let mut seen = self.seen.borrow_mut();
        let (entries, n) = &mut *seen;
        if *n < RECORDED {
            entries[*n] = (t, v, e, d);
            *n += 1;
        }
        (v, e, d)
    }

    /// g(t) and its bound as recorded at exactly t (newest first), else computed.
    fn at(&self, t: f64) -> (f64, f64) {
        let recorded = {
            let seen = self.seen.borrow();
            let (entries, n) = &*seen;
            entries[..*n]
                .iter()
                .rev()
                .find(|x| x.0 == t)
                .map(|x| (x.1, x.2))
        };
        recorded.unwrap_or_else(|| {
            let (v, e, _) = self.eval(t);
            (v, e)
        })
    }
}

/// Step budget of the f64 series that certifies the margin of a rod near the separatrix
/// ([`certify_margin`]): ≈ 3 µs per step.
pub(super) const MARGIN_SERIES_MAX_STEPS: usize = 60;
/// Largest estimated relative error of that series' J entries for which its g is used (its
/// rounding grows like e^{√‖F‖ t}, see [`certify_margin`]).
pub(super) const MARGIN_SERIES_MAX_REL: f64 = 1e-6;

/// The margin of a stable rod near the separatrix under a strong force, certified by the f64
/// series from the base to t_margin, its entries' errors bounded by [`SERIES_ENTRY_REL`] plus
/// ε·e^{√‖F‖ t} norm-wise (rounding made near the hyperbolic straight equilibrium grows at
/// that rate), where the closed form's norm-wise bound is too
/// pessimistic. None where that bound, the step budget or the agreement of both values does
/// not hold.
pub(super) fn certify_margin(
    a: &PlanarParams,
    s: Scan,
    g: &impl Fn(f64) -> (f64, f64),
) -> Option<StabilityReport> {
    let (a3, a5) = (a[0], a[2]);
    if a3.abs().max(a5.abs()) < SIGMA_RAY {
        return None;
    }
    let amplified = f64::EPSILON * (a[1].hypot(a[2]).sqrt() * s.t_margin).exp();
    if amplified.is_nan() || amplified > MARGIN_SERIES_MAX_REL {
        return None;
    }
    let rod = TaylorRod::new_to(
        Dual3::variable(a3, 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a5, 2),
        s.t_margin,
        MARGIN_SERIES_MAX_STEPS,
        false,
    )
    .ok()?;
    let j = scaled_jacobian(rod.tip(), a3, a5)?;
    let (value, error) = normalised_det_of(&j, a3, a5, s.t_margin, SERIES_ENTRY_REL, amplified);
    // The scan's value and the series' must agree within their bounds.
    let (v, e) = g(s.t_margin);
    if !(value.is_finite() && value.abs() > error && (value - v).abs() <= error + e) {
        return None;
    }
    Some(verdict(Scan { margin: value, ..s }, error))
}

/// Largest error bound of the closed form's g(t), relative to max(|g|, 1), for which the scan
/// takes its value (g is scale-free, ≈ 1 on a gently bent rod: a thousandth of that cannot
/// decide a sign or the margin's verdict; near a root of g the bound is small and the closed
/// form is kept).
pub(super) const CLOSED_G_ERROR: f64 = 1e-3;
/// Near the separatrix (norm-wise scan) the short series stands in for the closed form up to
/// √‖F‖·t = this only: beyond, g grows like e^{2√‖F‖ t} (the rod lingers by the straight
/// equilibrium) and the closed form's value decides its sign, while the margin, found at
/// small t or in a dip where the closed form is accurate, is certified separately
/// ([`certify_margin`]).
pub(super) const SHORT_SERIES_REACH: f64 = 6.0;
/// The short series' first end on a strongly bent rod is this over ρ = max(|a3|, √‖F‖) (a
/// few steps; 0.2 for ρ ≤ 10, as for every rod before).
pub(super) const SHORT_SERIES_FIRST_END_RHO: f64 = 2.0;
/// Step budget of the short series (≈ 3 µs per step): beyond, the rod is too strongly bent
/// for a short start and the closed form's value stands (an uncertain verdict then goes to
/// the full series, as without the short series).
pub(super) const SHORT_SERIES_MAX_STEPS: usize = 24;

/// The rod's Taylor series from the base to some t_end ≤ 1, built on first use and extended
/// (rebuilt to 2t) when asked beyond its end. Truncated at 1e-10 per step ([`CoarseDual3`]):
/// its g is taken to 1e-3 and bounded with the coarse series' own error
/// ([`COARSE_ENTRY_REL`]), and the longer steps cost a third less under a strong force.
pub(super) struct ShortSeries {
    pub(super) a: PlanarParams,
    /// The ends it grows to when asked at t beyond its end: 2t within [min_end, max_end]
    /// (at least t).
    pub(super) min_end: f64,
    pub(super) max_end: f64,
    pub(super) rod: std::cell::RefCell<Start>,
}

/// The state of a [`ShortSeries`].
pub(super) enum Start {
    NotBuilt,
    /// It could not be built or extended within its step budget.
    Failed,
    /// Built to `rod.t_end()`; `steps_left` of the budget remain (0 once an extension failed:
    /// the steps already taken stay valid and keep answering below their end).
    Built {
        rod: Box<TaylorRod<CoarseDual3>>,
        steps_left: usize,
    },
}

impl ShortSeries {
    fn new(a: &PlanarParams, min_end: f64, max_end: f64) -> Self {
        Self {
            a: *a,
            min_end,
            max_end,
            rod: std::cell::RefCell::new(Start::NotBuilt),
        }
    }

    /// The short series of [`closed_scan`]: norm-wise up to √‖F‖·t = [`SHORT_SERIES_REACH`];
    /// otherwise one low-order step reaches t ≈ 0.2 on a gently bent rod, and on a strongly
    /// bent one (ρ = max(|a3|, √‖F‖) ≫ 1) the steps shrink like 1/ρ while the closed form is
    /// accurate from t ~ 1/ρ on: the first end is capped there (it still grows to 2t).
    fn for_scan(a: &PlanarParams, norm_wise: bool) -> Self {
        let root_f = crate::scalar::fast_hypot(a[1], a[2]).sqrt();
        if norm_wise {
            Self::new(a, 0.0, (SHORT_SERIES_REACH / root_f).min(1.0))
        } else {
            let rho = a[0].abs().max(root_f);
            Self::new(a, (SHORT_SERIES_FIRST_END_RHO / rho).min(0.2), 1.0)
        }
    }

    /// g(t) and its error bound from the series; None where the series cannot be built (the
    /// caller keeps the closed form's value) or the bending is too small to scale (σ < 1e-60,
    /// where `whole_series_scan` works on a ray).
    fn normalised_det(&self, t: f64) -> Option<(f64, f64, f64)> {
        let (a3, a5) = (self.a[0], self.a[2]);
        if a3.abs().max(a5.abs()) < SIGMA_RAY {
            return None;
        }
        let mut slot = self.rod.borrow_mut();
        if let Start::NotBuilt = *slot {
            // Started empty and grown below: a budget that runs out before the first end
            // still leaves the steps taken.
            *slot = match TaylorRod::new_to(
                CoarseDual3::new(Dual3::variable(a3, 0)),
                CoarseDual3::new(Dual3::variable(self.a[1], 1)),
                CoarseDual3::new(Dual3::variable(a5, 2)),
                0.0,
                0,
                true,
            ) {
                Ok(rod) => Start::Built {
                    steps_left: SHORT_SERIES_MAX_STEPS,
                    rod: Box::new(rod),
                },
                Err(_) => Start::Failed,
            };
        }
        // Grown, not rebuilt: the steps to the old end are kept, and kept too when the budget
        // runs out before the new end (they still answer up to where they reached).
        if let Start::Built { rod, steps_left } = &mut *slot {
            if rod.t_end() < t && *steps_left > 0 {
                let end = (2.0 * t).clamp(self.min_end, self.max_end.max(t));
                let before = rod.steps();
                let _ = rod.extend_to(end, *steps_left);
                *steps_left -= rod.steps() - before;
                if rod.t_end() < end {
                    *steps_left = 0;
                }
            }
        }
        let Start::Built { rod, .. } = &*slot else {
            return None;
        };
        if rod.t_end() < t {
            return None;
        }
        let root_f = crate::scalar::fast_hypot(self.a[1], self.a[2]).sqrt();
        let amplified = (f64::EPSILON + COARSE_AMPLIFIED) * (root_f * t).exp();
        let j = scaled_series_jacobian(rod, a3, a5, t)?;
        let (v, e) = normalised_det_of(
            &j,
            a3,
            a5,
            t,
            SERIES_ENTRY_REL + COARSE_ENTRY_REL,
            amplified,
        );
        // g′ as [`normalised_det_sloped`] forms it, on the same scaled rows: the a4 entry of
        // ∂κ/∂a is scaled like J's a4 column (det′ and N then carry the same 1/σ²).
        if !v.is_finite() {
            return None;
        }
        let slope = rod.curvature(t).map_or(f64::NAN, |kappa| {
            let mut k = kappa.gradient();
            k[1] /= a3.abs().max(a5.abs());
            let log_slope = crate::types::planar_det_leading_term_log_slope(a3, a5, t);
            det3(&[j[0], j[1], k]) / normalisation_scaled(a3, a5, t) - v * log_slope
        });
        Some((v, e, slope))
    }
}

// The verdict the closed form's det J(t) decides alone.

/// How many times its own error bound g(1) must lie below zero for [`verdict_of`] to call a
/// rod unstable from that one sample (the scans call a sign beyond one bound certain; the
/// factor is a margin for the bound's own approximations).
pub(super) const END_UNSTABLE_BOUNDS: f64 = 4.0;

/// True where [`stability_of_with`] scans the f64 closed form with its own bounds (its last
/// branch): no series, no double-double, no small-angle expansion.
pub(super) fn plain_closed_scan(c: &Closed<Dual3>, a: &PlanarParams) -> bool {
    let theta = small_angle::max_angle(a[0], a[1], a[2]);
    matches!(c.case, Case::I | Case::II)
        && !c.needs_precise_series()
        && !c.det_needs_series()
        && c.needs_series() == SeriesNeed::None
        && SMALL_ANGLE_TRUNCATION_C * theta * theta > SMALL_ANGLE_MAX_TRUNCATION
}

/// True where g(1) < 0 beyond [`END_UNSTABLE_BOUNDS`] times its error bound (on a rod of the
/// plain scan, with the bound that scan uses): g → 1 as t → 0 (det J ~ t⁹(a3²/8640 +
/// a5²t²/33600) > 0 off the straight rod, docs/math.md §5), so det J vanishes somewhere on
/// (0, 1), a conjugate point.
pub(super) fn unstable_at_the_end(c: &Closed<Dual3>, a: &PlanarParams) -> bool {
    let (g, bound) = normalised_det(c, a[0], a[2], 1.0, false);
    g < -END_UNSTABLE_BOUNDS * bound
}

/// The verdict alone on the closed form ([`crate::planar::entry::stability_verdict`]), None where the
/// caller must run the full test. In order:
/// 1. a theorem ([`Closed::theorem_verdict`]: no conjugate point before the first inflection,
///    one by the third; [`with_theorem`] gives every report that verdict);
/// 2. on the rods of the plain closed-form scan only, g(1) ([`unstable_at_the_end`]);
/// 3. that scan from the theorem's t_free on ([`Closed::conjugate_free_until`]: no conjugate
///    point before it, so det J > 0 on (0, t_free) and the rod is stable iff det J > 0 on
///    [t_free, 1]), where the scan is certain.
///
/// On 20,000 rods of the paper's box the first two decide 64 % (20 % stable and 31 %
/// unstable by the theorems, 13 % unstable by g(1)); with the third, 7.1k instructions per
/// call, against 8.7k with the full test after the first two and 20.0k for the full test
/// (callgrind, 512 box rods).
pub(crate) fn verdict_of(
    c: &Closed<Dual3>,
    a: &PlanarParams,
) -> Result<Option<StabilityVerdict>, RodError> {
    if let Some(verdict) = c.theorem_verdict() {
        return Ok(Some(verdict));
    }
    if !plain_closed_scan(c, a) {
        return Ok(None);
    }
    if unstable_at_the_end(c, a) {
        return Ok(Some(StabilityVerdict::Unstable));
    }
    let report = closed_scan_from(c, a, false, None, c.conjugate_free_until())?;
    Ok((!report.uncertain).then(|| report.verdict()))
}
