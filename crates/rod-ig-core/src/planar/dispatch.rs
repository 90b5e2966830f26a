//! The one dispatcher of the planar evaluation (issue 44). Every entry point (`tip`,
//! `pose_and_jacobian`, `energy`, `stability`, `stability_verdict`, `evaluate`, the shape
//! `PlanarRod::new`, and the solvers' `tip_and_jacobian_for_iteration` / `_for_substep`) asks its [`Question`] through
//! [`answer`], which walks one ordered table of formulations ([`super::formulation`]) and
//! takes the first answer. It is the only place where a rod's regime is decided, so the entry
//! points share one domain and one refusal.
//!
//! | row | formulation | when it is asked | why here |
//! | --- | --- | --- | --- |
//! | 0 | (refusal) | a non-finite | nothing can answer |
//! | 1 | [`FullEvaluation`] | ‖(a4, a5)‖ > [`ORDINARY_FORCE`] | beyond, one formulation may refuse what another answers: the full evaluation decides for all |
//! | 2 | [`SmallAngle`] | the energy only | its bound is the cheapest certificate, and the identity cancels on nearly straight rods |
//! | 2½ | [`SeparatrixLimit`] | a barely bent rod under a strong force (ρ = max(\|β\|, \|a3\|/√R) ≤ 1e-7) | exact in log form where 1 − k² underflows and every closed form loses its phase |
//! | 3 | [`Series`] (no closed form) | ρ ≤ [`SERIES_RHO`] | one series step; the closed form's own estimate would reject nearly all of them |
//! | 4 | (refusal), [`Series`] | the closed form overflows | beyond √‖F‖ = ln(f64::MAX) under tension every f64 evaluation is wrong; below, the series has its own overflow detection |
//! | 5 | [`ClosedForm`] | its error estimate holds; for the verdict, a theorem or det J(1) | ≈ 0.3–2 µs, exact to ≈ 1e-10 |
//! | 6 | [`SmallAngle`] | the closed form declined, or the stability | nearly straight rods: the closed form's x row is rounding there |
//! | 7 | [`ClosedScan`] | the stability | the closed form's scans (its own bounds; the small-m scan) |
//! | 8 | [`IllConditioned`] | by the separatrix | rounding grows like e^{√‖F‖}: double-double, or the cross-check |
//! | 9 | [`Series`] | whatever is left | the f64 series is exact to ~1e-14 where only the closed form cancels |
//!
//! A formulation answers a quantity inside its own domain for it and says `None` outside (e.g.
//! [`FullEvaluation`] has J at t = 1 only): the next row is asked.

use super::closed::Closed;

use super::formulation::{
    Answer, ClosedForm, ClosedScan, Formulation, FullEvaluation, IllConditioned, Need, Precision,
    Rod, SeparatrixLimit, Series, SmallAngle,
};
use crate::planar::entry::{evaluate, Evaluation};
use crate::planar::shape::PlanarRod;
use crate::planar::taylor::curvature_scale;
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

/// ln(f64::MAX): under tension F the rod's J grows like e^{√F t}; beyond this √F it overflows.
pub(super) const LN_F64_MAX: f64 = 709.7;

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
    evaluate(a)
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

pub(super) fn overflow_force() -> RodError {
    RodError::Overflow(format!(
        "planar rod: under this force J(t, a) grows like e^(sqrt|F| t) and exceeds f64 \
         (sqrt|F| > {LN_F64_MAX})"
    ))
}

/// Checks a at every public entry, and charges the evaluation to the deadline in force (one
/// unit: a closed-form evaluation is bounded, ≈ 0.3–2 µs; the series inside charge their
/// steps).
pub(super) fn check_params(a: &PlanarParams) -> Result<(), RodError> {
    crate::deadline::charge(crate::deadline::units::PLANAR_EVALUATION);
    RodError::check_finite("a", a.as_slice())
}

