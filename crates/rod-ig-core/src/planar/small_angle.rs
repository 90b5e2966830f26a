//! The small-angle limit of the stability function g(t) for nearly straight rods (issue 23).
//!
//! A rod with little bending, σ = max(|a3|, |a5|) → 0 under a force a4 of any size, is a
//! perturbation of the straight rod. Linearised (docs/math.md §1 with θ, a3 and a5 small):
//!
//! ```text
//! θ'' = a4 θ − a5,  θ(0) = 0,  θ'(0) = a3   ⇒   θ = a3 S1 − a5 S2,   y = ∫θ = a3 S2 − a5 S3,
//! x = ∫cos θ = t − ½∫θ² + O(σ⁴),
//! ```
//!
//! with S1 = sinh(wt)/w (sin for a4 = −w² < 0), S2 = ∫S1, S3 = ∫S2, as in the closed form's
//! straight rod. The entries of J(t) = ∂(x, y, θ)/∂(a3, a4, a5) follow: the θ and y rows to
//! O(σ²) relative, the x row from ½∫θ² = ½(a3² I11 − 2 a3 a5 I12 + a5² I22), Iij = ∫Si Sj, to
//! O(σ²) relative as well. det J(t) is a quadratic form in (a3, a5) at leading order, and
//! g(t) = det J(t)/(t⁹(a3²/8640 + a5² t²/33600)) (docs/math.md §5) depends on (a3, a5) only
//! through their ratio: this module gives that limit g₀(t), accurate relative to itself (every
//! quantity is a positive series or a hyperbolic/trigonometric closed form, no difference of
//! O(1) elliptic quantities), where the closed form's x row, a difference of O(1) terms, is
//! swamped by rounding and the series costs tens of µs.
//!
//! The neglected terms are O(Θ²) relative, Θ the largest bending angle (measured bound in
//! [`truncation`]).
//!
//! As a formulation of the rod (issue 44), its answers come with their a-priori bounds
//! (`checked_*`): None where a bound exceeds the tolerance asked of an answer.

use super::closed::CLOSED_J_TOLERANCE;
use crate::planar::closed::ENERGY_REL_TOLERANCE;

use crate::{PlanarJacobian, PlanarParams, PlanarPose};

/// A value and its derivative with respect to a4 (a one-variable dual number: the straight
/// rod's functions need no other derivative, and Horner's rule in it costs a third of
/// [`crate::scalar::Dual3`]'s).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Jet {
    v: f64,
    d: f64,
}

impl Jet {
    const fn constant(v: f64) -> Self {
        Self { v, d: 0.0 }
    }

    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        Self {
            v: r,
            d: 0.5 * self.d / r,
        }
    }

    fn abs(self) -> Self {
        if self.v < 0.0 {
            Self {
                v: -self.v,
                d: -self.d,
            }
        } else {
            self
        }
    }

    /// (sinh, cosh) or (sin, cos) of self, by `hyperbolic`.
    fn sin_cos(self, hyperbolic: bool) -> (Self, Self) {
        let (s, c) = if hyperbolic {
            (self.v.sinh(), self.v.cosh())
        } else {
            self.v.sin_cos()
        };
        let sign = if hyperbolic { 1.0 } else { -1.0 };
        (
            Self {
                v: s,
                d: c * self.d,
            },
            Self {
                v: c,
                d: sign * s * self.d,
            },
        )
    }
}

impl std::ops::Add for Jet {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            d: self.d + o.d,
        }
    }
}

impl std::ops::Sub for Jet {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            d: self.d - o.d,
        }
    }
}

impl std::ops::Mul for Jet {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            d: self.v * o.d + self.d * o.v,
        }
    }
}

impl std::ops::Div for Jet {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let q = self.v / o.v;
        Self {
            v: q,
            d: (self.d - q * o.d) / o.v,
        }
    }
}

impl std::ops::Add<f64> for Jet {
    type Output = Self;
    fn add(self, o: f64) -> Self {
        Self {
            v: self.v + o,
            d: self.d,
        }
    }
}

impl std::ops::Sub<f64> for Jet {
    type Output = Self;
    fn sub(self, o: f64) -> Self {
        Self {
            v: self.v - o,
            d: self.d,
        }
    }
}

