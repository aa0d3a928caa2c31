//! Abaqus assembled matrices written by `*MATRIX GENERATE` with
//! `*MATRIX OUTPUT` (the `.mtx` files `jobname_STIF1.mtx`,
//! `jobname_MASS1.mtx`, …; Abaqus Keywords Guide, `*MATRIX OUTPUT` and
//! `*MATRIX INPUT`):
//!
//! - `FORMAT=MATRIX INPUT` (the default): lines `row node, row dof, column
//!   node, column dof, value`. Dofs are named `<node>_<dof>`; an internal
//!   node (negative label −L, e.g. a Lagrange multiplier) is `m<L>_<dof>`;
//!   dofs above 6 (pressure 8, temperature 11, …) are kept as written.
//! - `FORMAT=COORDINATE`: lines `row, column, value` with 1-based equation
//!   numbers (numbered dofs: [`LabelledMatrix::labels`] is `None`, and the
//!   size is the largest number, at most 64 per entry + 64 so that a stray
//!   number cannot make a huge matrix).
//!
//! Fields are apart by commas (or, without commas, by blanks). The format
//! is recognised by the number of fields (5 or 3) of the first data line;
//! every line must have the same. Blank lines and `**` comments
//! are skipped; a keyword line (`*CLOAD` of a load file, `*USER ELEMENT` of
//! element matrix output) is refused: only assembled matrices are read. A matrix
//! given by one triangle (upper or lower) is symmetric and mirrored; one
//! given by both triangles is read as given (an entry without its mirror,
//! such as a friction coupling, stays one-sided) and is symmetric if every
//! entry equals its mirror; a file giving most off-diagonal entries in one
//! triangle but some with their mirror is refused. An entry given twice is
//! an error.
//! Abaqus writes the lower triangle of a symmetric matrix, 16 significant
//! digits, and `1e36` on the diagonal of a constrained dof (kept as
//! written: the caller decides what a constrained dof is).
//! Pure: takes text; errors are one line, `line N: what is wrong`.

use crate::labelled::{fortran_real, Entries, LabelledMatrix, Labels, Symmetry};

