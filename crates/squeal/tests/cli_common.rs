//! Helpers shared by the CLI test files of issue 26 (the FE brake): run the
//! binary, and read what it printed.

use std::path::Path;
use std::process::{Command, Output};

/// Run `squeal` in `dir` with `args`.
pub fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

/// Its stdout, asserting success.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Its stdout as JSON, asserting success.
pub fn json(out: &Output) -> serde_json::Value {
    serde_json::from_str(&ok(out)).unwrap()
}

/// Its one-line error, asserting exit 2 and nothing on stdout.
pub fn refused(out: &Output) -> String {
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    assert!(out.stdout.is_empty());
    let e = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
    e
}

/// `(re, im)` of every eigenvalue of a `stability --json` document.
pub fn eigenvalues(v: &serde_json::Value) -> Vec<(f64, f64)> {
    v["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (e["re"].as_f64().unwrap(), e["im"].as_f64().unwrap()))
        .collect()
}
