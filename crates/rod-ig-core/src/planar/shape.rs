//! The shape of a planar rod: [`PlanarRod`], the rod ready to be sampled along its length.

use super::small_angle;
use crate::planar::closed::{overflow, Case, Closed};
use crate::planar::energy::closed_energy;
use crate::planar::taylor::{overflow_force, LN_F64_MAX};
use crate::planar::taylor::{series_f64, TaylorRod};
use crate::{PlanarParams, PlanarPose, RodError};

/// A planar rod ready to be sampled: the closed form with everything that depends on a only
/// precomputed (case, m, m1 = 1 − m, r, phase φ, the Landen sequence and the values at Γ0 = φ;
/// docs/math.md §2), so that each [`PlanarRod::pose`] costs one Jacobi-function evaluation — or,
/// for nearly straight, gently bent and tiny rods (and wherever the closed form's error
/// estimate fails), the Taylor-series polynomials of the rod, each pose one Horner evaluation.
#[derive(Clone, Debug)]
pub struct PlanarRod {
    a: PlanarParams,
    case: Case,
    backend: Backend,
    tip: PlanarPose,
}

/// How a [`PlanarRod`] places its poses.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // one per rod, never in bulk; boxing costs an allocation
pub(crate) enum Backend {
    /// The closed form (its estimate holds).
    Closed(Closed<f64>),
    /// The dense f64 Taylor series.
    Series(TaylorRod<f64>),
    /// The small-angle expansion (or the pendulum), where forward answers by it and the series
    /// cannot stand in (beyond √‖F‖ = ln(f64::MAX), a nearly straight rod under compression).
    SmallAngle,
    /// The separatrix limit's soliton lattice (a barely bent rod under a strong force).
    Separatrix(super::soliton::Lattice<f64>),
}

/// The closed-form case of a when the series is used without building the closed form (the
/// classification of docs/math.md §2, which `case()` reports for information).
pub(crate) fn case_without_closed(a: &PlanarParams) -> Case {
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

/// The series backend of a shape, or the small-angle expansion where the series cannot run and
/// the expansion's tip is within its bound (as forward does). Beyond √‖F‖ = ln(f64::MAX) the
/// series' poses between base and tip overflow (NaN at phases of ~1e8 loops where the tip did
/// not, a = (−8e−65, 5e16, 0), which forward refuses too).
pub(crate) fn series_backend(a: &PlanarParams) -> Result<Backend, RodError> {
    let series = if crate::scalar::fast_hypot(a[1], a[2]).sqrt() > LN_F64_MAX {
        Err(overflow_force())
    } else {
        series_f64(a, true)
    };
    match series {
        Err(e) if small_angle::checked_tip(a).is_none() => Err(e),
        Err(_) => Ok(Backend::SmallAngle),
        Ok(r) => Ok(Backend::Series(r)),
    }
}

impl PlanarRod {
    /// The rod with `tip` as its tip (the full evaluation's, beyond the ordinary force).
    pub(crate) fn with_tip(mut self, tip: PlanarPose) -> Self {
        self.tip = tip;
        self
    }

    /// The rod from the parts a formulation built (`planar/formulation/`); refused where its
    /// tip is not finite.
    pub(crate) fn from_parts(
        a: &PlanarParams,
        case: Case,
        backend: Backend,
        [x, y, theta]: [f64; 3],
    ) -> Result<Self, RodError> {
        let tip = PlanarPose::new(x, y, theta);
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

    /// Which closed form applies to a (docs/math.md §2 table and degenerate inputs), whichever
    /// formulation evaluates it.
    pub fn case(&self) -> Case {
        self.case
    }

    /// Pose q(t) = (x, y, θ)(t), θ unwrapped (docs/math.md §1: x = (a4 I4 + a5 I5)/F²,
    /// y = (a5 I4 − a4 I5)/F², with the integrals of §3; or the Taylor series). Intended for
    /// t ∈ [0, 1] (the series clamps t to it); NaN t gives a NaN pose.
    pub fn pose(&self, t: f64) -> PlanarPose {
        let p = match &self.backend {
            Backend::Closed(c) => c.pose(t),
            Backend::Series(r) if t.is_nan() => [t; 3],
            Backend::Series(r) => r.pose(t.clamp(0.0, 1.0)).unwrap_or([f64::NAN; 3]),
            // The base is the identity (the expansion's J is 0/0 there).
            Backend::Separatrix(l) if t.is_nan() => [t; 3],
            Backend::Separatrix(l) => l.pose(t.clamp(0.0, 1.0)),
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

    /// Curvature κ(t) = μ3(t) (docs/math.md §2 table: ε√α3 cn Γ, ε√α3 dn Γ or ε√α3 sech Γ).
    pub fn curvature(&self, t: f64) -> f64 {
        match &self.backend {
            Backend::Closed(c) => c.curvature(t),
            Backend::Series(r) => r.curvature(t.clamp(0.0, 1.0)).unwrap_or(f64::NAN),
            Backend::SmallAngle => small_angle::curvature(&self.a, t.clamp(0.0, 1.0)),
            Backend::Separatrix(l) => l.curvature(t.clamp(0.0, 1.0)),
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

    /// Elastic energy ½∫₀¹κ² = λ2/2 − a4 x(1) − a5 y(1), λ2 = a3² + 2a4 (docs/math.md §1), or
    /// integrated along the series where that identity cancels (see `closed_energy`).
    /// May be +∞ when a3² overflows (the free function [`energy`](crate::planar::energy) reports that as an error).
    pub fn energy(&self) -> f64 {
        match &self.backend {
            Backend::Closed(c) => closed_energy(c, &self.a, &self.tip).unwrap_or(f64::INFINITY),
            // ½∫κ² integrated along: the identity cancels for a nearly straight rod under force.
            Backend::Series(r) => r.energy(),
            Backend::SmallAngle => small_angle::checked_energy(&self.a).unwrap_or(f64::INFINITY),
            Backend::Separatrix(l) => l.energy(),
        }
    }
}
