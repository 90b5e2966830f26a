//! `rod-ig solve3d` and `forward3d` with a pinned or free tip (issue 52, 3-D): the answers,
//! `forward3d` giving them back, and refusals that name the field. The mathematics is checked
//! against an independent energy Hessian in `rod-ig-core/tests/ends3d.rs`.

mod common;

use common::run;
use serde_json::Value;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// A cable hanging from a level gripper (free tip) and a hooked one off the gravity plane
/// (pinned tip): stable answers, no wrench (free) or no moment (pinned) at the tip, on
/// target, and `forward3d` of each answer's `a` gives back its tip, energy and verdict.
#[test]
fn held_tips_answer_and_forward_gives_them_back() {
    let lines = "{\"tip_condition\":\"free\",\"weight\":50}\n\
        {\"tip_condition\":\"pinned\",\"weight\":10,\"target\":{\"position\":[0.6,0.2,-0.3]},\"all\":true}\n";
    let out = run(&["solve3d"], lines);
    for (answer, tip) in out.iter().zip(["free", "pinned"]) {
        assert_eq!(answer["success"], true, "{answer}");
        assert_eq!(answer["tip_condition"], tip);
        assert_eq!(answer["stable"], true);
        let moment = floats(&answer["tip_wrench"]["moment"]);
        assert!(moment.iter().all(|m| m.abs() < 1e-8), "{answer}");
        let weight = if tip == "free" { 50.0 } else { 10.0 };
        let a = floats(&answer["a"]);
        let line = format!("{{\"tip_condition\":\"{tip}\",\"weight\":{weight},\"a\":{a:?}}}\n");
        let back = &run(&["forward3d"], &line)[0];
        assert_eq!(back["stable"], true, "{back}");
        let (p0, p1) = (
            floats(&answer["tip"]["position"]),
            floats(&back["tip"]["position"]),
        );
        // At w ≤ 50 single shooting keeps ~12 digits of the tip.
        assert!(
            p0.iter().zip(&p1).all(|(x, y)| (x - y).abs() < 1e-9),
            "{p0:?} {p1:?}"
        );
        let (e0, e1) = (
            answer["energy"].as_f64().unwrap(),
            back["energy"].as_f64().unwrap(),
        );
        assert!((e0 - e1).abs() < 1e-9 * (1.0 + e0.abs()));
    }
    let free_force = floats(&out[0]["tip_wrench"]["force"]);
    assert!(free_force.iter().all(|f| f.abs() < 1e-9));
    assert!(out[1]["position_error"].as_f64().unwrap() < 1e-9);
    assert!(!out[1]["solutions"].as_array().unwrap().is_empty());
}

/// Refusals name the field: a pinned tip's orientation, a clamped tip's missing orientation,
/// anisotropic
/// bending, a free tip with a target, a free tip's base force other than its weight.
#[test]
fn held_tips_refusals_name_the_field() {
    let lines = "{\"tip_condition\":\"pinned\",\"target\":{\"position\":[0.5,0,0],\"quaternion\":[0,0,0,1]}}\n\
        {\"base_condition\":\"pinned\",\"target\":{\"position\":[0.5,0,0]}}\n\
        {\"tip_condition\":\"free\",\"weight\":5,\"stiffness\":[1,1,2]}\n\
        {\"tip_condition\":\"free\",\"weight\":5,\"target\":{\"position\":[0.5,0,0]}}\n\
        {\"tip_condition\":\"sideways\"}\n";
    let out = run(&["solve3d"], lines);
    for (answer, field) in
        out.iter()
            .zip(["target", "target", "stiffness", "target", "tip_condition"])
    {
        let e = answer["error"]
            .as_str()
            .unwrap_or_else(|| panic!("{answer}"));
        assert!(e.starts_with(field), "{field}: {e}");
    }
    let back = &run(
        &["forward3d"],
        "{\"tip_condition\":\"free\",\"weight\":5,\"a\":[0,1,0,0,0,-4]}\n",
    )[0];
    assert!(back["error"].as_str().unwrap().starts_with("a:"), "{back}");
}

/// A cable hung between two hooks (both ends pinned), and one hung on a hook at its base and
/// held by a gripper at its tip: the answer's base orientation and base force, given back to
/// `forward3d`, reproduce its tip position, energy and verdict; no moment at the pinned ends.
#[test]
fn pinned_base_and_forward_gives_it_back() {
    for tip in ["pinned", "clamped"] {
        pinned_base_round_trip(tip);
    }
}

fn pinned_base_round_trip(tip: &str) {
    let quaternion = if tip == "clamped" {
        ",\"quaternion\":[0,0.2,0,0.98]"
    } else {
        ""
    };
    let line = format!(
        "{{\"base_condition\":\"pinned\",\"tip_condition\":\"{tip}\",\"weight\":50,\
         \"target\":{{\"position\":[0.6,0.3,-0.2]{quaternion}}}}}\n"
    );
    let answer = &run(&["solve3d"], &line)[0];
    assert_eq!(answer["success"], true, "{answer}");
    assert_eq!(answer["stable"], true);
    let a = floats(&answer["a"]);
    assert_eq!(&a[..3], &[0.0, 0.0, 0.0]);
    let q = floats(&answer["base_quaternion"]);
    let pinned_ends: &[&str] = if tip == "pinned" {
        &["base_wrench", "tip_wrench"]
    } else {
        &["base_wrench"]
    };
    for end in pinned_ends {
        let m = floats(&answer[end]["moment"]);
        assert!(m.iter().all(|v| v.abs() < 1e-8), "{end}: {m:?}");
    }
    let back = &run(
        &["forward3d"],
        &format!(
            "{{\"base_condition\":\"pinned\",\"tip_condition\":\"{tip}\",\"weight\":50,\
             \"a\":{a:?},\"base_quaternion\":{q:?}}}\n"
        ),
    )[0];
    assert_eq!(back["stable"], true, "{back}");
    assert_eq!(back["jacobian"].as_array().map(Vec::len), Some(6), "{back}");
    let p = floats(&back["tip"]["position"]);
    assert!(
        p.iter()
            .zip([0.6, 0.3, -0.2])
            .all(|(x, y)| (x - y).abs() < 1e-9),
        "{p:?}"
    );
    let (e0, e1) = (
        answer["energy"].as_f64().unwrap(),
        back["energy"].as_f64().unwrap(),
    );
    assert!((e0 - e1).abs() < 1e-9 * (1.0 + e0.abs()));
}