/// The closed form a question evaluates: in f64 (the tip; the energy) or in dual numbers
/// seeded with the identity on a (J, stability, evaluation); without its phase φ where the
/// addition theorems place the poses it asks (`Closed::complete`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Build {
    /// f64, without the phase (the tip alone).
    F64,
    /// f64 with its phase (the energy, which uses its ζ form).
    F64WithPhase,
    /// Dual numbers without the phase (poses and J alone: the same bits either way).
    Dual,
    /// Dual numbers with the phase (the scans sample along the rod).
    DualWithPhase,
}

/// What an entry point asks of the rod: which quantity ([`Self::ask`]), from which rows.
pub(crate) trait Question: Copy {
    /// The quantity.
    type Answer;
    /// The closed form this question evaluates.
    const BUILD: Build;
    /// Whether row 1 ([`FullEvaluation`]) applies: not to the evaluation itself, which it
    /// is, nor to a solver's iterations, which verify their answer through the entry points.
    const FULL_EVALUATION: bool = true;
    /// Whether row 2 applies (the energy).
    const SMALL_ANGLE_FIRST: bool = false;
    /// The formulation's answer to this question.
    fn ask<F: Formulation>(self, f: &F) -> Answer<Self::Answer>;
}

/// The table (module docs): the first answer of its rows, in order.
#[inline]
pub(crate) fn answer<Q: Question>(a: &PlanarParams, q: Q) -> Result<Q::Answer, RodError> {
    check_params(a)?;
    if Q::FULL_EVALUATION && beyond_ordinary_force(a) {
        let e = domain_evaluation(a)?;
        if let Some(answer) = q.ask(&FullEvaluation(&e)) {
            return answer;
        }
    }
    let without_closed = Rod {
        a,
        closed: None,
        need: Need::NoClosedForm,
        case: None,
        precise_series: false,
    };
    if Q::SMALL_ANGLE_FIRST {
        if let Some(answer) = q.ask(&SmallAngle(without_closed)) {
            return answer;
        }
    }
    if let Some(limit) = SeparatrixLimit::of(a) {
        if let Some(answer) = q.ask(&limit) {
            return answer;
        }
    }
    from_closed_form(a, q, without_closed)
}

/// Rows 3–9 of the table: what the separatrix limit asks where its own theorems do not decide
/// the stability (an inflectional rod with one or two inflection points on the rod).
pub(crate) fn stability_from_closed_form(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    let without_closed = Rod {
        a,
        closed: None,
        need: Need::NoClosedForm,
        case: None,
        precise_series: false,
    };
    from_closed_form(a, Stability, without_closed)
}

/// Rows 3–9 of the table.
#[inline]
fn from_closed_form<Q: Question>(
    a: &PlanarParams,
    q: Q,
    without_closed: Rod,
) -> Result<Q::Answer, RodError> {
    if series_first(a) {
        return after_closed_form(q, without_closed);
    }
    match Q::BUILD {
        Build::F64 | Build::F64WithPhase => {
            // Built in place (`Closed::complete`): through an Option the form was copied.
            let mut c = Closed::<f64>::straight(a[0], a[1], a[2]);
            if !c.complete(a[0], a[1], a[2], Q::BUILD == Build::F64WithPhase) {
                tension_within_f64(a)?;
                return after_closed_form(q, without_closed);
            }
            let closed_form = ClosedForm::new(&c, a);
            match q.ask(&closed_form) {
                Some(answer) => answer,
                None => after_closed_form(q, Rod::after(&closed_form, None)),
            }
        }
        Build::Dual | Build::DualWithPhase => {
            let (a3, a4, a5) = (
                Dual3::variable(a[0], 0),
                Dual3::variable(a[1], 1),
                Dual3::variable(a[2], 2),
            );
            // ≈ 1 KB of dual numbers, borrowed where it is built, never moved.
            let mut c = Closed::straight(a3, a4, a5);
            if !c.complete(a3, a4, a5, Q::BUILD == Build::DualWithPhase) {
                // The closed form's intermediate ratios overflowed (e.g. a tiny moment against
                // a moderate force).
                tension_within_f64(a)?;
                return after_closed_form(q, without_closed);
            }
            let closed_form = ClosedForm::new(&c, a);
            match q.ask(&closed_form) {
                Some(answer) => answer,
                None => after_closed_form(q, Rod::after(&closed_form, Some(&c))),
            }
        }
    }
}

