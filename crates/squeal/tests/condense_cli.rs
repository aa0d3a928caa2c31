//! Dofs without mass in exported matrices (issue 26 §2): condensed
//! statically before any analysis, stated by `inspect`, refused by name
//! where an element acts on them. Checked against the closed form of a
//! chain with a massless middle node (two springs in series).

use crate::cli_common::{ok, squeal};
use std::path::Path;

/// Two masses `m` on ground springs `k0`, joined through a massless node
/// `2_1` by springs `k1` and `k2` (series: `ks = k1 k2 / (k1 + k2)`), in
/// DMIG; a prescribed-load contact on dof 1_1 (it does not change the
/// stiffness): the undamped frequencies are `√(k0/m)` and
/// `√((k0 + 2 ks)/m)`.
fn write_chain(dir: &Path, contact_dof: &str) {
    let (m, k0, k1, k2) = (2.0, 1.0e6, 3.0e6, 6.0e6);
    let k = [
        (1, 1, k0 + k1),
        (2, 1, -k1),
        (2, 2, k1 + k2),
        (3, 2, -k2),
        (3, 3, k0 + k2),
    ];
    let mut pch = String::from("DMIG,KAAX,0,6,2,0,,,3\n");
    for (i, j, v) in k {
        // Column j, row i (lower triangle), grids 1, 2, 3 component 1.
        pch += &format!("DMIG,KAAX,{j},1,,{i},1,{v:?}\n");
    }
    pch += "DMIG,MAAX,0,6,2,0,,,3\n";
    pch += &format!("DMIG,MAAX,1,1,,1,1,{m:?}\nDMIG,MAAX,3,1,,3,1,{m:?}\n");
    std::fs::write(dir.join("chain.pch"), pch).unwrap();
    let sc = format!(
        r#"name = "chain"
model = "lumped"

[matrices]
M = {{ file = "chain.pch", name = "MAAX" }}
K = {{ file = "chain.pch", name = "KAAX" }}

[[contact]]
name = "belt"
normal_force = 10.0
tangent = {{ {contact_dof} = -1.0 }}
V = 1.0
friction = "coulomb"
mu_s = 0.3
mu_k = 0.3
"#
    );
    std::fs::write(dir.join("chain.toml"), sc).unwrap();
}

#[test]
fn massless_dofs_are_condensed_to_the_closed_form() {
    let d = tempfile::tempdir().unwrap();
    write_chain(d.path(), "1_1");
    let (m, k0, k1, k2) = (2.0f64, 1.0e6f64, 3.0e6f64, 6.0e6f64);
    let ks = k1 * k2 / (k1 + k2);
    let want = [(k0 / m).sqrt(), ((k0 + 2.0 * ks) / m).sqrt()];
    let v: serde_json::Value = serde_json::from_str(&ok(&squeal(
        d.path(),
        &["stability", "chain.toml", "--json"],
    )))
    .unwrap();
    let mut got: Vec<f64> = v["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["im"].as_f64().unwrap())
        .filter(|w| *w > 0.0)
        .collect();
    got.sort_by(f64::total_cmp);
    assert_eq!(got.len(), 2);
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= 1e-12 * w, "{g} against {w}");
    }
    let i: serde_json::Value =
        serde_json::from_str(&ok(&squeal(d.path(), &["inspect", "chain.toml", "--json"]))).unwrap();
    assert_eq!(i["dof_count"], 2);
    assert_eq!(i["condensed"], serde_json::json!(["2_1"]));
    let text = ok(&squeal(d.path(), &["inspect", "chain.toml"]));
    assert!(
        text.contains("condensed statically: 1 dofs without mass (2_1)"),
        "{text}"
    );
}

#[test]
fn an_element_on_a_massless_dof_is_refused_by_name() {
    let d = tempfile::tempdir().unwrap();
    write_chain(d.path(), "2_1");
    let out = squeal(d.path(), &["stability", "chain.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("contact 'belt': tangent: dof '2_1' has no mass"),
        "{e}"
    );
}

fn frequencies(dir: &Path, args: &[&str]) -> Vec<f64> {
    let mut all = vec!["stability", "chain.toml", "--json"];
    all.extend(args);
    let v: serde_json::Value = serde_json::from_str(&ok(&squeal(dir, &all))).unwrap();
    let mut w: Vec<f64> = v["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["im"].as_f64().unwrap())
        .filter(|w| *w > 0.0)
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

/// `matrices.K_scale` and `matrices.M_scale` (issue 26 §4's per-file
/// levers): an undamped structure's frequencies scale by √(K_scale/M_scale)
/// exactly; in the file or by --set alike; a negative scale is refused.
#[test]
fn matrix_scale_keys_scale_the_frequencies_exactly() {
    let d = tempfile::tempdir().unwrap();
    write_chain(d.path(), "1_1");
    let base = frequencies(d.path(), &[]);
    let k2 = frequencies(d.path(), &["--set", "matrices.K_scale=2"]);
    let m4 = frequencies(d.path(), &["--set", "matrices.M_scale=4"]);
    for i in 0..2 {
        assert!((k2[i] - base[i] * 2f64.sqrt()).abs() <= 1e-12 * k2[i]);
        assert!((m4[i] - base[i] / 2.0).abs() <= 1e-12 * m4[i]);
    }
    let text = std::fs::read_to_string(d.path().join("chain.toml")).unwrap();
    std::fs::write(
        d.path().join("chain.toml"),
        text.replace("[matrices]\n", "[matrices]\nK_scale = 2.0\n"),
    )
    .unwrap();
    assert_eq!(frequencies(d.path(), &[]), k2);
    let out = squeal(
        d.path(),
        &["stability", "chain.toml", "--set", "matrices.K_scale=-1"],
    );
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("matrices.K_scale = -1"), "{e}");
    let out = squeal(
        d.path(),
        &["stability", "chain.toml", "--set", "matrices.C_scale=2"],
    );
    assert_eq!(out.status.code(), Some(2), "no C matrix: no C_scale");
}
