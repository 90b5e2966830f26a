//! `rod-ig bench`: every speed figure of the README, measured in one run on this machine.

use crate::timing::{measure, SplitMix64, Timing};
use rod_ig_core::ode::planar_reference as reference;
use rod_ig_core::{planar, PlanarParams};

/// The paper's fixed RK4 step (the baseline of its speed claim).
pub const RK4_STEP: f64 = 1e-4;

/// Random parameters in the public test box a3 ∈ [−10, 10], a4, a5 ∈ [−100, 100] (FINDINGS §7).
pub fn sample_box(n: usize, seed: u64) -> Vec<PlanarParams> {
    let mut rng = SplitMix64(seed);
    (0..n)
        .map(|_| {
            PlanarParams::new(
                rng.uniform(-10.0, 10.0),
                rng.uniform(-100.0, 100.0),
                rng.uniform(-100.0, 100.0),
            )
        })
        .collect()
}

fn row(name: &str, closed: Timing, rk4: Option<Timing>, goal: &str) {
    let (rk4_text, ratio) = match rk4 {
        Some(r) => (
            format!("{:>12.0}", r.median_ns),
            format!("{:>9.0}×", r.median_ns / closed.median_ns),
        ),
        None => (format!("{:>12}", "—"), format!("{:>10}", "—")),
    };
    println!(
        "{name:<28} {:>10.0} {:>10.0} {rk4_text} {ratio}   {goal}",
        closed.median_ns, closed.mean_ns
    );
}

/// Forward map, Jacobian, stability and shape: closed form against the paper's RK4 baseline.
pub fn planar_forward(quick: bool) {
    let (n, rounds, rk4_n, rk4_rounds) = if quick {
        (128, 5, 4, 3)
    } else {
        (512, 21, 16, 5)
    };
    let inputs = sample_box(n, 1);
    let rk4_inputs = &inputs[..rk4_n];
    println!("## Planar forward map (box a3 ∈ [−10, 10], a4, a5 ∈ [−100, 100]; {n} parameter sets, {rounds} rounds; single thread)");
    println!(
        "{:<28} {:>10} {:>10} {:>12} {:>10}   goal",
        "ns per call", "median", "mean", "RK4 median", "ratio"
    );
    let tip = measure(&inputs, rounds, |a| planar::tip(a).map(|p| p.x));
    let rk4_tip = measure(rk4_inputs, rk4_rounds, |a| {
        reference::rk4_tip(a, RK4_STEP).map(|p| p.x)
    });
    row(
        "forward q(1)",
        tip,
        Some(rk4_tip),
        "≤ 200 ns, ratio ≥ 1000×",
    );
    let tj = measure(&inputs, rounds, |a| {
        planar::tip_and_jacobian(a).map(|(_, j)| j[(0, 0)])
    });
    let rk4_tj = measure(rk4_inputs, rk4_rounds, |a| {
        reference::rk4_tip_and_jacobian(a, RK4_STEP).map(|(_, j)| j[(0, 0)])
    });
    row("forward + J(1)", tj, Some(rk4_tj), "≤ 500 ns");
    let st = measure(&inputs, rounds, |a| planar::stability(a).map(|s| s.stable));
    let rk4_st = measure(rk4_inputs, rk4_rounds, |a| {
        reference::rk4_stability(a, RK4_STEP).map(|s| s.stable)
    });
    row("stability test", st, Some(rk4_st), "≤ 10 µs");
    let shape = measure(&inputs, rounds, |a| {
        planar::PlanarRod::new(a).map(|rod| rod.shape(100).len())
    });
    // RK4 visits every t on its 1e-4 grid anyway: 100 samples cost what the tip costs.
    row(
        "shape, 100 samples",
        shape,
        Some(rk4_tip),
        "≈ 100 elliptic evaluations",
    );
    let energy = measure(&inputs, rounds, |a| planar::energy(a));
    row("elastic energy", energy, None, "");
    println!();
}
