//! The 3-D rod: planar-subset agreement with the planar reference, first integrals, J against
//! finite differences, stability (classical checks, fast scan vs full grid), inverse geometry.

mod workloads;
use nalgebra::{Rotation3, UnitQuaternion, Vector3, Vector6};
use proptest::prelude::*;
use rod_ig_core::ode::planar_reference as pr;
use rod_ig_core::solver::{self, IgError, Method, SolveOptions};
use rod_ig_core::spatial::Spatial;
use rod_ig_core::spatial::{self, SpatialParams, SpatialPose, StabilityOptions, Stiffness};
use workloads::spatial::{benchmark_random_targets, random_targets};

const RTOL: f64 = 1e-12;

/// Reproducible samples from the crate's SplitMix64.
struct Rng(rod_ig_core::rng::SplitMix64);
impl Rng {
    fn new(seed: u64) -> Self {
        Self(rod_ig_core::rng::SplitMix64::new(seed))
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0.range(lo, hi)
    }
    fn params(&mut self, m: f64, f: f64) -> SpatialParams {
        Vector6::new(
            self.uniform(-m, m),
            self.uniform(-m, m),
            self.uniform(-m, m),
            self.uniform(-f, f),
            self.uniform(-f, f),
            self.uniform(-f, f),
        )
    }
}

#[test]
fn planar_subset_matches_planar_reference() {
    let mut rng = Rng::new(7);
    let k = Stiffness::default();
    let (mut ep, mut er, mut ej, mut eoff) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..200 {
        let (a3, a4, a5) = (
            rng.uniform(-10.0, 10.0),
            rng.uniform(-100.0, 100.0),
            rng.uniform(-100.0, 100.0),
        );
        let a = Vector6::new(0.0, 0.0, a3, a4, a5, 0.0);
        let (pose, j) = spatial::tip_and_jacobian(&a, &k, RTOL).unwrap();
        let (pp, pj) = pr::tip_and_jacobian(&Vector3::new(a3, a4, a5), RTOL).unwrap();
        ep = ep.max((pose.position - Vector3::new(pp.x, pp.y, 0.0)).amax());
        let rz = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), pp.theta);
        er = er.max(pose.rotation.angle_to(&rz));
        // In-plane block: rows (ω3, v1, v2), columns (a3, a4, a5) = planar J rotated to body.
        let (c, s) = (pp.theta.cos(), pp.theta.sin());
        let scale = pj.amax();
        for col in 0..3 {
            let (dx, dy, dth) = (pj[(0, col)], pj[(1, col)], pj[(2, col)]);
            let body = [dth, c * dx + s * dy, -s * dx + c * dy];
            for (r, row) in [2usize, 3, 4].iter().enumerate() {
                ej = ej.max((j[(*row, col + 2)] - body[r]).abs() / scale);
            }
        }
        // Block-diagonal structure.
        for r in [0usize, 1, 5] {
            for col in [2usize, 3, 4] {
                eoff = eoff.max(j[(r, col)].abs()).max(j[(col, r)].abs());
            }
        }
    }
    println!("planar subset vs planar reference: position {ep:e}, rotation {er:e}, in-plane J rel {ej:e}, off-block {eoff:e}");
    assert!(ep < 1e-10 && er < 1e-9 && ej < 1e-9 && eoff < 1e-12);
}

#[test]
fn planar_subset_matches_closed_form() {
    // Against the closed form of `planar` (elliptic functions), where it is well conditioned.
    let mut rng = Rng::new(8);
    let k = Stiffness::default();
    let (mut ep, mut ej) = (0.0f64, 0.0f64);
    for _ in 0..200 {
        let (a3, a4, a5) = (
            rng.uniform(-10.0, 10.0),
            rng.uniform(-100.0, 100.0),
            rng.uniform(-100.0, 100.0),
        );
        let a = Vector6::new(0.0, 0.0, a3, a4, a5, 0.0);
        let (pose, j) = spatial::tip_and_jacobian(&a, &k, RTOL).unwrap();
        let (cp, cj) = rod_ig_core::planar::tip_and_jacobian(&Vector3::new(a3, a4, a5)).unwrap();
        ep = ep.max((pose.position - Vector3::new(cp.x, cp.y, 0.0)).amax());
        let rz = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), cp.theta);
        ep = ep.max(pose.rotation.angle_to(&rz));
        let (c, s) = (cp.theta.cos(), cp.theta.sin());
        for col in 0..3 {
            let (dx, dy, dth) = (cj[(0, col)], cj[(1, col)], cj[(2, col)]);
            let body = [dth, c * dx + s * dy, -s * dx + c * dy];
            for (r, row) in [2usize, 3, 4].iter().enumerate() {
                ej = ej.max((j[(*row, col + 2)] - body[r]).abs() / cj.amax());
            }
        }
    }
    println!("planar subset vs closed form: pose {ep:e}, in-plane J rel {ej:e}");
    assert!(ep < 1e-9 && ej < 1e-7);
}

