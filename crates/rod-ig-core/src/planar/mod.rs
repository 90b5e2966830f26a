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
mod stability;

pub use closed::Case;
use closed::Closed;

use crate::scalar::Dual3;
use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError, StabilityReport};

fn check_params(a: &PlanarParams) -> Result<(), RodError> {
    RodError::check_finite("a", a.as_slice())
}

fn overflow() -> RodError {
    RodError::Overflow("closed form of the planar rod: parameters too large for f64".into())
}

/// Runs `f` on the dual-number closed form seeded with the identity on a. The closed form
/// (≈ 1 KB of dual numbers) is borrowed where it was built, never moved through an
/// `Option`/`Result` (each move was a memcpy).
fn with_seeded<R>(
    a: &PlanarParams,
    f: impl FnOnce(&Closed<Dual3>) -> Result<R, RodError>,
) -> Result<R, RodError> {
    check_params(a)?;
    let closed = Closed::new(
        Dual3::variable(a[0], 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a[2], 2),
    );
    match &closed {
        Some(c) => f(c),
        None => Err(overflow()),
    }
}

/// Relative tolerance of the ODE reference used for J near the separatrix.
const REFERENCE_RTOL: f64 = 1e-12;

fn pose_and_jac_of(
    c: &Closed<Dual3>,
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    if c.needs_reference() {
        // FINDINGS §4: fall back to the ODE where the closed form's derivatives are poor;
        // the pose itself stays the closed form's.
        let (_, j) = crate::ode::planar_reference::pose_and_jacobian(a, t, REFERENCE_RTOL)?;
        let [x, y, th] = c.pose(t);
        return Ok((PlanarPose::new(x.v, y.v, th.v), j));
    }
    let [x, y, th] = c.pose(t);
    let pose = PlanarPose::new(x.v, y.v, th.v);
    let j = PlanarJacobian::new(
        x.g[0], x.g[1], x.g[2], y.g[0], y.g[1], y.g[2], th.g[0], th.g[1], th.g[2],
    );
    if !(pose.is_finite() && j.iter().all(|v| v.is_finite())) {
        return Err(overflow());
    }
    Ok((pose, j))
}

/// A planar rod with everything that depends on a only precomputed (case, m, m1 = 1 − m, r,
/// phase φ, the Landen sequence and the values at Γ0 = φ; FINDINGS §2). Each [`PlanarRod::pose`]
/// then costs one Jacobi-function evaluation.
#[derive(Clone, Debug)]
pub struct PlanarRod {
    a: PlanarParams,
    closed: Closed<f64>,
    tip: PlanarPose,
}

impl PlanarRod {
    /// Precomputes the closed form for a. Errors: [`RodError::NonFinite`] if a component of a
    /// is NaN or ±∞, [`RodError::Overflow`] if a is too large for f64 arithmetic.
    pub fn new(a: &PlanarParams) -> Result<Self, RodError> {
        check_params(a)?;
        let closed = Closed::new(a[0], a[1], a[2]).ok_or_else(overflow)?;
        let [x, y, th] = closed.pose(1.0);
        let tip = PlanarPose::new(x, y, th);
        if !tip.is_finite() {
            return Err(overflow());
        }
        Ok(Self { a: *a, closed, tip })
    }

    /// The parameters a = μ(0) this rod was built from.
    pub fn params(&self) -> PlanarParams {
        self.a
    }

    /// Which closed form applies (FINDINGS §2 table and degenerate inputs).
    pub fn case(&self) -> Case {
        self.closed.case
    }

    /// Pose q(t) = (x, y, θ)(t), θ unwrapped (FINDINGS §1: x = (a4 I4 + a5 I5)/F²,
    /// y = (a5 I4 − a4 I5)/F², with the integrals of §3). Intended for t ∈ [0, 1]; the
    /// formulas are evaluated as they are for other t (NaN t gives a NaN pose).
    pub fn pose(&self, t: f64) -> PlanarPose {
        let [x, y, th] = self.closed.pose(t);
        PlanarPose::new(x, y, th)
    }

    /// Tip pose q(1) (computed once by [`PlanarRod::new`]).
    pub fn tip(&self) -> PlanarPose {
        self.tip
    }