impl std::ops::Mul<f64> for Jet {
    type Output = Self;
    fn mul(self, o: f64) -> Self {
        Self {
            v: self.v * o,
            d: self.d * o,
        }
    }
}

/// Terms of the Maclaurin series in z = a4 t² (|z| < [`SERIES_MAX_Z`]): the first neglected
/// term is below 16²⁰/40! ≈ 1.5e-24 of the sum.
const TERMS: usize = 20;
/// Below this |a4 t²| the S and I functions come from their Maclaurin series (the closed forms
/// cancel there: I22 = (sc/2 + 3wt/2 − 2s)/(w a4²) is O((wt)⁵) as a difference of O(wt) terms).
/// At |z| = 4 the closed forms lose at most ~20 ulps.
const SERIES_MAX_Z: f64 = 4.0;

/// 1/k! for k < 64.
const INV_FACTORIAL: [f64; 64] = {
    let mut f = [1.0f64; 64];
    let mut k = 1;
    while k < 64 {
        f[k] = f[k - 1] / k as f64;
        k += 1;
    }
    f
};

/// Coefficients of Si = tⁱ Σ zᵏ/(2k + i)!.
const fn s_coefficients(i: usize) -> [f64; TERMS] {
    let mut c = [0.0; TERMS];
    let mut k = 0;
    while k < TERMS {
        c[k] = INV_FACTORIAL[2 * k + i];
        k += 1;
    }
    c
}

/// Coefficients of Iij = ∫₀ᵗ Si Sj = t^{i+j+1} Σ zⁿ (Σₖ 1/((2k + i)!(2(n − k) + j)!))/(2n + i +
/// j + 1) (the Cauchy product of the two series, integrated term by term).
const fn i_coefficients(i: usize, j: usize) -> [f64; TERMS] {
    let mut c = [0.0; TERMS];
    let mut n = 0;
    while n < TERMS {
        let mut sum = 0.0;
        let mut k = 0;
        while k <= n {
            sum += INV_FACTORIAL[2 * k + i] * INV_FACTORIAL[2 * (n - k) + j];
            k += 1;
        }
        c[n] = sum / (2 * n + i + j + 1) as f64;
        n += 1;
    }
    c
}

const S1: [f64; TERMS] = s_coefficients(1);
const S2: [f64; TERMS] = s_coefficients(2);
const S3: [f64; TERMS] = s_coefficients(3);
const I00: [f64; TERMS] = i_coefficients(0, 0);
const I01: [f64; TERMS] = i_coefficients(0, 1);
const I11: [f64; TERMS] = i_coefficients(1, 1);
const I12: [f64; TERMS] = i_coefficients(1, 2);
const I22: [f64; TERMS] = i_coefficients(2, 2);

/// Σ cₖ zᵏ by Horner's rule, over the first n terms.
fn horner(c: &[f64; TERMS], z: Jet, n: usize) -> Jet {
    let mut acc = Jet::constant(c[n - 1]);
    for &ck in c[..n - 1].iter().rev() {
        acc = acc * z + ck;
    }
    acc
}

/// (n, z_max): n terms of every series of [`series_jets`] (S1, S2, S3, I11, I12, I22) leave
/// tails in value and in z-derivative below 2⁻⁶⁴ of the sums' lower bounds c₀ − c₁|z| and
/// c₁ − 2c₂|z| for |z| ≤ z_max (bisected with exact rational coefficients, rounded down;
/// `series_terms_leave_no_tail` checks it). Beyond the last entry all [`TERMS`] are used (17
/// suffice at |z| = [`SERIES_MAX_Z`]): most samples of a scan sit at small z, where 9–12
/// terms do.
const TERMS_FOR_Z: [(usize, f64); 13] = [
    (4, 4.1e-6),
    (5, 2.1e-4),
    (6, 2.4e-3),
    (7, 1.3e-2),
    (8, 4.5e-2),
    (9, 0.118),
    (10, 0.252),
    (11, 0.472),
    (12, 0.797),
    (13, 1.245),
    (14, 1.828),
    (15, 2.551),
    (16, 3.401),
];

/// Terms [`series_jets`] needs at |z| (see [`TERMS_FOR_Z`]).
fn terms_for(z: f64) -> usize {
    let z = z.abs();
    TERMS_FOR_Z
        .iter()
        .find(|&&(_, z_max)| z <= z_max)
        .map_or(TERMS, |&(n, _)| n)
}

