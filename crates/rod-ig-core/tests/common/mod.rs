//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};

/// The project's `shared/` directory (paper, oracle): `$ROD_IG_SHARED` if set, else the first
/// `shared/` holding `oracle/` found walking up from this crate (in CI and in a fresh clone it
/// sits beside the repository). Panics with a clear message when absent: tests against the
/// oracle must fail, not pass vacuously, when their reference data is missing.
#[allow(dead_code)] // not every test binary that includes this module reads the oracle
pub fn shared_dir() -> PathBuf {
    if let Ok(p) = std::env::var("ROD_IG_SHARED") {
        let p = PathBuf::from(p);
        assert!(
            p.join("oracle").is_dir(),
            "ROD_IG_SHARED={} has no oracle/ directory",
            p.display()
        );
        return p;
    }
    let start = Path::new(env!("CARGO_MANIFEST_DIR"));
    start
        .ancestors()
        .map(|dir| dir.join("shared"))
        .find(|cand| cand.join("oracle").is_dir())
        .unwrap_or_else(|| {
            panic!(
                "shared oracle directory not found: set ROD_IG_SHARED or place `shared/oracle` \
                 beside the repository (searched upwards from {})",
                start.display()
            )
        })
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
