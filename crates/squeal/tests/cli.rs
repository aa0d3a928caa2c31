//! The `squeal` binary end to end: runs, outputs, bad input, determinism.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn read(p: PathBuf) -> String {
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn without_timing(summary: &str) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(summary).unwrap();
    v.as_object_mut().unwrap().remove("timing");
    v
}

#[test]
fn default_run_writes_the_documented_outputs() {
    let d = tmp();
    let out = squeal(d.path(), &["simulate", "--duration", "0.02"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dir = d.path().join("out/disc-pad");
    let series = read(dir.join("series.csv"));
    let mut lines = series.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t,x_d,x_p,y_d,y_p,vx_d,vx_p,vy_d,vy_p,F_y,F_t,v_rel,mode"
    );
    // 0.02 s at 200 kHz: samples at 0, 5 µs, …, 0.02 s.
    assert_eq!(series.lines().count(), 1 + 4001);
    let second: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(second.len(), 13);
    assert_eq!(second[0], 0.0);
    assert_eq!(second[11], 1.0, "v_rel = V at rest");
    assert_eq!(
        read(dir.join("events.csv")).lines().next().unwrap(),
        "t,kind,contact"
    );
    let summary: serde_json::Value = serde_json::from_str(&read(dir.join("summary.json"))).unwrap();
    for key in [
        "scenario",
        "integrator",
        "events",
        "stick_fraction",
        "rms",
        "timing",
    ] {
        assert!(summary.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(summary["scenario"]["params"]["k_dx"], 1.0e9);
    assert_eq!(summary["scenario"]["friction"]["law"], "thesis");
    assert!(summary["integrator"]["accepted_steps"].as_u64().unwrap() > 1000);
    assert!(summary["timing"]["integrate_s"].as_f64().unwrap() >= 0.0);
    for v in ["vx_d", "vx_p", "vy_d", "vy_p"] {
        assert!(summary["rms"][v].as_f64().unwrap() > 0.0, "rms.{v}");
    }
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("disc-pad") && text.contains("events:"),
        "{text}"
    );
    // No staging folder left behind.
    let leftovers: Vec<_> = std::fs::read_dir(d.path().join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

#[test]
fn belt_run_has_stick_slip() {
    let d = tmp();
    let out = squeal(
        d.path(),
        &["simulate", "belt-coulomb", "--out", "b", "--json"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is only JSON");
    assert!(json["events"]["stick"].as_u64().unwrap() >= 5);
    assert!(json["events"]["slip"].as_u64().unwrap() >= 5);
    let sf = json["stick_fraction"].as_f64().unwrap();
    // Exact cycle of the belt-coulomb scenario: stick 2(x_s−x_k)/V = 0.02 s of a
    // period 0.02 + (π + 2 atan2(V/ω, x_s−x_k))/ω = 0.0671 s.
    let omega = 100.0f64;
    let t_slip = (std::f64::consts::PI + 2.0 * (0.1 / omega).atan2(0.001)) / omega;
    let want = 0.02 / (0.02 + t_slip);
    assert!(
        (sf - want).abs() < 0.03,
        "stick fraction {sf} vs {want} (includes the start-up transient)"
    );
    let series = read(d.path().join("b/series.csv"));
    assert_eq!(series.lines().next().unwrap(), "t,x,v,F_t,v_rel,mode");
    assert_eq!(series.lines().count(), 1 + 1001);
    assert!(
        series.lines().skip(1).any(|l| l.ends_with(",1")),
        "stick samples flagged 1"
    );
}

/// Every bad input: one line on stderr naming key and value, exit 2, no output.
#[test]
fn bad_input_is_refused_with_exit_code_2() {
    let d = tmp();
    std::fs::write(
        d.path().join("malformed.toml"),
        "model = \"disc-pad\"\n[params\nm_d = 1",
    )
    .unwrap();
    std::fs::write(
        d.path().join("unknown.toml"),
        "model = \"disc-pad\"\n[params]\nm_dd = 1.0\n",
    )
    .unwrap();
    std::fs::write(d.path().join("neg.toml"), "[params]\nk_py = -4.0\n").unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (&["--set", "bogus=1"], &["bogus"]),
        (&["--set", "m_d=0"], &["m_d", "0"]),
        (&["--set", "m_p=-0.1"], &["m_p", "-0.1"]),
        (&["--set", "k_dx=-1e9"], &["k_dx"]),
        (&["--set", "c_dx=-1"], &["c_dx", "-1"]),
        (
            &["--set", "friction=coulomb", "--set", "mu_k=0.5"],
            &["mu_s", "mu_k"],
        ),
        (&["--set", "friction=glue"], &["friction", "glue"]),
        (&["--set", "N=nan"], &["N", "NaN"]),
        (&["--set", "k_dy=inf"], &["k_dy", "inf"]),
        (&["--set", "V=abc"], &["V", "abc"]),
        (&["--set", "initial=moving"], &["initial", "moving"]),
        (&["--set", "rtol=0"], &["rtol"]),
        (&["--set", "rtol=1"], &["rtol"]),
        (&["--set", "sample_rate=0"], &["sample_rate"]),
        (&["--set", "sample_rate=-5"], &["sample_rate"]),
        (&["--set", "x_q0=1"], &["x_q0"]),
        (&["--set", "noequals"], &["noequals"]),
        (&["--duration", "0"], &["duration"]),
        (&["--duration", "-1"], &["duration"]),
        (&["--duration", "nan"], &["duration"]),
        (&["missing.toml"], &["missing.toml"]),
        (&["no-such-scenario"], &["no-such-scenario"]),
        (&["malformed.toml"], &["malformed.toml"]),
        (&["unknown.toml"], &["unknown.toml", "m_dd"]),
        (&["neg.toml"], &["neg.toml", "k_py"]),
        (
            &["--set", "alpha=-1e6", "--set", "initial=equilibrium"],
            &["alpha"],
        ),
    ];
    for (args, needles) in cases {
        let mut full = vec!["simulate", "--out", "bad"];
        full.extend_from_slice(args);
        let out = squeal(d.path(), &full);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(
            err.trim().lines().count(),
            1,
            "{args:?}: one line, got {err}"
        );
        for n in *needles {
            assert!(err.contains(n), "{args:?}: '{n}' not in {err}");
        }
        assert!(!d.path().join("bad").exists(), "{args:?} left output");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn numerical_failure_exits_1_with_the_time() {
    let d = tmp();
    let out = squeal(
        d.path(),
        &[
            "simulate",
            "--out",
            "x",
            "--set",
            "h_max=1e-30",
            "--duration",
            "1e-3",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("t = ") && err.contains("underflow"), "{err}");
    assert!(!d.path().join("x").exists());
}

#[test]
fn runs_are_byte_identical() {
    let d = tmp();
    for dir in ["a", "b"] {
        let out = squeal(
            d.path(),
            &[
                "simulate",
                "--duration",
                "0.01",
                "--out",
                dir,
                "--format",
                "csv,npy",
            ],
        );
        assert!(out.status.success());
    }
    for f in ["series.csv", "events.csv", "series.npy"] {
        let a = std::fs::read(d.path().join("a").join(f)).unwrap();
        let b = std::fs::read(d.path().join("b").join(f)).unwrap();
        assert!(a == b, "{f} differs");
    }
    // summary.json differs only in its wall-clock timing.
    assert_eq!(
        without_timing(&read(d.path().join("a/summary.json"))),
        without_timing(&read(d.path().join("b/summary.json")))
    );
    // The .npy holds rows × 13 float64 after a 64-byte-aligned header.
    let npy = std::fs::read(d.path().join("a/series.npy")).unwrap();
    assert_eq!(&npy[..6], b"\x93NUMPY");
    let hlen = u16::from_le_bytes([npy[8], npy[9]]) as usize;
    assert_eq!((10 + hlen) % 64, 0);
    assert_eq!(npy.len() - 10 - hlen, 2001 * 13 * 8);
}

#[test]
fn shown_scenario_reproduces_the_default_run() {
    let d = tmp();
    let show = squeal(d.path(), &["scenario", "show", "disc-pad"]);
    assert!(show.status.success());
    std::fs::write(d.path().join("f.toml"), &show.stdout).unwrap();
    let text = String::from_utf8_lossy(&show.stdout);
    assert!(
        text.contains("k_dx = 1000000000.0") && text.contains("# N/m"),
        "documented: {text}"
    );
    // The equations live in the repository, and the shown file says where.
    assert!(text.contains("docs/physics.md"), "{text}");
    let physics = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/physics.md");
    let doc = std::fs::read_to_string(&physics).unwrap();
    for must in [
        "F_y = k_py",
        "v = V + ẋ_d − ẋ_p",
        "F_f = α·F_t·y_d",
        "μ_s·F_y / k_px",
        "**reconstruction**",
    ] {
        assert!(doc.contains(must), "docs/physics.md lacks {must}");
    }
    for (args, dir) in [
        (vec!["simulate", "--out", "a"], "a"),
        (vec!["simulate", "f.toml", "--out", "b"], "b"),
    ] {
        let mut args = args;
        args.extend(["--duration", "0.01"]);
        let out = squeal(d.path(), &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let _ = dir;
    }
    assert_eq!(
        read(d.path().join("a/series.csv")),
        read(d.path().join("b/series.csv"))
    );
    assert_eq!(
        read(d.path().join("a/events.csv")),
        read(d.path().join("b/events.csv"))
    );
    assert_eq!(
        without_timing(&read(d.path().join("a/summary.json"))),
        without_timing(&read(d.path().join("b/summary.json")))
    );
}

#[test]
fn overrides_reach_the_run() {
    let d = tmp();
    let out = squeal(
        d.path(),
        &[
            "simulate",
            "--json",
            "--out",
            "o",
            "--duration",
            "0.005",
            "--set",
            "N=2000",
            "--set",
            "c_dx=2.5",
            "--set",
            "alpha=-10",
            "--set",
            "friction=stribeck",
            "--set",
            "mu_k=0.05",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let sc = &j["scenario"];
    assert_eq!(sc["params"]["N"], 2000.0);
    assert_eq!(sc["params"]["c_dx"], 2.5);
    assert_eq!(sc["params"]["alpha"], -10.0);
    assert_eq!(sc["friction"]["law"], "stribeck");
    assert_eq!(sc["friction"]["mu_k"], 0.05);
    assert_eq!(sc["friction"]["mu_s"], 0.1);
}

/// `--out` never replaces what squeal did not write.
#[test]
fn output_folder_guards_user_data() {
    let d = tmp();
    std::fs::create_dir(d.path().join("mine")).unwrap();
    std::fs::write(d.path().join("mine/thesis.tex"), "precious").unwrap();
    std::fs::write(d.path().join("afile"), "precious").unwrap();
    for out in ["mine", "afile", "."] {
        let o = squeal(d.path(), &["simulate", "--duration", "0.001", "--out", out]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--out {out}: {err}");
        assert!(err.contains("--out"), "{err}");
    }
    assert_eq!(
        std::fs::read_to_string(d.path().join("mine/thesis.tex")).unwrap(),
        "precious"
    );
    assert_eq!(
        std::fs::read_to_string(d.path().join("afile")).unwrap(),
        "precious"
    );
    // A folder squeal wrote is replaced whole by the next run.
    for dur in ["0.002", "0.001"] {
        let o = squeal(
            d.path(),
            &["simulate", "--duration", dur, "--out", "run", "--no-plots"],
        );
        assert!(o.status.success());
    }
    let series = read(d.path().join("run/series.csv"));
    assert_eq!(series.lines().count(), 1 + 201);
}

/// A missing required flag is named on the one line of the error.
#[test]
fn missing_required_flags_are_named() {
    let d = tmp();
    let out = squeal(d.path(), &["branch", "belt"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--param <NAME=LO:HI:N>") && err.contains("--out <OUT>"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
}
