//! The CLI contracts of issues #2 and #3, checked on the built binary: field names, one answer
//! per line in order, errors that do not stop the stream.

use serde_json::Value;
use std::process::Command;

mod common;

use common::{run, run_with_stderr};

#[test]
fn forward_contract() {
    // An oracle line (cases_public.jsonl #2): tip [θ, x, y] and J rows θ, x, y there.
    let out = run(
        &["forward"],
        "{\"a\": [8.972988942744877, -37.63370959790291, -15.33471020548487]}\n{\"a\": [1, 2]}\nnot json\n{\"a\": [0, 0, 0]}\n",
    );
    assert_eq!(out.len(), 4);
    let first = &out[0];
    assert!((first["tip"]["x"].as_f64().unwrap() - 0.3224172897011997).abs() < 1e-11);
    assert!((first["tip"]["y"].as_f64().unwrap() - 0.2921048196081635).abs() < 1e-11);
    assert!((first["tip"]["theta"].as_f64().unwrap() + 1.1432055279122757).abs() < 1e-11);
    let jac = first["jacobian"].as_array().unwrap();
    assert_eq!(jac.len(), 3);
    // Row θ of the oracle is the third row here.
    assert!((jac[2][0].as_f64().unwrap() + 0.34773503102031716).abs() < 1e-8);
    assert!((jac[0][1].as_f64().unwrap() + 0.0196286100843422).abs() < 1e-8);
    assert_eq!(first["stable"], true);
    assert!((first["energy"].as_f64().unwrap() - 19.23665709368305).abs() < 1e-9);
    assert!(out[1]["error"].as_str().unwrap().contains("length 3"));
    assert!(out[2]["error"].is_string());
    // Straight rod: singular J, classified unstable (docs/math.md §5).
    assert_eq!(out[3]["stable"], false);
    assert_eq!(out[3]["tip"]["x"], 1.0);
}

#[test]
fn solve_contract() {
    let target =
        "{\"x\": 0.3134187265422321, \"y\": -0.587006393473652, \"theta\": -2.1624511539781346}";
    let input = format!(
        "{{\"target\": {target}}}\n\
         {{\"target\": {target}, \"method\": \"newton\", \"alpha\": 1.0, \"a0\": [-5.4, -39.9, 74.7], \"max_iterations\": 100, \"tolerance\": 1e-8}}\n\
         {{\"target\": {{\"x\": 1.5, \"y\": 0, \"theta\": 0}}}}\n\
         {{\"target\": {target}, \"method\": \"nope\"}}\n\
         {{\"target\": {target}, \"alpah\": 1}}\n"
    );
    let out = run(&["solve"], &input);
    assert_eq!(out.len(), 5);
    for answer in &out[..2] {
        assert_eq!(answer["success"], true, "{answer}");
        assert_eq!(answer["stable"], true);
        for key in ["a", "tip", "iterations", "residual", "energy"] {
            assert!(!answer[key].is_null(), "{key} missing in {answer}");
        }
        let tip = &answer["tip"];
        assert!((tip["x"].as_f64().unwrap() - 0.3134187265422321).abs() < 1e-6);
        assert!((tip["y"].as_f64().unwrap() + 0.587006393473652).abs() < 1e-6);
    }
    assert_eq!(out[2]["success"], false);
    assert!(out[2]["a"].is_null());
    assert!(out[2]["reason"].as_str().unwrap().contains("unreachable"));
    assert!(out[3]["error"]
        .as_str()
        .unwrap()
        .contains("unknown variant"));
    assert!(out[4]["error"].as_str().unwrap().contains("unknown field"));
}

/// A target no stable rod reaches (within reach, bent back at full extension): the answer says
/// what was searched, and `starts` counts it (issue 42: it read 0 beside "from 19 starts").
#[test]
fn a_failed_search_says_what_it_searched() {
    let out = run(
        &["solve"],
        "{\"target\": {\"x\": 0.999, \"y\": 0, \"theta\": 3.0}}\n",
    );
    let answer = &out[0];
    assert_eq!(answer["success"], false, "{answer}");
    assert_eq!(answer["termination"], "no_stable_solution");
    let reason = answer["reason"].as_str().unwrap();
    assert!(
        reason.contains("Newton starts") && reason.contains("branches followed"),
        "{reason}"
    );
    assert!(answer["starts"].as_u64().unwrap() > 0, "{answer}");
}

