//! Planar rods with weight: a cable in a vertical plane, held by two grippers.
//!
//! Model (unit rod, unit bending stiffness, base at the identity): the dimensionless weight
//! w = ρ g A L³ / EI ≥ 0 acts along the unit direction ĝ of gravity in the base frame. The
//! parameters keep their meaning, a = (a3, a4, a5) = (moment, internal force) at the base; the
//! internal force along the rod is n(t) = (a4, a5) − w t ĝ (force balance n' = −w ĝ), and the
//! moment balance gives
//!
//! κ' = n_x(t) sin θ − n_y(t) cos θ, θ' = κ, x' = cos θ, y' = sin θ, κ(0) = a3,
//!
//! the weightless equation (docs/math.md §1) with (a4, a5) replaced by n(t). The tip gripper
//! carries n(1) = n(0) − w ĝ. Energy: the elastic ½∫κ² plus the potential w ∫(−ĝ · r) dt
//! (zero at the base); [`HeavyEvaluation::energy`] is their sum.
//!
//! Without weight (w = 0) every function here is the weightless closed form's
//! ([`crate::planar`]), bit for bit. With weight the rod and its variational equations are
//! integrated by Taylor series (`series`: polynomial recurrences, dense output), and the
//! stability test scans det J(t) on the series' polynomials (`scan`).

// `!(x > y)` comparisons deliberately reject NaN; index loops mirror the formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod cable;
pub mod cable_search;
pub mod cable_tree;
pub mod catenary;
pub mod held;
mod model;
pub(crate) mod scan;
pub(crate) mod series;

pub use model::{carry, HeavyPlanar};

use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};
use serde::{Deserialize, Serialize};
use series::{Problem, Stop};

/// Largest accepted dimensionless weight w (a 1 m USB cable is ~2,000).
pub const MAX_WEIGHT: f64 = 1e4;
/// Largest accepted |a_i|: beyond it the series would need more than its step budget.
pub const MAX_PARAM: f64 = 1e5;

/// Gravity acting on a planar rod: the dimensionless weight w = ρgAL³/EI and the direction of
/// gravity in the base gripper's frame (unit, in the rod's plane).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gravity {
    weight: f64,
    direction: [f64; 2],
}

impl Default for Gravity {
    fn default() -> Self {
        Self::NONE
    }
}

impl Gravity {
    /// No weight: the weightless rod (gravity pointing along −y, irrelevant).
    pub const NONE: Gravity = Gravity {
        weight: 0.0,
        direction: [0.0, -1.0],
    };

    /// Weight `weight` ∈ [0, [`MAX_WEIGHT`]] along `direction` (any non-zero finite vector
    /// of the base frame's plane; normalised here).
    ///
    /// ```
    /// use rod_ig_core::planar::heavy::Gravity;
    /// let g = Gravity::new(50.0, [0.0, -9.81]).unwrap();
    /// assert_eq!(g.direction(), [0.0, -1.0]);
    /// assert!(Gravity::new(-1.0, [0.0, -1.0]).is_err());
    /// assert!(Gravity::new(1.0, [0.0, 0.0]).is_err());
    /// ```
    pub fn new(weight: f64, direction: [f64; 2]) -> Result<Self, RodError> {
        RodError::check_finite("weight", &[weight])?;
        RodError::check_finite("gravity", &direction)?;
        if !(0.0..=MAX_WEIGHT).contains(&weight) {
            return Err(RodError::OutOfDomain(format!(
                "weight must be in [0, {MAX_WEIGHT:e}] (got {weight})"
            )));
        }
        let norm = direction[0].hypot(direction[1]);
        if !(norm > 1e-300) || !norm.is_finite() {
            return Err(RodError::OutOfDomain(
                "gravity must be a non-zero vector".into(),
            ));
        }
        Ok(Self {
            weight,
            direction: [direction[0] / norm, direction[1] / norm],
        })
    }

    /// The gravity whose load per unit length is w ĝ = `load` (direction `fallback` when the
    /// load is zero).
    pub fn from_load(load: [f64; 2], fallback: [f64; 2]) -> Result<Self, RodError> {
        let w = load[0].hypot(load[1]);
        if w == 0.0 {
            return Self::new(0.0, fallback);
        }
        Self::new(w, load)
    }

