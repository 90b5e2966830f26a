//! Closed-form planar Kirchhoff rod (Roussel, Renaud & Taïx 2015, §2.2, with the corrections of
//! `shared/paper/FINDINGS.md`): shape q(t) = (x, y, θ)(t), sensitivity J(t, a) = ∂q(t)/∂a,
//! stability (Bretl & McCarthy: det J(t, a) > 0 on (0, 1]) and elastic energy.
//!
//! Conventions: a = (a3, a4, a5) = μ(0) (base moment and force), unit length and stiffness,
//! base at the identity; θ is unwrapped (θ(t) = ∫₀ᵗ κ); J has rows (x, y, θ) and columns
//! (a3, a4, a5).
//!
//! The closed form is written once, generic over [`crate::scalar::Real`]: in `f64` it gives the
//! pose, in [`crate::scalar::Dual3`] seeded with the identity on a it gives the exact J in the
//! same pass. All cases of FINDINGS §2 are covered: I (λ4 > 0), II (λ4 < 0, via the m > 1
//! transform), III (λ4 = 0 exactly), the circle (a4 = a5 = 0) and the straight rod
//! (a3 = a5 = 0), with a3 = 0 (ε = +1), a5 = 0, small force (m → 0, D form) and the
//! near-separatrix regime (m1 = 1 − m from λ4) handled without cancellation.

mod closed;
mod extended;
pub mod heavy;
pub mod ig;
pub mod model;
mod pendulum;
mod small_angle;
mod stability;
mod taylor;

pub use closed::Case;
use closed::{Closed, SeriesNeed, CLOSED_J_TOLERANCE, SEPARATRIX_M1, SERIES_DD_MAX_ROOT_F};
pub use model::{check_target, PlanarClosedForm, PlanarReference};

use crate::scalar::Dual3;
use crate::{
    PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport, StabilityVerdict,
};
pub(crate) use taylor::{
    pose_jac_from, series_dd, series_dual, series_f64, series_pose_and_jac, SERIES_MAX_STEPS,
};
use taylor::{Gradient, TaylorRod};

/// Rods with ρ = max(|a3|, √‖(a4, a5)‖) up to this value are evaluated by the Taylor series
/// without trying the closed form: one step from 0 to 1 (a few µs), and the closed form's own
/// error estimate ([`Closed::jacobian_rel_error`], which grows like 1/ρ³ on gently bent rods)
/// would reject nearly all of them. Above, the closed form is used wherever that estimate
/// allows (J within `CLOSED_J_TOLERANCE`), the series elsewhere: near the separatrix, at small
/// m (near-circles under a tiny force, nearly straight rods under compression) and on gently
/// bent rods whose entries of J are far smaller than the elliptic quantities they come from.
const SERIES_RHO: f64 = 0.25;
/// Largest √‖F‖ for which the stability scan runs on the double-double series near the
/// separatrix (the steps scale like √‖F‖: ≈ 20 ms at √‖F‖ = 100, the top of issue 9's
/// strong-force family a4 ≤ 1e4). Beyond [`SERIES_DD_MAX_ROOT_F`] its g(t) is not certified
/// to the scan's 1e-3, but the sign is robust: its verdicts matched the rigorous 320-bit
/// reference on all 720 separatrix rods of scripts/gen_separatrix_truth.py's samples (√‖F‖ up
/// to 100), where its tips and J were off by up to 0.25 and 100 %.
pub(crate) const STABILITY_DD_MAX_ROOT_F: f64 = 120.0;
/// ln(f64::MAX): under tension F the rod's J grows like e^{√F t}; beyond this √F it overflows.
const LN_F64_MAX: f64 = 709.7;

/// ‖(a4, a5)‖ up to which every planar entry point answers every finite a (none refused on
/// 180,000 rods of log-scale |a3| up to 1e12 and |a4|, |a5| up to this, with exact zeros:
/// `examples/domain_scan.rs`). Beyond (√‖F‖ > 25), by a strong force, a formulation may refuse
/// what another answers (the first refusals measured: √‖F‖ ≈ 27, a barely bent rod under
/// tension), so the full evaluation decides for all of them.
const ORDINARY_FORCE: f64 = 625.0;

/// The one refusal domain of the planar rod, shared by [`evaluate`] (forward), [`tip`],
/// [`pose_and_jacobian`], [`stability`], [`stability_verdict`], [`energy`] and
/// [`PlanarRod::new`] (shape): the full evaluation's. Below [`ORDINARY_FORCE`] it refuses only
/// non-finite a, so the entry points check nothing more (one comparison: this function);
/// beyond, they take [`domain_evaluation`]'s refusal, or its answer as theirs. Squared, so no
/// square root on every call; an overflow to +∞ or a NaN counts as beyond (and `evaluate`
/// refuses NaN).
#[inline]
fn beyond_ordinary_force(a: &PlanarParams) -> bool {
    let f2 = a[1] * a[1] + a[2] * a[2];
    f2 > ORDINARY_FORCE * ORDINARY_FORCE || f2.is_nan()
}

/// The full evaluation that decides the domain beyond [`ORDINARY_FORCE`]: out of line, so that
/// the entry points' fast paths stay as they were.
#[cold]
#[inline(never)]
fn domain_evaluation(a: &PlanarParams) -> Result<Evaluation, RodError> {
    evaluate(a)
}

/// ρ = max(|a3|, √‖(a4, a5)‖): the rod's curvature scale (its Taylor terms grow like ρᵏ/k!).
pub(crate) fn curvature_scale(a: &PlanarParams) -> f64 {
    a[0].abs().max(crate::scalar::fast_hypot(a[1], a[2]).sqrt())
}

