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
    // Contact loss: a switch makes the linearisation jump, no Hill's method.
    assert!(hb["switches_per_period"].as_u64().unwrap() >= 2);
    assert!(hb["hill"].is_null());
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

/// The thesis law's belt settles on stick-slip: HB holds stick as a
/// constraint (the dynamic Lagrangian step) and finds shooting's orbit.
/// Measured: frequency 5.0e-5 from `cycle`'s at H = 40 (2.1e-5 at 80),
/// stick 3.7 % of the period (shooting: 3.3 %).
#[test]
fn hb_holds_the_belts_stick_as_a_constraint() {
    let d = tempfile::tempdir().unwrap();
    let hb = json_of(&squeal(
        d.path(),
        &["hb", "belt", "--harmonics", "40", "--json"],
    ));
    assert_eq!(hb["stick_constraint"], true, "{hb}");
    let cy = json_of(&squeal(d.path(), &["cycle", "belt", "--json"]));
    let (fh, fc) = (
        hb["freq_hz"].as_f64().unwrap(),
        cy["frequency_hz"].as_f64().unwrap(),
    );
    assert!((fh / fc - 1.0).abs() <= 1e-4, "{fh} vs {fc}");
    let stick = hb["contact_modes"]["belt"]["stick"].as_f64().unwrap();
    assert!(stick > 0.02 && stick < 0.06, "{stick}");
    for name in ["x", "v"] {
        let (a, b) = (
            hb["amplitude"][name].as_f64().unwrap(),
            cy["amplitude"][name].as_f64().unwrap(),
        );
        assert!((a / b - 1.0).abs() <= 3e-3, "{name}: {a} vs {b}");
    }
    assert_eq!(hb["stable"], true);
}

