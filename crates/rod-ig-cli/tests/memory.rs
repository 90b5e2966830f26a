//! Bounded memory on streams (issue 42, item 5): `track` stays flat over 100,000 lines, with
//! and without a picture, and a line beyond the bound is refused without being held whole.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

/// Peak resident memory a `track` stream may reach (the atlas of stable rods is ≈ 25 MB of it).
const PEAK_LIMIT_KB: u64 = 64 * 1024;

/// A gripper circling slowly: `n` JSON target lines.
fn circling(n: usize) -> String {
    (0..n)
        .map(|i| {
            let t = i as f64 * 1e-3;
            format!(
                "{{\"target\":{{\"x\":{},\"y\":{},\"theta\":{}}}}}\n",
                0.6 + 0.2 * t.cos(),
                0.2 * t.sin(),
                0.5 * (2.0 * t).sin()
            )
        })
        .collect()
}

/// Feeds `input` to `rod-ig args`, reads every answer, and returns the answers and the
/// process's peak resident memory (kB, from /proc before its stdin closes).
fn peak_kb(args: &[&str], input: &str) -> (Vec<String>, u64) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("rod-ig starts");
    let mut stdin = child.stdin.take().expect("stdin");
    let expected = input.lines().count();
    let writer = {
        let input = input.to_string();
        std::thread::spawn(move || {
            let _ = stdin.write_all(input.as_bytes());
            stdin // kept open until the answers are read
        })
    };
    let reader = BufReader::new(child.stdout.take().expect("stdout"));
    let answers: Vec<String> = reader
        .lines()
        .take(expected)
        .map(|l| l.expect("answer line"))
        .collect();
    let status = std::fs::read_to_string(format!("/proc/{}/status", child.id())).expect("status");
    let peak = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .expect("VmHWM");
    drop(writer.join().expect("writer"));
    child.wait().expect("exit");
    (answers, peak)
}

#[test]
fn track_memory_stays_flat_over_100000_lines() {
    let svg = std::env::temp_dir().join(format!("rod-ig-track-{}.svg", std::process::id()));
    let svg_arg = svg.to_str().expect("path").to_string();
    for args in [vec!["track"], vec!["track", "--svg", &svg_arg]] {
        let (answers, peak) = peak_kb(&args, &circling(100_000));
        assert_eq!(answers.len(), 100_000);
        let solved = answers
            .iter()
            .filter(|a| a.contains("\"success\":true"))
            .count();
        assert!(solved >= 99_000, "{args:?}: {solved} solved");
        assert!(
            peak <= PEAK_LIMIT_KB,
            "{args:?}: peak {peak} kB after 100,000 lines"
        );
    }
    // The picture holds at most MAX_DRAWN_RODS rods, spread over the whole motion.
    let picture = std::fs::read_to_string(&svg).expect("svg written");
    let rods = picture.matches("<polyline").count();
    assert!((100..=1000).contains(&rods), "{rods} rods drawn");
    let _ = std::fs::remove_file(&svg);
}

#[test]
fn a_line_beyond_the_bound_is_refused_and_the_stream_goes_on() {
    // 64 MiB of one line, then a good line.
    let long = format!("{{\"a\":[{}1]}}\n", "0,".repeat(32 << 20));
    let input = format!("{long}{{\"a\":[2,-10,5]}}\n");
    let (answers, peak) = peak_kb(&["forward"], &input);
    assert_eq!(answers.len(), 2);
    assert!(answers[0].contains("refused"), "{}", &answers[0]);
    assert!(answers[1].contains("\"tip\""), "{}", &answers[1]);
    // Never held whole: at most the 16 MiB cap (its buffer may round up to 32 MiB).
    assert!(peak <= 40 * 1024, "peak {peak} kB for a 64 MiB line");
}
