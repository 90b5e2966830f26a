//! A bounded, deterministic fuzz of the JSON-lines front end (issue 9 item 6): valid requests of
//! every streaming subcommand mutated the way clients and fuzzers break them — extreme and
//! non-finite numbers, huge integers, wrong types, missing and unknown fields, truncation,
//! invalid UTF-8 — fed through the built binary. The contract checked: the process exits 0
//! (no panic, no abort), answers exactly one JSON object per input line, in order, and each
//! answer is either a result or `{"error": ..}` / `"success": false` with a reason.
//!
//! Stable toolchain only (cargo-fuzz needs nightly, which this machine cannot fetch): a
//! SplitMix64-driven mutator, seeded, so that a failure replays. `ROD_IG_FUZZ_LINES` sets the
//! number of lines per subcommand (default 1,500: a few seconds in release; the README's
//! testing section gives the longer run). Issue 24 added huge angles, subnormals, `track` and
//! `plan` with obstacles of every size.

use rod_ig_core::rng::SplitMix64;
use serde_json::Value;
use std::io::Write;
use std::process::{Command, Stdio};

const NUMBERS: [&str; 28] = [
    "370000000000.123",
    "-98765432099999.5",
    "1e15",
    "2.5e-310",
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    "1e-320",
    "-4.9e-324",
    "1e-60",
    "1e308",
    "-1.7976931348623157e308",
    "1e309",
    "NaN",
    "Infinity",
    "-Infinity",
    "null",
    "\"1\"",
    "18446744073709551615",
    "1000000000",
    "-2147483649",
    "3.141592653589793",
    "1e-300",
    "123456789012345678901234567890",
    "[]",
    "{}",
];

const TEMPLATES: [(&str, &[&str]); 7] = [
    (
        "forward",
        &[
            "{\"a\": [#, #, #]}",
            "{\"a\": [#, #, #], \"weight\": #, \"gravity\": [#, #]}",
        ],
    ),
    (
        "solve",
        &[
            "{\"target\": {\"x\": #, \"y\": #, \"theta\": #}}",
            "{\"target\": {\"x\": #, \"y\": #, \"theta\": #}, \"method\": \"newton\", \"a0\": [#, #, #], \"alpha\": #, \"max_iterations\": #, \"tolerance\": #, \"deadline_ms\": 20}",
            "{\"target\": {\"x\": #, \"y\": #, \"theta\": #}, \"objective\": \"least_energy\", \"all\": true, \"deadline_ms\": #}",
            "{\"target\": {\"x\": #, \"y\": #, \"theta\": #}, \"weight\": #, \"gravity\": [#, #], \"deadline_ms\": 20}",
        ],
    ),
    (
        "forward3d",
        &[
            "{\"a\": [#, #, #, #, #, #], \"stiffness\": [#, #, #], \"rtol\": #}",
            "{\"a\": [#, #, #, #, #, #], \"weight\": #, \"gravity\": [#, #, #]}",
        ],
    ),
    (
        "track",
        &[
            "{\"target\": {\"x\": #, \"y\": #, \"theta\": #}, \"tolerance\": #, \"deadline_ms\": 5}",
            "{\"target\": {\"x\": #, \"y\": #, \"theta\": #}, \"a0\": [#, #, #], \"deadline_ms\": #}",
            "{\"target\": {\"x\": #, \"y\": #, \"theta\": #}, \"weight\": #, \"gravity\": [#, #], \"deadline_ms\": 5}",
        ],
    ),
    (
        "plan",
        &[
            "{\"start\": [#, #, #], \"goal\": {\"x\": #, \"y\": #, \"theta\": #}, \"obstacles\": [{\"type\": \"polygon\", \"points\": [[#, #], [#, #], [#, #]]}], \"deadline_ms\": 5}",
            "{\"start\": [0.5, 0.1, 0.1], \"goal\": {\"x\": #, \"y\": #, \"theta\": #}, \"obstacles\": [{\"type\": \"disc\", \"center\": [#, #], \"radius\": #}], \"deadline_ms\": #}",
            "{\"start\": [#, #, #], \"goal\": {\"x\": #, \"y\": #, \"theta\": #}, \"weight\": #, \"gravity\": [#, #], \"deadline_ms\": 5}",
        ],
    ),
    (
        "solve3d",
        &[
            "{\"target\": {\"position\": [#, #, #], \"quaternion\": [#, #, #, #]}, \"max_iterations\": #, \"tolerance\": #, \"deadline_ms\": 30}",
            "{\"target\": {\"position\": [#, #, #], \"quaternion\": [#, #, #, #]}, \"weight\": #, \"gravity\": [#, #, #], \"deadline_ms\": 30}",
        ],
    ),
    (
        "track3d",
        &[
            "{\"target\": {\"position\": [#, #, #], \"quaternion\": [#, #, #, #]}, \"tolerance\": #, \"deadline_ms\": 30}",
            "{\"target\": {\"position\": [#, #, #], \"quaternion\": [#, #, #, #]}, \"a0\": [#, #, #, #, #, #], \"deadline_ms\": #}",
            "{\"target\": {\"position\": [#, #, #], \"quaternion\": [#, #, #, #]}, \"weight\": #, \"gravity\": [#, #, #], \"deadline_ms\": 30}",
        ],
    ),
];