    /// Curvature κ(t) = μ3(t) (FINDINGS §2 table: ε√α3 cn Γ, ε√α3 dn Γ or ε√α3 sech Γ).
    pub fn curvature(&self, t: f64) -> f64 {
        self.closed.curvature(t)
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

    /// Elastic energy ½∫₀¹κ² = λ2/2 − a4 x(1) − a5 y(1), λ2 = a3² + 2a4 (FINDINGS §1).
    /// May be +∞ when a3² overflows (the free function [`energy`] reports that as an error).
    pub fn energy(&self) -> f64 {
        let tip = self.tip();
        energy_from_tip(&self.a, &tip)
    }
}

fn energy_from_tip(a: &PlanarParams, tip: &PlanarPose) -> f64 {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    0.5 * a3 * a3 + a4 - a4 * tip.x - a5 * tip.y
}

/// Tip pose q(1, a) by the closed form (FINDINGS §1–§3).
pub fn tip(a: &PlanarParams) -> Result<PlanarPose, RodError> {
    // Same checks as `PlanarRod::new`, without building (and copying) the rod.
    check_params(a)?;
    let closed = Closed::<f64>::new(a[0], a[1], a[2]).ok_or_else(overflow)?;
    let [x, y, th] = closed.pose(1.0);
    let tip = PlanarPose::new(x, y, th);
    if !tip.is_finite() {
        return Err(overflow());
    }
    Ok(tip)
}

/// Pose q(t, a) and J(t, a) = ∂q(t)/∂a (rows x, y, θ; columns a3, a4, a5), exact up to
/// rounding: the closed form evaluated in forward-mode dual numbers. In the thin regimes where
/// those derivatives lose accuracy to cancellation (1 − m < 1e-7 near the separatrix, m < 1e-6
/// for near-straight rods under compression, see `Closed::needs_reference`), J comes from the
/// ODE reference (variational equations, rtol 1e-12) instead (FINDINGS §4); the pose is
/// always the closed form's.
pub fn pose_and_jacobian(
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    RodError::check_finite("t", &[t])?;
    with_seeded(a, |c| pose_and_jac_of(c, a, t))
}

/// Tip pose q(1, a) and J(1, a) (see [`pose_and_jacobian`]).
pub fn tip_and_jacobian(a: &PlanarParams) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    pose_and_jacobian(a, 1.0)
}

/// Stability of the equilibrium a (Bretl & McCarthy; FINDINGS §5): stable iff det J(t, a) > 0
/// on (0, 1]. The closed form is trusted for t ≥ 0.02 (below, det J > 0 by its leading term
/// a3²t⁹/8640 + a5²t¹¹/33600). det J is scanned on a grid whose spacing follows the rod's
/// wavelength, sign changes are located by regula falsi and local minima refined, so the cost
/// is a few tens of dual-number evaluations. The margin is FINDINGS §5 `det_min`: the minimum
/// over t ≥ 0.05 of det J(t)/(t⁹(a3²/8640 + a5²t²/33600)). The straight rod (a3 = a5 = 0) has
/// det J ≡ 0: unstable, margin 0.
pub fn stability(a: &PlanarParams) -> Result<StabilityReport, RodError> {
    with_seeded(a, |c| stability::stability_of(c, a))
}

/// Elastic energy ½∫₀¹κ² (FINDINGS §1 identity λ2/2 − a4 x(1) − a5 y(1)).
pub fn energy(a: &PlanarParams) -> Result<f64, RodError> {
    let e = PlanarRod::new(a)?.energy();
    if e.is_finite() {
        Ok(e)
    } else {
        Err(overflow())
    }
}

/// Everything `rod-ig forward` reports for one a.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation {
    /// Tip pose q(1).
    pub tip: PlanarPose,
    /// J(1, a), rows (x, y, θ), columns (a3, a4, a5).
    pub jacobian: PlanarJacobian,
    /// ½∫κ².
    pub energy: f64,
    /// Stability verdict and margin.
    pub stability: StabilityReport,
}

/// Tip, J(1, a), energy and stability in one call (one precomputation shared by all).
pub fn evaluate(a: &PlanarParams) -> Result<Evaluation, RodError> {
    with_seeded(a, |c| {
        let (tip, jacobian) = pose_and_jac_of(c, a, 1.0)?;
        let energy = energy_from_tip(a, &tip);
        if !energy.is_finite() {
            return Err(overflow());
        }
        let stability = stability::stability_of(c, a)?;
        Ok(Evaluation {
            tip,
            jacobian,
            energy,
            stability,
        })
    })
}
