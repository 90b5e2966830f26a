//! The planar ODE reference against the shared oracle (all of `cases_public.jsonl`), and the
//! integrators on problems with known solutions.

use nalgebra::{Matrix3, Vector3};
use rod_ig_core::ode::{self, planar_reference as pr, OdeError, OdeOptions};
use std::ops::ControlFlow;

mod common;
use common::oracle_file;

struct Case {
    a: Vector3<f64>,
    tip: [f64; 3], // θ, x, y
    jac: [[f64; 3]; 3],
    stable: bool,
    energy: f64,
    det_min: f64,
}

fn load_cases() -> Vec<Case> {
    let path = oracle_file("cases_public.jsonl");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).expect("oracle line is JSON");
            let f = |x: &serde_json::Value| x.as_f64().expect("number");
            let a = &v["a"];
            let jac = &v["jac"];
            Case {
                a: Vector3::new(f(&a[0]), f(&a[1]), f(&a[2])),
                tip: [f(&v["tip"][0]), f(&v["tip"][1]), f(&v["tip"][2])],
                jac: std::array::from_fn(|r| std::array::from_fn(|c| f(&jac[r][c]))),
                stable: v["stable"].as_bool().expect("bool"),
                energy: f(&v["energy"]),
                det_min: f(&v["det_min"]),
            }
        })
        .collect()
}

/// Oracle J (rows θ, x, y) reordered to rows x, y, θ.
fn oracle_jac(c: &Case) -> Matrix3<f64> {
    let j = &c.jac;
    Matrix3::from_fn(|r, col| j[[1, 2, 0][r]][col])
}

#[test]
fn oracle_tip_jacobian_energy() {
    let cases = load_cases();
    assert_eq!(cases.len(), 2000, "expected 2000 oracle cases");
    let (mut e_tip, mut e_jac, mut e_en) = (0.0f64, 0.0f64, 0.0f64);
    for c in &cases {
        let (p, j) = pr::tip_and_jacobian(&c.a, 1e-12).expect("integrates");
        let et = (p.theta - c.tip[0])
            .abs()
            .max((p.x - c.tip[1]).abs())
            .max((p.y - c.tip[2]).abs());
        let oj = oracle_jac(c);
        let ej = (j - oj).amax() / oj.amax().max(1e-300);
        let en = pr::energy(&c.a, 1e-12).expect("energy");
        let ee = (en - c.energy).abs() / c.energy.abs().max(1.0);
        assert!(et < 1e-10, "tip error {et:e} at a = {:?}", c.a);
        assert!(ej < 1e-9, "J rel error {ej:e} at a = {:?}", c.a);
        assert!(ee < 1e-10, "energy rel error {ee:e} at a = {:?}", c.a);
        e_tip = e_tip.max(et);
        e_jac = e_jac.max(ej);
        e_en = e_en.max(ee);
    }
    println!("oracle: max tip err {e_tip:e}, max J rel err {e_jac:e}, max energy rel err {e_en:e}");
}

#[test]
fn oracle_stability_verdicts() {
    let cases = load_cases();
    let mut mismatches = Vec::new();
    let mut e_margin = 0.0f64;
    for c in &cases {
        let r = pr::stability(&c.a).expect("stability");
        if r.stable != c.stable {
            mismatches.push((c.a, r, c.det_min));
        }
        if r.stable {
            assert!(r.margin > 0.0);
            e_margin = e_margin.max((r.margin - c.det_min).abs() / c.det_min.abs().max(1e-3));
        } else {
            assert!(r.margin <= 0.0);
        }
    }
    assert!(
        mismatches.is_empty(),
        "{} stability mismatches, e.g. {:?}",
        mismatches.len(),
        &mismatches[..mismatches.len().min(5)]
    );
    println!("oracle: stability verdicts identical on {} cases; max det_min rel diff (stable) {e_margin:e}", cases.len());
}

