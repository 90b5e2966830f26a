//! Parameter samples of the families of issue 9 next to the paper's uniform box: the regime a
//! cable lives in (gently bent, nearly straight), tiny parameters and strong axial force,
//! drawn with log-scale magnitudes and random signs (`rod-ig bench --only tails`, profiling).

use crate::SplitMix64;
use rod_ig_core::{PlanarParams, PlanarPose};
use std::f64::consts::PI;

/// ±10^u with u uniform in [lo, hi] and a random sign ([`SplitMix64::signed_pow10`]).
pub fn signed_pow10(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    rng.signed_pow10(lo, hi)
}

/// `n` parameters per sample, seeded (the same every run): the uniform box
/// (|a3| ≤ 10, |a4|, |a5| ≤ 100), issue 9's log-scale families and issue 23's near-circles
/// (a moment with a tiny force) and nearly straight rods under a moderate force.
pub fn samples(n: usize) -> Vec<(&'static str, Vec<PlanarParams>)> {
    let mut rng = SplitMix64::new(9);
    let mut gen = |f: &mut dyn FnMut(&mut SplitMix64) -> PlanarParams| {
        (0..n).map(|_| f(&mut rng)).collect::<Vec<_>>()
    };
    vec![
        (
            "uniform box",
            gen(&mut |r| {
                PlanarParams::new(
                    r.range(-10.0, 10.0),
                    r.range(-100.0, 100.0),
                    r.range(-100.0, 100.0),
                )
            }),
        ),
        (
            "log-scale",
            gen(&mut |r| {
                PlanarParams::new(
                    signed_pow10(r, -8.0, 0.7),
                    signed_pow10(r, -9.0, 1.5),
                    signed_pow10(r, -9.0, 1.5),
                )
            }),
        ),
        (
            "tiny (1e-60..1e-6)",
            gen(&mut |r| {
                PlanarParams::new(
                    signed_pow10(r, -60.0, -6.0),
                    signed_pow10(r, -60.0, -6.0),
                    signed_pow10(r, -60.0, -6.0),
                )
            }),
        ),
        (
            "strong force (|a4| 1e2..1e4)",
            gen(&mut |r| {
                PlanarParams::new(
                    signed_pow10(r, -6.0, 0.0),
                    signed_pow10(r, 2.0, 4.0),
                    signed_pow10(r, -6.0, 0.0),
                )
            }),
        ),
        (
            "near-circles (rho .3..2, F 1e-12..1e-2)",
            gen(&mut |r| {
                PlanarParams::new(
                    signed_pow10(r, -0.52, 0.3),
                    signed_pow10(r, -12.0, -2.0),
                    signed_pow10(r, -12.0, -2.0),
                )
            }),
        ),
        (
            "nearly straight (|a4| 15..30)",
            gen(&mut |r| {
                PlanarParams::new(
                    signed_pow10(r, -8.0, -3.0),
                    signed_pow10(r, 1.18, 1.48),
                    signed_pow10(r, -8.0, -3.0),
                )
            }),
        ),
    ]
}

/// A stable, loop-free long cable (issue 51) and its tip: w = 10^U(log 200, 4), gravity along
/// −y for half and anywhere for the rest; a3 = ±10^U(0, 2) with 5 % zeros, n(0) = s w ĝ +
/// 10^U(0, log w) in a random direction, s = U(0, 1); the rod's node states integrated from the
/// base, kept when stable by the second variation, loop-free, not crossing itself and
/// |tip| ≤ 0.98 (θ wrapped). `None` for a draw that is not kept.
pub fn long_cable(
    r: &mut SplitMix64,
) -> Option<(
    rod_ig_core::planar::heavy::Gravity,
    PlanarParams,
    PlanarPose,
)> {
    use rod_ig_core::planar::heavy::cable::Cable;
    use rod_ig_core::planar::heavy::Gravity;
    let w = 10f64.powf(r.range(200f64.log10(), 4.0));
    let dir = if r.next_u64().is_multiple_of(2) {
        [0.0, -1.0]
    } else {
        let phi = r.range(-std::f64::consts::PI, std::f64::consts::PI);
        [phi.cos(), phi.sin()]
    };
    let g = Gravity::new(w, dir).ok()?;
    let sign = |r: &mut SplitMix64| {
        if r.next_u64().is_multiple_of(2) {
            1.0
        } else {
            -1.0
        }
    };
    let a3 = if r.next_u64().is_multiple_of(20) {
        0.0
    } else {
        sign(r) * 10f64.powf(r.range(0.0, 2.0))
    };
    let share = r.range(0.0, 1.0);
    let (psi, mag) = (
        r.range(-std::f64::consts::PI, std::f64::consts::PI),
        10f64.powf(r.range(0.0, w.log10())),
    );
    let l = g.load();
    let a = PlanarParams::new(
        a3,
        share * l[0] + mag * psi.cos(),
        share * l[1] + mag * psi.sin(),
    );
    let c = Cable::from_params(&a, &g).ok()?;
    let tip = c.tip().ok()?;
    let ok = tip.x.hypot(tip.y) <= 0.98
        && c.second_variation().ok()?.stable()
        && c.turns().ok()? == 0
        && !c.self_intersects().ok()?;
    ok.then(|| {
        (
            g,
            a,
            PlanarPose::new(tip.x, tip.y, rod_ig_core::wrap_angle(tip.theta)),
        )
    })
}