/// Rows 6–9 of the table.
fn after_closed_form<Q: Question>(q: Q, rod: Rod) -> Result<Q::Answer, RodError> {
    // A question that asked the expansion first (row 2) has its answer already: not twice.
    if !Q::SMALL_ANGLE_FIRST {
        if let Some(answer) = q.ask(&SmallAngle(rod)) {
            return answer;
        }
    }
    if let Some(answer) = q.ask(&ClosedScan(rod)) {
        return answer;
    }
    if let Some(answer) = q.ask(&IllConditioned(rod)) {
        return answer;
    }
    q.ask(&Series(rod)).unwrap_or_else(|| {
        Err(RodError::OutOfDomain(
            "planar rod: no formulation answers this quantity".into(),
        ))
    })
}

/// The tip q(1).
#[derive(Clone, Copy)]
pub(crate) struct Tip;
impl Question for Tip {
    type Answer = PlanarPose;
    const BUILD: Build = Build::F64;
    fn ask<F: Formulation>(self, f: &F) -> Answer<PlanarPose> {
        f.tip()
    }
}

/// q(t) and J(t) for an answer.
#[derive(Clone, Copy)]
pub(crate) struct PoseAndJacobian(pub(crate) f64);
impl Question for PoseAndJacobian {
    type Answer = (PlanarPose, PlanarJacobian);
    const BUILD: Build = Build::Dual;
    fn ask<F: Formulation>(self, f: &F) -> Answer<Self::Answer> {
        f.pose_and_jacobian(self.0, Precision::Answer)
    }
}

/// q(1) and J(1) for a solver's iteration or a continuation's substep.
#[derive(Clone, Copy)]
pub(crate) struct SolverTipAndJacobian(pub(crate) Precision);
impl Question for SolverTipAndJacobian {
    type Answer = (PlanarPose, PlanarJacobian);
    const BUILD: Build = Build::Dual;
    const FULL_EVALUATION: bool = false;
    fn ask<F: Formulation>(self, f: &F) -> Answer<Self::Answer> {
        f.pose_and_jacobian(1.0, self.0)
    }
}

/// The elastic energy.
#[derive(Clone, Copy)]
pub(crate) struct Energy;
impl Question for Energy {
    type Answer = f64;
    const BUILD: Build = Build::F64WithPhase;
    const SMALL_ANGLE_FIRST: bool = true;
    fn ask<F: Formulation>(self, f: &F) -> Answer<f64> {
        f.energy()
    }
}

/// The stability report.
#[derive(Clone, Copy)]
pub(crate) struct Stability;
impl Question for Stability {
    type Answer = StabilityReport;
    const BUILD: Build = Build::DualWithPhase;
    fn ask<F: Formulation>(self, f: &F) -> Answer<StabilityReport> {
        f.stability()
    }
}

/// The stability verdict alone.
#[derive(Clone, Copy)]
pub(crate) struct Verdict;
impl Question for Verdict {
    type Answer = StabilityVerdict;
    const BUILD: Build = Build::DualWithPhase;
    fn ask<F: Formulation>(self, f: &F) -> Answer<StabilityVerdict> {
        f.stability_verdict()
    }
}

/// The whole evaluation (row 1 is this question's own answer: it does not ask it).
#[derive(Clone, Copy)]
pub(crate) struct Evaluate;
impl Question for Evaluate {
    type Answer = Evaluation;
    const BUILD: Build = Build::DualWithPhase;
    const FULL_EVALUATION: bool = false;
    fn ask<F: Formulation>(self, f: &F) -> Answer<Evaluation> {
        f.evaluate()
    }
}

/// The shape ([`PlanarRod`]): its refusals and tip beyond row 1 are the full evaluation's,
/// which `PlanarRod::new` asks first.
#[derive(Clone, Copy)]
pub(crate) struct Shape;
impl Question for Shape {
    type Answer = PlanarRod;
    const BUILD: Build = Build::F64WithPhase;
    const FULL_EVALUATION: bool = false;
    fn ask<F: Formulation>(self, f: &F) -> Answer<PlanarRod> {
        f.shape()
    }
}
