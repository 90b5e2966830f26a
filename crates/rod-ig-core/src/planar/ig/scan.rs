//! A fast stability pre-scan by fixed-step RK4 on the planar rod and its variational equations.
//!
//! The planar Kirchhoff rod (paper eq. 2.9, docs/math.md §1) reduces to a forced pendulum in the
//! tangent angle: θ' = κ, κ' = μ3' = −μ5 = a4 sin θ − a5 cos θ, x' = cos θ, y' = sin θ, with
//! θ(0) = 0, κ(0) = a3. Its variational equations give J(t, a) = ∂(x, y, θ)(t)/∂(a3, a4, a5)
//! at every step, hence det J(t) on the whole step grid at the cost of one integration.
//!
//! This is used where the solver needs many stability verdicts cheaply (the atlas build and
//! the trust-region iterations); the final verdict on a returned solution comes from the
//! closed-form test (`planar::stability`, docs/math.md §5) whenever this scan is not conclusive.
//! cos θ and sin θ are integrated as a unit vector (renormalised after every step) so that the
//! right-hand side needs no transcendental function.

use crate::{PlanarJacobian, PlanarParams, PlanarPose};

/// State: c, s, κ, x, y, then for j = 0..3 (a3, a4, a5): δθ, δκ, δx, δy; then θ (unwrapped).
const DIM: usize = 18;

#[inline]
fn rhs(a4: f64, a5: f64, y: &[f64; DIM], d: &mut [f64; DIM]) {
    let c = y[0];
    let s = y[1];
    let k = y[2];
    d[0] = -s * k;
    d[1] = c * k;
    d[2] = a4 * s - a5 * c;
    d[3] = c;
    d[4] = s;
    let g = a4 * c + a5 * s;
    // j = 0: derivative w.r.t. a3 (no explicit forcing)
    for j in 0..3 {
        let o = 5 + 4 * j;
        let dth = y[o];
        d[o] = y[o + 1];
        d[o + 1] = g * dth
            + match j {
                1 => s,
                2 => -c,
                _ => 0.0,
            };
        d[o + 2] = -s * dth;
        d[o + 3] = c * dth;
    }
    d[17] = k;
}

/// J(t) from the state, rows (x, y, θ), columns (a3, a4, a5).
#[inline]
fn jac_of(y: &[f64; DIM]) -> PlanarJacobian {
    let mut j = PlanarJacobian::zeros();
    for c in 0..3 {
        let o = 5 + 4 * c;
        j[(0, c)] = y[o + 2];
        j[(1, c)] = y[o + 3];
        j[(2, c)] = y[o];
    }
    j
}

/// Result of one RK4 scan.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scan {
    /// No sign change or zero of det J(t) was seen at the scanned steps t ≥ `T_MIN`.
    pub stable: bool,
    /// First scanned t with det J(t) ≤ 0, when unstable.
    pub first_conjugate_t: Option<f64>,
}

/// Smallest t at which the sign of det J(t) is trusted (docs/math.md §5: below ~0.02 rounding
/// swamps det J, and a conjugate point that early needs |a| far outside any practical range).
const T_MIN: f64 = crate::STABILITY_T_MIN;

/// Number of RK4 steps for parameters `a`: about `per_rad` steps per radian of the fastest
/// local frequency (max curvature √α3 and pendulum frequency √F), bounded.
pub(crate) fn steps_for(a: &PlanarParams, per_rad: f64) -> usize {
    let f = a[1].hypot(a[2]);
    let alpha3 = (a[0] * a[0] + 2.0 * (a[1] + f)).max(0.0);
    let w = alpha3.sqrt().max(f.sqrt()).max(a[0].abs());
    let n = (w * per_rad).ceil();
    if n.is_finite() {
        (n as usize).clamp(40, 20_000)
    } else {
        20_000
    }
}

