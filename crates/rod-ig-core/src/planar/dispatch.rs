//! The one dispatcher of the planar evaluation (issues 44 and 53). A rod's regime is decided
//! once, by [`classify`] (or [`regime`] for the questions the full evaluation does not
//! answer); every entry point (`tip`, `pose_and_jacobian`, `energy`, `stability`,
//! `stability_verdict`, `evaluate`, the shape `PlanarRod::new`, and the solvers'
//! `tip_and_jacobian_for_iteration` / `_for_substep`) is one function here with one `match`
//! on it, and its fallbacks named in order. It is the only place where a regime is decided,
//! so the entry points share one domain and one refusal.
//!
//! | regime | when | who answers, in order |
//! | --- | --- | --- |
//! | refused | a non-finite | nobody: `RodError::NonFinite` naming `a` |
//! | [`Class::StrongForce`] | ‖(a4, a5)‖ > [`ORDINARY_FORCE`] | the full evaluation (its refusals are every question's); J at t < 1, the evaluation itself, the shape and a solver's iterations take the regime below |
//! | [`Regime::SeparatrixLimit`] | a barely bent rod under a strong force (ρ = max(\|β\|, \|a3\|/√R) ≤ 1e-7) | its soliton lattice, exact in log form where 1 − k² underflows (the energy asks the small-angle expansion first) |
//! | [`Regime::GentlyBent`] | ρ ≤ [`SERIES_RHO`] | the rows after the closed form, without one (one series step; the closed form's own estimate would reject nearly all of them) |
//! | [`Regime::ClosedForm`] | the rest | the closed form (f64 for the tip, energy and shape; dual numbers for J, the stability and the evaluation) where its error estimate holds (≈ 0.3–2 µs, exact to ≈ 1e-10); the verdict where a theorem or det J(1) decides. Where it cannot be built: refused beyond √‖F‖ = ln(f64::MAX) under tension, else the rows after it |
//!
//! The rows after the closed form, in order: the small-angle expansion (nearly straight rods,
//! where the closed form's x row is rounding), the closed form's stability scans (the
//! stability alone), the ill-conditioned routes by the separatrix (double-double, the
//! cross-check), and the f64 series, which answers everything that reaches it. A new regime is
//! one variant of [`Regime`] and one arm in each question's `match` (the compiler asks for
//! every one); a question a formulation cannot answer is a method it does not have.

use super::closed::Closed;
use super::formulation::{
    ClosedForm, ClosedScan, Evaluation, IllConditioned, Precision, Rod, SeparatrixLimit, Series,
    SmallAngle,
};
use crate::planar::shape::PlanarRod;
use crate::planar::taylor::{curvature_scale, overflow_force, LN_F64_MAX};
use crate::scalar::Dual3;
use crate::StabilityVerdict;
use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};

/// Rods with ρ = max(|a3|, √‖(a4, a5)‖) up to this value are evaluated by the Taylor series
/// without trying the closed form: one step from 0 to 1 (a few µs), and the closed form's own
/// error estimate ([`Closed::jacobian_rel_error`], which grows like 1/ρ³ on gently bent rods)
/// would reject nearly all of them. Above, the closed form is used wherever that estimate
/// allows (J within `CLOSED_J_TOLERANCE`), the series elsewhere: near the separatrix, at small
/// m (near-circles under a tiny force, nearly straight rods under compression) and on gently
/// bent rods whose entries of J are far smaller than the elliptic quantities they come from.
pub(super) const SERIES_RHO: f64 = 0.25;

/// ‖(a4, a5)‖ up to which every planar entry point answers every finite a (none refused on
/// 180,000 rods of log-scale |a3| up to 1e12 and |a4|, |a5| up to this, with exact zeros:
/// `examples/domain_scan.rs`). Beyond (√‖F‖ > 25), by a strong force, a formulation may refuse
/// what another answers (the first refusals measured: √‖F‖ ≈ 27, a barely bent rod under
/// tension), so the full evaluation decides for all of them.
pub(super) const ORDINARY_FORCE: f64 = 625.0;

/// The one refusal domain of the planar rod, shared by [`evaluate`] (forward), [`tip`],
/// [`pose_and_jacobian`], [`stability`], [`stability_verdict`], [`energy`] and
/// [`PlanarRod::new`] (shape): the full evaluation's. Below [`ORDINARY_FORCE`] it refuses only
/// non-finite a, so the entry points check nothing more (one comparison: this function);
/// beyond, they take [`domain_evaluation`]'s refusal, or its answer as theirs. Squared, so no
/// square root on every call; an overflow to +∞ or a NaN counts as beyond (and `evaluate`
/// refuses NaN).
#[inline]
pub(super) fn beyond_ordinary_force(a: &PlanarParams) -> bool {
    let f2 = a[1] * a[1] + a[2] * a[2];
    f2 > ORDINARY_FORCE * ORDINARY_FORCE || f2.is_nan()
}

