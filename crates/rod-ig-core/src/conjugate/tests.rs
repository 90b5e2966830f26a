//! The scan's kit on functions with known roots and minima.

use super::minimum::refine_min;
use super::root::{bisect_root, ROOT_TOL};
use super::{find_root, golden_min, Probe};

/// [`find_root`] and [`refine_min`] on functions with known roots and minima: with slopes
/// the root comes within [`ROOT_TOL`] past the true one in at most 5 samples from a bracket
/// of 0.1, and the minimum to 1e-10 of g; without slopes (the regula falsi, parabolic
/// steps) the same answers to their own tolerances; non-finite values end in the regula
/// falsi without a panic.
#[test]
fn root_and_minimum_from_slopes() {
    use std::cell::Cell;
    let calls = Cell::new(0);
    // g = e^{−3t} − e^{−1.5}: root at 0.5, slope −3e^{−3t}.
    let g = |t: f64| {
        calls.set(calls.get() + 1);
        Probe {
            v: (-3.0 * t).exp() - (-1.5f64).exp(),
            d: -3.0 * (-3.0 * t).exp(),
        }
    };
    for (t0, t1) in [
        (0.45, 0.55),
        (0.41, 0.51),
        (0.499_999_99, 0.6),
        (0.3, 0.500_000_05),
    ] {
        calls.set(0);
        let root = find_root(&g, (t0, g(t0)), (t1, g(t1)));
        assert!(root >= 0.5 && root - 0.5 <= ROOT_TOL, "{t0}..{t1}: {root}");
        assert!(calls.get() <= 2 + 5, "{t0}..{t1}: {} samples", calls.get());
        let values = |t: f64| Probe {
            d: f64::NAN,
            ..g(t)
        };
        let root = find_root(&values, (t0, values(t0)), (t1, values(t1)));
        assert!(
            root >= 0.5 && root - 0.5 <= ROOT_TOL,
            "{t0}..{t1}: {root} (no slopes)"
        );
    }
    // Non-finite values inside the bracket: no panic, a point of the bracket.
    let wild = |t: f64| Probe {
        v: if (t - 0.5).abs() < 0.01 {
            f64::NEG_INFINITY
        } else {
            0.5 - t
        },
        d: -1.0,
    };
    let root = find_root(&wild, (0.4, wild(0.4)), (0.6, wild(0.6)));
    assert!((0.4..=0.6).contains(&root), "{root}");
    // A minimum of g = 1 − cos 3(t − 0.31) + 0.05 (t − 0.31)³ bracketed by 0.2, 0.3, 0.4.
    let bowl = |t: f64| {
        let x = t - 0.31;
        Probe {
            v: 1.0 - (3.0 * x).cos() + 0.05 * x.powi(3),
            d: 3.0 * (3.0 * x).sin() + 0.15 * x * x,
        }
    };
    let dense_min = (0..=200_000)
        .map(|k| bowl(0.2 + 0.2 * f64::from(k) / 200_000.0).v)
        .fold(f64::INFINITY, f64::min);
    let (a, b, c) = ((0.2, bowl(0.2)), (0.3, bowl(0.3)), (0.4, bowl(0.4)));
    let sloped = refine_min(&bowl, a, b, c);
    assert!((sloped.0 - 0.31).abs() < 1e-4, "{sloped:?}");
    assert!(
        sloped.1.v <= dense_min + 1e-10,
        "{sloped:?} against {dense_min}"
    );
    let values = |t: f64| Probe {
        d: f64::NAN,
        ..bowl(t)
    };
    let (a, b, c) = ((0.2, values(0.2)), (0.3, values(0.3)), (0.4, values(0.4)));
    let plain = refine_min(&values, a, b, c);
    assert!(
        plain.1.v <= dense_min + 1e-8,
        "{plain:?} against {dense_min}"
    );
}

/// Golden section and bisection, the kit's value-only tools (the heavy rod's polynomial, the
/// 3-D rod's dense output): a minimum to 1e-5 of its bracket, a root to the tolerance asked
/// from the side where g ≤ 0.
#[test]
fn golden_and_bisection() {
    let f = |t: f64| (t - 0.37).powi(2) + 0.1;
    let m = golden_min(&f, 0.2, 0.5);
    assert!((m - 0.37).abs() < 1e-5 * 0.3, "{m}");
    let g = |t: f64| 0.61 - t;
    let r = bisect_root(&g, 0.5, 0.7, 1e-12, 64);
    assert!(r >= 0.61 && r - 0.61 <= 1e-12, "{r}");
    // A degenerate bracket returns its end.
    assert_eq!(bisect_root(&g, 0.7, 0.7, 1e-12, 64), 0.7);
}
