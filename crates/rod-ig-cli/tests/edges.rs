//! The CLI's contract at its edges (issue 24), on the built binary: first requests within their
//! deadline, numeric options enforced, huge angles solved exactly, obstacle coordinates
//! bounded, `shape` streamed in bounded memory.

use serde_json::Value;
use std::io::{BufRead, BufReader, Read};
use std::process::{Command, Stdio};

mod common;

use common::{run, run_with_stderr};

/// A process's first request of each subcommand, with deadlines down to 1 ms, is answered
/// with one line: solved, or a failure that says why. (How long it took is
/// checked by counting work in the core's `deadlines` and `first_call_deadline` tests, and
/// measured by `rod-ig bench --only deadlines`: no test here reads a clock.)
#[test]
fn first_requests_of_every_subcommand_answer_within_their_deadline() {
    for ms in [1.0, 10.0, 100.0] {
        let solve =
            format!("{{\"target\":{{\"x\":0.9,\"y\":0.1,\"theta\":3}},\"deadline_ms\":{ms}}}\n");
        let plan = format!(
            "{{\"start\":[0.5,0.1,0.1],\"goal\":{{\"x\":0.8,\"y\":0.3,\"theta\":0.5}},\"deadline_ms\":{ms}}}\n"
        );
        for (command, line) in [("solve", &solve), ("track", &solve), ("plan", &plan)] {
            // A fresh process each time: its first request.
            let answers = run(&[command], line);
            assert_eq!(answers.len(), 1, "{command}: {answers:?}");
            let a = &answers[0];
            let solved = a["success"].as_bool() == Some(true);
            let why = a["reason"].as_str().or(a["error"].as_str()).unwrap_or("");
            assert!(
                solved || !why.is_empty(),
                "{command} at {ms} ms: neither solved nor said why: {a}"
            );
        }
    }
}

#[test]
fn numeric_options_out_of_range_are_refused() {
    let target = "\"target\":{\"x\":0.6,\"y\":0.3,\"theta\":0.5}";
    let target3 = "\"target\":{\"position\":[0.6,0.2,0.3],\"quaternion\":[0.1,0.2,0.3,0.9]}";
    let cases: [(&str, String, &str); 8] = [
        (
            "solve",
            format!("{{{target},\"max_iterations\":0}}"),
            "max_iterations",
        ),
        (
            "solve",
            format!("{{{target},\"max_iterations\":100001}}"),
            "max_iterations",
        ),
        (
            "solve",
            format!("{{{target},\"tolerance\":1e308}}"),
            "tolerance",
        ),
        (
            "solve",
            format!("{{{target},\"tolerance\":1e-20}}"),
            "tolerance",
        ),
        (
            "solve3d",
            format!("{{{target3},\"tolerance\":1e308}}"),
            "tolerance",
        ),
        (
            "solve3d",
            format!("{{{target3},\"stiffness\":[1e300,1,1]}}"),
            "stiffness",
        ),
        (
            "track",
            format!("{{{target},\"tolerance\":0.5}}"),
            "tolerance",
        ),
        (
            "solve",
            format!("{{{target},\"deadline_ms\":1e9}}"),
            "deadline",
        ),
    ];
    for (command, line, field) in cases {
        let answer = &run(&[command], &format!("{line}\n"))[0];
        let error = answer["error"]
            .as_str()
            .or_else(|| answer["reason"].as_str())
            .unwrap_or_else(|| panic!("{command} {line}: refused, got {answer}"));
        assert_ne!(answer["success"], true, "{command} {line}");
        assert!(error.contains(field), "{command} {line}: {error}");
    }
}

#[test]
fn max_iterations_holds_per_start() {
    let (_, stderr) = run_with_stderr(
        &["solve", "--verbose"],
        "{\"target\":{\"x\":0.6,\"y\":0.3,\"theta\":0.5},\"max_iterations\":1}\n",
    );
    let events: Vec<Value> = stderr
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let mut per_start = Vec::new();
    for e in &events {
        match e["event"].as_str() {
            Some("start") => per_start.push(0),
            Some("iteration") => *per_start.last_mut().expect("a start first") += 1,
            _ => {}
        }
    }
    assert!(!per_start.is_empty());
    assert!(per_start.iter().all(|&n| n <= 1), "{per_start:?}");
}

#[test]
fn huge_angles_solve_as_their_exact_reduction() {
    let answers = run(
        &["solve"],
        "{\"target\":{\"x\":0.6,\"y\":0.3,\"theta\":370000000000.123}}\n\
         {\"target\":{\"x\":0.6,\"y\":0.3,\"theta\":0.13099209125032246}}\n\
         {\"target\":{\"x\":0.6,\"y\":0.3,\"theta\":-98765432099999.5}}\n",
    );
    assert_eq!(answers[0]["success"], true, "{}", answers[0]);
    assert_eq!(answers[0]["a"], answers[1]["a"]);
    assert_eq!(
        answers[0]["orientation_error"],
        answers[1]["orientation_error"]
    );
    assert_eq!(answers[2]["success"], true, "{}", answers[2]);
    assert!(answers[0]["orientation_error"].as_f64().unwrap() <= 1e-6);
}

