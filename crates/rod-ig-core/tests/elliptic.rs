//! Elliptic functions against mpmath (80 digits; `scripts/references/gen_elliptic_fixtures.py`), and
//! identities as property tests.
//!
//! Fixture parameters go down to m1 = 1e-25 (m passed as fl(1 − m1) = 1) and up from
//! m = 1e-30; u up to ±40 (beyond K for every m1 ≥ 1e-25).

use proptest::prelude::*;
use rod_ig_core::elliptic::{self, Landen};
use rod_ig_core::scalar::{Dual3, Real};

fn fixture(name: &str) -> Vec<serde_json::Value> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("data")
        .join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read fixture {}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect()
}

fn f(v: &serde_json::Value, k: &str) -> f64 {
    v[k].as_f64().unwrap_or_else(|| panic!("field {k}"))
}

/// sn, cn, dn and E(am u|m) to ≤ 1e-14 absolute (docs/math.md §4) for |u| ≤ 10, and ≤ 1e-14·|u|/10
/// beyond (the argument itself carries a relative rounding of the order of 1e-16·|u|·r);
/// am to 1e-14 relative to max(1, |am|).
#[test]
fn jacobi_matches_mpmath() {
    let cases = fixture("elliptic_jacobi.jsonl");
    assert!(cases.len() > 200);
    let mut worst = [0.0f64; 5];
    for c in &cases {
        let (u, m, m1) = (f(c, "u"), f(c, "m"), f(c, "m1"));
        let j = elliptic::jacobi(u, m, m1);
        let e = elliptic::ellip_e_of_am(u, m, m1);
        let scale = (u.abs() / 10.0).max(1.0);
        let errs = [
            (j.sn - f(c, "sn")).abs() / scale,
            (j.cn - f(c, "cn")).abs() / scale,
            (j.dn - f(c, "dn")).abs() / scale,
            (j.am - f(c, "am")).abs() / f(c, "am").abs().max(1.0),
            (e - f(c, "e_am")).abs() / f(c, "e_am").abs().max(1.0),
        ];
        for (w, e) in worst.iter_mut().zip(errs) {
            *w = w.max(e);
        }
        for (name, e) in ["sn", "cn", "dn", "am", "E(am)"].iter().zip(errs) {
            assert!(e <= 1e-14, "{name} error {e:e} at u={u} m={m} m1={m1}");
        }
    }
    eprintln!(
        "jacobi vs mpmath, worst scaled errors sn cn dn am E(am): {:?}",
        worst.map(|w| format!("{w:.2e}"))
    );
}

/// F, E, D(φ|m) (any real φ) and complete K, E to 4e-15 relative to max(1, |value|).
#[test]
fn legendre_integrals_match_mpmath() {
    let cases = fixture("elliptic_integrals.jsonl");
    assert!(cases.len() > 200);
    let mut worst = 0.0f64;
    for c in &cases {
        let (phi, m, m1) = (f(c, "phi"), f(c, "m"), f(c, "m1"));
        let (ff, ee, dd) = elliptic::ellip_fed(phi, m, m1);
        let (k, ec, _) = elliptic::ellip_complete(m, m1);
        for (name, got, want) in [
            ("F", ff, f(c, "F")),
            ("E", ee, f(c, "E")),
            ("D", dd, f(c, "D")),
            ("K", k, f(c, "K")),
            ("Ec", ec, f(c, "Ec")),
        ] {
            let e = (got - want).abs() / want.abs().max(1.0);
            worst = worst.max(e);
            assert!(
                e <= 4e-15,
                "{name}({phi}|m={m}, m1={m1}) = {got} vs {want}: {e:e}"
            );
        }
    }
    eprintln!("integrals vs mpmath: worst relative error {worst:.2e}");
}

