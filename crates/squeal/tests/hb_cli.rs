//! `squeal hb` end to end: the JSON against `squeal cycle`'s on the same
//! scenario (frequency, amplitudes, multipliers), and what it refuses.

use crate::cli_common::{json as json_of, refused, squeal};

/// Hoffmann's two-dof model with contact loss (no stick, no reversal):
/// HB at H = 20 against shooting.
#[test]
fn hoffmann_hb_equals_the_shooting_cycle() {
    let d = tempfile::tempdir().unwrap();
    let hb = json_of(&squeal(
        d.path(),
        &["hb", "hoffmann", "--json", "--out", "h"],
    ));
    // The files: the document as printed, one period of the series (its
    // last row the first again), the picture.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("h/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary, hb);
    let csv = std::fs::read_to_string(d.path().join("h/hb_orbit.csv")).unwrap();
    assert_eq!(csv.lines().next().unwrap(), "t,x,y,vx,vy");
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    assert!((last[0] - hb["period"].as_f64().unwrap()).abs() < 1e-15);
    for c in 1..5 {
        assert!(
            (last[c] - first[c]).abs() <= 1e-12 * first[c].abs().max(1.0),
            "{c}"
        );
    }
    assert!(d.path().join("h/hb.png").is_file());
    let cy = json_of(&squeal(d.path(), &["cycle", "hoffmann", "--json"]));
    let (fh, fc) = (
        hb["freq_hz"].as_f64().unwrap(),
        cy["frequency_hz"].as_f64().unwrap(),
    );
    // Measured: 6e-11.
    assert!((fh / fc - 1.0).abs() <= 1e-8, "{fh} vs {fc}");
    assert_eq!(hb["frequency_hz"], hb["freq_hz"]);
    assert!((hb["period"].as_f64().unwrap() * fh - 1.0).abs() < 1e-14);
    // Amplitudes (half peak-to-peak of the series, and of shooting's
    // step ends: the latter can only be smaller, by the step's sampling).
    for s in ["x", "y", "vx", "vy"] {
        let (a, b) = (
            hb["amplitude"][s].as_f64().unwrap(),
            cy["amplitude"][s].as_f64().unwrap(),
        );
        assert!((a / b - 1.0).abs() <= 2e-3, "{s}: {a} vs {b}");
    }
    // The multipliers: the same exact period, from the HB state.
    let (mh, mc) = (
        hb["multipliers"].as_array().unwrap(),
        cy["multipliers"].as_array().unwrap(),
    );
    assert_eq!(mh.len(), mc.len());
    for (a, b) in mh.iter().zip(mc) {
        let (a, b) = (a["abs"].as_f64().unwrap(), b["abs"].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-6, "{a} vs {b}");
    }
    assert_eq!(hb["stable"], cy["stable"]);
    // The convergence table: H/4, H/2, H; the harmonics per dof: mean and 20.
    let conv = hb["convergence"].as_array().unwrap();
    let hs: Vec<u64> = conv
        .iter()
        .map(|r| r["harmonics"].as_u64().unwrap())
        .collect();
    assert_eq!(hs, [5, 10, 20]);
    assert!(conv[0]["amplitude_change"].is_null());
    assert_eq!(hb["harmonics"]["x"].as_array().unwrap().len(), 21);
    // Contact loss, about 31 % of the period; no stick.
    let m = &hb["contact_modes"]["belt"];
    let free = m["free"].as_f64().unwrap();
    assert!(free > 0.2 && free < 0.4, "{m}");
    assert_eq!(m["stick"].as_f64().unwrap(), 0.0);
    assert!(hb["shooting_defect"].as_f64().unwrap() < 1e-5);
    assert!(hb["warnings"].as_array().unwrap().is_empty(), "{hb}");
}

#[test]
fn hb_refuses_what_it_cannot_do_in_one_line() {
    let d = tempfile::tempdir().unwrap();
    // The thesis law's belt settles on stick-slip.
    let err = refused(&squeal(d.path(), &["hb", "belt"]));
    assert!(
        err.contains("sticks") && err.contains("squeal cycle"),
        "{err}"
    );
    let err = refused(&squeal(d.path(), &["hb", "hoffmann", "--guess", "guess"]));
    assert!(err.contains("--guess guess"), "{err}");
    for h in ["0", "401"] {
        let err = refused(&squeal(d.path(), &["hb", "hoffmann", "--harmonics", h]));
        assert!(err.contains(&format!("--harmonics {h}")), "{err}");
    }
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
}

/// Where the motion passes an unstable or vanishing orbit before it
/// settles (thesis set 17: a 429 Hz transient while the pad's mode grows),
/// HB settles on as `cycle` does and finds the same orbit; the lumped
/// Hoffmann model's settled "period" is eight turns, and HB takes the
/// minimal one.
#[test]
fn hb_finds_the_orbit_cycle_settles_on() {
    let d = tempfile::tempdir().unwrap();
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios");
    for (s, tol) in [
        (format!("{root}/thesis/set17.toml"), 1e-7),
        (format!("{root}/lumped/hoffmann.toml"), 1e-8),
    ] {
        let hb = json_of(&squeal(d.path(), &["hb", &s, "--json"]));
        let cy = json_of(&squeal(d.path(), &["cycle", &s, "--json"]));
        let (fh, fc) = (
            hb["freq_hz"].as_f64().unwrap(),
            cy["frequency_hz"].as_f64().unwrap(),
        );
        // Measured: 1.3e-8 and 3e-11.
        assert!((fh / fc - 1.0).abs() <= tol, "{s}: {fh} vs {fc}");
        assert_eq!(hb["stable"], cy["stable"], "{s}");
        let (mh, mc) = (
            hb["max_multiplier"].as_f64().unwrap(),
            cy["max_multiplier"].as_f64().unwrap(),
        );
        assert!((mh - mc).abs() <= 1e-5, "{s}: {mh} vs {mc}");
    }
}

/// `--guess hopf`: no simulation; Hoffmann's orbit from steady sliding's
/// growing mode at the amplitude where the normal force first reaches zero
/// is the shooting cycle's (measured 1.5e-10).
#[test]
fn hb_from_the_hopf_guess_needs_no_settling() {
    let d = tempfile::tempdir().unwrap();
    let hb = json_of(&squeal(
        d.path(),
        &["hb", "hoffmann", "--guess", "hopf", "--json"],
    ));
    let cy = json_of(&squeal(d.path(), &["cycle", "hoffmann", "--json"]));
    assert_eq!(hb["guess"], "hopf");
    assert_eq!(hb["settle_time"].as_f64(), Some(0.0));
    let (fh, fc) = (
        hb["freq_hz"].as_f64().unwrap(),
        cy["frequency_hz"].as_f64().unwrap(),
    );
    assert!((fh / fc - 1.0).abs() <= 1e-8, "{fh} vs {fc}");
    assert_eq!(hb["stable"], true);
}
