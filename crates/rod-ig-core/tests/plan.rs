//! Planning stable gripper paths (issue 12): every plan re-verified independently — tips by the
//! closed form and the reference integrator, stability of every rod and every midpoint by the
//! reference integrator, spacing, obstacles on a denser body sampling.

mod workloads;
use rod_ig_core::plan::{Obstacle, PlanError, PlanRequest, Planner, MIN_MARGIN};
use rod_ig_core::planar::PlanarReference;
use rod_ig_core::planar::{self, PlanarRod};
use rod_ig_core::solver::RodModel;
use rod_ig_core::{wrap_angle, PlanarParams, PlanarPose};
use std::time::Duration;
use workloads::SplitMix64;

fn random_stable(rng: &mut SplitMix64, min_margin: f64) -> (PlanarParams, PlanarPose) {
    loop {
        let a = PlanarParams::new(
            rng.range(-6.0, 6.0),
            rng.range(-40.0, 40.0),
            rng.range(-40.0, 40.0),
        );
        if let Ok(e) = planar::evaluate(&a) {
            if e.stability.stable && e.stability.margin >= min_margin {
                return (a, e.tip);
            }
        }
    }
}

/// The independent checks of one plan (`reference`: stability by the reference integrator).
fn verify(plan: &rod_ig_core::plan::Plan, request: &PlanRequest, reference: bool) {
    assert_eq!(plan.rods[0], request.start);
    assert_eq!(plan.rods.len(), plan.gripper.len());
    let last = plan.rods.last().expect("non-empty");
    let tip = planar::tip(last).expect("evaluates");
    let g = &request.goal;
    assert!((tip.x - g.x).hypot(tip.y - g.y) <= 1e-6);
    assert!(wrap_angle(tip.theta - g.theta).abs() <= 1e-6);
    let model = PlanarReference::default();
    for w in plan.rods.windows(2) {
        let (a, b) = (w[0], w[1]);
        let limit = 0.1 * (1.0 + a.norm().min(b.norm()));
        assert!(
            (b - a).norm() <= limit + 1e-12,
            "spacing {} > {limit}",
            (b - a).norm()
        );
        for r in [b, 0.5 * (a + b)] {
            let verdict = if reference {
                model.stability(&r).expect("evaluates")
            } else {
                planar::stability(&r).expect("evaluates")
            };
            assert!(verdict.stable && verdict.margin > 0.0, "{r:?}: {verdict:?}");
        }
    }
    if reference {
        let t = model.tip(last).expect("evaluates");
        assert!((t.x - g.x).hypot(t.y - g.y) <= 1e-6);
    }
    // Obstacles, on a body sampling 4× denser than the planner's: clear of every disc.
    for a in &plan.rods {
        let body = PlanarRod::new(a).expect("evaluates").shape(200);
        for o in &request.obstacles {
            if let Obstacle::Disc { center, radius } = o {
                for p in &body {
                    let d = (p.x - center[0]).hypot(p.y - center[1]);
                    assert!(
                        d > radius - 2e-3,
                        "rod {a:?} enters the disc ({d} < {radius})"
                    );
                }
            }
        }
    }
}

#[test]
fn plans_between_random_stable_rods_are_stable_all_the_way() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    let mut rng = SplitMix64::new(2026);
    let mut planner = Planner::new();
    let mut solved = 0;
    let n = 30;
    for i in 0..n {
        let (start, _) = random_stable(&mut rng, 0.01);
        let (_, goal) = random_stable(&mut rng, 0.01);
        let request = PlanRequest {
            start,
            goal,
            obstacles: Vec::new(),
            // The longest a request may ask: a loaded machine must not change the count
            // (the planner's speed is measured by `rod-ig bench`).
            deadline: rod_ig_core::planar::ig::MAX_DEADLINE,
            gravity: rod_ig_core::planar::heavy::Gravity::NONE,
        };
        match planner.plan(&request) {
            Ok(plan) => {
                assert!(plan.min_margin >= MIN_MARGIN);
                verify(&plan, &request, true);
                solved += 1;
            }
            Err(e) => println!("query {i}: {e}"),
        }
    }
    println!("plans: {solved}/{n} solved");
    assert!(solved * 100 >= n * 95, "{solved}/{n}");
}

