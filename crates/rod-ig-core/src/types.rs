//! Types shared by every module and by the adapters (CLI, ROS node).

use serde::{Deserialize, Serialize};

/// Planar rod parameters a = (a3, a4, a5) = μ(0): the base moment a3 and base force (a4, a5),
/// in the paper's normalised units (unit length, unit bending stiffness).
pub type PlanarParams = nalgebra::Vector3<f64>;

/// Sensitivity J(t, a) = ∂(x, y, θ)(t) / ∂(a3, a4, a5).
/// Rows are x, y, θ (the order of [`PlanarPose`]); columns a3, a4, a5.
pub type PlanarJacobian = nalgebra::Matrix3<f64>;

/// A pose q = (x, y, θ) of the planar rod at some t ∈ [0, 1], base frame.
///
/// `theta` is unwrapped when it comes from the rod (θ(t) = ∫₀ᵗ κ); compare targets modulo 2π
/// with [`wrap_angle`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
// A target written {"x", "y", "theta", "z": 5} is a mistake to report, not to solve in the plane.
#[serde(deny_unknown_fields)]
pub struct PlanarPose {
    /// Position along the base tangent.
    pub x: f64,
    /// Position normal to the base tangent.
    pub y: f64,
    /// Tangent angle (rad).
    pub theta: f64,
}

impl PlanarPose {
    /// A pose from its three coordinates.
    pub const fn new(x: f64, y: f64, theta: f64) -> Self {
        Self { x, y, theta }
    }

    /// True when all three coordinates are finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.theta.is_finite()
    }

    /// As the column vector (x, y, θ).
    pub fn to_vector(&self) -> nalgebra::Vector3<f64> {
        nalgebra::Vector3::new(self.x, self.y, self.theta)
    }
}

/// Verdict of the stability test (Bretl & McCarthy 2014; docs/math.md §5): the rod is a stable
/// equilibrium iff det J(t, a) > 0 for every t ∈ (0, 1].
///
/// Three outcomes: stable (`stable`), unstable (neither flag), or `uncertain` — the margin is
/// within its own error estimate of zero, so the sign of det J cannot be decided in f64
/// (a rod at a fold of the equilibrium set, or the exactly straight rod a3 = a5 = 0, for which
/// det J ≡ 0). `stable` is false when uncertain: callers that need a stable rod reject it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StabilityReport {
    /// True iff det J(t, a) > 0 on (0, 1] was established: the margin exceeds its error
    /// bound, or a theorem rules out any conjugate point on the rod (planar: non-inflectional
    /// rods and circles have none, and an inflectional rod none before its first inflection
    /// point; Sachkov 2008), whatever a scan could decide. Where the same theorem places one
    /// on (0, 1] (by an inflectional rod's third inflection point), false and certain.
    pub stable: bool,
    /// Normalised margin g_min = min over t ∈ [0.05, 1] of
    /// g(t) = det J(t) / (t⁹ (a3²/8640 + a5² t²/33600)) (docs/math.md §5 `det_min`): scale-free,
    /// ≈ 1 for a gently bent rod, → 1 as t → 0; negative iff det J changes sign. 0 for the
    /// straight rod.
    pub margin: f64,
    /// First t at which det J changes sign (a conjugate point), when unstable.
    pub first_conjugate_t: Option<f64>,
    /// True when |margin| is within its rounding-error estimate: the verdict is undecided
    /// (then `stable` is false).
    #[serde(default)]
    pub uncertain: bool,
}

impl StabilityReport {
    /// The verdict without the margin: what [`crate::planar::stability_verdict`] answers.
    pub fn verdict(&self) -> StabilityVerdict {
        if self.stable {
            StabilityVerdict::Stable
        } else if self.uncertain {
            StabilityVerdict::Uncertain
        } else {
            StabilityVerdict::Unstable
        }
    }
}

/// The outcome of the stability test alone, without its margin
/// ([`crate::planar::stability_verdict`]; [`StabilityReport::verdict`] of a full report).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StabilityVerdict {
    /// det J(t, a) > 0 on (0, 1] was established (a scan beyond its error bound, or a theorem).
    Stable,
    /// det J(t, a) changes sign on (0, 1]: the rod has a conjugate point.
    Unstable,
    /// The sign of det J could not be decided in floating point ([`StabilityReport::uncertain`]).
    Uncertain,
}

