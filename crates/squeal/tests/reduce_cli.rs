//! `squeal reduce` (issue 27 §2–3): the 124-dof two-pad FE brake reduced by
//! Craig–Bampton and written as a scenario that `stability`, `simulate` and
//! `cycle` read. Checked against the unreduced model's dense complex
//! eigenvalue analysis (exact to round-off at 124 dofs).

use crate::cli_common::{eigenvalues, json, ok, refused, squeal};
use std::path::{Path, PathBuf};

fn brake() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/fe-brake/two-pad/brake.toml")
}

/// `examples/fe-brake/disc-reduced`: an FE disc of 2164 dofs reduced to 18.
fn disc_reduced() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/fe-brake/disc-reduced/scenario.toml")
}

/// The unstable eigenvalue (largest real part) of `stability --json`.
fn unstable(v: &serde_json::Value) -> (f64, f64) {
    eigenvalues(v)
        .into_iter()
        .filter(|e| e.1 >= 0.0)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap()
}

fn rel(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1) / b.0.hypot(b.1)
}

fn reduce(dir: &Path, out: &str, sets: &[&str]) -> serde_json::Value {
    let b = brake();
    let mut args = vec!["reduce", b.to_str().unwrap(), "--out", out, "--json"];
    for s in sets {
        args.extend(["--set", s]);
    }
    json(&squeal(dir, &args))
}

/// The unstable eigenvalue of the reduced model against the full one's as
/// the fixed-interface modes grow (measured: 2.0e-1 with modes to 496 Hz,
/// 2.1e-3 to 1.13 kHz, 3.6e-4 to 1.64 kHz, 3.4e-5 to 4.8 kHz, 3.1e-7 with
/// the default cut-off, 40 kHz): the error falls, is below 1e-3 once the
/// modes reach 2.4× the squeal frequency (696.5 Hz), and the reduced
/// model keeps the contact and force dofs by name.
#[test]
fn the_reduced_brake_converges_on_the_full_one() {
    let d = tempfile::tempdir().unwrap();
    let b = brake();
    let full = unstable(&json(&squeal(
        d.path(),
        &["stability", b.to_str().unwrap(), "--json"],
    )));
    assert!(
        full.0 > 300.0 && (full.1 / std::f64::consts::TAU - 696.48).abs() < 0.01,
        "{full:?}"
    );
    let mut errors = Vec::new();
    for (k, f) in ["700", "2100", "40000"].iter().enumerate() {
        let out = format!("r{k}");
        let rec = reduce(d.path(), &out, &[&format!("modal.cutoff_hz={f}")]);
        let boundary: Vec<&str> = rec["boundary"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        assert_eq!(
            boundary,
            ["6_1", "6_3", "6_5", "9001_1", "9001_3", "9002_1", "9002_3"]
        );
        assert_eq!(rec["dofs"], 124);
        assert_eq!(rec["interior_modes"], 117);
        let path = d.path().join(&out).join("scenario.toml");
        for file in ["M.mtx", "K.mtx", "C.mtx", "reduce.json"] {
            assert!(d.path().join(&out).join(file).is_file(), "{file}");
        }
        let red = unstable(&json(&squeal(
            d.path(),
            &["stability", path.to_str().unwrap(), "--json"],
        )));
        errors.push(rel(red, full));
    }
    assert!(errors[0] > 0.1, "{errors:?}");
    assert!(errors[1] < 1e-3, "{errors:?}");
    assert!(errors[2] < 1e-6, "{errors:?}");
}

/// The scale keys and shared parameters act on the reduced model as on the
/// full one (`T` depends on neither): the same `--set` on both gives the
/// same unstable eigenvalue to the reduction's own error.
#[test]
fn parameters_act_on_the_reduced_model_as_on_the_full_one() {
    let d = tempfile::tempdir().unwrap();
    let b = brake();
    reduce(d.path(), "r", &[]);
    let path = d.path().join("r/scenario.toml");
    for set in ["matrices.K_scale=1.21", "mu=0.6", "matrices.M_scale=0.8"] {
        let full = unstable(&json(&squeal(
            d.path(),
            &["stability", b.to_str().unwrap(), "--set", set, "--json"],
        )));
        let red = unstable(&json(&squeal(
            d.path(),
            &["stability", path.to_str().unwrap(), "--set", set, "--json"],
        )));
        assert!(rel(red, full) < 1e-6, "{set}: {red:?} vs {full:?}");
    }
}

/// The reduced brake simulates (the full one has more dofs than a run
/// allows): its squeal frequency within 1 % of the reduced CEA's unstable
/// mode, its measured growth rate within 1 % of the eigenvalue's.
#[test]
fn the_reduced_brake_simulates_and_squeals_at_its_eigenfrequency() {
    let d = tempfile::tempdir().unwrap();
    reduce(d.path(), "r", &[]);
    let path = d.path().join("r/scenario.toml");
    let p = path.to_str().unwrap();
    let lin = unstable(&json(&squeal(d.path(), &["stability", p, "--json"])));
    ok(&squeal(d.path(), &["simulate", p, "--out", "run"]));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("run/summary.json")).unwrap())
            .unwrap();
    let f = s["squeal"]["frequency_hz"].as_f64().unwrap();
    let f_lin = lin.1 / std::f64::consts::TAU;
    assert!((f - f_lin).abs() <= 0.01 * f_lin, "{f} vs {f_lin}");
    assert_eq!(s["verdict"], "grows", "{}", s["verdict"]);
}

