//! The one solver API (issue 11): every strategy on every model, one Solution and error type,
//! typed terminations, observers.

mod workloads;
use nalgebra::{Vector3, Vector6};
use rod_ig_core::planar::{PlanarClosedForm, PlanarReference};
use rod_ig_core::solver::{
    self, observe, relative_distance, Counters, Event, IgError, InverseGeometry, IterationLog,
    Method, Objective, RodModel, SolveOptions, Termination, DISTINCT,
};
use rod_ig_core::spatial::Spatial;
use rod_ig_core::spatial::{SpatialPose, Stiffness};
use rod_ig_core::{planar, PlanarParams, PlanarPose};
use std::time::Duration;
use workloads::spatial::random_targets;

/// Stable planar rods spread over moments and forces, and their tips.
fn planar_cases() -> Vec<(PlanarParams, PlanarPose)> {
    [
        [1.0, 2.0, -1.0],
        [-2.5, 10.0, 4.0],
        [0.3, -3.0, 0.5],
        [4.0, 20.0, -12.0],
        [0.05, 1e-3, 1e-4],
    ]
    .into_iter()
    .map(PlanarParams::from)
    .filter_map(|a| {
        let e = planar::evaluate(&a).ok()?;
        e.stability.stable.then_some((a, e.tip))
    })
    .collect()
}

fn spatial_cases(n: usize) -> Vec<(Vector6<f64>, SpatialPose)> {
    random_targets(n, 77, &Stiffness::default())
}

/// Checks the contract of a returned solution on `model`, independently of the solver:
/// re-evaluated tip within the tolerance, stable, reported errors consistent.
fn assert_verified<const N: usize, M: RodModel<N>>(
    model: &M,
    target: &M::Pose,
    s: &solver::Solution<nalgebra::SVector<f64, N>, M::Pose>,
    tolerance: f64,
) {
    let e = model.evaluate(&s.a).expect("the solution evaluates");
    let (pe, oe) = model.pose_error(&e.tip, target);
    assert!(pe <= tolerance && oe <= tolerance, "{pe:e} {oe:e}");
    assert!(s.stable && e.stability.stable && s.stability_margin > 0.0);
    assert!((s.residual - s.position_error.hypot(s.orientation_error)).abs() <= 1e-15);
    assert!((s.energy - e.energy).abs() <= 1e-8 * (1.0 + e.energy.abs()));
}

#[test]
fn the_paper_newton_is_one_implementation_for_every_model() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    // From a guess near the answer, the paper's Newton (α = 1) converges on each model to the
    // rod the target came from. Tolerance 1e-10: a is compared to 1e-5, and J⁻¹ amplifies tip
    // errors up to ~1e4 on these rods (the compressed one).
    for (a, target) in planar_cases() {
        let options = SolveOptions {
            method: Method::Newton,
            initial_guess: Some(a + Vector3::repeat(1e-3)),
            tolerance: 1e-10,
            ..SolveOptions::default()
        };
        for s in [
            solver::solve(&PlanarClosedForm, &target, &options),
            solver::solve(&PlanarReference::default(), &target, &options),
        ] {
            let s = s.expect("Newton from a close guess converges");
            assert_verified(&PlanarClosedForm, &target, &s, 1e-9);
            assert!(
                (s.a - a).norm() <= 1e-5 * (1.0 + a.norm()),
                "{:?} {a:?}",
                s.a
            );
            assert_eq!(s.starts, 1);
        }
    }
    for (a, target) in spatial_cases(6) {
        let options = SolveOptions {
            method: Method::Newton,
            initial_guess: Some(a + Vector6::repeat(1e-3)),
            ..SolveOptions::default()
        };
        let s = solver::solve(&Spatial::default(), &target, &options).expect("converges");
        assert_verified(&Spatial::default(), &target, &s, 1e-6);
    }
}

