//! The 3-D rod with weight: the reduced formulation of the weightless 3-D rod (the world
//! wrench recovered from the pose) with gravity.
//!
//! With the load w ĝ per unit length (ĝ unit, base frame), the world force and moment are no
//! longer conserved but known in closed form along the rod:
//! n(t) = a_f − t w ĝ, and the world moment about the base M(t) = a_m − P(t) × w ĝ with
//! P(t) = ∫₀ᵗ p (from M' = p × n' = −p × w ĝ). So the body wrench is
//! f = Rᵀ n(t), m = Rᵀ (M(t) − p × n(t)), and the integrated state gains P (3 values). The
//! variations gain one term, δm ∋ −Rᵀ (δP × w ĝ), with δP' = δp = R η_v (world frame, 3
//! values per column). The potential energy w ∫(−ĝ · p) = −w ĝ · P(1) comes for free.
//!
//! Stability: det J(t) > 0 on the rule's grid t = i/2000 ∈ [0.02, 1] (docs/math.md §10, the grid of
//! `shared/oracle/gravity_public.jsonl`'s 3-D lines), by dense output at rtol 1e-10.

use super::heavy_ode::{rhs, NB};
use super::{SpatialJacobian, SpatialParams, SpatialPose, Stiffness};
use crate::ode::{solve, solve_dense, OdeOptions};
use crate::{RodError, StabilityReport};
use std::ops::ControlFlow;

pub use super::heavy_ode::Gravity3;

/// Base + η (6 rows × 6 columns, row-major) + δP (3 rows × 6 columns, row-major).
const NV: usize = NB + 36 + 18;
/// Relative tolerance of every integration here (tip ≤ 1e-9, J ≤ 1e-6 relative).
pub const HEAVY_RTOL: f64 = 1e-10;

fn initial() -> [f64; NV] {
    let mut s = [0.0; NV];
    s[0] = 1.0;
    s
}

fn jac(s: &[f64; NV]) -> SpatialJacobian {
    SpatialJacobian::from_fn(|r, c| s[NB + 6 * r + c])
}

fn pose(s: &[f64; NV]) -> SpatialPose {
    super::pose_from_parts([s[0], s[1], s[2], s[3]], [s[4], s[5], s[6]])
}

fn options(a: &SpatialParams) -> OdeOptions {
    super::options_for(a, HEAVY_RTOL, super::default_atol(HEAVY_RTOL))
}

fn check(a: &SpatialParams, k: &Stiffness) -> Result<(), RodError> {
    super::check_params(a, k)
}

/// Tip, J(1, a), energies and stability of a heavy 3-D rod.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeavyEvaluation3d {
    /// q(1).
    pub tip: SpatialPose,
    /// J(1, a) (body twists, rows ω, v).
    pub jacobian: SpatialJacobian,
    /// Elastic + gravitational energy.
    pub energy: f64,
    /// Elastic energy.
    pub elastic_energy: f64,
    /// det J(t) > 0 on the grid (module docs); margin min over t ≥ 0.05 of
    /// det J(t) / [`super::det_leading_term`] (a normalisation, not a distance).
    pub stability: StabilityReport,
    /// ‖J(1, a)‖∞ · max(1, ‖a‖∞): how much a relative rounding of a moves the tip (as the
    /// planar rod's). Above w = 200 a condition beyond
    /// [`crate::planar::heavy::MAX_TRUSTED_CONDITION`] makes the verdict `uncertain`, unless
    /// the rod is one a 3-D solver returned, evaluated from its node states
    /// ([`super::cable::recall`]).
    pub condition: f64,
}

