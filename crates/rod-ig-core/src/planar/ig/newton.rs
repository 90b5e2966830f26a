//! Building blocks of the planar Newton iterations (paper §3.1, eq. 3.1: the step solves
//! J(1, a) p = −f(a), f(a) = Υ(a) − b): the 3×3 solve, one evaluated iterate, its verification
//! at full accuracy. The paper's Newton itself is written once for every model in
//! `crate::solver::newton`.

use super::Solution;
use crate::planar::model;
use crate::planar::model::Precision;

use crate::solver::{Verified, Work};
use crate::{PlanarJacobian, PlanarParams, PlanarPose};
use nalgebra::Vector3;

/// One evaluated iterate.
pub(crate) struct Eval {
    pub tip: PlanarPose,
    pub jac: PlanarJacobian,
    pub f: Vector3<f64>,
    pub pos_err: f64,
    pub ang_err: f64,
    pub norm: f64,
    /// ½∫κ² when the evaluation computed it (`verify_with_stability`).
    pub energy: Option<f64>,
}

pub(crate) fn eval(a: &PlanarParams, target: &PlanarPose, precision: Precision) -> Option<Eval> {
    eval_from(
        model::tip_and_jacobian_for_iteration(a, precision).ok()?,
        target,
    )
}

/// The converged iterate `a` re-evaluated at full accuracy (iterations may use a cheaper
/// evaluation on ill-conditioned rods, or the tip alone), and its stability test, from one
/// evaluation (`planar::evaluate`: one closed form or one dense series serves the tip, J, the
/// energy and the scan of det J(t), where separate calls built it three times). None when the
/// re-evaluated point misses the tolerance or cannot be evaluated.
pub(crate) fn verify_with_stability(
    a: &PlanarParams,
    target: &PlanarPose,
    tolerance: f64,
) -> Option<(Eval, crate::StabilityReport)> {
    let ev = model::evaluate_precise(a).ok()?;
    let mut e = eval_from((ev.tip, ev.jacobian), target)?;
    e.energy = Some(ev.energy);
    (e.pos_err <= tolerance && e.ang_err <= tolerance).then_some((e, ev.stability))
}

/// The iterate `a` evaluated by its tip alone (`planar::tip_by_closed_form`), with `jac` the J
/// of an earlier iterate: a chord step's trial (`solver::globalised`). None where the closed
/// form needs a series.
pub(crate) fn eval_residual(
    a: &PlanarParams,
    jac: &PlanarJacobian,
    target: &PlanarPose,
) -> Option<Eval> {
    eval_from((crate::planar::entry::tip_by_closed_form(a)?, *jac), target)
}

fn eval_from((tip, jac): (PlanarPose, PlanarJacobian), target: &PlanarPose) -> Option<Eval> {
    let f = model::residual(&tip, target);
    if !(f.iter().all(|v| v.is_finite()) && jac.iter().all(|v| v.is_finite())) {
        return None;
    }
    let pos_err = crate::scalar::fast_hypot(f[0], f[1]);
    let ang_err = f[2].abs();
    Some(Eval {
        tip,
        jac,
        f,
        pos_err,
        ang_err,
        norm: f.norm(),
        energy: None,
    })
}

pub(crate) fn make_solution(
    a: &PlanarParams,
    e: &Eval,
    stable: bool,
    margin: f64,
    iterations: u32,
) -> Solution {
    // The identity cancels on nearly straight rods under force: the evaluation's energy
    // (integrated where needed) when there is one.
    let energy = e
        .energy
        .or_else(|| crate::planar::entry::energy(a).ok())
        .unwrap_or_else(|| model::energy_from_tip(a, &e.tip));
    let verified = Verified {
        tip: e.tip,
        errors: (e.pos_err, e.ang_err),
        energy,
        margin,
    };
    let work = Work {
        iterations,
        evaluations: iterations + 1,
        starts: 1,
    };
    Solution {
        stable,
        ..Solution::new(*a, verified, work)
    }
}
