//! Starts for targets near full extension (‖(x, y)‖ → 1), reachable only by nearly straight
//! rods, often under strong tension near the separatrix λ4 = 0, where Υ is so anisotropic that
//! atlas seeds rarely fall in Newton's basin.
//!
//! Small-angle model of the rod equation θ'' = κ' = a4 sin θ − a5 cos θ (FINDINGS §1) about the
//! straight rod: θ'' = T θ − a5 with T = a4, θ(0) = 0, θ'(0) = a3. With c = a5/T and k = √|T|,
//! - tension (T > 0): θ(t) = c (1 − cosh kt) + (a3/k) sinh kt,
//! - compression (T < 0): θ(t) = c (1 − cos kt) + (a3/k) sin kt,
//!
//! and y(1) ≈ ∫θ, x(1) ≈ 1 − ½∫θ². For each T, (c, a3) follow from (y, θ) of the target by a
//! 2×2 linear solve; T is then chosen so that ½∫θ² matches the target's deficit 1 − x (a scan in
//! log k and bisection). Each root gives a start a = (a3, T, c T) that Newton refines.

use crate::{wrap_angle, PlanarParams, PlanarPose};

/// θ(t) of the small-angle model.
#[inline]
fn theta(t: f64, k: f64, tension: bool, c: f64, a3: f64) -> f64 {
    let kt = k * t;
    if tension {
        c * (1.0 - kt.cosh()) + a3 / k * kt.sinh()
    } else {
        c * (1.0 - kt.cos()) + a3 / k * kt.sin()
    }
}

/// (c, a3) such that the model meets y(1) = y, θ(1) = th.
fn coefficients(k: f64, tension: bool, y: f64, th: f64) -> Option<(f64, f64)> {
    let (m11, m12, m21, m22) = if tension {
        let (s, ch) = (k.sinh(), k.cosh());
        (1.0 - s / k, (ch - 1.0) / (k * k), 1.0 - ch, s / k)
    } else {
        let (s, co) = (k.sin(), k.cos());
        (1.0 - s / k, (1.0 - co) / (k * k), 1.0 - co, s / k)
    };
    let det = m11 * m22 - m12 * m21;
    if !(det.is_finite() && det.abs() > 1e-300) {
        return None;
    }
    let c = (y * m22 - m12 * th) / det;
    let a3 = (m11 * th - m21 * y) / det;
    (c.is_finite() && a3.is_finite()).then_some((c, a3))
}

/// ½∫₀¹θ² by composite Simpson (resolves boundary layers of width 1/k for k ≤ 100).
fn half_energy(k: f64, tension: bool, c: f64, a3: f64) -> f64 {
    const N: usize = 256;
    let h = 1.0 / N as f64;
    let mut s = 0.0;
    for i in 0..=N {
        let th = theta(i as f64 * h, k, tension, c, a3);
        let w = if i == 0 || i == N {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        s += w * th * th;
    }
    0.5 * s * h / 3.0
}

/// Deficit mismatch g(k) = ½∫θ² − (1 − x) for the model at k, and the start it gives.
fn mismatch(k: f64, tension: bool, y: f64, th: f64, deficit: f64) -> Option<(f64, PlanarParams)> {
    let (c, a3) = coefficients(k, tension, y, th)?;
    let g = half_energy(k, tension, c, a3) - deficit;
    let t = if tension { k * k } else { -k * k };
    let a = PlanarParams::new(a3, t, c * t);
    (g.is_finite() && a.iter().all(|v| v.is_finite())).then_some((g, a))
}

/// Up to `max` starts for a target near full extension (distance > 0.9, small tip angle), in
/// the order found (compression branch first, then tension by increasing T).
pub(crate) fn starts(target: &PlanarPose, max: usize) -> Vec<PlanarParams> {
    let mut out = Vec::new();
    let r = target.x.hypot(target.y);
    let th = wrap_angle(target.theta);
    if !(r > 0.9 && r < 1.0 && target.x > 0.0 && th.abs() < 1.2) {
        return out;
    }
    let (y, deficit) = (target.y, 1.0 - target.x);
    // Compression: k ∈ [0.05, 2π·0.999] (beyond, the straight rod is past its first
    // clamped–clamped Euler load); tension: k ∈ [0.05, 100], log-spaced.
    for tension in [false, true] {
        let (k_lo, k_hi): (f64, f64) = if tension {
            (0.05, 100.0)
        } else {
            (0.05, 0.999 * std::f64::consts::TAU)
        };
        const M: usize = 48;
        let ratio = (k_hi / k_lo).ln() / M as f64;
        let mut prev: Option<(f64, f64)> = None;
        for i in 0..=M {
            let k = k_lo * (ratio * i as f64).exp();
            let Some((g, _)) = mismatch(k, tension, y, th, deficit) else {
                prev = None;
                continue;
            };
            if let Some((k0, g0)) = prev {
                if (g0 <= 0.0) != (g <= 0.0) {
                    // Bisection in log k.
                    let (mut lo, mut hi, mut glo) = (k0.ln(), k.ln(), g0);
                    for _ in 0..30 {
                        let mid = 0.5 * (lo + hi);
                        match mismatch(mid.exp(), tension, y, th, deficit) {
                            Some((gm, _)) if (gm <= 0.0) == (glo <= 0.0) => {
                                lo = mid;
                                glo = gm;
                            }
                            Some(_) => hi = mid,
                            None => break,
                        }
                    }
                    if let Some((_, a)) = mismatch((0.5 * (lo + hi)).exp(), tension, y, th, deficit)
                    {
                        out.push(a);
                        if out.len() >= max {
                            return out;
                        }
                    }
                }
            }
            prev = Some((k, g));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_tensioned_and_compressed_rods() {
        // Nearly straight rods: strong tension (hypersensitive, near the separatrix) and
        // moderate compression.
        for a in [
            PlanarParams::new(0.21379433849032559, 73.60275354814638, 1.8243287658602725),
            PlanarParams::new(0.1, -5.0, 0.1),
            PlanarParams::new(0.3, -20.0, 1.0),
        ] {
            let b = crate::planar::tip(&a).unwrap();
            let s = starts(&b, 4);
            // One start within ~25 % of a (small-angle model).
            assert!(
                s.iter().any(|g| (g - a).norm() < 0.25 * a.norm()),
                "{a:?}: {s:?}"
            );
        }
    }
}