fn check_first_integrals(a: SpatialParams, k: Stiffness) -> f64 {
    let ts: Vec<f64> = (0..=20).map(|i| i as f64 / 20.0).collect();
    let st = spatial::states(&a, &k, &ts, RTOL).unwrap();
    let m0 = Vector3::new(a[0], a[1], a[2]);
    let f0 = Vector3::new(a[3], a[4], a[5]);
    let h = |mu: &Vector6<f64>| {
        0.5 * (mu[0] * mu[0] / k.c1 + mu[1] * mu[1] / k.c2 + mu[2] * mu[2] / k.c3) + mu[3]
    };
    let scale = 1.0 + a.amax() * a.amax();
    let mut e = 0.0f64;
    for s in &st {
        let r = s.pose.rotation.to_rotation_matrix();
        let m = Vector3::new(s.mu[0], s.mu[1], s.mu[2]);
        let f = Vector3::new(s.mu[3], s.mu[4], s.mu[5]);
        let rf = r * f;
        e = e.max((rf - f0).amax() / (1.0 + f0.amax()));
        e = e.max((r * m + s.pose.position.cross(&rf) - m0).amax() / (1.0 + a.amax()));
        e = e.max((f.norm_squared() - f0.norm_squared()).abs() / scale);
        e = e.max((m.dot(&f) - m0.dot(&f0)).abs() / scale);
        e = e.max((h(&s.mu) - h(&a)).abs() / scale);
        if k.c2 == k.c3 {
            e = e.max((s.mu[0] - a[0]).abs() / (1.0 + a.amax()));
        }
        let rm = r.matrix();
        e = e.max((rm.transpose() * rm - nalgebra::Matrix3::identity()).amax());
    }
    e
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn first_integrals_isotropic(a1 in -5.0..5.0f64, a2 in -5.0..5.0f64, a3 in -5.0..5.0f64,
                                 a4 in -30.0..30.0f64, a5 in -30.0..30.0f64, a6 in -30.0..30.0f64) {
        let e = check_first_integrals(Vector6::new(a1, a2, a3, a4, a5, a6), Stiffness::default());
        prop_assert!(e < 1e-9, "first-integral drift {e:e}");
    }

    #[test]
    fn first_integrals_anisotropic(a1 in -5.0..5.0f64, a2 in -5.0..5.0f64, a3 in -5.0..5.0f64,
                                   a4 in -30.0..30.0f64, a5 in -30.0..30.0f64, a6 in -30.0..30.0f64,
                                   c1 in 0.5..2.0f64, c2 in 0.5..2.0f64, c3 in 0.5..2.0f64) {
        let k = Stiffness { c1, c2, c3 };
        let e = check_first_integrals(Vector6::new(a1, a2, a3, a4, a5, a6), k);
        prop_assert!(e < 1e-9, "first-integral drift {e:e}");
        let k = Stiffness { c1, c2, c3: c2 };
        let e = check_first_integrals(Vector6::new(a1, a2, a3, a4, a5, a6), k);
        prop_assert!(e < 1e-9, "first-integral drift (c2 = c3) {e:e}");
    }
}

#[test]
fn jacobian_matches_central_differences() {
    let mut rng = Rng::new(11);
    let mut worst = 0.0f64;
    for (i, k) in [
        Stiffness::default(),
        Stiffness {
            c1: 0.7,
            c2: 1.3,
            c3: 0.9,
        },
    ]
    .iter()
    .cycle()
    .take(20)
    .enumerate()
    {
        let a = rng.params(5.0, 30.0);
        let (q, j) = spatial::tip_and_jacobian(&a, k, RTOL).unwrap();
        let h = 1e-4 * (1.0 + (i % 3) as f64);
        let mut fd = nalgebra::Matrix6::zeros();
        for c in 0..6 {
            let mut ap = a;
            ap[c] += h;
            let mut am = a;
            am[c] -= h;
            let qp = spatial::tip(&ap, k, RTOL).unwrap();
            let qm = spatial::tip(&am, k, RTOL).unwrap();
            let d = (q.body_error_to(&qp) - q.body_error_to(&qm)) / (2.0 * h);
            fd.set_column(c, &d);
        }
        let e = (fd - j).amax() / j.amax();
        worst = worst.max(e);
    }
    println!("J vs central differences: max rel err {worst:e}");
    assert!(worst < 1e-6);
}

