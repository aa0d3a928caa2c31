//! One answer for every model (issue 28 §1–§2): the squeal frequency does
//! not depend on the run's length (within its stated uncertainty), it is
//! the same number on the terminal and in summary.json, the linear
//! prediction stands beside it, the growth rate measured on the unstable
//! mode's own modal coordinate matches its eigenvalue, and a run that ends
//! before the squeal shows says so instead of naming another mode.

use crate::cli_common::{json, ok, squeal};
use serde_json::Value;

/// `simulate NAME --duration D --json --no-plots [ARGS]` in a fresh folder.
fn run(name: &str, duration: &str, args: &[&str]) -> Value {
    let d = tempfile::tempdir().unwrap();
    let mut all = vec![
        "simulate",
        name,
        "--duration",
        duration,
        "--json",
        "--no-plots",
        "--out",
        "run",
    ];
    all.extend_from_slice(args);
    json(&squeal(d.path(), &all))
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The leading eigenvalue `(σ, f)` by `squeal stability --json`.
fn leading(name: &str) -> (f64, f64) {
    let d = tempfile::tempdir().unwrap();
    let v = json(&squeal(
        d.path(),
        &["stability", name, "--json", "--no-levers"],
    ));
    (
        f(&v["least_stable"]["re"]),
        f(&v["least_stable"]["freq_hz"]),
    )
}

#[test]
fn the_squeal_frequency_does_not_depend_on_the_run_length() {
    // Brakes whose squeal saturates (disc-pad, the lumped two-pad brake:
    // stick-slip after ~0.35 s), one that is still growing at every length
    // (the 8-dof floating caliper, σ = +0.16 1/s), and the belt and
    // Hoffmann's model at their own time scale (16 Hz: ten times longer).
    for (name, durations) in [
        ("disc-pad", ["0.2", "0.3", "0.5", "1.0"]),
        ("two-pad-brake", ["0.2", "0.3", "0.5", "1.0"]),
        ("floating-caliper", ["0.2", "0.3", "0.5", "1.0"]),
        ("belt", ["2", "3", "5", "10"]),
    ] {
        let (_, f_lin) = leading(name);
        let answers: Vec<(f64, f64)> = durations
            .iter()
            .map(|d| {
                let v = run(name, d, &[]);
                let s = &v["squeal"];
                assert_eq!(s["established"], true, "{name} {d} s: {s}");
                assert_eq!(s["source"], "run", "{name} {d} s");
                assert!((f(&s["linear_hz"]) - f_lin).abs() < 1e-6 * f_lin);
                // Half the judged window's resolution, 1/(2T).
                let w = &v["verdict_detail"]["window_s"];
                let u = f(&s["uncertainty_hz"]);
                assert!(
                    (u * 2.0 * (f(&w[1]) - f(&w[0])) - 1.0).abs() < 1e-2,
                    "{name} {d} s: {u}"
                );
                (f(&s["frequency_hz"]), u)
            })
            .collect();
        for a in &answers {
            for b in &answers {
                assert!(
                    (a.0 - b.0).abs() <= a.1 + b.1,
                    "{name}: {a:?} and {b:?} differ by more than their uncertainties"
                );
            }
            // The linear prediction within the uncertainty (the saturated
            // cycles too: 0.02 Hz from it at 20.75 kHz).
            assert!((a.0 - f_lin).abs() <= a.1, "{name}: {a:?} vs {f_lin}");
        }
    }
}

#[test]
fn the_terminal_and_summary_give_the_same_frequency_and_growth() {
    let d = tempfile::tempdir().unwrap();
    let text = ok(&squeal(
        d.path(),
        &["simulate", "floating-caliper", "--no-plots", "--out", "run"],
    ));
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("run/summary.json")).unwrap())
            .unwrap();
    let first = text.lines().next().unwrap();
    // 2250.763… Hz printed to five digits.
    assert!(f(&s["squeal"]["frequency_hz"]) > 2250.7 && f(&s["squeal"]["frequency_hz"]) < 2250.8);
    assert!(
        first.starts_with("squeals (still growing) at 2.2508 kHz ± 4.0 Hz (x_p1)"),
        "{first}"
    );
    assert!(first.contains("linear prediction 2.25076 kHz"), "{first}");
    // Still growing (+0.18 dB over the judged 0.125 s).
    assert_eq!(s["verdict"], "grows");
    assert_eq!(s["verdict_detail"]["verdict"], "grows");
    let second = text.lines().nth(1).unwrap();
    let g = f(&s["linear"]["measured_growth"]["rate"]);
    assert!(
        second.starts_with(&format!("growth: {g:+.6e} 1/s")),
        "{second}"
    );
    // The spectral peaks line says what it is.
    assert!(text
        .contains("spectral peaks (the strongest line of each velocity, not the squeal answer): "));
}

