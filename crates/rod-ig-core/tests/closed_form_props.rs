//! Properties of the planar closed form: exact J vs central differences, robustness on any
//! f64 input, continuity of θ(t), shape endpoints, and every degenerate family of docs/math.md §2
//! checked (a) for first-order consistency with neighbouring generic values and (b) against the
//! adaptive ODE reference `ode::planar_reference` (docs/math.md §6 tolerances).

use proptest::prelude::*;
use rod_ig_core::ode::planar_reference as ode;
use rod_ig_core::planar::{self, Case, PlanarRod};
use rod_ig_core::{PlanarJacobian, PlanarParams, PlanarPose, RodError};

fn p(a3: f64, a4: f64, a5: f64) -> PlanarParams {
    PlanarParams::new(a3, a4, a5)
}

fn v(q: &PlanarPose) -> nalgebra::Vector3<f64> {
    q.to_vector()
}

/// Central differences of the closed-form tip with step h in each a_i.
/// Five-point central differences (truncation O(h⁴ ∂⁵q)): near-straight rods under strong
/// tension have ‖J‖ ~ 300 and large higher derivatives, where the 3-point stencil's O(h² ∂³q)
/// alone exceeds 1e-5 ‖J‖.
fn fd_jacobian(a: &PlanarParams, h: f64) -> PlanarJacobian {
    let mut j = PlanarJacobian::zeros();
    let tip_at = |c: usize, d: f64| {
        let mut ad = *a;
        ad[c] += d;
        v(&planar::tip(&ad).expect("tip"))
    };
    for c in 0..3 {
        let d1 = tip_at(c, h) - tip_at(c, -h);
        let d2 = tip_at(c, 2.0 * h) - tip_at(c, -2.0 * h);
        j.set_column(c, &((8.0 * d1 - d2) / (12.0 * h)));
    }
    j
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// J (dual numbers) vs five-point central differences over |a3| ≤ 30, |a4|, |a5| ≤ 400:
    /// ‖J − R‖_F ≤ 1e-5 (‖J‖_F + 1e-3) + ‖J_h − J_h/2‖_F, where J_h is the stencil at h = 1e-5,
    /// R = J_h/2 + (J_h/2 − J_h)/15 its Richardson extrapolation, and the last term bounds the
    /// truncation O(h⁴ ∂⁵q) the extrapolation leaves. That term is ~1e-9‖J‖ on most of the box,
    /// but ∂⁵q is not bounded on it: at a = (−15.43, 278.03, −283.60) J_h is off by 1.1e-5 of
    /// ‖J‖ (by 0.26 at h = 1e-4), where J agrees with the DOP853 reference to 2.8e-9 and the
    /// stencil at h = 1e-6 to 2.5e-8. Rounding O(1e-16 |q|/h) ≈ 1e-10.
    #[test]
    fn jacobian_matches_central_differences(a3 in -30.0f64..30.0, a4 in -400.0f64..400.0, a5 in -400.0f64..400.0) {
        let a = p(a3, a4, a5);
        let (_, j) = planar::tip_and_jacobian(&a).expect("J");
        let (jh, jh2) = (fd_jacobian(&a, 1e-5), fd_jacobian(&a, 5e-6));
        let extrapolated = jh2 + (jh2 - jh) / 15.0;
        let truncation = (jh - jh2).norm();
        let err = (j - extrapolated).norm();
        prop_assert!(
            err <= 1e-5 * (j.norm() + 1e-3) + truncation,
            "a = {:?}: ‖ΔJ‖ = {:e}, ‖J‖ = {:e}, truncation {:e}", a.as_slice(), err, j.norm(), truncation
        );
    }

    /// No panic on arbitrary f64 triples (NaN, ±∞, huge, subnormal): every entry point returns
    /// either a finite result or an error; non-finite a gives `RodError::NonFinite`.
    #[test]
    fn no_panic_on_any_f64(a3 in any::<f64>(), a4 in any::<f64>(), a5 in any::<f64>()) {
        check_any(p(a3, a4, a5));
    }

    /// θ(t) is continuous (unwrapped): Δθ agrees with the trapezoid ∫κ over each step, and the
    /// rod is unit-speed (|Δ(x, y)| ≤ Δt).
    #[test]
    fn theta_is_continuous_along_t(a3 in -30.0f64..30.0, a4 in -400.0f64..400.0, a5 in -400.0f64..400.0) {
        let rod = PlanarRod::new(&p(a3, a4, a5)).expect("rod");
        let n = 2001;
        let s = rod.shape(n);
        let dt = 1.0 / (n - 1) as f64;
        let kmax = (0..n).map(|i| rod.curvature(i as f64 * dt).abs()).fold(0.0, f64::max);
        for i in 0..n - 1 {
            let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
            let trap = 0.5 * dt * (rod.curvature(t0) + rod.curvature(t1));
            let dth = s[i + 1].theta - s[i].theta;
            prop_assert!((dth - trap).abs() <= 1e-6 * (1.0 + kmax), "jump in θ at t = {t0}: {dth} vs {trap}");
            let ds = ((s[i + 1].x - s[i].x).powi(2) + (s[i + 1].y - s[i].y).powi(2)).sqrt();
            prop_assert!(ds <= dt * (1.0 + 1e-9) + 1e-15);
        }
    }

    /// shape(n) starts at the identity and ends exactly at tip().
    #[test]
    fn shape_endpoints(a3 in -30.0f64..30.0, a4 in -400.0f64..400.0, a5 in -400.0f64..400.0, n in 2usize..50) {
        let rod = PlanarRod::new(&p(a3, a4, a5)).expect("rod");
        let s = rod.shape(n);
        prop_assert_eq!(s.len(), n);
        prop_assert!(s[0].x.abs() <= 1e-15 && s[0].y.abs() <= 1e-15 && s[0].theta.abs() <= 1e-15, "{:?}", s[0]);
        prop_assert_eq!(s[n - 1], rod.tip());
    }
}

