//! Issue 26 §4: levers for any model — sensitivities from left and right
//! eigenvectors (against closed forms, an exact scaling identity and finite
//! differences), smallest changes with their stable windows inside each
//! parameter's physical range, and changes that only move the squeal.

use crate::cli_common::{json, squeal};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn fe_brake() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/fe-brake/two-pad/brake.toml")
}

fn sensitivity<'a>(doc: &'a Value, p: &str) -> &'a Value {
    doc["sensitivities"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["param"] == p)
        .unwrap_or_else(|| panic!("no sensitivity for {p}: {}", doc["sensitivities"]))
}

/// The eigenvalue nearest `(re, im)` in a `stability --json` document.
fn nearest(doc: &Value, re: f64, im: f64) -> (f64, f64) {
    crate::cli_common::eigenvalues(doc)
        .into_iter()
        .filter(|e| e.1 >= 0.0)
        .min_by(|a, b| {
            let d = |e: &(f64, f64)| (e.0 - re).hypot(e.1 - im);
            d(a).total_cmp(&d(b))
        })
        .unwrap()
}

/// Two oscillators on belts with the thesis law (slope dμ/dV = −f0 f1 (1 −
/// V/Uc) = −0.036 at V = 1 m/s), loaded by `P` and `130 − P`: each grows
/// iff its load times 0.036 exceeds its damping 2 kg/s. At P = 100 the
/// 15.9 Hz one grows (σ = (3.6 − 2)/2 = 0.8 1/s) and the 31.8 Hz one is
/// damped; lowering P below 74.44 makes the 31.8 Hz one grow and below
/// 55.56 stops the 15.9 Hz one: lowering P only moves the squeal.
const TWO_BELTS: &str = r#"
name = "two-belts"
model = "lumped"
dofs = ["x", "y"]

[params]
P = 100.0

[masses]
x = 1.0
y = 1.0

[[spring]]
name = "sx"
on = { x = 1.0 }
k = 1.0e4
c = 2.0

[[spring]]
name = "sy"
on = { y = 1.0 }
k = 4.0e4
c = 2.0

[[contact]]
name = "bx"
normal_force = "P"
tangent = { x = -1.0 }
V = 1.0
friction = "thesis"
f0 = 0.4
f1 = 0.1
Uc = 10.0

[[contact]]
name = "by"
normal_force = "130 - P"
tangent = { y = -1.0 }
V = 1.0
friction = "thesis"
f0 = 0.4
f1 = 0.1
Uc = 10.0
"#;

/// Sensitivities against their closed forms, and the move of the squeal
/// from one oscillator to the other at the value where the first stops.
#[test]
fn levers_of_two_belts_match_the_closed_forms() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("belts.toml"), TWO_BELTS).unwrap();
    let doc = json(&squeal(d.path(), &["stability", "belts.toml", "--json"]));
    let slope = 0.4 * 0.1 * (1.0 - 1.0 / 10.0);
    // σ = (N·|μ'| − c)/(2m) for the growing x oscillator.
    for (p, exact) in [
        ("sx.c", -0.5),
        ("P", slope / 2.0),
        ("bx.normal_force", slope / 2.0),
        ("bx.f1", 100.0 * 0.4 * 0.9 / 2.0),
        ("sy.c", 0.0),
    ] {
        let got = sensitivity(&doc, p)["d_growth_rate"].as_f64().unwrap();
        assert!(
            (got - exact).abs() <= 1e-8 * exact.abs().max(1.0),
            "dσ/d{p} = {got} vs {exact}"
        );
    }
    // Raising sx.c to N|μ'| = 3.6 stops it; nothing grows again up to ×1000.
    let lever = doc["levers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["param"] == "sx.c" && l["way"] == "raise")
        .unwrap_or_else(|| panic!("{}", doc["levers"]));
    let to = lever["to"].as_f64().unwrap();
    assert!((to - 100.0 * slope).abs() <= 1e-9 * to, "{lever}");
    assert_eq!(lever["stops"], true);
    assert!(lever["stable_until"].is_null(), "{lever}");
    assert!((lever["relative_change"].as_f64().unwrap() - (to - 2.0) / 2.0).abs() < 1e-12);
    // Lowering P: no stable window (the y oscillator grows below 79.49), and
    // at P = c/|μ'| = 55.56 the 15.9 Hz mode stops while the 31.8 Hz one grows.
    assert!(
        !doc["levers"]
            .as_array()
            .unwrap()
            .iter()
            .any(|l| l["param"] == "P"),
        "{}",
        doc["levers"]
    );
    let mv = doc["mode_moves"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["param"] == "P")
        .unwrap_or_else(|| panic!("no move: {}", doc["mode_moves"]));
    assert_eq!(mv["way"], "lower");
    let at = mv["at"].as_f64().unwrap();
    assert!((at - 2.0 / slope).abs() <= 1e-4 * at, "{mv}");
    let (fx, fy) = (
        1e2 / (2.0 * std::f64::consts::PI),
        2e2 / (2.0 * std::f64::consts::PI),
    );
    assert!((mv["stops_hz"].as_f64().unwrap() - fx).abs() < 0.01, "{mv}");
    assert!((mv["grows_hz"].as_f64().unwrap() - fy).abs() < 0.01, "{mv}");
    assert_eq!(mv["already_growing"], false);
    let text = crate::cli_common::ok(&squeal(d.path(), &["stability", "belts.toml"]));
    assert!(text.contains("lowering P only moves the squeal"), "{text}");
}