#[test]
fn reduced_formulation_matches_mu_form() {
    let mut rng = Rng::new(13);
    let (mut ep, mut ej) = (0.0f64, 0.0f64);
    for i in 0..100 {
        let k = if i % 2 == 0 {
            Stiffness::default()
        } else {
            Stiffness {
                c1: rng.uniform(0.5, 2.0),
                c2: rng.uniform(0.5, 2.0),
                c3: rng.uniform(0.5, 2.0),
            }
        };
        let a = rng.params(5.0, 30.0);
        let t = rng.uniform(0.1, 1.0);
        let (p1, j1) = spatial::pose_and_jacobian(&a, &k, t, RTOL).unwrap();
        let (p2, j2) = spatial::reference_pose_and_jacobian(&a, &k, t, RTOL).unwrap();
        ep = ep
            .max((p1.position - p2.position).amax())
            .max(p1.rotation.angle_to(&p2.rotation));
        ej = ej.max((j1 - j2).amax() / j2.amax());
    }
    println!("reduced vs mu-form: pose {ep:e}, J rel {ej:e}");
    assert!(ep < 1e-10 && ej < 1e-9);
}

#[test]
fn classical_conjugate_points() {
    let k = Stiffness::default();
    // Clamped twist: t* = 8.9868 / m1 (slightly bent so that det is not identically 0).
    for m1 in [10.0f64, 12.0, 15.0] {
        let a = Vector6::new(m1, 1e-3, 0.0, 0.0, 0.0, 0.0);
        let r = spatial::stability(&a, &k).unwrap();
        let t = r.first_conjugate_t.expect("twist buckling");
        println!("twist m1 = {m1}: t* = {t}, expected {}", 8.9868 / m1);
        assert!(!r.stable && (t - 8.9868 / m1).abs() < 1e-3);
    }
    // Euler: t* = 2π/√F (planar-subset input: blocks tested separately).
    for f in [40.0f64, 60.0] {
        let a = Vector6::new(0.0, 0.0, 0.0, -f, 0.1, 0.0);
        let r = spatial::stability(&a, &k).unwrap();
        let t = r.first_conjugate_t.expect("Euler buckling");
        let expect = 2.0 * std::f64::consts::PI / f.sqrt();
        println!("Euler F = {f}: t* = {t}, expected {expect}");
        assert!(!r.stable && (t - expect).abs() < 1e-3);
    }
    // The same Euler rod rotated about the base tangent: blocks still tested separately.
    let phi = 0.7f64;
    let a = Vector6::new(0.0, 0.0, 0.0, -40.0, 0.1 * phi.cos(), 0.1 * phi.sin());
    let r = spatial::stability(&a, &k).unwrap();
    let t = r.first_conjugate_t.expect("rotated Euler buckling");
    assert!(
        !r.stable && (t - 2.0 * std::f64::consts::PI / 40f64.sqrt()).abs() < 1e-3,
        "{t}"
    );
    // Straight rods: unstable, margin 0.
    let r = spatial::stability(&Vector6::new(3.0, 0.0, 0.0, 5.0, 0.0, 0.0), &k).unwrap();
    assert!(!r.stable && r.margin == 0.0);
}

#[test]
fn fast_stability_scan_matches_full_grid() {
    // Boxes ±5/±30 and ±8/±50, every fifth sample an exact planar-subset rod.
    let mut rng = Rng::new(77);
    let k = Stiffness::default();
    let mut stable = 0;
    let mut step_end_only_mismatches = 0;
    let n = 600;
    for i in 0..n {
        let (m, f) = if i % 2 == 0 { (5.0, 30.0) } else { (8.0, 50.0) };
        let mut a = rng.params(m, f);
        if i % 5 == 4 {
            a[0] = 0.0;
            a[1] = 0.0;
            a[5] = 0.0;
        }
        let full = spatial::stability_full_grid(&a, &k).unwrap();
        let fast = spatial::stability(&a, &k).unwrap();
        let prod = spatial::stability_with(&a, &k, &StabilityOptions::production()).unwrap();
        assert_eq!(fast.stable, full.stable, "a = {a:?}");
        assert_eq!(prod.stable, full.stable, "production, a = {a:?}");
        if let (Some(t1), Some(t2)) = (fast.first_conjugate_t, full.first_conjugate_t) {
            assert!((t1 - t2).abs() < 1e-6, "{t1} vs {t2}");
        }
        let ends = StabilityOptions {
            coarse_stride: 0,
            ..StabilityOptions::production()
        };
        if spatial::stability_with(&a, &k, &ends).unwrap().stable != full.stable {
            step_end_only_mismatches += 1;
        }
        if full.stable {
            stable += 1;
        }
    }
    println!("fast scan = full grid on {n} samples ({stable} stable); step-end-only scan differs on {step_end_only_mismatches}");
    assert!(step_end_only_mismatches <= n / 100);
}