fn check_any(a: PlanarParams) {
    let finite = a.iter().all(|x| x.is_finite());
    let ok_pose = |q: &PlanarPose| q.is_finite();
    match planar::tip(&a) {
        Ok(q) => assert!(finite && ok_pose(&q), "{a:?} -> {q:?}"),
        Err(e) => {
            if !finite {
                assert!(matches!(e, RodError::NonFinite { .. }), "{e:?}");
            }
        }
    }
    if let Ok((q, j)) = planar::tip_and_jacobian(&a) {
        assert!(ok_pose(&q) && j.iter().all(|x| x.is_finite()));
    }
    let report = planar::stability(&a);
    if let Ok(s) = report {
        assert!(s.margin.is_finite());
    }
    // The verdict alone: no panic, and the full test's outcome wherever both answer.
    if let (Ok(v), Ok(s)) = (planar::stability_verdict(&a), report) {
        assert_eq!(v, s.verdict(), "{a:?}: {s:?}");
    }
    if let Ok(e) = planar::energy(&a) {
        assert!(e.is_finite());
    }
    let _ = planar::evaluate(&a);
    let _ = planar::pose_and_jacobian(&a, 0.5);
    let _ = planar::pose_and_jacobian(&a, f64::NAN);
    if let Ok(rod) = PlanarRod::new(&a) {
        for q in rod.shape(5) {
            assert!(q.is_finite(), "{a:?}: shape {q:?}");
        }
        assert!(rod.curvature(0.3).is_finite());
    }
}

/// Mixed magnitudes, exhaustively: every triple of tiny, subnormal, signed-zero, moderate and
/// huge components.
#[test]
fn no_panic_on_mixed_magnitudes() {
    const VALS: [f64; 14] = [
        0.0,
        -0.0,
        5e-324,
        -1e-310,
        1e-160,
        1e-8,
        1.0,
        -3.0,
        1e5,
        -1e77,
        1e154,
        1e200,
        f64::MAX,
        -f64::MAX,
    ];
    for &a3 in &VALS {
        for &a4 in &VALS {
            for &a5 in &VALS {
                check_any(p(a3, a4, a5));
            }
        }
    }
}