#[test]
fn plans_avoid_obstacles_and_failures_say_why() {
    // The atlas, once per process, outside the deadlines under test.
    rod_ig_core::planar::ig::warm_up();
    let mut planner = Planner::new();
    let start = PlanarParams::new(1.0, 2.0, -1.0);
    let goal = PlanarPose::new(0.3, 0.6, 2.5);
    let disc = Obstacle::Disc {
        center: [0.5, 0.35],
        radius: 0.1,
    };
    let request = PlanRequest {
        start,
        goal,
        obstacles: vec![disc.clone()],
        deadline: Duration::from_secs(2),
        gravity: rod_ig_core::planar::heavy::Gravity::NONE,
    };
    let plan = planner.plan(&request).expect("a way around the disc");
    verify(&plan, &request, true);
    // Unreachable goal, unstable start, start in an obstacle, bad obstacle: typed reasons.
    let far = PlanRequest {
        goal: PlanarPose::new(1.5, 0.0, 0.0),
        obstacles: Vec::new(),
        ..request.clone()
    };
    assert!(matches!(
        planner.plan(&far),
        Err(PlanError::GoalUnreachable(_))
    ));
    let straight = PlanRequest {
        start: PlanarParams::zeros(),
        ..request.clone()
    };
    assert!(matches!(
        planner.plan(&straight),
        Err(PlanError::StartUnstable { .. })
    ));
    let around_base = PlanRequest {
        obstacles: vec![Obstacle::Disc {
            center: [0.0, 0.0],
            radius: 0.05,
        }],
        ..request.clone()
    };
    assert!(matches!(
        planner.plan(&around_base),
        Err(PlanError::StartCollides)
    ));
    let bad = PlanRequest {
        obstacles: vec![Obstacle::Polygon {
            points: vec![[0.0, 0.0], [1.0, f64::NAN]],
        }],
        ..request
    };
    assert!(matches!(planner.plan(&bad), Err(PlanError::Invalid(_))));
}

/// A stable heavy rod of gentle moment and force with margin ≥ 1e-2 (comfortably above the
/// planner's [`MIN_MARGIN`]), and its tip.
fn random_stable_heavy(
    rng: &mut SplitMix64,
    g: &rod_ig_core::planar::heavy::Gravity,
) -> (PlanarParams, PlanarPose) {
    use rod_ig_core::planar::heavy;
    loop {
        let a = PlanarParams::new(
            rng.range(-3.0, 3.0),
            rng.range(-15.0, 15.0),
            rng.range(-15.0, 15.0),
        );
        if let Ok(e) = heavy::evaluate(&a, g) {
            if e.stability.stable && e.stability.margin >= 1e-2 {
                return (a, e.tip);
            }
        }
    }
}

/// A cable with weight (issue 41): the plan's rods are the heavy rod's. Every rod and midpoint
/// is a stable heavy rod with margin; the last rod's heavy tip is the goal by the independent
/// DOP853 integration of the rod with weight, while its weightless tip is elsewhere; the
/// sagging bodies stay clear of a disc just under the held cable.
#[test]
fn plans_for_a_cable_with_weight_use_the_heavy_rod() {
    use rod_ig_core::ode::heavy_reference;
    use rod_ig_core::planar::heavy::{self, Gravity};
    rod_ig_core::planar::ig::warm_up();
    let g = Gravity::new(15.0, [0.0, -1.0]).expect("gravity");
    let mut rng = SplitMix64::new(41);
    let (start, _) = random_stable_heavy(&mut rng, &g);
    let (_, goal) = random_stable_heavy(&mut rng, &g);
    // Just under the held cable's lowest point.
    let body = heavy::shape(&start, &g, 49).expect("evaluates");
    let low = body
        .iter()
        .min_by(|p, q| p.y.total_cmp(&q.y))
        .expect("samples");
    let centre = [low.x, low.y - 0.15];
    let request = PlanRequest {
        start,
        goal,
        obstacles: vec![Obstacle::Disc {
            center: centre,
            radius: 0.1,
        }],
        deadline: rod_ig_core::planar::ig::MAX_DEADLINE,
        gravity: g,
    };
    let mut planner = Planner::new();
    let plan = planner.plan(&request).expect("a plan for the cable");
    assert_eq!(plan.rods[0], start);
    assert!(plan.min_margin >= MIN_MARGIN);
    for w in plan.rods.windows(2) {
        let (a, b) = (w[0], w[1]);
        assert!((b - a).norm() <= 0.1 * (1.0 + a.norm().min(b.norm())) + 1e-12);
        for r in [b, 0.5 * (a + b)] {
            let report = heavy::stability(&r, &g).expect("evaluates");
            assert!(report.stable && report.margin > 0.0, "{r:?}: {report:?}");
        }
    }
    for (a, q) in plan.rods.iter().zip(&plan.gripper) {
        assert_eq!(*q, heavy::tip(a, &g).expect("evaluates"));
        for p in heavy::shape(a, &g, 200).expect("evaluates") {
            let d = (p.x - centre[0]).hypot(p.y - centre[1]);
            assert!(d > 0.1 - 2e-3, "rod {a:?} enters the disc ({d})");
        }
    }
    let last = plan.rods.last().expect("non-empty");
    let reference = heavy_reference::evaluate(last, &g).expect("evaluates");
    let off = |t: &PlanarPose| {
        (t.x - goal.x).hypot(t.y - goal.y) + wrap_angle(t.theta - goal.theta).abs()
    };
    assert!(off(&reference.tip) <= 1e-6, "{:?}", reference.tip);
    assert!(reference.stability.stable);
    let weightless_tip = planar::tip(last).expect("evaluates");
    assert!(off(&weightless_tip) > 1e-2, "the weight changed nothing");
    // The same planner, weightless again: its own rods (the heavy verdicts were dropped).
    let weightless = PlanRequest {
        start: random_stable(&mut SplitMix64::new(7), 1e-2).0,
        gravity: Gravity::NONE,
        obstacles: Vec::new(),
        ..request
    };
    let plan = planner.plan(&weightless).expect("a weightless plan");
    verify(&plan, &weightless, false);
}