#[test]
fn rotated_planar_rods_match_planar_subset() {
    // Rotating a planar-subset rod about the base tangent conjugates its shape: same verdict,
    // same first conjugate point, tip = g q g⁻¹.
    let mut rng = Rng::new(21);
    let k = Stiffness::default();
    for _ in 0..60 {
        let (a3, a4, a5) = (
            rng.uniform(-5.0, 5.0),
            rng.uniform(-30.0, 30.0),
            rng.uniform(-30.0, 30.0),
        );
        let phi = rng.uniform(-3.0, 3.0);
        let a = Vector6::new(0.0, 0.0, a3, a4, a5, 0.0);
        let g = Rotation3::from_axis_angle(&Vector3::x_axis(), phi);
        let m = g * Vector3::new(0.0, 0.0, a3);
        let f = g * Vector3::new(a4, a5, 0.0);
        let ar = Vector6::new(0.0, m.y, m.z, f.x, f.y, f.z);
        let s0 = spatial::stability(&a, &k).unwrap();
        let s1 = spatial::stability(&ar, &k).unwrap();
        assert_eq!(s0.stable, s1.stable, "a = {a:?}, phi = {phi}");
        if let (Some(t0), Some(t1)) = (s0.first_conjugate_t, s1.first_conjugate_t) {
            assert!((t0 - t1).abs() < 1e-6);
        }
        let q0 = spatial::tip(&a, &k, RTOL).unwrap();
        let q1 = spatial::tip(&ar, &k, RTOL).unwrap();
        assert!((g * q0.position - q1.position).amax() < 1e-10);
        let gq = UnitQuaternion::from_rotation_matrix(&g);
        assert!((gq * q0.rotation * gq.inverse()).angle_to(&q1.rotation) < 1e-9);
    }
}

#[test]
fn pose_serialisation_convention() {
    let p = SpatialPose {
        position: Vector3::new(1.0, 2.0, 3.0),
        rotation: UnitQuaternion::from_rotation_matrix(&Rotation3::from_euler_angles(
            0.1, 3.0, -2.0,
        )),
    };
    let v = serde_json::to_value(p).unwrap();
    let q = v["quaternion"].as_array().unwrap();
    assert!(q[3].as_f64().unwrap() >= 0.0);
    let back: SpatialPose = serde_json::from_value(v).unwrap();
    assert!(back.rotation.angle_to(&p.rotation) < 1e-12);
    assert!((back.position - p.position).amax() == 0.0);
    let bad = serde_json::json!({"position": [0.0, 0.0, 0.0], "quaternion": [0.0, 0.0, 0.0, 0.0]});
    assert!(serde_json::from_value::<SpatialPose>(bad).is_err());
}

#[test]
fn spatial_rejects_bad_input_without_panicking() {
    let k = Stiffness::default();
    for bad in [f64::NAN, f64::INFINITY] {
        let a = Vector6::new(bad, 0.0, 1.0, 0.0, 0.0, 0.0);
        assert!(spatial::tip_and_jacobian(&a, &k, 1e-8).is_err());
        assert!(spatial::stability(&a, &k).is_err());
        assert!(spatial::shape(&a, &k, 10).is_err());
        let kb = Stiffness { c1: bad, ..k };
        assert!(spatial::tip(&Vector6::new(0.0, 1.0, 1.0, 0.0, 0.0, 0.0), &kb, 1e-8).is_err());
    }
    assert!(spatial::tip(
        &Vector6::new(0.0, 1.0, 1.0, 0.0, 0.0, 0.0),
        &Stiffness { c1: 0.0, ..k },
        1e-8
    )
    .is_err());
    for big in [1e6, 1e100, f64::MAX] {
        let a = Vector6::new(big, -big, big, big, -big, big);
        let _ = spatial::tip_and_jacobian(&a, &k, 1e-8);
        let _ = spatial::stability(&a, &k);
    }
}

