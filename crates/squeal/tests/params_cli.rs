//! Shared, named parameters of lumped scenario files (issue 26 §3): a
//! `[params]` table, element values that name them or are expressions of
//! them, every command's keys (`--set`, `--param`, `sweep`), `scenario
//! show`, summary.json, `--set <contact>.friction=<law>`, and bad input.
//! Each result is checked against the same model written with numbers.

use crate::cli_common::{eigenvalues, json, ok, refused, squeal};
use std::path::Path;

/// A disc between two pads; `friction` holds the two contacts' law keys
/// (`{p}` is replaced by the pad's number), `head` goes before the
/// elements (a `[params]` table), `brake` is each brake force's value.
fn brake(head: &str, friction: &str, brake: &str) -> String {
    let mut s = format!(
        r#"name = "shared"
model = "lumped"
duration = 0.01
dofs = ["x_d", "y_d", "x_p1", "y_p1", "x_p2", "y_p2"]
{head}
[masses]
x_d = 2.0
y_d = 2.0
x_p1 = 0.1
y_p1 = 0.1
x_p2 = 0.1
y_p2 = 0.1

[[spring]]
name = "disc_x"
on = {{ x_d = 1.0 }}
k = 2.0e9
c = 2.0

[[spring]]
name = "disc_y"
on = {{ y_d = 1.0 }}
k = 1.6e7
c = 2.0

[[spring]]
name = "pad1_x"
on = {{ x_p1 = 1.0 }}
k = 1.7e9
c = 0.2

[[spring]]
name = "pad2_x"
on = {{ x_p2 = 1.0 }}
k = 1.2e9
c = 0.2
"#
    );
    for (p, sign, normal) in [
        (1, -1.0, "{ y_d = 1.0, y_p1 = -1.0 }"),
        (2, 1.0, "{ y_p2 = 1.0, y_d = -1.0 }"),
    ] {
        let value = brake.replace("{s}", if sign < 0.0 { "-" } else { "" });
        s += &format!(
            r#"
[[force]]
name = "brake_{p}"
on = {{ y_p{p} = 1.0 }}
value = {value}

[[contact]]
name = "pad{p}"
normal = {normal}
k = 4.0e9
c = 0.2
tangent = {{ x_d = 1.0, x_p{p} = -1.0 }}
V = 1.0
{}
"#,
            friction.replace("{p}", &p.to_string())
        );
    }
    s
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    std::fs::write(dir.join(name), text).unwrap();
    name.into()
}

const SHARED_HEAD: &str = "\n[params]\nmu = 0.3\nFb = 1000.0\n";
const SHARED_LAW: &str =
    "friction = \"stribeck\"\nmu_k = \"mu\"\nmu_s = \"1.2*mu\"\nv_s = 2.0\ndelta = 2.0";

