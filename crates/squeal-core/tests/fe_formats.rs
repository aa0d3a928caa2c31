//! The FE readers against each other: the fixtures of `tests/data/fe`
//! (written by pyNastran 1.4.1, SciPy and `make_pynastran.py`, see there)
//! in DMIG (small, large and free field), Harwell–Boeing (RUA, and RSA with
//! ANSYS's mapping file) against SciPy's Matrix Market files of the same
//! matrices.

use squeal_core::labelled::LabelledMatrix;
use squeal_core::{dmig, harwell_boeing, matrix_market};

/// The dense matrix of `m` with rows and columns in the dof order `order`.
fn dense_by(m: &LabelledMatrix, order: &[&str]) -> Vec<Vec<f64>> {
    let n = order.len();
    assert_eq!((m.triplets.rows, m.triplets.cols), (n, n));
    let name = |i: usize| match &m.labels {
        Some(l) => l[i].clone(),
        None => (i + 1).to_string(),
    };
    let pos = |i: usize| order.iter().position(|o| *o == name(i)).unwrap();
    let mut d = vec![vec![0.0; n]; n];
    for &(r, c, v) in &m.triplets.entries {
        assert_eq!(d[pos(r)][pos(c)], 0.0, "entry ({r}, {c}) twice");
        d[pos(r)][pos(c)] = v;
    }
    d
}

/// `a` equals `b` entry by entry to `rel` relative (zeros exactly).
fn close(a: &[Vec<f64>], b: &[Vec<f64>], rel: f64, what: &str) {
    for (i, (ra, rb)) in a.iter().zip(b).enumerate() {
        for (j, (x, y)) in ra.iter().zip(rb).enumerate() {
            assert!(
                (x - y).abs() <= rel * y.abs(),
                "{what} ({i}, {j}): {x} vs {y}"
            );
        }
    }
}

#[test]
fn independent_writers_agree() {
    let dofs: Vec<&str> = include_str!("data/fe/dofs.txt").lines().collect();
    let numbers = ["1", "2", "3", "4", "5", "6"];
    let reference = |text: &str| {
        let t = matrix_market::parse(text).unwrap();
        let m = LabelledMatrix {
            name: String::new(),
            format: "matrix-market",
            labels: None,
            triplets: t,
            symmetric: false,
        };
        dense_by(&m, &numbers)
    };
    let k = reference(include_str!("data/fe/k.mtx"));
    let u = reference(include_str!("data/fe/u.mtx"));
    assert_eq!(k[4][4], 1.1764828785956233e4);
    assert_eq!(u[2][5], 0.1234567890123457);
    assert_eq!(u[5][2], 0.0);
    for (file, text, rel) in [
        ("small", include_str!("data/fe/kaax_small.bdf"), 2e-4),
        ("large", include_str!("data/fe/kaax_large.bdf"), 1e-9),
        ("free", include_str!("data/fe/kaax_free.bdf"), 0.0),
    ] {
        let m = dmig::parse(text).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(m.len(), 2);
        assert_eq!((m[0].name.as_str(), m[1].name.as_str()), ("KAAX", "UAAX"));
        assert!(m[0].symmetric && !m[1].symmetric);
        assert_eq!(
            m[0].labels.as_ref().unwrap()[..3],
            ["1203_1", "1203_2", "1203_3"]
        );
        close(&dense_by(&m[0], &dofs), &k, rel, file);
        close(&dense_by(&m[1], &dofs), &u, rel, file);
    }
    let hb = |text: &str, mapping: Option<&str>| harwell_boeing_parse(text, mapping);
    let m = hb(include_str!("data/fe/k_rua.rb"), None);
    assert!(!m.symmetric);
    close(&dense_by(&m, &numbers), &k, 0.0, "k_rua.rb");
    let m = hb(include_str!("data/fe/u_rua.rb"), None);
    close(&dense_by(&m, &numbers), &u, 0.0, "u_rua.rb");
    let m = hb(
        include_str!("data/fe/k_rsa.matrix"),
        Some(include_str!("data/fe/k_rsa.mapping")),
    );
    assert!(m.symmetric);
    let ansys = ["1203_1", "1203_2", "1203_3", "88_3", "7_PRES", "5_6"];
    assert_eq!(m.labels.as_deref().unwrap(), ansys);
    close(&dense_by(&m, &ansys), &k, 1e-14, "k_rsa.matrix");
}

fn harwell_boeing_parse(text: &str, mapping: Option<&str>) -> LabelledMatrix {
    harwell_boeing::parse(text, mapping).unwrap()
}