/// The phase inverse F(atan2(s, c)|m) through c = 0 and beyond π/2.
#[test]
fn inverse_phase_covers_all_quadrants() {
    for &m1 in &[1e-20, 1e-8, 0.01, 0.5, 0.99] {
        let m = 1.0 - m1;
        let k = elliptic::ellip_k(m1);
        for i in -39..40 {
            let psi = i as f64 * 0.04;
            let (s, c) = psi.sin_cos();
            let want = elliptic::ellip_f(psi, m, m1);
            let got = elliptic::inverse_phase(s, c, m, m1, k);
            assert!(
                (got - want).abs() <= 1e-14 * want.abs().max(1.0),
                "{psi} {m1}"
            );
        }
    }
}

/// Derivatives propagated through the Landen recursion agree with central differences.
#[test]
fn dual_jacobi_derivatives() {
    for &(u, m) in &[(0.7, 0.3), (2.2, 0.9), (-1.3, 0.05), (5.0, 0.999)] {
        let du = Dual3::variable(u, 0);
        let dm = Dual3::variable(m, 1);
        let dm1 = Dual3::constant(1.0) - dm;
        let j = Landen::new(dm, dm1).eval(du);
        let h = 1e-6;
        let fsn = |u: f64, m: f64| elliptic::jacobi(u, m, 1.0 - m).sn;
        let fdn = |u: f64, m: f64| elliptic::jacobi(u, m, 1.0 - m).dn;
        for (d, fun) in [(j.sn, &fsn as &dyn Fn(f64, f64) -> f64), (j.dn, &fdn)] {
            let gu = (fun(u + h, m) - fun(u - h, m)) / (2.0 * h);
            let gm = (fun(u, m + h) - fun(u, m - h)) / (2.0 * h);
            assert!((d.g[0] - gu).abs() < 1e-7, "d/du {} vs {gu}", d.g[0]);
            assert!((d.g[1] - gm).abs() < 1e-6, "d/dm {} vs {gm}", d.g[1]);
            assert!(d.re().is_finite());
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn jacobi_identities(u in -60.0f64..60.0, lm1 in -25.0f64..0.0, small in proptest::bool::ANY) {
        // either m1 = 10^lm1 (near the separatrix) or m = 10^lm1 (small m)
        let (m, m1) = if small { let m = 10f64.powf(lm1); (m, 1.0 - m) } else { let m1 = 10f64.powf(lm1); (1.0 - m1, m1) };
        let j = elliptic::jacobi(u, m, m1);
        prop_assert!((j.sn * j.sn + j.cn * j.cn - 1.0).abs() <= 4e-16);
        prop_assert!((j.dn * j.dn + m * j.sn * j.sn - 1.0).abs() <= 1e-15);
        prop_assert!(j.dn > 0.0);
        // F(am u|m) = u; dF/dφ = 1/dn, so the rounding of am (a few ulps of |am|) is amplified by 1/dn
        let back = elliptic::ellip_f(j.am, m, m1);
        let tol = 1e-13 * u.abs().max(1.0) + 4e-15 * j.am.abs().max(1.0) / j.dn;
        prop_assert!((back - u).abs() <= tol, "F(am u) = {} vs {}", back, u);
    }

    #[test]
    fn am_is_continuous_and_increasing(u in -30.0f64..30.0, m in 0.0f64..1.0) {
        let m1 = 1.0 - m;
        let h = 1e-4;
        let a0 = elliptic::jacobi(u, m, m1).am;
        let a1 = elliptic::jacobi(u + h, m, m1).am;
        // am' = dn ∈ [√m1, 1]
        prop_assert!(a1 - a0 > 0.0 && a1 - a0 <= h * (1.0 + 1e-9));
    }

    #[test]
    fn amplitude_round_trip(phi in -20.0f64..20.0, m in 0.0f64..0.999) {
        let m1 = 1.0 - m;
        let u = elliptic::ellip_f(phi, m, m1);
        let j = elliptic::jacobi(u, m, m1);
        prop_assert!((j.am - phi).abs() <= 2e-14 * phi.abs().max(1.0));
    }
}