/// Parse the text of an Abaqus `*MATRIX OUTPUT` file (see the module docs).
pub fn parse(text: &str) -> Result<LabelledMatrix, String> {
    let mut labels = Labels::default();
    // (node, dof) → index, so that a label is formatted once per dof
    let mut ids: std::collections::HashMap<(i64, i64), usize> = Default::default();
    let mut entries = Entries::default();
    let mut fields_per_line: Option<(usize, usize)> = None;
    let mut largest = (0usize, 0usize);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let t = raw.trim();
        if t.is_empty() || t.starts_with("**") {
            continue;
        }
        if t.starts_with('*') {
            return Err(format!(
                "line {line}: keyword line '{t}': squeal reads the assembled matrices that *MATRIX GENERATE with *MATRIX OUTPUT writes (FORMAT=MATRIX INPUT or COORDINATE), not loads (*CLOAD) or element matrices (*USER ELEMENT)"
            ));
        }
        let mut w: Vec<&str> = if t.contains(',') {
            t.split(',').map(str::trim).collect()
        } else {
            t.split_whitespace().collect()
        };
        if w.len() > 1 && w.last() == Some(&"") {
            w.pop();
        }
        let (n, first) = *fields_per_line.get_or_insert((w.len(), line));
        if w.len() != n {
            return Err(format!(
                "line {line}: {} fields, but line {first} has {n}: expected {}",
                w.len(),
                if n == 5 {
                    "'row node, row dof, column node, column dof, value'"
                } else {
                    "'row, column, value'"
                }
            ));
        }
        let int = |s: &str, what: &str| -> Result<i64, String> {
            s.parse::<i64>()
                .map_err(|_| format!("line {line}: {what} '{s}' is not an integer"))
        };
        let value = fortran_real(w[n - 1])
            .ok_or_else(|| format!("line {line}: '{}' is not a real number", w[n - 1]))?;
        let (r, c) = match n {
            5 => {
                let mut dof = |node: &str, dof: &str| -> Result<usize, String> {
                    let node = int(node, "node")?;
                    let d = int(dof, "dof")?;
                    if d < 1 {
                        return Err(format!("line {line}: dof {d} is not a dof number (1, 2, …)"));
                    }
                    Ok(*ids.entry((node, d)).or_insert_with(|| {
                        labels.get(if node < 0 {
                            format!("m{}_{d}", node.unsigned_abs())
                        } else {
                            format!("{node}_{d}")
                        })
                    }))
                };
                (dof(w[0], w[1])?, dof(w[2], w[3])?)
            }
            3 => {
                let idx = |s: &str| -> Result<usize, String> {
                    match int(s, "equation number")? {
                        k if k >= 1 => Ok((k - 1) as usize),
                        k => Err(format!("line {line}: equation number {k} is not 1 or more")),
                    }
                };
                let (r, c) = (idx(w[0])?, idx(w[1])?);
                if r.max(c) + 1 > largest.0 {
                    largest = (r.max(c) + 1, line);
                }
                (r, c)
            }
            _ => {
                return Err(format!(
                    "line {line}: {n} fields: expected 'row node, row dof, column node, column dof, value' (FORMAT=MATRIX INPUT) or 'row, column, value' (FORMAT=COORDINATE)"
                ))
            }
        };
        let names = &labels.names;
        let coordinate = n == 3;
        entries.add(r, c, value, line, &|k| {
            if coordinate {
                (k + 1).to_string()
            } else {
                names[k].clone()
            }
        })?;
    }
    let Some((n, _)) = fields_per_line else {
        return Err("no matrix entries in the file".into());
    };
    let coordinate = n == 3;
    let size = if coordinate {
        let (largest, at) = largest;
        if largest > 64 * entries.len() + 64 {
            return Err(format!(
                "line {at}: equation number {largest} is far beyond the {} entries of the file: a coordinate file numbers its dofs 1…n (at most 64 per entry + 64 read)",
                entries.len()
            ));
        }
        largest
    } else {
        labels.names.len()
    };
    let names = &labels.names;
    let (triplets, symmetric) = entries.finish(size, Symmetry::Detect, &|k| {
        if coordinate {
            (k + 1).to_string()
        } else {
            names[k].clone()
        }
    })?;
    Ok(LabelledMatrix {
        name: String::new(),
        format: if coordinate {
            "abaqus-coordinate"
        } else {
            "abaqus"
        },
        labels: (!coordinate).then_some(labels.names),
        triplets,
        symmetric,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dmig::tests::{k_sym, u_unsym};
    use crate::labelled::tests::dense_by;

    /// The DMIG tests' matrix on Abaqus dofs: node 101's 1, 2, 3, node 102's
    /// 3, and dof 8 of internal node −7.
    const NODES: [(i64, u32); 5] = [(101, 1), (101, 2), (101, 3), (102, 3), (-7, 8)];
    const LABELS: [&str; 5] = ["101_1", "101_2", "101_3", "102_3", "m7_8"];
    const NUMBERS: [&str; 5] = ["1", "2", "3", "4", "5"];

    /// `0`: lower triangle, `1`: upper, `2`: both.
    fn write(a: &[Vec<f64>], part: u8, coordinate: bool) -> String {
        let mut s = String::from("** written by the test\n");
        for j in 0..5 {
            for i in 0..5 {
                let keep = match part {
                    0 => i >= j,
                    1 => i <= j,
                    _ => true,
                };
                if keep && a[i][j] != 0.0 {
                    if coordinate {
                        s.push_str(&format!("{},{}, {:.16e}\n", i + 1, j + 1, a[i][j]));
                    } else {
                        let ((ni, di), (nj, dj)) = (NODES[i], NODES[j]);
                        s.push_str(&format!("{ni},{di},{nj},{dj}, {:.16e}\n", a[i][j]));
                    }
                }
            }
        }
        s
    }

    #[test]
    fn both_formats_and_every_triangle_give_the_same_matrix() {
        for coordinate in [false, true] {
            let order: &[&str] = if coordinate { &NUMBERS } else { &LABELS };
            for part in 0..3 {
                let m = parse(&write(&k_sym(), part, coordinate)).unwrap();
                assert!(m.symmetric);
                assert_eq!(m.labels.is_none(), coordinate);
                assert_eq!(
                    m.format,
                    if coordinate {
                        "abaqus-coordinate"
                    } else {
                        "abaqus"
                    }
                );
                assert_eq!(dense_by(&m, order), k_sym(), "{coordinate} {part}");
            }
            let m = parse(&write(&u_unsym(), 2, coordinate)).unwrap();
            assert!(!m.symmetric);
            assert_eq!(dense_by(&m, order), u_unsym());
        }
    }

    #[test]
    fn hand_written_files_entry_by_entry() {
        let text = "** STIFFNESS MATRIX, step 1\n\n  12, 3, 12, 3,  1.0000000000000000e+06\n12,3,-4,11, -2.5e+02,\n -4, 11, -4, 11, 3.5D+02\n";
        let m = parse(text).unwrap();
        assert_eq!(m.labels.as_ref().unwrap(), &["12_3", "m4_11"]);
        assert_eq!(
            m.triplets.entries,
            vec![(0, 0, 1e6), (0, 1, -250.0), (1, 0, -250.0), (1, 1, 350.0)]
        );
        assert!(m.symmetric);
        assert_eq!(m.name, "");
        let m = parse("1, 1, 2.0\n3, 1, -1.0\n").unwrap();
        assert_eq!((m.triplets.rows, m.triplets.cols), (3, 3));
        assert_eq!(
            m.triplets.entries,
            vec![(0, 0, 2.0), (2, 0, -1.0), (0, 2, -1.0)]
        );
    }

    /// The layout of a file written by Abaqus (`*MATRIX OUTPUT, STIFFNESS`):
    /// the lower triangle in Abaqus's equation order (an internal node −1
    /// first), 16 digits, `1e36` on the diagonal of constrained dofs.
    #[test]
    fn abaqus_layout_with_an_internal_node_and_constrained_dofs() {
        let text = "\
-1,1, -1,1,  4.000000000000000e+01
-1,2, -1,1, -1.000000000000000e+01
1,1, -1,1,  2.000000000000000e+01
-1,2, -1,2,  3.000000000000000e+01
1,1, -1,2,  2.500000000000000e+01
1,1, 1,1,  1.000000000000000e+36
2,1, 1,1, -3.000000000000000e+02
2,1, 2,1,  3.000000000000000e+02
";
        let m = parse(text).unwrap();
        assert!(m.symmetric);
        assert_eq!(m.labels.as_ref().unwrap(), &["m1_1", "m1_2", "1_1", "2_1"]);
        let d = dense_by(&m, &["m1_1", "m1_2", "1_1", "2_1"]);
        assert_eq!(
            d,
            vec![
                vec![40.0, -10.0, 20.0, 0.0],
                vec![-10.0, 30.0, 25.0, 0.0],
                vec![20.0, 25.0, 1e36, -300.0],
                vec![0.0, 0.0, -300.0, 300.0]
            ]
        );
        // FORMAT=COORDINATE apart by blanks
        let m = parse("1 1  2.0e+00\n2 1 -1.0e+00\n2 2  2.0e+00\n").unwrap();
        assert_eq!(m.format, "abaqus-coordinate");
        assert_eq!(
            m.triplets.entries,
            vec![(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 2.0)]
        );
    }

    #[test]
    fn bad_files_name_the_line() {
        for (text, needle) in [
            ("", "no matrix entries"),
            ("** only a comment\n", "no matrix entries"),
            (
                "*USER ELEMENT, NODES=2\n",
                "line 1: keyword line '*USER ELEMENT, NODES=2'",
            ),
            (
                "1,1,2,1,1.0\n2,1,1,1,1.0\n3,1,1,1,1.0\n4,1,1,1,1.0\n5,1,1,1,1.0\n",
                "line 2: entry (row 1_1, column 2_1) is given with its mirror (line 1), but most off-diagonal entries (3 of 5)",
            ),
            (
                "** Assembled nodal loads\n*CLOAD, REAL\n2,3,  5.4e+04\n",
                "line 2: keyword line '*CLOAD, REAL'",
            ),
            (
                "1,1,1,1,2.0\n1,2,3.0\n",
                "line 2: 3 fields, but line 1 has 5",
            ),
            ("1,1,2.0,4\n", "line 1: 4 fields: expected"),
            ("1,1,1,1,abc\n", "line 1: 'abc' is not a real number"),
            ("1,x,1,1,1.0\n", "line 1: dof 'x' is not an integer"),
            ("1,0,1,1,1.0\n", "line 1: dof 0 is not a dof number"),
            (
                "1,1,1,1,1.0\n\n1,1,1,1,1.0\n",
                "line 3: entry (row 1_1, column 1_1) given twice (first on line 1)",
            ),
            ("0,1,1.0\n", "line 1: equation number 0 is not 1 or more"),
            (
                "1,1,1.0\n1000,1,1.0\n",
                "line 2: equation number 1000 is far beyond the 2 entries",
            ),
            (
                "2,1,1.0\n1,2,1.0\n3,1,1.0\n1,3,2.0\n2,2,1.0\n2,2,1.0\n",
                "line 6: entry (row 2, column 2) given twice",
            ),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(needle), "{text:?}:\n{e}\nwanted: {needle}");
        }
    }
}
