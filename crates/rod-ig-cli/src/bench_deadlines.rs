//! `rod-ig bench --only deadlines`: how late the requests that once overran their deadline
//! answer now (issue 42, item 3), and what one work unit of [`rod_ig_core::deadline`] costs at
//! each site that charges it. The tests check the deadlines by counting work; this is where
//! the wall clock is read.

use nalgebra::Vector3;
use rod_ig_core::deadline;
use rod_ig_core::plan::{Obstacle, PlanRequest, Planner, MAX_OBSTACLES};
use rod_ig_core::planar::heavy::{Gravity, HeavyPlanar};
use rod_ig_core::planar::ig::{self, SolveOptions};
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::solver::{self, Objective};
use rod_ig_core::spatial::{self, Spatial, SpatialParams, SpatialPose, StabilityOptions};
use rod_ig_core::{PlanarParams, PlanarPose};
use std::time::{Duration, Instant};

/// A request under test: runs once with the deadline given.
type Request = Box<dyn FnMut(Duration)>;

fn stiff_3d() -> Spatial {
    Spatial {
        stiffness: spatial::Stiffness {
            c1: 1e-6,
            c2: 1.0,
            c3: 1e6,
        },
        ..Spatial::default()
    }
}

fn requests() -> Vec<(&'static str, Request)> {
    let target3 =
        SpatialPose::from_xyzw(Vector3::new(0.6, 0.2, 0.3), [0.1, 0.2, 0.3, 0.9]).expect("pose");
    let planar_target = PlanarPose::new(-0.3, 0.4, 2.5);
    let discs: Vec<Obstacle> = (0..MAX_OBSTACLES)
        .map(|i| Obstacle::Disc {
            center: [10.0 + i as f64 * 1e-3, 10.0],
            radius: 1e-4,
        })
        .collect();
    let mut planner = Planner::new();
    vec![
        (
            "solve3d, c = (1e-6, 1, 1e6)",
            Box::new(move |d| {
                let o = solver::SolveOptions::with_deadline(d);
                let _ = solver::solve(&stiff_3d(), &target3, &o);
            }),
        ),
        (
            "forward3d, c = (1e-6, 1, 1e6)",
            Box::new(|d| {
                let _deadline = deadline::scope(d);
                let a = SpatialParams::from([3.0, -2.0, 5.0, 1.0, 4.0, -3.0]);
                let opts = StabilityOptions::production();
                let _ = spatial::evaluate(&a, &stiff_3d().stiffness, &opts);
            }),
        ),
        (
            "Newton from (3e3, 1, 1)",
            Box::new(|d| {
                let o = SolveOptions {
                    method: ig::Method::Newton,
                    initial_guess: Some(PlanarParams::new(3e3, 1.0, 1.0)),
                    deadline: d,
                    ..SolveOptions::default()
                };
                let _ = ig::solve(&PlanarPose::new(0.5, 0.3, 0.7), &o);
            }),
        ),
        (
            "least energy + all (planar)",
            Box::new(move |d| {
                let o = SolveOptions {
                    objective: Objective::LeastEnergy,
                    deadline: d,
                    ..SolveOptions::default()
                };
                let _deadline = deadline::scope(d);
                let _ = solver::solve(&PlanarClosedForm, &planar_target, &o);
                let _ = solver::solve_every(&PlanarClosedForm, &planar_target, &o);
            }),
        ),
        (
            "solve, w = 5000",
            Box::new(|d| {
                let g = Gravity::new(5_000.0, [0.0, -1.0]).expect("gravity");
                let o = solver::SolveOptions::with_deadline(d);
                let _ = solver::solve(&HeavyPlanar::new(g), &PlanarPose::new(0.3, -0.5, -1.2), &o);
            }),
        ),
        (
            "plan, 10,000 discs",
            Box::new(move |d| {
                let _ = planner.plan(&PlanRequest {
                    start: PlanarParams::new(0.5, 0.1, 0.1),
                    goal: PlanarPose::new(0.8, 0.3, 0.5),
                    obstacles: discs.clone(),
                    deadline: d,
                    gravity: rod_ig_core::planar::heavy::Gravity::NONE,
                });
            }),
        ),
    ]
}

/// Prints, per request and deadline, the median and worst time past the deadline over
/// `rounds` runs, and the µs per work unit the request charged.
pub fn run(quick: bool) {
    ig::warm_up();
    let rounds = if quick { 5 } else { 21 };
    println!("\n## Deadlines held inside evaluations (issue 42)");
    println!(
        "{:<32} {:>9} {:>12} {:>12} {:>10}",
        "request", "deadline", "late p50 ms", "late max ms", "µs/unit"
    );
    for (name, mut request) in requests() {
        for ms in [1u64, 10] {
            let deadline = Duration::from_millis(ms);
            let mut late = Vec::with_capacity(rounds);
            let (mut units, mut secs) = (0u64, 0.0f64);
            for _ in 0..rounds {
                let before = deadline::charged();
                let t0 = Instant::now();
                request(deadline);
                let took = t0.elapsed();
                units += deadline::charged() - before;
                secs += took.as_secs_f64();
                late.push((took.as_secs_f64() - deadline.as_secs_f64()).max(0.0) * 1e3);
            }
            let worst = late.iter().copied().fold(0.0, f64::max);
            let p50 = crate::timing::median(&mut late);
            let per_unit = if units > 0 {
                format!("{:.2}", secs * 1e6 / units as f64)
            } else {
                "-".into()
            };
            println!("{name:<32} {ms:>7} ms {p50:>12.3} {worst:>12.3} {per_unit:>10}");
        }
    }
    println!(
        "Goal: every request answered within its deadline + 10 ms; a unit is meant to cost \
         ≈ 1 µs (the clock is read every {} units).",
        deadline::POLL_UNITS
    );
}