/// `n` long cables drawn by [`long_cable`] from `seed` (the same every run).
pub fn long_cables(
    n: usize,
    seed: u64,
) -> Vec<(
    rod_ig_core::planar::heavy::Gravity,
    PlanarParams,
    rod_ig_core::PlanarPose,
)> {
    let mut r = SplitMix64::new(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        out.extend(long_cable(&mut r));
    }
    out
}

/// A stable 3-D long cable and its tip, or None where the draw is not one (issue 51, item 5):
/// a planar long cable of [`long_cable`] (w = 10^U(log 200, 4), its node states integrated from
/// the base, stable, loop-free) posed in a plane turned by U(−π, π) about the base tangent,
/// then carried by the 3-D multiple shooting out of that plane to a target moved by up to 0.2
/// in position (|tip| ≤ 0.98) and 0.4 rad in orientation, in random directions; kept when the
/// 3-D rod reached is stable (`SpatialCable::stability`, out of the plane too).
#[allow(clippy::type_complexity)]
pub fn long_cable_3d(
    r: &mut SplitMix64,
) -> Option<(
    rod_ig_core::spatial::SpatialParams,
    rod_ig_core::spatial::heavy::Gravity3,
    rod_ig_core::spatial::SpatialPose,
)> {
    use nalgebra::{Rotation3, Unit, UnitQuaternion, Vector3};
    use rod_ig_core::planar::heavy::cable::Cable;
    use rod_ig_core::spatial::cable::SpatialCable;
    use rod_ig_core::spatial::heavy::Gravity3;
    use rod_ig_core::spatial::{SpatialParams, SpatialPose, Stiffness};
    let unit = |r: &mut SplitMix64| loop {
        let v = Vector3::new(r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-1.0, 1.0));
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    };
    let (g2, a2, _) = long_cable(r)?;
    let planar = Cable::from_params(&a2, &g2).ok()?;
    let turn = Rotation3::from_axis_angle(&Vector3::x_axis(), r.range(-PI, PI));
    let normal = Unit::new_normalize(turn * Vector3::z());
    let lift = |n: &[f64; 4]| {
        (
            UnitQuaternion::from_axis_angle(&normal, n[2]),
            turn * Vector3::new(n[0], n[1], 0.0),
        )
    };
    let poses: Vec<_> = planar.nodes().iter().map(lift).collect();
    let (m, f) = (
        turn * Vector3::new(0.0, 0.0, a2[0]),
        turn * Vector3::new(a2[1], a2[2], 0.0),
    );
    let a = SpatialParams::new(m.x, m.y, m.z, f.x, f.y, f.z);
    let gd = turn * Vector3::new(g2.direction()[0], g2.direction()[1], 0.0);
    let g = Gravity3::new(g2.weight(), [gd.x, gd.y, gd.z]).ok()?;
    let k = Stiffness::default();
    let mut cable = SpatialCable::from_poses(&a, &k, &g, planar.mesh().to_vec(), &poses).ok()?;
    let tip2 = planar.tip().ok()?;
    let (rotation, position) = lift(&[tip2.x, tip2.y, tip2.theta, 0.0]);
    let from = SpatialPose { position, rotation };
    let to = SpatialPose {
        position: position + unit(r) * r.range(0.0, 0.2),
        rotation: UnitQuaternion::from_scaled_axis(unit(r) * r.range(0.0, 0.4)) * rotation,
    };
    if to.position.norm() > 0.98 {
        return None;
    }
    cable.carry(&from, &to).ok()?;
    if !cable.stability().ok()?.stable {
        return None;
    }
    Some((cable.params(), g, to))
}