#[test]
fn the_reference_model_agrees_with_the_closed_forms() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    // The robust strategy on the reference integrator returns the closed-form answer polished
    // by the integrator: both solve their own model to 1e-6, and agree to the conditioning of
    // J times the models' difference (≲ 1e-9 here).
    let options = SolveOptions::default();
    for (_, target) in planar_cases() {
        let c = solver::solve(&PlanarClosedForm, &target, &options).expect("closed form");
        let r = solver::solve(&PlanarReference::default(), &target, &options).expect("reference");
        assert_verified(&PlanarReference::default(), &target, &r, 1e-6);
        assert!(
            (c.a - r.a).norm() <= 1e-5 * (1.0 + c.a.norm()),
            "{:?} {:?}",
            c.a,
            r.a
        );
    }
}

fn check_all_and_least_energy<const N: usize, M: InverseGeometry<N>>(
    model: &M,
    target: &M::Pose,
    options: &SolveOptions<nalgebra::SVector<f64, N>>,
) {
    let first = solver::solve(model, target, options).expect("reachable");
    let all = solver::solve_all(model, target, options);
    assert!(!all.is_empty(), "all is never empty where solve succeeds");
    for w in all.windows(2) {
        assert!(w[0].energy <= w[1].energy, "sorted by energy");
    }
    let scale = model.param_scale();
    for (i, s) in all.iter().enumerate() {
        assert_verified(model, target, s, options.tolerance);
        for o in &all[..i] {
            assert!(relative_distance(&o.a, &s.a, &scale) > DISTINCT, "distinct");
        }
    }
    let least = solver::solve(
        model,
        target,
        &SolveOptions {
            objective: Objective::LeastEnergy,
            ..*options
        },
    )
    .expect("least energy succeeds where first-found does");
    assert_verified(model, target, &least, options.tolerance);
    assert!(least.energy <= first.energy + 1e-9);
    assert!(least.energy <= all[0].energy + 1e-9);
}

#[test]
fn least_energy_and_all_serve_planar_and_spatial_alike() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    for (_, target) in planar_cases() {
        check_all_and_least_energy(&PlanarClosedForm, &target, &SolveOptions::default());
    }
    for (_, target) in spatial_cases(4) {
        check_all_and_least_energy(&Spatial::default(), &target, &SolveOptions::default());
    }
}

#[test]
fn errors_carry_typed_terminations_on_every_model() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    let planar_far = PlanarPose::new(1.5, 0.0, 0.0);
    let f = solver::solve(&PlanarClosedForm, &planar_far, &SolveOptions::default()).unwrap_err();
    assert_eq!(f.termination(), Termination::Unreachable);
    let spatial_far = SpatialPose {
        position: Vector3::new(0.0, 2.0, 0.0),
        ..SpatialPose::identity()
    };
    let f = solver::solve(&Spatial::default(), &spatial_far, &SolveOptions::default()).unwrap_err();
    assert_eq!(f.termination(), Termination::Unreachable);
    let nan = PlanarPose::new(f64::NAN, 0.0, 0.0);
    let f = solver::solve(&PlanarClosedForm, &nan, &SolveOptions::default()).unwrap_err();
    assert!(matches!(
        f.reason,
        IgError::NonFiniteTarget { component: "x", .. }
    ));
    assert_eq!(f.termination(), Termination::InvalidInput);
    let bad_model = Spatial {
        rtol: 0.5,
        ..Spatial::default()
    };
    let (_, target) = spatial_cases(1)[0];
    let f = solver::solve(&bad_model, &target, &SolveOptions::default()).unwrap_err();
    assert_eq!(f.termination(), Termination::InvalidInput);
    // Newton from a far guess with a tiny budget stops at the iteration limit or on leaving
    // the stable set, typed either way; never silently.
    let options = SolveOptions {
        method: Method::Newton,
        max_iterations: 1,
        initial_guess: Some(PlanarParams::new(3.0, 30.0, -20.0)),
        ..SolveOptions::default()
    };
    let (_, t) = planar_cases()[0];
    if let Err(f) = solver::solve(&PlanarClosedForm, &t, &options) {
        assert!(matches!(
            f.termination(),
            Termination::IterationLimit | Termination::LeftStableSet | Termination::Singular
        ));
    }
    // A deadline too short for the 3-D search ends as a deadline.
    let options = SolveOptions {
        deadline: Duration::from_nanos(1),
        ..SolveOptions::default()
    };
    let f = solver::solve(&Spatial::default(), &target, &options).unwrap_err();
    assert_eq!(f.termination(), Termination::Deadline);
}

