//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};

/// The public reference sets (`data/oracle/` of the repository: cases, inverse geometry,
/// near-relaxed rods; see its README), by file name.
#[allow(dead_code)] // not every test binary that includes this module reads the oracle
pub fn oracle_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/oracle")
        .join(name)
}

/// The numbers of a JSON array (panics with a clear message on anything else: test data).
#[allow(dead_code)] // not every test binary that includes this module reads JSON arrays
pub fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// The JSON values of a JSON-lines text, blank lines skipped (panics on a malformed line: test
/// data).
#[allow(dead_code)] // not every test binary that includes this module reads JSON lines
pub fn json_lines(text: &str) -> impl Iterator<Item = serde_json::Value> + '_ {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
}