/// The straight rod's functions at t and their a4-derivatives:
/// [S1, S2, S3, I11, I12, I22] (module docs).
fn straight_jets(a4: f64, t: f64) -> [Jet; 6] {
    if (a4 * t * t).abs() < SERIES_MAX_Z {
        series_jets(a4, t)
    } else {
        closed_jets(a4, t)
    }
}

/// [S1, S2, S3, I11, I12, I22] of the straight rod under a4 at t (module docs), values only
/// (also the small-angle starts of the inverse geometry, `ig/straight.rs`).
pub(crate) fn straight_functions(a4: f64, t: f64) -> [f64; 6] {
    straight_jets(a4, t).map(|j| j.v)
}

/// [`straight_jets`] by the Maclaurin series in z = a4 t².
fn series_jets(a4: f64, t: f64) -> [Jet; 6] {
    let z = Jet { v: a4, d: 1.0 } * (t * t);
    let n = terms_for(z.v);
    let (t2, t3) = (t * t, t * t * t);
    [
        horner(&S1, z, n) * t,
        horner(&S2, z, n) * t2,
        horner(&S3, z, n) * t3,
        horner(&I11, z, n) * t3,
        horner(&I12, z, n) * (t2 * t2),
        horner(&I22, z, n) * (t2 * t3),
    ]
}

/// [`straight_jets`] by the hyperbolic (a4 > 0) or trigonometric (a4 < 0) closed forms.
fn closed_jets(a4: f64, t: f64) -> [Jet; 6] {
    let f = Jet { v: a4, d: 1.0 };
    // a4 = ±w²: (s, c) = (sinh, cosh)(wt) or (sin, cos)(wt); the same formulas hold in both
    // cases when written with a4 itself (I12 differs in the sign of its s² term).
    let w = f.abs().sqrt();
    let wt = w * t;
    let (s, c) = wt.sin_cos(a4 > 0.0);
    let s2_sign = if a4 > 0.0 { 1.0 } else { -1.0 };
    let wf = w * f;
    let ff = f * f;
    [
        s / w,
        (c - 1.0) / f,
        (s - wt) / wf,
        (s * c - wt) / (wf * 2.0),
        (s * s * (0.5 * s2_sign) - c + 1.0) / ff,
        (s * c * 0.5 + wt * 1.5 - s * 2.0) / (wf * f),
    ]
}

/// J(t) of the linearised rod from the straight rod's functions at t, with (b3, b5) in place
/// of (a3, a5) (the bending itself, or its direction (a3, a5)/σ, which scales the x row and
/// the a4 column by 1/σ), and each entry's sum of absolute terms (its rounding is a few ulps
/// of that). Rows (x, y, θ), columns (a3, a4, a5).
fn jacobian_and_sizes(b3: f64, b5: f64, jets: &[Jet; 6]) -> ([[f64; 3]; 3], [[f64; 3]; 3]) {
    let [s1, s2, s3, i11, i12, i22] = *jets;
    let (p3, p5) = (b3.abs(), b5.abs());
    let j = [
        [
            -(b3 * i11.v - b5 * i12.v),
            -0.5 * (b3 * b3 * i11.d - 2.0 * b3 * b5 * i12.d + b5 * b5 * i22.d),
            b3 * i12.v - b5 * i22.v,
        ],
        [s2.v, b3 * s2.d - b5 * s3.d, -s3.v],
        [s1.v, b3 * s1.d - b5 * s2.d, -s2.v],
    ];
    let size = [
        [
            p3 * i11.v.abs() + p5 * i12.v.abs(),
            0.5 * (p3 * p3 * i11.d.abs() + 2.0 * p3 * p5 * i12.d.abs() + p5 * p5 * i22.d.abs()),
            p3 * i12.v.abs() + p5 * i22.v.abs(),
        ],
        [s2.v.abs(), p3 * s2.d.abs() + p5 * s3.d.abs(), s3.v.abs()],
        [s1.v.abs(), p3 * s1.d.abs() + p5 * s2.d.abs(), s2.v.abs()],
    ];
    (j, size)
}

/// Rounding of the straight rod's functions and of the combinations that make J's entries, in
/// ulps of the sum of the combinations' absolute terms (the closed forms lose ≲ 20 ulps where
/// they meet the series, `series_and_closed_forms_agree`; ×3).
const ENTRY_ULPS: f64 = 64.0;

