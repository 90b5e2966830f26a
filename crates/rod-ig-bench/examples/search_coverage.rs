//! How complete the planar robust search is (issue 42, item 1), and the independent search
//! that the test data of `rod-ig-core/tests/search.rs` comes from.
//!
//! ```text
//! cargo run --release -p rod-ig-bench --example search_coverage -- box N SEED
//!     stable rods with |a3| <= 100, |F| <= 500 (log-scale magnitudes, exact zeros): their
//!     tips solved from no guess; prints the misses and the count
//! cargo run --release -p rod-ig-bench --example search_coverage -- workspace N SEED
//!     N random targets, |p| <= 0.95 uniform in the disc, theta uniform: prints `nf x,y,theta`
//!     for each target not solved, the count and the solve times
//! cargo run --release -p rod-ig-bench --example search_coverage -- reference FILE
//!     for each `nf` line of FILE: the branch follower from the 40 stable rods, out of a
//!     million sampled with |a3| <= 100, |F| <= 2000, whose tips are nearest the target;
//!     prints `x,y,theta,a3,a4,a5` where one reaches it (slow: ~10 s a target)
//! cargo run --release -p rod-ig-bench --example search_coverage -- solves N
//!     N stable rods of the paper's box solved from their tips (for callgrind's instruction
//!     counts of the search: `--toggle-collect='rod_ig_core::planar::ig::solve'`)
//! cargo run --release -p rod-ig-bench --example search_coverage -- evidence FILE
//!     for each `x,y,theta,a3,a4,a5` line: the rod polished onto the target (its branch
//!     followed, else Newton from it) and checked by the DOP853 reference (tip 2e-6, stable):
//!     JSON lines {"target", "a"}
//! cargo run --release -p rod-ig-bench --example search_coverage -- heavy N SEED
//!     issue 41's success rate: N targets reached by stable heavy rods (log-scale a as in
//!     `box`, w = 10^U(-1, log 200) with 5 % at exactly 200, gravity along -y for half, in any
//!     direction for the rest; tips within 0.98 of the base), solved by the robust search
//!     with weight from no guess; each answer re-checked (on target to 1e-6, stable); prints
//!     `miss w gx,gy x,y,theta a3,a4,a5 why` per failure, the count and the time quantiles
//! cargo run --release -p rod-ig-bench --example search_coverage -- heavy3d N SEED
//!     the same for the 3-D rod with weight: moments and forces log-scale (1e-2..10 and
//!     1e-2..100, signs, 10 % exact zeros), w = 10^U(-1, log 200), gravity along -z for half
//! cargo run --release -p rod-ig-bench --example search_coverage -- long N SEED [objective]
//!     issue 51's success rate: N targets of stable loop-free long cables (w = 10^U(log 200, 4),
//!     gravity along -y for half, anywhere for the rest; a3 = ±10^U(0, 2) with 5 % zeros,
//!     n(0) = s w ĝ + 10^U(0, log w) in a random direction, s = U(0, 1); the rod's node
//!     states integrated from the base, kept when stable by the second variation, loop-free,
//!     not crossing itself and |tip| <= 0.98), solved from no guess (deadline 2 s; objective
//!     `first` or `least_energy`); each answer re-checked on target (1e-6) and stable
//! cargo run --release -p rod-ig-bench --example search_coverage -- pinned N SEED
//!     issue 52's held ends: N stable, loop-free equilibria with a pinned tip (clamped or
//!     pinned base; w = 10^U(-1, log 300), gravity along -y for half), drawn as a free tip
//!     carrying a log-scale force (clamped base: every root of κ(1)(a3)) or as a scan of the
//!     base angle for κ(1) = 0 (pinned base, a3 = 0) -- not the search's route -- and each
//!     solved from its tip's position by `held::least_energy` (deadline 2 s); prints the
//!     misses, the answers of more energy than the drawn rod, the count and the times
//! cargo run --release -p rod-ig-bench --example search_coverage -- long3d N SEED
//!     the same in 3-D (`families::long_cable_3d`: the planar long cables turned into a random
//!     plane and carried out of it, stable in 3-D), solved with the default options
//! ```
use rod_ig_core::ode::planar_reference;
use rod_ig_core::planar::{self, ig, PlanarClosedForm};
use rod_ig_core::rng::SplitMix64;
use rod_ig_core::solver::BranchFollower;
use rod_ig_core::{wrap_angle, PlanarParams, PlanarPose, StabilityVerdict};
use std::f64::consts::PI;
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize, default: u64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(default);
    ig::warm_up();
    match args.first().map(String::as_str) {
        Some("box") => goal_box(num(1, 2000) as usize, num(2, 1)),
        Some("workspace") => workspace(num(1, 600) as usize, num(2, 11)),
        Some("reference") => reference(&read(args.get(1))),
        Some("evidence") => evidence(&read(args.get(1))),
        Some("solves") => solves(num(1, 500) as usize),
        Some("heavy") => heavy_coverage(num(1, 3000) as usize, num(2, 41)),
        Some("heavy3d") => heavy_coverage_3d(num(1, 500) as usize, num(2, 43)),
        Some("long3d") => long_coverage_3d(num(1, 100) as usize, num(2, 53)),
        Some("pinned") => pinned_coverage(num(1, 200) as usize, num(2, 52)),
        Some("long") => long_coverage(
            num(1, 200) as usize,
            num(2, 51),
            args.get(3).map(String::as_str) == Some("least_energy"),
        ),
        _ => {
            eprintln!("usage: search_coverage box|workspace|heavy N SEED | reference|evidence FILE")
        }
    }
}

