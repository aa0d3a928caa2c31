//! `squeal stability`, `critical` and `map` end to end.

use std::path::Path;
use std::process::{Command, Output};

fn squeal_env(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_squeal"));
    c.current_dir(dir).args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("squeal runs")
}

fn squeal(dir: &Path, args: &[&str]) -> Output {
    let out = squeal_env(dir, args, &[]);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn json(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).expect("stdout is JSON only")
}

#[test]
fn stability_lists_all_eigenvalues_of_the_default_brake() {
    let d = tempfile::tempdir().unwrap();
    let j = json(&squeal(d.path(), &["stability", "--json"]));
    let ev = j["eigenvalues"].as_array().unwrap();
    assert_eq!(ev.len(), 8, "2n eigenvalues for 4 DOF");
    assert_eq!(j["stable"], false);
    // MODEL.md §5: pad tangential 20.75 kHz with σ ≈ +14.7 1/s is the least stable.
    let max = j["max_growth_rate"].as_f64().unwrap();
    assert!((max - 14.6667).abs() < 1e-3, "{max}");
    assert_eq!(ev[0]["dominant"], "x_p");
    assert!((ev[0]["freq_hz"].as_f64().unwrap() - 20751.0).abs() < 2.0);
    let rates: Vec<f64> = ev.iter().map(|e| e["re"].as_f64().unwrap()).collect();
    assert!(
        rates.windows(2).all(|w| w[0] >= w[1]),
        "sorted by growth rate"
    );
    let text = String::from_utf8_lossy(&squeal(d.path(), &["stability"]).stdout).to_string();
    assert!(text.contains("UNSTABLE") && text.contains("x_p"), "{text}");
    // No steady sliding: a clear input error.
    let out = squeal_env(d.path(), &["stability", "--set", "V=0"], &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("V = 0"));
}

#[test]
fn critical_speed_of_the_belt_matches_the_closed_form() {
    let d = tempfile::tempdir().unwrap();
    // belt built-in: thesis law (f0 = 0.1, f1 = 1/15, Uc = 50/3), c = 0.2, N = 100.
    let j = json(&squeal(
        d.path(),
        &["critical", "belt", "--param", "V=0:30", "--json"],
    ));
    let want = 50.0 / 3.0 * (1.0 - 0.2 / (100.0 * 0.1 / 15.0));
    let got = j["value"].as_f64().unwrap();
    assert!((got - want).abs() <= 1e-9 * want, "{got} vs {want}");
    assert_eq!(j["param"], "V");
    // No crossing in range: value null, exit 0.
    let j = json(&squeal(
        d.path(),
        &["critical", "belt", "--param", "V=12:30", "--json"],
    ));
    assert!(j["value"].is_null());
    let out = squeal_env(d.path(), &["critical", "--param", "bogus=0:1"], &[]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn map_is_identical_single_and_multi_threaded() {
    let d = tempfile::tempdir().unwrap();
    let args = |out: &'static str| {
        vec![
            "map",
            "--x",
            "V=0.5:20:41",
            "--y",
            "N=100:3000:31",
            "--log-y",
            "--out",
            out,
        ]
    };
    let one = squeal_env(d.path(), &args("one"), &[("RAYON_NUM_THREADS", "1")]);
    assert!(
        one.status.success(),
        "{}",
        String::from_utf8_lossy(&one.stderr)
    );
    let two = squeal_env(d.path(), &args("two"), &[("RAYON_NUM_THREADS", "2")]);
    assert!(two.status.success());
    let a = std::fs::read_to_string(d.path().join("one/map.csv")).unwrap();
    let b = std::fs::read_to_string(d.path().join("two/map.csv")).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.lines().next().unwrap(), "V,N,max_growth_rate,freq_hz");
    assert_eq!(a.lines().count(), 1 + 41 * 31);
    assert!(d.path().join("one/map.png").is_file() && d.path().join("one/map.svg").is_file());
    // Above Uc every point is stable (conclusion 3); below, at N = 500, unstable.
    for line in a.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        if v[0] > 50.0 / 3.0 {
            assert!(v[2] < 0.0, "{line}");
        }
    }
}