/// g₀(t): the σ → 0 limit of g(t) = det J(t)/(t⁹(a3²/8640 + a5²t²/33600)) (module docs), with
/// (a3, a5) entering through their ratio only, and a first-order bound on its rounding: each
/// entry's error [`ENTRY_ULPS`]·ε times the sum of its terms' magnitudes, times the
/// magnitude of its cofactor, plus the expansion's own rounding. Under a strong tension the
/// entries grow like e^{√a4 t} (the x row like e^{2√a4 t}) while det J grows slower: the
/// bound shows that cancellation.
pub(crate) fn normalised_det(a3: f64, a4: f64, a5: f64, t: f64) -> (f64, f64) {
    let (g, rounding, _) = normalised_det_sloped(a3, a4, a5, t);
    (g, rounding)
}

/// [`normalised_det`] and the slope g₀′(t): d det J/dt = det[J_x; J_y; ∂κ/∂a], since the
/// linearised rod's rows x′ = −θ·J_θ and y′ = J_θ are multiples of the θ row; κ = θ′ =
/// a3 S1′ − a5 S1 with S1′ = 1 + a4 S2 (θ'' = a4 θ − a5 and S2 = ∫S1, module docs). The slope
/// only steers the scan's samples and carries no bound.
pub(crate) fn normalised_det_sloped(a3: f64, a4: f64, a5: f64, t: f64) -> (f64, f64, f64) {
    let sigma = a3.abs().max(a5.abs());
    let (u3, u5) = (a3 / sigma, a5 / sigma);
    // The x row and the a4 column divided by σ.
    let jets = straight_jets(a4, t);
    let (j, size) = jacobian_and_sizes(u3, u5, &jets);
    let mut det = 0.0;
    let mut err = 0.0;
    for c in 0..3 {
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        let cof = j[1][c1] * j[2][c2] - j[1][c2] * j[2][c1];
        det += j[0][c] * cof;
        // First order in every entry's error: the x row's through its cofactor, the other rows'
        // through the minors they share with the x row.
        err += size[0][c] * cof.abs()
            + j[0][c].abs()
                * (size[1][c1] * j[2][c2].abs()
                    + j[1][c1].abs() * size[2][c2]
                    + size[1][c2] * j[2][c1].abs()
                    + j[1][c2].abs() * size[2][c1]);
    }
    let [s1, s2, ..] = jets;
    // ∂κ/∂a, scaled as the θ row (a4 column over σ): the θ row's t-derivative, with
    // S1′ = 1 + a4 S2 and S2′ = S1.
    let s1_slope = Jet {
        v: 1.0 + a4 * s2.v,
        d: s2.v + a4 * s2.d,
    };
    let kappa_row = [s1_slope.v, u3 * s1_slope.d - u5 * s1.d, -s1.v];
    let det_slope = crate::types::det3(&[j[0], j[1], kappa_row]);
    let n = crate::planar_det_leading_term(u3, u5, t);
    let g = det / n;
    let log_slope = crate::types::planar_det_leading_term_log_slope(u3, u5, t);
    (
        g,
        ENTRY_ULPS * f64::EPSILON * err / n,
        det_slope / n - g * log_slope,
    )
}

/// The linearised rod at some t: pose, J and first-order bounds on their rounding.
pub(crate) struct Linearised {
    /// (x, y, θ).
    pub pose: [f64; 3],
    /// ∂(x, y, θ)/∂(a3, a4, a5), rows x, y, θ.
    pub jacobian: [[f64; 3]; 3],
    /// Absolute rounding bound of the pose.
    pub pose_rounding: f64,
    /// Relative (Frobenius) rounding bound of J.
    pub jacobian_rounding: f64,
}

