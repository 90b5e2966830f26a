//! A complete stable search (issue 42, item 1): targets whose only stable rods lie beyond the
//! paper's box are found, and a failure says what was searched.
//!
//! `data/beyond_box_targets.jsonl`: 77 random workspace targets (|p| ≤ 0.95 uniform in the
//! disc, θ uniform; `search_coverage workspace 600 11`, an example of rod-ig-bench) that the
//! search of the previous release did not solve, each with a stable rod `a` reaching it that
//! an independent search found: the branch follower run from the 40 stable rods, out of a
//! million sampled with |a3| ≤ 100 and |F| ≤ 2000, whose tips are nearest the target
//! (`search_coverage reference`), polished from there (`search_coverage evidence`). Those
//! rods have |a3| = 4–86, |F| = 53–2011 and J(1, a) up to ~500: a seed must lie within ~1e-3
//! of one for Newton to converge.
//!
//! Every answer is checked by the independent DOP853 reference (tip at rtol 1e-12, its own
//! stability test), so the search is trusted only where an integration agrees.

use rod_ig_core::ode::planar_reference;
use rod_ig_core::planar::ig::{self, IgError, SolveOptions, Termination};
use rod_ig_core::rng::SplitMix64;
use rod_ig_core::{planar, wrap_angle, PlanarParams, PlanarPose, StabilityVerdict};
use serde_json::Value;

/// The target and the rod the independent search found there.
fn beyond_box_targets() -> Vec<(PlanarPose, PlanarParams)> {
    include_str!("data/beyond_box_targets.jsonl")
        .lines()
        .map(|line| {
            let v: Value = serde_json::from_str(line).expect("JSON line");
            let f = |key: &str, i: usize| v[key][i].as_f64().expect("number");
            (
                PlanarPose::new(f("target", 0), f("target", 1), f("target", 2)),
                PlanarParams::new(f("a", 0), f("a", 1), f("a", 2)),
            )
        })
        .collect()
}

/// The solution reaches `target` (1e-6, the solve's tolerance, plus the reference's own error)
/// and is stable, both by the DOP853 reference.
fn check_by_reference(target: &PlanarPose, a: &PlanarParams) {
    let (tip, _) = planar_reference::tip_and_jacobian(a, 1e-12).expect("reference tip");
    let dp = (tip.x - target.x).hypot(tip.y - target.y);
    let dth = wrap_angle(tip.theta - target.theta).abs();
    assert!(
        dp <= 2e-6 && dth <= 2e-6,
        "{a:?}: tip {tip:?} vs {target:?}"
    );
    let st = planar_reference::stability(a).expect("reference stability");
    assert!(st.stable, "{a:?}: the reference finds it unstable ({st:?})");
}

#[test]
fn stable_rods_beyond_the_box_are_found() {
    ig::warm_up();
    let targets = beyond_box_targets();
    assert_eq!(targets.len(), 77);
    let mut missed = Vec::new();
    for (target, rod) in &targets {
        // A stable rod exists there: the reference says so of the independent search's.
        check_by_reference(target, rod);
        // The search alone, from no guess. Its failures take up to ~200 ms, near the default
        // deadline: the far one keeps a loaded machine's clock out of a count of coverage.
        let options = SolveOptions {
            deadline: rod_ig_core::solver::MAX_DEADLINE,
            ..Default::default()
        };
        match ig::solve(target, &options) {
            Ok(s) => check_by_reference(target, &s.a),
            Err(f) => {
                assert_eq!(f.termination(), Termination::NoStableSolution, "{f}");
                missed.push((*target, f.reason));
            }
        }
    }
    for (t, why) in &missed {
        eprintln!("missed {t:?}: {why}");
    }
    // The previous release found none of them; this one misses 1 (a rod with |a3| ≈ 30–35 by
    // the separatrix, where the atlas beyond the box holds too few seeds).
    assert!(missed.len() <= 1, "{} of 77 missed", missed.len());
}

#[test]
fn the_targets_named_in_the_issue_are_found() {
    ig::warm_up();
    for target in [
        PlanarPose::new(-0.806021, -0.156856, -2.847325),
        PlanarPose::new(-0.5, -0.7, -3.0 * std::f64::consts::FRAC_PI_4),
    ] {
        let s = ig::solve(&target, &SolveOptions::default())
            .unwrap_or_else(|f| panic!("{target:?}: {f}"));
        check_by_reference(&target, &s.a);
    }
}

/// |a3| ≤ 100 and |F| ≤ 500, magnitudes log-uniform from 1e-3, exact zeros (10 %), forces
/// along the axes (half) or at any angle: the tips of the stable rods among them are found
/// (the issue's goal: 99.9 %). 50,000 of them (`search_coverage box`) were all found.
#[test]
fn stable_rods_of_the_goal_box_are_found() {
    ig::warm_up();
    let mut rng = SplitMix64::new(42);
    let (mut tried, mut missed) = (0, Vec::new());
    while tried < 2000 {
        let a = log_scale_rod(&mut rng);
        if planar::stability_verdict(&a) != Ok(StabilityVerdict::Stable) {
            continue;
        }
        let Ok(tip) = planar::tip(&a) else { continue };
        tried += 1;
        if let Err(f) = ig::solve(&tip, &SolveOptions::default()) {
            missed.push((a, f.reason));
        }
    }
    assert!(missed.len() <= 2, "missed {missed:?}");
}

fn log_scale_rod(rng: &mut SplitMix64) -> PlanarParams {
    let a3 = if rng.next_u64().is_multiple_of(10) {
        0.0
    } else {
        rng.signed_pow10(-3.0, 2.0)
    };
    let f = if rng.next_u64().is_multiple_of(10) {
        0.0
    } else {
        10f64.powf(rng.range(-3.0, 500f64.log10()))
    };
    let (a4, a5) = match rng.next_u64() % 8 {
        0 => (f, 0.0),
        1 => (-f, 0.0),
        2 => (0.0, f),
        3 => (0.0, -f),
        _ => {
            let phi = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
            (f * phi.cos(), f * phi.sin())
        }
    };
    PlanarParams::new(a3, a4, a5)
}

#[test]
fn a_failure_says_what_was_searched() {
    ig::warm_up();
    // Within reach (|p| < 1) but bent back on itself so close to full extension that no
    // stable rod gets there.
    let target = PlanarPose::new(0.999, 0.0, 3.0);
    let f = ig::solve(&target, &SolveOptions::default()).unwrap_err();
    let IgError::SearchExhausted(searched) = &f.reason else {
        panic!("expected SearchExhausted, got {}", f.reason);
    };
    assert!(searched.starts > 0 && searched.branches > 0, "{}", f.reason);
    assert_eq!(f.starts, searched.starts + searched.branches);
    let text = f.reason.to_string();
    assert!(
        text.contains("Newton starts") && text.contains("ms"),
        "{text}"
    );
}