#[test]
fn rk4_baseline_close_to_oracle() {
    // The paper's baseline dt = 1e-4 on a subset; RK4's O(h⁴) error depends on |a|.
    let cases = load_cases();
    let mut e = 0.0f64;
    let mut agree = 0;
    let n = 100;
    for c in cases.iter().take(n) {
        let p = pr::rk4_tip(&c.a, 1e-4).expect("rk4");
        e = e.max((p.x - c.tip[1]).abs().max((p.y - c.tip[2]).abs()));
        let (_, j) = pr::rk4_tip_and_jacobian(&c.a, 1e-4).expect("rk4 J");
        let oj = oracle_jac(c);
        assert!((j - oj).amax() / oj.amax() < 1e-5);
        if pr::rk4_stability(&c.a, 1e-4).expect("rk4 stab").stable == c.stable {
            agree += 1;
        }
    }
    println!("rk4 dt=1e-4: max tip err {e:e}, stability agrees on {agree}/{n}");
    assert!(e < 1e-9);
    assert!(agree >= n - 2);
}

#[test]
fn reference_special_cases() {
    // Straight rod: unstable, margin 0.
    let r = pr::stability(&Vector3::new(0.0, 5.0, 0.0)).unwrap();
    assert!(!r.stable && r.margin == 0.0);
    // Circle (F = 0): θ = a3 t, x = sin(a3)/a3, y = 2 sin²(a3/2)/a3.
    let a3 = 2.5f64;
    let (p, _) = pr::tip_and_jacobian(&Vector3::new(a3, 0.0, 0.0), 1e-12).unwrap();
    assert!((p.theta - a3).abs() < 1e-12);
    assert!((p.x - a3.sin() / a3).abs() < 1e-12);
    assert!((p.y - 2.0 * (a3 / 2.0).sin().powi(2) / a3).abs() < 1e-12);
    // Euler check of docs/math.md §5: (0, −40, 1) loses stability at t ≈ 0.9935.
    let r = pr::stability(&Vector3::new(0.0, -40.0, 1.0)).unwrap();
    assert!(!r.stable);
    let tc = r.first_conjugate_t.unwrap();
    assert!((tc - 0.9935).abs() < 1e-3, "t* = {tc}");
    // Shape at unsorted times equals pose_and_jacobian.
    let a = Vector3::new(1.0, -3.0, 2.0);
    let ts = [0.7, 0.0, 0.3, 1.0];
    let s = pr::shape(&a, &ts, 1e-12).unwrap();
    for (t, p) in ts.iter().zip(&s) {
        let (q, _) = pr::pose_and_jacobian(&a, *t, 1e-12).unwrap();
        assert!((q.to_vector() - p.to_vector()).amax() < 1e-10);
    }
    // Energy identity of docs/math.md §1: ½∫κ² = λ2/2 − a4 x(1) − a5 y(1).
    let (tip, _) = pr::tip_and_jacobian(&a, 1e-12).unwrap();
    let lam2 = a[0] * a[0] + 2.0 * a[1];
    let e = pr::energy(&a, 1e-12).unwrap();
    assert!((e - (lam2 / 2.0 - a[1] * tip.x - a[2] * tip.y)).abs() < 1e-10);
}

#[test]
fn reference_rejects_bad_input_without_panicking() {
    for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY] {
        let a = Vector3::new(bad, 1.0, 1.0);
        assert!(pr::tip_and_jacobian(&a, 1e-10).is_err());
        assert!(pr::stability(&a).is_err());
        assert!(pr::energy(&a, 1e-10).is_err());
        assert!(pr::rk4_tip(&a, 1e-3).is_err());
        assert!(pr::pose_and_jacobian(&Vector3::new(1.0, 1.0, 1.0), bad, 1e-10).is_err());
        assert!(pr::tip_and_jacobian(&Vector3::new(1.0, 1.0, 1.0), bad).is_err());
    }
    assert!(pr::rk4_tip(&Vector3::new(1.0, 1.0, 1.0), 0.0).is_err());
    assert!(pr::rk4_tip(&Vector3::new(1.0, 1.0, 1.0), 1e-300).is_err());
    assert!(pr::pose_and_jacobian(&Vector3::new(1.0, 1.0, 1.0), 1.5, 1e-10).is_err());
    // Huge inputs: an error or a finite answer, never a panic or a hang.
    for big in [1e8, 1e150, 1e300, f64::MAX] {
        let a = Vector3::new(big, -big, big);
        let _ = pr::tip_and_jacobian(&a, 1e-10);
        let _ = pr::stability(&a);
        let _ = pr::energy(&a, 1e-8);
    }
}