/// On the FE brake: each sensitivity equals a central difference of the
/// eigenvalue (computed by separate runs), and the time-scaling identity
/// M → M/s², C → C/s, λ → sλ gives −2 dλ/dM_scale − dλ/dC_scale = λ
/// exactly (the contacts are undamped and Coulomb friction has no slope).
#[test]
fn fe_brake_sensitivities_match_differences_and_the_scaling_identity() {
    let d = tempfile::tempdir().unwrap();
    let sc = fe_brake();
    let sc = sc.to_str().unwrap();
    let doc = json(&squeal(d.path(), &["stability", sc, "--json"]));
    let lam = &doc["sensitivity_of"];
    let (re, im) = (lam["re"].as_f64().unwrap(), lam["im"].as_f64().unwrap());
    let two_pi = 2.0 * std::f64::consts::PI;
    let (sm, sc_) = (
        sensitivity(&doc, "matrices.M_scale"),
        sensitivity(&doc, "matrices.C_scale"),
    );
    let id_re =
        -2.0 * sm["d_growth_rate"].as_f64().unwrap() - sc_["d_growth_rate"].as_f64().unwrap();
    let id_im =
        two_pi * (-2.0 * sm["d_freq_hz"].as_f64().unwrap() - sc_["d_freq_hz"].as_f64().unwrap());
    let mag = re.hypot(im);
    assert!((id_re - re).abs() <= 1e-7 * mag, "{id_re} vs σ = {re}");
    assert!((id_im - im).abs() <= 1e-7 * mag, "{id_im} vs ω = {im}");
    for p in ["mu", "inner.k", "outer.mu_k", "matrices.K_scale"] {
        let s = sensitivity(&doc, p);
        assert_eq!(s["method"], "eigenvectors");
        let v = s["value"].as_f64().unwrap();
        let h = 1e-4 * v;
        let at = |x: f64| {
            let set = format!("{p}={x:e}");
            let o = json(&squeal(
                d.path(),
                &["stability", sc, "--json", "--no-levers", "--set", &set],
            ));
            nearest(&o, re, im)
        };
        let (up, down) = (at(v + h), at(v - h));
        let fd = (up.0 - down.0) / (2.0 * h);
        let got = s["d_growth_rate"].as_f64().unwrap();
        // Central difference: O(h²) ≈ 1e-8 relative, plus the round-off of σ
        // (≈ 1e-12·|λ|) over 2h.
        let tol = 1e-5 * got.abs() + 1e-11 * mag / (2.0 * h);
        assert!((got - fd).abs() <= tol, "dσ/d{p}: {got} vs difference {fd}");
    }
    // Parameters steady sliding does not depend on are said so, with no lever.
    let inert: Vec<&str> = doc["inert_params"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert!(
        inert.contains(&"inner.mu_s") && inert.contains(&"outer.V"),
        "{inert:?}"
    );
}

/// Every lever of the FE brake is a true boundary (the verdict differs just
/// before and just after it, and again across the end of its window), keeps
/// the parameter in its physical range, and the levers are ranked by the
/// relative change they need.
#[test]
fn fe_brake_levers_are_boundaries_inside_the_physical_range() {
    let d = tempfile::tempdir().unwrap();
    let sc = fe_brake();
    let sc = sc.to_str().unwrap();
    let doc = json(&squeal(d.path(), &["stability", sc, "--json"]));
    assert_eq!(doc["verdict"], "unstable");
    let levers = doc["levers"].as_array().unwrap();
    assert!(levers.len() >= 3, "{levers:?}");
    let growth = |p: &str, v: f64| {
        let set = format!("{p}={v:e}");
        json(&squeal(
            d.path(),
            &["stability", sc, "--json", "--no-levers", "--set", &set],
        ))["max_growth_rate"]
            .as_f64()
            .unwrap()
    };
    let mut last = 0.0;
    for l in levers {
        let (p, from, to) = (
            l["param"].as_str().unwrap(),
            l["from"].as_f64().unwrap(),
            l["to"].as_f64().unwrap(),
        );
        assert!(to * from > 0.0, "a lever keeps the sign: {l}");
        let rel = l["relative_change"].as_f64().unwrap().abs();
        assert!(rel >= last, "ranked by relative change: {levers:?}");
        last = rel;
        let dir = (to - from).signum();
        let eps = 1e-6 * to.abs();
        assert!(growth(p, to - dir * eps) > 0.0, "{p} before {to}");
        assert!(growth(p, to + dir * eps) < 0.0, "{p} after {to}");
        if let Some(u) = l["stable_until"]["value"].as_f64() {
            let e = 1e-6 * u.abs();
            assert!(growth(p, u - dir * e) < 0.0, "{p} inside its window at {u}");
            assert!(growth(p, u + dir * e) > 0.0, "{p} past its window at {u}");
        }
    }
}