/// True when the series is chosen without building the closed form.
fn series_first(a: &PlanarParams) -> bool {
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

fn overflow_force() -> RodError {
    RodError::Overflow(format!(
        "planar rod: under this force J(t, a) grows like e^(sqrt|F| t) and exceeds f64 \
         (sqrt|F| > {LN_F64_MAX})"
    ))
}

/// Largest √‖F‖ for which the f64 series answers the tip, J and energy of an ill-conditioned
/// rod. Its rounding grows like e^{√‖F‖ t} at most, and far less where the rod only leaves the
/// straight equilibrium: against the 320-bit references (the 82 rods of
/// `tests/data/separatrix_truth*.jsonl` near the separatrix with √‖F‖ from 10.7 to 27) its J is
/// within 0.04·ε·e^{√‖F‖} and its tip within a hundredth of that. With ×3, J stays within 1e-9
/// up to √‖F‖ = 17.4, a hundred times inside the 1e-6 asked of J, at ~1/50 of the
/// double-double series' cost.
const SERIES_F64_TIP_MAX_ROOT_F: f64 = 17.0;

/// q(1), J(1) and the energy of an ill-conditioned rod (see [`series_dd`]): the closed form in
/// double-double where its estimates hold (`extended`), else the f64 series up
/// to √‖F‖ = [`SERIES_F64_TIP_MAX_ROOT_F`], the double-double series where it is certified
/// (√‖F‖ ≤ [`SERIES_DD_MAX_ROOT_F`]), else [`cross_checked_tip`].
fn ill_conditioned_tip(a: &PlanarParams) -> Result<(PlanarPose, PlanarJacobian, f64), RodError> {
    ill_conditioned_tip_with(a, extended::seeded_within_reach(a).as_ref())
}

/// [`ill_conditioned_tip`] with the rod's closed form in double-double, if within its reach.
fn ill_conditioned_tip_with(
    a: &PlanarParams,
    extended: Option<&Closed<crate::dd::DualDd>>,
) -> Result<(PlanarPose, PlanarJacobian, f64), RodError> {
    // The closed form in double-double first: tens of µs where the series takes ms.
    if let Some(answer) = extended.and_then(|c| extended::answer(c, a)) {
        return Ok(answer);
    }
    let root_f = a[1].hypot(a[2]).sqrt();
    if root_f > SERIES_DD_MAX_ROOT_F {
        return cross_checked_tip(a);
    }
    if root_f <= SERIES_F64_TIP_MAX_ROOT_F {
        let rod = series_dual(a, false)?;
        let (p, j) = pose_jac_from(rod.tip())?;
        return Ok((p, j, rod.energy().v));
    }
    let rod = series_dd::<false>(a, false, SERIES_DD_MAX_ROOT_F)?;
    let (p, j) = pose_jac_from(rod.tip())?;
    Ok((p, j, rod.energy().value()))
}

/// Largest disagreement in the tip (absolute) and in J (relative, Frobenius) between the closed
/// form and the double-double series for which [`cross_checked_tip`] answers: ten times inside
/// issue 9's 1e-9 and 1e-6.
const CROSS_CHECK_TIP: f64 = 1e-10;
const CROSS_CHECK_J: f64 = 1e-7;

/// Near the separatrix under a force beyond what either method certifies alone (√‖F‖ >
/// [`SERIES_DD_MAX_ROOT_F`], closed-form estimate above its last resort): the answer is the
/// closed form's where it agrees with the double-double series within [`CROSS_CHECK_TIP`] and
/// [`CROSS_CHECK_J`] (their errors have unrelated causes, cancellation in the elliptic
/// derivatives and amplified integration rounding, so agreement certifies both), and the energy
/// by the identity where its bound holds or the two energies agree to 1e-9; otherwise a clear
/// error. Measured on the rigorous reference (`tests/separatrix_truth.rs`): where they agree
/// the answer is right; they disagree where the series is off (by up to 100 % in J).
fn cross_checked_tip(a: &PlanarParams) -> Result<(PlanarPose, PlanarJacobian, f64), RodError> {
    let refuse = |why: String| {
        RodError::OutOfDomain(format!(
            "planar rod near its straight equilibrium under a force of {:.3e}: the answer \
             cannot be certified to 1e-9 ({why})",
            a[1].hypot(a[2])
        ))
    };
    let rod = series_dd::<true>(a, false, STABILITY_DD_MAX_ROOT_F)?;
    let (tip_s, j_s) = pose_jac_from(rod.tip())?;
    let Some(c) = seeded_closed(a) else {
        return Err(refuse("the closed form overflows".into()));
    };
    let (tip, j) = pose_jac_from(c.pose(1.0))?;
    let dtip = (tip.x - tip_s.x)
        .abs()
        .max((tip.y - tip_s.y).abs())
        .max((tip.theta - tip_s.theta).abs());
    let dj = (j - j_s).norm() / j_s.norm();
    if !(dtip <= CROSS_CHECK_TIP && dj <= CROSS_CHECK_J) {
        return Err(refuse(format!(
            "the closed form and the double-double series differ by {dtip:.1e} in the tip, \
             {dj:.1e} in J"
        )));
    }
    let energy = match energy_by_identity(&c, a, &tip)? {
        Some(e) => e,
        None => {
            let (e_s, e_i) = (rod.energy().value(), energy_from_tip(a, &tip));
            let agree = (e_s - e_i).abs() <= ENERGY_REL_TOLERANCE * e_s.abs();
            if !agree {
                return Err(refuse(format!(
                    "its energy: the series gives {e_s:e}, the identity {e_i:e}"
                )));
            }
            e_s
        }
    };
    Ok((tip, j, energy))
}

/// Checks a at every public entry, and charges the evaluation to the deadline in force (one
/// unit: a closed-form evaluation is bounded, ≈ 0.3–2 µs; the series inside charge their
/// steps).
fn check_params(a: &PlanarParams) -> Result<(), RodError> {
    crate::deadline::charge(crate::deadline::units::PLANAR_EVALUATION);
    RodError::check_finite("a", a.as_slice())
}

fn overflow() -> RodError {
    RodError::Overflow("closed form of the planar rod: parameters too large for f64".into())
}

/// The closed form in dual numbers seeded with the identity on a (so that it carries J); None
/// where an intermediate quantity overflows.
fn seeded_closed(a: &PlanarParams) -> Option<Closed<Dual3>> {
    Closed::new(
        Dual3::variable(a[0], 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a[2], 2),
    )
}

/// Runs `f` on the dual-number closed form seeded with the identity on a. The closed form
/// (≈ 1 KB of dual numbers) is borrowed where it was built, never moved through an
/// `Option`/`Result` (each move was a memcpy). Without `with_phase` it leaves φ out where the
/// addition theorems place its poses (`Closed::complete`): for callers that ask poses and J
/// alone, which come out the same bits either way.
fn with_seeded<R>(
    a: &PlanarParams,
    with_phase: bool,
    f: impl FnOnce(&Closed<Dual3>) -> Result<R, RodError>,
    series: impl FnOnce() -> Result<R, RodError>,
) -> Result<R, RodError> {
    check_params(a)?;
    let (a3, a4, a5) = (
        Dual3::variable(a[0], 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a[2], 2),
    );
    // Built in place (`Closed::complete`): through `Closed::new`'s Option the form was copied.
    let mut c = Closed::straight(a3, a4, a5);
    if c.complete(a3, a4, a5, with_phase) {
        f(&c)
    } else {
        // The closed form's intermediate ratios overflowed (e.g. a tiny moment against a
        // moderate force): the series has its own overflow detection.
        tension_within_f64(a)?;
        series()
    }
}

fn pose_and_jac_of(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jac_with(c, a, t, true)
}

/// `precise`: double-double where the rod is ill-conditioned; otherwise the f64 series there
/// (errors up to ≈ 1e-8: good enough for a Newton step, not for an answer).
fn pose_and_jac_with(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    t: f64,
    precise: bool,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    let need = match c.needs_series() {
        // J(t) of the part [0, t] is as hard as J(1) of a gently bent rod (see
        // `Closed::jacobian_rel_error_at`): its own estimate decides at t < 1.
        SeriesNeed::None if t < 1.0 && c.jacobian_rel_error_at(t) > CLOSED_J_TOLERANCE => {
            if c.needs_precise_series() {
                SeriesNeed::IllConditioned
            } else {
                SeriesNeed::Cancellation
            }
        }
        need => need,
    };
    if need != SeriesNeed::None {
        if let Some(answer) = small_angle::checked_pose_and_jacobian(a, t) {
            return Ok(answer);
        }
    }
    match need {
        // FINDINGS §4: where the closed form's error estimate fails, the Taylor series gives
        // the pose and J (both: near the separatrix the closed-form pose drifts too).
        SeriesNeed::IllConditioned if t >= 1.0 && precise => {
            let (p, j, _) = ill_conditioned_tip(a)?;
            return Ok((p, j));
        }
        SeriesNeed::IllConditioned if precise => {
            let rod = series_dd::<false>(a, true, SERIES_DD_MAX_ROOT_F)?;
            return pose_jac_from(rod.pose(t.max(0.0)).ok_or_else(overflow)?);
        }
        SeriesNeed::IllConditioned | SeriesNeed::Cancellation => return series_pose_and_jac(a, t),
        SeriesNeed::None => {}
    }
    pose_jac_from(c.pose(t))
}

/// A planar rod ready to be sampled: the closed form with everything that depends on a only
/// precomputed (case, m, m1 = 1 − m, r, phase φ, the Landen sequence and the values at Γ0 = φ;
/// FINDINGS §2), so that each [`PlanarRod::pose`] costs one Jacobi-function evaluation — or,
/// for nearly straight, gently bent and tiny rods (and wherever the closed form's error
/// estimate fails), the Taylor-series polynomials of the rod, each pose one Horner evaluation.
#[derive(Clone, Debug)]
pub struct PlanarRod {
    a: PlanarParams,
    case: Case,
    backend: Backend,
    tip: PlanarPose,
}

#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // one per rod, never in bulk; boxing costs an allocation
enum Backend {
    Closed(Closed<f64>),
    Series(TaylorRod<f64>),
    /// The small-angle expansion (or the pendulum), where forward answers by it and the series
    /// cannot stand in (beyond √‖F‖ = ln(f64::MAX), a nearly straight rod under compression).
    SmallAngle,
}

/// The closed-form case of a when the series is used without building the closed form (the
/// classification of FINDINGS §2, which `case()` reports for information).
fn case_without_closed(a: &PlanarParams) -> Case {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    if a3 == 0.0 && a5 == 0.0 {
        Case::Straight
    } else if a4 == 0.0 && a5 == 0.0 {
        Case::Circle
    } else {
        // Tiny inputs can overflow the closed form's intermediate ratios: case I then.
        Closed::new(a3, a4, a5).map_or(Case::I, |c| c.case)
    }
}

impl PlanarRod {
    /// Precomputes the rod for a. Errors: [`RodError::NonFinite`] if a component of a is NaN
    /// or ±∞; every refusal of [`evaluate`] (one domain: beyond ‖(a4, a5)‖ = 625 the full
    /// evaluation runs first, and its tip is the shape's); [`RodError::Overflow`] where the
    /// shape cannot be represented in f64 (its series beyond √‖(a4, a5)‖ = ln(f64::MAX), the
    /// one kind of rod forward answers and the shape does not: `tests/domain.rs`).
    pub fn new(a: &PlanarParams) -> Result<Self, RodError> {
        check_params(a)?;
        // Forward's refusals are the shape's too (one domain); its tip is the shape's.
        let known = if beyond_ordinary_force(a) {
            Some(domain_evaluation(a)?)
        } else {
            None
        };
        let closed = if series_first(a) {
            None
        } else {
            Closed::new(a[0], a[1], a[2])
        };
        // Where the series stands in for the closed form, beyond √‖F‖ = ln(f64::MAX) its poses
        // between base and tip overflow (NaN at phases of ~1e8 loops where the tip did not, a =
        // (−8e−65, 5e16, 0), which forward refuses too).
        let series = || {
            if crate::scalar::fast_hypot(a[1], a[2]).sqrt() > LN_F64_MAX {
                return Err(overflow_force());
            }
            series_f64(a, true)
        };
        // As forward does, the small-angle expansion before a series that cannot run.
        let series_or_small_angle = || match series() {
            Err(e) if small_angle::checked_tip(a).is_none() => Err(e),
            Err(_) => Ok(Backend::SmallAngle),
            Ok(r) => Ok(Backend::Series(r)),
        };
        let (case, backend) = match closed {
            Some(c) if !c.needs_reference() => (c.case, Backend::Closed(c)),
            Some(c) => (c.case, series_or_small_angle()?),
            None => (case_without_closed(a), series_or_small_angle()?),
        };
        let tip = match &backend {
            _ if let Some(e) = &known => [e.tip.x, e.tip.y, e.tip.theta],
            Backend::Closed(c) => c.pose(1.0),
            // Near the separatrix the f64 series' tip drifts: the double-double one (at small
            // m the f64 series is exact to ~1e-14 and serves as is).
            Backend::Series(_)
                if closed.is_some_and(|c| c.needs_series() == SeriesNeed::IllConditioned) =>
            {
                // As `tip` does: the small-angle expansion first (a nearly straight rod under
                // tension), so that forward and shape answer the same rods.
                match small_angle::checked_tip(a) {
                    Some(tip) => tip,
                    None => ill_conditioned_tip(a).map(|(p, _, _)| [p.x, p.y, p.theta])?,
                }
            }
            Backend::Series(r) => r.tip(),
            Backend::SmallAngle => small_angle::checked_tip(a).ok_or_else(overflow)?,
        };
        let tip = PlanarPose::new(tip[0], tip[1], tip[2]);
        if !tip.is_finite() {
            return Err(overflow());
        }
        Ok(Self {
            a: *a,
            case,
            backend,
            tip,
        })
    }

    /// The parameters a = μ(0) this rod was built from.
    pub fn params(&self) -> PlanarParams {
        self.a
    }

    /// Which closed form applies to a (FINDINGS §2 table and degenerate inputs), whichever
    /// formulation evaluates it.
    pub fn case(&self) -> Case {
        self.case
    }

    /// Pose q(t) = (x, y, θ)(t), θ unwrapped (FINDINGS §1: x = (a4 I4 + a5 I5)/F²,
    /// y = (a5 I4 − a4 I5)/F², with the integrals of §3; or the Taylor series). Intended for
    /// t ∈ [0, 1] (the series clamps t to it); NaN t gives a NaN pose.
    pub fn pose(&self, t: f64) -> PlanarPose {
        let p = match &self.backend {
            Backend::Closed(c) => c.pose(t),
            Backend::Series(r) if t.is_nan() => [t; 3],
            Backend::Series(r) => r.pose(t.clamp(0.0, 1.0)).unwrap_or([f64::NAN; 3]),
            // The base is the identity (the expansion's J is 0/0 there).
            Backend::SmallAngle if t <= 0.0 => [0.0; 3],
            Backend::SmallAngle => small_angle::checked_pose_and_jacobian(&self.a, t.min(1.0))
                .map_or([f64::NAN; 3], |(p, _)| [p.x, p.y, p.theta]),
        };
        PlanarPose::new(p[0], p[1], p[2])
    }

    /// Tip pose q(1) (computed once by [`PlanarRod::new`]).
    pub fn tip(&self) -> PlanarPose {
        self.tip
    }

    /// Curvature κ(t) = μ3(t) (FINDINGS §2 table: ε√α3 cn Γ, ε√α3 dn Γ or ε√α3 sech Γ).
    pub fn curvature(&self, t: f64) -> f64 {
        match &self.backend {
            Backend::Closed(c) => c.curvature(t),
            Backend::Series(r) => r.curvature(t.clamp(0.0, 1.0)).unwrap_or(f64::NAN),
            Backend::SmallAngle => small_angle::curvature(&self.a, t.clamp(0.0, 1.0)),
        }
    }

    /// `samples` poses at t_i = i/(samples − 1) (one Jacobi evaluation each). `samples = 1`
    /// gives the base pose only; `samples = 0` an empty vector. Endpoints are exactly t = 0
    /// and t = 1.
    pub fn shape(&self, samples: usize) -> Vec<PlanarPose> {
        match samples {
            0 => Vec::new(),
            1 => vec![self.pose(0.0)],
            n => {
                let d = (n - 1) as f64;
                (0..n)
                    .map(|i| {
                        if i == n - 1 {
                            self.tip
                        } else {
                            self.pose(i as f64 / d)
                        }
                    })
                    .collect()
            }
        }
    }

    /// Elastic energy ½∫₀¹κ² = λ2/2 − a4 x(1) − a5 y(1), λ2 = a3² + 2a4 (FINDINGS §1), or
    /// integrated along the series where that identity cancels (see `closed_energy`).
    /// May be +∞ when a3² overflows (the free function [`energy`] reports that as an error).
    pub fn energy(&self) -> f64 {
        match &self.backend {
            Backend::Closed(c) => closed_energy(c, &self.a, &self.tip).unwrap_or(f64::INFINITY),
            // ½∫κ² integrated along: the identity cancels for a nearly straight rod under force.
            Backend::Series(r) => r.energy(),
            Backend::SmallAngle => small_angle::checked_energy(&self.a).unwrap_or(f64::INFINITY),
        }
    }
}

fn energy_from_tip(a: &PlanarParams, tip: &PlanarPose) -> f64 {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    0.5 * a3 * a3 + a4 - a4 * tip.x - a5 * tip.y
}

/// Relative accuracy asked of the energy: issue 9 asks 1e-8; 10× inside, with a bound that
/// is itself ≥ 2× the measured error.
const ENERGY_REL_TOLERANCE: f64 = 1e-9;

/// Rounding of [`Closed::energy_by_zeta_bounded`] in ulps of its terms: measured ≤ 10.1 on
/// 1,160 rods of cases I and II against the 320-bit references (tests/data/separatrix_truth*
/// .jsonl) and the double-double series (`zeta_energy_meets_its_bound`), ×3.
const ZETA_ENERGY_ULPS: f64 = 32.0;

/// The energy by the identity λ2/2 − a4 x − a5 y of FINDINGS §1 where its error bound allows,
/// else None. The identity subtracts a4·x + a5·y from λ2/2, both ≈ ‖F‖ on a nearly straight
/// rod under force, whose energy is orders of magnitude smaller: its error is (|a4| + |a5|)
/// times the pose error ([`Closed::pose_abs_error`]) plus the rounding of the sum.
fn energy_by_identity<T: crate::scalar::Real>(
    c: &Closed<T>,
    a: &PlanarParams,
    tip: &PlanarPose,
) -> Result<Option<f64>, RodError> {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let e = energy_from_tip(a, tip);
    let rounding =
        4.0 * f64::EPSILON * (0.5 * a3 * a3 + a4.abs() + (a4 * tip.x).abs() + (a5 * tip.y).abs());
    let bound = (a4.abs() + a5.abs()) * c.pose_abs_error() + rounding;
    if !e.is_finite() {
        return Err(overflow());
    }
    Ok((bound <= ENERGY_REL_TOLERANCE * e.abs()).then_some(e))
}

/// The energy of a rod whose tip came from the closed form `c`: the identity (free) where its
/// error bound allows ([`energy_by_identity`]), else ½∫κ² integrated along the Taylor series
/// (double-double near the separatrix under a strong force).
fn closed_energy<T: crate::scalar::Real>(
    c: &Closed<T>,
    a: &PlanarParams,
    tip: &PlanarPose,
) -> Result<f64, RodError> {
    if let Some(e) = energy_by_identity(c, a, tip)? {
        return Ok(e);
    }
    // Case I below m = ½ (a nearly straight rod under compression, where the identity
    // cancels): ∫cn² in closed form, within 2.2e-11 of the double-double series on 4,000
    // log-scale rods (1.7e-14 on those under compression; tests: see
    // `small_m_compression_closed_form_meets_its_estimate`); near m = 1 its Z/m terms cancel.
    // Elsewhere (case I from m = ½ up to the separatrix, case II) it is taken where its
    // rounding, a few ulps of its terms, is below the tolerance (a rod with some bending
    // under a strong tension: the series there takes 100+ steps).
    if let Some((e, terms)) = c.energy_by_zeta_bounded() {
        let bound = ZETA_ENERGY_ULPS * f64::EPSILON * terms;
        if (c.case == Case::I && c.m.re() < 0.5) || bound <= ENERGY_REL_TOLERANCE * e.abs() {
            return Ok(e);
        }
    }
    if let Some(e) = small_angle::checked_energy(a) {
        return Ok(e);
    }
    // Near the separatrix under a strong force the f64 series' rounding grows like e^{√‖F‖}
    // (measured far less: see [`SERIES_F64_TIP_MAX_ROOT_F`]): there the identity in
    // double-double (40–80 µs), else the double-double series (ms).
    let root_f = a[1].hypot(a[2]).sqrt();
    let e = if c.needs_precise_series() && root_f > SERIES_F64_TIP_MAX_ROOT_F {
        match extended::energy(a) {
            Some(e) => e,
            None => series_dd::<false>(a, false, SERIES_DD_MAX_ROOT_F)?
                .energy()
                .value(),
        }
    } else {
        series_f64(a, false)?.energy()
    };
    if e.is_finite() {
        Ok(e)
    } else {
        Err(overflow())
    }
}

fn finite_tip([x, y, th]: [f64; 3]) -> Result<PlanarPose, RodError> {
    let tip = PlanarPose::new(x, y, th);
    if tip.is_finite() {
        Ok(tip)
    } else {
        Err(overflow())
    }
}

/// q(1, a) from the f64 closed form without its phase, where its error estimate needs no
/// series (as in [`tip`]); `None` elsewhere (series rods, overflow). The solvers' chord steps
/// evaluate their trials with it: half the instructions of q + J there (1.8k against 3.6k on
/// the paper's box), and no slower path where the estimate fails.
pub(crate) fn tip_by_closed_form(a: &PlanarParams) -> Option<PlanarPose> {
    if check_params(a).is_err() || series_first(a) {
        return None;
    }
    let mut closed = Closed::<f64>::straight(a[0], a[1], a[2]);
    if !closed.complete(a[0], a[1], a[2], false) || closed.needs_series() != SeriesNeed::None {
        return None;
    }
    let [x, y, theta] = closed.pose(1.0);
    let tip = PlanarPose::new(x, y, theta);
    tip.is_finite().then_some(tip)
}

/// Tip pose q(1, a): the closed form (FINDINGS §1–§3), or the Taylor series for nearly
/// straight, gently bent and tiny rods and wherever the closed form's error estimate fails.
/// In cases I and II with m1, m ≥ 1e-3, 1e-2 the closed form places the tip by the addition
/// theorems without computing its phase (~18 % fewer instructions on the paper's box), so it
/// may differ from [`evaluate`]'s tip in the last bits (both within the closed form's pose
/// bound, `tip_without_the_phase_within_the_pose_bound`).
pub fn tip(a: &PlanarParams) -> Result<PlanarPose, RodError> {
    // Same checks as `PlanarRod::new`, without building (and copying) the rod.
    check_params(a)?;
    if beyond_ordinary_force(a) {
        return domain_evaluation(a).map(|e| e.tip);
    }
    let [x, y, th] = if series_first(a) {
        series_f64(a, false)?.tip()
    } else {
        // Built in place (`Closed::complete`: through an Option the form was copied), without
        // the phase where the addition theorems place the tip instead (~18 % of q(1)).
        let mut closed = Closed::<f64>::straight(a[0], a[1], a[2]);
        if !closed.complete(a[0], a[1], a[2], false) {
            tension_within_f64(a)?;
            return finite_tip(series_f64(a, false)?.tip());
        }
        match closed.needs_series() {
            SeriesNeed::None => closed.pose(1.0),
            _ if let Some(tip) = small_angle::checked_tip(a) => tip,
            SeriesNeed::IllConditioned => {
                ill_conditioned_tip(a).map(|(p, _, _)| [p.x, p.y, p.theta])?
            }
            SeriesNeed::Cancellation => series_f64(a, false)?.tip(),
        }
    };
    let tip = PlanarPose::new(x, y, th);
    if !tip.is_finite() {
        return Err(overflow());
    }
    Ok(tip)
}

/// Pose q(t, a) and J(t, a) = ∂q(t)/∂a (rows x, y, θ; columns a3, a4, a5), exact up to
/// rounding: the closed form evaluated in forward-mode dual numbers, or, for nearly straight,
/// gently bent and tiny rods (ρ ≤ 0.25) and wherever the closed form's error estimate fails
/// (near the separatrix, at small m, gently bent rods: see `Closed::needs_series`),
/// the Taylor series in dual numbers (double-double where rounding grows like e^{√‖F‖}).
/// FINDINGS §4 asks for such a fallback.
pub fn pose_and_jacobian(
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    RodError::check_finite("t", &[t])?;
    check_params(a)?;
    if beyond_ordinary_force(a) {
        let e = domain_evaluation(a)?;
        if t == 1.0 {
            return Ok((e.tip, e.jacobian));
        }
    }
    if series_first(a) {
        return series_pose_and_jac(a, t);
    }
    with_seeded(
        a,
        false,
        |c| pose_and_jac_of(c, a, t),
        || series_pose_and_jac(a, t),
    )
}

/// Largest estimated error (ε·e^{√‖F‖}) of the f64 series for which a solver's iterations
/// use it: beyond (√‖F‖ ≳ 22), the f64 tip has fewer than six correct digits and Newton steps
/// from it are noise (strong-tension rods, a4 ~ 1e3, were left unsolved).
const ITERATION_F64_MAX_ERROR: f64 = 1e-6;

/// Whether iterations near `a` need the double-double series near the separatrix
/// (ε·e^{√‖F‖} > [`ITERATION_F64_MAX_ERROR`]). Solvers decide this once per start, from the
/// start: a start in the strong-tension regime iterates precisely (a few ms per evaluation),
/// while an iterate that wanders there from an ordinary start keeps the cheap f64 evaluation
/// and fails fast instead of spending the deadline.
pub(crate) fn needs_precise_iterations(a: &PlanarParams) -> bool {
    crate::scalar::fast_hypot(a[1], a[2]).sqrt().exp() * f64::EPSILON > ITERATION_F64_MAX_ERROR
}

/// q(1) and J(1, a) for the iterations of a solver: as [`tip_and_jacobian`] except on
/// ill-conditioned rods (near the separatrix) when `precise` is false, where the f64 series
/// replaces the double-double one (≈ 100× cheaper, errors ε·e^{√‖F‖}, see
/// [`needs_precise_iterations`]). Solvers verify their answer with [`tip_and_jacobian`].
pub(crate) fn tip_and_jacobian_for_iteration(
    a: &PlanarParams,
    precise: bool,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    check_params(a)?;
    if series_first(a) {
        return series_pose_and_jac(a, 1.0);
    }
    with_seeded(
        a,
        false,
        |c| pose_and_jac_with(c, a, 1.0, precise),
        || series_pose_and_jac(a, 1.0),
    )
}

/// Largest estimated relative error of the closed form's J (its cancellation estimate) for
/// which a continuation's intermediate step uses it: 100× inside the steps' 1e-6 tolerance.
/// Strongly tensioned rods (a4 ≈ 600) have estimates of 1e-8 to 2e-8, just past the 1e-8 of
/// an answer ([`closed::CLOSED_J_TOLERANCE`]), and agree with the double-double series to
/// 1e-14; the series costs 3 ms there, the closed form under 1 µs.
const SUBSTEP_J_TOLERANCE: f64 = 1e-8 * 100.0;

/// q(1) and J(1, a) for the intermediate poses of a continuation
/// (`RodModel::tip_and_jacobian_for_substep`): the closed form wherever its error estimate is
/// within [`SUBSTEP_J_TOLERANCE`] (cases I and II away from m → 0), else [`tip_and_jacobian`].
pub(crate) fn tip_and_jacobian_for_substep(
    a: &PlanarParams,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    check_params(a)?;
    if series_first(a) {
        return series_pose_and_jac(a, 1.0);
    }
    with_seeded(
        a,
        false,
        |c| {
            if c.needs_series() != SeriesNeed::None && c.accurate_within(SUBSTEP_J_TOLERANCE) {
                pose_jac_from(c.pose(1.0))
            } else {
                pose_and_jac_of(c, a, 1.0)
            }
        },
        || series_pose_and_jac(a, 1.0),
    )
}

/// Tip pose q(1, a) and J(1, a) (see [`pose_and_jacobian`]).
pub fn tip_and_jacobian(a: &PlanarParams) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jacobian(a, 1.0)
}