/// Tip and J(1, a) of the heavy 3-D rod (w = 0: the weightless rod's, [`super::tip_and_jacobian`]
/// at the production tolerance).
pub fn tip_and_jacobian(
    a: &SpatialParams,
    k: &Stiffness,
    g: &Gravity3,
) -> Result<(SpatialPose, SpatialJacobian), RodError> {
    if g.is_weightless() {
        // No weight: the weightless rod's answer, bit for bit (issue 51, item 5).
        return super::tip_and_jacobian(a, k, super::PRODUCTION_RTOL);
    }
    check(a, k)?;
    if g.weight() > crate::planar::heavy::cable_search::LONG_CABLE_WEIGHT {
        // A long cable a solver returned: from its node states (as `evaluate`).
        if let Some(cable) = super::cable::recall(a, k, g) {
            if let Some(j) = cable.tip_jacobian()? {
                return Ok((cable.tip()?, j));
            }
        }
    }
    let (ci, av, load) = (k.inv(), super::reduced::params(a), g.load());
    let (s, _) = solve(
        |t, s, ds| rhs::<NV, 6>(&ci, &av, load, t, s, ds, true),
        0.0,
        initial(),
        1.0,
        &options(a),
    )?;
    super::finite(&s)?;
    Ok((pose(&s), jac(&s)))
}

/// Tip, J, energies and the stability verdict on the grid (module docs).
pub fn evaluate(
    a: &SpatialParams,
    k: &Stiffness,
    g: &Gravity3,
) -> Result<HeavyEvaluation3d, RodError> {
    if g.is_weightless() {
        // No weight: the weightless rod's answer, bit for bit (issue 51, item 5).
        let e = super::evaluate(a, k, &super::StabilityOptions::production())?;
        return Ok(HeavyEvaluation3d {
            tip: e.tip,
            jacobian: e.jacobian,
            energy: e.energy,
            elastic_energy: e.energy,
            stability: e.stability,
            condition: condition_of(a, &e.jacobian),
        });
    }
    check(a, k)?;
    let long = g.weight() > crate::planar::heavy::cable_search::LONG_CABLE_WEIGHT;
    if long {
        // A long cable a solver returned: from its node states, whatever single shooting from
        // its f64 `a` would say.
        if let Some(cable) = super::cable::recall(a, k, g) {
            return of_cable(&cable, a, k, g);
        }
    }
    let (ci, av, load) = (k.inv(), super::reduced::params(a), g.load());
    let grid: Vec<f64> = (40..=2000).map(|i| f64::from(i) / 2000.0).collect();
    let mut last = initial();
    let mut scan = crate::conjugate::Stream::new();
    let mut finite = true;
    solve_dense(
        |t, s, ds| rhs::<NV, 6>(&ci, &av, load, t, s, ds, true),
        0.0,
        initial(),
        &grid,
        &options(a),
        |_, t, s| {
            let det = jac(s).determinant();
            finite &= det.is_finite();
            let _ = scan.sample_det(t, det, super::det_leading_term(a, t));
            last = *s;
            ControlFlow::Continue(())
        },
    )?;
    if !finite {
        return Err(RodError::Overflow(
            "non-finite Jacobian of the heavy 3-D rod".into(),
        ));
    }
    super::finite(&last)?;
    let potential = -(load[0] * last[8] + load[1] * last[9] + load[2] * last[10]);
    let degenerate = a[1] == 0.0 && a[2] == 0.0 && a[4] == 0.0 && a[5] == 0.0 && {
        // A straight rod along gravity stays straight: det J ≡ 0.
        let d = g.direction();
        g.is_weightless() || (d[1] == 0.0 && d[2] == 0.0)
    };
    let jacobian = jac(&last);
    let condition = condition_of(a, &jacobian);
    let undecided = crate::conjugate::undecided();
    let mut e = HeavyEvaluation3d {
        tip: pose(&last),
        jacobian,
        condition,
        energy: last[7] + potential,
        elastic_energy: last[7],
        stability: if degenerate {
            undecided
        } else {
            scan.exact_report()
        },
    };
    if long && !(condition <= crate::planar::heavy::MAX_TRUSTED_CONDITION) {
        // The tip of this f64 `a` is not determined to the accuracy of the verdict.
        e.stability = undecided;
    }
    Ok(e)
}

/// The condition figure of an evaluation, ‖J(1)‖∞ · max(1, ‖a‖∞): the tip of an f64 `a` is
/// uncertain by about this × 1.1e-16 ([`HeavyEvaluation3d::condition`]).
pub fn condition_of(a: &SpatialParams, j: &SpatialJacobian) -> f64 {
    j.abs().row_sum().max() * a.amax().max(1.0)
}

