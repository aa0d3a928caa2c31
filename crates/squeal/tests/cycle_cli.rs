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
        "V,period,amplitude_x,amplitude_v,max_multiplier,stable,events_stick,events_slip,events_reverse,events_separate,events_contact,point"
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

/// The `belt` scenario's branch starting at V = 0.2 m/s, where the cycle is
/// found by settling from a kick for over 23 s into stick-slip with a
/// continuous friction law (μ(0⁺) = μ_s). Its first stick used to end the
/// run in "endless stick-slip chatter" (`crates/squeal-core/tests/breakaway.rs`).
#[test]
fn belt_branch_from_slow_belt_settles_into_stick_slip() {
    let d = tempfile::tempdir().unwrap();
    let j = json_of(&squeal(
        d.path(),
        &[
            "branch",
            "belt",
            "--param",
            "V=0.2:0.46:2",
            "--out",
            "b",
            "--json",
        ],
    ));
    assert_eq!(j["failed"].as_array().unwrap().len(), 0, "{}", j["failed"]);
    let points = j["points"].as_array().unwrap();
    assert_eq!(points.len(), 2);
    // One stick and one slip per period, at the natural period 2π/100 s
    // (m = 1 kg, k = 10⁴ N/m) to within the friction's influence, 0.1 %.
    let natural = 2.0 * std::f64::consts::PI / 100.0;
    for p in points {
        assert_eq!(p["events_per_period"]["stick"], 1);
        assert_eq!(p["events_per_period"]["slip"], 1);
        let period = p["period"].as_f64().unwrap();
        assert!((period / natural - 1.0).abs() < 1e-3, "{period} s");
    }
    assert_eq!(points[0]["value"].as_f64(), Some(0.2), "{}", points[0]);
}

/// `squeal branch` on the belt with `μ(v) = 0.5 + 0.5 exp(−v²)`, m = k = N = 1.
fn gaussian_branch(dir: &Path, c: &str, range: &str, out: &str) -> serde_json::Value {
    let o = squeal(
        dir,
        &[
            "branch",
            "belt",
            "--set",
            "friction=stribeck",
            "--set",
            "mu_s=1",
            "--set",
            "mu_k=0.5",
            "--set",
            "v_s=1",
            "--set",
            "delta=2",
            "--set",
            "sigma=0",
            "--set",
            "m=1",
            "--set",
            "k=1",
            "--set",
            "N=1",
            "--set",
            c,
            "--param",
            range,
            "--out",
            out,
            "--json",
        ],
    );
    json_of(&o)
}

#[test]
fn branch_folds_and_meets_criticals_hopf_point() {
    let d = tempfile::tempdir().unwrap();
    // Subcritical Hopf (c = 0.2): the stable cycle folds near V = 1.4575 into
    // the unstable one that shrinks onto steady sliding at the Hopf speed.
    let doc = gaussian_branch(d.path(), "c=0.2", "V=1.2:2.0:5", "fold");
    let kinds: Vec<&str> = doc["bifurcations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["kind"].as_str().unwrap())
        .collect();
    assert!(
        kinds.contains(&"fold") && kinds.contains(&"grazing_sliding"),
        "{kinds:?}"
    );
    let csv = std::fs::read_to_string(d.path().join("fold/branch.csv")).unwrap();
    let folds: Vec<&str> = csv.lines().filter(|l| l.ends_with(",fold")).collect();
    assert_eq!(folds.len(), 1, "{csv}");
    let v_fold: f64 = folds[0].split(',').next().unwrap().parse().unwrap();
    assert!((1.45..1.47).contains(&v_fold), "{v_fold}");
    // V = 1.4 twice: the stable cycle and the unstable one.
    assert_eq!(csv.lines().filter(|l| l.starts_with("1.4e0,")).count(), 2);
    assert!(d.path().join("fold/branch.png").is_file());
    // The branch's end on steady sliding and critical's Hopf point agree.
    for (doc, what) in [
        (doc, "subcritical"),
        // Supercritical Hopf (c = 0.35, μ''' > 0 at V_H ≈ 1.0466): a small
        // smooth cycle below V_H.
        (
            gaussian_branch(d.path(), "c=0.35", "V=0.95:1.05:3", "super"),
            "supercritical",
        ),
    ] {
        let h = &doc["hopf"];
        let v_h = h["value"].as_f64().unwrap();
        let end = &h["branch_end"];
        let dv = end["value_difference"].as_f64().unwrap();
        let df = end["freq_difference_hz"].as_f64().unwrap();
        assert!(dv.abs() <= 1e-5 * v_h, "{what}: {dv}");
        // The linear frequency at the Hopf point: √(k/m)/2π.
        let f = 0.5 / std::f64::consts::PI;
        assert!(df.abs() <= 1e-6 * f, "{what}: {df}");
        assert!((h["freq_hz"].as_f64().unwrap() - f).abs() <= 1e-6 * f);
    }
}

/// The floating caliper's steady sliding grows at σ = 0.162 1/s, 7.2e-5 a
/// period of its 2.25 kHz mode: below every settling match the retries try,
/// a still-growing oscillation passes for settled and shooting fails. The
/// error says so and names the `--settle-tol` that works; with it, the
/// stable stick-slip orbit (one stick, one slip a period, 2250.34 Hz, below
/// the linear 2250.76 Hz) that a simulation grows into.
#[test]
fn a_very_slow_growth_is_named_with_the_settle_tol_that_resolves_it() {
    let d = tempfile::tempdir().unwrap();
    let out = squeal(d.path(), &["cycle", "floating-caliper"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("grows by only 7.2e-5 a period") && err.contains("try --settle-tol 7e-6"),
        "{err}"
    );
    let v = json_of(&squeal(
        d.path(),
        &[
            "cycle",
            "floating-caliper",
            "--settle-tol",
            "7e-6",
            "--json",
        ],
    ));
    let f = 1.0 / v["period"].as_f64().unwrap();
    assert!((f - 2250.337).abs() < 0.01, "{f} Hz");
    assert_eq!(v["stable"], true);
    assert_eq!(v["events_per_period"]["stick"], 1);
    assert_eq!(v["events_per_period"]["slip"], 1);
}