/// Stability of the equilibrium a (Bretl & McCarthy; FINDINGS §5): stable iff det J(t, a) > 0
/// on (0, 1]. g(t) = det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) is scanned on a grid whose spacing
/// follows the rod's wavelength (from t = 0.02 on the closed form, 0.01 on the series; below,
/// det J > 0 by its leading term), sign changes are located to 1e-7 and local minima refined;
/// on the closed form every sample also gives g′(t) (d det J/dt = det[J_x; J_y; ∂κ/∂a]), which
/// finds minima between samples and steers those refinements (half-wavelength grid). The margin is FINDINGS §5 `det_min`, min over t ∈ [0.05, 1] of g; the report is
/// `uncertain` when it lies within its error bound (the closed form first hands such rods to
/// the series). The straight rod (a3 = a5 = 0) has det J ≡ 0: uncertain, margin 0.
///
/// Theory settles what rounding cannot (Sachkov, "Conjugate points in Euler's elastic
/// problem", 2008): a rod whose curvature keeps its sign (λ4 < 0, circles, or λ4 > 0 with no
/// inflection point on (0, 1]) has no conjugate point, so it is reported stable and certain,
/// its margin the scan's (floored at 0). Negative values of g within their error bound
/// before the first conjugate point can come are rounding and carry no sign in the scan.
pub fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    check_params(a)?;
    if beyond_ordinary_force(a) {
        return domain_evaluation(a).map(|e| e.stability);
    }
    if series_first(a) {
        return stability_by_series(a);
    }
    with_seeded(
        a,
        true,
        |c| {
            let report = stability::stability_of(c, a)?;
            Ok(stability::with_theorem(report, || c.theorem_verdict()))
        },
        || stability_by_series(a),
    )
}