#[test]
fn a_failed_multistart_says_why_its_last_start_failed() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    // On the reach boundary (|p| → 1 with a bent tip), no stable rod exists: the robust
    // search ends with what it searched (SearchExhausted, termination NoStableSolution) and
    // the last start's own reason.
    let target = PlanarPose::new(0.9999, 0.0, 2.5);
    let f = solver::solve(&PlanarClosedForm, &target, &SolveOptions::default()).unwrap_err();
    assert_eq!(f.termination(), Termination::NoStableSolution);
    match &f.reason {
        IgError::SearchExhausted(searched) => {
            let (starts, branches, last) = (&searched.starts, &searched.branches, &searched.last);
            assert!(*starts > 0);
            assert_eq!(
                f.starts,
                starts + branches,
                "the failure counts every start"
            );
            let text = f.reason.to_string();
            assert!(
                text.contains("|a3| <=") && text.contains("branches followed"),
                "{text}"
            );
            let last = last.as_ref().expect("the last start's reason is kept");
            assert!(matches!(
                last.termination(),
                Termination::Stalled
                    | Termination::IterationLimit
                    | Termination::LeftStableSet
                    | Termination::Deadline
            ));
            assert!(f.reason.to_string().contains("last start"));
        }
        other => panic!("expected SearchExhausted, got {other}"),
    }
}

#[test]
fn observers_see_every_start_and_iteration() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    let (_, target) = planar_cases()[1];
    let (r, log) = observe(IterationLog::default(), || {
        solver::solve(&PlanarClosedForm, &target, &SolveOptions::default())
    });
    let s = r.expect("solves");
    assert_eq!(log.iterations(), s.iterations as usize);
    assert_eq!(log.starts(), s.starts as usize);
    match log.events.last() {
        Some(Event::Finished {
            termination,
            iterations,
            ..
        }) => {
            assert_eq!(*termination, Termination::Converged);
            assert_eq!(*iterations, s.iterations);
        }
        other => panic!("last event {other:?}"),
    }
    // The residuals of one start's iterations decrease (the robust search's line search).
    let residuals: Vec<f64> = log
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Iteration { residual, .. } => Some(*residual),
            _ => None,
        })
        .collect();
    assert!(!residuals.is_empty());
    // 3-D: the same observer type.
    let (_, t3) = spatial_cases(1)[0];
    let (r, log) = observe(IterationLog::default(), || {
        solver::solve(&Spatial::default(), &t3, &SolveOptions::default())
    });
    let s = r.expect("solves");
    assert_eq!(log.iterations(), s.iterations as usize);
    assert!(log.starts() >= 1);
    // Counters over several solves, and nesting restores the outer observer.
    let ((), counters) = observe(Counters::default(), || {
        for (_, t) in planar_cases() {
            let _ = solver::solve(&PlanarClosedForm, &t, &SolveOptions::default());
        }
        let ((), inner) = observe(Counters::default(), || {
            let _ = solver::solve(&PlanarClosedForm, &target, &SolveOptions::default());
        });
        assert_eq!(inner.solves, 1);
    });
    assert_eq!(counters.solves, planar_cases().len() as u64);
    assert!(counters.iterations > 0 && counters.starts >= counters.solves);
    // Without an observer nothing is recorded and nothing breaks.
    assert!(solver::solve(&PlanarClosedForm, &target, &SolveOptions::default()).is_ok());
}
