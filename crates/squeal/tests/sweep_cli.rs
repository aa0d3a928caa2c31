//! `squeal sweep` and the mode shapes of `squeal stability` end to end.

use std::path::Path;
use std::process::{Command, Output};

fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

fn ok(dir: &Path, args: &[&str]) -> Output {
    let out = run(dir, args);
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

fn csv(path: &Path) -> (String, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

#[test]
fn sweep_hoffmann_writes_sweep_csv_and_finds_the_coalescence() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("sw");
    let j = json(&ok(
        d.path(),
        &[
            "sweep",
            "hoffmann",
            "--param",
            "mu=0.05:0.5:46",
            "--set",
            "c1=0",
            "--set",
            "c2=0",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ],
    ));
    let (header, rows) = csv(&out.join("sweep.csv"));
    assert_eq!(header, "mu,mode,growth_rate,freq_hz,damping_ratio");
    assert_eq!(rows.len(), 46 * 2, "two modes at 46 values");
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), 5);
        assert_eq!(r[1], ((k % 2) + 1).to_string());
        for v in r {
            assert!(v.parse::<f64>().unwrap().is_finite(), "{r:?}");
        }
    }
    assert_eq!(rows[0][0].parse::<f64>().unwrap(), 0.05);
    assert_eq!(rows[91][0].parse::<f64>().unwrap(), 0.5);
    assert!(out.join("sweep.png").is_file() && out.join("sweep.svg").is_file());
    // μ_c = ((k11 − k22)² + 4 k12²)/(4 k12 k3) = 0.25 for the defaults.
    let on = &j["onsets"].as_array().unwrap()[0];
    assert_eq!(on["coalescence"], true);
    assert_eq!(on["direction"], "destabilising");
    let v = on["value"].as_f64().unwrap();
    assert!((v - 0.25).abs() < 1e-6 * 0.25, "{v}");
    // `critical` agrees.
    let c = json(&ok(
        d.path(),
        &[
            "critical",
            "hoffmann",
            "--param",
            "mu=0.05:0.5",
            "--set",
            "c1=0",
            "--set",
            "c2=0",
            "--json",
        ],
    ));
    assert!((c["value"].as_f64().unwrap() - v).abs() < 1e-6 * v);
    // Running again replaces squeal's own folder.
    ok(
        d.path(),
        &[
            "sweep",
            "hoffmann",
            "--param",
            "mu=0.1:0.2:3",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(csv(&out.join("sweep.csv")).1.len(), 6);
}

#[test]
fn sweep_runs_on_every_built_in_model() {
    let d = tempfile::tempdir().unwrap();
    for (sc, param, modes) in [
        ("disc-pad", "V=1:10:4", 4),
        ("belt", "V=0.5:5:4", 1),
        ("hoffmann", "k3=5000:20000:4", 2),
        ("thesis-01", "N=500:3000:4", 4),
    ] {
        let out = d.path().join(sc);
        // thesis-01 starts from rest (V = 0): give the disc a speed to slide at.
        let mut args = vec![
            "sweep",
            sc,
            "--param",
            param,
            "--out",
            out.to_str().unwrap(),
        ];
        if sc == "thesis-01" {
            args.extend(["--set", "V=2"]);
        }
        ok(d.path(), &args);
        let name = param.split('=').next().unwrap();
        let (header, rows) = csv(&out.join("sweep.csv"));
        assert_eq!(
            header,
            format!("{name},mode,growth_rate,freq_hz,damping_ratio")
        );
        assert_eq!(rows.len(), 4 * modes, "{sc}");
    }
}

#[test]
fn bad_param_is_refused_naming_it_and_nothing_is_written() {
    let d = tempfile::tempdir().unwrap();
    for spec in [
        "nope=0:1:5",
        "mu=0.1:0.5",
        "mu=0.5:0.1:5",
        "mu=0.1:0.5:1",
        "mu=-1:0.5:5",
        "mu",
    ] {
        let out = d.path().join("never");
        let o = run(
            d.path(),
            &[
                "sweep",
                "hoffmann",
                "--param",
                spec,
                "--out",
                out.to_str().unwrap(),
            ],
        );
        assert_eq!(o.status.code(), Some(2), "{spec}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("--param") && err.contains(spec),
            "{spec}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!out.exists(), "{spec}: output written");
    }
}

#[test]
fn stability_reports_complex_mode_shapes() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("st");
    let j = json(&ok(
        d.path(),
        &["stability", "--json", "--out", out.to_str().unwrap()],
    ));
    assert!(j["shape_normalisation"]
        .as_str()
        .unwrap()
        .contains("largest"));
    let ev = j["eigenvalues"].as_array().unwrap();
    for e in ev {
        let shape = e["shape"].as_array().unwrap();
        assert_eq!(shape.len(), 4, "one entry per dof");
        let amps: Vec<f64> = shape
            .iter()
            .map(|s| s["amplitude"].as_f64().unwrap())
            .collect();
        assert!(amps.iter().all(|a| (0.0..=1.0).contains(a)));
        // The reference dof: amplitude exactly 1, phase 0.
        let r = shape
            .iter()
            .find(|s| s["amplitude"].as_f64() == Some(1.0))
            .unwrap();
        assert_eq!(r["phase_deg"].as_f64(), Some(0.0));
        // The dominant dof (by energy) has a large amplitude.
        let dom = shape.iter().find(|s| s["dof"] == e["dominant"]).unwrap();
        assert!(dom["amplitude"].as_f64().unwrap() > 0.0);
    }
    // Conjugate modes have conjugate shapes: same amplitudes, opposite phases
    // (the phase of a component below 1e-6 of the largest is round-off).
    let (a, b) = (&ev[0]["shape"], &ev[1]["shape"]);
    assert_eq!(ev[0]["re"], ev[1]["re"]);
    for i in 0..4 {
        assert!(
            (a[i]["amplitude"].as_f64().unwrap() - b[i]["amplitude"].as_f64().unwrap()).abs()
                < 1e-12
        );
        let (pa, pb) = (
            a[i]["phase_deg"].as_f64().unwrap(),
            b[i]["phase_deg"].as_f64().unwrap(),
        );
        assert!(
            (pa + pb).abs() < 1e-9 || (pa.abs() - 180.0).abs() < 1e-9,
            "{pa} {pb}"
        );
    }
    let (header, rows) = csv(&out.join("modes.csv"));
    assert_eq!(
        header,
        "mode,growth_rate,freq_hz,damping_ratio,dof,amplitude,phase_deg"
    );
    assert_eq!(rows.len(), 8 * 4);
    assert_eq!(rows[0][4], "x_d");
    assert_eq!(rows[0][0], "1");
    assert_eq!(rows[31][0], "8");
    // A folder of the user's is not replaced.
    let mine = d.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "keep").unwrap();
    let o = run(d.path(), &["stability", "--out", mine.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
        "keep"
    );
}