/// The stability verdict alone: the outcome of [`stability`]`(a)?.`[`verdict`](
/// StabilityReport::verdict)`()` (equal on 14,000 rods of six families), without the margin
/// or the conjugate point, for callers that only keep or reject a rod (a planner sampling
/// configurations, a stable-target generator). Where a theorem or the sign of det J(1)
/// decides (64 % of the paper's box) it skips the scan, and elsewhere scans only from the
/// first inflection point on (so it may decide a rod whose full scan is uncertain only
/// before that point, where the theorem rules out a conjugate point): ~3× faster on the box
/// (`rod-ig bench`, "stability test, verdict").
///
/// ```
/// use rod_ig_core::{planar, PlanarParams, StabilityVerdict};
/// let a = PlanarParams::new(2.0, -10.0, 5.0);
/// assert_eq!(planar::stability_verdict(&a)?, StabilityVerdict::Stable);
/// assert_eq!(planar::stability_verdict(&a)?, planar::stability(&a)?.verdict());
/// # Ok::<(), rod_ig_core::RodError>(())
/// ```
pub fn stability_verdict(a: &PlanarParams) -> Result<StabilityVerdict, RodError> {
    check_params(a)?;
    if beyond_ordinary_force(a) {
        return domain_evaluation(a).map(|e| e.stability.verdict());
    }
    if series_first(a) {
        return stability_by_series(a).map(|r| r.verdict());
    }
    with_seeded(
        a,
        true,
        |c| match stability::verdict_of(c, a)? {
            Some(verdict) => Ok(verdict),
            None => {
                let report = stability::stability_of(c, a)?;
                Ok(stability::with_theorem(report, || c.theorem_verdict()).verdict())
            }
        },
        || stability_by_series(a).map(|r| r.verdict()),
    )
}

