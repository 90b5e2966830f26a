//! Pinned and free ends (issue 52, item 1) against the public reference cases
//! (`ends_public.jsonl`: shooting with DOP853 at rtol 1e-12, refined by multiple shooting;
//! stability from the discretised energy's reduced Hessian with the same ends, N = 200/400 and
//! Richardson, cross-checked there by a focal-point count), and against the straight rod's
//! eigenvalues in closed form.

mod common;

use rod_ig_core::ends::{EndCondition, HeldEnds};
use rod_ig_core::planar::heavy::cable::SecondVariation;
use rod_ig_core::planar::heavy::held::{self, HeldError};
use rod_ig_core::planar::heavy::Gravity;
use rod_ig_core::planar::ig::SolveOptions;
use rod_ig_core::PlanarPose;
use serde_json::Value;
use std::f64::consts::PI;
use std::time::Duration;

fn cases() -> Vec<Value> {
    let text = std::fs::read_to_string(common::oracle_file("ends_public.jsonl")).expect("oracle");
    common::json_lines(&text).collect()
}

fn condition(v: &Value) -> EndCondition {
    v.as_str().expect("name").parse().expect("condition")
}

fn setup(case: &Value) -> (HeldEnds, Gravity, Option<PlanarPose>) {
    let ends = HeldEnds::new(
        condition(&case["base_condition"]),
        condition(&case["tip_condition"]),
    )
    .expect("ends");
    let g = common::numbers(&case["gravity"]);
    let gravity = Gravity::new(case["weight"].as_f64().expect("w"), [g[0], g[1]]).expect("g");
    let target = case["target"]
        .as_array()
        .map(|t| PlanarPose::new(t[0].as_f64().expect("x"), t[1].as_f64().expect("y"), 0.0));
    (ends, gravity, target)
}