impl StabilityVerdict {
    /// True only for [`StabilityVerdict::Stable`]: callers that need a stable rod reject the
    /// other two, as they do a report whose `stable` is false.
    pub fn is_stable(self) -> bool {
        self == Self::Stable
    }
}

pub use crate::angle::wrap_angle;

/// Smallest t at which the sign of det J(t, a) is trusted by the stability tests (docs/math.md §5):
/// det J(t) ~ t⁹ near the base, so below t ≈ 0.02 its absolute rounding error swamps it. Every
/// stability test (closed form, series, RK4 scan, 3-D grid) starts here.
pub const STABILITY_T_MIN: f64 = 0.02;

/// Smallest t entering the normalised stability margin `det_min` = min over t ∈ [this, 1] of
/// g(t) (docs/math.md §5): below it g's normalisation t⁹(…) is too small for its value to mean
/// much. One value for every rod: the planar closed forms and series, the rod with weight, the
/// 3-D rod and the references.
pub const STABILITY_MARGIN_T_MIN: f64 = 0.05;

/// The leading small-t term of det J(t, a) for the planar rod, t⁹ (a3²/8640 + a5² t²/33600)
/// (docs/math.md §5): the normalisation of the stability margin g(t) = det J(t) / this, written
/// once for the closed form's test and the reference integrator's.
pub fn planar_det_leading_term(a3: f64, a5: f64, t: f64) -> f64 {
    let t2 = t * t;
    let t9 = t2 * t2 * t2 * t2 * t;
    t9 * (a3 * a3 / 8640.0 + a5 * a5 * t2 / 33600.0)
}

/// det of a 3×3 matrix by expansion along its first row (J, or J with a row replaced).
#[inline]
pub(crate) fn det3(j: &[[f64; 3]; 3]) -> f64 {
    let m0 = j[1][1] * j[2][2] - j[1][2] * j[2][1];
    let m1 = j[1][0] * j[2][2] - j[1][2] * j[2][0];
    let m2 = j[1][0] * j[2][1] - j[1][1] * j[2][0];
    j[0][0] * m0 - j[0][1] * m1 + j[0][2] * m2
}

/// det J and a first-order bound on its error: Σ e_ij |C_ij| over the entries' errors
/// e_ij = rel·|J_ij| + abs and the cofactors C_ij, plus the rounding of the expansion.
pub(crate) fn det_and_error(j: &[[f64; 3]; 3], rel: f64, abs: f64) -> (f64, f64) {
    det_and_error_with(j, |r, c| rel * j[r][c].abs() + abs)
}

/// [`det_and_error`] when every entry of column c of J is off by at most `column_error[c]`.
pub(crate) fn det_and_error_by_column(j: &[[f64; 3]; 3], column_error: [f64; 3]) -> (f64, f64) {
    det_and_error_with(j, |_, c| column_error[c])
}

/// det J and Σ e_ij |C_ij| + 8ε Σ |J_0j C_0j| for the entries' errors e_ij = `entry_error(i, j)`.
#[inline(always)]
fn det_and_error_with(j: &[[f64; 3]; 3], entry_error: impl Fn(usize, usize) -> f64) -> (f64, f64) {
    let det = det3(j);
    let mut err = 0.0;
    let mut size = 0.0;
    for r in 0..3 {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        for c in 0..3 {
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            let cof = (j[r1][c1] * j[r2][c2]).abs() + (j[r1][c2] * j[r2][c1]).abs();
            err += entry_error(r, c) * cof;
            if r == 0 {
                size += j[r][c].abs() * cof;
            }
        }
    }
    (det, err + 8.0 * f64::EPSILON * size)
}

/// N′/N of that leading term N ([`planar_det_leading_term`]): 9/t + (a5²t/16800)/(a3²/8640 +
/// a5²t²/33600), for the slope of g = det J/N, g′ = det′/N − g·N′/N.
pub(crate) fn planar_det_leading_term_log_slope(a3: f64, a5: f64, t: f64) -> f64 {
    let (b3, b5) = (a3 * a3, a5 * a5);
    9.0 / t + (b5 * t / 16800.0) / (b3 / 8640.0 + b5 * t * t / 33600.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn wrap_angle_range() {
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), -PI);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap_angle(-12.740563317464874) - (-12.740563317464874 + 4.0 * PI)).abs() < 1e-12);
    }
}
