//! `wrap_angle` against 80-digit reductions (scripts/references/gen_angle_tables.py, mpmath): 423 angles
//! from 1e-3 to f64::MAX, both signs, exact multiples of 2π rounded to f64 and integers near
//! 2⁵³. Tolerance: 1 ulp of the result (the reduction is correctly rounded up to the last bit
//! of a double-double product), and the result lies in (−π, π].

use rod_ig_core::wrap_angle;
use std::f64::consts::PI;

mod common;

#[test]
fn reduction_matches_80_digit_values() {
    let text = include_str!("data/angle_reduction.jsonl");
    let mut worst = 0.0f64;
    for v in common::json_lines(text) {
        let x = v["x"].as_f64().expect("x");
        let want = v["wrapped"].as_f64().expect("wrapped");
        let got = wrap_angle(x);
        // f64 PI is below π: −PI is inside (−π, π].
        assert!(
            (-PI..=PI).contains(&got),
            "wrap_angle({x:e}) = {got} outside (−π, π]"
        );
        let ulp = f64::EPSILON * want.abs().max(f64::MIN_POSITIVE);
        let err = (got - want).abs() / ulp;
        worst = worst.max(err);
        assert!(
            err <= 1.0 || (got - want).abs() <= 1e-300,
            "wrap_angle({x:e}) = {got:e}, 80 digits: {want:e}"
        );
    }
    eprintln!("angle reduction: worst error {worst:.2} ulp");
}
