//! How loud (issue 28 §4): the equivalent radiated power and sound pressure
//! levels of a run, against hand-computed values for a sine, the defaults
//! of the disc–pad, and the outputs that carry them.

use crate::cli_common::{json, ok, refused, squeal};
use serde_json::Value;
use std::f64::consts::{PI, TAU};

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// One undamped dof of 1 kg ringing at 2 kHz from y(0) = 1 µm, radiating
/// from 0.05 m² to a listener 2 m away: v(t) = −aω sin ωt exactly, so over
/// the window's samples ⟨v²⟩ is known without squeal; W = ρc·A·⟨v²⟩,
/// p² = ρc·W/(4πr²) (or 2πr² in a half-space), and at 2 kHz the
/// A-weighting is +1.20 dB (IEC 61672-1).
#[test]
fn a_ringing_piston_by_hand() {
    let d = tempfile::tempdir().unwrap();
    let (fr, a, area, r) = (2000.0, 1e-6, 0.05, 2.0);
    let w = TAU * fr;
    let text = format!(
        "name = \"piston\"\nmodel = \"lumped\"\nduration = 0.2\nsample_rate = 100000.0\ndofs = [\"y\"]\n\
         [masses]\ny = 1.0\n[[spring]]\nname = \"s\"\non = {{ y = 1.0 }}\nk = {:?}\n\
         [offsets]\ny0 = {a:?}\n[radiation]\ndistance_m = {r:?}\n[radiation.area_m2]\ny = {area:?}\n",
        w * w
    );
    std::fs::write(d.path().join("piston.toml"), text).unwrap();
    let mut levels = Vec::new();
    for space in ["free", "half"] {
        let set = format!("radiation.space={space}");
        let out = squeal(
            d.path(),
            &[
                "simulate",
                "piston.toml",
                "--json",
                "--no-plots",
                "--out",
                space,
                "--set",
                &set,
            ],
        );
        let v = json(&out);
        let rad = &v["radiation"];
        let (t0, t1) = (f(&rad["t_start"]), f(&rad["t_end"]));
        // ⟨v²⟩ over the window's samples (t = k/fs), from the exact solution.
        let fs = 100_000.0;
        let (k0, k1) = ((t0 * fs).round() as i64, (t1 * fs).round() as i64);
        let ms: f64 = (k0..=k1)
            .map(|k| (a * w * (w * k as f64 / fs).sin()).powi(2))
            .sum::<f64>()
            / (k1 - k0 + 1) as f64;
        let rho_c = 1.204 * 343.2;
        let erp = rho_c * area * ms;
        assert!(
            (f(&rad["erp_w"]) / erp - 1.0).abs() < 1e-5,
            "ERP {} vs {erp}",
            rad["erp_w"]
        );
        assert!((f(&rad["erp_db"]) - 10.0 * (erp / 1e-12).log10()).abs() < 1e-4);
        let omega = if space == "free" { 4.0 * PI } else { 2.0 * PI };
        let p2 = rho_c * erp / (omega * r * r);
        let spl = 10.0 * (p2 / 4e-10).log10();
        assert!(
            (f(&rad["spl_db"]) - spl).abs() < 1e-4,
            "SPL {} vs {spl}",
            rad["spl_db"]
        );
        // The one line sits at 2 kHz (leakage spreads it over ±50 Hz, where
        // A changes by < 0.02 dB).
        let dba = f(&rad["spl_dba"]) - f(&rad["spl_db"]);
        assert!((dba - 1.20).abs() < 0.03, "A(2 kHz) through the run: {dba}");
        assert_eq!(rad["distance_m"], 2.0);
        assert_eq!(rad["area_m2"], 0.05);
        assert_eq!(rad["space"], space);
        assert_eq!(rad["surfaces"][0]["dof"], "y");
        assert!(rad["assumptions"]
            .as_str()
            .unwrap()
            .contains("radiation efficiency 1"));
        levels.push(f(&rad["spl_db"]));
    }
    // A half-space doubles the intensity: +3.01 dB.
    assert!((levels[1] - levels[0] - 10.0 * 2f64.log10()).abs() < 1e-9);
}

/// The disc–pad radiates from its disc faces by default; its squeal is the
/// pad's in-plane mode, which the output says the levels do not include;
/// without a surface the levels are null with the reason; the terminal
/// carries the same numbers.
#[test]
fn the_disc_pad_radiates_from_its_disc_and_says_what_it_leaves_out() {
    let d = tempfile::tempdir().unwrap();
    let v = json(&squeal(
        d.path(),
        &[
            "simulate",
            "--duration",
            "0.2",
            "--json",
            "--no-plots",
            "--out",
            "a",
        ],
    ));
    let rad = &v["radiation"];
    assert!((f(&rad["area_m2"]) - 2.0 * PI * (0.14f64.powi(2) - 0.08f64.powi(2))).abs() < 1e-12);
    assert_eq!(rad["surfaces"][0]["velocity"], "vy_d");
    assert_eq!(v["squeal"]["coordinate"], "x_p");
    assert_eq!(rad["squeal_on_surface"], false);
    assert!(rad["note"].as_str().unwrap().contains("x_p"));
    assert!(f(&rad["erp_db"]) > 80.0, "{}", rad["erp_db"]);
    let text = ok(&squeal(
        d.path(),
        &["simulate", "--duration", "0.2", "--no-plots", "--out", "b"],
    ));
    let line = text.lines().find(|l| l.starts_with("sound: ")).unwrap();
    assert!(
        line.contains(&format!("{:.1} dB(A)", f(&rad["spl_dba"]))),
        "{line}"
    );
    assert!(text.contains("not a radiating surface"), "{text}");
    // No surface: null levels with a reason, and the terminal says so.
    let v = json(&squeal(
        d.path(),
        &[
            "simulate",
            "--duration",
            "0.05",
            "--json",
            "--no-plots",
            "--out",
            "c",
            "--set",
            "radiation.area_m2.y_d=0",
        ],
    ));
    assert!(v["radiation"]["erp_w"].is_null() && v["radiation"]["spl_dba"].is_null());
    assert!(v["radiation"]["reason"]
        .as_str()
        .unwrap()
        .contains("no radiating surface"));
    // Bad keys and values: one line naming them, exit 2.
    let e = refused(&squeal(
        d.path(),
        &["simulate", "--out", "e", "--set", "radiation.area_m2.q=1"],
    ));
    assert!(
        e.contains("radiation.area_m2.q") && e.contains("not a dof"),
        "{e}"
    );
    let e = refused(&squeal(
        d.path(),
        &["simulate", "--out", "e", "--set", "radiation.space=moon"],
    ));
    assert!(e.contains("radiation.space") && e.contains("moon"), "{e}");
}

/// `map --transient` writes each run's A-weighted level of its last window
/// as `spl_dba`, and its picture.
#[test]
fn a_transient_map_has_its_levels() {
    let d = tempfile::tempdir().unwrap();
    ok(&squeal(
        d.path(),
        &[
            "map",
            "--x",
            "V=1:10:2",
            "--y",
            "N=1000:4000:2",
            "--transient",
            "--duration",
            "0.05",
            "--out",
            "m",
        ],
    ));
    let csv = std::fs::read_to_string(d.path().join("m/map.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "spl_dba").unwrap();
    for line in csv.lines().skip(1) {
        let x: f64 = line.split(',').nth(col).unwrap().parse().unwrap();
        assert!(x.is_finite() && x > 60.0, "{line}");
    }
    assert!(d.path().join("m/spl_dba.png").exists());
}