/// q(t) and J(t) = ∂(x, y, θ)/∂(a3, a4, a5) of the linearised rod (module docs): θ and y to
/// first order in σ, x to second (relative truncation O(Θ²) in every entry and in θ, y; O(Θ⁴)
/// absolute in x); rounding bounded by [`ENTRY_ULPS`] ulps of each combination's terms (they
/// cancel where the terms of a3 and a5 nearly balance).
pub(crate) fn pose_and_jacobian(a3: f64, a4: f64, a5: f64, t: f64) -> Linearised {
    let jets = straight_jets(a4, t);
    let [s1, s2, s3, i11, i12, i22] = jets;
    let (p3, p5) = (a3.abs(), a5.abs());
    let theta = a3 * s1.v - a5 * s2.v;
    let y = a3 * s2.v - a5 * s3.v;
    let half_q = 0.5 * (a3 * a3 * i11.v - 2.0 * a3 * a5 * i12.v + a5 * a5 * i22.v);
    let half_q_size =
        0.5 * (p3 * p3 * i11.v.abs() + 2.0 * p3 * p5 * i12.v.abs() + p5 * p5 * i22.v.abs());
    let (jacobian, size) = jacobian_and_sizes(a3, a5, &jets);
    let norm = |v: &mut dyn Iterator<Item = f64>| v.map(|e| e * e).sum::<f64>().sqrt();
    let ulp = ENTRY_ULPS * f64::EPSILON;
    let pose_size = (p3 * s1.v.abs() + p5 * s2.v.abs())
        .max(p3 * s2.v.abs() + p5 * s3.v.abs())
        .max(t + half_q_size);
    Linearised {
        pose: [t - half_q, y, theta],
        jacobian,
        pose_rounding: ulp * pose_size,
        jacobian_rounding: ulp * norm(&mut size.into_iter().flatten())
            / norm(&mut jacobian.into_iter().flatten()),
    }
}

/// ½∫₀¹κ² of the linearised rod, κ = θ' = a3 S0 − a5 S1 (S0 = cosh(wt) or cos(wt)):
/// ½(a3² I00 − 2 a3 a5 I01 + a5² I11), relative truncation O(Θ²); with a bound on its
/// relative rounding ([`ENTRY_ULPS`] ulps of its terms).
pub(crate) fn energy(a3: f64, a4: f64, a5: f64) -> (f64, f64) {
    let [i00, i01, i11] = if a4.abs() < SERIES_MAX_Z {
        let z = Jet::constant(a4);
        [
            horner(&I00, z, TERMS).v,
            horner(&I01, z, TERMS).v,
            horner(&I11, z, TERMS).v,
        ]
    } else {
        let w = a4.abs().sqrt();
        let (s, c, sign) = if a4 > 0.0 {
            (w.sinh(), w.cosh(), 1.0)
        } else {
            let (s, c) = w.sin_cos();
            (s, c, -1.0)
        };
        [
            (w + s * c) / (2.0 * w),
            sign * s * s / (2.0 * a4),
            (s * c - w) / (2.0 * w * a4),
        ]
    };
    let e = 0.5 * (a3 * a3 * i00 - 2.0 * a3 * a5 * i01 + a5 * a5 * i11);
    let size = 0.5 * (a3 * a3 * i00.abs() + 2.0 * (a3 * a5 * i01).abs() + a5 * a5 * i11.abs());
    (e, ENTRY_ULPS * f64::EPSILON * size / e.abs())
}

/// Constants of the a-priori bounds of the linearised rod's J (relative, Frobenius), tip
/// (absolute) and energy (relative) in the effective angle Θₑ ([`effective_angle`]):
/// C·Θₑ² (Θₑ³ for the tip) plus rounding. Measured against the dual-number series (J, tip) and
/// the double-double one (energy) on 6,000 nearly straight rods (a4 from 1e-6 to 1e4 of either
/// sign and 0, a3 and a5 log-scale from 1e-20 to 0.1 and 0; `small_angle_bounds_hold`):
/// J ≤ 4.2·Θₑ² and 6.1e-13, tip ≤ 0.042·Θₑ³, energy ≤ 0.086·Θₑ² and 1.5e-14; ×4 or more.
const J_C: f64 = 16.0;
const J_ROUNDING: f64 = 1e-11;
const TIP_C: f64 = 0.2;
const TIP_ROUNDING: f64 = 1e-15;
const ENERGY_C: f64 = 0.4;
const ENERGY_ROUNDING: f64 = 1e-13;

/// Θₑ = Θ·√(1 + √|a4|): the relative truncation of the expansion is O(Θ²) per wavelength, and
/// under compression the nonlinearity's O(Θ²) phase shift accumulates over the √|a4|/π
/// wavelengths of the rod.
pub(crate) fn effective_angle(a3: f64, a4: f64, a5: f64) -> f64 {
    if a4 > MAX_TENSION {
        return f64::INFINITY;
    }
    max_angle(a3, a4, a5) * (1.0 + a4.abs().sqrt()).sqrt()
}

