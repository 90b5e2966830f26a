//! The formulations of the planar rod (issues 44 and 53). Each is one way of evaluating the
//! rod, with inherent methods for the quantities it can give: a method of a formulation that
//! answers only inside its own domain for that quantity (the a-priori error bound that decides
//! it) returns `None` outside, and the question's `match` in [`super::dispatch`] names its next
//! formulation explicitly; [`Series`] and [`SeparatrixLimit`] always answer. A quantity a
//! formulation does not have is a method it does not have: asking it does not compile. None
//! calls the dispatcher back.
//!
//! | formulation | module | answers |
//! | --- | --- | --- |
//! | [`SeparatrixLimit`] | `separatrix_limit` | a barely bent rod under a strong force (ρ ≤ 1e-7): every quantity from its soliton lattice, exact where 1 − k² underflows |
//! | [`ClosedForm`] | `closed_form` | where the closed form's error estimate holds (J to 1e-8); the verdict where a theorem or det J(1) decides |
//! | [`ClosedScan`] | `closed_form` | the stability scans on the closed form, after the small-angle expansion's |
//! | [`SmallAngle`] | `small_angle` | nearly straight rods, where the expansion's (or the pendulum's) bounds hold |
//! | [`IllConditioned`] | `ill_conditioned` | by the separatrix: double-double closed form, f64 / double-double series, cross-check |
//! | [`Series`] | `series` | gently bent rods (ρ ≤ 0.25), closed forms that overflow, closed-form J that cancels: every quantity |
//!
//! Beyond ‖(a4, a5)‖ = 625 the full evaluation decides every quantity (the dispatcher's
//! `Regime::StrongForce`).

use super::closed::Case;

use super::closed::{Closed, SeriesNeed, CLOSED_J_TOLERANCE};
use super::shape::{case_without_closed, series_backend, Backend};
use crate::planar::shape::PlanarRod;
use crate::scalar::Dual3;
use crate::StabilityVerdict;

use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};

mod closed_form;
mod ill_conditioned;
mod separatrix_limit;
mod series;
mod small_angle;

#[cfg(test)]
pub(crate) use closed_form::SUBSTEP_J_TOLERANCE;
pub(crate) use closed_form::{ClosedForm, ClosedScan};
#[cfg(test)]
pub(crate) use ill_conditioned::ill_conditioned_tip;
pub(crate) use ill_conditioned::{IllConditioned, CROSS_CHECK_J, CROSS_CHECK_TIP};
pub(crate) use separatrix_limit::SeparatrixLimit;
pub(crate) use series::Series;
pub(crate) use small_angle::SmallAngle;

/// Tip, J(1, a) (rows x, y, θ; columns a3, a4, a5), ½∫κ² and the stability verdict of one rod
/// at full accuracy: the solvers' evaluation type ([`crate::solver::ModelEvaluation`]) for the
/// planar rod.
pub type Evaluation = crate::solver::ModelEvaluation<3, PlanarPose>;

/// An answer of a formulation: `None` outside its domain, else its value or its refusal.
pub(crate) type Answer<T> = Option<Result<T, RodError>>;

/// How accurate the J of `pose_and_jacobian` must be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Precision {
    /// An answer: J to 1e-8 relative and the tip to 1e-11, wherever a formulation certifies them.
    Answer,
    /// A solver's iteration: by the separatrix the f64 series stands in for the double-double
    /// ones (errors ε·e^{√‖F‖}, ≈ 100× cheaper; the solvers verify their answer at `Answer`).
    Iteration,
    /// A continuation's intermediate step: the closed form wherever its J estimate is within
    /// 100× an answer's tolerance (strongly tensioned rods: 1 µs where the series takes ms).
    Substep,
}

/// What the closed form of the rod said, for the rows after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Need {
    /// No closed form: a gently bent rod (ρ ≤ 0.25), or one whose closed form overflowed.
    NoClosedForm,
    /// The closed form's estimate holds.
    Closed,
    /// Cancellation in the closed form only: the f64 series is accurate.
    Cancellation,
    /// By the separatrix: rounding grows like e^{√‖F‖} in any f64 evaluation.
    IllConditioned,
}