fn read(path: Option<&String>) -> String {
    std::fs::read_to_string(path.expect("a file")).expect("readable file")
}

/// |a3| ≤ 100, |F| ≤ 500: magnitudes log-uniform from 1e-3, 10 % exact zeros, half the
/// forces along an axis.
fn log_scale_rod(r: &mut SplitMix64) -> PlanarParams {
    let a3 = match r.next_u64() % 10 {
        0 => 0.0,
        _ => r.signed_pow10(-3.0, 2.0),
    };
    let f = match r.next_u64() % 10 {
        0 => 0.0,
        _ => 10f64.powf(r.range(-3.0, 500f64.log10())),
    };
    let (a4, a5) = match r.next_u64() % 8 {
        0 => (f, 0.0),
        1 => (-f, 0.0),
        2 => (0.0, f),
        3 => (0.0, -f),
        _ => {
            let phi = r.range(-PI, PI);
            (f * phi.cos(), f * phi.sin())
        }
    };
    PlanarParams::new(a3, a4, a5)
}

fn goal_box(n: usize, seed: u64) {
    let mut r = SplitMix64::new(seed);
    let (mut tried, mut missed) = (0, 0);
    while tried < n {
        let a = log_scale_rod(&mut r);
        if planar::stability_verdict(&a) != Ok(StabilityVerdict::Stable) {
            continue;
        }
        let Ok(tip) = planar::tip(&a) else { continue };
        tried += 1;
        if let Err(f) = ig::solve(&tip, &ig::SolveOptions::default()) {
            missed += 1;
            println!("missed a = {:?}: {}", a.as_slice(), f.reason);
        }
    }
    println!("goal box: {tried} stable rods, {missed} tips not solved");
}

fn workspace(n: usize, seed: u64) {
    let mut r = SplitMix64::new(seed);
    let mut times = Vec::with_capacity(n);
    let mut found = 0;
    for _ in 0..n {
        let (rho, phi) = (0.95 * r.uniform().sqrt(), r.range(-PI, PI));
        let t = PlanarPose::new(rho * phi.cos(), rho * phi.sin(), r.range(-PI, PI));
        let t0 = Instant::now();
        let result = ig::solve(&t, &ig::SolveOptions::default());
        times.push(t0.elapsed().as_secs_f64() * 1e6);
        match result {
            Ok(_) => found += 1,
            Err(f) => println!("nf {:.6},{:.6},{:.6} {}", t.x, t.y, t.theta, f.reason),
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "workspace: {found} of {n} solved; time median {:.0} µs, p90 {:.0} µs, max {:.0} µs",
        times[n / 2],
        times[n * 9 / 10],
        times[n - 1]
    );
}

/// The targets of the `nf x,y,theta` lines.
fn targets(text: &str) -> Vec<PlanarPose> {
    text.lines()
        .filter_map(|l| l.strip_prefix("nf "))
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .next()
                .unwrap_or("")
                .split(',')
                .map(|x| x.parse().expect("number"))
                .collect();
            PlanarPose::new(v[0], v[1], v[2])
        })
        .collect()
}