#[test]
fn plan_refuses_obstacles_beyond_the_coordinate_bound() {
    let answers = run(
        &["plan"],
        "{\"start\":[0.5,0.1,0.1],\"goal\":{\"x\":0.8,\"y\":0.3,\"theta\":0.5},\"obstacles\":[{\"type\":\"polygon\",\"points\":[[1e200,1e200],[-1e200,1e200],[0,-1e200]]}]}\n\
         {\"start\":[0.5,0.1,0.1],\"goal\":{\"x\":0.8,\"y\":0.3,\"theta\":0.5},\"obstacles\":[{\"type\":\"polygon\",\"points\":[[1e6,1e6],[-1e6,1e6],[0,-1e6]]}]}\n",
    );
    assert_eq!(answers[0]["success"], false);
    assert!(answers[0]["reason"].as_str().unwrap().contains("1e6"));
    assert_eq!(answers[1]["success"], false);
    assert!(answers[1]["reason"].as_str().unwrap().contains("touches"));
}

/// Peak resident memory of a running process (kB), from /proc.
fn peak_rss_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

#[test]
fn shape_streams_a_million_samples_in_bounded_memory() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["shape", "--a", "1,2,3", "--samples", "1000000"])
        .stdout(Stdio::piped())
        .spawn()
        .expect("rod-ig starts");
    let pid = child.id();
    let mut stdout = child.stdout.take().unwrap();
    // Read slowly at first so that the process is measured while it writes.
    let mut buf = vec![0u8; 1 << 16];
    let (mut total, mut peak) = (0usize, 0u64);
    loop {
        let n = stdout.read(&mut buf).unwrap();
        if n == 0 {
            break;
        }
        total += n;
        if total % (1 << 22) < n {
            peak = peak.max(peak_rss_kb(pid).unwrap_or(0));
        }
    }
    assert!(child.wait().unwrap().success());
    // 77 MB of output; held in memory it peaked at 642 MB before streaming.
    assert!(total > 70_000_000, "{total} bytes");
    assert!(
        peak > 0 && peak < 40_000,
        "peak RSS {peak} kB while streaming"
    );
}

#[test]
fn streamed_shape_equals_the_rods_samples() {
    let out = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["shape", "--a", "1,2,3", "--a", "-3,20,5", "--samples", "9"])
        .output()
        .unwrap();
    let lines: Vec<Value> = BufReader::new(&out.stdout[..])
        .lines()
        .map(|l| serde_json::from_str(&l.unwrap()).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    for (line, a) in lines.iter().zip([[1.0, 2.0, 3.0], [-3.0, 20.0, 5.0]]) {
        let rod = rod_ig_core::planar::PlanarRod::new(&a.into()).unwrap();
        let expected = serde_json::to_value(rod.shape(9)).unwrap();
        assert_eq!(line["poses"], expected);
        assert_eq!(line["a"], serde_json::json!(a));
    }
}

/// `rod-ig bench | head -1`: the report stops quietly when its reader goes away (std ignores
/// SIGPIPE, so each write fails with BrokenPipe; println! used to panic with a backtrace).
#[test]
fn bench_stops_quietly_when_its_reader_goes_away() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(["bench", "--only", "spatial", "--quick"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("rod-ig starts");
    let mut first = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut first)
        .expect("the report's first line");
    assert!(first.starts_with("## 3-D rod"), "{first}");
    // The reader is dropped here: the pipe closes with the report unfinished.
    let out = child.wait_with_output().expect("rod-ig exits");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "exit status {:?}: {stderr}",
        out.status
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn a_search_cut_by_its_deadline_says_it_is_incomplete() {
    let line = |ms: f64| {
        format!(
            "{{\"target\":{{\"x\":-0.3,\"y\":0.4,\"theta\":2.5}},\"objective\":\"least_energy\",\
             \"all\":true,\"deadline_ms\":{ms}}}\n"
        )
    };
    let full = &run(&["solve"], &line(10_000.0))[0];
    assert_eq!(full["complete"], true, "{full}");
    assert_eq!(full["success"], true, "{full}");
    let cut = &run(&["solve"], &line(0.05))[0];
    assert_eq!(cut["complete"], false, "{cut}");
}

#[test]
fn forward3d_holds_its_deadline() {
    // c1 = 1e-6: ~10⁵ integration steps, cut by a 1 ms deadline with a reason.
    let stiff = "\"a\":[3,-2,5,1,4,-3],\"stiffness\":[1e-6,1,1e6]";
    let answers = run(
        &["forward3d"],
        &format!(
            "{{{stiff},\"deadline_ms\":1}}\n{{{stiff},\"deadline_ms\":0}}\n\
             {{{stiff},\"deadline_ms\":20000}}\n{{\"a\":[0.5,1,-1,2,3,-4],\"deadline_ms\":1000}}\n"
        ),
    );
    let error = |i: usize| answers[i]["error"].as_str().unwrap_or("").to_string();
    assert!(error(0).contains("deadline passed"), "{}", answers[0]);
    assert!(error(1).contains("deadline_ms"), "{}", answers[1]);
    assert!(error(2).contains("deadline_ms"), "{}", answers[2]);
    assert!(answers[3]["tip"].is_object(), "{}", answers[3]);
}
