//! `rod-ig track` over random moves between reachable poses of stable rods (issue 20): every
//! line ends in one of three documented states, and a deadline never loses the rod.

mod common;

use common::run;
use rod_ig_core::rng::SplitMix64;
use serde_json::Value;

/// Tips of random stable rods of the paper's box: poses a gripper can reach with a stable rod.
fn reachable_tips(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::new();
    while out.len() < n {
        let a = rod_ig_core::PlanarParams::new(
            rng.range(-6.0, 6.0),
            rng.range(-60.0, 60.0),
            rng.range(-60.0, 60.0),
        );
        if let Ok(e) = rod_ig_core::planar::evaluate(&a) {
            if e.stability.stable && e.tip.x.hypot(e.tip.y) < 0.95 {
                out.push([e.tip.x, e.tip.y, e.tip.theta]);
            }
        }
    }
    out
}

/// One `track` line per tip, with `extra` JSON fields after the target.
fn track_lines(tips: &[[f64; 3]], extra: &str) -> String {
    tips.iter()
        .map(|t| {
            format!(
                "{{\"target\":{{\"x\":{},\"y\":{},\"theta\":{}}}{extra}}}\n",
                t[0], t[1], t[2]
            )
        })
        .collect()
}

#[test]
fn every_move_ends_reached_kept_or_lost_and_a_deadline_keeps_the_rod() {
    let tips = reachable_tips(40, 0x7A11);
    let lines = track_lines(&tips, "");
    let answers = run(&["track"], &lines);
    assert_eq!(answers.len(), tips.len());
    let (mut reached, mut kept) = (0, 0);
    for (k, a) in answers.iter().enumerate() {
        let progress = a["progress"].as_f64().expect("progress");
        let event = a["event"].as_str().expect("event");
        if a["success"] == true {
            reached += 1;
            assert_eq!(progress, 1.0, "line {k}: {a}");
            assert!(event == "none" || event == "snap", "line {k}: {a}");
            assert_eq!(a["held_a"], a["a"], "line {k}: the rod held is the answer");
        } else if a["termination"] == "deadline" {
            kept += 1;
            assert_eq!(event, "none", "line {k}: a deadline is not a loss: {a}");
            assert!(a["held_a"].is_array(), "line {k}: the rod is kept: {a}");
            assert!((0.0..1.0).contains(&progress), "line {k}: {a}");
        } else {
            assert_eq!(event, "lost", "line {k}: {a}");
            assert_eq!(a["held_a"], Value::Null, "line {k}: {a}");
        }
    }
    // Most moves between reachable poses of stable rods reach their target within the default
    // deadline (measured: see the closing note of issue 20).
    println!("reached {reached}, kept {kept} of {}", answers.len());
    assert!(
        reached >= answers.len() * 3 / 4,
        "reached {reached}, kept {kept} of {}",
        answers.len()
    );
}

/// Given the time, every move between reachable poses of stable rods ends on a stable rod
/// (`none` or `snap`): `lost` is kept for poses with no stable equilibrium near. Two cases
/// used to end `lost`: a branch that folded between two continuation steps (det J(1, a)
/// changed sign twice, so the end rod failed the full test), and a snap whose stable rods all
/// had, by rounding, the critical rod's energy or more.
#[test]
fn given_the_time_no_move_between_stable_poses_is_lost() {
    let tips = reachable_tips(300, 0x5EED_2026);
    let lines = track_lines(&tips, ",\"deadline_ms\":10000");
    let answers = run(&["track"], &lines);
    assert_eq!(answers.len(), tips.len());
    for (k, a) in answers.iter().enumerate() {
        let event = a["event"].as_str().expect("event");
        assert!(a["success"] == true, "line {k}: {a}");
        assert!(event == "none" || event == "snap", "line {k}: {a}");
        assert_eq!(a["held_a"], a["a"], "line {k}: the rod held is the answer");
        assert_eq!(a["stable"], true, "line {k}: {a}");
    }
}
