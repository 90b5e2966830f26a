//! Acceptance tests of the planar inverse geometry (issue #3).
//!
//! Reference data: `shared/oracle/ig_public.jsonl` (30 targets × 15 stable initial guesses) and
//! the figures of `shared/paper/FINDINGS.md` §8. The shared directory is found from the
//! environment variable `ROD_IG_SHARED`, else by walking up from this crate's directory to the
//! first ancestor holding `shared/oracle`.

use rod_ig_core::ig::{
    self,
    bench::{self, IgCase, ParamBox},
    IgError, Method, Objective, SolveOptions, Tracker,
};
use rod_ig_core::{wrap_angle, PlanarParams, PlanarPose};
use std::path::PathBuf;

fn shared_dir() -> PathBuf {
    if let Ok(p) = std::env::var("ROD_IG_SHARED") {
        let p = PathBuf::from(p);
        assert!(
            p.join("oracle").is_dir(),
            "ROD_IG_SHARED={} has no oracle/ directory",
            p.display()
        );
        return p;
    }
    let start = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for dir in start.ancestors() {
        let cand = dir.join("shared");
        if cand.join("oracle").is_dir() {
            return cand;
        }
    }
    panic!(
        "shared data directory not found: set ROD_IG_SHARED, or place `shared/oracle` in an \
         ancestor of {} (e.g. a sibling of the repository)",
        start.display()
    );
}

fn ig_cases() -> Vec<IgCase> {
    let path = shared_dir().join("oracle").join("ig_public.jsonl");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .enumerate()
        .map(|(i, l)| {
            serde_json::from_str(l)
                .unwrap_or_else(|e| panic!("{}:{}: bad case: {e}", path.display(), i + 1))
        })
        .collect()
}

/// Independent check: forward map within tolerance, stable by the stability test.
fn check_solution(target: &PlanarPose, a: &PlanarParams, tol: f64) {
    assert!(
        bench::verify(target, a, tol),
        "a = {a:?} does not solve {target:?} stably"
    );
}

#[test]
#[ignore]
fn report() {
    let cases = ig_cases();
    let t = std::time::Instant::now();
    let n = ig::warm_up();
    eprintln!("atlas: {n} seeds in {:?}", t.elapsed());
    for r in bench::table1(&cases, &[1.0, 0.9, 0.7, 0.5, 0.3, 0.2], 100, 1e-6) {
        eprintln!("{r:?}");
    }
    let o = SolveOptions::default();
    eprintln!("{:?}", bench::robust_from_starts(&cases, &o));
    eprintln!("{:?}", bench::robust_no_start(&cases, &o));
    eprintln!("{:?}", bench::robust_random(2000, 7, ParamBox::PAPER, &o));
    eprintln!("{:?}", bench::robust_random(2000, 8, ParamBox::PUBLIC, &o));
    let path = bench::ellipse_path(0.5, 0.2, 0.2, 0.3, 0.5, 400);
    eprintln!("{:?}", bench::tracking("ellipse", &path, &o));
    let path = bench::random_stable_path(3, ParamBox::PAPER, 400, 0.005);
    eprintln!("{:?}", bench::tracking("random stable path", &path, &o));
}