fn pick<'a>(rng: &mut SplitMix64, items: &[&'a str]) -> &'a str {
    items[(rng.next_u64() % items.len() as u64) as usize]
}

/// One request: a template with its `#` filled by plausible or extreme numbers, then mutated.
fn line(rng: &mut SplitMix64, templates: &[&str]) -> Vec<u8> {
    let mut s = String::new();
    for c in pick(rng, templates).chars() {
        if c == '#' {
            if rng.next_u64().is_multiple_of(3) {
                s.push_str(pick(rng, &NUMBERS));
            } else {
                s.push_str(&format!("{}", rng.range(-1.2, 1.2)));
            }
        } else {
            s.push(c);
        }
    }
    let mut bytes = s.into_bytes();
    match rng.next_u64() % 8 {
        0 => {
            let cut = (rng.next_u64() % bytes.len() as u64) as usize;
            bytes.truncate(cut.max(1));
        }
        1 => {
            let i = (rng.next_u64() % bytes.len() as u64) as usize;
            bytes[i] = (rng.next_u64() % 256) as u8;
        }
        2 => bytes.extend_from_slice(b", \"unknown\": 1}"),
        3 => bytes
            .splice(1..1, b"\"a\": 1, ".iter().copied())
            .for_each(drop),
        _ => {}
    }
    bytes.retain(|&b| b != b'\n' && b != b'\r');
    if bytes.iter().all(u8::is_ascii_whitespace) {
        bytes = b"{}".to_vec();
    }
    bytes
}

