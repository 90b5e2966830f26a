//! Circles of any curvature (a = (c, 0, 0)): forward (`evaluate`) and shape (`PlanarRod`)
//! answer the same rods, and right (issue 42, item 2: forward refused c ≳ 2e6 after ~0.1 s of
//! a Taylor series that could not reach the tip, while shape drew the exact circle).
//!
//! Reference: the exact circle x = sin c/c, y = (1 − cos c)/c, θ = c, and J from the
//! linearisation δκ′ = δa4 sin θ0 − δa5 cos θ0 about θ0 = c t (elementary integrals, written
//! for |c| ≥ 1 where they do not cancel). Tolerances: the tip within 1e-12 relative to 1/|c|
//! (sin and cos of an exact f64 argument are correctly rounded to ~1 ulp); each column of J
//! within 1e-8 of its own norm (the contract's J accuracy is 1e-8 relative).
use rod_ig_core::planar::{self, PlanarRod};
use rod_ig_core::rng::SplitMix64;
use rod_ig_core::{PlanarParams, StabilityVerdict};

/// Exact tip and J (rows x, y, θ; columns a3, a4, a5) of the circle of curvature c.
fn exact(c: f64) -> ([f64; 3], [[f64; 3]; 3]) {
    let (s, co) = c.sin_cos();
    let c2 = c * c;
    let (s2, one_minus) = ((2.0 * c).sin(), 1.0 - co);
    let tip = [s / c, one_minus / c, c];
    // ∫ t sin(ct), ∫ sin², ∫ t cos(ct), ∫ sin cos, ∫ sin, ∫ cos, ∫ cos² over [0, 1].
    let a = (s - c * co) / c2;
    let b = 0.5 - s2 / (4.0 * c);
    let cc = (co + c * s - 1.0) / c2;
    let d = s * s / (2.0 * c);
    let (e, f, h) = (one_minus / c, s / c, 0.5 + s2 / (4.0 * c));
    let j = [
        [co / c - s / c2, -(a / c - b / c2), (e - d) / c2],
        [s / c - one_minus / c2, cc / c - d / c2, -(f - h) / c2],
        [1.0, 1.0 / c - s / c2, -one_minus / c2],
    ];
    (tip, j)
}

#[test]
fn circles_of_any_curvature_are_answered_by_forward_and_shape_alike() {
    let mut r = SplitMix64::new(42);
    let mut curvatures: Vec<f64> = vec![1.0, 3e6, 1e7, 1e8, 1e12];
    curvatures.extend((0..60).map(|_| 10f64.powf(r.range(0.0, 12.0))));
    for (i, c) in curvatures.into_iter().enumerate() {
        let c = if i % 2 == 1 { -c } else { c };
        let a = PlanarParams::new(c, 0.0, 0.0);
        let e = planar::evaluate(&a).unwrap_or_else(|e| panic!("forward refused {a:?}: {e}"));
        let rod = PlanarRod::new(&a).unwrap_or_else(|e| panic!("shape refused {a:?}: {e}"));
        let (tip, j) = exact(c);
        let scale = 1.0 / c.abs();
        for (got, want) in [
            (e.tip.x, tip[0]),
            (e.tip.y, tip[1]),
            (rod.tip().x, tip[0]),
            (rod.tip().y, tip[1]),
        ] {
            assert!(
                (got - want).abs() <= 1e-12 * scale,
                "{a:?}: tip {got} vs {want}"
            );
        }
        assert!(
            (e.tip.theta - c).abs() <= 1e-15 * c.abs()
                && (rod.tip().theta - c).abs() <= 1e-15 * c.abs()
        );
        let columns: [[f64; 3]; 3] = std::array::from_fn(|col| std::array::from_fn(|k| j[k][col]));
        for (col, want) in columns.iter().enumerate() {
            let norm = want.iter().map(|v| v * v).sum::<f64>().sqrt();
            let err = want
                .iter()
                .enumerate()
                .map(|(k, v)| (e.jacobian[(k, col)] - v).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(
                err <= 1e-8 * norm,
                "{a:?}: J column {col} off by {:.1e} relative",
                err / norm
            );
        }
        // No conjugate point on a circle (Sachkov 2008): stable, and certain.
        assert_eq!(e.stability.verdict(), StabilityVerdict::Stable, "{a:?}");
    }
}
