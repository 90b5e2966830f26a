//! Which rods each planar entry point answers: `cargo run --release -p rod-ig-bench --example
//! domain_scan -- N SEED [F_MAX]` samples N rods with log-uniform magnitudes (|a3| from 1e-300
//! to 1e12, |a4|, |a5| to F_MAX (1e12), signs, 10 % exact zeros) and counts those that `evaluate` (forward),
//! `PlanarRod::new` (shape), `tip_and_jacobian` and `stability` answer differently
//! (issue 42, item 2: one refusal domain), listing the first of each kind.
use rod_ig_bench::planar::log_scale_component;
use rod_ig_core::planar::{self, PlanarRod};
use rod_ig_core::rng::SplitMix64;
use rod_ig_core::PlanarParams;
use std::collections::BTreeMap;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    // Largest |a4|, |a5| sampled (|a3| always up to 1e12).
    let f_max: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1e12);
    let mut r = SplitMix64::new(seed);
    let mut kinds: BTreeMap<String, (usize, String)> = BTreeMap::new();
    let mut refused = 0;
    // (√‖F‖, |a3|) of every rod some entry point refuses: where refusals live.
    let mut refusing: Vec<(f64, f64)> = Vec::new();
    for _ in 0..n {
        let a = PlanarParams::new(
            log_scale_component(&mut r, 1e12),
            log_scale_component(&mut r, f_max),
            log_scale_component(&mut r, f_max),
        );
        let forward = planar::evaluate(&a);
        let answers = [
            ("forward", forward.is_ok()),
            // Drawn: built, and every pose of a 17-sample shape finite.
            (
                "shape",
                PlanarRod::new(&a).is_ok_and(|r| r.shape(17).iter().all(|p| p.is_finite())),
            ),
            ("tip_and_jacobian", planar::tip_and_jacobian(&a).is_ok()),
            ("stability", planar::stability(&a).is_ok()),
        ];
        refused += usize::from(forward.is_err());
        if answers.iter().any(|x| !x.1) {
            refusing.push((a[1].hypot(a[2]).sqrt(), a[0].abs()));
        }
        if answers.iter().any(|x| x.1 != answers[0].1) {
            let key: Vec<String> = answers
                .iter()
                .map(|(name, ok)| format!("{name} {}", if *ok { "ok" } else { "refused" }))
                .collect();
            let e = kinds.entry(key.join(", ")).or_insert((0, String::new()));
            e.0 += 1;
            if e.1.is_empty() {
                e.1 = format!(
                    "{:?}: {:?}",
                    [a[0], a[1], a[2]],
                    forward.err().map(|e| e.to_string())
                );
            }
        }
    }
    println!("{n} rods, {refused} refused by forward");
    refusing.sort_by(|x, y| x.0.total_cmp(&y.0));
    let smallest: Vec<String> = refusing
        .iter()
        .take(5)
        .map(|(f, a3)| format!("sqrt|F| {f:.3e} |a3| {a3:.1e}"))
        .collect();
    println!(
        "smallest forces among rods some entry point refuses: {}",
        smallest.join("; ")
    );
    for (k, (count, example)) in &kinds {
        println!("{count:6} {k}\n       e.g. {example}");
    }
}