#[test]
fn hb_refuses_what_it_cannot_do_in_one_line() {
    let d = tempfile::tempdir().unwrap();
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

fn lumped(name: &str) -> String {
    format!(
        "{}/../../scenarios/lumped/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// The forced Duffing oscillator: its response at 15 Hz (a linear damped
/// model's pair of multipliers has |μ| = e^{−cT/2m} exactly, Liouville),
/// and its frequency-response curve from 10 to 30 Hz through both folds,
/// the middle branch unstable, with the files of `--out`.
#[test]
fn the_duffing_response_and_its_curve_through_both_folds() {
    let d = tempfile::tempdir().unwrap();
    let duffing = lumped("duffing");
    let one = json_of(&squeal(d.path(), &["hb", &duffing, "--json"]));
    assert_eq!(one["forced"], true);
    assert_eq!(one["forcing_hz"].as_f64(), Some(15.0));
    assert!((one["freq_hz"].as_f64().unwrap() - 15.0).abs() < 1e-12);
    let liouville = (-2.0 / 2.0 / 15.0f64).exp();
    assert!((one["max_multiplier"].as_f64().unwrap() - liouville).abs() < 1e-6);
    assert_eq!(one["stable"], true);
    // The orbit is smooth: Hill's method from the series alone gives the
    // exact period's multipliers (measured to 1e-9).
    let hill = &one["hill"];
    assert_eq!(hill["multipliers"].as_array().unwrap().len(), 2);
    let h = hill["max_multiplier"].as_f64().unwrap();
    assert!(
        (h - one["max_multiplier"].as_f64().unwrap()).abs() < 1e-7,
        "{hill}"
    );
    // Below the resonance the response is unique: HB is the settled run's.
    let x = one["amplitude"]["x"].as_f64().unwrap();
    assert!((4e-3..1e-2).contains(&x), "{x}");
    let out = squeal(
        d.path(),
        &[
            "hb",
            &duffing,
            "--param",
            "shaker.freq_hz=10:30:41",
            "--json",
            "--out",
            "frc",
        ],
    );
    let br = json_of(&out);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("frc/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary, br);
    let folds: Vec<f64> = br["folds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert!((22.2..22.45).contains(&folds[0]) && (17.1..17.35).contains(&folds[1]));
    let points = br["points"].as_array().unwrap();
    // Between the folds, in the order followed: stable, unstable, stable;
    // the last point at 30 Hz exactly.
    let stable: Vec<bool> = points.iter().map(|p| p["stable"] == true).collect();
    let changes = stable.windows(2).filter(|w| w[0] != w[1]).count();
    assert_eq!(changes, 2, "{stable:?}");
    assert_eq!(points.last().unwrap()["value"].as_f64(), Some(30.0));
    let csv = std::fs::read_to_string(d.path().join("frc/branch.csv")).unwrap();
    assert_eq!(
        csv.lines().next().unwrap(),
        "shaker.freq_hz,period,freq_hz,amplitude_x,amplitude_vx,max_multiplier,stable,point"
    );
    assert_eq!(csv.lines().count(), points.len() + 1);
    assert_eq!(csv.matches(",fold").count(), 2);
    assert!(d.path().join("frc/hb_branch.png").is_file());
}

/// Den Hartog's Coulomb-damped oscillator (r = 1.5, β = 0.3): the exact
/// amplitude for motion without stops, `X_st √(1/(1 − r²)² − (βU)²)`, `U =
/// sin(π/r)/(r(1 + cos(π/r)))`; HB at H = 40 is within its first-order
/// truncation error (1.4e-3).
#[test]
fn den_hartogs_oscillator_through_the_cli() {
    let d = tempfile::tempdir().unwrap();
    let v = json_of(&squeal(
        d.path(),
        &[
            "hb",
            &lumped("coulomb-forced"),
            "--harmonics",
            "40",
            "--json",
        ],
    ));
    let (r, beta, x_st) = (1.5f64, 0.3f64, 1e-3);
    let pi = std::f64::consts::PI;
    let u = (pi / r).sin() / (r * (1.0 + (pi / r).cos()));
    let exact = x_st * (1.0 / (1.0 - r * r).powi(2) - (beta * u).powi(2)).sqrt();
    let x = v["amplitude"]["x"].as_f64().unwrap();
    assert!((x / exact - 1.0).abs() < 2e-3, "{x} vs {exact}");
    assert_eq!(v["contact_modes"]["rub"]["stick"].as_f64(), Some(0.0));
    assert_eq!(v["switches_per_period"].as_u64(), Some(2));
}

/// Shooting refuses forced models; hb refuses what does not apply to them.
#[test]
fn forced_models_are_refused_where_they_do_not_belong() {
    let d = tempfile::tempdir().unwrap();
    let duffing = lumped("duffing");
    for args in [
        vec!["cycle", &duffing],
        vec![
            "branch",
            &duffing,
            "--param",
            "shaker.freq_hz=10:20:3",
            "--out",
            "b",
        ],
    ] {
        let err = refused(&squeal(d.path(), &args));
        assert!(err.contains("forced") && err.contains("squeal hb"), "{err}");
    }
    let err = refused(&squeal(d.path(), &["hb", &duffing, "--guess", "hopf"]));
    assert!(
        err.contains("--guess hopf") && err.contains("forced"),
        "{err}"
    );
    let err = refused(&squeal(
        d.path(),
        &["hb", &duffing, "--set", "shaker.freq_hz=0"],
    ));
    assert!(
        err.contains("shaker.freq_hz") && err.contains("freq_hz > 0"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
}

/// A simulated forced run does not call its forced line squeal.
#[test]
fn a_forced_run_is_a_response_not_squeal() {
    let d = tempfile::tempdir().unwrap();
    let out = crate::cli_common::ok(&squeal(
        d.path(),
        &["simulate", &lumped("duffing"), "--out", "r"],
    ));
    let first = out.lines().next().unwrap();
    assert!(
        first.starts_with("responds at ") && first.contains("not self-excited squeal"),
        "{first}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("r/summary.json")).unwrap())
            .unwrap();
    assert_eq!(v["squeal"]["forced_hz"].as_f64(), Some(15.0));
}

/// The friction damper's nonlinear mode: the stuck mode at low amplitude
/// (x1 alone on k1 + k2: √(2·10⁴)/2π Hz, its damping the springs' c = 0.2
/// kg/s through φᵀCφ), the freely sliding chain's out-of-phase mode at
/// high amplitude (√((3+√5)/2·10⁴)/2π Hz), and friction's damping peak
/// between; the files of `--out`; refusals.
#[test]
fn the_friction_dampers_nonlinear_mode() {
    let d = tempfile::tempdir().unwrap();
    let sc = lumped("friction-damper");
    let v = json_of(&squeal(
        d.path(),
        &[
            "nma",
            &sc,
            "--mode",
            "1",
            "--modal-amplitude",
            "1e-4:1:13",
            "--json",
            "--out",
            "n",
        ],
    ));
    let tau = std::f64::consts::TAU;
    let stuck = 2e4f64.sqrt() / tau;
    assert!((v["linear_hz"].as_f64().unwrap() / stuck - 1.0).abs() < 1e-9);
    let pts = v["points"].as_array().unwrap();
    assert_eq!(pts.len(), 13, "{}", v["failures"]);
    let f = |i: usize, k: &str| pts[i][k].as_f64().unwrap();
    assert!((f(0, "freq_hz") / stuck - 1.0).abs() < 1e-5);
    let sliding = ((3.0 + 5f64.sqrt()) / 2.0 * 1e4).sqrt() / tau;
    assert!((f(12, "freq_hz") / sliding - 1.0).abs() < 1e-4);
    // The stuck mode's damping: x1 on the springs' c1 + c2 = 0.4 kg/s, and
    // the tanh damper's slope c_f = μN/ε = 10⁵ kg/s holding x2 almost still
    // (|x2| = k2|x1|/(c_f ω)), which dissipates as a dashpot k2²/(c_f ω²) =
    // 0.05 kg/s on x1: D = 0.45/(2ω).
    let w = stuck * tau;
    let d0 = (0.4 + 1e8 / (1e5 * w * w)) / (2.0 * w);
    assert!(
        (f(0, "damping_ratio") / d0 - 1.0).abs() < 1e-3,
        "{}",
        f(0, "damping_ratio")
    );
    let peak = (0..13).map(|i| f(i, "damping_ratio")).fold(0.0, f64::max);
    assert!(peak > 20.0 * d0, "{peak}");
    let csv = std::fs::read_to_string(d.path().join("n/nma.csv")).unwrap();
    assert!(csv.starts_with("modal_amplitude,freq_hz,xi,damping_ratio,amplitude_x1,"));
    assert!(d.path().join("n/nma.png").is_file());
    for (args, want) in [
        (
            vec!["nma", "hoffmann", "--modal-amplitude", "1e-3:1e-2:3"],
            "lumped",
        ),
        (
            vec![
                "nma",
                &sc,
                "--mode",
                "3",
                "--modal-amplitude",
                "1e-3:1e-2:3",
            ],
            "--mode 3",
        ),
        (
            vec!["nma", &sc, "--modal-amplitude", "0:1:3"],
            "--modal-amplitude",
        ),
    ] {
        let err = refused(&squeal(d.path(), &args));
        assert!(err.contains(want), "{err}");
    }
}

/// The same damper with exact Coulomb friction: where it sticks on part of
/// the period, stick is a constraint (before, those amplitudes failed or
/// were flagged as inexact). Below the stick-slip threshold the damper
/// never slips: the stuck mode exactly (ξ = c₁ + c₂); above it, the
/// sliding tail equals the tanh law's (ε = 10⁻⁴) to 1e-5.
#[test]
fn a_coulomb_dampers_nonlinear_mode_sticks_as_a_constraint() {
    let d = tempfile::tempdir().unwrap();
    let sc = lumped("friction-damper");
    let coulomb = [
        "--set",
        "damper.friction=coulomb",
        "--set",
        "damper.mu_s=1",
        "--set",
        "damper.mu_k=1",
    ];
    let run = |extra: &[&str]| {
        json_of(&squeal(
            d.path(),
            &[
                &["nma", &sc, "--modal-amplitude", "1e-3:1e-2:7", "--json"][..],
                extra,
            ]
            .concat(),
        ))
    };
    let v = run(&coulomb);
    let pts = v["points"].as_array().unwrap();
    assert_eq!(pts.len(), 7, "{}", v["failures"]);
    let f = |i: usize, k: &str| pts[i][k].as_f64().unwrap();
    let stuck = 2e4f64.sqrt() / std::f64::consts::TAU;
    assert!((f(0, "freq_hz") / stuck - 1.0).abs() < 1e-9);
    assert!((f(0, "xi") / 0.4 - 1.0).abs() < 1e-9, "{}", f(0, "xi"));
    for p in pts {
        assert_eq!(p["sticks"], p["stick_constraint"], "{p}");
    }
    assert!(pts
        .iter()
        .any(|p| p["stick_constraint"] == true && p["xi"].as_f64().unwrap() > 1.0));
    let tanh = run(&[]);
    let (a, b) = (
        f(6, "freq_hz"),
        tanh["points"][6]["freq_hz"].as_f64().unwrap(),
    );
    assert!((a / b - 1.0).abs() < 1e-5, "{a} vs {b}");
}

/// `hb --param` from a Hopf point: with no orbit at LO (steady sliding is
/// stable there), the branch starts at `critical`'s Hopf point inside the
/// range. On the belt with the (exponential) Stribeck law the Hopf point is
/// generic, so near it the amplitude grows as `A² ∝ p − p_h` (the normal
/// form), the orbit has the critical mode's frequency, and the branch of
/// pure slip ends where its velocity amplitude reaches the belt speed; it
/// goes on with stick as a constraint.
/// The thesis law's belt sticks at every speed of the range: the first
/// orbit (`squeal hb` at `lo`) is solved with stick as a constraint, so the
/// whole branch is too (a start with stick is not a solution of the
/// balance with friction as slip, which refused it before). Each end
/// against `squeal cycle` at that speed.
#[test]
fn hb_param_goes_on_with_stick_from_a_start_that_sticks() {
    let d = tempfile::tempdir().unwrap();
    let br = json_of(&squeal(
        d.path(),
        &["hb", "belt", "--param", "V=0.01:0.1:4", "--json"],
    ));
    assert_eq!(br["start"]["stick_constraint"], true, "{br}");
    let pts = br["points"].as_array().unwrap();
    assert!(pts.len() >= 4, "{br}");
    assert!(pts.iter().all(|p| p["stick_constraint"] == true), "{br}");
    assert!(pts.iter().all(|p| p["stable"] == true), "{br}");
    for k in [0, pts.len() - 1] {
        let v = pts[k]["value"].as_f64().unwrap();
        let set = format!("V={v}");
        let cy = json_of(&squeal(
            d.path(),
            &["cycle", "belt", "--set", &set, "--json"],
        ));
        let (fh, fc) = (
            pts[k]["freq_hz"].as_f64().unwrap(),
            cy["frequency_hz"].as_f64().unwrap(),
        );
        // H = 20 with stick: algebraic convergence (1.4e-4 measured).
        assert!((fh / fc - 1.0).abs() <= 3e-4, "V = {v}: {fh} vs {fc}");
        let (a, b) = (
            pts[k]["amplitude"]["x"].as_f64().unwrap(),
            cy["amplitude"]["x"].as_f64().unwrap(),
        );
        // 2.1e-3 measured.
        assert!((a / b - 1.0).abs() <= 5e-3, "V = {v}: {a} vs {b}");
    }
}

#[test]
fn hb_param_starts_at_the_hopf_point_when_lo_has_no_orbit() {
    let d = tempfile::tempdir().unwrap();
    let set = ["--set", "friction=stribeck"];
    let crit = json_of(&squeal(
        d.path(),
        &[
            &["critical", "belt", "--param", "V=0.01:0.1", "--json"][..],
            &set,
        ]
        .concat(),
    ));
    let br = json_of(&squeal(
        d.path(),
        &[
            &["hb", "belt", "--param", "V=0.01:0.1:10", "--json"][..],
            &set,
        ]
        .concat(),
    ));
    assert!(br["start"].is_null());
    let vh = crit["value"].as_f64().unwrap();
    assert!((br["hopf"]["value"].as_f64().unwrap() - vh).abs() <= 1e-12 * vh);
    let fh = crit["freq_hz"].as_f64().unwrap();
    let pts = br["points"].as_array().unwrap();
    assert!(pts.len() >= 3, "{br}");
    let at = |k: usize| {
        (
            pts[k]["value"].as_f64().unwrap(),
            pts[k]["amplitude"]["x"].as_f64().unwrap(),
            pts[k]["freq_hz"].as_f64().unwrap(),
        )
    };
    let ((v1, a1, f1), (v2, a2, _)) = (at(0), at(1));
    // Supercritical: the orbit is on the unstable side (V > V_h), stable.
    assert!(v1 > vh && v2 > v1, "{v1} {v2} {vh}");
    assert!(pts.iter().all(|p| p["stable"] == true));
    assert!((f1 - fh).abs() <= 1e-6 * fh, "{f1} vs {fh}");
    // (V₂ − V_h)/(V₁ − V_h) = (A₂/A₁)² near the Hopf point (3 %).
    let law = ((v2 - vh) / (v1 - vh)) / (a2 / a1).powi(2);
    assert!((law - 1.0).abs() < 0.03, "A² law off by {law}");
    // The branch of pure slip stalls where the orbit's velocity amplitude
    // ωA reaches the belt speed; from there it goes on with stick imposed
    // as a constraint, to the range's end, where the orbit is stick-slip:
    // ωA stays near V (the slip phase's speed amplitude, 1 %).
    let slip = pts
        .iter()
        .take_while(|p| p["stick_constraint"] == false)
        .count();
    assert!(slip >= 3 && slip < pts.len(), "{br}");
    let speed = |k: usize| {
        let (v, a, f) = at(k);
        (std::f64::consts::TAU * f * a, v)
    };
    let (s, v) = speed(slip - 1);
    assert!((s - v).abs() <= 2e-3 * v, "{s} vs {v}");
    // The stick-slip leg starts with a small step from the corner where
    // the two branches meet: no gap there (it was 2.5 grid spacings when
    // the leg's first step followed the slip branch's tangent at full
    // length).
    let gap = at(slip).0 - at(slip - 1).0;
    assert!(gap > 0.0 && gap < 0.25 * 0.01, "first stick step {gap}");
    assert!(br["end"].as_str().unwrap().starts_with("reached"), "{br}");
    assert!(pts[slip..].iter().all(|p| p["stick_constraint"] == true));
    let (s, v) = speed(pts.len() - 1);
    assert!(
        (v - 0.1).abs() < 1e-12 && (s - v).abs() <= 1e-2 * v,
        "{s} vs {v}"
    );
    assert!(br["warnings"][0]
        .as_str()
        .unwrap()
        .contains("continued with stick as a constraint"));
}

/// Hoffmann's model: no orbit at μ = 0.1, the branch from its Hopf point
/// (vertical while the model is linear, then bent by contact loss); on it,
/// HB equals shooting at the same μ.
#[test]
fn hb_param_from_the_hopf_point_equals_shooting_on_the_branch() {
    let d = tempfile::tempdir().unwrap();
    let br = json_of(&squeal(
        d.path(),
        &["hb", "hoffmann", "--param", "mu=0.1:0.5:9", "--json"],
    ));
    assert!(br["start"].is_null());
    let mu_c = br["hopf"]["value"].as_f64().unwrap();
    assert!((mu_c - 0.2501375).abs() < 1e-6, "{mu_c}");
    assert_eq!(br["folds"].as_array().unwrap().len(), 0, "{br}");
    // The branch's point nearest μ = `target`, and `squeal cycle` there.
    let near = |target: f64| {
        let p = br["points"]
            .as_array()
            .unwrap()
            .iter()
            .min_by(|a, b| {
                let d = |p: &serde_json::Value| (p["value"].as_f64().unwrap() - target).abs();
                d(a).total_cmp(&d(b))
            })
            .unwrap()
            .clone();
        let mu = p["value"].as_f64().unwrap();
        let cy = json_of(&squeal(
            d.path(),
            &["cycle", "hoffmann", "--set", &format!("mu={mu}"), "--json"],
        ));
        (mu, p, cy)
    };
    let (mu, p, cy) = near(0.3);
    assert!((mu - 0.3).abs() < 0.01, "{mu}");
    let (fh, fc) = (
        p["freq_hz"].as_f64().unwrap(),
        cy["frequency_hz"].as_f64().unwrap(),
    );
    assert!((fh - fc).abs() <= 1e-8 * fc, "{fh} vs {fc}");
    let (ah, ac) = (
        p["amplitude"]["y"].as_f64().unwrap(),
        cy["amplitude"]["y"].as_f64().unwrap(),
    );
    assert!((ah - ac).abs() <= 1e-4 * ac, "{ah} vs {ac}");
    // From μ ≈ 0.3102 the orbit sticks: the branch goes on to the range's
    // end with stick as a constraint, and says so. Near μ = 0.4 (stick 12 %,
    // no contact 48 % of the period) its frequency is shooting's to 5.4e-4
    // at H = 20 (the amplitude of y to 6 %; `hb --harmonics 80` there: 7.5e-5
    // and 0.8 %, the algebraic convergence of stick with contact loss).
    assert!(
        br["end"].as_str().unwrap().contains("reached"),
        "{}",
        br["end"]
    );
    assert!(
        br["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("stick as a constraint")),
        "{}",
        br["warnings"]
    );
    let (mu, p, cy) = near(0.4);
    assert!((mu - 0.4).abs() < 0.02, "{mu}");
    let (fh, fc) = (
        p["freq_hz"].as_f64().unwrap(),
        cy["frequency_hz"].as_f64().unwrap(),
    );
    assert!((fh - fc).abs() <= 1e-3 * fc, "μ = {mu}: {fh} vs {fc}");
}