/// [`stability`] on the Taylor series (near-relaxed rods, or where the closed form overflows).
fn stability_by_series(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    let report = stability::stability_of_series(a, None, None, None)?;
    Ok(stability::with_theorem(report, || theorem_verdict(a)))
}

/// [`Closed::theorem_verdict`] of a rod whose closed form was not built (None where it
/// cannot be).
fn theorem_verdict(a: &PlanarParams) -> Option<StabilityVerdict> {
    Closed::<f64>::new(a[0], a[1], a[2]).and_then(|c| c.theorem_verdict())
}

/// Elastic energy ½∫₀¹κ² (FINDINGS §1 identity λ2/2 − a4 x(1) − a5 y(1)).
pub fn energy(a: &PlanarParams) -> Result<f64, RodError> {
    check_params(a)?;
    if beyond_ordinary_force(a) {
        return domain_evaluation(a).map(|e| e.energy);
    }
    if let Some(e) = small_angle::checked_energy(a) {
        return Ok(e);
    }
    let e = PlanarRod::new(a)?.energy();
    if e.is_finite() {
        Ok(e)
    } else {
        Err(overflow())
    }
}

/// Tip, J(1, a) (rows x, y, θ; columns a3, a4, a5), ½∫κ² and the stability verdict of one rod
/// at full accuracy: the solvers' evaluation type ([`crate::solver::ModelEvaluation`]) for the
/// planar rod.
pub type Evaluation = crate::solver::ModelEvaluation<3, PlanarPose>;

