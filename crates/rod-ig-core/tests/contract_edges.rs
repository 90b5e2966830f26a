//! The solver's contract at its edges (issue 24): options enforced as documented, huge angles
//! solved as their exact reduction, obstacle coordinates bounded.

use rod_ig_core::plan::{Obstacle, PlanError, PlanRequest, Planner, MAX_OBSTACLE_COORDINATE};
use rod_ig_core::planar::ig::{self, SolveOptions, Termination};
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::solver::{
    self, observe, BranchFollower, Event, IterationLog, MAX_ITERATIONS_LIMIT, MAX_TOLERANCE,
    MIN_TOLERANCE,
};
use rod_ig_core::spatial::Spatial;
use rod_ig_core::spatial::SpatialPose;
use rod_ig_core::{wrap_angle, PlanarParams, PlanarPose};
use std::time::Duration;

/// Targets of every kind: gently bent, looped, near full extension, behind the base.
const TARGETS: [(f64, f64, f64); 6] = [
    (0.6, 0.3, 0.5),
    (0.3134187265422321, -0.587006393473652, -2.1624511539781346),
    (0.9, 0.1, 3.0),
    (0.98, 0.01, 0.02),
    (-0.2, 0.4, 2.5),
    (0.1, 0.0, 3.1),
];

/// Iterations each start made, from the observer's events.
fn per_start_iterations(events: &[Event]) -> Vec<u32> {
    let mut out: Vec<u32> = Vec::new();
    for e in events {
        match e {
            Event::StartBegun { .. } => out.push(0),
            Event::Iteration { .. } => {
                if let Some(last) = out.last_mut() {
                    *last += 1;
                } else {
                    out.push(1);
                }
            }
            _ => {}
        }
    }
    out
}

#[test]
fn max_iterations_bounds_every_start_of_the_search() {
    ig::warm_up();
    for max in [1u32, 2, 5] {
        for (x, y, t) in TARGETS {
            let options = SolveOptions {
                max_iterations: max,
                ..SolveOptions::default()
            };
            let target = PlanarPose::new(x, y, t);
            let (result, log) = observe(IterationLog::default(), || ig::solve(&target, &options));
            let starts = per_start_iterations(&log.events);
            assert!(
                starts.iter().all(|&n| n <= max),
                "max_iterations {max}, target {target:?}: starts ran {starts:?}"
            );
            let total = match &result {
                Ok(s) => s.iterations,
                Err(f) => f.iterations,
            };
            // Newton starts report their iterations; a branch followed by the last stage is
            // bounded by its steps instead (ig::BRANCH_STEPS, each at most
            // CORRECTOR_ITERATIONS + 1 corrections).
            let newton: u32 = starts.iter().sum();
            let per_branch = ig::BRANCH_STEPS * (solver::CORRECTOR_ITERATIONS + 1);
            assert!(
                total <= newton + per_branch * starts.len() as u32,
                "max_iterations {max}: {total} iterations over {} starts",
                starts.len()
            );
        }
    }
}

#[test]
fn the_paper_newton_stops_at_max_iterations() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    let target = PlanarPose::new(0.6, 0.3, 0.5);
    for max in [1u32, 3] {
        let options = SolveOptions {
            method: ig::Method::Newton,
            initial_guess: Some(PlanarParams::new(1.0, -5.0, 3.0)),
            alpha: 0.1,
            max_iterations: max,
            ..SolveOptions::default()
        };
        let r = ig::solve(&target, &options);
        let n = match &r {
            Ok(s) => s.iterations,
            Err(f) => f.iterations,
        };
        assert!(n <= max, "Newton ran {n} > {max} iterations");
    }
}

#[test]
fn out_of_range_options_are_refused() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    let target = PlanarPose::new(0.6, 0.3, 0.5);
    let bad: [(&str, SolveOptions); 6] = [
        (
            "max_iterations 0",
            SolveOptions {
                max_iterations: 0,
                ..Default::default()
            },
        ),
        (
            "max_iterations beyond the limit",
            SolveOptions {
                max_iterations: MAX_ITERATIONS_LIMIT + 1,
                ..Default::default()
            },
        ),
        (
            "tolerance 1e308",
            SolveOptions {
                tolerance: 1e308,
                ..Default::default()
            },
        ),
        (
            "tolerance above the bound",
            SolveOptions {
                tolerance: MAX_TOLERANCE * 1.5,
                ..Default::default()
            },
        ),
        (
            "tolerance below the rounding bound",
            SolveOptions {
                tolerance: MIN_TOLERANCE / 2.0,
                ..Default::default()
            },
        ),
        (
            "alpha 0",
            SolveOptions {
                alpha: 0.0,
                ..Default::default()
            },
        ),
    ];
    for (what, options) in bad {
        let f = ig::solve(&target, &options).expect_err(what);
        assert_eq!(
            f.termination(),
            Termination::InvalidInput,
            "{what}: {}",
            f.reason
        );
        assert_eq!(f.iterations, 0, "{what}: refused before any work");
    }
    // The bounds themselves are accepted.
    for tolerance in [MIN_TOLERANCE, MAX_TOLERANCE] {
        let options = SolveOptions {
            tolerance,
            ..Default::default()
        };
        let s = ig::solve(&target, &options).expect("tolerance at its bound");
        assert!(s.position_error <= tolerance && s.orientation_error <= tolerance);
    }
    // 3-D: the same limits.
    let target3 = SpatialPose::from_xyzw([0.6, 0.2, 0.3].into(), [0.1, 0.2, 0.3, 0.9]).unwrap();
    let f = solver::solve(
        &Spatial::default(),
        &target3,
        &solver::SolveOptions {
            tolerance: 1e308,
            ..Default::default()
        },
    )
    .expect_err("3-D tolerance 1e308");
    assert_eq!(f.termination(), Termination::InvalidInput);
    let f = solver::solve(
        &Spatial::default(),
        &target3,
        &solver::SolveOptions {
            max_iterations: 0,
            ..Default::default()
        },
    )
    .expect_err("3-D max_iterations 0");
    assert_eq!(f.termination(), Termination::InvalidInput);
}

