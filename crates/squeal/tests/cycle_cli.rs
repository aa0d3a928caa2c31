//! `squeal cycle` and `squeal branch` end to end: JSON keys, files, bad input.

use std::path::Path;
use std::process::{Command, Output};

fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

fn json_of(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn coulomb_belt_cycle_json_and_files() {
    let d = tempfile::tempdir().unwrap();
    let out = squeal(d.path(), &["cycle", "belt-coulomb", "--json", "--out", "c"]);
    let v = json_of(&out);
    // The exact Coulomb cycle of the built-in (m = 1, k = 1e4, N = 100,
    // V = 0.1, μ_s = 0.4, μ_k = 0.3; tests/cycle.rs derives it).
    let (omega, xi, v_belt) = (100.0f64, 0.004f64 - 0.003, 0.1f64);
    let want =
        2.0 * xi / v_belt + (std::f64::consts::PI + 2.0 * (v_belt / omega).atan2(xi)) / omega;
    let period = v["period"].as_f64().unwrap();
    assert!((period - want).abs() <= 1e-8 * want, "{period} vs {want}");
    let m = v["multipliers"].as_array().unwrap();
    assert_eq!(m.len(), 2);
    for key in ["re", "im", "abs"] {
        assert!(m[0][key].is_number(), "{key}");
    }
    assert!(m[0]["abs"].as_f64() >= m[1]["abs"].as_f64());
    assert!(v["stable"].as_bool().unwrap());
    assert!(v["amplitude"]["x"].as_f64().unwrap() > 0.0);
    assert!(v["amplitude"]["v"].as_f64().unwrap() > 0.0);
    assert_eq!(v["events_per_period"]["stick"], 1);
    assert_eq!(v["events_per_period"]["slip"], 1);
    assert_eq!(v["events_per_period"]["reverse"], 0);
    assert!(v["residual"].as_f64().unwrap() < 1e-6);
    let orbit = std::fs::read_to_string(d.path().join("c/orbit.csv")).unwrap();
    let header = orbit.lines().next().unwrap();
    assert_eq!(header, "t,x,v,F_t,v_rel,mode,event");
    assert_eq!(orbit.lines().filter(|l| l.ends_with(",stick")).count(), 1);
    assert_eq!(orbit.lines().filter(|l| l.ends_with(",slip")).count(), 1);
    for f in ["cycle.png", "cycle_phase.png", "summary.json"] {
        assert!(d.path().join("c").join(f).is_file(), "{f}");
    }
}

#[test]
fn bad_cycle_input_exits_2_and_writes_nothing() {
    let d = tempfile::tempdir().unwrap();
    for args in [
        vec!["cycle", "belt", "--section", "nope", "--out", "o"],
        vec!["cycle", "belt", "--section", "v=abc", "--out", "o"],
        vec!["cycle", "belt", "--settle-time", "-1", "--out", "o"],
        vec!["cycle", "belt", "--set", "m=-1", "--out", "o"],
    ] {
        let out = squeal(d.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!d.path().join("o").exists());
    }
}

#[test]
fn no_cycle_is_a_clear_error() {
    // Heavy damping: the belt settles on steady sliding, there is no cycle.
    let d = tempfile::tempdir().unwrap();
    let out = squeal(
        d.path(),
        &["cycle", "belt", "--set", "c=1000", "--settle-time", "5"],
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no periodic orbit"), "{err}");
}

#[test]
fn coulomb_belt_branch_over_v_is_exact() {
    // Stick-slip for V < ω(x_s − x_k)… and beyond: the exact period and
    // amplitude R = √((x_s − x_k)² + (V/ω)²) at every point that sticks.
    let d = tempfile::tempdir().unwrap();
    let out = squeal(
        d.path(),
        &[
            "branch",
            "belt-coulomb",
            "--param",
            "V=0.02:0.09:8",
            "--out",
            "b",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(d.path().join("b/branch.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "V,period,amplitude_x,amplitude_v,max_multiplier,stable,events_stick,events_slip,events_reverse,events_separate,events_contact"
    );
    let (omega, xi) = (100.0f64, 0.001f64);
    let mut rows = 0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let v: f64 = f[0].parse().unwrap();
        let period: f64 = f[1].parse().unwrap();
        let amp_x: f64 = f[2].parse().unwrap();
        let phi = (v / omega).atan2(xi);
        let want = 2.0 * xi / v + (std::f64::consts::PI + 2.0 * phi) / omega;
        let r = (xi * xi + (v / omega).powi(2)).sqrt();
        assert!(
            (period - want).abs() <= 1e-6 * want,
            "V = {v}: {period} vs {want}"
        );
        assert!((amp_x - r).abs() <= 1e-2 * r, "V = {v}: {amp_x} vs {r}");
        assert_eq!(f[5], "true");
        assert_eq!((f[6], f[7]), ("1", "1"));
        rows += 1;
    }
    assert_eq!(rows, 8);
    assert!(d.path().join("b/branch.png").is_file());
}
