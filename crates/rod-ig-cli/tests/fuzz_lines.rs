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

const TEMPLATES: [(&str, &[&str]); 6] = [
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
        ],
    ),
    (
        "solve3d",
        &[
            "{\"target\": {\"position\": [#, #, #], \"quaternion\": [#, #, #, #]}, \"max_iterations\": #, \"tolerance\": #, \"deadline_ms\": 30}",
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
