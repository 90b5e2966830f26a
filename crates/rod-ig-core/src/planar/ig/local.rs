//! Globalised Newton from one start (the robust solver's inner loop): the iteration of
//! [`crate::solver::globalised`] (Newton direction p = −J(1, a)⁻¹ f(a), paper eq. 3.1,
//! backtracking on the merit ‖f‖, Levenberg–Marquardt steps when it fails), with two planar
//! safeguards:
//! - a trust box on the step in parameter space (|Δa3| ≤ 4, |Δa4|, |Δa5| ≤ 40), so that one
//!   step cannot jump across several solution branches;
//! - a trial is rejected when det J(1, a) ≤ 0. Along a continuous path in a, a conjugate point
//!   can only enter (0, 1] through t = 1 (the index of the second variation changes only when
//!   det J(1, a) = 0), so the sign of det J(1, a) — free with the Jacobian — is the cheap guard
//!   that keeps short steps inside the stable set A_stable (paper §3.1). The full test of
//!   docs/math.md §5 is applied to the converged point by the caller.
//!
//! The weighted scaling a ↦ (s a3, s² a4, s² a5) maps the rod on [0, s] to the unit rod, so
//! det J(t, a(s)) has the sign of det J(s t, a): scaling by s < t₁ (the first conjugate time)
//! brings any a into the stable set ([`pull_into_stable`]).

use super::newton::{eval, eval_residual, Eval};
use super::scan;
use crate::planar::model::{solve3, Precision};

use crate::solver::globalised::{self, Iterate, Problem, Settings};
use crate::solver::{emit, Event, IgError};
use crate::{PlanarParams, PlanarPose};
use nalgebra::{Matrix3, Vector3};

/// Outcome of one local solve.
pub(crate) struct Local {
    /// Converged point and its errors (not yet checked by the full stability test).
    pub found: Option<(PlanarParams, TipErrors)>,
    /// Accepted Newton steps.
    pub iterations: u32,
    /// Evaluations of Υ and J.
    pub evaluations: u32,
    /// ‖f‖ at the last accepted iterate.
    pub residual: f64,
    /// Last accepted iterate.
    pub last_a: PlanarParams,
    /// Why it stopped without converging.
    pub stop: Stop,
    /// Chord steps that led to the last iterate (`solver::globalised`): its J is then from an
    /// earlier one. Callers use `found`'s point only; the tests read it.
    #[cfg_attr(not(test), allow(dead_code))]
    pub chord_steps: u32,
}

/// Why a local solve stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stop {
    Converged,
    /// Start is non-finite or not in the stable set (det J(1, a0) ≤ 0).
    BadStart,
    /// Backtracking found no acceptable step.
    Stalled,
    MaxIterations,
    /// The solve's deadline passed.
    Deadline,
}

impl Stop {
    /// The error a start that stopped this way reports (through the robust solver's
    /// `NoStableSolution::last`) after `iterations` iterations.
    pub(crate) fn to_error(self, iterations: u32) -> super::IgError {
        use super::IgError;
        match self {
            // A converged point that failed the verification or the full stability test.
            Stop::Converged | Stop::BadStart => IgError::LeftStableSet {
                iteration: iterations,
            },
            Stop::Stalled => IgError::Stalled {
                iteration: iterations,
            },
            Stop::MaxIterations => IgError::MaxIterations { iterations },
            Stop::Deadline => IgError::Deadline {
                iteration: iterations,
            },
        }
    }
}

/// Half-width in a3 of the box a step may move in (trust region of one Newton/LM step). a3 is
/// a moment and a4, a5 forces: the paper's sampling box is |a3| ≤ 2π, |a4|, |a5| ≤ 100, so
/// the box keeps the same ratio of about 1:10 ([`MAX_DA45`]), ~2/3 and ~2/5 of each half-range.
/// An engineering choice, not a derivation: it bounds how far one step can jump across
/// branches while leaving Newton's full step free in the interior of the box.
pub(crate) const MAX_DA3: f64 = 4.0;
/// Half-width in a4 and a5 of the box a step may move in (see [`MAX_DA3`]).
pub(crate) const MAX_DA45: f64 = 40.0;