fn reference(text: &str) {
    let mut r = SplitMix64::new(99);
    let mut pool: Vec<(PlanarParams, [f64; 3])> = Vec::new();
    while pool.len() < 1_000_000 {
        let a = match pool.len() % 3 {
            0 => log_scale_rod(&mut r),
            1 => PlanarParams::new(
                r.range(-100.0, 100.0),
                r.range(-500.0, 500.0),
                r.range(-500.0, 500.0),
            ),
            _ => PlanarParams::new(
                r.range(-40.0, 40.0),
                r.range(-300.0, 100.0),
                r.range(-200.0, 200.0),
            ),
        };
        if planar::stability_verdict(&a) != Ok(StabilityVerdict::Stable) {
            continue;
        }
        if let Ok(t) = planar::tip(&a) {
            pool.push((a, [t.x, t.y, wrap_angle(t.theta)]));
        }
    }
    for t in targets(text) {
        let d = |p: &[f64; 3]| {
            let dt = 0.5 * wrap_angle(p[2] - t.theta);
            (p[0] - t.x).powi(2) + (p[1] - t.y).powi(2) + dt * dt
        };
        let mut idx: Vec<usize> = (0..pool.len()).collect();
        idx.select_nth_unstable_by(40, |&i, &j| d(&pool[i].1).total_cmp(&d(&pool[j].1)));
        idx[..40].sort_by(|&i, &j| d(&pool[i].1).total_cmp(&d(&pool[j].1)));
        let options = ig::SolveOptions {
            deadline: Duration::from_millis(300),
            ..Default::default()
        };
        let reached = idx[..40].iter().find_map(|&i| {
            let mut f = BranchFollower::holding(PlanarClosedForm, options, pool[i].0).ok()?;
            f.follow(&t).result.ok().filter(|s| s.stable)
        });
        if let Some(s) = reached {
            println!(
                "{:?},{:?},{:?},{:?},{:?},{:?}",
                t.x, t.y, t.theta, s.a[0], s.a[1], s.a[2]
            );
        }
    }
}

fn evidence(text: &str) {
    let options = ig::SolveOptions {
        deadline: Duration::from_secs(5),
        max_iterations: 2000,
        ..Default::default()
    };
    for line in text.lines() {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.trim().parse().expect("number"))
            .collect();
        let t = PlanarPose::new(v[0], v[1], v[2]);
        let hint = PlanarParams::new(v[3], v[4], v[5]);
        let followed = BranchFollower::holding(PlanarClosedForm, options, hint)
            .ok()
            .and_then(|mut f| f.follow(&t).result.ok());
        let polished = || {
            let o = ig::SolveOptions {
                initial_guess: Some(hint),
                ..options
            };
            ig::solve(&t, &o).ok()
        };
        let Some(a) = followed.or_else(polished).map(|s| s.a) else {
            eprintln!("no rod from {line}");
            continue;
        };
        let (tip, _) = planar_reference::tip_and_jacobian(&a, 1e-12).expect("reference tip");
        let on_target = (tip.x - t.x).hypot(tip.y - t.y) <= 2e-6
            && wrap_angle(tip.theta - t.theta).abs() <= 2e-6;
        let stable = planar_reference::stability(&a).is_ok_and(|s| s.stable);
        if !(on_target && stable) {
            eprintln!("the reference disagrees on {line}");
            continue;
        }
        println!(
            "{{\"target\":[{:?},{:?},{:?}],\"a\":[{:?},{:?},{:?}]}}",
            t.x, t.y, t.theta, a[0], a[1], a[2]
        );
    }
}

fn solves(n: usize) {
    let mut r = SplitMix64::new(2024);
    let mut solved = 0;
    let mut tried = 0;
    while tried < n {
        let a = PlanarParams::new(
            r.range(-2.0 * PI, 2.0 * PI),
            r.range(-100.0, 100.0),
            r.range(-100.0, 100.0),
        );
        if planar::stability_verdict(&a) != Ok(StabilityVerdict::Stable) {
            continue;
        }
        let Ok(tip) = planar::tip(&a) else { continue };
        tried += 1;
        solved += usize::from(ig::solve(&tip, &ig::SolveOptions::default()).is_ok());
    }
    println!("{solved} of {n} solved");
}