    /// The dimensionless weight w.
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// The unit direction ĝ of gravity in the base frame.
    pub fn direction(&self) -> [f64; 2] {
        self.direction
    }

    /// True when w = 0.
    pub fn is_weightless(&self) -> bool {
        self.weight == 0.0
    }

    /// The same direction with another weight (continuation in w).
    pub fn with_weight(&self, weight: f64) -> Result<Self, RodError> {
        Self::new(weight, self.direction)
    }

    /// The weight per unit length w ĝ.
    pub fn load(&self) -> [f64; 2] {
        [
            self.weight * self.direction[0],
            self.weight * self.direction[1],
        ]
    }

    /// The internal force at the tip, n(1) = (a4, a5) − w ĝ: what the tip gripper holds.
    pub fn tip_force(&self, a: &PlanarParams) -> [f64; 2] {
        let l = self.load();
        [a[1] - l[0], a[2] - l[1]]
    }

    fn problem(&self, a: &PlanarParams) -> Problem {
        Problem {
            a: [a[0], a[1], a[2]],
            load: self.load(),
            direction: self.direction,
        }
    }
}

/// Tip, J(1, a), energies and stability of a heavy rod.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeavyEvaluation {
    /// q(1) = (x, y, θ), θ unwrapped.
    pub tip: PlanarPose,
    /// J(1, a) = ∂q(1)/∂a, rows (x, y, θ).
    pub jacobian: PlanarJacobian,
    /// Total energy: elastic + gravitational, w ∫(−ĝ · r) dt.
    pub energy: f64,
    /// Elastic energy ½∫κ².
    pub elastic_energy: f64,
    /// Stability verdict and margin (`scan`; for a long cable a solver returned, the second
    /// variation: [`cable::SecondVariation`]).
    pub stability: StabilityReport,
    /// ‖J(1, a)‖∞ · max(1, ‖a‖∞): how much a relative rounding of a moves the tip. The tip of
    /// an f64 `a` is uncertain by about `condition` × 1.1e-16; above w = 200 a condition
    /// beyond [`MAX_TRUSTED_CONDITION`] makes the verdict `uncertain`, unless the rod is one a
    /// solver returned, evaluated from its node states ([`cable_search::recall`]).
    pub condition: f64,
}

/// Largest `condition` at which a single-shooting evaluation is trusted (tip to ~1e-7).
pub const MAX_TRUSTED_CONDITION: f64 = 1e9;

fn condition_of(a: &PlanarParams, j: &PlanarJacobian) -> f64 {
    j.abs().row_sum().max() * a.amax().max(1.0)
}

/// The evaluation of a long cable a solver returned, from its node states.
fn evaluate_cable(c: &cable::Cable) -> Result<HeavyEvaluation, RodError> {
    let (energy, elastic_energy) = c.energies()?;
    let sv = c.second_variation()?;
    let jacobian = c.jacobian()?;
    Ok(HeavyEvaluation {
        tip: c.tip()?,
        jacobian,
        energy,
        elastic_energy,
        stability: StabilityReport {
            stable: sv.stable(),
            margin: sv.normalised(),
            first_conjugate_t: None,
            uncertain: sv.uncertain(),
        },
        condition: condition_of(&c.params(), &jacobian),
    })
}

fn recalled(a: &PlanarParams, g: &Gravity) -> Option<cable::Cable> {
    if g.weight() > cable_search::LONG_CABLE_WEIGHT {
        cable_search::recall(a, g)
    } else {
        None
    }
}

fn check_params(a: &PlanarParams) -> Result<(), RodError> {
    RodError::check_finite("a", a.as_slice())?;
    if let Some(v) = a.iter().find(|v| v.abs() > MAX_PARAM) {
        return Err(RodError::OutOfDomain(format!(
            "|a_i| <= {MAX_PARAM:e} is required with weight (got {v})"
        )));
    }
    Ok(())
}

