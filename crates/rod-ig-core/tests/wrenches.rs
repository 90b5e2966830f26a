//! The wrenches the rod exerts on its grippers (issue 52, item 2), checked by what they must
//! satisfy independently of how they are computed: the tip wrench against the 3-D μ-form
//! integration's own μ(1), and the balance of forces and moments of the whole rod with its
//! weight, whose moment ∫ r × w ĝ is integrated from the sampled shape (Simpson on 2,001
//! samples: error ≲ 1e-10 for these smooth rods, tolerance 1e-7).

use nalgebra::Vector3;
use rod_ig_core::planar::heavy::{self, Gravity};
use rod_ig_core::spatial::{self, heavy::Gravity3, SpatialParams, Stiffness};
use rod_ig_core::PlanarParams;

/// Simpson's rule over equally spaced samples on [0, 1] (odd count).
fn simpson(v: &[f64]) -> f64 {
    let n = v.len() - 1;
    let h = 1.0 / n as f64;
    let inner: f64 = (1..n)
        .map(|i| v[i] * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    h / 3.0 * (v[0] + v[n] + inner)
}

#[test]
fn planar_wrenches_balance_the_rod_and_its_weight() {
    let cases = [
        (PlanarParams::new(1.3, -20.0, 4.0), Gravity::NONE),
        (
            PlanarParams::new(-2.0, 5.0, 3.0),
            Gravity::new(8.0, [0.0, -1.0]).unwrap(),
        ),
        (
            PlanarParams::new(0.5, 12.0, 40.0),
            Gravity::new(60.0, [0.6, -0.8]).unwrap(),
        ),
        (
            PlanarParams::new(0.0, 0.0, 0.0),
            Gravity::new(1.0, [0.0, -1.0]).unwrap(),
        ),
    ];
    for (a, g) in cases {
        let w = heavy::wrenches(&a, &g).unwrap();
        assert_eq!(w.base.force, [a[1], a[2]]);
        assert_eq!(w.base.moment, a[0]);
        let shape = heavy::shape(&a, &g, 2001).unwrap();
        let tip = shape[2000];
        let (s, c) = tip.theta.sin_cos();
        let [fx, fy] = w.tip.force;
        let tip_world = [c * fx - s * fy, s * fx + c * fy];
        let load = g.load();
        // Forces: the grippers carry the weight.
        for i in 0..2 {
            let sum = w.base.force[i] + tip_world[i];
            assert!(
                (sum - load[i]).abs() < 1e-9,
                "{a:?}: force {i}: {sum} vs {}",
                load[i]
            );
        }
        // Moments about the base: the grippers' and the weight's, ∫ r × (−w ĝ)… balance:
        // what the rod exerts on the grippers equals the moment of its weight about the base.
        let px = simpson(&shape.iter().map(|p| p.x).collect::<Vec<_>>());
        let py = simpson(&shape.iter().map(|p| p.y).collect::<Vec<_>>());
        let weight_moment = px * load[1] - py * load[0];
        let grippers = w.base.moment + w.tip.moment + tip.x * tip_world[1] - tip.y * tip_world[0];
        assert!(
            (grippers - weight_moment).abs() < 1e-7,
            "{a:?}, w = {}: moments {grippers} vs {weight_moment}",
            g.weight()
        );
    }
}

#[test]
fn spatial_tip_wrench_is_minus_the_internal_wrench_at_the_tip() {
    let k = Stiffness::default();
    for a in [
        SpatialParams::new(0.3, -0.8, 1.2, 2.0, -3.0, 1.5),
        SpatialParams::new(1.0, 0.0, 2.0, -10.0, 4.0, 0.0),
    ] {
        let w = spatial::heavy::wrenches(&a, &k, &Gravity3::NONE).unwrap();
        let mu = spatial::states(&a, &k, &[1.0], 1e-12).unwrap()[0].mu;
        for i in 0..3 {
            assert!((w.tip.moment[i] + mu[i]).abs() < 1e-6, "{a:?}: m{i}");
            assert!((w.tip.force[i] + mu[3 + i]).abs() < 1e-6, "{a:?}: f{i}");
        }
    }
}

#[test]
fn spatial_wrenches_balance_the_rod_and_its_weight() {
    let k = Stiffness::default();
    let g = Gravity3::new(12.0, [0.0, 0.0, -1.0]).unwrap();
    let a = SpatialParams::new(0.4, -1.0, 0.7, 3.0, 1.0, 6.0);
    let w = spatial::heavy::wrenches(&a, &k, &g).unwrap();
    let shape = spatial::heavy::shape(&a, &k, &g, 2001).unwrap();
    let tip = shape[2000];
    let f_tip = tip.rotation * Vector3::from(w.tip.force);
    let m_tip = tip.rotation * Vector3::from(w.tip.moment);
    let load = Vector3::from(g.load());
    let f_sum = Vector3::from(w.base.force) + f_tip;
    assert!((f_sum - load).norm() < 1e-9, "{f_sum} vs {load}");
    let p = Vector3::new(
        simpson(&shape.iter().map(|q| q.position.x).collect::<Vec<_>>()),
        simpson(&shape.iter().map(|q| q.position.y).collect::<Vec<_>>()),
        simpson(&shape.iter().map(|q| q.position.z).collect::<Vec<_>>()),
    );
    let grippers = Vector3::from(w.base.moment) + m_tip + tip.position.cross(&f_tip);
    let weight = p.cross(&load);
    assert!((grippers - weight).norm() < 1e-7, "{grippers} vs {weight}");
}