/// Issue 41's success rate of the robust search with weight (see the module's header).
fn heavy_coverage(n: usize, seed: u64) {
    use rod_ig_core::planar::heavy::{self, Gravity};
    let mut r = SplitMix64::new(seed);
    let mut cases = Vec::new();
    while cases.len() < n {
        let a = log_scale_rod(&mut r);
        let w = if r.next_u64().is_multiple_of(20) {
            200.0
        } else {
            10f64.powf(r.range(-1.0, 200f64.log10()))
        };
        let dir = if r.next_u64().is_multiple_of(2) {
            [0.0, -1.0]
        } else {
            let phi = r.range(-PI, PI);
            [phi.cos(), phi.sin()]
        };
        let Ok(g) = Gravity::new(w, dir) else {
            continue;
        };
        let Ok(e) = heavy::evaluate(&a, &g) else {
            continue;
        };
        if e.stability.verdict() == StabilityVerdict::Stable && e.tip.x.hypot(e.tip.y) <= 0.98 {
            cases.push((a, g, e.tip));
        }
    }
    let cases: Vec<_> = cases.into_iter().map(|(a, g, tip)| (g, a, tip)).collect();
    solve_and_report(&cases, &ig::SolveOptions::default());
}

/// Issue 41's success rate of the 3-D robust search with weight (see the module's header).
fn heavy_coverage_3d(n: usize, seed: u64) {
    use rod_ig_core::spatial::heavy::{self as heavy3, Gravity3};
    use rod_ig_core::spatial::{SpatialParams, Stiffness};
    let mut r = SplitMix64::new(seed);
    let k = Stiffness::default();
    let mut cases = Vec::new();
    while cases.len() < n {
        let a = SpatialParams::from_fn(|i, _| match r.next_u64() % 10 {
            0 => 0.0,
            _ if i < 3 => r.signed_pow10(-2.0, 1.0),
            _ => r.signed_pow10(-2.0, 2.0),
        });
        let w = 10f64.powf(r.range(-1.0, 200f64.log10()));
        let dir = if r.next_u64().is_multiple_of(2) {
            [0.0, 0.0, -1.0]
        } else {
            [r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-1.0, 1.0)]
        };
        let Ok(g) = Gravity3::new(w, dir) else {
            continue;
        };
        let Ok(e) = heavy3::evaluate(&a, &k, &g) else {
            continue;
        };
        if e.stability.verdict() == StabilityVerdict::Stable && e.tip.position.norm() <= 0.98 {
            cases.push((a, g, e.tip));
        }
    }
    solve_and_report_3d(&cases);
}

/// Issue 51's success rate in 3-D: N targets of stable long cables (`families::long_cable_3d`).
fn long_coverage_3d(n: usize, seed: u64) {
    let mut r = SplitMix64::new(seed);
    let mut cases = Vec::new();
    while cases.len() < n {
        cases.extend(rod_ig_bench::families::long_cable_3d(&mut r));
        eprint!("\rdrawn {}", cases.len());
    }
    eprintln!();
    solve_and_report_3d(&cases);
}

/// Solves every (a, gravity, target) 3-D case from no guess (default options), re-checks each
/// answer (on target to 1e-6, stable), prints the misses, the count and the time quantiles.
fn solve_and_report_3d(
    cases: &[(
        rod_ig_core::spatial::SpatialParams,
        rod_ig_core::spatial::heavy::Gravity3,
        rod_ig_core::spatial::SpatialPose,
    )],
) {
    use rod_ig_core::solver;
    use rod_ig_core::spatial::heavy as heavy3;
    use rod_ig_core::spatial::{HeavySpatial, Stiffness};
    let k = Stiffness::default();
    let options = solver::SolveOptions::default();
    let (mut solved, mut wrong, mut times) = (0usize, 0usize, Vec::new());
    // ONLY=i,j,…: re-run those cases alone (the indices the misses print).
    let only: Option<Vec<usize>> = std::env::var("ONLY")
        .ok()
        .map(|v| v.split(',').filter_map(|x| x.parse().ok()).collect());
    let mut tried = 0usize;
    for (index, (a, g, target)) in cases.iter().enumerate() {
        if only.as_ref().is_some_and(|o| !o.contains(&index)) {
            continue;
        }
        tried += 1;
        let model = HeavySpatial {
            stiffness: k,
            gravity: *g,
        };
        let t0 = Instant::now();
        let result = solver::solve(&model, target, &options);
        times.push(t0.elapsed().as_secs_f64() * 1e6);
        let why = match &result {
            Ok(s) => match heavy3::evaluate(&s.a, &k, g) {
                Ok(e)
                    if e.stability.stable
                        && (e.tip.position - target.position).norm() <= 1e-6
                        && e.tip.rotation.angle_to(&target.rotation) <= 1e-6 =>
                {
                    solved += 1;
                    continue;
                }
                other => {
                    wrong += 1;
                    format!("WRONG: re-check gives {other:?}")
                }
            },
            Err(f) => f.reason.to_string(),
        };
        println!(
            "miss #{index} {:.0} µs w={:.6e} g={:?} target={:?} a={:?} {why}",
            times.last().copied().unwrap_or(0.0),
            g.weight(),
            g.direction(),
            target,
            a.as_slice()
        );
    }
    println!(
        "{solved} of {tried} solved ({:.2} %), {wrong} wrong; µs {}",
        100.0 * solved as f64 / tried.max(1) as f64,
        quantiles(&mut times)
    );
}