/// What cannot be reduced is refused in one line, and nothing is written.
#[test]
fn what_cannot_be_reduced_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let e = refused(&squeal(d.path(), &["reduce", "disc-pad", "--out", "x"]));
    assert!(e.contains("only a lumped model with [matrices]"), "{e}");
    assert!(!d.path().join("x").exists());
    std::fs::write(
        d.path().join("elements.toml"),
        "name = \"e\"\nmodel = \"lumped\"\ndofs = [\"a\"]\n[masses]\na = 1.0\n[[spring]]\nname = \"s\"\non = { a = 1.0 }\nk = 1.0\n",
    )
    .unwrap();
    let e = refused(&squeal(
        d.path(),
        &["reduce", "elements.toml", "--out", "x"],
    ));
    assert!(e.contains("no M and K matrix files"), "{e}");
    assert!(!d.path().join("x").exists());
}

/// `modal.basis = "craig-bampton"` in the projected CEA spans the same
/// space as `squeal reduce` (so the same unstable eigenvalue, to the
/// solvers' round-off), says so, and its truncation table grows the
/// fixed-interface modes; a bad value is refused naming the key.
#[test]
fn the_projected_analysis_takes_a_craig_bampton_basis() {
    let d = tempfile::tempdir().unwrap();
    let b = brake();
    let b = b.to_str().unwrap();
    reduce(d.path(), "r", &["modal.cutoff_hz=2100"]);
    let path = d.path().join("r/scenario.toml");
    let red = unstable(&json(&squeal(
        d.path(),
        &["stability", path.to_str().unwrap(), "--json", "--no-levers"],
    )));
    let sets = [
        "--set",
        "modal.dense_max_dofs=0",
        "--set",
        "modal.cutoff_hz=2100",
        "--set",
        "modal.basis=craig-bampton",
    ];
    let mut args = vec!["stability", b, "--json", "--no-levers"];
    args.extend(sets);
    let doc = json(&squeal(d.path(), &args));
    assert_eq!(doc["modal"]["basis"], "craig-bampton", "{}", doc["modal"]);
    let cb = unstable(&doc);
    assert!(rel(cb, red) < 1e-9, "{cb:?} vs {red:?}");
    let mut args = vec!["stability", b, "--no-levers"];
    args.extend(sets);
    let text = ok(&squeal(d.path(), &args));
    assert!(
        text.contains("Craig–Bampton basis of 124 dofs: the 7 contact dofs kept physical and 5 fixed-interface modes"),
        "{text}"
    );
    let e = refused(&squeal(
        d.path(),
        &["stability", b, "--set", "modal.basis=free"],
    ));
    assert!(
        e.contains("modal.basis = 'free': expected modes or craig-bampton"),
        "{e}"
    );
}