#[test]
fn shape_svg_and_json() {
    let dir = std::env::temp_dir().join(format!("rod-ig-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("rod.svg");
    let status = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["shape", "--a", "1,-5,3", "--a", "-2,10,-20", "-o"])
        .arg(&svg)
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(text.matches("<polyline").count(), 2);
    let out = run(&["shape", "--a", "1,-5,3", "--samples", "5"], "");
    let poses = out[0]["poses"].as_array().unwrap();
    assert_eq!(poses.len(), 5);
    assert_eq!(poses[0]["x"], 0.0);
    let bad = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["shape", "--a", "1,nan,3"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("not"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn forward3d_planar_subset_matches_forward() {
    // (a1, a2, a6) = 0 is the planar rod (docs/math.md §10): same tip, rotation about z by θ.
    let planar = run(&["forward"], "{\"a\": [2.5, -12.0, 7.0]}\n");
    let spatial = run(
        &["forward3d"],
        "{\"a\": [0, 0, 2.5, -12.0, 7.0, 0], \"rtol\": 1e-12}\n{\"a\": [1, 2, 3]}\n{\"a\": [0, 0, 1, 1, 1, 0], \"stiffness\": [1, -1, 1]}\n",
    );
    assert_eq!(spatial.len(), 3);
    let tip = &spatial[0]["tip"];
    let p = tip["position"].as_array().unwrap();
    let q = tip["quaternion"].as_array().unwrap();
    let theta = planar[0]["tip"]["theta"].as_f64().unwrap();
    assert!((p[0].as_f64().unwrap() - planar[0]["tip"]["x"].as_f64().unwrap()).abs() < 1e-9);
    assert!((p[1].as_f64().unwrap() - planar[0]["tip"]["y"].as_f64().unwrap()).abs() < 1e-9);
    assert!(p[2].as_f64().unwrap().abs() < 1e-12);
    // q = (0, 0, sin θ/2, cos θ/2) up to the sign that makes w ≥ 0.
    let (qz, qw) = (q[2].as_f64().unwrap(), q[3].as_f64().unwrap());
    assert!(qw >= 0.0);
    assert!((qz.atan2(qw) * 2.0 - rod_ig_core::wrap_angle(theta)).abs() < 1e-8);
    assert_eq!(spatial[0]["stable"], planar[0]["stable"]);
    assert_eq!(spatial[0]["jacobian"].as_array().unwrap().len(), 6);
    assert!(spatial[1]["error"].as_str().unwrap().contains("length 6"));
    assert!(spatial[2]["error"].as_str().unwrap().contains("stiffness"));
}

#[test]
fn solve3d_contract() {
    let out = run(
        &["solve3d"],
        "{\"target\": {\"position\": [0.5, 0.3, 0.2], \"quaternion\": [0, 0, 0.3826834, 0.9238795]}}\n\
         {\"target\": {\"position\": [2, 0, 0], \"quaternion\": [0, 0, 0, 1]}}\n\
         {\"target\": {\"position\": [0.5, 0, 0], \"quaternion\": [0, 0, 0, 0]}}\n",
    );
    assert_eq!(out.len(), 3);
    assert_eq!(out[0]["success"], true, "{}", out[0]);
    assert_eq!(out[0]["stable"], true);
    let p = out[0]["tip"]["position"].as_array().unwrap();
    for (got, want) in p.iter().zip([0.5, 0.3, 0.2]) {
        assert!((got.as_f64().unwrap() - want).abs() < 1e-6);
    }
    assert_eq!(out[1]["success"], false);
    assert!(out[1]["reason"].as_str().unwrap().contains("reach"));
    assert!(out[2]["error"].as_str().unwrap().contains("quaternion"));
}

/// Issue 9: every request is bounded — absurd iteration counts and tolerances are refused with
/// the reason, a deadline is honoured and reported, shapes have a size limit.
#[test]
fn requests_are_bounded_with_clear_reasons() {
    let target = "{\"x\": 0.5, \"y\": 0.2, \"theta\": 1.0}";
    let out = run(
        &["solve"],
        &format!(
            "{{\"target\": {target}, \"method\": \"newton\", \"a0\": [1, -5, 3], \"max_iterations\": 1000000000, \"tolerance\": 1e-6}}\n\
             {{\"target\": {target}, \"method\": \"newton\", \"a0\": [1, -5, 3], \"tolerance\": 1e-300}}\n\
             {{\"target\": {target}, \"method\": \"newton\", \"a0\": [1, -5, 3], \"alpha\": 0.001, \"max_iterations\": 100000, \"tolerance\": 1e-14, \"deadline_ms\": 20}}\n\
             {{\"target\": {target}, \"deadline_ms\": -1}}\n\
             {{\"target\": {target}, \"deadline_ms\": 60000}}\n"
        ),
    );
    assert_eq!(out.len(), 5);
    // Options out of range: an error line (the CLI checks the solver's documented bounds).
    assert!(
        out[0]["error"].as_str().unwrap().contains("max_iterations"),
        "{}",
        out[0]
    );
    assert!(
        out[1]["error"].as_str().unwrap().contains("tolerance"),
        "{}",
        out[1]
    );
    assert!(
        out[2]["reason"].as_str().unwrap().contains("deadline"),
        "{}",
        out[2]
    );
    assert!(
        out[3]["error"].as_str().unwrap().contains("deadline_ms"),
        "{}",
        out[3]
    );
    assert!(
        out[4]["reason"].as_str().unwrap().contains("deadline"),
        "{}",
        out[4]
    );
    let status = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["shape", "--a", "1,2,3", "--samples", "18446744073709551615"])
        .output()
        .expect("rod-ig runs");
    assert!(!status.status.success());
    assert!(String::from_utf8_lossy(&status.stderr).contains("--samples must be between"));
}

/// Issue 9: `all` never reports success with no solutions; least energy succeeds where the
/// default does; the forward answer says when the verdict is uncertain (straight rod).
#[test]
fn all_least_energy_and_uncertain_verdicts() {
    let target = "{\"x\": 0.95, \"y\": 0.05, \"theta\": 0.02}";
    let out = run(
        &["solve"],
        &format!(
            "{{\"target\": {target}}}\n\
             {{\"target\": {target}, \"objective\": \"least_energy\", \"all\": true}}\n"
        ),
    );
    assert_eq!(out[0]["success"], true, "{}", out[0]);
    assert_eq!(out[1]["success"], true, "{}", out[1]);
    assert!(!out[1]["solutions"].as_array().unwrap().is_empty());
    let out = run(
        &["forward"],
        "{\"a\": [0, 3, 0]}\n{\"a\": [0.05, 1e-8, 1e-8]}\n",
    );
    assert_eq!(out[0]["stability_uncertain"], true);
    assert_eq!(out[0]["stable"], false);
    assert_eq!(out[1]["stability_uncertain"], false);
    assert_eq!(out[1]["stable"], true);
    let m = out[1]["stability_margin"].as_f64().unwrap();
    assert!((0.9..=1.01).contains(&m), "{m}");
}

/// Issue 9: a 3-D rod of stiffness [s, s, s] is solved for s ≠ 1 (seeds scale with stiffness);
/// its a is s times the unit rod's (moments and forces scale with the stiffness).
#[test]
fn solve3d_with_scaled_stiffness() {
    let req = |s: f64| {
        format!(
            "{{\"target\": {{\"position\": [0.5, 0.3, 0.2], \"quaternion\": [0, 0, 0.3827, 0.9239]}}, \"stiffness\": [{s}, {s}, {s}]}}\n"
        )
    };
    let unit = run(&["solve3d"], &req(1.0));
    for s in [0.3, 2.0, 5.0] {
        let out = run(&["solve3d"], &req(s));
        assert_eq!(out[0]["success"], true, "s = {s}: {}", out[0]);
        let a = out[0]["a"].as_array().unwrap();
        let u = unit[0]["a"].as_array().unwrap();
        let dev = a
            .iter()
            .zip(u)
            .map(|(x, y)| (x.as_f64().unwrap() - s * y.as_f64().unwrap()).abs())
            .fold(0.0, f64::max);
        assert!(dev < 1e-4 * s * 200.0, "s = {s}: a deviates by {dev}");
    }
}

#[test]
fn solve3d_has_every_option_of_solve() {
    // A planar target lifted to 3-D (rotation about z by θ): the same request fields as
    // `solve`, objective and all included; answers carry the typed termination.
    let theta: f64 = 0.8;
    let (s, c) = ((theta / 2.0).sin(), (theta / 2.0).cos());
    let target = format!("{{\"position\": [0.5, 0.4, 0.0], \"quaternion\": [0.0, 0.0, {s}, {c}]}}");
    let input = format!(
        "{{\"target\": {target}, \"all\": true}}\n\
         {{\"target\": {target}, \"objective\": \"least_energy\"}}\n\
         {{\"target\": {target}, \"objective\": \"sideways\"}}\n\
         {{\"target\": {{\"position\": [0.0, 2.0, 0.0], \"quaternion\": [0, 0, 0, 1]}}}}\n"
    );
    let out = run(&["solve3d"], &input);
    assert_eq!(out.len(), 4);
    let all = &out[0];
    assert_eq!(all["success"], true);
    assert_eq!(all["termination"], "converged");
    let solutions = all["solutions"].as_array().expect("solutions listed");
    assert!(!solutions.is_empty());
    let energies: Vec<f64> = solutions
        .iter()
        .map(|s| s["energy"].as_f64().unwrap())
        .collect();
    assert!(energies.windows(2).all(|w| w[0] <= w[1]), "{energies:?}");
    let least = &out[1];
    assert_eq!(least["success"], true);
    assert!(least["energy"].as_f64().unwrap() <= all["energy"].as_f64().unwrap() + 1e-9);
    assert!(least["energy"].as_f64().unwrap() <= energies[0] + 1e-9);
    assert!(out[2]["error"].as_str().unwrap().contains("sideways"));
    assert_eq!(out[3]["success"], false);
    assert_eq!(out[3]["termination"], "unreachable");
}

#[test]
fn verbose_prints_the_solver_events_on_stderr() {
    let (out, stderr) = run_with_stderr(
        &["solve", "--verbose"],
        "{\"target\": {\"x\": 0.5, \"y\": 0.3, \"theta\": 0.8}}\n",
    );
    let answer = &out[0];
    let events: Vec<Value> = stderr
        .lines()
        .map(|l| serde_json::from_str(l).expect("each event is JSON"))
        .collect();
    let iterations = events.iter().filter(|e| e["event"] == "iteration").count();
    assert_eq!(iterations as u64, answer["iterations"].as_u64().unwrap());
    let starts = events.iter().filter(|e| e["event"] == "start").count();
    assert_eq!(starts as u64, answer["starts"].as_u64().unwrap());
    let last = events.last().expect("events");
    assert_eq!(last["event"], "finished");
    assert_eq!(last["termination"], "converged");
}

#[test]
fn track_reports_the_snap_of_a_buckled_rod() {
    // The buckled rod (bump up) held by grippers 0.8 apart; the tip gripper turns by 0.02 rad
    // per line. One line reports the snap with the critical pose; the others stay on a branch.
    let mut input = String::from(
        "{\"a0\": [5.849576446834202, -43.929163868139426, 0.0], \"target\": {\"x\": 0.8, \"y\": 0.0, \"theta\": 0.0}}\n",
    );
    for k in 1..=50 {
        input.push_str(&format!(
            "{{\"target\": {{\"x\": 0.8, \"y\": 0.0, \"theta\": {}}}}}\n",
            0.02 * f64::from(k)
        ));
    }
    input.push_str("{\"target\": {\"x\": 0.8, \"y\": 0.0, \"theta\": 0.5}, \"a0\": [1, 2, 3]}\n");
    let svg = std::env::temp_dir().join(format!("rod-ig-track-{}.svg", std::process::id()));
    let out = run(&["track", "--svg", svg.to_str().unwrap()], &input);
    assert_eq!(out.len(), 52);
    let snaps: Vec<&Value> = out.iter().filter(|o| o["event"] == "snap").collect();
    assert_eq!(snaps.len(), 1, "one snap");
    let snap = snaps[0];
    assert_eq!(snap["success"], true);
    let critical = snap["critical"]["theta"].as_f64().unwrap();
    assert!(critical > 0.7 && critical < 0.9, "{critical}");
    assert!(snap["energy_released"].as_f64().unwrap() > 0.0);
    assert!(out[..51]
        .iter()
        .all(|o| o["success"] == true && o["event"] != "lost"));
    assert!(out[51]["error"].as_str().unwrap().contains("first line"));
    let picture = std::fs::read_to_string(&svg).expect("svg written");
    assert!(
        picture.contains("stroke-dasharray=\"7 4\""),
        "critical rod drawn"
    );
    let _ = std::fs::remove_file(svg);
}

#[test]
fn plan_answers_with_stable_rods_or_a_reason() {
    let input = "{\"start\": [1.0, 2.0, -1.0], \"goal\": {\"x\": 0.3, \"y\": 0.6, \"theta\": 2.5}, \"obstacles\": [{\"type\": \"disc\", \"center\": [0.5, 0.35], \"radius\": 0.1}]}\n\
                 {\"start\": [1.0, 2.0, -1.0], \"goal\": {\"x\": 1.5, \"y\": 0.0, \"theta\": 0.0}}\n\
                 {\"start\": [1.0, 2.0, -1.0], \"goal\": {\"x\": 0.3, \"y\": 0.6, \"theta\": 2.5}, \"obstacles\": [{\"type\": \"cloud\"}]}\n";
    let out = run(&["plan"], input);
    assert_eq!(out.len(), 3);
    assert_eq!(out[0]["success"], true);
    let rods = out[0]["rods"].as_array().unwrap();
    let gripper = out[0]["gripper"].as_array().unwrap();
    assert_eq!(rods.len(), gripper.len());
    assert_eq!(rods[0], serde_json::json!([1.0, 2.0, -1.0]));
    let last = gripper.last().unwrap();
    assert!((last["x"].as_f64().unwrap() - 0.3).abs() < 1e-6);
    assert!(out[0]["min_margin"].as_f64().unwrap() >= 1e-3);
    assert_eq!(out[1]["success"], false);
    assert!(out[1]["reason"].as_str().unwrap().contains("unreachable"));
    assert!(out[2]["error"].as_str().unwrap().contains("cloud"));
}

#[test]
fn weight_and_gravity_fields() {
    // A public gravity case (data/oracle/gravity_public.jsonl, line 1), then the same rod
    // without weight (the weightless answer), then refusals that name the field.
    let case = "\"a\": [-2.5899894578390388, -14.485326946763456, 28.871000799863218]";
    let input = format!(
        "{{{case}, \"weight\": 0.20137468828407715, \"gravity\": [0.12585306093929588, -0.9920488934786481]}}\n\
         {{{case}}}\n\
         {{{case}, \"weight\": -1}}\n\
         {{{case}, \"weight\": 1, \"gravity\": [0, 0]}}\n\
         {{{case}, \"weight\": 1, \"gravity\": [0, 0, -1]}}\n"
    );
    let out = run(&["forward"], &input);
    assert_eq!(out.len(), 5);
    let heavy = &out[0];
    assert!((heavy["tip"]["x"].as_f64().unwrap() - 0.1422357048066626).abs() < 1e-9);
    assert!((heavy["tip"]["y"].as_f64().unwrap() + 0.7237771386111447).abs() < 1e-9);
    assert!((heavy["energy"].as_f64().unwrap() - 11.75830899936043).abs() < 1e-8);
    assert!(heavy["elastic_energy"].is_f64() && heavy["tip_force"].is_array());
    assert_eq!(heavy["stable"], true);
    // Without `weight` the answer has exactly the weightless fields.
    assert!(out[1].get("elastic_energy").is_none() && out[1].get("tip_force").is_none());
    assert!(out[2]["error"].as_str().unwrap().contains("weight"));
    assert!(out[3]["error"].as_str().unwrap().contains("gravity"));
    assert!(out[4]["error"].is_string());

    // Inverse geometry with weight: a rod held level sags with a5 = −w/2 (symmetry).
    let out = run(
        &["solve"],
        "{\"target\": {\"x\": 0.6, \"y\": 0, \"theta\": 0}, \"weight\": 50, \"objective\": \"least_energy\"}\n",
    );
    assert_eq!(out[0]["success"], true, "{}", out[0]);
    assert_eq!(out[0]["stable"], true);
    assert!(
        (out[0]["a"][2].as_f64().unwrap() + 25.0).abs() < 1e-4,
        "{}",
        out[0]
    );
}

#[test]
fn shape_draws_heavy_rods_beside_weightless_ones() {
    let dir = std::env::temp_dir().join(format!("rod-ig-heavy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("heavy.svg");
    let status = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["shape", "--target", "0.6,0,0", "--weight", "50", "-o"])
        .arg(&svg)
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("weight 50") && text.contains("<svg"));
    // JSON poses of a heavy rod: the base at the origin, one line per rod.
    let out = run(
        &[
            "shape",
            "--a",
            "3,-2,-25",
            "--weight",
            "50",
            "--gravity",
            "0,-1",
            "--samples",
            "5",
        ],
        "",
    );
    assert_eq!(out.len(), 1);
    assert_eq!(out[0]["poses"].as_array().unwrap().len(), 5);
    assert_eq!(out[0]["poses"][0]["x"], 0.0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn track_follows_changes_of_weight_and_gravity() {
    // The gripper holds a rod level at 0.6; the cable gets heavier, then the base turns so that
    // gravity points along +x, then back: each line answers a stable rod on target.
    let lines = [
        "{\"target\": {\"x\": 0.6, \"y\": 0, \"theta\": 0}}",
        "{\"target\": {\"x\": 0.6, \"y\": 0, \"theta\": 0}, \"weight\": 50}",
        "{\"target\": {\"x\": 0.55, \"y\": 0.05, \"theta\": 0}}",
        "{\"target\": {\"x\": 0.55, \"y\": 0.05, \"theta\": 0}, \"gravity\": [1, 0]}",
        "{\"target\": {\"x\": 0.55, \"y\": 0.05, \"theta\": 0}, \"gravity\": [0, -1]}",
        "{\"target\": {\"x\": 0.55, \"y\": 0.05, \"theta\": 0}, \"weight\": -3}",
    ];
    let out = run(&["track"], &(lines.join("\n") + "\n"));
    assert_eq!(out.len(), 6);
    for (i, answer) in out[..5].iter().enumerate() {
        assert_eq!(answer["success"], true, "line {i}: {answer}");
        assert_eq!(answer["stable"], true);
        assert!(answer["position_error"].as_f64().unwrap() < 1e-6);
    }
    // The held rod under w = 50, gravity −y at (0.6, 0, 0) is the level rod: a5 = −25.
    assert!(
        (out[1]["a"][2].as_f64().unwrap() + 25.0).abs() < 1e-5,
        "{}",
        out[1]
    );
    // Back to the same gravity and pose: the same branch, hence the same rod.
    let (a2, a4) = (&out[2]["a"], &out[4]["a"]);
    for k in 0..3 {
        assert!(
            (a2[k].as_f64().unwrap() - a4[k].as_f64().unwrap()).abs() < 1e-4,
            "{a2} vs {a4}"
        );
    }
    assert!(out[5]["error"].as_str().unwrap().contains("weight"));
}

#[test]
fn plan_takes_weight_and_gravity() {
    // A cable of weight 15 held by a stable heavy rod, planned to a pose below: the gripper path
    // ends at the goal with the heavy rod's tip; the same request weightless is another plan;
    // a negative weight is refused naming it.
    let start = "\"start\": [1.7939773444075664, -11.347913785723009, 2.39993152353178]";
    let goal = "\"goal\": {\"x\": 0.2413, \"y\": -0.7694, \"theta\": -1.5494}";
    let lines = [
        format!("{{{start}, {goal}, \"weight\": 15, \"gravity\": [0, -1]}}"),
        format!("{{{start}, {goal}}}"),
        format!("{{{start}, {goal}, \"weight\": -1}}"),
    ];
    let out = run(&["plan"], &(lines.join("\n") + "\n"));
    assert_eq!(out.len(), 3);
    for answer in &out[..2] {
        assert_eq!(answer["success"], true, "{answer}");
        let last = answer["gripper"]
            .as_array()
            .unwrap()
            .last()
            .unwrap()
            .clone();
        let (x, y) = (last["x"].as_f64().unwrap(), last["y"].as_f64().unwrap());
        assert!((x - 0.2413).hypot(y + 0.7694) < 1e-6, "{answer}");
        assert!(answer["min_margin"].as_f64().unwrap() >= 1e-3);
    }
    let end = |k: usize| out[k]["rods"].as_array().unwrap().last().unwrap().clone();
    let (heavy, light) = (end(0), end(1));
    let gap = (0..3)
        .map(|i| (heavy[i].as_f64().unwrap() - light[i].as_f64().unwrap()).abs())
        .fold(0.0, f64::max);
    assert!(gap > 1.0, "the weight changed nothing: {heavy} vs {light}");
    assert!(out[2]["error"].as_str().unwrap().contains("weight"));
}

#[test]
fn forward3d_takes_weight_and_gravity() {
    // The first 3-D line of data/oracle/gravity_public.jsonl.
    let line = "{\"a\": [-0.5125436654357536, 2.054283434253289, -2.0221151279950513, 7.275847824793701, 3.653817900748945, -24.609998593465576], \"weight\": 0.10318130992463896, \"gravity\": [-0.036431999446761, -0.3497845171631451, -0.9361215204070764]}\n{\"a\": [0, 0, 1, 0, 0, 0], \"weight\": -1}\n{\"a\": [0, 0, 1, 0, 0, 0], \"weight\": 1, \"rtol\": 1e-6}\n";
    let out = run(&["forward3d"], line);
    assert_eq!(out.len(), 3);
    let p = &out[0]["tip"]["position"];
    let expected = [
        0.05030032491968891,
        0.19973999817185245,
        0.18362400467299786,
    ];
    for (i, e) in expected.iter().enumerate() {
        assert!((p[i].as_f64().unwrap() - e).abs() < 1e-9, "{}", out[0]);
    }
    assert!((out[0]["energy"].as_f64().unwrap() - 14.990809108592806).abs() < 1e-8);
    assert_eq!(out[0]["stable"], true);
    assert!(out[0]["elastic_energy"].is_f64());
    assert!(out[1]["error"].as_str().unwrap().contains("weight"));
    assert!(out[2]["error"].as_str().unwrap().contains("rtol"));
}

#[test]
fn solve3d_takes_weight_and_gravity() {
    let target =
        "\"target\": {\"position\": [0.5, 0.3, 0.2], \"quaternion\": [0, 0, 0.3827, 0.9239]}";
    let input = format!(
        "{{{target}, \"weight\": 20, \"gravity\": [0, 0, -1]}}\n{{{target}}}\n{{{target}, \"weight\": 20, \"gravity\": [0, 0]}}\n"
    );
    let out = run(&["solve3d"], &input);
    assert_eq!(out.len(), 3);
    assert_eq!(out[0]["success"], true, "{}", out[0]);
    assert_eq!(out[0]["stable"], true);
    assert!(out[0]["position_error"].as_f64().unwrap() < 1e-6);
    // The heavy rod's answer is another rod than the weightless one for the same pose; the
    // forward map with the same weight puts its tip on the target.
    let a: Vec<f64> = out[0]["a"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_ne!(out[0]["a"], out[1]["a"]);
    let check = run(
        &["forward3d"],
        &format!("{{\"a\": {a:?}, \"weight\": 20, \"gravity\": [0, 0, -1]}}\n"),
    );
    let p = &check[0]["tip"]["position"];
    for (i, e) in [0.5, 0.3, 0.2].iter().enumerate() {
        assert!((p[i].as_f64().unwrap() - e).abs() < 1e-6, "{}", check[0]);
    }
    assert!(out[2]["error"].is_string());
}

#[test]
fn smaller_contract_mends_of_issue_42() {
    // An unknown field inside a planar target is refused, as the 3-D pose refuses one.
    let out = run(
        &["solve"],
        "{\"target\": {\"x\": 0.5, \"y\": 0.2, \"theta\": 1.0, \"z\": 5}}\n",
    );
    assert!(
        out[0]["error"].as_str().unwrap().contains("z"),
        "{}",
        out[0]
    );
    // A refused first `track` line does not lock `a0` out of the next one.
    let out = run(
        &["track"],
        "{\"target\": {\"x\": 0.6, \"y\": 0, \"theta\": 0}, \"tolerance\": -1}\n\
         {\"target\": {\"x\": 0.6, \"y\": 0.01, \"theta\": 0}, \"a0\": [-0.5422184936207011, 99.66906108365531, 0.0]}\n\
         {\"target\": {\"x\": 0.6, \"y\": 0, \"theta\": 0}, \"a0\": [0, 1, 0]}\n",
    );
    assert!(out[0]["error"].is_string());
    assert!(out[1].get("error").is_none(), "{}", out[1]);
    assert!(out[2]["error"].as_str().unwrap().contains("a0"));
    // `--verbose` with a closed stderr still answers every line on stdout, exit 0.
    let mut child = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["solve", "--verbose"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    {
        use std::io::Write;
        let mut stdin = child.stdin.take().unwrap();
        for _ in 0..3 {
            writeln!(
                stdin,
                "{{\"target\": {{\"x\": 0.5, \"y\": 0.2, \"theta\": 1.0}}}}"
            )
            .unwrap();
        }
    }
    let output = child.wait_with_output().unwrap();
    assert!(output.status.success(), "{:?}", output.status);
    assert_eq!(String::from_utf8_lossy(&output.stdout).lines().count(), 3);
}

#[test]
fn track_starts_from_the_straight_rod_at_rest() {
    // a0 = 0: the rod at rest (issue 42, item 7); the first move buckles it, and says so.
    let out = run(
        &["track"],
        "{\"target\": {\"x\": 0.9, \"y\": 0, \"theta\": 0}, \"a0\": [0, 0, 0]}\n\
         {\"target\": {\"x\": 0.88, \"y\": 0.02, \"theta\": 0.05}}\n",
    );
    assert_eq!(out[0]["success"], true, "{}", out[0]);
    assert_eq!(out[0]["event"], "buckle");
    assert_eq!(out[1]["success"], true, "{}", out[1]);
    assert_ne!(out[1]["event"], "buckle");
}

/// A 1 m cable (w = 2,000) held level 0.8 apart (issue 51): `solve` answers the hanging,
/// loop-free rod on target (a5 = −w/2, `turns` 0), `forward` of an `a` one rounding away reports its
/// `condition` and an uncertain verdict, and a bad `max_turns` is refused by name.
#[test]
fn a_one_metre_cable_is_solved() {
    let out = run(
        &["solve"],
        "{\"target\": {\"x\": 0.8, \"y\": 0, \"theta\": 0}, \"weight\": 2000, \"max_turns\": 0, \"deadline_ms\": 5000}\n\
         {\"target\": {\"x\": 0.8, \"y\": 0, \"theta\": 0}, \"weight\": 2000, \"max_turns\": 1000}\n",
    );
    assert_eq!(out[0]["success"], true, "{}", out[0]);
    let a5 = out[0]["a"][2].as_f64().unwrap();
    assert!((a5 + 1000.0).abs() < 1e-6, "{}", out[0]);
    assert_eq!(out[0]["turns"], 0, "{}", out[0]);
    assert!(out[0]["position_error"].as_f64().unwrap() < 1e-9);
    assert!(out[1]["error"].as_str().unwrap().contains("max_turns"));
    // The answer's a with a4 rounded differently: a new process has no node states for it.
    let a: Vec<f64> = (0..3).map(|i| out[0]["a"][i].as_f64().unwrap()).collect();
    let line = format!(
        "{{\"a\": [{}, {}, {}], \"weight\": 2000}}\n",
        a[0],
        a[1] * (1.0 + 4e-16),
        a[2]
    );
    let f = run(&["forward"], &line);
    assert!(f[0]["condition"].as_f64().unwrap() > 1e9, "{}", f[0]);
    assert_eq!(f[0]["stability_uncertain"], true);
}

/// `track` with a 1 m cable (issue 51): the weight ramped line by line at fixed grippers from
/// 50 to 10⁴ (coarse steps: ×2 to ×2.5), then the gripper moved in 20 lines at w = 10⁴; every
/// line succeeds with event "none" (the hanging rod carried and followed on its branch).
#[test]
fn track_carries_and_follows_a_long_cable() {
    let mut lines = String::new();
    for w in [
        50.0, 100.0, 250.0, 500.0, 1_000.0, 2_000.0, 5_000.0, 10_000.0,
    ] {
        lines += &format!(
            "{{\"target\": {{\"x\": 0.8, \"y\": 0, \"theta\": 0}}, \"weight\": {w}, \"deadline_ms\": 10000}}\n"
        );
    }
    for i in 1..=20 {
        let s = i as f64 / 20.0;
        lines += &format!(
            "{{\"target\": {{\"x\": {}, \"y\": {}, \"theta\": {}}}, \"deadline_ms\": 10000}}\n",
            0.8 - 0.2 * s,
            0.1 * s,
            0.3 * s
        );
    }
    let out = run(&["track"], &lines);
    assert_eq!(out.len(), 28);
    for (i, o) in out.iter().enumerate() {
        assert_eq!(o["success"], true, "line {i}: {o}");
        assert_eq!(o["event"], "none", "line {i}: {o}");
    }
    // The hanging rod at w = 10⁴: each gripper holds half of the weight.
    assert!(
        (out[7]["a"][2].as_f64().unwrap() + 5_000.0).abs() < 1e-6,
        "{}",
        out[7]
    );
}

/// Issue 52, item 2: every answer with a rod carries `base_wrench` and `tip_wrench`, each
/// {"force", "moment"} in its gripper's frame (what the rod exerts on that gripper): the base's
/// is a itself, and without weight the tip's balances it (forces opposite in the base frame,
/// moments about the base summing to zero); with weight the grippers carry it.
#[test]
fn answers_carry_both_gripper_wrenches() {
    let f = |v: &Value| v.as_f64().unwrap();
    let check_planar = |v: &Value, load: [f64; 2]| {
        let a: Vec<f64> = v["a"].as_array().unwrap().iter().map(f).collect();
        let (base, tip) = (&v["base_wrench"], &v["tip_wrench"]);
        assert_eq!(f(&base["moment"]), a[0]);
        assert_eq!((f(&base["force"][0]), f(&base["force"][1])), (a[1], a[2]));
        let th = f(&v["tip"]["theta"]);
        let (fx, fy) = (f(&tip["force"][0]), f(&tip["force"][1]));
        let world = [th.cos() * fx - th.sin() * fy, th.sin() * fx + th.cos() * fy];
        assert!((a[1] + world[0] - load[0]).abs() < 1e-9, "{v}");
        assert!((a[2] + world[1] - load[1]).abs() < 1e-9, "{v}");
        if load == [0.0, 0.0] {
            let (x, y) = (f(&v["tip"]["x"]), f(&v["tip"]["y"]));
            let m = a[0] + f(&tip["moment"]) + x * world[1] - y * world[0];
            assert!(m.abs() < 1e-6, "{v}: moments {m}");
        }
    };
    let target = "{\"x\": 0.5, \"y\": 0.2, \"theta\": 1.0}";
    let solved = run(
        &["solve"],
        &format!(
            "{{\"target\": {target}, \"all\": true}}\n{{\"target\": {target}, \"weight\": 5}}\n"
        ),
    );
    check_planar(&solved[0], [0.0, 0.0]);
    for s in solved[0]["solutions"].as_array().unwrap() {
        check_planar(s, [0.0, 0.0]);
    }
    check_planar(&solved[1], [0.0, -5.0]);
    let tracked = run(&["track"], &format!("{{\"target\": {target}}}\n"));
    check_planar(&tracked[0], [0.0, 0.0]);
    let forward = run(&["forward"], "{\"a\": [1, 2, 3]}\n");
    let mut fwd = forward[0].clone();
    fwd["a"] = serde_json::json!([1.0, 2.0, 3.0]);
    check_planar(&fwd, [0.0, 0.0]);
    // 3-D: 3-vectors; the base's is (a1..a3, a4..a6).
    for line in [
        "{\"a\": [0.3, -0.8, 1.2, 2, -3, 1.5]}",
        "{\"a\": [0.3, -0.8, 1.2, 2, -3, 1.5], \"weight\": 2}",
    ] {
        let v = &run(&["forward3d"], &format!("{line}\n"))[0];
        let base: Vec<f64> = v["base_wrench"]["moment"]
            .as_array()
            .unwrap()
            .iter()
            .map(f)
            .collect();
        assert_eq!(base, vec![0.3, -0.8, 1.2], "{v}");
        assert_eq!(v["tip_wrench"]["force"].as_array().unwrap().len(), 3, "{v}");
    }
    let target3 = "{\"position\": [0.7, 0.2, 0.1], \"quaternion\": [0, 0, 0.2, 1]}";
    let v = &run(&["solve3d"], &format!("{{\"target\": {target3}}}\n"))[0];
    assert_eq!(v["success"], true, "{v}");
    assert_eq!(
        v["tip_wrench"]["moment"].as_array().unwrap().len(),
        3,
        "{v}"
    );
    // A failure has no rod, and no wrench.
    let v = &run(
        &["solve"],
        "{\"target\": {\"x\": 2, \"y\": 0, \"theta\": 0}}\n",
    )[0];
    assert!(v.get("base_wrench").is_none(), "{v}");
}

/// A 1 m cable in 3-D (w = 2,000, held level 0.8 apart): `solve3d` answers the hanging rod
/// (issue 51, item 5), and `forward3d` of that `a` in another process says its tip cannot be
/// placed by single shooting (`condition` > 1e9, `stability_uncertain`) rather than a
/// confident verdict; weightless `forward3d` answers carry neither field.
#[test]
fn long_cables_in_3d_are_solved_and_forward3d_says_when_it_cannot_place_a_tip() {
    let solved = run(
        &["solve3d"],
        "{\"target\": {\"position\": [0.8, 0, 0], \"quaternion\": [0, 0, 0, 1]}, \"weight\": 2000}\n",
    );
    let s = &solved[0];
    assert_eq!(s["success"], true, "{s}");
    assert!(s["residual"].as_f64().unwrap() < 1e-10, "{s}");
    let a = s["a"].clone();
    assert!((a[5].as_f64().unwrap() + 1000.0).abs() < 1e-6, "{s}");
    let forward = run(
        &["forward3d"],
        &format!("{{\"a\": {a}, \"weight\": 2000}}\n{{\"a\": [0, 1, 0, 0, 0, 0]}}\n"),
    );
    assert_eq!(forward[0]["stability_uncertain"], true, "{}", forward[0]);
    assert_eq!(forward[0]["stable"], false);
    assert!(forward[0]["condition"].as_f64().unwrap() > 1e9);
    assert!(
        forward[1].get("condition").is_none() && forward[1].get("stability_uncertain").is_none()
    );
}

/// Pinned and free ends (issue 52, item 1): a free tip has no target and answers the hanging
/// cable of least energy with its stable alternatives; pinned ends answer a position target
/// with the base's angle; the moments at pinned and free ends are zero in the wrenches; the
/// clamped contract is unchanged when the conditions say "clamped"; refusals name the field.
#[test]
fn pinned_and_free_ends_are_solved_and_refusals_name_the_field() {
    let out = run(
        &["solve"],
        concat!(
            "{\"tip_condition\": \"free\", \"weight\": 36.92695280826509, \"gravity\": [-1, 0], \"all\": true}\n",
            "{\"target\": {\"x\": 0.8, \"y\": 0}, \"base_condition\": \"pinned\", \"tip_condition\": \"pinned\", \"weight\": 50}\n",
            "{\"target\": {\"x\": 0.8, \"y\": 0, \"theta\": 0}, \"base_condition\": \"clamped\", \"tip_condition\": \"clamped\"}\n",
            "{\"target\": {\"x\": 0.8, \"y\": 0, \"theta\": 0.2}, \"tip_condition\": \"pinned\"}\n",
            "{\"target\": {\"x\": 0.8, \"y\": 0}, \"tip_condition\": \"free\"}\n",
            "{\"tip_condition\": \"free\", \"base_condition\": \"free\"}\n",
            "{\"tip_condition\": \"hinged\", \"target\": {\"x\": 0.8, \"y\": 0}}\n",
        ),
    );
    // A cable clamped pointing along gravity's normal, gravity along −x: it hangs to either
    // side (two mirror rods of energy 4.158152, ends_public A-003); the straight one is unstable.
    let free = &out[0];
    assert_eq!(free["success"], true, "{free}");
    assert!((free["energy"].as_f64().unwrap() - 4.158152069940845).abs() < 1e-8);
    assert_eq!(free["solutions"].as_array().unwrap().len(), 2, "{free}");
    assert_eq!(free["rejected"], 1);
    assert!(free["tip_wrench"]["moment"].as_f64().unwrap().abs() < 1e-9);
    assert!(free["tip_wrench"]["force"][0].as_f64().unwrap().abs() < 1e-12);
    // Pinned both ends, held level 0.8 apart: the hanging catenary with bending (C-002).
    let pinned = &out[1];
    assert_eq!(pinned["success"], true, "{pinned}");
    assert!((pinned["base_angle"].as_f64().unwrap() + 0.9202652225760789).abs() < 1e-8);
    assert!((pinned["energy"].as_f64().unwrap() + 6.24283394420708).abs() < 1e-8);
    assert_eq!(pinned["a"][0].as_f64().unwrap(), 0.0);
    assert!(pinned["position_error"].as_f64().unwrap() < 1e-10);
    assert_eq!(pinned["base_condition"], "pinned");
    // Explicitly clamped: the paper's answer, with its fields.
    assert_eq!(out[2]["success"], true);
    assert!(out[2].get("iterations").is_some() && out[2].get("base_condition").is_none());
    for (line, field) in [
        (3, "target"),
        (4, "target"),
        (5, "base_condition"),
        (6, "tip_condition"),
    ] {
        let e = out[line]["error"]
            .as_str()
            .unwrap_or_else(|| panic!("{}", out[line]));
        assert!(e.starts_with(field), "{e}");
    }
}

/// `forward` with held ends (issue 52, item 1): the rods `solve` returns, given back as `a`
/// (and `base_angle`), reproduce their tips and verdicts with the natural conditions; an
/// explicit "clamped" is the paper's forward; refusals name the field.
#[test]
fn forward_with_held_ends_reproduces_the_solved_rods() {
    let solved = run(
        &["solve"],
        concat!(
            "{\"tip_condition\": \"free\", \"weight\": 36.92695280826509, \"gravity\": [-1, 0]}\n",
            "{\"target\": {\"x\": 0.8, \"y\": 0}, \"base_condition\": \"pinned\", \"tip_condition\": \"pinned\", \"weight\": 50}\n",
        ),
    );
    let lines: Vec<String> = solved
        .iter()
        .zip([
            "\"tip_condition\": \"free\", \"weight\": 36.92695280826509, \"gravity\": [-1, 0]",
            "\"base_condition\": \"pinned\", \"tip_condition\": \"pinned\", \"weight\": 50",
        ])
        .map(|(s, ends)| {
            assert_eq!(s["success"], true, "{s}");
            format!(
                "{{\"a\": {}, \"base_angle\": {}, {ends}}}",
                s["a"], s["base_angle"]
            )
        })
        .chain([
            "{\"a\": [1, 2, 3], \"base_condition\": \"clamped\"}".to_string(),
            "{\"a\": [1, 0, 0], \"base_condition\": \"pinned\", \"tip_condition\": \"pinned\"}"
                .to_string(),
            "{\"a\": [1, 0, 0], \"tip_condition\": \"free\", \"weight\": 5}".to_string(),
            "{\"a\": [1, 0, 0], \"tip_condition\": \"pivot\"}".to_string(),
        ])
        .collect();
    let out = run(&["forward"], &(lines.join("\n") + "\n"));
    for (f, s) in out.iter().zip(&solved) {
        for c in ["x", "y"] {
            let d = f["tip"][c].as_f64().unwrap() - s["tip"][c].as_f64().unwrap();
            assert!(d.abs() < 1e-9, "{f} vs {s}");
        }
        assert_eq!(f["stable"], true, "{f}");
        assert_eq!(f["turns"], 0);
        assert!((f["energy"].as_f64().unwrap() - s["energy"].as_f64().unwrap()).abs() < 1e-8);
    }
    assert_eq!(out[1]["base_condition"], "pinned");
    assert!(out[1]["tip_wrench"]["moment"].as_f64().unwrap().abs() < 1e-8);
    // Explicitly clamped: the paper's forward, without the held answer's fields.
    assert!(out[2].get("jacobian").is_some() && out[2].get("base_condition").is_none());
    for (line, field) in [(3, "a"), (4, "a"), (5, "tip_condition")] {
        let e = out[line]["error"]
            .as_str()
            .unwrap_or_else(|| panic!("{}", out[line]));
        assert!(e.starts_with(field), "{e}");
    }
}

/// `shape` with held ends (issue 52, item 1): a free tip without --a draws every stable rod
/// hanging from the clamp (at w = 300, ends_public A: two mirror rods, each ending straight
/// down, κ(1) = 0 so the last samples are collinear); a pinned base's --a rod starts at its
/// base angle; a pinned base with a moment and an unknown condition are refused by flag.
#[test]
fn shape_draws_rods_held_by_pinned_and_free_ends() {
    let out = run(
        &[
            "shape",
            "--tip-condition",
            "free",
            "--weight",
            "300",
            "--samples",
            "201",
        ],
        "",
    );
    assert_eq!(out.len(), 2, "{out:?}");
    for rod in &out {
        assert_eq!(rod["stable"], true);
        let poses = rod["poses"].as_array().unwrap();
        let theta = poses.last().unwrap()["theta"].as_f64().unwrap();
        assert!(
            (rod_ig_core::wrap_angle(theta) + std::f64::consts::FRAC_PI_2).abs() < 1e-3,
            "{theta}"
        );
    }
    let pinned = run(
        &[
            "shape",
            "--base-condition",
            "pinned",
            "--tip-condition",
            "pinned",
            "--a",
            "0,5,-2",
            "--base-angle",
            "0.3",
            "--samples",
            "3",
        ],
        "",
    );
    assert_eq!(pinned[0]["poses"][0]["theta"], 0.3);
    for (args, flag) in [
        (
            vec!["shape", "--base-condition", "pinned", "--a", "1,2,3"],
            "a:",
        ),
        (
            vec!["shape", "--base-condition", "hinge", "--a", "0,2,3"],
            "--base-condition",
        ),
    ] {
        let bad = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
            .args(&args)
            .output()
            .unwrap();
        assert!(!bad.status.success());
        assert!(
            String::from_utf8_lossy(&bad.stderr).contains(flag),
            "{args:?}"
        );
    }
}

/// `track` with held ends (issue 52, item 1): a cable pinned at both ends, 0.8 apart at
/// w = 50 (ends_public C-002's rod), follows its tip gripper over 10 steps and a weight ramp
/// to 2,000 with the event "none", each rod on target with zero end moments; the ramp ends on
/// the rod a fresh `solve` finds there (the same base angle to 1e-8); a free tip follows
/// gravity turning; a line naming other ends is refused by field.
#[test]
fn track_follows_rods_held_by_pinned_and_free_ends() {
    let ends = "\"base_condition\": \"pinned\", \"tip_condition\": \"pinned\"";
    let mut lines = vec![format!(
        "{{\"target\": {{\"x\": 0.8, \"y\": 0}}, {ends}, \"weight\": 50}}"
    )];
    for i in 1..=10 {
        let (x, y) = (0.8 - 0.01 * i as f64, 0.01 * i as f64);
        lines.push(format!(
            "{{\"target\": {{\"x\": {x}, \"y\": {y}}}, {ends}}}"
        ));
    }
    for w in [300.0, 1000.0, 2000.0] {
        lines.push(format!(
            "{{\"target\": {{\"x\": 0.7, \"y\": 0.1}}, {ends}, \"weight\": {w}}}"
        ));
    }
    lines.push("{\"tip_condition\": \"free\"}".into());
    let out = run(&["track"], &(lines.join("\n") + "\n"));
    assert_eq!(out.len(), 15);
    assert!((out[0]["base_angle"].as_f64().unwrap() + 0.9202652225760789).abs() < 1e-8);
    for (i, v) in out[..14].iter().enumerate() {
        assert_eq!(v["success"], true, "line {i}: {v}");
        assert_eq!(v["event"], "none", "line {i}: {v}");
        assert!(
            v["position_error"].as_f64().unwrap() < 1e-9,
            "line {i}: {v}"
        );
        assert!(v["base_wrench"]["moment"].as_f64().unwrap().abs() < 1e-8);
        assert!(v["tip_wrench"]["moment"].as_f64().unwrap().abs() < 1e-8);
    }
    let fresh = run(
        &["solve"],
        &format!("{{\"target\": {{\"x\": 0.7, \"y\": 0.1}}, {ends}, \"weight\": 2000, \"deadline_ms\": 5000}}\n"),
    );
    let d = out[13]["base_angle"].as_f64().unwrap() - fresh[0]["base_angle"].as_f64().unwrap();
    assert!(d.abs() < 1e-8, "{} vs {}", out[13], fresh[0]);
    assert!(out[14]["error"]
        .as_str()
        .unwrap()
        .starts_with("base_condition"));
    let free = run(
        &["track"],
        "{\"tip_condition\": \"free\", \"weight\": 100}\n{\"tip_condition\": \"free\", \"gravity\": [0.3, -1]}\n",
    );
    for v in &free {
        assert_eq!(v["success"], true, "{v}");
        assert_eq!(v["event"], "none", "{v}");
        assert!(
            v["tip_wrench"]["force"][0].as_f64().unwrap().abs() < 1e-9,
            "{v}"
        );
    }
}