fn long_coverage(n: usize, seed: u64, least_energy: bool) {
    use rod_ig_core::solver::Objective;
    let cases = rod_ig_bench::families::long_cables(n, seed);
    let options = ig::SolveOptions {
        deadline: Duration::from_secs(2),
        objective: if least_energy {
            Objective::LeastEnergy
        } else {
            Objective::FirstFound
        },
        ..ig::SolveOptions::default()
    };
    solve_and_report(&cases, &options);
}

/// Solves every (gravity, a, target) case from no guess with `options`, re-checks each answer
/// (on target to 1e-6, stable), prints `miss w gx,gy x,y,theta a3,a4,a5 why` per failure, then
/// the count and the time quantiles (ms).
fn solve_and_report(
    cases: &[(
        rod_ig_core::planar::heavy::Gravity,
        PlanarParams,
        PlanarPose,
    )],
    options: &ig::SolveOptions,
) {
    use rod_ig_core::planar::heavy::{self, HeavyPlanar};
    use rod_ig_core::solver;
    let (mut solved, mut wrong, mut times) = (0usize, 0usize, Vec::new());
    for (g, a, target) in cases {
        let t0 = Instant::now();
        let result = solver::solve(&HeavyPlanar::new(*g), target, options);
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        let why = match &result {
            Ok(s) => match heavy::evaluate(&s.a, g) {
                Ok(e)
                    if e.stability.stable
                        && (e.tip.x - target.x).hypot(e.tip.y - target.y) <= 1e-6
                        && wrap_angle(e.tip.theta - target.theta).abs() <= 1e-6 =>
                {
                    solved += 1;
                    continue;
                }
                other => {
                    wrong += 1;
                    format!("WRONG: re-check gives {other:?}")
                }
            },
            Err(f) => f.reason.to_string(),
        };
        println!(
            "miss {:.6e} {:.6},{:.6} {:.9},{:.9},{:.9} {:.9e},{:.9e},{:.9e} {why}",
            g.weight(),
            g.direction()[0],
            g.direction()[1],
            target.x,
            target.y,
            target.theta,
            a[0],
            a[1],
            a[2]
        );
    }
    println!(
        "{solved} of {} solved ({:.2} %), {wrong} wrong; ms {}",
        cases.len(),
        100.0 * solved as f64 / cases.len().max(1) as f64,
        quantiles(&mut times)
    );
}