#[test]
fn the_growth_on_the_modal_coordinate_matches_the_eigenvalue() {
    // Linear-phase runs of every kind: the thesis's disc-pad (its linear
    // phase is the first 0.36 s), the two-pad brake, the 8-dof caliper
    // (σ·T = 0.08: a mode growing by e in 6 s, measured in 0.5 s), the belt
    // and Hoffmann's mode-coupling model. The eigenvalue and the run are
    // independent computations (a QR eigen-solver, and DOP853 on the
    // nonlinear equations).
    for (name, duration, tolerance) in [
        ("disc-pad", "0.5", 1e-5),
        ("two-pad-brake", "0.5", 1e-5),
        ("floating-caliper", "0.5", 1e-3),
        ("belt", "5", 1e-5),
        ("hoffmann", "5", 1e-5),
    ] {
        let (sigma, _) = leading(name);
        let v = run(name, duration, &[]);
        let l = &v["linear"];
        assert!((f(&l["growth_rate"]) - sigma).abs() < 1e-9 * sigma.abs());
        let g = &l["measured_growth"];
        assert!(g["reason"].is_null(), "{name}: {g}");
        let rate = f(&g["rate"]);
        assert!(
            (rate - sigma).abs() <= tolerance * sigma,
            "{name}: measured {rate} against the eigenvalue's {sigma}"
        );
        assert!((f(&g["relative_difference"]) - (rate - sigma) / sigma).abs() < 1e-12);
        assert!(f(&g["t_end"]) > f(&g["t_start"]));
    }
}

#[test]
fn envelope_fits_that_no_mode_explains_are_not_reported() {
    // The disc-pad's disc velocity: its envelope over the saturation fits
    // −2.4e2 1/s, which no eigenvalue at its 5.03 kHz line has: `null` with
    // the reason. The pad's fit is the 20.75 kHz mode's +14.667 1/s, and
    // the normal velocities' decay is the 429 Hz mode's −0.4545 1/s.
    let v = run("disc-pad", "0.5", &[]);
    let g = &v["growth_rate"];
    assert!(g["vx_d"]["rate"].is_null(), "{}", g["vx_d"]);
    assert!(g["vx_d"]["reason"]
        .as_str()
        .unwrap()
        .contains("no eigenvalue of steady sliding at its strongest line (5.033 kHz)"));
    assert!((f(&g["vx_p"]["rate"]) - 14.666_666_666).abs() < 0.01 * 14.67);
    assert!(g["vx_p"]["reason"].is_null());
    for n in ["vy_d", "vy_p"] {
        assert!(
            (f(&g[n]["rate"]) + 0.454_531_3).abs() < 0.01 * 0.4545,
            "{n}"
        );
    }
}

