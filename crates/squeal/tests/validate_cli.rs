//! `squeal validate` (issue 28 §6): every case passes, the JSON keys are the
//! public ones, kinds are valid, the named cases are there; a filter that
//! matches nothing is refused.

use crate::cli_common::{json, refused, squeal};
use std::collections::BTreeSet;

const KEYS: [&str; 8] = [
    "name",
    "kind",
    "reference",
    "source",
    "value",
    "error",
    "tolerance",
    "pass",
];

#[test]
fn validate_json_every_case_passes() {
    let d = tempfile::tempdir().unwrap();
    let doc = json(&squeal(d.path(), &["validate", "--json"]));
    let cases = doc["cases"].as_array().unwrap();
    let mut names = BTreeSet::new();
    for c in cases {
        let obj = c.as_object().unwrap();
        for k in KEYS {
            assert!(obj.contains_key(k), "{k} missing in {c}");
        }
        let kind = c["kind"].as_str().unwrap();
        assert!(
            ["analytic", "published", "independent", "regression"].contains(&kind),
            "{kind}"
        );
        assert_eq!(c["pass"].as_bool(), Some(true), "{c}");
        let (v, e, t) = (
            c["value"].as_f64().unwrap(),
            c["error"].as_f64().unwrap(),
            c["tolerance"].as_f64().unwrap(),
        );
        assert!(v.is_finite() && e <= t, "{c}");
        assert!(!c["source"].as_str().unwrap().is_empty());
        names.insert(c["name"].as_str().unwrap().to_string());
    }
    for want in [
        "belt-coulomb-period",
        "belt-hopf-speed",
        "disc-pad-hopf-speed",
        "hoffmann-mu-undamped",
        "hoffmann-mu-damped",
        "leine-rational-period",
        "nastran-punch-frequencies",
        "fe-brake-every-format",
    ] {
        assert!(names.contains(want), "{want} missing: {names:?}");
    }
    assert_eq!(doc["passed"].as_u64(), Some(cases.len() as u64));
    assert_eq!(doc["failed"].as_u64(), Some(0));
}

#[test]
fn validate_filter_and_table() {
    let d = tempfile::tempdir().unwrap();
    let out = squeal(d.path(), &["validate", "hoffmann"]);
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("hoffmann-mu-undamped"), "{text}");
    assert!(!text.contains("belt-coulomb-period"), "{text}");
    assert!(text.contains("3 of 3 cases passed"), "{text}");
    assert!(text.lines().all(|l| l.chars().count() <= 100), "{text}");
    let e = refused(&squeal(d.path(), &["validate", "no-such-case"]));
    assert!(e.contains("no-such-case"), "{e}");
}