#[test]
fn every_line_gets_one_json_answer() {
    let n: usize = std::env::var("ROD_IG_FUZZ_LINES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1500);
    let mut rng = SplitMix64::new(0xF022);
    for (command, templates) in TEMPLATES {
        let lines: Vec<Vec<u8>> = (0..n).map(|_| line(&mut rng, templates)).collect();
        let mut input = Vec::new();
        for l in &lines {
            input.extend_from_slice(l);
            input.push(b'\n');
        }
        let mut child = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
            .arg(command)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("rod-ig starts");
        let mut stdin = child.stdin.take().expect("stdin");
        let writer = std::thread::spawn(move || stdin.write_all(&input));
        let out = child.wait_with_output().expect("rod-ig exits");
        writer.join().expect("writer").expect("stdin written");
        assert!(
            out.status.success(),
            "{command}: exit {:?}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        let answers: Vec<Value> = String::from_utf8(out.stdout)
            .expect("UTF-8 output")
            .lines()
            .map(|l| serde_json::from_str(l).expect("every answer is JSON"))
            .collect();
        assert_eq!(answers.len(), lines.len(), "{command}: one answer per line");
        for (l, a) in lines.iter().zip(&answers) {
            let ok = a.get("error").is_some_and(Value::is_string)
                || a.get("tip").is_some()
                || (a["success"] == false && a["reason"].is_string())
                || (a["success"] == true && a["rods"].is_array());
            assert!(ok, "{command}: {} -> {a}", String::from_utf8_lossy(l));
        }
    }
}

/// The bounds of issue 42 at their edges, in one `plan` stream: obstacles at and one past
/// [`MAX_OBSTACLES`], polygon vertices one past [`MAX_VERTICES`], a line one byte past the
/// 16 MiB line bound, `deadline_ms` at and past its maximum. Every line gets its answer in
/// order; a refusal names the bound; what is within the bounds is not refused for them.
#[test]
fn bounds_are_answered_at_their_edges() {
    use rod_ig_core::plan::{MAX_OBSTACLES, MAX_VERTICES};
    const MAX_LINE_BYTES: usize = 16 << 20;
    let request = |obstacles: &str, deadline_ms: u64| {
        format!(
            "{{\"start\": [0.5, 0.1, 0.1], \"goal\": {{\"x\": 0.6, \"y\": 0.3, \"theta\": 0.5}}, \
             \"obstacles\": [{obstacles}], \"deadline_ms\": {deadline_ms}}}"
        )
    };
    let discs =
        |n: usize| vec!["{\"type\": \"disc\", \"center\": [5, 5], \"radius\": 0.01}"; n].join(", ");
    let polygon = |n: usize| {
        let points: Vec<String> = (0..n)
            .map(|i| {
                let phi = i as f64 * std::f64::consts::TAU / n as f64;
                format!("[{}, {}]", 5.0 + 0.1 * phi.cos(), 5.0 + 0.1 * phi.sin())
            })
            .collect();
        format!(
            "{{\"type\": \"polygon\", \"points\": [{}]}}",
            points.join(", ")
        )
    };
    let mut long = request("", 50);
    long.insert_str(1, &" ".repeat(MAX_LINE_BYTES + 1 - long.len()));
    let lines = [
        request(&discs(MAX_OBSTACLES), 2000),
        request(&discs(MAX_OBSTACLES + 1), 2000),
        request(&polygon(MAX_VERTICES + 1), 2000),
        long,
        request("", 10_000),
        request("", 10_001),
    ];
    let input: String = lines.iter().map(|l| format!("{l}\n")).collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .arg("plan")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("rod-ig starts");
    let mut stdin = child.stdin.take().expect("stdin");
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let out = child.wait_with_output().expect("rod-ig exits");
    writer.join().expect("writer").expect("stdin written");
    assert!(out.status.success());
    let answers: Vec<Value> = String::from_utf8(out.stdout)
        .expect("UTF-8")
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON answer"))
        .collect();
    assert_eq!(answers.len(), lines.len(), "{answers:?}");
    let reason = |a: &Value| {
        a["reason"]
            .as_str()
            .or_else(|| a["error"].as_str())
            .unwrap_or("")
            .to_string()
    };
    assert!(!reason(&answers[0]).contains("accepted"), "{}", answers[0]);
    assert!(
        reason(&answers[1]).contains(&format!("at most {MAX_OBSTACLES}")),
        "{}",
        answers[1]
    );
    assert!(
        reason(&answers[2]).contains(&format!("at most {MAX_VERTICES}")),
        "{}",
        answers[2]
    );
    assert!(reason(&answers[3]).contains("bytes"), "{}", answers[3]);
    assert_eq!(answers[4]["success"], true, "{}", answers[4]);
    assert!(reason(&answers[5]).contains("deadline"), "{}", answers[5]);
}