impl Need {
    /// What the closed form says of J(t) ([`Closed::needs_series`]): at t < 1 the part [0, t]
    /// is a rod of length t, whose J is as hard as J(1) of a gently bent rod
    /// ([`Closed::jacobian_rel_error_at`]).
    #[inline]
    pub(crate) fn at<T: crate::scalar::Real>(c: &Closed<T>, t: f64) -> Self {
        match c.needs_series() {
            SeriesNeed::None if t < 1.0 && c.jacobian_rel_error_at(t) > CLOSED_J_TOLERANCE => {
                if c.needs_precise_series() {
                    Need::IllConditioned
                } else {
                    Need::Cancellation
                }
            }
            SeriesNeed::None => Need::Closed,
            SeriesNeed::Cancellation => Need::Cancellation,
            SeriesNeed::IllConditioned => Need::IllConditioned,
        }
    }
}

/// The rod as the formulations after the closed form see it: a, the closed form in dual
/// numbers where the question built one, and what it said.
#[derive(Clone, Copy)]
pub(crate) struct Rod<'c> {
    /// The parameters a = (a3, a4, a5).
    pub(crate) a: &'c PlanarParams,
    /// The closed form in dual numbers (None without one, or where the question built it in f64).
    pub(crate) closed: Option<&'c Closed<Dual3>>,
    /// What the closed form said at t = 1.
    pub(crate) need: Need,
    /// The closed form's case (docs/math.md §2), where one was built.
    pub(crate) case: Option<Case>,
    /// Whether a series standing in for the closed form must be the double-double one
    /// ([`Closed::needs_precise_series`]; false without a closed form).
    pub(crate) precise_series: bool,
}

impl<'c> Rod<'c> {
    /// The rod a without a closed form (gently bent, one whose closed form overflowed, or
    /// before the closed form is asked).
    #[inline]
    pub(crate) fn without_closed(a: &'c PlanarParams) -> Self {
        Rod {
            a,
            closed: None,
            need: Need::NoClosedForm,
            case: None,
            precise_series: false,
        }
    }

    /// The rod of a built closed form, for the rows after it (the closed form declined).
    pub(crate) fn after<T: crate::scalar::Real>(
        closed_form: &ClosedForm<'c, T>,
        closed: Option<&'c Closed<Dual3>>,
    ) -> Self {
        Rod {
            a: closed_form.a,
            closed,
            need: closed_form.need(),
            case: Some(closed_form.c.case),
            precise_series: closed_form.c.needs_precise_series(),
        }
    }

    /// The case the shape reports (the closed form's, else classified from a).
    pub(crate) fn case(&self) -> Case {
        self.case.unwrap_or_else(|| case_without_closed(self.a))
    }

    /// A shape on the series (or the expansion where the series cannot run), with `tip`.
    pub(crate) fn series_shape(
        &self,
        tip: impl FnOnce(&Backend) -> Result<[f64; 3], RodError>,
    ) -> Result<PlanarRod, RodError> {
        let backend = series_backend(self.a)?;
        let tip = tip(&backend)?;
        PlanarRod::from_parts(self.a, self.case(), backend, tip)
    }

    /// What the closed form says of J(t) ([`Need::at`]; without one, [`Need::NoClosedForm`]).
    pub(crate) fn need_at(&self, t: f64) -> Need {
        match self.closed {
            Some(c) if t < 1.0 => Need::at(c, t),
            _ => self.need,
        }
    }
}

/// The tip as a pose, refused where it is not finite.
pub(crate) fn finite_tip([x, y, th]: [f64; 3]) -> Result<PlanarPose, RodError> {
    let tip = PlanarPose::new(x, y, th);
    if tip.is_finite() {
        Ok(tip)
    } else {
        Err(crate::planar::closed::overflow())
    }
}

/// An evaluation whose every part is at full accuracy.
pub(crate) fn full_accuracy(
    tip: PlanarPose,
    jacobian: PlanarJacobian,
    energy: f64,
    stability: StabilityReport,
) -> Evaluation {
    Evaluation {
        tip,
        jacobian,
        energy,
        stability,
        full_accuracy: true,
    }
}

/// The evaluation with the stability verdict a theorem gives where one applies
/// (`stability::with_theorem`).
pub(crate) fn with_theorem(
    e: Evaluation,
    theorem: impl FnOnce() -> Option<StabilityVerdict>,
) -> Evaluation {
    Evaluation {
        stability: super::stability::with_theorem(e.stability, theorem),
        ..e
    }
}