/// The evaluation of a long cable a 3-D solver returned, from its node states. Its J is single
/// shooting's (the true, ill-conditioned J(1, a); NaN where that integration overflows).
fn of_cable(
    cable: &super::cable::SpatialCable,
    a: &SpatialParams,
    k: &Stiffness,
    g: &Gravity3,
) -> Result<HeavyEvaluation3d, RodError> {
    let (ci, av, load) = (k.inv(), super::reduced::params(a), g.load());
    let jacobian = solve(
        |t, s, ds| rhs::<NV, 6>(&ci, &av, load, t, s, ds, true),
        0.0,
        initial(),
        1.0,
        &options(a),
    )
    .map(|(s, _)| jac(&s))
    .unwrap_or_else(|_| SpatialJacobian::from_element(f64::NAN));
    let (elastic_energy, energy) = cable.energies()?;
    Ok(HeavyEvaluation3d {
        tip: cable.tip()?,
        jacobian,
        energy,
        elastic_energy,
        stability: cable.stability()?,
        condition: condition_of(a, &jacobian),
    })
}

/// The wrenches the rod exerts on its two grippers ([`crate::wrench`]; each in its gripper's
/// frame). The world wrench at the tip is n(1) = a_f − w ĝ and, about the base,
/// M(1) = a_m − P(1) × w ĝ (module docs); without weight, a_f and a_m.
pub fn wrenches(
    a: &SpatialParams,
    k: &Stiffness,
    g: &Gravity3,
) -> Result<crate::wrench::GripperWrenches<crate::wrench::SpatialWrench>, RodError> {
    use nalgebra::Vector3;
    let (am, af) = (
        Vector3::new(a[0], a[1], a[2]),
        Vector3::new(a[3], a[4], a[5]),
    );
    if g.is_weightless() {
        let tip = super::tip(a, k, super::PRODUCTION_RTOL)?;
        return Ok(crate::wrench::spatial(a, &tip, af, am));
    }
    check(a, k)?;
    let load = Vector3::from(g.load());
    // A long cable a solver returned: its tip and P(1) from its node states.
    if let Some(cable) = super::cable::recall(a, k, g) {
        let (tip, arm) = cable.tip_and_moment_arm()?;
        return Ok(crate::wrench::spatial(
            a,
            &tip,
            af - load,
            am - arm.cross(&load),
        ));
    }
    let (ci, av) = (k.inv(), super::reduced::params(a));
    let (s, _) = solve(
        |t, s, ds| rhs::<NV, 6>(&ci, &av, g.load(), t, s, ds, false),
        0.0,
        initial(),
        1.0,
        &options(a),
    )?;
    super::finite(&s)?;
    let moment = am - Vector3::new(s[8], s[9], s[10]).cross(&load);
    Ok(crate::wrench::spatial(a, &pose(&s), af - load, moment))
}

/// `samples` poses of the heavy 3-D rod from the base to the tip.
pub fn shape(
    a: &SpatialParams,
    k: &Stiffness,
    g: &Gravity3,
    samples: usize,
) -> Result<Vec<SpatialPose>, RodError> {
    check(a, k)?;
    let (ci, av, load) = (k.inv(), super::reduced::params(a), g.load());
    let ts: Vec<f64> = (0..samples)
        .map(|i| {
            if samples < 2 {
                0.0
            } else {
                i as f64 / (samples - 1) as f64
            }
        })
        .collect();
    if g.weight() > crate::planar::heavy::cable_search::LONG_CABLE_WEIGHT {
        // A long cable a solver returned: sampled from its node states.
        if let Some(cable) = super::cable::recall(a, k, g) {
            return cable.poses_at(&ts);
        }
    }
    let mut out = Vec::with_capacity(samples);
    solve_dense(
        |t, s, ds| rhs::<NV, 6>(&ci, &av, load, t, s, ds, false),
        0.0,
        initial(),
        &ts,
        &options(a),
        |_, _, s| {
            out.push(pose(s));
            ControlFlow::Continue(())
        },
    )?;
    Ok(out)
}