/// The full evaluation that decides the domain beyond [`ORDINARY_FORCE`]: out of line, so that
/// the entry points' fast paths stay as they were.
#[cold]
#[inline(never)]
pub(super) fn domain_evaluation(a: &PlanarParams) -> Result<Evaluation, RodError> {
    evaluation(a)
}

/// True when the series is chosen without building the closed form.
pub(super) fn series_first(a: &PlanarParams) -> bool {
    curvature_scale(a) <= SERIES_RHO
}

/// Refuses, as the domain says, a rod under tension beyond √‖F‖ = ln(f64::MAX) whose closed
/// form cannot be built (deep by the separatrix): its rounding grows like e^{√‖F‖ t} in any
/// f64 integration, whose answer is then wrong without overflowing (a = (8.9e-220, 1.05e6,
/// −1.4e-103) came out θ = 20π, x = 0.922 where the exact pendulum has θ = 1.8e-104,
/// x = 0.992). Compressed rods (a4 ≤ 0) stay near their stable equilibrium and pass.
fn tension_within_f64(a: &PlanarParams) -> Result<(), RodError> {
    if a[1] > 0.0 && crate::scalar::fast_hypot(a[1], a[2]).sqrt() > LN_F64_MAX {
        return Err(overflow_force());
    }
    Ok(())
}

/// Checks a at every public entry, and charges the evaluation to the deadline in force (one
/// unit: a closed-form evaluation is bounded, ≈ 0.3–2 µs; the series inside charge their
/// steps).
pub(super) fn check_params(a: &PlanarParams) -> Result<(), RodError> {
    crate::deadline::charge(crate::deadline::units::PLANAR_EVALUATION);
    RodError::check_finite("a", a.as_slice())
}

/// Where a rod stands against the one domain: beyond the ordinary force the full evaluation
/// decides every quantity, within it the [`Regime`].
pub(crate) enum Class<'a> {
    /// ‖(a4, a5)‖ > [`ORDINARY_FORCE`] (or its square overflowed): the full evaluation.
    StrongForce,
    /// Within the ordinary force.
    Within(Regime<'a>),
}

/// How a rod within the ordinary force is evaluated (module docs' table).
pub(crate) enum Regime<'a> {
    /// A barely bent rod under a strong force: its soliton lattice (boxed: the other regimes,
    /// nearly every rod, move a pointer-sized value, not the lattice; a copy of it cost 10 %
    /// of the tip's instructions).
    SeparatrixLimit(Box<SeparatrixLimit<'a>>),
    /// ρ ≤ [`SERIES_RHO`]: the series, no closed form.
    GentlyBent,
    /// The closed form where its own error estimate holds, the rows after it elsewhere.
    ClosedForm,
}

/// The one classification: refuses a non-finite a (and charges the evaluation to the deadline
/// in force), else its [`Class`].
#[inline]
pub(crate) fn classify(a: &PlanarParams) -> Result<Class<'_>, RodError> {
    check_params(a)?;
    if beyond_ordinary_force(a) {
        return Ok(Class::StrongForce);
    }
    Ok(Class::Within(regime_within(a)))
}

/// [`classify`] for the questions the full evaluation does not answer (the evaluation itself,
/// the shape, a solver's iterations): the regime whatever the force.
#[inline]
pub(crate) fn regime(a: &PlanarParams) -> Result<Regime<'_>, RodError> {
    check_params(a)?;
    Ok(regime_within(a))
}

#[inline]
fn regime_within(a: &PlanarParams) -> Regime<'_> {
    if let Some(limit) = SeparatrixLimit::of(a) {
        return Regime::SeparatrixLimit(Box::new(limit));
    }
    if series_first(a) {
        return Regime::GentlyBent;
    }
    Regime::ClosedForm
}