#[test]
fn shared_parameters_set_every_key_bound_to_them() {
    let d = tempfile::tempdir().unwrap();
    let shared = write(
        d.path(),
        "shared.toml",
        &brake(SHARED_HEAD, SHARED_LAW, "\"{s}Fb/2\""),
    );
    // The same model with the numbers of mu = 0.45, Fb = 1600 written out.
    let plain = write(
        d.path(),
        "plain.toml",
        &brake(
            "",
            "friction = \"stribeck\"\nmu_k = 0.45\nmu_s = 0.54\nv_s = 2.0\ndelta = 2.0",
            "{s}800.0",
        ),
    );
    let a = json(&squeal(
        d.path(),
        &[
            "stability",
            &shared,
            "--json",
            "--set",
            "mu=0.45",
            "--set",
            "Fb=1600",
        ],
    ));
    let b = json(&squeal(d.path(), &["stability", &plain, "--json"]));
    let (ea, eb) = (eigenvalues(&a), eigenvalues(&b));
    assert_eq!(ea.len(), 12);
    for (x, y) in ea.iter().zip(&eb) {
        // 1.2*0.45 is 0.54 to one ulp: the eigenvalues agree to round-off.
        let mag = y.0.hypot(y.1);
        assert!(
            (x.0 - y.0).abs() <= 1e-12 * mag && (x.1 - y.1).abs() <= 1e-12 * mag,
            "{x:?} vs {y:?}"
        );
    }
    // A bound key set directly takes the number and leaves the others bound.
    let c = json(&squeal(
        d.path(),
        &[
            "stability",
            &shared,
            "--json",
            "--set",
            "mu=0.45",
            "--set",
            "Fb=1600",
            "--set",
            "pad2.mu_k=0.2",
        ],
    ));
    assert_ne!(eigenvalues(&c), ea);
    // `scenario show` prints the expressions with their values.
    let shown = ok(&squeal(d.path(), &["scenario", "show", &shared]));
    assert!(
        shown.contains("[params]") && shown.contains("\nFb = 1000.0\nmu = 0.3\n"),
        "{shown}"
    );
    assert!(shown.contains("mu_s = \"1.2*mu\"  # = 0.36"), "{shown}");
    assert!(shown.contains("value = \"-Fb/2\"  # = -500.0"), "{shown}");
    // Shown, it reads back as the same model.
    let again = write(d.path(), "again.toml", &shown);
    let e = json(&squeal(
        d.path(),
        &[
            "stability",
            &again,
            "--json",
            "--set",
            "mu=0.45",
            "--set",
            "Fb=1600",
        ],
    ));
    assert_eq!(eigenvalues(&e), ea);
    // summary.json records each expression with its value.
    ok(&squeal(
        d.path(),
        &["simulate", &shared, "--set", "mu=0.4", "--out", "run"],
    ));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("run/summary.json")).unwrap())
            .unwrap();
    let ex = &summary["scenario"]["expressions"];
    assert_eq!(ex["pad1.mu_k"]["expr"], "mu");
    assert_eq!(ex["pad1.mu_k"]["value"], 0.4);
    assert_eq!(ex["pad2.mu_s"]["expr"], "1.2*mu");
    assert!((ex["pad2.mu_s"]["value"].as_f64().unwrap() - 0.48).abs() < 1e-15);
    assert_eq!(summary["scenario"]["params"]["mu"], 0.4);
}