/// Integrates the rod and its variational equations over [0, 1] with `n` RK4 steps and calls
/// `visit(t, x, y, θ, J(t), det J(t))` after every step (θ unwrapped); stops early when `visit`
/// returns false. Returns the final state's tip and J, or `None` on non-finite input or values.
pub(crate) fn integrate<V>(
    a: &PlanarParams,
    n: usize,
    mut visit: V,
) -> Option<(PlanarPose, PlanarJacobian)>
where
    V: FnMut(f64, f64, f64, f64, &PlanarJacobian, f64) -> bool,
{
    if !(a[0].is_finite() && a[1].is_finite() && a[2].is_finite()) {
        return None;
    }
    let n = n.clamp(1, 20_000);
    let (a3, a4, a5) = (a[0], a[1], a[2]);
    let mut y = [0.0; DIM];
    y[0] = 1.0;
    y[2] = a3;
    y[5 + 1] = 1.0; // δκ/δa3 = 1 at t = 0
    let h = 1.0 / n as f64;
    let (mut k1, mut k2, mut k3, mut k4) = ([0.0; DIM], [0.0; DIM], [0.0; DIM], [0.0; DIM]);
    let mut tmp = [0.0; DIM];
    for i in 0..n {
        rhs(a4, a5, &y, &mut k1);
        for q in 0..DIM {
            tmp[q] = y[q] + 0.5 * h * k1[q];
        }
        rhs(a4, a5, &tmp, &mut k2);
        for q in 0..DIM {
            tmp[q] = y[q] + 0.5 * h * k2[q];
        }
        rhs(a4, a5, &tmp, &mut k3);
        for q in 0..DIM {
            tmp[q] = y[q] + h * k3[q];
        }
        rhs(a4, a5, &tmp, &mut k4);
        for q in 0..DIM {
            y[q] += h / 6.0 * (k1[q] + 2.0 * (k2[q] + k3[q]) + k4[q]);
        }
        let r = (y[0] * y[0] + y[1] * y[1]).sqrt();
        if !(r.is_finite() && r > 0.0) {
            return None;
        }
        y[0] /= r;
        y[1] /= r;
        let t = (i + 1) as f64 * h;
        let jac = jac_of(&y);
        let det = jac.determinant();
        if !det.is_finite() {
            return None;
        }
        if !visit(t, y[3], y[4], y[17], &jac, det) {
            break;
        }
    }
    if !y.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some((PlanarPose::new(y[3], y[4], y[17]), jac_of(&y)))
}

/// Integrates the rod and its variational equations over [0, 1] with `n` RK4 steps, checking
/// the sign of det J(t) at every step t ≥ 0.02 (docs/math.md §5 rule), stopping at the first
/// non-positive value. Returns `None` on non-finite input or values.
pub(crate) fn scan(a: &PlanarParams, n: usize) -> Option<Scan> {
    let mut first_conjugate_t = None;
    integrate(a, n, |t, _, _, _, _, det| {
        if t >= T_MIN && det <= 0.0 {
            first_conjugate_t = Some(t);
            return false;
        }
        true
    })?;
    Some(Scan {
        stable: first_conjugate_t.is_none(),
        first_conjugate_t,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_tip() {
        // a = (a3, 0, 0): a circle of curvature a3.
        let a = PlanarParams::new(1.3, 0.0, 0.0);
        let (tip, _) = integrate(&a, 400, |_, _, _, _, _, _| true).unwrap();
        assert!(scan(&a, 400).unwrap().stable);
        assert!((tip.x - (1.3f64).sin() / 1.3).abs() < 1e-10);
        assert!((tip.y - 2.0 * (0.65f64).sin().powi(2) / 1.3).abs() < 1e-10);
        assert!((tip.theta - 1.3).abs() < 1e-10);
    }

    #[test]
    fn euler_load() {
        // docs/math.md §5: (0, −40, 1) loses stability at t = 0.9935.
        let s = scan(&PlanarParams::new(0.0, -40.0, 1.0), 400).unwrap();
        assert!(!s.stable);
        let s = scan(&PlanarParams::new(0.0, -38.0, 1.0), 400).unwrap();
        assert!(s.stable);
    }
}