fn stop_error(s: Stop) -> RodError {
    match s {
        Stop::NonFinite { t } => RodError::Overflow(format!("the heavy rod's state at t = {t}")),
        Stop::Budget { t } => RodError::Integration(format!(
            "the heavy rod needs more than {} series steps (stopped at t = {t})",
            series::MAX_STEPS
        )),
        Stop::Deadline { t } => RodError::Deadline { t },
    }
}

fn jacobian_of(s: &series::State) -> PlanarJacobian {
    let mut j = PlanarJacobian::zeros();
    for c in 0..3 {
        j[(0, c)] = s.var[c][2];
        j[(1, c)] = s.var[c][3];
        j[(2, c)] = s.var[c][0];
    }
    j
}

/// Tip pose q(1) of the heavy rod (w = 0: [`crate::planar::entry::tip`]).
pub fn tip(a: &PlanarParams, g: &Gravity) -> Result<PlanarPose, RodError> {
    if g.is_weightless() {
        return crate::planar::entry::tip(a);
    }
    check_params(a)?;
    if let Some(c) = recalled(a, g) {
        return c.tip();
    }
    let end = series::integrate(&g.problem(a), false, |_| true).map_err(stop_error)?;
    Ok(PlanarPose::new(end.x, end.y, end.theta))
}

/// Tip pose q(1) and J(1, a) (w = 0: [`crate::planar::entry::tip_and_jacobian`]).
pub fn tip_and_jacobian(
    a: &PlanarParams,
    g: &Gravity,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    if g.is_weightless() {
        return crate::planar::entry::tip_and_jacobian(a);
    }
    check_params(a)?;
    if let Some(c) = recalled(a, g) {
        return Ok((c.tip()?, c.jacobian()?));
    }
    let end = series::integrate(&g.problem(a), true, |_| true).map_err(stop_error)?;
    Ok((PlanarPose::new(end.x, end.y, end.theta), jacobian_of(&end)))
}

/// Pose q(t) and J(t, a) for t ∈ [0, 1] (w = 0: [`crate::planar::entry::pose_and_jacobian`]).
pub fn pose_and_jacobian(
    a: &PlanarParams,
    g: &Gravity,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    if g.is_weightless() {
        return crate::planar::entry::pose_and_jacobian(a, t);
    }
    check_params(a)?;
    RodError::check_finite("t", &[t])?;
    if !(0.0..=1.0).contains(&t) {
        return Err(RodError::OutOfDomain(format!("t = {t} is outside [0, 1]")));
    }
    let mut at = None;
    let end = series::integrate(&g.problem(a), true, |s| {
        if t <= s.t0 + s.h {
            at = Some(s.state_at(t - s.t0));
            return false;
        }
        true
    })
    .map_err(stop_error)?;
    let s = at.unwrap_or(end);
    Ok((PlanarPose::new(s.x, s.y, s.theta), jacobian_of(&s)))
}

/// `samples` poses at t_i = i/(samples − 1), base to tip (w = 0:
/// [`crate::planar::shape::PlanarRod::shape`]). One integration; each pose is a Horner evaluation of
/// the step's polynomials.
pub fn shape(a: &PlanarParams, g: &Gravity, samples: usize) -> Result<Vec<PlanarPose>, RodError> {
    if g.is_weightless() {
        return Ok(crate::planar::shape::PlanarRod::new(a)?.shape(samples));
    }
    check_params(a)?;
    if let Some(c) = recalled(a, g) {
        return c.shape(samples);
    }
    let mut out = Vec::new();
    out.try_reserve_exact(samples)
        .map_err(|_| RodError::OutOfDomain(format!("{samples} samples do not fit in memory")))?;
    if samples == 0 {
        return Ok(out);
    }
    let t_of = |i: usize| {
        if samples == 1 {
            0.0
        } else {
            i as f64 / (samples - 1) as f64
        }
    };
    series::integrate(&g.problem(a), false, |s| {
        let end = s.t0 + s.h;
        while out.len() < samples && (t_of(out.len()) <= end || end >= 1.0) {
            let [x, y, th] = s.pose_at((t_of(out.len()) - s.t0).clamp(0.0, s.h));
            out.push(PlanarPose::new(x, y, th));
        }
        out.len() < samples
    })
    .map_err(stop_error)?;
    Ok(out)
}