/// Draws stable loop-free equilibria with a pinned tip (module docs, `pinned`).
fn pinned_cases(
    n: usize,
    seed: u64,
) -> Vec<(
    rod_ig_core::ends::HeldEnds,
    rod_ig_core::planar::heavy::held::HeldSolution,
)> {
    use rod_ig_core::ends::{EndCondition::*, HeldEnds};
    use rod_ig_core::planar::heavy::{cable::Cable, held, Gravity};
    let mut r = SplitMix64::new(seed);
    let mut out = Vec::new();
    let dummy = PlanarPose::new(0.0, 0.0, 0.0);
    while out.len() < n {
        let w = 10f64.powf(r.range(-1.0, 300f64.log10()));
        let psi = if r.uniform() < 0.5 {
            -PI / 2.0
        } else {
            r.range(-PI, PI)
        };
        let g = Gravity::new(w, [psi.cos(), psi.sin()]).expect("gravity");
        let pinned_base = r.uniform() < 0.5;
        let (mag, dir) = (
            10f64.powf(r.range(-1.0, (50.0 + w).log10())),
            r.range(-PI, PI),
        );
        let force = [mag * dir.cos(), mag * dir.sin()];
        let ends = HeldEnds::new(if pinned_base { Pinned } else { Clamped }, Pinned).expect("ends");
        // (base angle, a) of the drawn equilibria.
        let mut drawn: Vec<(f64, PlanarParams)> = Vec::new();
        if pinned_base {
            let k1 = |t0: f64| {
                Cable::held(t0, &PlanarParams::new(0.0, force[0], force[1]), &g, ends)
                    .and_then(|c| c.tip_curvature())
                    .ok()
            };
            let m = 720;
            let mut prev: Option<(f64, f64)> = None;
            for i in 0..=m {
                let t0 = -PI + 2.0 * PI * i as f64 / m as f64;
                let Some(k) = k1(t0) else { continue };
                if let Some((tp, kp)) = prev {
                    if kp.signum() != k.signum() {
                        let (mut lo, mut hi) = (tp, t0);
                        for _ in 0..60 {
                            let mid = 0.5 * (lo + hi);
                            match k1(mid) {
                                Some(km) if km.signum() == kp.signum() => lo = mid,
                                Some(_) => hi = mid,
                                None => break,
                            }
                        }
                        drawn.push((0.5 * (lo + hi), PlanarParams::new(0.0, force[0], force[1])));
                    }
                }
                prev = Some((t0, k));
            }
        } else {
            let l = g.load();
            let tip_load = [force[0] - l[0], force[1] - l[1]];
            for a3 in held::free_tip_roots(&g, tip_load) {
                drawn.push((0.0, PlanarParams::new(a3, force[0], force[1])));
            }
        }
        for (t0, a) in drawn {
            let Ok(mut c) = Cable::held(t0, &a, &g, ends) else {
                continue;
            };
            let Ok(tip) = c.tip() else { continue };
            // Polish κ(1) = 0 at this tip position (the cable's own Newton).
            let target = PlanarPose::new(tip.x, tip.y, 0.0);
            if c.solve(&target).is_err() {
                continue;
            }
            let Ok(s) = held::HeldSolution::of(c) else {
                continue;
            };
            if s.stability.stable()
                && s.turns == 0
                && !s.self_intersects
                && s.tip.x.hypot(s.tip.y) <= 0.98
                && out.len() < n
            {
                out.push((ends, s));
            }
        }
        let _ = dummy;
        eprint!("\rdrawn {}", out.len());
    }
    eprintln!();
    out
}

fn pinned_coverage(n: usize, seed: u64) {
    use rod_ig_core::planar::heavy::held;
    let cases = pinned_cases(n, seed);
    let options = ig::SolveOptions {
        deadline: Duration::from_secs(2),
        ..ig::SolveOptions::default()
    };
    let (mut solved, mut worse, mut times) = (0usize, 0usize, Vec::new());
    for (ends, drawn) in &cases {
        let g = *drawn.cable.gravity();
        let target = PlanarPose::new(drawn.tip.x, drawn.tip.y, 0.0);
        let t0 = Instant::now();
        let result = held::least_energy(*ends, &g, Some(&target), &options);
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        match result {
            Ok((s, _)) if (s.tip.x - target.x).hypot(s.tip.y - target.y) <= 1e-9 => {
                solved += 1;
                if s.energy > drawn.energy + 1e-9 * (1.0 + drawn.energy.abs()) {
                    worse += 1;
                    println!(
                        "worse {:?} w {:.4e} g {:?} target {:.9},{:.9} drawn E {:.9} a {:?} θ0 {:.9}; answer E {:.9}",
                        ends, g.weight(), g.direction(), target.x, target.y, drawn.energy,
                        drawn.a.as_slice(), drawn.base_angle, s.energy
                    );
                }
            }
            other => println!(
                "miss {:?} w {:.4e} g {:?} target {:.9},{:.9} a {:?} θ0 {:.9}: {}",
                ends,
                g.weight(),
                g.direction(),
                target.x,
                target.y,
                drawn.a.as_slice(),
                drawn.base_angle,
                other
                    .err()
                    .map_or("off target".to_string(), |e| e.to_string())
            ),
        }
    }
    println!(
        "{solved} of {} solved ({:.2} %), {worse} of more energy than the drawn rod; ms {}",
        cases.len(),
        100.0 * solved as f64 / cases.len().max(1) as f64,
        quantiles(&mut times)
    );
}

/// "median m, p90 a, p99 b, max c" of `times` (sorted here), to three significant digits.
fn quantiles(times: &mut [f64]) -> String {
    if times.is_empty() {
        return "(none)".into();
    }
    times.sort_by(f64::total_cmp);
    let q = |p: f64| times[((times.len() - 1) as f64 * p) as usize];
    format!(
        "median {:.3}, p90 {:.3}, p99 {:.3}, max {:.3}",
        q(0.5),
        q(0.9),
        q(0.99),
        q(1.0)
    )
}
