//! The closed form against the independent oracle `data/oracle/cases_public.jsonl`
//! (2,000 cases, DOP853 at rtol 1e-12 with variational equations).
//!
//! Acceptance (data/oracle/README.md): tip ≤ 1e-11 abs, J ≤ 1e-8 relative (‖ΔJ‖_F/‖J‖_F),
//! stability verdict identical on every line, energy ≤ 1e-9 abs.
//! The data is part of the repository: if it cannot be read the test FAILS.

use rod_ig_core::planar;
use rod_ig_core::{PlanarJacobian, PlanarParams};

mod common;
use common::{numbers as arr, oracle_file};

#[test]
fn closed_form_matches_oracle_on_all_public_cases() {
    let path = oracle_file("cases_public.jsonl");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let (mut e_tip, mut e_jac, mut e_en, mut e_margin) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut mismatches = Vec::new();
    let mut n = 0;
    for (line_no, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let v: serde_json::Value = serde_json::from_str(line).expect("json line");
        let a = arr(&v["a"]);
        let a = PlanarParams::new(a[0], a[1], a[2]);
        let tip_o = arr(&v["tip"]); // θ, x, y
        let jac_o: Vec<Vec<f64>> = v["jac"].as_array().expect("jac").iter().map(arr).collect();
        // permute oracle rows (θ, x, y) → (x, y, θ)
        let jo = PlanarJacobian::from_fn(|i, j| jac_o[(i + 1) % 3][j]);
        let ev = planar::evaluate(&a).unwrap_or_else(|e| panic!("line {line_no}: {e}"));
        let dt = (ev.tip.x - tip_o[1])
            .abs()
            .max((ev.tip.y - tip_o[2]).abs())
            .max((ev.tip.theta - tip_o[0]).abs());
        e_tip = e_tip.max(dt);
        let dj = (ev.jacobian - jo).norm() / jo.norm();
        e_jac = e_jac.max(dj);
        let de = (ev.energy - v["energy"].as_f64().expect("energy")).abs();
        e_en = e_en.max(de);
        let stable_o = v["stable"].as_bool().expect("stable");
        let dm = v["det_min"].as_f64().expect("det_min");
        e_margin = e_margin.max((ev.stability.margin - dm).abs() / dm.abs().max(1.0));
        if stable_o != ev.stability.stable {
            mismatches.push((line_no, a, stable_o, dm, ev.stability));
        }
        // the separate entry points agree with evaluate()
        if line_no % 97 == 0 {
            let t = planar::tip(&a).expect("tip");
            assert!((t.x - ev.tip.x).abs() < 1e-12 && (t.theta - ev.tip.theta).abs() < 1e-12);
            let (_, j) = planar::tip_and_jacobian(&a).expect("tip_and_jacobian");
            assert_eq!(j, ev.jacobian);
            assert_eq!(planar::stability(&a).expect("stability"), ev.stability);
        }
        n += 1;
    }
    eprintln!(
        "oracle: {n} cases; max |Δtip| = {e_tip:.3e}, max rel ‖ΔJ‖ = {e_jac:.3e}, \
         max |Δenergy| = {e_en:.3e}, max margin deviation = {e_margin:.3e}, \
         verdict mismatches = {}",
        mismatches.len()
    );
    for m in &mismatches {
        eprintln!(
            "  mismatch line {}: a = {:?} oracle stable = {} det_min = {} ours = {:?}",
            m.0,
            m.1.as_slice(),
            m.2,
            m.3,
            m.4
        );
    }
    assert_eq!(n, 2000, "expected 2000 oracle lines");
    assert!(e_tip <= 1e-11, "tip error {e_tip:e}");
    assert!(e_jac <= 1e-8, "J error {e_jac:e}");
    assert!(e_en <= 1e-9, "energy error {e_en:e}");
    assert!(
        mismatches.is_empty(),
        "{} stability verdict mismatches",
        mismatches.len()
    );
}