#[test]
fn non_finite_inputs_are_rejected() {
    for a in [
        p(f64::NAN, 1.0, 1.0),
        p(1.0, f64::INFINITY, 1.0),
        p(1.0, 1.0, f64::NEG_INFINITY),
    ] {
        assert!(matches!(
            planar::tip(&a),
            Err(RodError::NonFinite { name: "a", .. })
        ));
        assert!(planar::tip_and_jacobian(&a).is_err());
        assert!(planar::stability(&a).is_err());
        assert!(matches!(
            planar::stability_verdict(&a),
            Err(RodError::NonFinite { name: "a", .. })
        ));
        assert!(planar::evaluate(&a).is_err());
    }
    assert!(matches!(
        planar::pose_and_jacobian(&p(1.0, 2.0, 3.0), f64::NAN),
        Err(RodError::NonFinite { name: "t", .. })
    ));
    // overflow is an error, not NaN
    assert!(matches!(
        planar::tip(&p(1e200, 1e300, -1e300)),
        Err(RodError::Overflow(_))
    ));
}

/// The degenerate families of docs/math.md §2, with the case the closed form must select.
fn degenerate_families() -> Vec<(&'static str, PlanarParams, Option<Case>)> {
    vec![
        ("a3 = 0, tension", p(0.0, 5.0, 7.0), Some(Case::I)),
        ("a3 = 0, compression", p(0.0, -30.0, 10.0), Some(Case::I)),
        ("a3 = 0, a5 < 0", p(0.0, 50.0, -3.0), Some(Case::I)),
        ("a5 = 0, case I", p(1.0, -30.0, 0.0), Some(Case::I)),
        (
            "a5 = 0, case II, a4 > 0 (φ = K)",
            p(2.0, 10.0, 0.0),
            Some(Case::II),
        ),
        ("a5 = 0, case II, a4 < 0", p(5.0, -3.0, 0.0), Some(Case::II)),
        ("a5 = 0, ε = −1", p(-5.0, 20.0, 0.0), Some(Case::II)),
        ("λ4 = 0: (2, 3, 4)", p(2.0, 3.0, 4.0), Some(Case::III)),
        ("λ4 = 0: (2, −1, 0)", p(2.0, -1.0, 0.0), Some(Case::III)),
        ("λ4 = 0: (−2, 3, 4)", p(-2.0, 3.0, 4.0), Some(Case::III)),
        ("λ4 = 0: (2, 3, −4)", p(2.0, 3.0, -4.0), Some(Case::III)),
        ("λ4 = 0: (1, 0, 0.5)", p(1.0, 0.0, 0.5), Some(Case::III)),
        ("λ4 = 0: (4, 5, 12)", p(4.0, 5.0, 12.0), Some(Case::III)),
        ("circle", p(3.0, 0.0, 0.0), Some(Case::Circle)),
        ("circle, ε = −1", p(-0.5, 0.0, 0.0), Some(Case::Circle)),
        ("circle, tight", p(20.0, 0.0, 0.0), Some(Case::Circle)),
        (
            "circle, nearly straight",
            p(1e-3, 0.0, 0.0),
            Some(Case::Circle),
        ),
        ("straight, no force", p(0.0, 0.0, 0.0), Some(Case::Straight)),
        ("straight, tension", p(0.0, 10.0, 0.0), Some(Case::Straight)),
        (
            "straight, compression",
            p(0.0, -10.0, 0.0),
            Some(Case::Straight),
        ),
        (
            "straight, beyond Euler load",
            p(0.0, -50.0, 0.0),
            Some(Case::Straight),
        ),
        (
            "straight, strong tension",
            p(0.0, 100.0, 0.0),
            Some(Case::Straight),
        ),
        ("small force", p(3.0, 1e-9, 2e-9), Some(Case::SmallForce)),
        (
            "small force, above the switch",
            p(3.0, 1e-7, 2e-7),
            Some(Case::II),
        ),
        ("small force, a5 = 0", p(3.0, 1e-5, 0.0), Some(Case::II)),
        (
            "small force, ε = −1",
            p(-5.0, 1e-12, -1e-12),
            Some(Case::SmallForce),
        ),
        (
            "near separatrix, λ4 > 0",
            p(2.0, 3.0, 4.0 + 1e-12),
            Some(Case::I),
        ),
        (
            "near separatrix, λ4 < 0",
            p(2.0, 3.0, 4.0 - 1e-12),
            Some(Case::II),
        ),
        (
            "near separatrix, 1e-8",
            p(2.0, 3.0, 4.0 + 1e-8),
            Some(Case::I),
        ),
        ("near-straight under tension", p(1e-7, 50.0, 1e-7), None),
        (
            "near-straight under compression",
            p(1e-7, -20.0, 1e-7),
            None,
        ),
    ]
}