/// The wrenches the rod exerts on its two grippers ([`crate::wrench`]: each in its gripper's
/// frame, as a wrist sensor reads it). Without weight κ(1) comes from the tip by the moment
/// balance; with weight from the integration (or a long cable's node states).
pub fn wrenches(
    a: &PlanarParams,
    g: &Gravity,
) -> Result<crate::wrench::GripperWrenches<crate::wrench::PlanarWrench>, RodError> {
    let (tip, kappa) = if g.is_weightless() {
        let tip = crate::planar::entry::tip(a)?;
        (tip, crate::wrench::weightless_tip_curvature(a, &tip))
    } else {
        check_params(a)?;
        if let Some(c) = recalled(a, g) {
            (c.tip()?, c.tip_curvature()?)
        } else {
            let end = series::integrate(&g.problem(a), false, |_| true).map_err(stop_error)?;
            (PlanarPose::new(end.x, end.y, end.theta), end.kappa)
        }
    };
    Ok(crate::wrench::planar(a, &tip, g.tip_force(a), kappa))
}

/// Stability of the heavy rod (`scan`; w = 0: [`crate::planar::stability`]).
pub fn stability(a: &PlanarParams, g: &Gravity) -> Result<StabilityReport, RodError> {
    Ok(evaluate(a, g)?.stability)
}

/// (total, elastic) energy (w = 0: both [`crate::planar::entry::energy`]).
pub fn energy(a: &PlanarParams, g: &Gravity) -> Result<(f64, f64), RodError> {
    if g.is_weightless() {
        let e = crate::planar::entry::energy(a)?;
        return Ok((e, e));
    }
    check_params(a)?;
    if let Some(c) = recalled(a, g) {
        return c.energies();
    }
    let end = series::integrate(&g.problem(a), false, |_| true).map_err(stop_error)?;
    Ok((end.elastic + g.weight * end.potential, end.elastic))
}

/// Tip, J(1, a), energies and stability in one integration (w = 0: [`crate::planar::entry::evaluate`]).
///
/// ```
/// use rod_ig_core::planar::heavy::{self, Gravity};
/// use rod_ig_core::PlanarParams;
/// // Without moment or force at its base, a heavy rod clamped level curls down under its weight:
/// // its tip is below the base, and so is its potential energy.
/// let g = Gravity::new(5.0, [0.0, -1.0]).unwrap();
/// let e = heavy::evaluate(&PlanarParams::new(0.0, 0.0, 0.0), &g).unwrap();
/// assert!(e.tip.y < 0.0 && e.energy < e.elastic_energy);
/// assert_eq!(g.tip_force(&PlanarParams::zeros()), [0.0, 5.0]); // the tip gripper holds it up
/// ```
pub fn evaluate(a: &PlanarParams, g: &Gravity) -> Result<HeavyEvaluation, RodError> {
    if g.is_weightless() {
        let e = crate::planar::entry::evaluate(a)?;
        return Ok(HeavyEvaluation {
            tip: e.tip,
            jacobian: e.jacobian,
            energy: e.energy,
            elastic_energy: e.energy,
            stability: e.stability,
            condition: condition_of(a, &e.jacobian),
        });
    }
    check_params(a)?;
    if let Some(c) = recalled(a, g) {
        return evaluate_cable(&c);
    }
    let p = g.problem(a);
    let mut scan = scan::Scan::new(a[0], a[2], p.load[1]);
    let end = series::integrate(&p, true, |s| {
        if !scan.degenerate() {
            scan.push(s);
        }
        true
    })
    .map_err(stop_error)?;
    let jacobian = jacobian_of(&end);
    let condition = condition_of(a, &jacobian);
    let mut stability = scan.report();
    if g.weight() > cable_search::LONG_CABLE_WEIGHT && !(condition <= MAX_TRUSTED_CONDITION) {
        // The tip of this f64 `a` is not determined to the accuracy of the verdict.
        stability.stable = false;
        stability.uncertain = true;
    }
    Ok(HeavyEvaluation {
        tip: PlanarPose::new(end.x, end.y, end.theta),
        jacobian,
        energy: end.elastic + g.weight * end.potential,
        elastic_energy: end.elastic,
        stability,
        condition,
    })
}
