//! The engineer's FE brake from the files FE packages write (issue 26 §2):
//! the ring-disc brakes of `examples/fe-brake/` (written by its
//! `make_brake.py` in Matrix Market by SciPy, and in Nastran DMIG, Abaqus
//! `*MATRIX OUTPUT` and Harwell–Boeing RSA with ANSYS's mapping file) give
//! the same steady sliding and eigenvalues from every format, the leading
//! eigenvalue of an independent SciPy analysis (`examples/fe-brake/cea.py`),
//! `squeal inspect` says what was read, and bad files are refused in one
//! line naming the file, the line and what is wrong.

use crate::cli_common::{eigenvalues, json, ok, refused, squeal};
use std::path::{Path, PathBuf};

fn example(model: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/fe-brake")
        .join(model)
}

#[test]
fn every_format_gives_the_same_eigenvalues_and_the_independent_ones() {
    // The leading eigenvalue by SciPy (`python3 cea.py two-pad/brake.toml`,
    // `python3 cea.py four-pad/brake.toml`): steady sliding by one dense
    // solve, eigenvalues of the 2n state matrix by LAPACK.
    for (model, reference) in [
        ("two-pad", (356.40551404893483f64, 4376.135799046114f64)),
        ("four-pad", (636.04653314299, 4991.0231603748325)),
    ] {
        let dir = example(model);
        let base = json(&squeal(&dir, &["stability", "brake.toml", "--json"]));
        let e0 = eigenvalues(&base);
        let (re, im) = e0[0];
        let mag = reference.0.hypot(reference.1);
        assert!(
            (re - reference.0).abs() <= 1e-9 * mag && (im.abs() - reference.1).abs() <= 1e-9 * mag,
            "{model}: {re} {im} against {reference:?}"
        );
        assert_eq!(base["verdict"], "unstable", "{model}");
        // Every format holds the same doubles: the same eigenvalues, bit
        // for bit.
        for f in ["brake-dmig.toml", "brake-abaqus.toml", "brake-hb.toml"] {
            let v = json(&squeal(&dir, &["stability", f, "--json"]));
            assert_eq!(eigenvalues(&v), e0, "{model} {f}");
        }
    }
}

#[test]
fn dofs_may_be_left_out_when_the_files_name_them() {
    let d = tempfile::tempdir().unwrap();
    let src = example("two-pad");
    for f in [
        "brake.pch",
        "brake_MASS1.mtx",
        "brake_STIF1.mtx",
        "brake_DMPV1.mtx",
    ] {
        std::fs::copy(src.join(f), d.path().join(f)).unwrap();
    }
    let text = std::fs::read_to_string(src.join("brake-dmig.toml")).unwrap();
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("dofs = "))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(d.path().join("a.toml"), &without).unwrap();
    let a = json(&squeal(d.path(), &["stability", "a.toml", "--json"]));
    let b = json(&squeal(&src, &["stability", "brake-dmig.toml", "--json"]));
    // Another state order: the same eigenvalues to round-off.
    let (ea, eb) = (eigenvalues(&a), eigenvalues(&b));
    assert_eq!(ea.len(), 248);
    for (x, y) in ea.iter().zip(&eb) {
        let mag = y.0.hypot(y.1);
        assert!(
            (x.0 - y.0).abs() <= 1e-9 * mag && (x.1 - y.1).abs() <= 1e-9 * mag,
            "{x:?} vs {y:?}"
        );
    }
    // dofs, when given, must list the matrices' dofs.
    let bad = text.replacen("\"1_1\", ", "", 1);
    std::fs::write(d.path().join("b.toml"), bad).unwrap();
    let e = refused(&squeal(d.path(), &["stability", "b.toml"]));
    assert!(
        e.contains("dofs: '1_1' of the matrices is not listed"),
        "{e}"
    );
    let bad = text.replacen("\"1_1\", ", "\"1_1\", \"77_7\", ", 1);
    std::fs::write(d.path().join("c.toml"), bad).unwrap();
    let e = refused(&squeal(d.path(), &["stability", "c.toml"]));
    assert!(e.contains("dofs: '77_7' is in no matrix"), "{e}");
}