/// Each family is first-order consistent with neighbouring generic values: the residual
/// r(δ) = ‖q(a + δd) − q(a) − δ J(a) d‖ must be O(δ²): either r(1e-6) ≤ 1e-9, or
/// r(1e-6) ≤ 0.03 r(1e-5) (quadratic decay gives 0.01, a wrong J gives 0.1). Several directions
/// d per family: this checks continuity of q and that J at the degenerate point is the true
/// derivative.
#[test]
fn degenerate_families_are_consistent_with_neighbours() {
    let dirs = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.6, -0.48, 0.64],
        [-0.36, 0.8, 0.48],
    ];
    for (name, a, case) in degenerate_families() {
        let rod = PlanarRod::new(&a).expect(name);
        if let Some(c) = case {
            assert_eq!(rod.case(), c, "{name}");
        }
        let (q, j) = planar::tip_and_jacobian(&a).expect(name);
        assert!((v(&q) - v(&rod.tip())).norm() <= 1e-13, "{name}");
        for d in dirs {
            let d = nalgebra::Vector3::from(d);
            for sgn in [1.0, -1.0] {
                let res = |delta: f64| {
                    let an = a + d * (sgn * delta);
                    let qn = v(&planar::tip(&an).expect(name));
                    (qn - v(&q) - j * d * (sgn * delta)).norm()
                };
                let (r1, r2) = (res(1e-5), res(1e-6));
                assert!(
                    r2 <= 1e-9 || r2 <= 0.03 * r1,
                    "{name}: a = {:?}, d = {d:?}·{sgn}: residuals {r1:e} (δ = 1e-5), {r2:e} (δ = 1e-6)",
                    a.as_slice(),
                );
            }
        }
    }
}

/// Closed form vs the adaptive ODE reference (rtol 1e-13) on every degenerate family, at t = 1
/// and t = 0.37: tip ≤ 1e-11 (docs/math.md §6; ≤ 1.1e-9 for near-straight rods under tension),
/// J ≤ 1e-8 relative, energy ≤ 1e-9.
#[test]
fn degenerate_families_match_ode_reference() {
    let mut worst = 0.0f64;
    for (name, a, _) in degenerate_families() {
        let tol_tip = if name.contains("near-straight under tension") {
            1.1e-9
        } else {
            1e-11
        };
        for t in [0.37, 1.0] {
            let (qc, jc) = planar::pose_and_jacobian(&a, t).expect(name);
            let (qo, jo) = ode::pose_and_jacobian(&a, t, 1e-13).expect(name);
            let dq = (v(&qc) - v(&qo)).amax();
            worst = worst.max(dq);
            assert!(dq <= tol_tip, "{name} t={t}: tip error {dq:e}");
            let dj = (jc - jo).norm() / jo.norm().max(1e-12);
            assert!(dj <= 1e-8, "{name} t={t}: J error {dj:e}\n{jc}\n{jo}");
        }
        let ec = planar::energy(&a).expect(name);
        let eo = ode::energy(&a, 1e-13).expect(name);
        assert!(
            (ec - eo).abs() <= 1e-9 * eo.abs().max(1.0),
            "{name}: energy {ec} vs {eo}"
        );
        let sc = planar::stability(&a).expect(name);
        let so = ode::stability(&a).expect(name);
        assert_eq!(
            sc.stable, so.stable,
            "{name}: stability {sc:?} vs ODE {so:?}"
        );
    }
    eprintln!("degenerate families: worst tip error vs ODE {worst:.2e}");
}