#[test]
fn transient_map_classifies_by_simulation() {
    let d = tempfile::tempdir().unwrap();
    let out = squeal(
        d.path(),
        &[
            "map",
            "belt",
            "--x",
            "V=2:16:3",
            "--y",
            "c=0.05:1:2",
            "--transient",
            "--duration",
            "4",
            "--out",
            "t",
            "--json",
        ],
    );
    let j = json(&out);
    assert_eq!(j["points"], 6);
    let csv = std::fs::read_to_string(d.path().join("t/map.csv")).unwrap();
    assert_eq!(
        csv.lines().next().unwrap(),
        "V,c,max_growth_rate,freq_hz,outcome,rms_tangential,stick_fraction,t_end,agree,spl_dba"
    );
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let sigma: f64 = f[2].parse().unwrap();
        let outcome = f[4];
        // Linearly stable points decay; unstable ones end in stick-slip.
        if sigma < -0.05 {
            assert_eq!(outcome, "decays", "{line}");
        } else if sigma > 0.05 {
            assert!(outcome == "stick-slip" || outcome == "grows", "{line}");
        }
        // The agree column is never empty.
        assert!(["yes", "no", "n/a"].contains(&f[8]), "{line}");
    }
    // Drawn as outcome classes with a legend, not a colour scale.
    let svg = std::fs::read_to_string(d.path().join("t/transient.svg")).unwrap();
    for class in [
        "decays",
        "grows",
        "stick-slip",
        "steady",
        "out-of-range",
        "failed",
        "too-short",
    ] {
        assert!(svg.contains(class), "legend lacks {class}");
    }
    assert!(!svg.contains("log10 RMS"));
}

#[test]
fn hoffmann_critical_friction_matches_the_coalescence() {
    let d = tempfile::tempdir().unwrap();
    // Undamped: the two frequencies coalesce at μ_c = ((k11 − k22)² + 4 k12²)/(4 k12 k3)
    // with the built-in's k11 = 1e4, k12 = 2e3, k22 = 1.2e4, k3 = 1e4: μ_c = 0.25.
    let j = json(&squeal(
        d.path(),
        &[
            "critical",
            "hoffmann",
            "--param",
            "mu=0.01:1",
            "--set",
            "c1=0",
            "--set",
            "c2=0",
            "--json",
        ],
    ));
    let want = ((1e4f64 - 1.2e4).powi(2) + 4.0 * 2e3f64.powi(2)) / (4.0 * 2e3 * 1e4);
    let got = j["value"].as_f64().unwrap();
    assert!((got - want).abs() <= 1e-9 * want, "{got} vs {want}");
    assert_eq!(j["from_neutral"], true);
    // The built-in is above it: it flutters.
    let s = json(&squeal(d.path(), &["stability", "hoffmann", "--json"]));
    assert_eq!(s["stable"], false);
}

#[test]
fn map_and_critical_refuse_bad_ranges_with_exit_code_2() {
    let d = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["map", "--x", "Q=0:1:10", "--y", "N=1:2:3", "--out", "m"],
            "Q",
        ),
        (
            &["map", "--x", "V=2:1:10", "--y", "N=1:2:3", "--out", "m"],
            "V=2:1:10",
        ),
        (
            &["map", "--x", "V=1:2:1", "--y", "N=1:2:3", "--out", "m"],
            "V=1:2:1",
        ),
        (
            &[
                "map", "--x", "V=0:2:5", "--y", "N=1:2:3", "--log-x", "--out", "m",
            ],
            "LO > 0",
        ),
        (
            &["map", "--x", "V=1:2:5", "--y", "V=1:2:3", "--out", "m"],
            "both vary V",
        ),
        (
            &["map", "--x", "V=1:2", "--y", "N=1:2:3", "--out", "m"],
            "NAME=LO:HI:N",
        ),
        (&["critical", "--param", "V=3:1"], "V=3:1"),
        (&["critical", "--param", "V"], "NAME=LO:HI"),
    ];
    for (args, needle) in cases {
        let out = squeal_env(d.path(), args, &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: '{needle}' not in {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!d.path().join("m").exists());
    }
}