/// Largest tension a4 of the expansion: √a4 = 350, where its x row's ∫S1² ≈ e^{2√a4}/(8a4^{3/2})
/// still fits in f64 (it overflows past √a4 ≈ 354). The truncation constants were measured
/// up to √a4 = 27 against the series, and up to 350 against the exact pendulum
/// (`scripts/references/gen_tension_truth.py`, `tests/tension.rs`: barely bent rods under tension and
/// rods at the expansion's edge, Θ from 1e-7 to 1e-2).
const MAX_TENSION: f64 = 122_500.0;

/// A-priori relative (Frobenius) truncation error of [`pose_and_jacobian`]'s J at the
/// effective angle `th` ([`effective_angle`]; add its
/// `jacobian_rounding`); infinite beyond the tension where it was measured.
pub(crate) fn jacobian_rel_error(th: f64) -> f64 {
    J_C * th * th + J_ROUNDING
}

/// A-priori absolute truncation error of [`pose_and_jacobian`]'s pose at the effective angle
/// `th` (in length units of the
/// rod and radians; add its `pose_rounding`); infinite beyond the measured tension.
pub(crate) fn tip_abs_error(th: f64) -> f64 {
    TIP_C * th * th * th + TIP_ROUNDING
}

/// A-priori relative truncation error of [`energy`] at the effective angle `th` (add its
/// rounding); infinite beyond the
/// measured tension.
pub(crate) fn energy_rel_error(th: f64) -> f64 {
    ENERGY_C * th * th + ENERGY_ROUNDING
}

/// Largest bending angle Θ of the linearised rod over [0, 1] (bounded above): |θ| ≤ |a3| S1 +
/// |a5| S2 with S1, S2 ≥ 0 increasing under tension; under compression |S1| ≤ min(t, 1/w) and
/// |S2| ≤ min(t²/2, 2/w²). Infinite (beyond the expansion) when already |a3| + |a5|/2 > 0.01
/// under tension (S1 ≥ 1, S2 ≥ ½), so that a bent rod pays no more than that test.
pub(crate) fn max_angle(a3: f64, a4: f64, a5: f64) -> f64 {
    if a4 >= 0.0 && a3.abs() + 0.5 * a5.abs() > 0.01 {
        return f64::INFINITY;
    }
    max_angle_to(a3, a4, a5, 1.0)
}

/// Largest bending angle of the linearised rod over [0, t] (bounded above, as
/// [`max_angle`] over [0, 1]): the part [0, t] of the rod is a rod of length t.
pub(crate) fn max_angle_to(a3: f64, a4: f64, a5: f64, t: f64) -> f64 {
    if a4 >= 0.0 {
        let [s1, s2, ..] = straight_jets(a4, t);
        a3.abs() * s1.v + a5.abs() * s2.v
    } else {
        let w = (-a4).sqrt();
        a3.abs() * w.recip().min(t) + a5.abs() * (2.0 / (w * w)).min(0.5 * t * t)
    }
}

// The formulation (issue 44): the expansion's answers where its a-priori bounds are within the
// tolerances asked of an answer, None elsewhere (the dispatcher then takes another formulation).

/// κ(t) = θ′ of the linearised rod, θ = a3 S1 − a5 S2 (`small_angle`): a3 S0 − a5 S1, with
/// S0 = cosh(wt), cos(wt) or 1 and S1 = sinh(wt)/w, sin(wt)/w or t (w = √|a4|) under tension,
/// compression or no axial force.
pub(super) fn curvature(a: &PlanarParams, t: f64) -> f64 {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let w = a4.abs().sqrt();
    let (s0, s1) = if a4 > 0.0 {
        ((w * t).cosh(), (w * t).sinh() / w)
    } else if a4 < 0.0 {
        let (s, c) = (w * t).sin_cos();
        (c, s / w)
    } else {
        (1.0, t)
    };
    a3 * s0 - a5 * s1
}

/// Largest a-priori error of the small-angle tip ([`tip_abs_error`]) for which it
/// is taken: 100× inside the 1e-11 the references check.
pub(super) const TIP_TOLERANCE: f64 = 1e-13;