/// Known physical checks: (0, −40, 1) loses stability at t ≈ 0.9935 (clamped–clamped Euler
/// load 4π², docs/math.md §5); circles (no force) are stable; the straight rod is unstable with
/// margin 0.
#[test]
fn stability_landmarks() {
    let s = planar::stability(&p(0.0, -40.0, 1.0)).expect("stability");
    assert!(!s.stable);
    let tc = s.first_conjugate_t.expect("conjugate point");
    assert!((tc - 0.9935).abs() < 1e-3, "{tc}");
    assert!(s.margin < 0.0);
    let s = planar::stability(&p(3.0, 0.0, 0.0)).expect("stability");
    assert!(s.stable && s.margin > 0.0 && s.first_conjugate_t.is_none());
    let s = planar::stability(&p(0.0, 7.0, 0.0)).expect("stability");
    assert!(!s.stable && s.margin == 0.0);
}

/// Energy identity ½∫κ² = λ2/2 − a4 x(1) − a5 y(1) against a direct quadrature of κ².
#[test]
fn energy_identity_matches_quadrature() {
    for a in [
        p(1.0, 2.0, 3.0),
        p(-7.0, -60.0, 20.0),
        p(0.0, -30.0, 10.0),
        p(4.0, 0.0, 0.0),
    ] {
        let rod = PlanarRod::new(&a).expect("rod");
        // composite Simpson on 4000 intervals
        let n = 4000;
        let h = 1.0 / n as f64;
        let mut s = 0.0;
        for i in 0..=n {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            s += w * rod.curvature(i as f64 * h).powi(2);
        }
        let quad = 0.5 * s * h / 3.0;
        assert!(
            (rod.energy() - quad).abs() <= 1e-9 * quad.max(1.0),
            "{a:?}: {} vs {quad}",
            rod.energy()
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Closed form vs the adaptive ODE reference (DOP853, rtol 1e-12) over the wide box
    /// |a3| ≤ 30, |a4|, |a5| ≤ 400 (four times the oracle's force range): tip ≤ 2e-9 abs
    /// (docs/math.md §6: ≤ 1.1e-9 on near-straight rods under tension, ≤ 1e-11 elsewhere; the ODE's
    /// own error grows with |a| as θ winds up to ~10 turns here), J ≤ 1e-7 relative, and the
    /// same stability verdict unless the rod sits on the boundary (|margin| < 1e-6 by either).
    /// Measured on 5,000 draws: tip ≤ 1e-10, J ≤ 1e-8; the bounds leave room for the rare
    /// near-straight rod under tension.
    #[test]
    fn closed_form_matches_ode_reference_on_wide_box(a3 in -30.0f64..30.0, a4 in -400.0f64..400.0, a5 in -400.0f64..400.0) {
        let a = p(a3, a4, a5);
        let (q, j) = planar::tip_and_jacobian(&a).expect("closed form");
        let (qr, jr) = ode::tip_and_jacobian(&a, 1e-12).expect("ode");
        let tip_err = (v(&q) - v(&qr)).amax();
        prop_assert!(tip_err <= 2e-9, "a = {:?}: tip error {:e}", a.as_slice(), tip_err);
        let j_err = (j - jr).norm() / jr.norm().max(1e-300);
        prop_assert!(j_err <= 1e-7, "a = {:?}: J relative error {:e}", a.as_slice(), j_err);
        let s = planar::stability(&a).expect("stability");
        let sr = ode::stability(&a).expect("ode stability");
        if s.margin.abs() > 1e-6 && sr.margin.abs() > 1e-6 {
            prop_assert_eq!(s.stable, sr.stable, "a = {:?}: margins {} vs {}", a.as_slice(), s.margin, sr.margin);
        }
    }
}