/// "What would stop it": one-parameter changes that silence the default brake,
/// checked against the one-DOF criterion c_px + N·μ'(V) = 0 of its pad mode.
#[test]
fn stability_names_what_would_stop_the_squeal() {
    let d = tempfile::tempdir().unwrap();
    let j = json(&squeal(d.path(), &["stability", "--json"]));
    let levers = j["levers"].as_array().unwrap();
    let find = |p: &str| {
        levers
            .iter()
            .find(|l| l["param"] == p)
            .unwrap_or_else(|| panic!("no lever {p}: {levers:?}"))
    };
    let (f0, f1, uc, c_px) = (0.1, 1.0 / 15.0, 50.0 / 3.0, 0.2);
    // Raise V to V_H = Uc (1 − c_px/(N f0 f1)).
    let v_h = uc * (1.0 - c_px / (500.0 * f0 * f1));
    let v = find("V")["to"].as_f64().unwrap();
    assert!((v - v_h).abs() <= 1e-7 * v_h, "{v} vs {v_h}");
    // Lower N to c_px / (f0 f1 (1 − V/Uc)): the one-DOF value, which the coupled
    // eigenvalues shift by the disc–pad friction coupling (measured 1.3e-4).
    let n_c = c_px / (f0 * f1 * (1.0 - 1.0 / uc));
    let n = find("N")["to"].as_f64().unwrap();
    assert!((n - n_c).abs() <= 1e-3 * n_c, "{n} vs {n_c}");
    // Damping of one part alone cannot silence both the disc and the pad.
    assert!(
        levers
            .iter()
            .all(|l| l["param"] != "c_dx" && l["param"] != "c_px"),
        "{levers:?}"
    );
    let text = String::from_utf8_lossy(&squeal(d.path(), &["stability"]).stdout).to_string();
    assert!(
        text.contains("what would stop it") && text.contains("raise V"),
        "{text}"
    );
}

#[test]
fn a_tiny_positive_growth_rate_is_unstable_and_round_off_is_neutral() {
    let d = tempfile::tempdir().unwrap();
    // Just past the Hopf point in N: σ = +1.3e-4 1/s, |λ| = 1.3e5 1/s.
    let j = json(&squeal(
        d.path(),
        &["stability", "--json", "--set", "N=31.91905"],
    ));
    let s = j["max_growth_rate"].as_f64().unwrap();
    assert!((s - 1.302e-4).abs() < 1e-6, "{s}");
    assert_eq!(j["stable"], false);
    assert_eq!(j["neutral"], false);
    assert_eq!(j["verdict"], "unstable");
    // The same σ reached through f1 gives the same answer.
    let j = json(&squeal(
        d.path(),
        &["stability", "--json", "--set", "f1=4.255874e-3"],
    ));
    assert_eq!(j["stable"], false);
    // Hoffmann without damping below its coalescence: purely imaginary
    // eigenvalues, σ = 0 within round-off: neutral, not stable, in words.
    let args = [
        "stability",
        "hoffmann",
        "--set",
        "c1=0",
        "--set",
        "c2=0",
        "--set",
        "mu=0.2",
    ];
    let mut with_json = args.to_vec();
    with_json.push("--json");
    let j = json(&squeal(d.path(), &with_json));
    assert_eq!(j["stable"], false);
    assert_eq!(j["neutral"], true);
    assert_eq!(j["verdict"], "neutral");
    for e in j["eigenvalues"].as_array().unwrap() {
        assert_eq!(e["neutral"], true, "{e}");
        assert_eq!(e["growing"], false, "{e}");
    }
    let text = String::from_utf8_lossy(&squeal(d.path(), &args).stdout).into_owned();
    assert!(text.contains("NEUTRAL"), "{text}");
    // A damped brake is stable.
    let j = json(&squeal(
        d.path(),
        &["stability", "--json", "--set", "c_dx=5", "--set", "c_px=5"],
    ));
    assert_eq!(j["stable"], true);
    assert_eq!(j["verdict"], "stable");
}

#[test]
fn levers_are_the_critical_values() {
    let d = tempfile::tempdir().unwrap();
    let j = json(&squeal(d.path(), &["stability", "--json"]));
    let levers = j["levers"].as_array().unwrap();
    for (p, range) in [
        ("N", "N=1:500"),
        ("V", "V=1:100"),
        ("f0", "f0=0.0001:0.1"),
        ("f1", "f1=0.00001:0.0666"),
        ("Uc", "Uc=0.1:16.6"),
    ] {
        let lever = levers
            .iter()
            .find(|l| l["param"] == p)
            .unwrap_or_else(|| panic!("no lever {p}: {levers:?}"))["to"]
            .as_f64()
            .unwrap();
        let c = json(&squeal(d.path(), &["critical", "--param", range, "--json"]));
        let crit = c["value"].as_f64().unwrap();
        assert!(
            (lever - crit).abs() <= 1e-9 * crit.abs(),
            "{p}: lever {lever:.15e} vs critical {crit:.15e}"
        );
        // On the true boundary: the growth rate changes sign across it.
        let at = |v: f64| {
            let set = format!("{p}={v:e}");
            json(&squeal(d.path(), &["stability", "--json", "--set", &set]))["max_growth_rate"]
                .as_f64()
                .unwrap()
        };
        let (below, above) = (at(crit * (1.0 - 1e-8)), at(crit * (1.0 + 1e-8)));
        assert!(below * above < 0.0, "{p}: σ {below:e} / {above:e}");
    }
}
