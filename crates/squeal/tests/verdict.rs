//! The verdict and the squeal answer of real runs (issue "One answer"): the
//! same word whatever the run's length and sample rate, and the same squeal
//! frequency as the eigen-analysis.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

fn squeal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs")
}

/// `simulate ARGS --json --no-plots` in a fresh folder: summary.json.
fn summary(args: &[&str]) -> Value {
    let d = tempfile::tempdir().unwrap();
    let mut all = vec!["simulate", "--json", "--no-plots", "--out", "run"];
    all.extend_from_slice(args);
    let out = squeal(d.path(), &all);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn verdict(s: &Value) -> &str {
    s["verdict"].as_str().unwrap()
}

#[test]
fn belt_coulomb_is_stick_slip_at_every_length_and_sample_rate() {
    let mut cases = Vec::new();
    for d in ["0.5", "1", "5", "50"] {
        for sr in ["100", "1000", "20000"] {
            cases.push((d, sr));
        }
    }
    let results: Vec<(&str, &str, Value)> = std::thread::scope(|s| {
        let hs: Vec<_> = cases
            .iter()
            .map(|&(d, sr)| {
                s.spawn(move || {
                    let set = format!("sample_rate={sr}");
                    (
                        d,
                        sr,
                        summary(&["belt-coulomb", "--duration", d, "--set", &set]),
                    )
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (d, sr, s) in &results {
        assert_eq!(
            verdict(s),
            "stick-slip",
            "duration {d} s, {sr} Hz: {}",
            s["verdict_detail"]
        );
        // One true stick per cycle, no reversals: the classic Coulomb cycle.
        let pc = &s["verdict_detail"]["per_cycle"];
        let spc = pc["sticks_per_cycle"].as_f64().unwrap();
        assert!((0.8..=1.35).contains(&spc), "{d} s {sr} Hz: {pc}");
        assert_eq!(pc["reversals_per_cycle"].as_f64().unwrap(), 0.0);
        // Its frequency is the stick period's, from the integrator's event
        // times: the same at every sample rate.
        let sq = &s["squeal"];
        assert_eq!(sq["coordinate"], "x");
        let f = sq["frequency_hz"].as_f64().unwrap();
        let f_ref = results[0].2["squeal"]["frequency_hz"].as_f64().unwrap();
        assert!(
            (f - f_ref).abs() < 1e-6 * f_ref,
            "{d} s {sr} Hz: {f} vs {f_ref}"
        );
    }
}

#[test]
fn hoffmann_settles_on_a_bounded_sustained_cycle() {
    let s = summary(&["hoffmann"]);
    assert!(
        ["limit-cycle", "stick-slip"].contains(&verdict(&s)),
        "{}",
        s["verdict_detail"]
    );
    let sq = &s["squeal"];
    assert!(!sq.is_null());
    // Its level is that of the settled cycle: ≈ 1 m/s, not still rising.
    let rms = sq["rms"].as_f64().unwrap();
    assert!((0.5..2.0).contains(&rms), "{sq}");
    for (_, t) in s["verdict_detail"]["trends"].as_object().unwrap() {
        if let Some(c) = t["change_db"].as_f64() {
            assert!(c.abs() < 1.0, "{t}");
        }
    }
}

#[test]
fn short_linear_growth_is_grows_and_too_short_is_said() {
    // Set 27 (σ = +1.067 1/s, the disc mode): in 0.05 s it is still linear.
    let s = summary(&["thesis-27", "--duration", "0.05"]);
    assert_eq!(verdict(&s), "grows", "{}", s["verdict_detail"]);
    let sq = &s["squeal"];
    assert_eq!(sq["coordinate"], "x_d");
    let f = sq["frequency_hz"].as_f64().unwrap();
    assert!((f - 5032.92).abs() < 0.005 * 5032.92, "{sq}");
    let rate = s["verdict_detail"]["trends"]["x_d"]["rate"]
        .as_f64()
        .unwrap();
    assert!((rate - 1.0667).abs() < 0.5, "{rate}");
    // Four cycles of its 430 Hz normal motion are not enough to tell.
    let s = summary(&["thesis-27", "--duration", "0.01"]);
    assert_eq!(verdict(&s), "too-short", "{}", s["verdict_detail"]);
    assert!(s["squeal"].is_null());
}

#[test]
fn undamped_ringing_is_neutral_and_damped_decays() {
    // Set 1: V = 0, no damping: the step load makes the disc ring forever.
    let s = summary(&["thesis-01"]);
    assert_eq!(verdict(&s), "neutral", "{}", s["verdict_detail"]);
    assert!(s["squeal"].is_null());
    // The default brake damped past both Hopf points: every mode decays.
    let s = summary(&["--set", "c_dx=5", "--set", "c_px=5"]);
    assert_eq!(verdict(&s), "decays", "{}", s["verdict_detail"]);
    assert!(s["squeal"].is_null());
}

#[test]
fn repeated_contact_loss_is_lift_off_and_a_flung_pad_out_of_range() {
    // Set 39 (α = −1000): the pad leaves the disc thousands of times a second.
    let s = summary(&["thesis-39"]);
    assert_eq!(verdict(&s), "lift-off", "{}", s["verdict_detail"]);
    let pc = &s["verdict_detail"]["per_cycle"];
    assert!(pc["separations"].as_u64().unwrap() > 1000, "{pc}");
    // Set 40 (α = −1e5): the pad is flung metres away.
    let s = summary(&["thesis-40"]);
    assert_eq!(verdict(&s), "out-of-range", "{}", s["verdict_detail"]);
    assert!(s["squeal"].is_null());
    assert_eq!(s["scenario"]["validity"], 0.1);
    // The bound is a setting: with a (meaningless) 1000 km bound the same run is judged on.
    let s = summary(&["thesis-40", "--set", "validity=1e6"]);
    assert_ne!(verdict(&s), "out-of-range", "{}", s["verdict_detail"]);
}

#[test]
fn a_bad_validity_is_refused() {
    let d = tempfile::tempdir().unwrap();
    for v in ["validity=0", "validity=-1", "validity=nan"] {
        let out = squeal(d.path(), &["simulate", "--set", v]);
        assert_eq!(out.status.code(), Some(2), "{v}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("validity"), "{err}");
        assert!(!d.path().join("out").exists());
    }
}

#[test]
fn default_squeal_is_the_pad_at_the_least_stable_frequency() {
    let d = tempfile::tempdir().unwrap();
    let out = squeal(d.path(), &["stability", "--json"]);
    assert!(out.status.success());
    let st: Value = serde_json::from_slice(&out.stdout).unwrap();
    let f_lin = st["least_stable"]["freq_hz"].as_f64().unwrap();
    assert_eq!(st["least_stable"]["dominant"], "x_p");

    let out = squeal(d.path(), &["simulate", "--no-plots"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // The terminal summary leads with the answer.
    let first = text.lines().next().unwrap();
    assert!(
        first.starts_with("squeals at 20.75 kHz (pad tangential, x_p)"),
        "{first}"
    );
    let s: Value = serde_json::from_str(
        &std::fs::read_to_string(d.path().join("out/disc-pad/summary.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(verdict(&s), "stick-slip");
    let sq = &s["squeal"];
    assert_eq!(sq["coordinate"], "x_p");
    let f = sq["frequency_hz"].as_f64().unwrap();
    assert!((f - f_lin).abs() < 0.005 * f_lin, "{f} vs {f_lin}");
    // Level: the pad's velocity RMS over the judged window, and its dB.
    let rms = sq["rms"].as_f64().unwrap();
    assert!((0.6..0.8).contains(&rms), "{sq}");
    let db = sq["level_db"].as_f64().unwrap();
    assert!((db - 20.0 * rms.log10()).abs() < 1e-9);
    // How it is friction-limited: many reversals, few true sticks, per cycle.
    let pc = &s["verdict_detail"]["per_cycle"];
    let rev = pc["reversals_per_cycle"].as_f64().unwrap();
    let st = pc["sticks_per_cycle"].as_f64().unwrap();
    assert!(rev > 1.0 && st < 0.2, "{pc}");
}