#[test]
fn shape_and_energy() {
    let k = Stiffness::default();
    let a = Vector6::new(0.5, 1.0, -2.0, 3.0, -4.0, 5.0);
    let s = spatial::shape(&a, &k, 11).unwrap();
    assert_eq!(s.len(), 11);
    assert!(s[0].position.norm() == 0.0);
    let tip = spatial::tip(&a, &k, RTOL).unwrap();
    assert!((s[10].position - tip.position).amax() < 1e-9);
    // Energy of the planar subset equals the planar reference.
    let a = Vector6::new(0.0, 0.0, 2.0, -3.0, 4.0, 0.0);
    let e3 = spatial::energy(&a, &k, RTOL).unwrap();
    let e2 = pr::energy(&Vector3::new(2.0, -3.0, 4.0), RTOL).unwrap();
    assert!((e3 - e2).abs() < 1e-10);
}

#[test]
fn ig_random_targets_robust() {
    // Box |a1..3| <= 5, |a4..6| <= 30 (docs/math.md §10: ~70 % stable); targets = tips of stable a.
    let k = Stiffness::default();
    let targets = random_targets(150, 2024, &k);
    assert_eq!(targets.len(), 150);
    let opts = SolveOptions::default();
    let mut ok = 0;
    let mut worst_pos = 0.0f64;
    for (_, target) in &targets {
        match solver::solve(&Spatial::default(), target, &opts) {
            Ok(sol) => {
                assert!(sol.stable && sol.residual <= 2.0 * opts.tolerance);
                // Independent check at reference accuracy: tip and stability (full grid).
                let tip = spatial::tip(&sol.a, &k, RTOL).unwrap();
                let (pe, ang) = tip.distance_to(target);
                worst_pos = worst_pos.max(pe).max(ang);
                assert!(pe < 1e-5 && ang < 1e-5, "{pe} {ang}");
                let st = spatial::stability_full_grid(&sol.a, &k).unwrap();
                assert!(st.stable, "returned an unstable rod: {:?}", sol.a);
                ok += 1;
            }
            Err(f) => println!("failure: {f}"),
        }
    }
    println!(
        "3-D robust IG: {ok}/{} solved, worst reference residual {worst_pos:e}",
        targets.len()
    );
    assert!(ok as f64 >= 0.98 * targets.len() as f64);
}

#[test]
fn ig_newton_and_failures() {
    let k = Stiffness::default();
    let targets = random_targets(20, 99, &k);
    // Paper's Newton from a nearby guess converges to the same rod.
    let mut converged = 0;
    for (a, target) in &targets {
        let opts = SolveOptions {
            method: Method::Newton,
            initial_guess: Some(a + Vector6::repeat(0.05)),
            ..Default::default()
        };
        if let Ok(sol) = solver::solve(&Spatial::default(), target, &opts) {
            assert!(sol.residual < 1e-5);
            converged += 1;
        }
    }
    assert!(converged >= 18, "{converged}");
    // Typed failures.
    let far = SpatialPose {
        position: Vector3::new(2.0, 0.0, 0.0),
        rotation: UnitQuaternion::identity(),
    };
    let f = solver::solve(&Spatial::default(), &far, &SolveOptions::default()).unwrap_err();
    assert!(matches!(f.reason, IgError::Unreachable { .. }));
    let nan = SpatialPose {
        position: Vector3::new(f64::NAN, 0.0, 0.0),
        rotation: UnitQuaternion::identity(),
    };
    assert!(matches!(
        solver::solve(&Spatial::default(), &nan, &SolveOptions::default())
            .unwrap_err()
            .reason,
        IgError::NonFiniteTarget { .. }
    ));
    let bad = SolveOptions {
        alpha: 0.0,
        ..Default::default()
    };
    assert!(matches!(
        solver::solve(&Spatial::default(), &targets[0].1, &bad)
            .unwrap_err()
            .reason,
        IgError::InvalidOptions(_)
    ));
    // The straight target is only reached by an unstable (straight) rod: bounded failure.
    let straight = SpatialPose {
        position: Vector3::new(1.0, 0.0, 0.0),
        rotation: UnitQuaternion::identity(),
    };
    let opts = SolveOptions {
        max_iterations: 30,
        max_starts: Some(3),
        ..Default::default()
    };
    let model = Spatial::default();
    if let Ok(sol) = solver::solve(&model, &straight, &opts) {
        assert!(sol.stable);
    }
}

#[test]
fn ig_benchmark_report() {
    let r = benchmark_random_targets(30, 5);
    println!("{r:?}");
    assert_eq!(r.targets, 30);
    assert!(r.success_rate >= 0.9 && r.median_us > 0.0);
    // The observer saw every solve and at least one start each.
    assert_eq!(r.work.solves, 30);
    assert!(r.work.starts >= 30);
}