/// q(t) and J(t) of a nearly straight rod from the small-angle expansion, where its error
/// bounds are within the closed form's tolerances (J to [`CLOSED_J_TOLERANCE`], the pose to
/// [`TIP_TOLERANCE`]); None elsewhere. It replaces the series where the closed
/// form's x row (O(σ), O(σ²)) is swamped by rounding.
pub(super) fn checked_pose_and_jacobian(
    a: &PlanarParams,
    t: f64,
) -> Option<(PlanarPose, PlanarJacobian)> {
    checked_pose_and_jacobian_at(a, t, effective_angle(a[0], a[1], a[2]))
}

/// [`checked_pose_and_jacobian`] for the rod's effective angle `th`
/// ([`effective_angle`], computed once by callers that need several answers): the
/// straight-rod linearisation, or under compression the pendulum of exact frequency
/// ([`super::pendulum`]), whose error does not grow with the number of wavelengths.
pub(super) fn checked_pose_and_jacobian_at(
    a: &PlanarParams,
    t: f64,
    th: f64,
) -> Option<(PlanarPose, PlanarJacobian)> {
    let ([x, y, theta], jacobian) =
        checked_linearised(a, t, th).or_else(|| checked_pendulum(a, t))?;
    let pose = PlanarPose::new(x, y, theta);
    let j = PlanarJacobian::from_row_slice(&jacobian.concat());
    (pose.is_finite() && j.iter().all(|v| v.is_finite())).then_some((pose, j))
}

/// (x, y, θ) and J (rows) of the straight-rod linearisation where its bounds are within the
/// tolerances (see [`checked_pose_and_jacobian`]).
fn checked_linearised(a: &PlanarParams, t: f64, th: f64) -> Option<PoseAndRows> {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let j_truncation = jacobian_rel_error(th);
    let tip_truncation = tip_abs_error(th);
    if j_truncation > CLOSED_J_TOLERANCE || tip_truncation > TIP_TOLERANCE {
        return None;
    }
    let lin = pose_and_jacobian(a3, a4, a5, t);
    (j_truncation + lin.jacobian_rounding <= CLOSED_J_TOLERANCE
        && tip_truncation + lin.pose_rounding <= TIP_TOLERANCE)
        .then_some((lin.pose, lin.jacobian))
}

/// (x, y, θ) and J (rows x, y, θ) of an expansion.
type PoseAndRows = ([f64; 3], [[f64; 3]; 3]);

/// (x, y, θ) and J (rows) of the compressed rod's pendulum where its bounds are within the
/// tolerances (see [`checked_pose_and_jacobian`]).
fn checked_pendulum(a: &PlanarParams, t: f64) -> Option<PoseAndRows> {
    let form = super::pendulum::pose_and_jacobian(a[0], a[1], a[2], t)?;
    (form.jacobian_error <= CLOSED_J_TOLERANCE && form.pose_error <= TIP_TOLERANCE)
        .then_some((form.pose, form.jacobian))
}

/// The tip of a nearly straight rod from the small-angle expansion (or, under compression,
/// the pendulum of exact frequency), where its bound is within [`TIP_TOLERANCE`].
pub(super) fn checked_tip(a: &PlanarParams) -> Option<[f64; 3]> {
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let truncation = tip_abs_error(effective_angle(a3, a4, a5));
    if truncation <= TIP_TOLERANCE {
        let lin = pose_and_jacobian(a3, a4, a5, 1.0);
        if truncation + lin.pose_rounding <= TIP_TOLERANCE && lin.pose.iter().all(|v| v.is_finite())
        {
            return Some(lin.pose);
        }
    }
    super::pendulum::tip(a3, a4, a5)
        .and_then(|(tip, error)| (error <= TIP_TOLERANCE).then_some(tip))
}

/// ½∫κ² of a nearly straight rod from the small-angle expansion, where its bound is within
/// [`crate::planar::closed::ENERGY_REL_TOLERANCE`].
pub(super) fn checked_energy(a: &PlanarParams) -> Option<f64> {
    checked_energy_at(a, effective_angle(a[0], a[1], a[2]))
}