/// A long command states what it will compute before it starts (issue 27
/// §1): an FE model's size, its files' nonzeros, the method and its
/// memory, one line on stderr; a small model's analysis says nothing.
#[test]
fn long_commands_state_what_they_will_compute() {
    let d = tempfile::tempdir().unwrap();
    let b = brake();
    let b = b.to_str().unwrap();
    let out = squeal(d.path(), &["stability", b, "--no-levers"]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("stability: two-pad: 124 dofs (C 528 nonzeros, K 528 nonzeros, M 524 nonzeros); steady sliding, then the dense complex eigenvalue problem of 248 states; up to 5 MB"),
        "{err}"
    );
    let out = squeal(
        d.path(),
        &[
            "critical",
            b,
            "--param",
            "mu=0.1:0.6",
            "--set",
            "modal.dense_max_dofs=0",
        ],
    );
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("the real modes of all 124 dofs") && err.contains(", 64 times;"),
        "{err}"
    );
    let out = squeal(d.path(), &["stability", "disc-pad", "--no-levers"]);
    ok(&out);
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The reduced brake in the other transient commands: `map --transient`
/// (its watched velocity found from the contacts' tangential dofs, which
/// FE names like `6_1` do not announce: before, every point `failed`),
/// `listen`, and with modes to 1.4 kHz (11 dofs) `cycle`, whose limit cycle
/// is stable with its 4 sticks and 2 separations a period.
#[test]
fn the_reduced_brake_maps_listens_and_cycles() {
    let d = tempfile::tempdir().unwrap();
    reduce(d.path(), "r", &[]);
    let p = d.path().join("r/scenario.toml");
    let p = p.to_str().unwrap();
    ok(&squeal(
        d.path(),
        &[
            "map",
            p,
            "--x",
            "mu=0.3:0.6:2",
            "--y",
            "Fb=1500:2500:2",
            "--transient",
            "--duration",
            "0.05",
            "--out",
            "m",
        ],
    ));
    let csv = std::fs::read_to_string(d.path().join("m/map.csv")).unwrap();
    let outcomes: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(4).unwrap())
        .collect();
    assert_eq!(outcomes.len(), 4);
    assert!(!outcomes.contains(&"failed"), "{csv}");
    assert_eq!(outcomes[1], "grows", "{csv}");
    ok(&squeal(d.path(), &["listen", p, "--out", "s.wav"]));
    assert!(d.path().join("s.wav").metadata().unwrap().len() > 1000);
    reduce(d.path(), "r11", &["modal.cutoff_hz=1400"]);
    let p11 = d.path().join("r11/scenario.toml");
    let c = json(&squeal(
        d.path(),
        &["cycle", p11.to_str().unwrap(), "--json"],
    ));
    assert_eq!(c["stable"], true, "{c}");
    let f = c["frequency_hz"].as_f64().unwrap();
    assert!((f - 605.22).abs() < 0.01, "{f}");
    assert_eq!(c["events_per_period"]["stick"], 4, "{c}");
    assert_eq!(c["events_per_period"]["separate"], 2, "{c}");
}