fn options(max_turns: u32) -> SolveOptions {
    SolveOptions {
        deadline: Duration::from_secs(20),
        max_turns,
        ..SolveOptions::default()
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * (1.0 + b.abs())
}

/// Case A (clamped base, free tip): every root of κ(1)(a3) the reference lists, and no other;
/// each with its energy, its verdict, its Morse index and the least eigenvalue of the second
/// variation. Tolerances: a3 and energies 1e-9 relative (both sides are solved to residuals
/// ≤ 1e-12; the roots' κ(1) slope is up to 3e4, so 1e-13 in κ is ~1e-12 in a3); μ 1e-4
/// relative (two Richardson extrapolations of O(h²) discretisations, N ≥ 400 on each side).
#[test]
fn a_free_tip_has_every_equilibrium_of_the_reference_and_their_stability() {
    for case in cases().iter().filter(|c| c["case"] == "A") {
        let id = case["id"].as_str().expect("id");
        let (ends, gravity, target) = setup(case);
        assert!(target.is_none());
        let found = held::equilibria(ends, &gravity, None, &options(3)).expect("posed");
        let roots = case["roots"].as_array().expect("roots");
        assert_eq!(found.equilibria.len(), roots.len(), "{id}: number of roots");
        for r in roots {
            let a = common::numbers(&r["a"]);
            let s = found
                .equilibria
                .iter()
                .find(|s| close(s.a[0], a[0], 1e-9))
                .unwrap_or_else(|| panic!("{id}: root a3 = {} not found", a[0]));
            assert!(
                close(s.a[1], a[1], 1e-12) && close(s.a[2], a[2], 1e-12),
                "{id}"
            );
            assert!(close(s.energy, r["energy"].as_f64().unwrap(), 1e-9), "{id}");
            assert!(
                s.tip_curvature.abs() < 1e-9,
                "{id}: κ(1) = {}",
                s.tip_curvature
            );
            assert_eq!(s.stability.stable(), r["stable"].as_bool().unwrap(), "{id}");
            assert_eq!(
                s.stability.index as u64,
                r["morse_index"].as_u64().unwrap(),
                "{id}"
            );
            let mu = r["hessian_min_eig_rich"].as_f64().unwrap();
            assert!(
                close(s.stability.eigenvalue, mu, 1e-4),
                "{id}: μ {} vs {mu}",
                s.stability.eigenvalue
            );
        }
        let least = case["least_energy_known"].as_f64().unwrap();
        assert!(close(found.solutions[0].energy, least, 1e-9), "{id}");
        assert!(found.solutions.iter().all(|s| s.stability.stable()));
    }
}

/// Cases B (clamped base, pinned tip) and C (both pinned): the least-energy stable
/// equilibrium is the reference's (a, θ0 and energy to 1e-8 relative: Newton on both sides to
/// 1e-12 residuals, κ(1) slopes ~1e2), on target with the released moments zero, and its μ
/// agrees with the reduced Hessian's to 1e-4.
#[test]
fn pinned_ends_reach_the_reference_least_energy_rod() {
    for case in cases().iter().filter(|c| c["case"] != "A") {
        let id = case["id"].as_str().expect("id");
        let (ends, gravity, target) = setup(case);
        let target = target.expect("a target");
        let (best, found) =
            held::least_energy(ends, &gravity, Some(&target), &options(0)).expect("solved");
        let a = common::numbers(&case["a_least_energy_known"]);
        for i in 0..3 {
            assert!(
                close(best.a[i], a[i], 1e-8),
                "{id}: a {:?} vs {a:?}",
                best.a
            );
        }
        let theta0 = case
            .get("theta0_least_energy_known")
            .and_then(Value::as_f64)
            .unwrap_or(0.0);
        assert!(close(best.base_angle, theta0, 1e-8), "{id}: θ0");
        assert!(close(
            best.energy,
            case["least_energy_known"].as_f64().unwrap(),
            1e-9
        ));
        assert!((best.tip.x - target.x).abs() < 1e-10 && (best.tip.y - target.y).abs() < 1e-10);
        assert!(best.tip_curvature.abs() < 1e-10, "{id}: κ(1)");
        if ends.base() == EndCondition::Pinned {
            assert_eq!(best.a[0], 0.0, "{id}: a pinned base has no moment");
        }
        let reference = case["equilibria"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| close(e["energy"].as_f64().unwrap(), best.energy, 1e-9))
            .expect("the reference's least-energy rod");
        let mu = reference["hessian_min_eig_rich"].as_f64().unwrap();
        assert!(close(best.stability.eigenvalue, mu, 1e-4), "{id}: μ");
        // Every stable rod listed is one of the reference's equilibria, stable there too.
        for s in &found.solutions {
            let same = case["equilibria"].as_array().unwrap().iter().any(|e| {
                close(e["energy"].as_f64().unwrap(), s.energy, 1e-8)
                    && e["stable"].as_bool() == Some(true)
            });
            assert!(
                same,
                "{id}: a stable rod the reference does not list: {:?}",
                s.a
            );
        }
    }
}

/// The straight weightless rod's least eigenvalue with natural conditions, in closed form:
/// −v'' = μ v with v(0) = 0, v'(1) = 0 (free tip: μ = π²/4); with v'(0) = v'(1) = 0 and
/// ∫ v = 0 (both pinned, the tip's position held: μ = π²). The grid's Richardson value is
/// within 1e-6 relative (h² error ~1e-5 at N = 400, cancelled to h⁴).
#[test]
fn natural_conditions_give_the_straight_rods_eigenvalues() {
    use EndCondition::*;
    let free = SecondVariation::straight_rod(HeldEnds::new(Clamped, Free).unwrap());
    assert!(close(free, PI * PI / 4.0, 1e-6), "{free}");
    let pinned = SecondVariation::straight_rod(HeldEnds::new(Pinned, Pinned).unwrap());
    assert!(close(pinned, PI * PI, 1e-6), "{pinned}");
}

#[test]
fn targets_that_do_not_fit_the_tip_are_refused_by_name() {
    use EndCondition::*;
    let g = Gravity::new(10.0, [0.0, -1.0]).unwrap();
    let free = HeldEnds::new(Clamped, Free).unwrap();
    let pinned = HeldEnds::new(Clamped, Pinned).unwrap();
    let t = PlanarPose::new(0.5, 0.0, 0.0);
    let field = |e: HeldError| match e {
        HeldError::Target { field, why } => format!("{field}: {why}"),
        other => panic!("{other}"),
    };
    let e = held::equilibria(free, &g, Some(&t), &options(0)).unwrap_err();
    assert!(field(e).contains("free tip has no target"));
    let e = held::equilibria(pinned, &g, None, &options(0)).unwrap_err();
    assert!(field(e).contains("needs a target"));
    let far = PlanarPose::new(1.5, 0.0, 0.0);
    let e = held::equilibria(pinned, &g, Some(&far), &options(0)).unwrap_err();
    assert!(field(e).contains("unreachable"));
    let nan = PlanarPose::new(f64::NAN, 0.0, 0.0);
    assert!(held::equilibria(pinned, &g, Some(&nan), &options(0)).is_err());
    assert!(HeldEnds::new(Free, Clamped)
        .unwrap_err()
        .to_string()
        .starts_with("base_condition"));
    assert!("hinged".parse::<EndCondition>().is_err());
}

/// A deadline too short for any start ends the search with a failure that says so (never a
/// panic, never an answer past it).
#[test]
fn a_search_cut_by_its_deadline_says_so() {
    use EndCondition::*;
    let g = Gravity::new(50.0, [0.0, -1.0]).unwrap();
    let ends = HeldEnds::new(Pinned, Pinned).unwrap();
    let t = PlanarPose::new(0.8, 0.0, 0.0);
    let opts = SolveOptions {
        deadline: Duration::from_nanos(1),
        ..SolveOptions::default()
    };
    match held::least_energy(ends, &g, Some(&t), &opts) {
        Err(HeldError::NotFound { cut, .. }) => assert!(cut.contains("deadline")),
        other => panic!("{other:?}"),
    }
}

/// A long cable hanging from a level clamp (free tip) up to w = 10⁴: the roots scanned at
/// w = 300 are carried in load on the node states. Checked against the tension boundary
/// layer at the clamp (the elastica's first integral ½κ² = T (1 − cos Δ) with T = w and the
/// tangent turning Δ = π/2 from level to hanging): a3 → −√(2w), the relative gap shrinking like
/// 1/√w (0.4 % measured at 10⁴; asserted below 1 %), and the energy → −w/2 (the vertical
/// string) plus the layer's O(√w).
#[test]
fn a_long_cable_hangs_from_a_level_clamp_up_to_w_1e4() {
    use EndCondition::*;
    let ends = HeldEnds::new(Clamped, Free).unwrap();
    for w in [2_000.0, 10_000.0] {
        let g = Gravity::new(w, [0.0, -1.0]).unwrap();
        let (best, found) = held::least_energy(ends, &g, None, &options(0)).expect("hangs");
        let layer = -(2.0 * w).sqrt();
        assert!(
            ((best.a[0] - layer) / layer).abs() < 0.01,
            "w {w}: a3 {}",
            best.a[0]
        );
        assert!(
            (best.energy + 0.5 * w).abs() < 2.0 * w.sqrt(),
            "w {w}: E {}",
            best.energy
        );
        assert!(best.stability.stable() && best.turns == 0 && !best.self_intersects);
        assert!(best.tip_curvature.abs() < 1e-9);
        assert!(found.solutions.iter().all(|s| s.stability.stable()));
    }
}

/// The catenary's parameter u = d / (2 c) for span d of a unit string: sinh u / u = 1 / d.
fn catenary_u(span: f64) -> f64 {
    let (mut lo, mut hi) = (1e-9_f64, 20.0_f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid.sinh() / mid < 1.0 / span {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// A long cable pinned at both ends tends to the inextensible catenary as w grows (a pinned
/// end has no moment, so no bending boundary layer there): its base angle to
/// −atan(sinh u) with a gap shrinking like 1/√w (measured: 0.022 at w = 2,000, 0.011 at 10⁴;
/// asserted ≤ 1.5/√w and the ratio of the two gaps within 25 % of √5), and its potential
/// energy per unit weight to the catenary's ∫ y ds (computed here by Simpson's rule on 2·10⁴
/// intervals; agreement 4e-6 and 5e-7 measured, asserted ≤ 2e-5).
#[test]
fn a_long_cable_pinned_at_both_ends_tends_to_the_catenary() {
    use EndCondition::*;
    let span = 0.8;
    let u = catenary_u(span);
    let c = 0.5 * span / u;
    let theta_string = -u.sinh().atan();
    // ∫ y ds with y = c cosh((x − d/2)/c) − c cosh(u), ds = cosh((x − d/2)/c) dx.
    let n = 20_000;
    let f = |x: f64| {
        let z = (x - 0.5 * span) / c;
        (c * z.cosh() - c * u.cosh()) * z.cosh()
    };
    let h = span / n as f64;
    let potential: f64 = (0..=n)
        .map(|i| {
            let weight = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            weight * f(i as f64 * h)
        })
        .sum::<f64>()
        * h
        / 3.0;
    let ends = HeldEnds::new(Pinned, Pinned).unwrap();
    let target = PlanarPose::new(span, 0.0, 0.0);
    let mut gaps = Vec::new();
    for w in [2_000.0_f64, 10_000.0] {
        let g = Gravity::new(w, [0.0, -1.0]).unwrap();
        let (best, _) = held::least_energy(ends, &g, Some(&target), &options(0)).expect("hangs");
        let per_weight = (best.energy - best.elastic_energy) / w;
        assert!(
            (per_weight - potential).abs() < 2e-5,
            "w {w}: {per_weight} vs {potential}"
        );
        let gap = best.base_angle - theta_string;
        assert!(
            gap.abs() <= 1.5 / w.sqrt(),
            "w {w}: θ0 {} vs {theta_string}",
            best.base_angle
        );
        assert!(best.stability.stable() && best.turns == 0);
        gaps.push(gap);
    }
    let ratio = gaps[0] / gaps[1];
    assert!(
        (ratio / 5f64.sqrt() - 1.0).abs() < 0.25,
        "gap ratio {ratio}"
    );
}

/// A weightless cantilever with a point load at its free tip (`equilibria_with_tip_load`):
/// for P L²/EI = 1 the large-deflection elastica's tip sits at (0.94356, −0.30172)
/// (Bisshopp & Drucker 1945, Q. Appl. Math. 3, table 1: δ_v/L = 0.30172, δ_h/L = 0.05644),
/// and by the weightless closed form's moment balance κ(1) = a3 + a4 y(1) − a5 x(1) = 0
/// (checked to 1e-9 on the closed form, independent of the shooting that found it). A load on
/// a held tip is refused by name.
#[test]
fn a_cantilever_with_a_tip_load_matches_the_large_deflection_elastica() {
    use EndCondition::*;
    let ends = HeldEnds::new(Clamped, Free).unwrap();
    let found =
        held::equilibria_with_tip_load(ends, &Gravity::NONE, [0.0, -1.0], None, &options(0))
            .expect("posed");
    let (best, _) = held::best_of(ends, found).expect("a cantilever");
    assert!((best.tip.x - 0.94356).abs() < 2e-5, "{:?}", best.tip);
    assert!((best.tip.y + 0.30172).abs() < 2e-5, "{:?}", best.tip);
    let tip = rod_ig_core::planar::tip(&best.a).unwrap();
    let k1 = best.a[0] + best.a[1] * tip.y - best.a[2] * tip.x;
    assert!(k1.abs() < 1e-9, "κ(1) = {k1}");
    let pinned = HeldEnds::new(Clamped, Pinned).unwrap();
    let t = PlanarPose::new(0.5, 0.0, 0.0);
    let e =
        held::equilibria_with_tip_load(pinned, &Gravity::NONE, [0.0, -1.0], Some(&t), &options(0));
    assert!(matches!(
        e,
        Err(HeldError::Target {
            field: "tip_load",
            ..
        })
    ));
}

/// The forward map with held ends (`held::evaluate`, what `rod-ig forward` answers) against
/// the references: (1) every free-tip root of the public cases, given its a, is an equilibrium
/// with κ(1) = 0 (to 1e-9), the reference's energy (1e-9) and verdict; (2) a weightless rod
/// leaving a pinned base at angle φ is the closed form's clamped rod with the base force turned
/// by −φ, turned by φ (tip to 1e-10: two independent evaluations); (3) its J's first column is
/// ∂tip/∂φ (central differences, 1e-6); (4) a moment at a pinned base, a force at a free tip
/// other than w ĝ + load, a base angle at a clamped base are refused by field.
#[test]
fn the_forward_map_with_held_ends_matches_the_references() {
    for case in cases().iter().filter(|c| c["case"] == "A") {
        let (ends, gravity, _) = setup(case);
        for r in case["roots"].as_array().expect("roots") {
            let a = common::numbers(&r["a"]);
            let a = rod_ig_core::PlanarParams::new(a[0], a[1], a[2]);
            let e = held::evaluate(0.0, &a, &gravity, ends, [0.0; 2]).expect("evaluates");
            // An f64 a reproduces its rod to about condition × ε (single shooting from the
            // base), and κ, θ's derivative, one factor √w more (the boundary layer's scale).
            let tol = 1e-9_f64.max(1e-14 * e.condition * (1.0 + gravity.weight().sqrt()));
            assert!(
                e.solution.tip_curvature.abs() < tol,
                "{a:?}: κ(1) {} condition {:e}",
                e.solution.tip_curvature,
                e.condition
            );
            assert!(close(
                e.solution.energy,
                r["energy"].as_f64().unwrap(),
                1e-9
            ));
            assert_eq!(e.stable(), r["stable"].as_bool().unwrap(), "{a:?}");
        }
    }
    let pinned = HeldEnds::new(EndCondition::Pinned, EndCondition::Pinned).unwrap();
    for (phi, f) in [(0.3, [5.0, -2.0]), (-1.2, [-3.0, 8.0]), (2.5, [0.5, 0.0])] {
        let a = rod_ig_core::PlanarParams::new(0.0, f[0], f[1]);
        let e = held::evaluate(phi, &a, &Gravity::NONE, pinned, [0.0; 2]).expect("evaluates");
        let (s, c) = f64::sin_cos(phi);
        let turned = rod_ig_core::PlanarParams::new(0.0, c * f[0] + s * f[1], -s * f[0] + c * f[1]);
        let t = rod_ig_core::planar::tip(&turned).expect("closed form");
        let (x, y) = (c * t.x - s * t.y, s * t.x + c * t.y);
        let tip = e.solution.tip;
        assert!(
            (tip.x - x)
                .abs()
                .max((tip.y - y).abs())
                .max((tip.theta - t.theta - phi).abs())
                < 1e-10,
            "φ {phi}: {tip:?} vs ({x}, {y}, {})",
            t.theta + phi
        );
        let h = 1e-6;
        let at = |p: f64| {
            held::evaluate(p, &a, &Gravity::NONE, pinned, [0.0; 2])
                .expect("evaluates")
                .solution
                .tip
        };
        let (up, down) = (at(phi + h), at(phi - h));
        let fd = [
            (up.x - down.x) / (2.0 * h),
            (up.y - down.y) / (2.0 * h),
            (up.theta - down.theta) / (2.0 * h),
        ];
        for (r, f) in fd.iter().enumerate() {
            assert!((e.jacobian[(r, 0)] - f).abs() < 1e-6 * (1.0 + f.abs()));
        }
    }
    let refused = |phi: f64, a: [f64; 3], ends: HeldEnds, field: &str| {
        let g = Gravity::new(10.0, [0.0, -1.0]).unwrap();
        let a = rod_ig_core::PlanarParams::new(a[0], a[1], a[2]);
        match held::evaluate(phi, &a, &g, ends, [0.0; 2]) {
            Err(HeldError::Target { field: f, .. }) => assert_eq!(f, field),
            other => panic!("expected a refusal of {field}, got {other:?}"),
        }
    };
    refused(0.0, [1.0, 0.0, 0.0], pinned, "a");
    let free = HeldEnds::new(EndCondition::Clamped, EndCondition::Free).unwrap();
    refused(0.0, [1.0, 0.0, -5.0], free, "a");
    refused(0.4, [1.0, 0.0, -10.0], free, "base_angle");
}