/// [`checked_energy`] for the rod's effective angle `th` (under compression, the
/// pendulum's ½∫ψ'² where the linearisation's bound fails).
pub(super) fn checked_energy_at(a: &PlanarParams, th: f64) -> Option<f64> {
    let truncation = energy_rel_error(th);
    if truncation <= ENERGY_REL_TOLERANCE {
        let (e, rounding) = energy(a[0], a[1], a[2]);
        if truncation + rounding <= ENERGY_REL_TOLERANCE && e.is_finite() {
            return Some(e);
        }
    }
    super::pendulum::energy(a[0], a[1], a[2])
        .and_then(|(e, error)| (error <= ENERGY_REL_TOLERANCE).then_some(e))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::rng::SplitMix64;
    use crate::PlanarParams;

    /// Nearly straight rods the way users give them: a4 log-scale 1e-6..1e4 of either sign
    /// and exact 0, a3 and a5 log-scale 1e-20..0.1 and exact zeros.
    pub(crate) fn nearly_straight_sample(r: &mut SplitMix64, i: usize) -> Option<PlanarParams> {
        let a4 = if i.is_multiple_of(11) {
            0.0
        } else {
            r.signed_pow10(-6.0, 4.0)
        };
        let a3 = if i.is_multiple_of(7) {
            0.0
        } else {
            r.signed_pow10(-20.0, -1.0)
        };
        let a5 = if i.is_multiple_of(5) {
            0.0
        } else {
            r.signed_pow10(-20.0, -1.0)
        };
        (a3 != 0.0 || a5 != 0.0).then(|| PlanarParams::new(a3, a4, a5))
    }

    /// [`TERMS_FOR_Z`]: at each z_max, the neglected terms of every series of `series_jets`
    /// (value and z-derivative) stay below 2⁻⁶³ of the sums' lower bounds c₀ − c₁z and
    /// c₁ − 2c₂z (the table was bisected at 2⁻⁶⁴ in exact arithmetic), and all [`TERMS`] do
    /// at |z| = [`SERIES_MAX_Z`].
    #[test]
    fn series_terms_leave_no_tail() {
        let check = |n: usize, z: f64| {
            for c in [&S1, &S2, &S3, &I11, &I12, &I22] {
                let (mut tail_v, mut tail_d) = (0.0f64, 0.0f64);
                for (k, ck) in c.iter().enumerate().skip(n) {
                    tail_v += ck.abs() * z.powi(k as i32);
                    tail_d += k as f64 * ck.abs() * z.powi(k as i32 - 1);
                }
                let (lower_v, lower_d) = (c[0] - c[1] * z, c[1] - 2.0 * c[2] * z);
                assert!(lower_v > 0.0 && lower_d > 0.0, "n {n} z {z}");
                assert!(
                    tail_v <= 2f64.powi(-63) * lower_v && tail_d <= 2f64.powi(-63) * lower_d,
                    "n {n} z {z}: tails {tail_v:e} {tail_d:e}"
                );
            }
        };
        let mut previous = 0.0;
        for &(n, z_max) in &TERMS_FOR_Z {
            assert!(z_max > previous);
            previous = z_max;
            check(n, z_max);
        }
        check(TERMS, SERIES_MAX_Z);
    }

    /// The series and closed-form branches of the straight rod's functions agree where they
    /// meet (|z| = 4) and beyond (the series converges for every z), values and
    /// a4-derivatives, to the closed forms' loss (≲ 20 ulps at |z| = 4, ×10 allowance).
    #[test]
    fn series_and_closed_forms_agree() {
        for a4 in [4.0, -4.0, 7.5, -7.5, 12.0, -12.0] {
            for t in [1.0, 0.9] {
                let series = series_jets(a4, t);
                let closed = closed_jets(a4, t);
                for (s, c) in series.iter().zip(&closed) {
                    let tol = 200.0 * f64::EPSILON;
                    assert!((s.v - c.v).abs() <= tol * c.v.abs(), "{a4}: {s:?} vs {c:?}");
                    assert!((s.d - c.d).abs() <= tol * c.d.abs(), "{a4}: {s:?} vs {c:?}");
                }
            }
        }
    }

    /// At t → 0 g → 1 by the normalisation (docs/math.md §5), for any ratio and force.
    #[test]
    fn leading_term_normalises_to_one() {
        for (a3, a4, a5) in [(1e-6, 20.0, 3e-7), (0.0, -20.0, 1e-5), (1e-5, 0.3, 0.0)] {
            let (g, _) = normalised_det(a3, a4, a5, 1e-5);
            assert!((g - 1.0).abs() < 1e-4, "{a3} {a4} {a5}: {g}");
        }
    }
}