/// An evaluation whose every part is at full accuracy.
fn full_accuracy(
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

/// [`evaluate`] on the Taylor series (one dense integration serves all four quantities).
fn evaluate_series(a: &PlanarParams) -> Result<Evaluation, RodError> {
    // Where the small-angle limit decides stability, the scan needs no dense output.
    let small_angle = stability::small_angle_report(a)?;
    let rod = series_dual(a, small_angle.is_none())?;
    let (tip, jacobian) = pose_jac_from(rod.tip())?;
    let energy = rod.energy().v;
    let stability = match small_angle {
        Some(report) => report,
        None => stability::stability_of_dense_series(a, &rod)?,
    };
    Ok(full_accuracy(tip, jacobian, energy, stability))
}

/// [`evaluate`] of a nearly straight rod by the small-angle expansion, where every part of it
/// is within its tolerance; None elsewhere.
fn evaluate_small_angle(a: &PlanarParams) -> Result<Option<Evaluation>, RodError> {
    let th = small_angle::effective_angle(a[0], a[1], a[2]);
    let Some((tip, jacobian)) = small_angle::checked_pose_and_jacobian_at(a, 1.0, th) else {
        return Ok(None);
    };
    let Some(energy) = small_angle::checked_energy_at(a, th) else {
        return Ok(None);
    };
    let Some(stability) = stability::small_angle_report(a)? else {
        return Ok(None);
    };
    Ok(Some(full_accuracy(tip, jacobian, energy, stability)))
}

/// Tip, J(1, a), energy and stability in one call (one precomputation shared by all).
pub fn evaluate(a: &PlanarParams) -> Result<Evaluation, RodError> {
    check_params(a)?;
    let series = || Ok(with_theorem(evaluate_series(a)?, || theorem_verdict(a)));
    if series_first(a) {
        return series();
    }
    with_seeded(
        a,
        true,
        |c| Ok(with_theorem(evaluate_closed(c, a)?, || c.theorem_verdict())),
        series,
    )
}

/// The evaluation with the stability verdict a theorem gives where one applies
/// ([`stability::with_theorem`]).
fn with_theorem(e: Evaluation, theorem: impl FnOnce() -> Option<StabilityVerdict>) -> Evaluation {
    Evaluation {
        stability: stability::with_theorem(e.stability, theorem),
        ..e
    }
}

/// [`evaluate`] on the closed form (handing to the small-angle expansion or the series where
/// its estimates say so), with the stability verdict of the scans alone.
fn evaluate_closed(c: &Closed<Dual3>, a: &PlanarParams) -> Result<Evaluation, RodError> {
    if c.needs_series() != SeriesNeed::None {
        if let Some(e) = evaluate_small_angle(a)? {
            return Ok(e);
        }
    }
    if c.needs_series() == SeriesNeed::Cancellation {
        return evaluate_series(a);
    }
    if c.needs_series() == SeriesNeed::IllConditioned {
        // One double-double closed form for the forward map and the stability scan.
        let dd = extended::seeded_within_reach(a);
        let (tip, jacobian, energy) = ill_conditioned_tip_with(a, dd.as_ref())?;
        let stability = stability::stability_of_with(c, a, dd.as_ref())?;
        return Ok(full_accuracy(tip, jacobian, energy, stability));
    }
    let (tip, jacobian) = pose_and_jac_of(c, a, 1.0)?;
    let near_separatrix = c.m1 < SEPARATRIX_M1
        && !c.needs_precise_series()
        && energy_by_identity(c, a, &tip)?.is_none();
    if near_separatrix {
        // A nearly straight rod under a force near the separatrix: its energy and
        // det J(t) both need the series (the identity cancels, the x row of J is below
        // the closed form's error floor); one dense series serves both. The tip and J
        // stay the closed form's, identical to `tip_and_jacobian`'s. Where the
        // small-angle limit decides stability, the energy needs no dense series (the
        // zeta form, or the series' values only).
        if let Some(stability) = stability::small_angle_report(a)? {
            return Ok(full_accuracy(
                tip,
                jacobian,
                closed_energy(c, a, &tip)?,
                stability,
            ));
        }
        let rod = series_dual(a, true)?;
        return Ok(full_accuracy(
            tip,
            jacobian,
            rod.energy().v,
            stability::stability_of_dense_series(a, &rod)?,
        ));
    }
    let energy = closed_energy(c, a, &tip)?;
    let stability = stability::stability_of(c, a)?;
    Ok(full_accuracy(tip, jacobian, energy, stability))
}

#[cfg(test)]
mod tests;