/// Huge angles whose exact reduction is known (80-digit arithmetic, as in
/// tests/data/angle_reduction.jsonl): the solve must equal the solve of the reduced angle.
#[test]
fn huge_angles_solve_as_their_exact_reduction() {
    ig::warm_up();
    let cases = [
        (0.6, 0.3, 370000000000.123, 0.13099209125032246),
        (
            0.6,
            0.3,
            -9.87654321e13 + 0.5,
            wrap_angle(-9.87654321e13 + 0.5),
        ),
        (0.5, -0.2, 2.5e11, wrap_angle(2.5e11)),
        (0.4, 0.4, 1e300, wrap_angle(1e300)),
    ];
    for (x, y, huge, reduced) in cases {
        assert!(reduced.abs() <= std::f64::consts::PI);
        let options = SolveOptions::default();
        let a = ig::solve(&PlanarPose::new(x, y, huge), &options).expect("huge angle solves");
        let b = ig::solve(&PlanarPose::new(x, y, reduced), &options).expect("reduced solves");
        assert_eq!(
            a.a, b.a,
            "theta {huge}: the same rod as its reduction {reduced}"
        );
        assert_eq!(a.orientation_error, b.orientation_error);
        // The reported error is the true one: against the exact reduction.
        let true_error = wrap_angle(a.tip.theta - reduced).abs();
        assert!(
            (a.orientation_error - true_error).abs() <= 1e-15,
            "theta {huge}"
        );
        assert!(a.orientation_error <= options.tolerance);
        // The branch follower and the tracker reduce the same way.
        let mut follower = BranchFollower::holding(PlanarClosedForm, options, b.a).unwrap();
        let m = follower.follow(&PlanarPose::new(x, y, huge));
        let s = m
            .result
            .expect("a move to the pose already held, spelled huge");
        assert!(wrap_angle(s.tip.theta - reduced).abs() <= options.tolerance);
        let mut tracker = ig::Tracker::new(SolveOptions {
            initial_guess: Some(b.a),
            ..options
        });
        let s = tracker
            .solve(&PlanarPose::new(x, y, huge))
            .expect("tracker");
        assert!(wrap_angle(s.tip.theta - reduced).abs() <= options.tolerance);
    }
}

#[test]
fn obstacle_coordinates_are_bounded_and_huge_ones_refused() {
    ig::warm_up();
    let request = |obstacles| PlanRequest {
        start: PlanarParams::new(0.5, 0.1, 0.1),
        goal: PlanarPose::new(0.8, 0.3, 0.5),
        obstacles,
        deadline: Duration::from_secs(2),
        gravity: rod_ig_core::planar::heavy::Gravity::NONE,
    };
    let mut planner = Planner::new();
    // The triangle: 1e200 overflowed the geometry and was ignored (success: true).
    let huge = Obstacle::Polygon {
        points: vec![[1e200, 1e200], [-1e200, 1e200], [0.0, -1e200]],
    };
    match planner.plan(&request(vec![huge])) {
        Err(PlanError::Invalid(why)) => assert!(why.contains("1e6"), "{why}"),
        other => panic!("a 1e200 polygon must be refused, got {other:?}"),
    }
    let big_disc = Obstacle::Disc {
        center: [0.0, 0.0],
        radius: 1e7,
    };
    assert!(matches!(
        planner.plan(&request(vec![big_disc])),
        Err(PlanError::Invalid(_))
    ));
    // At the bound, the same triangle covers the workspace: the start rod touches it.
    let m = MAX_OBSTACLE_COORDINATE;
    let covering = Obstacle::Polygon {
        points: vec![[m, m], [-m, m], [0.0, -m]],
    };
    assert_eq!(
        planner.plan(&request(vec![covering])),
        Err(PlanError::StartCollides)
    );
}