/// Runs the globalised Newton from `a0` for at most `max_iterations` accepted steps.
pub(crate) fn solve(
    target: &PlanarPose,
    a0: &PlanarParams,
    alpha: f64,
    max_iterations: u32,
    tolerance: f64,
) -> Local {
    solve_predicted(target, a0, None, alpha, max_iterations, tolerance)
}

/// As [`solve`], with an optional predicted first iterate `(a1, r0)`: a Newton step from `a0`
/// computed from an already known J(1, a0) (atlas seed, previous tracking solution), where `r0`
/// is the known (or estimated) ‖f(a0)‖. It is taken when it is in A_stable's det J(1) > 0 side
/// and decreases the residual below `r0`; otherwise the solve starts from `a0`. A taken
/// prediction counts as one iteration.
pub(crate) fn solve_predicted(
    target: &PlanarPose,
    a0: &PlanarParams,
    predicted: Option<(PlanarParams, f64)>,
    alpha: f64,
    max_iterations: u32,
    tolerance: f64,
) -> Local {
    if let Some((a1, r0)) = predicted {
        if max_iterations > 0 {
            if let Some(e1) = eval(&a1, target, Precision::for_start(a0)) {
                if e1.jac.determinant() > 0.0 && e1.norm < (1.0 - 1e-4) * r0 {
                    emit(Event::Iteration {
                        iteration: 1,
                        residual: r0,
                        step: (a1 - a0).norm(),
                        alpha: 1.0,
                    });
                    let precision = Precision::for_start(a0);
                    let mut out = run(
                        target,
                        a1,
                        e1,
                        precision,
                        alpha,
                        max_iterations - 1,
                        tolerance,
                    );
                    out.iterations += 1;
                    out.evaluations += 1;
                    return out;
                }
            }
            let mut out = solve(target, a0, alpha, max_iterations, tolerance);
            out.evaluations += 1;
            return out;
        }
    }
    let out = Local {
        found: None,
        iterations: 0,
        evaluations: 1,
        residual: f64::INFINITY,
        last_a: *a0,
        stop: Stop::BadStart,
        chord_steps: 0,
    };
    let precision = Precision::for_start(a0);
    match eval(a0, target, precision) {
        Some(e) if e.jac.determinant() > 0.0 => {
            let mut out = run(target, *a0, e, precision, alpha, max_iterations, tolerance);
            out.evaluations += 1;
            out
        }
        _ => out,
    }
}

/// One run of the globalised Newton/LM ([`globalised`]) on the planar rod: trials evaluated at
/// the start's precision and rejected where det J(1, a) ≤ 0 (module docs), steps limited to
/// the box (±[`MAX_DA3`], ±[`MAX_DA45`], ±[`MAX_DA45`]).
struct PlanarSteps<'t> {
    target: &'t PlanarPose,
    precision: Precision,
    tolerance: f64,
}

/// What an iterate keeps of its evaluation besides f, ‖f‖ and J: the tip errors the
/// convergence test reads (the whole evaluation, ~160 bytes, was copied with every move of an
/// iterate).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TipErrors {
    /// Position error (rod lengths).
    pub position: f64,
    /// Wrapped angle error (rad).
    pub angle: f64,
}

fn iterate(e: Eval) -> Iterate<3, TipErrors> {
    Iterate {
        f: e.f,
        norm: e.norm,
        jacobian: e.jac,
        data: TipErrors {
            position: e.pos_err,
            angle: e.ang_err,
        },
    }
}

impl Problem<3> for PlanarSteps<'_> {
    type Data = TipErrors;
    const OFFERS_RESIDUAL: bool = true;

    fn evaluate(
        &mut self,
        a: &PlanarParams,
        _from: f64,
    ) -> Result<Option<Iterate<3, TipErrors>>, IgError> {
        Ok(eval(a, self.target, self.precision)
            .filter(|e| e.jac.determinant() > 0.0)
            .map(iterate))
    }

    fn converged(&self, x: &Iterate<3, TipErrors>) -> bool {
        x.data.position <= self.tolerance && x.data.angle <= self.tolerance
    }

    fn step_scale(&self, _a: &PlanarParams, p: &Vector3<f64>) -> f64 {
        (p[0].abs() / MAX_DA3)
            .max(p[1].abs() / MAX_DA45)
            .max(p[2].abs() / MAX_DA45)
    }

    fn solve(&self, m: &Matrix3<f64>, r: &Vector3<f64>) -> Option<Vector3<f64>> {
        solve3(m, r).ok()
    }

    fn evaluate_residual(
        &mut self,
        a: &PlanarParams,
        _from: f64,
        jacobian: &Matrix3<f64>,
    ) -> Result<Option<Iterate<3, TipErrors>>, IgError> {
        Ok(eval_residual(a, jacobian, self.target).map(iterate))
    }
}