/// What a question's route records (issue 53: each answer can say which formulation answered
/// and which declined). The questions run with `()`, which records nothing and compiles away;
/// [`route`] runs them with a [`Route`].
pub(crate) trait Record {
    /// The rod's regime (or class).
    fn regime(&mut self, name: &'static str);
    /// A formulation was asked; `answered` is false where it declined (outside its bound).
    fn asked(&mut self, formulation: &'static str, answered: bool);
}

impl Record for () {
    #[inline(always)]
    fn regime(&mut self, _: &'static str) {}
    #[inline(always)]
    fn asked(&mut self, _: &'static str, _: bool) {}
}

/// The route one question took for one rod: its regime and the formulations asked, in order,
/// each with whether it answered (the last one that answered gave the answer).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Route {
    /// "strong force", "separatrix limit", "gently bent" or "closed form".
    pub regime: &'static str,
    /// (formulation, answered) in the order they were asked.
    pub asked: Vec<(&'static str, bool)>,
}

impl Route {
    /// The formulation that answered (the last one asked that did).
    pub fn answered_by(&self) -> Option<&'static str> {
        self.asked.iter().rev().find(|(_, ok)| *ok).map(|(f, _)| *f)
    }
}

impl Record for Route {
    fn regime(&mut self, name: &'static str) {
        self.regime = name;
    }
    fn asked(&mut self, formulation: &'static str, answered: bool) {
        self.asked.push((formulation, answered));
    }
}

/// A question of [`route`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// The tip q(1) ([`crate::planar::tip`]).
    Tip,
    /// q(1) and J(1) ([`crate::planar::tip_and_jacobian`]).
    TipAndJacobian,
    /// The elastic energy ([`crate::planar::energy`]).
    Energy,
    /// The stability report ([`crate::planar::stability`]).
    Stability,
    /// The verdict alone ([`crate::planar::stability_verdict`]).
    Verdict,
    /// The whole evaluation ([`crate::planar::evaluate`]).
    Evaluation,
    /// The shape ([`crate::planar::PlanarRod::new`]).
    Shape,
}

/// The route `quantity` takes for the rod a, computed by asking it: which regime a is in and
/// which formulations were asked, in order, and which answered. For debugging and for
/// reading the dispatcher against a rod; the refusals are the question's own.
///
/// ```
/// use rod_ig_core::planar::{route, Quantity};
/// use rod_ig_core::PlanarParams;
/// let r = route(&PlanarParams::new(2.0, -10.0, 5.0), Quantity::TipAndJacobian)?;
/// assert_eq!((r.regime, r.answered_by()), ("closed form", Some("closed form")));
/// let r = route(&PlanarParams::new(1e-3, 0.0, 1e-3), Quantity::Tip)?;
/// assert_eq!(r.regime, "gently bent");
/// # Ok::<(), rod_ig_core::RodError>(())
/// ```
pub fn route(a: &PlanarParams, quantity: Quantity) -> Result<Route, RodError> {
    let mut r = Route::default();
    match quantity {
        Quantity::Tip => tip_with(a, &mut r).map(drop),
        Quantity::TipAndJacobian => pose_and_jacobian_with(a, 1.0, &mut r).map(drop),
        Quantity::Energy => energy_with(a, &mut r).map(drop),
        Quantity::Stability => stability_with(a, &mut r).map(drop),
        Quantity::Verdict => verdict_with(a, &mut r).map(drop),
        Quantity::Evaluation => evaluation_with(a, &mut r).map(drop),
        Quantity::Shape => shape_with(a, &mut r).map(drop),
    }?;
    Ok(r)
}

/// `answer` from `formulation`, recorded.
#[inline(always)]
fn ask<T, R: Record>(
    r: &mut R,
    formulation: &'static str,
    answer: Option<Result<T, RodError>>,
) -> Option<Result<T, RodError>> {
    r.asked(formulation, answer.is_some());
    answer
}

/// The answer of a formulation that always answers, recorded.
#[inline(always)]
fn last<T, R: Record>(
    r: &mut R,
    formulation: &'static str,
    answer: Result<T, RodError>,
) -> Result<T, RodError> {
    r.asked(formulation, true);
    answer
}

/// [`classify`], recorded.
#[inline(always)]
fn classified<'a, R: Record>(a: &'a PlanarParams, r: &mut R) -> Result<Class<'a>, RodError> {
    let class = classify(a)?;
    r.regime(match &class {
        Class::StrongForce => "strong force",
        Class::Within(regime) => regime.name(),
    });
    Ok(class)
}

/// [`regime`], recorded.
#[inline(always)]
fn regime_recorded<'a, R: Record>(a: &'a PlanarParams, r: &mut R) -> Result<Regime<'a>, RodError> {
    let regime = regime(a)?;
    r.regime(regime.name());
    Ok(regime)
}