#[test]
fn a_run_ended_before_the_squeal_shows_gives_the_linear_prediction_and_says_so() {
    // The caliper knocked but its squeal mode not excited: in 0.2 s only
    // the caliper's 550 Hz ring (and round-off) is there. The answer is the
    // linear prediction, labelled so, not another mode's frequency.
    let (_, f_lin) = leading("floating-caliper");
    let v = run("floating-caliper", "0.2", &["--set", "x_p10=0"]);
    let s = &v["squeal"];
    assert_eq!(s["established"], false, "{s}");
    assert_eq!(s["source"], "linear");
    assert!((f(&s["frequency_hz"]) - f_lin).abs() <= 1e-9 * f_lin, "{s}");
    assert!(s["uncertainty_hz"].is_null() && s["rms"].is_null() && s["level_db"].is_null());
    assert_eq!(s["coordinate"], "x_p1");
    assert!((f(&s["dominant_hz"]) - 550.36).abs() < 3.0, "{s}");
    // The mode is at round-off: no estimate of how much longer, and the
    // advice says why.
    assert!(s["lengthen_s"].is_null(), "{s}");
    let note = s["note"].as_str().unwrap();
    assert!(
        note.contains("not established") && note.contains("too weakly excited"),
        "{note}"
    );
    assert!(note.contains("an offset on x_p1"), "{note}");
    // The judge's "steady" window was round-off: the verdict says too short.
    assert_eq!(v["verdict"], "too-short");
    assert_eq!(v["verdict_detail"]["judged"], "limit-cycle");
    // The growth is not measured, and says why, with no number.
    let g = &v["linear"]["measured_growth"];
    assert!(g["rate"].is_null() && g["reason"].is_string(), "{g}");
}

/// An undamped set with constant friction (thesis set 6) has a leading
/// eigenvalue whose σ = +1.2e-11 1/s is the eigen-solver's round-off of 0
/// (|σ| ≤ 1e-12·|λ|): the answer calls it neutral, names no growing mode
/// and no squeal, instead of "too short" with an e-fold time of 8e10 s.
#[test]
fn a_round_off_sigma_is_neutral_not_growing() {
    let v = run("thesis-06", "0.1", &[]);
    let sigma = f(&v["linear"]["growth_rate"]);
    assert!(sigma.abs() < 1e-9, "{sigma}");
    assert_eq!(v["linear"]["growing_modes"], 0);
    assert_eq!(v["verdict"], "neutral");
    assert!(v["squeal"].is_null(), "{}", v["squeal"]);
}

/// Pictures for any number of dofs (issue 28 §5): the 8-dof caliper's
/// triplet shows four velocities by default — the squealing one first —
/// in 8 panels 2400 px high, says which on stderr, and `--signals` still
/// draws any set; the squeal's title carries the very number of
/// summary.json.
#[test]
fn an_eight_dof_triplet_shows_the_squeal_first_and_says_what_it_left_out() {
    let d = tempfile::tempdir().unwrap();
    let out = crate::cli_common::squeal(
        d.path(),
        &[
            "simulate",
            "floating-caliper",
            "--duration",
            "0.2",
            "--out",
            "a",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("triplet: 4 of the 8 velocities (vx_p1, "),
        "{err}"
    );
    let png = std::fs::read(d.path().join("a/triplet.png")).unwrap();
    let height = u32::from_be_bytes([png[20], png[21], png[22], png[23]]);
    assert_eq!(height, 2400);
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("a/summary.json")).unwrap())
            .unwrap();
    let words = squeal_words(&summary["squeal"]);
    let svg = std::fs::read_to_string(d.path().join("a/spectrogram.svg")).unwrap();
    assert!(
        svg.contains(&words),
        "{words} not in the spectrogram's title"
    );
    let out = crate::cli_common::squeal(
        d.path(),
        &[
            "simulate",
            "floating-caliper",
            "--duration",
            "0.05",
            "--out",
            "b",
            "--signals",
            "vx_d,vy_d,vx_p1,vy_p1,vx_p2,vy_p2",
        ],
    );
    assert!(!String::from_utf8_lossy(&out.stderr).contains("triplet:"));
    let png = std::fs::read(d.path().join("b/triplet.png")).unwrap();
    let height = u32::from_be_bytes([png[20], png[21], png[22], png[23]]);
    assert_eq!(height, 3600, "6 velocities asked for, 12 panels");
}

/// "squeal 2.2508 kHz ± 4.0 Hz" from summary.json's squeal, as the
/// pictures write it (SI prefix, 5 and 2 significant digits).
fn squeal_words(s: &Value) -> String {
    let (hz, u) = (f(&s["frequency_hz"]), f(&s["uncertainty_hz"]));
    assert!(
        (1000.0..10_000.0).contains(&hz) && (1.0..10.0).contains(&u),
        "{s}"
    );
    format!("squeal {:.4} kHz ± {:.1} Hz", hz / 1000.0, u)
}