/// The iteration proper, from an evaluated start (`evaluations` excludes the start's), every
/// evaluation at the start's `precision`.
fn run(
    target: &PlanarPose,
    a0: PlanarParams,
    e0: Eval,
    precision: Precision,
    alpha: f64,
    max_iterations: u32,
    tolerance: f64,
) -> Local {
    let mut steps = PlanarSteps {
        target,
        precision,
        tolerance,
    };
    let settings = Settings {
        alpha,
        max_iterations,
        max_evaluations: u32::MAX,
    };
    let start_norm = e0.norm;
    match globalised::run(&mut steps, a0, iterate(e0), &settings) {
        Ok(r) => Local {
            stop: match r.stop {
                globalised::Stop::Converged => Stop::Converged,
                globalised::Stop::Stalled => Stop::Stalled,
                globalised::Stop::MaxIterations | globalised::Stop::Budget => Stop::MaxIterations,
                globalised::Stop::Deadline => Stop::Deadline,
            },
            iterations: r.iterations,
            evaluations: r.evaluations,
            residual: r.last.norm,
            last_a: r.a,
            found: (r.stop == globalised::Stop::Converged).then_some((r.a, r.last.data)),
            chord_steps: r.chord_steps,
        },
        // PlanarSteps never returns an error; kept total all the same.
        Err(_) => Local {
            found: None,
            iterations: 0,
            evaluations: 0,
            residual: start_norm,
            last_a: a0,
            stop: Stop::Stalled,
            chord_steps: 0,
        },
    }
}

/// Brings `a` into the stable set by the weighted scaling a ↦ (s a3, s² a4, s² a5) with
/// s = 0.9 t₁, t₁ the first conjugate time of `a` (docs/math.md §5 rule on an RK4 scan).
/// Returns `a` unchanged when it is already stable, `None` when the scan fails.
pub(crate) fn pull_into_stable(a: &PlanarParams) -> Option<PlanarParams> {
    let s = scan::scan(a, scan::steps_for(a, 8.0))?;
    match s.first_conjugate_t {
        None if s.stable => Some(*a),
        Some(t1) => {
            let s = 0.9 * t1;
            Some(PlanarParams::new(s * a[0], s * s * a[1], s * s * a[2]))
        }
        None => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// Newton from a start near a stable rod of the paper's box (its tip the target, the
    /// start 1e-3 away in each parameter: ‖f‖ ~ 1e-3, inside the chord steps' range) ends
    /// on chord steps, and every point reached that way passes the full verification at the
    /// 1e-10 tolerance and the stability test: the residual-only evaluations judge convergence
    /// as full ones do.
    #[test]
    fn chord_steps_end_near_converged_solves_and_pass_verification() {
        let mut rng = SplitMix64::new(23);
        let (mut solved, mut by_chord) = (0, 0);
        for _ in 0..400 {
            let a = PlanarParams::new(
                rng.range(-6.0, 6.0),
                rng.range(-60.0, 60.0),
                rng.range(-60.0, 60.0),
            );
            let Ok(tip) = crate::planar::entry::tip(&a) else {
                continue;
            };
            if !crate::planar::entry::stability(&a).is_ok_and(|s| s.stable) {
                continue;
            }
            let a0 = a + PlanarParams::new(1e-3, -1e-3, 1e-3);
            let r = solve(&tip, &a0, 1.0, 20, 1e-10);
            let Some((found, _)) = r.found else { continue };
            solved += 1;
            by_chord += usize::from(r.chord_steps > 0);
            assert!(
                super::super::newton::verify_with_stability(&found, &tip, 1e-10)
                    .is_some_and(|(_, st)| st.stable),
                "{found:?} for the rod {a:?}: chord steps {}",
                r.chord_steps
            );
        }
        assert!(solved >= 150, "{solved} solves");
        // Residual-only evaluations need the closed form without a series: most box rods.
        assert!(
            by_chord * 10 >= solved * 8,
            "{by_chord} of {solved} ended on chord steps"
        );
    }
}