/// A reduced FE disc of 18 dofs (`examples/fe-brake/disc-reduced`: the
/// hexahedral disc of `make_disc.py --radial 4 --circ 48 --layers 2`,
/// 2164 dofs, reduced by `squeal reduce` to its 8 contact dofs and 10
/// fixed-interface modes to 5.8 kHz) has more dofs than the 16 compiled
/// exactly, so `cycle` runs it padded to 24 dofs, its Floquet analysis on
/// the 36 real states only: its limit cycle is stable (the pads
/// separate and touch again once each per period), at 698.31 Hz, within
/// 0.2 % of the growing eigenvalue's 697.60 Hz (`stability` of the same
/// file; the orbit's amplitude shifts it), with 36 multipliers, one of them
/// the trivial 1 (to the shooting tolerance).
#[test]
fn a_reduced_fe_disc_of_18_dofs_cycles() {
    let d = tempfile::tempdir().unwrap();
    let p = disc_reduced();
    let p = p.to_str().unwrap();
    let s = json(&squeal(
        d.path(),
        &["stability", p, "--no-levers", "--json"],
    ));
    let growing: Vec<f64> = s["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["re"].as_f64().unwrap() > 0.0 && e["im"].as_f64().unwrap() > 0.0)
        .map(|e| e["im"].as_f64().unwrap() / std::f64::consts::TAU)
        .collect();
    assert_eq!(growing.len(), 1, "{growing:?}");
    assert!((growing[0] - 697.605).abs() < 1e-2, "{growing:?}");
    let c = json(&squeal(d.path(), &["cycle", p, "--json"]));
    assert_eq!(c["stable"], true, "{c}");
    let f = c["frequency_hz"].as_f64().unwrap();
    assert!((f - growing[0]).abs() < 2e-3 * growing[0], "{f}");
    assert!((f - 698.305).abs() < 0.01, "{f}");
    let m = c["multipliers"].as_array().unwrap();
    assert_eq!(m.len(), 36, "{c}");
    let trivial: Vec<&serde_json::Value> = m.iter().filter(|x| x["trivial"] == true).collect();
    assert_eq!(trivial.len(), 1);
    assert!(
        (trivial[0]["abs"].as_f64().unwrap() - 1.0).abs() < 1e-6,
        "{c}"
    );
    let max = c["max_multiplier"].as_f64().unwrap();
    assert!(max > 0.99 && max < 1.0, "{max}");
    assert_eq!(c["amplitude"].as_object().unwrap().len(), 36, "{c}");
    assert_eq!(c["events_per_period"]["separate"], 2, "{c}");
    assert_eq!(c["events_per_period"]["contact"], 2, "{c}");
}

/// A transient map of an FE model started at its equilibrium with no
/// offset: its positions wander from their static deflection by integration
/// noise alone (a few 10⁻¹² m in 0.05 s, against the 2.6·10⁻¹¹ m of 100
/// tolerances), and its growing mode (σ = +33 1/s) stays under that noise.
/// Every point is `too-short`, with no agreement claimed either way
/// (before, one unstable point was classed `decays` by the fast modes'
/// decaying round-off and counted as disagreeing, the other `grows`), and
/// the summary says why. Given a start of 1 nm on a pad, the unstable
/// points grow and agree with the linear verdict.
#[test]
fn a_transient_map_from_round_off_says_too_short() {
    let d = tempfile::tempdir().unwrap();
    let p = disc_reduced();
    let p = p.to_str().unwrap();
    let map = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "map",
            p,
            "--x",
            "mu=0.1:0.45:2",
            "--y",
            "Fb=1000:2000:2",
            "--transient",
            "--duration",
            "0.05",
            "--set",
            "sample_rate=3e5",
            "--out",
            out,
        ];
        args.extend_from_slice(extra);
        let o = squeal(d.path(), &args);
        ok(&o);
        let csv = std::fs::read_to_string(d.path().join(out).join("map.csv")).unwrap();
        let rows: Vec<(String, String)> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                (f[4].to_string(), f[8].to_string())
            })
            .collect();
        (o, rows)
    };
    let (o, rows) = map("still", &["--json"]);
    let j = json(&o);
    assert_eq!(j["too_short"], 4, "{j}");
    assert_eq!(j["linear_nonlinear_disagree"], 0, "{j}");
    for (class, agree) in &rows {
        assert_eq!((class.as_str(), agree.as_str()), ("too-short", "n/a"));
    }
    let (o, _) = map("still-text", &[]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("4 points too-short") && text.contains("give the scenario an offset"),
        "{text}"
    );
    let svg = std::fs::read_to_string(d.path().join("still/transient.svg")).unwrap();
    assert!(svg.contains("too-short"));
    // Points 1 and 3 (μ = 0.45) are the unstable ones.
    let (_, rows) = map("kicked", &["--set", "9000001_10=1e-9"]);
    for k in [1, 3] {
        assert_eq!(
            rows[k],
            ("grows".to_string(), "yes".to_string()),
            "{rows:?}"
        );
    }
}