#[test]
fn inspect_says_what_was_read() {
    let dir = example("two-pad");
    let mut freqs = Vec::new();
    for (f, format, names) in [
        ("brake-dmig.toml", "dmig", ["MAAX", "KAAX", "BAAX"]),
        ("brake-abaqus.toml", "abaqus", ["", "", ""]),
        ("brake-hb.toml", "harwell-boeing", ["", "", ""]),
        ("brake.toml", "matrix-market", ["", "", ""]),
    ] {
        let v = json(&squeal(&dir, &["inspect", f, "--json"]));
        assert_eq!(v["dof_count"], 124, "{f}");
        let dofs = v["dofs"].as_array().unwrap();
        assert_eq!(dofs[0], "1_1");
        assert_eq!(dofs[123], "9002_3");
        let m = v["matrices"].as_array().unwrap();
        assert_eq!(m.len(), 3, "{f}");
        for (i, key) in ["M", "K", "C"].iter().enumerate() {
            let mi = m.iter().find(|x| x["key"] == *key).unwrap();
            assert_eq!(mi["format"], format, "{f} {key}");
            assert_eq!(mi["name"], names[i], "{f} {key}");
            assert_eq!(mi["size"], 124, "{f} {key}");
            assert_eq!(mi["symmetric"], true, "{f} {key}");
        }
        // The ring's consistent mass: 40 elements × (4 bar + 16 beam
        // entries) into 120 dofs, 4 overlapping per node pair… counted
        // exactly as stored: the K of the ring adds the pads' abutment
        // couplings (2 per pad).
        let nnz = |key: &str| m.iter().find(|x| x["key"] == key).unwrap()["nonzeros"].clone();
        assert_eq!(nnz("M"), 524, "{f}");
        assert_eq!(nnz("K"), 528, "{f}");
        if format == "harwell-boeing" {
            let mi = m.iter().find(|x| x["key"] == "K").unwrap();
            assert_eq!(mi["mapping"], "brake_K.mapping");
        }
        let c = &v["contacts"][0];
        assert_eq!(c["name"], "inner");
        assert_eq!(c["kind"], "unilateral");
        assert_eq!(
            c["normal"],
            serde_json::json!([["6_3", 1.0], ["9001_3", -1.0]])
        );
        assert_eq!(
            c["tangent"],
            serde_json::json!([["6_1", 1.0], ["6_5", -0.01], ["9001_1", -1.0]])
        );
        let fr: Vec<f64> = v["natural_frequencies_hz"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(fr.len(), 12);
        assert!(fr.windows(2).all(|w| w[0] <= w[1]) && fr[0] > 0.0, "{fr:?}");
        freqs.push(fr);
    }
    assert!(freqs.windows(2).all(|w| w[0] == w[1]));
    let text = ok(&squeal(&dir, &["inspect", "brake-dmig.toml"]));
    assert!(
        text.contains("K = brake.pch KAAX: dmig, 124×124, 528 nonzeros, symmetric"),
        "{text}"
    );
    assert!(
        text.contains("lowest natural frequencies without friction (Hz): "),
        "{text}"
    );
}

#[test]
fn bad_fe_files_are_refused_naming_the_file_and_the_line() {
    let d = tempfile::tempdir().unwrap();
    let src = example("two-pad");
    let pch = std::fs::read_to_string(src.join("brake.pch")).unwrap();
    let scenario = std::fs::read_to_string(src.join("brake-dmig.toml")).unwrap();
    let run = |name: &str, pch_text: &str, sc: &str| {
        std::fs::write(d.path().join("x.pch"), pch_text).unwrap();
        std::fs::write(d.path().join(name), sc.replace("brake.pch", "x.pch")).unwrap();
        refused(&squeal(d.path(), &["stability", name]))
    };
    // Several matrices and no name.
    let e = run(
        "a.toml",
        &pch,
        &scenario.replace("{ file = \"brake.pch\", name = \"KAAX\" }", "\"brake.pch\""),
    );
    assert!(
        e.contains("matrices: K = 'x.pch': holds 3 matrices (MAAX, KAAX, BAAX): name one"),
        "{e}"
    );
    // A name the file does not hold.
    let e = run("b.toml", &pch, &scenario.replace("\"KAAX\"", "\"KGG\""));
    assert!(
        e.contains("matrices: K = 'x.pch'") && e.contains("KGG"),
        "{e}"
    );
    // A format that does not exist.
    let e = run(
        "c.toml",
        &pch,
        &scenario.replace(
            "name = \"KAAX\" }",
            "name = \"KAAX\", format = \"nastran\" }",
        ),
    );
    assert!(
        e.contains("format = \"nastran\": expected one of matrix-market, dmig"),
        "{e}"
    );
    // A truncated card: the line is named.
    let lines: Vec<&str> = pch.lines().collect();
    let k = lines
        .iter()
        .position(|l| l.starts_with("DMIG,KAAX,1,"))
        .unwrap();
    let mut cut: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    cut[k] = "DMIG,KAAX,1,1,,1".into();
    let e = run("d.toml", &(cut.join("\n") + "\n"), &scenario);
    assert!(
        e.contains("matrices: K = 'x.pch': line ") && e.contains(&format!("line {}", k + 1)),
        "{e}"
    );
    // A duplicate entry.
    let mut dup: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    dup.insert(k + 1, lines[k].to_string());
    let e = run("e.toml", &(dup.join("\n") + "\n"), &scenario);
    assert!(e.contains(&format!("line {}", k + 2)), "{e}");
    // A contact on a dof no matrix has.
    let e = run(
        "f.toml",
        &pch,
        &scenario.replace("6_3 = 1.0, 9001_3", "999_3 = 1.0, 9001_3"),
    );
    assert!(
        e.contains("contact 'inner'") && e.contains("unknown dof '999_3'"),
        "{e}"
    );
    // Named and numbered matrices mixed.
    std::fs::copy(src.join("K.mtx"), d.path().join("K.mtx")).unwrap();
    let e = run(
        "g.toml",
        &pch,
        &scenario.replace("{ file = \"brake.pch\", name = \"KAAX\" }", "\"K.mtx\""),
    );
    assert!(
        e.contains("names its dofs") && e.contains("K = 'K.mtx' (matrix-market) numbers them"),
        "{e}"
    );
    // Nothing is written by a refused run.
    assert!(!d.path().join("out").exists());
}

/// Issue 26 §5: the FE brake squeals by mode coupling — its growing mode
/// is made of two real modes of comparable share — while the lumped
/// asymmetric two-pad brake's growing modes are each one real mode (the
/// negative damping of a falling friction law).
#[test]
fn stability_names_the_real_modes_a_growing_mode_is_made_of() {
    let dir = example("two-pad");
    let v = json(&squeal(&dir, &["stability", "brake-dmig.toml", "--json"]));
    let c = v["coupled_modes"].as_array().unwrap();
    assert_eq!(c.len(), 1, "{c:?}");
    let m = &c[0];
    assert_eq!(m["eigenvalue"], 1);
    assert!((m["growth_rate"].as_f64().unwrap() - 356.40551404893483).abs() < 1e-6);
    // A complete basis (124 dofs, dense): it holds the whole mode.
    assert!((m["captured"].as_f64().unwrap() - 1.0).abs() < 1e-9);
    let shares: Vec<f64> = m["real_modes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["share"].as_f64().unwrap())
        .collect();
    assert!(shares.windows(2).all(|w| w[0] >= w[1]), "{shares:?}");
    let sum: f64 = shares.iter().sum();
    assert!(sum <= 1.0 + 1e-12 && sum > 0.95, "{shares:?}");
    assert!(
        shares[0] < 0.8 && shares[1] > 0.2,
        "two modes couple: {shares:?}"
    );
    let dofs: Vec<&str> = m["contact_dofs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["dof"].as_str().unwrap())
        .collect();
    let contact = ["6_1", "6_3", "6_5", "9001_1", "9001_3", "9002_1", "9002_3"];
    assert!(dofs.iter().all(|d| contact.contains(d)), "{dofs:?}");
    let text = ok(&squeal(&dir, &["stability", "brake-dmig.toml"]));
    assert!(text.contains("growing mode #1 (696.48 Hz"), "{text}");
    // The lumped asymmetric two-pad brake: three growing modes, each one
    // real mode.
    let v = json(&squeal(
        &dir,
        &["stability", "two-pad-brake-asymmetric", "--json"],
    ));
    let c = v["coupled_modes"].as_array().unwrap();
    assert_eq!(c.len(), 3);
    for m in c {
        assert!(m["real_modes"][0]["share"].as_f64().unwrap() > 0.98, "{m}");
    }
}

#[test]
fn a_real_nastran_punch_gives_nastrans_own_frequencies() {
    // A punch file written by MSC Nastran 2013 itself (SOL 103, large
    // field, form 6, `D` exponents, a form-9 VAX to skip), with the
    // natural frequencies from Nastran's own f06 ("CYCLES", 7 digits,
    // Givens); see tests/data/msc-nastran-2013/README.md.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/msc-nastran-2013");
    let v = json(&squeal(&dir, &["inspect", "beam.toml", "--json"]));
    assert_eq!(v["dof_count"], 10);
    assert_eq!(v["matrices"][0]["format"], "dmig");
    assert_eq!(v["matrices"][1]["nonzeros"], 46);
    let f: Vec<f64> = v["natural_frequencies_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let nastran = [
        2.114057e+01,
        2.135569e+01,
        1.287332e+02,
        1.297476e+02,
        4.371801e+02,
        4.382013e+02,
        1.258988e+03,
        1.259566e+03,
    ];
    assert_eq!(f.len(), 10);
    // The two rigid-body modes: zero to the punch file's ten digits
    // (√(1e-5)/2π Hz from stiffness round-off of 1e7-sized terms).
    assert!(f[0].abs() < 1e-3 && f[1].abs() < 1e-3, "{f:?}");
    for (x, y) in f[2..].iter().zip(nastran) {
        // The f06 rounds to 7 significant digits: half a unit of the 7th.
        assert!((x - y).abs() <= 5.01e-7 * y, "{x} against Nastran's {y}");
    }
}

/// A request that breaks several limits is refused once, naming all of
/// them (issue 27 §1): the 124-dof FE brake run for 200 s at the default
/// 200 kHz needs a series too large for memory (4·10⁷ samples of 257
/// columns) and is sampled below twice its fastest mode (430 kHz); before,
/// `simulate` named one, then the other on the next try. Nothing is written.
#[test]
fn every_broken_limit_is_named_in_one_refusal() {
    let d = tempfile::tempdir().unwrap();
    let brake = example("two-pad").join("brake.toml");
    let e = refused(&squeal(
        d.path(),
        &[
            "simulate",
            brake.to_str().unwrap(),
            "--duration",
            "200",
            "--out",
            "o",
        ],
    ));
    assert!(e.contains("2 limits broken"), "{e}");
    assert!(e.contains("GB in memory"), "{e}");
    assert!(
        e.contains("sample_rate = 200000") && e.contains("8.594146e5 Hz"),
        "{e}"
    );
    assert!(!d.path().join("o").exists());
}

/// The truncation error made visible (issue 27 §2): `stability` of a
/// projected FE brake prints the growing eigenvalue for growing bases
/// (`convergence` in the JSON). Against the dense eigenvalue of the same
/// 124-dof model, the error does not grow with the basis, is below 1e-3
/// (relative) once the modes reach twice the squeal frequency, and the last
/// row is the analysis's own eigenvalue. A basis that stops below the
/// squeal's modes is flagged: not settled, with a warning.
#[test]
fn the_projected_eigenvalue_converges_as_the_basis_grows() {
    let d = tempfile::tempdir().unwrap();
    let brake = example("two-pad").join("brake.toml");
    let brake = brake.to_str().unwrap();
    let dense = json(&squeal(
        d.path(),
        &["stability", brake, "--json", "--no-levers"],
    ));
    assert!(
        dense.get("convergence").is_none(),
        "a dense analysis truncates nothing"
    );
    let exact = (
        f(&dense["least_stable"]["re"]),
        f(&dense["least_stable"]["im"]),
    );
    let f_squeal = exact.1 / std::f64::consts::TAU;
    let run = |modes: &str| {
        squeal(
            d.path(),
            &[
                "stability",
                brake,
                "--json",
                "--no-levers",
                "--set",
                "modal.dense_max_dofs=0",
                "--set",
                &format!("modal.modes={modes}"),
            ],
        )
    };
    let out = run("16");
    let v = json(&out);
    let c = &v["convergence"];
    let rows = c["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    let err = |r: &serde_json::Value| {
        let e = &r["eigenvalues"][0];
        (f(&e["re"]) - exact.0).hypot(f(&e["im"]) - exact.1) / exact.0.hypot(exact.1)
    };
    let errors: Vec<f64> = rows.iter().map(err).collect();
    for w in errors.windows(2) {
        assert!(w[1] <= w[0] * 1.01 + 1e-12, "the error grew: {errors:?}");
    }
    let mut checked = 0;
    for (r, e) in rows.iter().zip(&errors) {
        if f(&r["basis_max_hz"]) >= 2.0 * f_squeal {
            assert!(*e < 1e-3, "modes to {} Hz: error {e}", r["basis_max_hz"]);
            checked += 1;
        }
    }
    assert!(checked >= 2, "{errors:?}");
    assert!(
        errors[0] > 1e-2,
        "the smallest basis is far off: {errors:?}"
    );
    let last = &rows[3]["eigenvalues"][0];
    assert!((f(&last["re"]) - f(&v["least_stable"]["re"])).abs() < 1e-9 * exact.1);
    assert_eq!(c["settled"], true);
    assert!(c["warning"].is_null());
    // Four modes reach 563 Hz, below the 696 Hz squeal: not settled.
    let out = run("4");
    let v = json(&out);
    assert_eq!(v["convergence"]["settled"], false);
    let err_text = String::from_utf8_lossy(&out.stderr);
    assert!(err_text.contains("have not settled"), "{err_text}");
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}