#[test]
fn dop853_exponential_and_oscillator() {
    let opts = OdeOptions::with_tolerances(1e-12, 1e-14);
    let (y, st) = ode::solve(
        |_, y: &[f64; 1], dy: &mut [f64; 1]| dy[0] = y[0],
        0.0,
        [1.0],
        2.0,
        &opts,
    )
    .unwrap();
    assert!((y[0] - 2f64.exp()).abs() < 1e-11 * 2f64.exp(), "{}", y[0]);
    assert!(st.accepted < 200);
    // Backwards in time.
    let (y, _) = ode::solve(
        |_, y: &[f64; 1], dy: &mut [f64; 1]| dy[0] = y[0],
        0.0,
        [1.0],
        -1.0,
        &opts,
    )
    .unwrap();
    assert!((y[0] - (-1f64).exp()).abs() < 1e-12);
    // Harmonic oscillator, dense output at many times.
    let w = 3.0;
    let ts: Vec<f64> = (0..=500).map(|i| i as f64 * 0.02).collect();
    let mut emax = 0.0f64;
    ode::solve_dense(
        |_, y: &[f64; 2], dy: &mut [f64; 2]| {
            dy[0] = y[1];
            dy[1] = -w * w * y[0];
        },
        0.0,
        [1.0, 0.0],
        &ts,
        &opts,
        |_, t, y| {
            emax = emax
                .max((y[0] - (w * t).cos()).abs())
                .max((y[1] + w * (w * t).sin()).abs() / w);
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    assert!(emax < 1e-10, "dense output error {emax:e}");
}

#[test]
fn dop853_converges_at_high_order() {
    // Error decreases with the tolerance roughly proportionally.
    let f = |t: f64, y: &[f64; 1], dy: &mut [f64; 1]| dy[0] = -2.0 * t * y[0];
    let exact = (-4.0f64).exp();
    let mut prev = f64::INFINITY;
    for rtol in [1e-6, 1e-9, 1e-12] {
        let (y, _) = ode::solve(
            f,
            0.0,
            [1.0],
            2.0,
            &OdeOptions::with_tolerances(rtol, rtol * 1e-3),
        )
        .unwrap();
        let e = (y[0] - exact).abs() / exact;
        assert!(e < 100.0 * rtol, "rtol {rtol}: err {e:e}");
        assert!(e <= prev);
        prev = e;
    }
}

#[test]
fn rk4_order_four() {
    let f = |_: f64, y: &[f64; 2], dy: &mut [f64; 2]| {
        dy[0] = y[1];
        dy[1] = -y[0];
    };
    let err = |n: u64| {
        let y = ode::rk4_solve(f, 0.0, [1.0, 0.0], 3.0, n).unwrap();
        (y[0] - 3f64.cos()).abs().max((y[1] + 3f64.sin()).abs())
    };
    let (e1, e2, e3) = (err(50), err(100), err(200));
    let (r1, r2) = (e1 / e2, e2 / e3);
    println!("rk4 error ratios {r1} {r2}");
    assert!(
        (r1 - 16.0).abs() < 1.0 && (r2 - 16.0).abs() < 1.0,
        "{r1} {r2}"
    );
}

#[test]
fn step_budget_is_an_error_not_a_hang() {
    let opts = OdeOptions {
        max_steps: 50,
        ..OdeOptions::with_tolerances(1e-12, 1e-14)
    };
    let r = ode::solve(
        |_, y: &[f64; 2], dy: &mut [f64; 2]| {
            dy[0] = y[1];
            dy[1] = -1e6 * y[0];
        },
        0.0,
        [1.0, 0.0],
        100.0,
        &opts,
    );
    assert!(matches!(r, Err(OdeError::StepBudget { .. })), "{r:?}");
    // Blow-up in finite time: error, no hang.
    let r = ode::solve(
        |_, y: &[f64; 1], dy: &mut [f64; 1]| dy[0] = y[0] * y[0],
        0.0,
        [1.0],
        2.0,
        &OdeOptions::default(),
    );
    assert!(r.is_err());
    // Invalid tolerances.
    assert!(ode::solve(
        |_, _: &[f64; 1], dy: &mut [f64; 1]| dy[0] = 0.0,
        0.0,
        [0.0],
        1.0,
        &OdeOptions::with_tolerances(f64::NAN, 0.0)
    )
    .is_err());
}