#[test]
fn a_sweep_over_a_shared_parameter_moves_every_pad() {
    let d = tempfile::tempdir().unwrap();
    let shared = write(
        d.path(),
        "shared.toml",
        &brake(SHARED_HEAD, SHARED_LAW, "\"{s}Fb/2\""),
    );
    ok(&squeal(
        d.path(),
        &["sweep", &shared, "--param", "mu=0.2:0.5:4", "--out", "sw"],
    ));
    let csv = std::fs::read_to_string(d.path().join("sw/sweep.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "mu,mode,growth_rate,freq_hz,damping_ratio"
    );
    // The largest growth rate at each value, against `stability` there.
    let mut best: Vec<(f64, f64)> = Vec::new();
    for l in lines {
        let r: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        match best.iter_mut().find(|(mu, _)| *mu == r[0]) {
            Some(b) => b.1 = b.1.max(r[2]),
            None => best.push((r[0], r[2])),
        }
    }
    assert_eq!(best.len(), 4);
    for (mu, growth) in best {
        let one = json(&squeal(
            d.path(),
            &["stability", &shared, "--json", "--set", &format!("mu={mu}")],
        ));
        let want = one["max_growth_rate"].as_f64().unwrap();
        assert!(
            (growth - want).abs() <= 1e-9 * want.abs().max(1.0),
            "mu = {mu}: {growth} vs {want}"
        );
    }
}

#[test]
fn a_contacts_law_is_switched_with_its_keys() {
    let d = tempfile::tempdir().unwrap();
    let thesis = write(
        d.path(),
        "thesis.toml",
        &brake("", "friction = \"thesis\"", "{s}500.0"),
    );
    let coulomb = write(
        d.path(),
        "coulomb.toml",
        &brake(
            "",
            "friction = \"coulomb\"\nmu_s = 0.5\nmu_k = 0.4",
            "{s}500.0",
        ),
    );
    let e = refused(&squeal(
        d.path(),
        &[
            "stability",
            &thesis,
            "--set",
            "pad1.friction=coulomb",
            "--set",
            "pad1.mu_k=0.4",
        ],
    ));
    assert!(
        e.contains("pad1.friction=coulomb") && e.contains("missing: pad1.mu_s"),
        "{e}"
    );
    let sets = [
        "--set",
        "pad1.friction=coulomb",
        "--set",
        "pad1.mu_s=0.5",
        "--set",
        "pad1.mu_k=0.4",
        "--set",
        "pad2.friction=coulomb",
        "--set",
        "pad2.mu_s=0.5",
        "--set",
        "pad2.mu_k=0.4",
    ];
    let mut args = vec!["stability", thesis.as_str(), "--json"];
    args.extend(sets);
    let a = json(&squeal(d.path(), &args));
    let b = json(&squeal(d.path(), &["stability", &coulomb, "--json"]));
    assert_eq!(eigenvalues(&a), eigenvalues(&b));
    let e = refused(&squeal(
        d.path(),
        &["stability", &thesis, "--set", "pad1.friction=viscous"],
    ));
    assert!(
        e.contains("pad1.friction=viscous") && e.contains("coulomb"),
        "{e}"
    );
}

#[test]
fn bad_parameters_and_expressions_are_refused_naming_the_key() {
    let d = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &str, &[&str]); 5] = [
        (
            SHARED_HEAD,
            "friction = \"coulomb\"\nmu_k = \"nu\"\nmu_s = 0.5",
            "{s}500.0",
            &[
                "contact 'pad1'",
                "pad1.mu_k = \"nu\"",
                "'nu' is not a parameter",
                "Fb, mu",
            ],
        ),
        (
            SHARED_HEAD,
            "friction = \"coulomb\"\nmu_k = \"2*(mu\"\nmu_s = 0.5",
            "{s}500.0",
            &["pad1.mu_k = \"2*(mu\"", "not an expression"],
        ),
        (
            "\n[params]\n\"a.b\" = 1.0\n",
            "friction = \"thesis\"",
            "{s}500.0",
            &["params", "'a.b' is not a parameter name"],
        ),
        (
            "\n[params]\nmu = \"x\"\n",
            "friction = \"thesis\"",
            "{s}500.0",
            &["params: mu = \"x\": expected a number"],
        ),
        (
            SHARED_HEAD,
            "friction = \"coulomb\"\nmu_k = \"mu\"\nmu_s = \"0.5*mu\"",
            "{s}500.0",
            &["pad1.mu_s", "mu_k"],
        ),
    ];
    for (i, (head, law, load, want)) in cases.iter().enumerate() {
        let f = write(d.path(), &format!("bad{i}.toml"), &brake(head, law, load));
        let e = refused(&squeal(d.path(), &["stability", &f]));
        for w in *want {
            assert!(e.contains(w), "case {i}: '{w}' not in {e}");
        }
    }
    // A coefficient of a combination takes a number.
    let text = brake(SHARED_HEAD, "friction = \"thesis\"", "{s}500.0")
        .replace("on = { x_d = 1.0 }", "on = { x_d = \"mu\" }");
    let f = write(d.path(), "coef.toml", &text);
    let e = refused(&squeal(d.path(), &["stability", &f]));
    assert!(
        e.contains("spring 'disc_x': on.x_d = \"mu\": expected a number"),
        "{e}"
    );
    // --set takes numbers for a shared parameter too, and a value that
    // breaks a relation names the parameter and the key it moved.
    let f = write(
        d.path(),
        "ok.toml",
        &brake(SHARED_HEAD, SHARED_LAW, "\"{s}Fb/2\""),
    );
    let e = refused(&squeal(d.path(), &["stability", &f, "--set", "mu=abc"]));
    assert!(e.contains("mu"), "{e}");
    let e = refused(&squeal(d.path(), &["stability", &f, "--set", "mu=-1"]));
    assert!(
        e.contains("mu = -1: makes pad1.mu_s = -1.2: must be ≥ 0"),
        "{e}"
    );
}

/// The shipped symmetric two-pad brake shares its pads' friction law:
/// `--set f1=…` moves both pads, as setting each pad does.
#[test]
fn the_shipped_two_pad_brake_shares_its_friction_law() {
    let d = tempfile::tempdir().unwrap();
    let a = json(&squeal(
        d.path(),
        &["stability", "two-pad-brake", "--json", "--set", "f1=0.03"],
    ));
    let b = json(&squeal(
        d.path(),
        &[
            "stability",
            "two-pad-brake",
            "--json",
            "--set",
            "pad1.f1=0.03",
            "--set",
            "pad2.f1=0.03",
        ],
    ));
    assert_eq!(eigenvalues(&a), eigenvalues(&b));
    let c = json(&squeal(d.path(), &["stability", "two-pad-brake", "--json"]));
    assert_ne!(eigenvalues(&a), eigenvalues(&c));
    let shown = ok(&squeal(d.path(), &["scenario", "show", "two-pad-brake"]));
    assert!(
        shown.contains("f1 = \"f1\"  # = 0.06666666666666667"),
        "{shown}"
    );
}
