//! Starts for rods under strong tension (a4 ≫ 1, |a3|, |a5| small): the rod runs straight along
//! the force and turns only in short "fronts" of width ≈ 1/√a4, full loops and a partial front
//! at the tip. There Υ depends exponentially on a3 (the front's position is ln(1/a3)/√a4), so
//! atlas seeds, which stop near |a4| ≈ 150, are almost never in Newton's basin.
//!
//! Model. With a5 = 0 the rod equation θ'' = a4 sin θ (docs/math.md §1, κ' = a4 sin θ − a5 cos θ)
//! is a pendulum about its unstable point θ = 0; for small a3 the solution stays near the
//! separatrix, where every turn is the soliton θ(t) = 4 atan(e^{k (t − c)}), k = √a4, and
//! θ' = 2k sin(θ/2). Integrating x' = cos θ, y' = sin θ through a turn gives (exact on the
//! separatrix)
//!
//! - a full loop (θ: 0 → 2π) shortens x by 4/k and leaves y unchanged;
//! - a partial front that reaches θf ∈ (0, 2π) at the tip shortens x by (2/k)(1 − cos(θf/2))
//!   and adds y = (2/k) sin(θf/2).
//!
//! So a target with n full loops and tip angle θ = 2πn + θf fixes k from its shortening
//! 1 − x = (4n + 2(1 − cos(θf/2)))/k; the tip front's centre is t_f = 1 − ln(tan(θf/4))/k.
//! Near the separatrix the turns are equally spaced, with the first at c₁ = t_f/(2n + 1) (half a
//! period from the base, where θ' = a3), and the linear growth θ ≈ (a3/2k) e^{kt} before the
//! first turn matches the soliton's tail 4 e^{k(t − c₁)}: a3 = 8k e^{−k c₁}. The target's
//! wrapped angle leaves n open: a start is made for each n whose predicted y is closest to the
//! target's, and Newton corrects what the model leaves out (a5 tilts the straight parts).

use crate::{wrap_angle, PlanarParams, PlanarPose};
use std::f64::consts::TAU;

/// Smallest k = √a4 served: below it the fronts are not thin (width 1/k ≳ 0.1) and the
/// atlas, which covers |a4| ≤ 150, has seeds.
const K_MIN: f64 = 8.0;
/// Largest k served: a4 = 4e4, beyond the strong-force family of issue 9 (|a4| ≤ 1e4), still
/// within what f64 represents (the forward map refuses √a4 > 709).
const K_MAX: f64 = 200.0;
/// Most full loops tried (each adds 4/k to the shortening).
const MAX_LOOPS: u32 = 40;

/// The start for `n` full loops and a tip front reaching `theta_f` ∈ (0, 2π), turning
/// counter-clockwise, with shortening `deficit` = 1 − x; and the model's y.
fn start(n: u32, theta_f: f64, deficit: f64) -> Option<(PlanarParams, f64)> {
    let half = 0.5 * theta_f;
    let k = (4.0 * n as f64 + 2.0 * (1.0 - half.cos())) / deficit;
    if !(K_MIN..=K_MAX).contains(&k) {
        return None;
    }
    // Tip front's centre; a front barely begun (θf → 0) sits far beyond the tip: capped so that
    // a3 stays a normal number (e^{-k c} ≥ e^{-60}).
    let t_f = (1.0 - (0.25 * theta_f).tan().ln() / k).min(1.0 + 40.0 / k);
    let c1 = t_f / (2 * n + 1) as f64;
    let a3 = 8.0 * k * (-k * c1).exp();
    let y = 2.0 / k * half.sin();
    let a = PlanarParams::new(a3, k * k, 0.0);
    (a.iter().all(|v| v.is_finite()) && a3 > 0.0).then_some((a, y))
}

/// Up to `max` starts for `target`, best predicted y first; empty where the model does not
/// apply (x ≤ 0 or ‖(x, y)‖ ≥ 1).
pub(crate) fn starts(target: &PlanarPose, max: usize) -> Vec<PlanarParams> {
    let deficit = 1.0 - target.x;
    if !(target.x > 0.0 && target.x.hypot(target.y) < 1.0 && deficit > 0.0) {
        return Vec::new();
    }
    let th = wrap_angle(target.theta);
    let mut cands: Vec<(f64, PlanarParams)> = Vec::new();
    // Counter-clockwise turns (θ increasing), and the mirror image (y, θ, a3, a5 → −).
    for mirror in [false, true] {
        let (y, th) = if mirror {
            (-target.y, -th)
        } else {
            (target.y, th)
        };
        let theta_f = th.rem_euclid(TAU);
        if !(theta_f > 1e-12 && theta_f < TAU - 1e-12) {
            continue;
        }
        for n in 0..=MAX_LOOPS {
            let Some((mut a, y_model)) = start(n, theta_f, deficit) else {
                continue;
            };
            if mirror {
                a[0] = -a[0];
            }
            // Where the model's y disagrees with the target's by more than its own size, the
            // target is not this family's (the start would only cost iterations).
            let miss = (y - y_model).abs();
            if miss <= y_model.abs().max(0.05) {
                cands.push((miss, a));
            }
        }
    }
    cands.sort_by(|p, q| p.0.total_cmp(&q.0));
    cands.into_iter().take(max).map(|(_, a)| a).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model recovers a4 and the front-setting combination δ = a3/k − a5/a4 (θ ≈ δ/2·e^{kt}
    /// before the first turn, so a5 = 0 in the start is no loss) of strong-tension rods, to the
    /// accuracy of the separatrix approximation: 10 % in a4, a factor e² in δ.
    #[test]
    fn recovers_looped_and_tip_bent_rods() {
        for a in [
            // Two loops and half a third (θ ≈ 5π).
            PlanarParams::new(0.00528, 3230.0, -0.000897),
            // One tip front (θ ≈ −2.4), no loop.
            PlanarParams::new(-3.25e-6, 152.0, 0.00366),
            PlanarParams::new(1.67e-5, 187.0, -3.45e-5),
        ] {
            let b = crate::planar::entry::tip(&a).unwrap();
            let s = starts(&b, 4);
            assert!(
                s.iter().any(|g| {
                    let delta = a[0] / a[1].sqrt() - a[2] / a[1];
                    let delta_g = g[0] / g[1].sqrt();
                    (g[1] / a[1] - 1.0).abs() < 0.1
                        && delta * delta_g > 0.0
                        && (delta_g.abs().ln() - delta.abs().ln()).abs() < 2.0
                }),
                "{a:?}: {s:?}"
            );
        }
    }
}