impl Regime<'_> {
    /// Its name in a [`Route`].
    #[inline(always)]
    fn name(&self) -> &'static str {
        match self {
            Regime::SeparatrixLimit(_) => "separatrix limit",
            Regime::GentlyBent => "gently bent",
            Regime::ClosedForm => "closed form",
        }
    }
}

/// The f64 closed form of a (with its phase φ when `phase`, else placed by the addition
/// theorems) handed to `closed`; where it cannot be built, refused beyond √‖F‖ = ln(f64::MAX)
/// under tension, else the rod without it handed to `after`. Built in place
/// (`Closed::complete`): through an Option the form was copied.
#[inline]
fn with_closed_f64<T, R: Record>(
    a: &PlanarParams,
    phase: bool,
    r: &mut R,
    closed: impl FnOnce(&ClosedForm<'_, f64>, &mut R) -> Result<T, RodError>,
    after: impl FnOnce(Rod<'_>, &mut R) -> Result<T, RodError>,
) -> Result<T, RodError> {
    let mut c = Closed::<f64>::straight(a[0], a[1], a[2]);
    if !c.complete(a[0], a[1], a[2], phase) {
        r.asked("closed form (overflowed)", false);
        tension_within_f64(a)?;
        return after(Rod::without_closed(a), r);
    }
    closed(&ClosedForm::new(&c, a), r)
}

/// [`with_closed_f64`] in dual numbers seeded with the identity on a (≈ 1 KB, borrowed where
/// it is built, never moved): `closed` gets the formulation and the form itself.
#[inline]
fn with_closed_dual<T, R: Record>(
    a: &PlanarParams,
    phase: bool,
    r: &mut R,
    closed: impl FnOnce(&ClosedForm<'_, Dual3>, &Closed<Dual3>, &mut R) -> Result<T, RodError>,
    after: impl FnOnce(Rod<'_>, &mut R) -> Result<T, RodError>,
) -> Result<T, RodError> {
    let (a3, a4, a5) = (
        Dual3::variable(a[0], 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a[2], 2),
    );
    let mut c = Closed::straight(a3, a4, a5);
    if !c.complete(a3, a4, a5, phase) {
        // The closed form's intermediate ratios overflowed (e.g. a tiny moment against a
        // moderate force).
        r.asked("closed form (overflowed)", false);
        tension_within_f64(a)?;
        return after(Rod::without_closed(a), r);
    }
    closed(&ClosedForm::new(&c, a), &c, r)
}

/// The tip q(1).
#[inline]
pub(crate) fn tip(a: &PlanarParams) -> Result<PlanarPose, RodError> {
    tip_with(a, &mut ())
}

#[inline]
fn tip_with<R: Record>(a: &PlanarParams, r: &mut R) -> Result<PlanarPose, RodError> {
    match classified(a, r)? {
        Class::StrongForce => last(r, "full evaluation", domain_evaluation(a).map(|e| e.tip)),
        Class::Within(Regime::SeparatrixLimit(limit)) => last(r, "separatrix limit", limit.tip()),
        Class::Within(Regime::GentlyBent) => tip_after(Rod::without_closed(a), r),
        Class::Within(Regime::ClosedForm) => with_closed_f64(
            a,
            false,
            r,
            |cf, r| match ask(r, "closed form", cf.tip()) {
                Some(answer) => answer,
                None => tip_after(Rod::after(cf, None), r),
            },
            tip_after,
        ),
    }
}

#[inline]
fn tip_after<R: Record>(rod: Rod, r: &mut R) -> Result<PlanarPose, RodError> {
    if let Some(answer) = ask(r, "small angle", SmallAngle(rod).tip()) {
        return answer;
    }
    if let Some(answer) = ask(r, "ill-conditioned", IllConditioned(rod).tip()) {
        return answer;
    }
    last(r, "series", Series(rod).tip())
}

/// q(t) and J(t) for an answer (beyond the ordinary force the full evaluation's J(1), and its
/// refusal at any t).
#[inline]
pub(crate) fn pose_and_jacobian(
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jacobian_with(a, t, &mut ())
}

#[inline]
fn pose_and_jacobian_with<R: Record>(
    a: &PlanarParams,
    t: f64,
    r: &mut R,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    let regime = match classified(a, r)? {
        Class::Within(regime) => regime,
        Class::StrongForce => {
            let e = domain_evaluation(a)?;
            if t == 1.0 {
                r.asked("full evaluation", true);
                return Ok((e.tip, e.jacobian));
            }
            r.asked("full evaluation (J(1) only)", false);
            regime_within(a)
        }
    };
    pose_and_jacobian_in(a, regime, t, Precision::Answer, r)
}

/// q(1) and J(1) for a solver's iteration or a continuation's substep (no full evaluation:
/// solvers verify their answer through the entry points).
#[inline]
pub(crate) fn solver_tip_and_jacobian(
    a: &PlanarParams,
    precision: Precision,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jacobian_in(a, regime(a)?, 1.0, precision, &mut ())
}

#[inline]
fn pose_and_jacobian_in<R: Record>(
    a: &PlanarParams,
    regime: Regime,
    t: f64,
    precision: Precision,
    r: &mut R,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    let after = |rod: Rod, r: &mut R| {
        if let Some(answer) = ask(
            r,
            "small angle",
            SmallAngle(rod).pose_and_jacobian(t, precision),
        ) {
            return answer;
        }
        if let Some(answer) = ask(
            r,
            "ill-conditioned",
            IllConditioned(rod).pose_and_jacobian(t, precision),
        ) {
            return answer;
        }
        last(r, "series", Series(rod).pose_and_jacobian(t, precision))
    };
    match regime {
        Regime::SeparatrixLimit(limit) => {
            last(r, "separatrix limit", limit.pose_and_jacobian(t, precision))
        }
        Regime::GentlyBent => after(Rod::without_closed(a), r),
        Regime::ClosedForm => with_closed_dual(
            a,
            false,
            r,
            |cf, c, r| match ask(r, "closed form", cf.pose_and_jacobian(t, precision)) {
                Some(answer) => answer,
                None => after(Rod::after(cf, Some(c)), r),
            },
            after,
        ),
    }
}

/// The elastic energy: the small-angle expansion first (its bound is the cheapest
/// certificate, and the identity cancels on nearly straight rods).
#[inline]
pub(crate) fn energy(a: &PlanarParams) -> Result<f64, RodError> {
    energy_with(a, &mut ())
}

#[inline]
fn energy_with<R: Record>(a: &PlanarParams, r: &mut R) -> Result<f64, RodError> {
    let regime = match classified(a, r)? {
        Class::StrongForce => {
            return last(r, "full evaluation", domain_evaluation(a).map(|e| e.energy))
        }
        Class::Within(regime) => regime,
    };
    if let Some(e) = ask(
        r,
        "small angle",
        SmallAngle(Rod::without_closed(a)).energy(),
    ) {
        return e;
    }
    // The expansion was asked: not twice.
    let after = |rod: Rod, r: &mut R| match ask(r, "ill-conditioned", IllConditioned(rod).energy())
    {
        Some(answer) => answer,
        None => last(r, "series", Series(rod).energy()),
    };
    match regime {
        Regime::SeparatrixLimit(limit) => last(r, "separatrix limit", limit.energy()),
        Regime::GentlyBent => after(Rod::without_closed(a), r),
        Regime::ClosedForm => with_closed_f64(
            a,
            true,
            r,
            |cf, r| match ask(r, "closed form", cf.energy()) {
                Some(answer) => answer,
                None => after(Rod::after(cf, None), r),
            },
            after,
        ),
    }
}

/// The stability report.
#[inline]
pub(crate) fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    stability_with(a, &mut ())
}

#[inline]
fn stability_with<R: Record>(a: &PlanarParams, r: &mut R) -> Result<StabilityReport, RodError> {
    match classified(a, r)? {
        Class::StrongForce => last(
            r,
            "full evaluation",
            domain_evaluation(a).map(|e| e.stability),
        ),
        Class::Within(Regime::SeparatrixLimit(limit)) => {
            last(r, "separatrix limit", limit.stability())
        }
        Class::Within(Regime::GentlyBent) => stability_after(Rod::without_closed(a), r),
        Class::Within(Regime::ClosedForm) => stability_by_closed_form(a, r),
    }
}

/// The closed form's regime of the stability (its rows): what the separatrix limit asks where
/// its own theorems do not decide (an inflectional rod with one or two inflection points).
pub(crate) fn stability_from_closed_form(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    if series_first(a) {
        return stability_after(Rod::without_closed(a), &mut ());
    }
    stability_by_closed_form(a, &mut ())
}

/// The closed form has no stability of its own: it is built for the scans after it.
#[inline]
fn stability_by_closed_form<R: Record>(
    a: &PlanarParams,
    r: &mut R,
) -> Result<StabilityReport, RodError> {
    with_closed_dual(
        a,
        true,
        r,
        |cf, c, r| stability_after(Rod::after(cf, Some(c)), r),
        stability_after,
    )
}

fn stability_after<R: Record>(rod: Rod, r: &mut R) -> Result<StabilityReport, RodError> {
    if let Some(answer) = ask(r, "small angle", SmallAngle(rod).stability()) {
        return answer;
    }
    if let Some(answer) = ask(r, "closed-form scans", ClosedScan(rod).stability()) {
        return answer;
    }
    if let Some(answer) = ask(r, "ill-conditioned", IllConditioned(rod).stability()) {
        return answer;
    }
    last(r, "series", Series(rod).stability())
}

/// The stability verdict alone: the closed form's where a theorem or det J(1) decides, else
/// the report's.
#[inline]
pub(crate) fn verdict(a: &PlanarParams) -> Result<StabilityVerdict, RodError> {
    verdict_with(a, &mut ())
}

#[inline]
fn verdict_with<R: Record>(a: &PlanarParams, r: &mut R) -> Result<StabilityVerdict, RodError> {
    let after = |rod: Rod, r: &mut R| stability_after(rod, r).map(|report| report.verdict());
    match classified(a, r)? {
        Class::StrongForce => last(
            r,
            "full evaluation",
            domain_evaluation(a).map(|e| e.stability.verdict()),
        ),
        Class::Within(Regime::SeparatrixLimit(limit)) => last(
            r,
            "separatrix limit",
            limit.stability().map(|report| report.verdict()),
        ),
        Class::Within(Regime::GentlyBent) => after(Rod::without_closed(a), r),
        Class::Within(Regime::ClosedForm) => with_closed_dual(
            a,
            true,
            r,
            |cf, c, r| match ask(r, "closed form", cf.stability_verdict()) {
                Some(answer) => answer,
                None => after(Rod::after(cf, Some(c)), r),
            },
            after,
        ),
    }
}

/// Tip, J(1), energy and stability at full accuracy (the full evaluation itself: every
/// force takes its regime).
#[inline]
pub(crate) fn evaluation(a: &PlanarParams) -> Result<Evaluation, RodError> {
    evaluation_with(a, &mut ())
}

#[inline]
fn evaluation_with<R: Record>(a: &PlanarParams, r: &mut R) -> Result<Evaluation, RodError> {
    let after = |rod: Rod, r: &mut R| {
        if let Some(answer) = ask(r, "small angle", SmallAngle(rod).evaluate()) {
            return answer;
        }
        if let Some(answer) = ask(r, "ill-conditioned", IllConditioned(rod).evaluate()) {
            return answer;
        }
        last(r, "series", Series(rod).evaluate())
    };
    match regime_recorded(a, r)? {
        Regime::SeparatrixLimit(limit) => last(r, "separatrix limit", limit.evaluate()),
        Regime::GentlyBent => after(Rod::without_closed(a), r),
        Regime::ClosedForm => with_closed_dual(
            a,
            true,
            r,
            |cf, c, r| match ask(r, "closed form", cf.evaluate()) {
                Some(answer) => answer,
                None => after(Rod::after(cf, Some(c)), r),
            },
            after,
        ),
    }
}

/// The shape ([`PlanarRod`]): its refusals and tip beyond the ordinary force are the full
/// evaluation's, which `PlanarRod::new` asks first.
pub(crate) fn shape(a: &PlanarParams) -> Result<PlanarRod, RodError> {
    shape_with(a, &mut ())
}

fn shape_with<R: Record>(a: &PlanarParams, r: &mut R) -> Result<PlanarRod, RodError> {
    let after = |rod: Rod, r: &mut R| {
        if let Some(answer) = ask(r, "small angle", SmallAngle(rod).shape()) {
            return answer;
        }
        if let Some(answer) = ask(r, "ill-conditioned", IllConditioned(rod).shape()) {
            return answer;
        }
        last(r, "series", Series(rod).shape())
    };
    match regime_recorded(a, r)? {
        Regime::SeparatrixLimit(limit) => last(r, "separatrix limit", limit.shape()),
        Regime::GentlyBent => after(Rod::without_closed(a), r),
        Regime::ClosedForm => with_closed_f64(
            a,
            true,
            r,
            |cf, r| match ask(r, "closed form", cf.shape()) {
                Some(answer) => answer,
                None => after(Rod::after(cf, None), r),
            },
            after,
        ),
    }
}
