//! Property test: no scenario file and no `--set` list makes squeal panic.
//! Every input ends in a resolved scenario or in one line naming what is
//! wrong, and a resolved one passes the run checks or is refused by them.
//! Bounded (a few hundred cases, a few seconds) so that it runs in CI.

use crate::scenario::Scenario;
use proptest::prelude::*;

const KEYS: &[&str] = &[
    "name",
    "description",
    "model",
    "duration",
    "sample_rate",
    "initial",
    "contact",
    "m_d",
    "m_p",
    "k_dx",
    "k_dy",
    "k_px",
    "k_py",
    "c_dx",
    "c_px",
    "N",
    "V",
    "alpha",
    "t_ramp",
    "m",
    "k",
    "c",
    "k11",
    "k12",
    "k22",
    "k3",
    "mu",
    "N0",
    "friction",
    "law",
    "f0",
    "f1",
    "Uc",
    "mu_s",
    "mu_k",
    "v_s",
    "delta",
    "sigma",
    "rtol",
    "atol_pos",
    "atol_vel",
    "atol_x_p",
    "h_max",
    "x_d0",
    "vx_p0",
    "x0",
    "v0",
];
const SECTIONS: &[&str] = &["", "params", "friction", "offsets", "solver", "other"];

fn key() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => proptest::sample::select(KEYS).prop_map(String::from),
        1 => "[a-zA-Z_][a-zA-Z0-9_]{0,8}",
    ]
}

/// A number as text, biased to the edges: 0, signs, huge, tiny, non-finite.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        proptest::sample::select(
            &[
                "0",
                "-0",
                "1",
                "-1",
                "1e308",
                "-1e308",
                "1e-308",
                "5e-324",
                "1e15",
                "1e-12",
                "1e-300",
                "nan",
                "inf",
                "-inf",
                "2.5",
                "0.5",
                "9007199254740993",
                "1e999",
            ][..]
        )
        .prop_map(String::from),
        any::<f64>().prop_map(|x| format!("{x:e}")),
        any::<i64>().prop_map(|i| i.to_string()),
    ]
}

/// A TOML value: number, string, boolean, array or table, or raw junk.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => number(),
        2 => proptest::sample::select(&[
            "\"thesis\"", "\"coulomb\"", "\"stribeck\"", "\"rational\"", "\"disc-pad\"",
            "\"belt\"", "\"hoffmann\"", "\"rest\"", "\"equilibrium\"", "\"bilateral\"",
            "\"../x\"", "\"\"", "\"/abs\"", "\"a\\u0007b\"", "\"tab\\there\"",
        ][..]).prop_map(String::from),
        1 => "[ -~]{0,12}".prop_map(|s| format!("{s:?}")),
        1 => any::<String>().prop_map(|s| toml::Value::String(s).to_string()),
        1 => Just("true".to_string()),
        1 => Just("[1, 2]".to_string()),
        1 => Just("{ a = 1 }".to_string()),
        1 => "[ -~]{0,6}",
    ]
}

fn toml_text() -> impl Strategy<Value = String> {
    let line = (proptest::sample::select(SECTIONS), key(), value());
    prop_oneof![
        6 => proptest::collection::vec(line, 0..14).prop_map(|lines| {
            let mut top = String::new();
            let mut sections = String::new();
            for (section, k, v) in lines {
                if section.is_empty() {
                    top.push_str(&format!("{k} = {v}\n"));
                } else {
                    sections.push_str(&format!("[{section}]\n{k} = {v}\n"));
                }
            }
            top + &sections
        }),
        // A shipped scenario with some of its values replaced: deep paths.
        4 => (
            proptest::sample::select(&["disc-pad", "belt", "belt-coulomb", "hoffmann"][..]),
            proptest::collection::vec((any::<proptest::sample::Index>(), value()), 1..4),
        )
            .prop_map(|(name, edits)| {
                let text = Scenario::builtin(name).unwrap().to_toml();
                let mut lines: Vec<String> = text.lines().map(String::from).collect();
                for (i, v) in edits {
                    let l = i.index(lines.len());
                    if let Some((k, _)) = lines[l].split_once(" = ") {
                        lines[l] = format!("{} = {v}", k.trim());
                    }
                }
                lines.join("\n")
            }),
        1 => any::<String>(),
    ]
}

fn sets() -> impl Strategy<Value = Vec<String>> {
    let one = prop_oneof![
        6 => (key(), prop_oneof![number(), "[ -~]{0,8}"]).prop_map(|(k, v)| format!("{k}={v}")),
        1 => "[ -~]{0,12}",
        1 => any::<String>(),
    ];
    proptest::collection::vec(one, 0..5)
}

fn one_line(e: &str) {
    assert!(!e.contains('\n') && !e.is_empty(), "not one line: {e:?}");
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 400,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn scenario_files_and_overrides_never_panic(text in toml_text(), sets in sets()) {
        let mut sc = match Scenario::from_toml(&text) {
            Ok(sc) => {
                // A resolved scenario prints as TOML that reads back the same.
                let back = Scenario::from_toml(&sc.to_toml());
                prop_assert_eq!(back, Ok(sc.clone()));
                sc
            }
            Err(e) => {
                one_line(&e.0);
                Scenario::builtin("disc-pad").unwrap()
            }
        };
        match sc.apply_overrides(&sets) {
            Err(e) => one_line(&e.0),
            Ok(()) => {
                if let Err(e) = crate::feasible::prepare(&mut sc) {
                    one_line(&e.to_string());
                }
            }
        }
    }

    #[test]
    fn builtins_with_any_overrides_never_panic(
        name in proptest::sample::select(&["disc-pad", "belt", "belt-coulomb", "hoffmann"][..]),
        sets in sets(),
    ) {
        let mut sc = Scenario::builtin(name).unwrap();
        match sc.apply_overrides(&sets) {
            Err(e) => one_line(&e.0),
            Ok(()) => {
                if let Err(e) = crate::feasible::prepare(&mut sc) {
                    one_line(&e.to_string());
                }
            }
        }
    }
}

/// Found while writing the property above: `scenario show` must print any
/// accepted name and description as TOML that reads back.
#[test]
fn any_description_survives_the_toml_round_trip() {
    for d in [
        "a\u{7}b",
        "tab\there",
        "quote\"s and \\ back",
        "line\nbreak",
        "ünï",
    ] {
        let mut sc = Scenario::builtin("belt").unwrap();
        sc.description = d.to_string();
        let back = Scenario::from_toml(&sc.to_toml()).unwrap();
        assert_eq!(back.description, d);
    }
}
