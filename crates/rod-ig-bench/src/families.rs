//! Parameter samples of the families of issue 9 next to the paper's uniform box: the regime a
//! cable lives in (gently bent, nearly straight), tiny parameters and strong axial force,
//! drawn with log-scale magnitudes and random signs (`rod-ig bench --only tails`, profiling).

use crate::SplitMix64;
use rod_ig_core::PlanarParams;

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
