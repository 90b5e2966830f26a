//! Running the built `rod-ig` binary from the integration tests.

use serde_json::Value;
use std::io::Write;
use std::process::{Command, Stdio};

/// Runs `rod-ig args` on `stdin`: its JSON output lines (the process must exit 0).
pub fn run(args: &[&str], stdin: &str) -> Vec<Value> {
    run_with_stderr(args, stdin).0
}

/// Runs `rod-ig args` on `stdin`: its JSON output lines and its stderr.
pub fn run_with_stderr(args: &[&str], stdin: &str) -> (Vec<Value>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rod-ig"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("rod-ig starts");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(stdin.as_bytes())
        .expect("write stdin");
    let out = child.wait_with_output().expect("rod-ig exits");
    assert!(out.status.success(), "exit status {:?}", out.status);
    let lines = String::from_utf8(out.stdout)
        .expect("UTF-8 output")
        .lines()
        .map(|l| serde_json::from_str(l).expect("each output line is JSON"))
        .collect();
    (lines, String::from_utf8(out.stderr).expect("UTF-8 stderr"))
}
