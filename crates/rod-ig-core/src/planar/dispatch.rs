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

/// The f64 closed form of a (with its phase φ when `phase`, else placed by the addition
/// theorems) handed to `closed`; where it cannot be built, refused beyond √‖F‖ = ln(f64::MAX)
/// under tension, else the rod without it handed to `after`. Built in place
/// (`Closed::complete`): through an Option the form was copied.
#[inline]
fn with_closed_f64<R>(
    a: &PlanarParams,
    phase: bool,
    closed: impl FnOnce(&ClosedForm<'_, f64>) -> Result<R, RodError>,
    after: impl FnOnce(Rod<'_>) -> Result<R, RodError>,
) -> Result<R, RodError> {
    let mut c = Closed::<f64>::straight(a[0], a[1], a[2]);
    if !c.complete(a[0], a[1], a[2], phase) {
        tension_within_f64(a)?;
        return after(Rod::without_closed(a));
    }
    closed(&ClosedForm::new(&c, a))
}

/// [`with_closed_f64`] in dual numbers seeded with the identity on a (≈ 1 KB, borrowed where
/// it is built, never moved): `closed` gets the formulation and the form itself.
#[inline]
fn with_closed_dual<R>(
    a: &PlanarParams,
    phase: bool,
    closed: impl FnOnce(&ClosedForm<'_, Dual3>, &Closed<Dual3>) -> Result<R, RodError>,
    after: impl FnOnce(Rod<'_>) -> Result<R, RodError>,
) -> Result<R, RodError> {
    let (a3, a4, a5) = (
        Dual3::variable(a[0], 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a[2], 2),
    );
    let mut c = Closed::straight(a3, a4, a5);
    if !c.complete(a3, a4, a5, phase) {
        // The closed form's intermediate ratios overflowed (e.g. a tiny moment against a
        // moderate force).
        tension_within_f64(a)?;
        return after(Rod::without_closed(a));
    }
    closed(&ClosedForm::new(&c, a), &c)
}

/// The tip q(1).
#[inline]
pub(crate) fn tip(a: &PlanarParams) -> Result<PlanarPose, RodError> {
    match classify(a)? {
        Class::StrongForce => Ok(domain_evaluation(a)?.tip),
        Class::Within(Regime::SeparatrixLimit(limit)) => limit.tip(),
        Class::Within(Regime::GentlyBent) => tip_after(Rod::without_closed(a)),
        Class::Within(Regime::ClosedForm) => with_closed_f64(
            a,
            false,
            |cf| cf.tip().unwrap_or_else(|| tip_after(Rod::after(cf, None))),
            tip_after,
        ),
    }
}

fn tip_after(rod: Rod) -> Result<PlanarPose, RodError> {
    SmallAngle(rod)
        .tip()
        .or_else(|| IllConditioned(rod).tip())
        .unwrap_or_else(|| Series(rod).tip())
}

/// q(t) and J(t) for an answer (beyond the ordinary force the full evaluation's J(1), and its
/// refusal at any t).
#[inline]
pub(crate) fn pose_and_jacobian(
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    let regime = match classify(a)? {
        Class::Within(regime) => regime,
        Class::StrongForce => {
            let e = domain_evaluation(a)?;
            if t == 1.0 {
                return Ok((e.tip, e.jacobian));
            }
            regime_within(a)
        }
    };
    pose_and_jacobian_in(a, regime, t, Precision::Answer)
}

/// q(1) and J(1) for a solver's iteration or a continuation's substep (no full evaluation:
/// solvers verify their answer through the entry points).
#[inline]
pub(crate) fn solver_tip_and_jacobian(
    a: &PlanarParams,
    precision: Precision,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jacobian_in(a, regime(a)?, 1.0, precision)
}

#[inline]
fn pose_and_jacobian_in(
    a: &PlanarParams,
    regime: Regime,
    t: f64,
    precision: Precision,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    let after = |rod: Rod| {
        SmallAngle(rod)
            .pose_and_jacobian(t, precision)
            .or_else(|| IllConditioned(rod).pose_and_jacobian(t, precision))
            .unwrap_or_else(|| Series(rod).pose_and_jacobian(t, precision))
    };
    match regime {
        Regime::SeparatrixLimit(limit) => limit.pose_and_jacobian(t, precision),
        Regime::GentlyBent => after(Rod::without_closed(a)),
        Regime::ClosedForm => with_closed_dual(
            a,
            false,
            |cf, c| {
                cf.pose_and_jacobian(t, precision)
                    .unwrap_or_else(|| after(Rod::after(cf, Some(c))))
            },
            after,
        ),
    }
}

/// The elastic energy: the small-angle expansion first (its bound is the cheapest
/// certificate, and the identity cancels on nearly straight rods).
#[inline]
pub(crate) fn energy(a: &PlanarParams) -> Result<f64, RodError> {
    let regime = match classify(a)? {
        Class::StrongForce => return Ok(domain_evaluation(a)?.energy),
        Class::Within(regime) => regime,
    };
    if let Some(e) = SmallAngle(Rod::without_closed(a)).energy() {
        return e;
    }
    // The expansion was asked: not twice.
    let after = |rod: Rod| {
        IllConditioned(rod)
            .energy()
            .unwrap_or_else(|| Series(rod).energy())
    };
    match regime {
        Regime::SeparatrixLimit(limit) => limit.energy(),
        Regime::GentlyBent => after(Rod::without_closed(a)),
        Regime::ClosedForm => with_closed_f64(
            a,
            true,
            |cf| cf.energy().unwrap_or_else(|| after(Rod::after(cf, None))),
            after,
        ),
    }
}

/// The stability report.
#[inline]
pub(crate) fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    match classify(a)? {
        Class::StrongForce => Ok(domain_evaluation(a)?.stability),
        Class::Within(Regime::SeparatrixLimit(limit)) => limit.stability(),
        Class::Within(Regime::GentlyBent) => stability_after(Rod::without_closed(a)),
        Class::Within(Regime::ClosedForm) => stability_by_closed_form(a),
    }
}

/// The closed form's regime of the stability (its rows): what the separatrix limit asks where
/// its own theorems do not decide (an inflectional rod with one or two inflection points).
pub(crate) fn stability_from_closed_form(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    if series_first(a) {
        return stability_after(Rod::without_closed(a));
    }
    stability_by_closed_form(a)
}

/// The closed form has no stability of its own: it is built for the scans after it.
#[inline]
fn stability_by_closed_form(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    with_closed_dual(
        a,
        true,
        |cf, c| stability_after(Rod::after(cf, Some(c))),
        stability_after,
    )
}

fn stability_after(rod: Rod) -> Result<StabilityReport, RodError> {
    SmallAngle(rod)
        .stability()
        .or_else(|| ClosedScan(rod).stability())
        .or_else(|| IllConditioned(rod).stability())
        .unwrap_or_else(|| Series(rod).stability())
}

/// The stability verdict alone: the closed form's where a theorem or det J(1) decides, else
/// the report's.
#[inline]
pub(crate) fn verdict(a: &PlanarParams) -> Result<StabilityVerdict, RodError> {
    let after = |rod: Rod| stability_after(rod).map(|r| r.verdict());
    match classify(a)? {
        Class::StrongForce => Ok(domain_evaluation(a)?.stability.verdict()),
        Class::Within(Regime::SeparatrixLimit(limit)) => limit.stability().map(|r| r.verdict()),
        Class::Within(Regime::GentlyBent) => after(Rod::without_closed(a)),
        Class::Within(Regime::ClosedForm) => with_closed_dual(
            a,
            true,
            |cf, c| {
                cf.stability_verdict()
                    .unwrap_or_else(|| after(Rod::after(cf, Some(c))))
            },
            after,
        ),
    }
}

/// Tip, J(1), energy and stability at full accuracy (the full evaluation itself: every
/// force takes its regime).
#[inline]
pub(crate) fn evaluation(a: &PlanarParams) -> Result<Evaluation, RodError> {
    let after = |rod: Rod| {
        SmallAngle(rod)
            .evaluate()
            .or_else(|| IllConditioned(rod).evaluate())
            .unwrap_or_else(|| Series(rod).evaluate())
    };
    match regime(a)? {
        Regime::SeparatrixLimit(limit) => limit.evaluate(),
        Regime::GentlyBent => after(Rod::without_closed(a)),
        Regime::ClosedForm => with_closed_dual(
            a,
            true,
            |cf, c| {
                cf.evaluate()
                    .unwrap_or_else(|| after(Rod::after(cf, Some(c))))
            },
            after,
        ),
    }
}

/// The shape ([`PlanarRod`]): its refusals and tip beyond the ordinary force are the full
/// evaluation's, which `PlanarRod::new` asks first.
pub(crate) fn shape(a: &PlanarParams) -> Result<PlanarRod, RodError> {
    let after = |rod: Rod| {
        SmallAngle(rod)
            .shape()
            .or_else(|| IllConditioned(rod).shape())
            .unwrap_or_else(|| Series(rod).shape())
    };
    match regime(a)? {
        Regime::SeparatrixLimit(limit) => limit.shape(),
        Regime::GentlyBent => after(Rod::without_closed(a)),
        Regime::ClosedForm => with_closed_f64(
            a,
            true,
            |cf| cf.shape().unwrap_or_else(|| after(Rod::after(cf, None))),
            after,
        ),
    }
}
