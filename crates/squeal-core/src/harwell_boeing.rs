//! Harwell–Boeing matrices (Duff, Grimes & Lewis, "Users' Guide for the
//! Harwell-Boeing Sparse Matrix Collection", 1992): assembled real
//! symmetric (`RSA`: one triangle stored column by column, as ANSYS's
//! `HBMAT` writes K and M; expanded to both triangles) and unsymmetric
//! (`RUA`, as SciPy's `scipy.io.hb_write` writes) square matrices.
//!
//! The header is 4 lines (5 with a right-hand side): title and key; the
//! card counts `TOTCRD PTRCRD INDCRD VALCRD RHSCRD`; `MXTYPE NROW NCOL
//! NNZERO NELTVL`; the Fortran formats of the pointers, row indices and
//! values (`(10I8)`, `(I14)`, `(4E20.12)`, `(1P,4E20.12)`, `(d25.15)`, …),
//! whose field widths are used to split the lines (numbers may run
//! together); a line that does not fit the widths but whose numbers are
//! apart by blanks is read by its blanks (SciPy's `hb_write` declares
//! `(3E25.16)` and writes its values 24 characters wide). Then the column pointers, the row indices and the values,
//! each section starting on a new line; a right-hand side after the values
//! (HBMAT writes one by default) is skipped. Pattern-only (`P..`), complex
//! (`C..`), skew, rectangular and elemental (`..E`) matrices are refused.
//! Counts are checked against what the file holds, and nothing is allocated
//! from a count before the file shows the data.
//!
//! ANSYS's mapping file (`HBMAT,…,Mapping=YES`, `Fname.mapping`): a header
//! line `Matrix Eqn   Node   DOF`, then `equation node label` per line;
//! it names the dofs `<node>_<component>` (`UX…ROTZ` → 1…6, other labels
//! kept: `1203_PRES`). Without it the dofs are numbered
//! ([`LabelledMatrix::labels`] is `None`).
//! Pure: takes text; errors are one line, `line N: what is wrong`.

use crate::labelled::{
    ansys_component, fortran_real, is_integer, Entries, LabelledMatrix, Symmetry,
};

/// A Fortran edit descriptor's (repeat count, field width): `(10I8)` →
/// (10, 8); `(1P,4E20.12)` → (4, 20); `(d25.15)` → (1, 25).
fn fortran_format(f: &str) -> Option<(usize, usize)> {
    let s: String = f
        .trim()
        .strip_prefix('(')?
        .strip_suffix(')')?
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_uppercase();
    // a scale factor `kP` or `kP,` first
    let s = match s.find('P') {
        Some(p)
            if s[..p]
                .trim_start_matches('-')
                .bytes()
                .all(|b| b.is_ascii_digit()) =>
        {
            s[p + 1..].trim_start_matches(',').to_string()
        }
        _ => s,
    };
    let digits = s.bytes().take_while(u8::is_ascii_digit).count();
    let repeat = if digits == 0 {
        1
    } else {
        s[..digits].parse().ok()?
    };
    let rest = &s[digits..];
    let rest = ["ES", "EN", "I", "E", "D", "F", "G"]
        .iter()
        .find_map(|l| rest.strip_prefix(l))?;
    let w = rest.bytes().take_while(u8::is_ascii_digit).count();
    let width: usize = rest[..w].parse().ok()?;
    let tail = &rest[w..];
    let ok_tail = tail.is_empty()
        || (tail.starts_with('.') && tail[1..].bytes().all(|b| b.is_ascii_digit() || b == b'E'));
    (repeat >= 1 && width >= 1 && ok_tail).then_some((repeat, width))
}

/// Read `count` numbers from `lines[start..]`, `per` per line in fields of
/// `width`; returns them with their 1-based lines, and the next line index.
fn section<T>(
    lines: &[&str],
    start: usize,
    count: usize,
    (per, width): (usize, usize),
    what: &str,
    read: impl Fn(&str) -> Option<T>,
) -> Result<(Vec<(T, usize)>, usize), String> {
    let mut out = Vec::new();
    let mut i = start;
    while out.len() < count {
        let Some(l) = lines.get(i) else {
            return Err(format!(
                "line {}: the file ends after {} of the {count} {what} the header promises",
                lines.len(),
                out.len()
            ));
        };
        let line = i + 1;
        let want = per.min(count - out.len());
        // every line but the last of a section is full; a line that does not
        // fit the widths but holds its numbers apart by blanks is read by
        // its blanks (SciPy's hb_write writes its E25.16 values 24 wide)
        let values = match by_width(l, line, want, per, width, what, &read) {
            Ok(v) if v.len() == want => v,
            first => {
                let tokens: Vec<&str> = l.split_whitespace().collect();
                match tokens.iter().map(|t| read(t)).collect::<Option<Vec<T>>>() {
                    Some(v) if v.len() == want => v,
                    _ => {
                        return Err(match first {
                            Err(e) => e,
                            Ok(v) if v.is_empty() => format!(
                                "line {line}: blank line where the {what} should be ({} of {count} read)",
                                out.len()
                            ),
                            Ok(v) => format!(
                                "line {line}: {} of the {want} {what} expected on the line (the format gives {per} per line, {width} characters each)",
                                v.len()
                            ),
                        })
                    }
                }
            }
        };
        out.extend(values.into_iter().map(|v| (v, line)));
        i += 1;
    }
    Ok((out, i))
}

/// The `want` numbers of one line in fields of `width` (fewer if the line
/// ends early).
fn by_width<T>(
    l: &str,
    line: usize,
    want: usize,
    per: usize,
    width: usize,
    what: &str,
    read: &impl Fn(&str) -> Option<T>,
) -> Result<Vec<T>, String> {
    let chars: Vec<char> = l.chars().collect();
    let mut out = Vec::new();
    for k in 0..want {
        let a = k * width;
        if a >= chars.len() {
            break;
        }
        let field: String = chars[a..(a + width).min(chars.len())].iter().collect();
        if field.trim().is_empty() {
            if chars[a..].iter().all(|c| c.is_whitespace()) {
                break;
            }
            return Err(format!(
                "line {line}: blank field {} among the {what} (fields of {width} characters)",
                k + 1
            ));
        }
        out.push(read(field.trim()).ok_or_else(|| {
            format!(
                "line {line}: '{}' is not one of the {what} (fields of {width} characters)",
                field.trim()
            )
        })?);
    }
    if chars.len() > want * width && !chars[want * width..].iter().all(|c| c.is_whitespace()) {
        return Err(format!(
            "line {line}: more than {want} {what} on the line (the format gives {per} per line, {width} characters each)"
        ));
    }
    Ok(out)
}

fn index(s: &str) -> Option<usize> {
    is_integer(s).then(|| s.parse::<usize>().ok()).flatten()
}

/// Parse a Harwell–Boeing text, with the text of ANSYS's mapping file if
/// there is one (see the module docs). Errors name the line; errors in the
/// mapping file say "mapping line N".
pub fn parse(text: &str, mapping: Option<&str>) -> Result<LabelledMatrix, String> {
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() < 4 {
        return Err(format!(
            "line {}: the file ends inside the 4-line Harwell-Boeing header",
            lines.len()
        ));
    }
    let counts: Vec<usize> = lines[1]
        .split_whitespace()
        .map(index)
        .collect::<Option<_>>()
        .filter(|c: &Vec<usize>| c.len() >= 4)
        .ok_or_else(|| {
            format!(
                "line 2: expected the card counts 'TOTCRD PTRCRD INDCRD VALCRD [RHSCRD]', got '{}'",
                lines[1].trim()
            )
        })?;
    let rhscrd = counts.get(4).copied().unwrap_or(0);
    let mut w3 = lines[2].split_whitespace();
    let mxtype = w3.next().unwrap_or("").to_ascii_uppercase();
    let dims: Vec<usize> = w3
        .map(index)
        .collect::<Option<_>>()
        .filter(|d: &Vec<usize>| d.len() >= 3)
        .ok_or_else(|| {
            format!(
                "line 3: expected 'MXTYPE NROW NCOL NNZERO [NELTVL]', got '{}'",
                lines[2].trim()
            )
        })?;
    let t: Vec<char> = mxtype.chars().collect();
    if t.len() != 3 {
        return Err(format!(
            "line 3: matrix type '{mxtype}' is not three letters (RSA, RUA, …)"
        ));
    }
    match t[0] {
        'R' => {}
        'P' => return Err(format!("line 3: matrix type {mxtype} is a pattern without values: squeal needs a real matrix (RSA or RUA)")),
        'C' => return Err(format!("line 3: matrix type {mxtype} is complex: a mass, stiffness or damping matrix is real (RSA or RUA)")),
        _ => return Err(format!("line 3: unknown matrix type {mxtype} (RSA or RUA)")),
    }
    let symmetry = match t[1] {
        'S' | 'H' => Symmetry::Declared,
        'U' => Symmetry::General,
        'Z' => return Err(format!("line 3: matrix type {mxtype} is skew-symmetric: not supported (RSA or RUA)")),
        'R' => return Err(format!("line 3: matrix type {mxtype} is rectangular: squeal reads square matrices (RSA or RUA)")),
        _ => return Err(format!("line 3: unknown matrix type {mxtype} (RSA or RUA)")),
    };
    if t[2] != 'A' {
        return Err(format!(
            "line 3: matrix type {mxtype} is {}: squeal reads assembled matrices (RSA or RUA)",
            if t[2] == 'E' { "elemental" } else { "unknown" }
        ));
    }
    let (nrow, ncol, nnz) = (dims[0], dims[1], dims[2]);
    if nrow != ncol {
        return Err(format!(
            "line 3: a {nrow}×{ncol} matrix: squeal reads square matrices"
        ));
    }
    let mut formats = Vec::new();
    let mut rest = lines[3];
    while let Some(a) = rest.find('(') {
        let mut depth = 0;
        let mut end = None;
        for (k, ch) in rest[a..].char_indices() {
            match ch {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(a + k);
                        break;
                    }
                }
                _ => {}
            }
        }
        let Some(e) = end else { break };
        formats.push(&rest[a..=e]);
        rest = &rest[e + 1..];
    }
    if formats.len() < 3 {
        return Err(format!(
            "line 4: expected the Fortran formats of the pointers, indices and values, got '{}'",
            lines[3].trim()
        ));
    }
    let fmt = |k: usize| {
        fortran_format(formats[k]).ok_or_else(|| {
            format!(
                "line 4: Fortran format {} is not supported (a repeat count, a letter I, E, D, F or G, a width: (10I8), (1P,4E20.12))",
                formats[k]
            )
        })
    };
    let (pf, inf, vf) = (fmt(0)?, fmt(1)?, fmt(2)?);
    let start = if rhscrd > 0 { 5 } else { 4 };
    if lines.len() < start {
        return Err(format!(
            "line {}: the file ends inside the 5-line header (RHSCRD = {rhscrd} announces a right-hand side line)",
            lines.len()
        ));
    }
    let (ptr, next) = section(
        &lines,
        start,
        ncol.saturating_add(1),
        pf,
        "column pointers",
        index,
    )?;
    let (ind, next) = section(&lines, next, nnz, inf, "row indices", index)?;
    let (val, _) = section(&lines, next, nnz, vf, "values", fortran_real)?;
    let labels = match mapping {
        Some(m) => Some(read_mapping(m, ncol)?),
        None => None,
    };
    let name = |i: usize| match &labels {
        Some(l) => l[i].clone(),
        None => (i + 1).to_string(),
    };
    if ptr[0].0 != 1 {
        return Err(format!(
            "line {}: the first column pointer is {}, not 1",
            ptr[0].1, ptr[0].0
        ));
    }
    let mut entries = Entries::default();
    for j in 0..ncol {
        let (a, b) = (ptr[j].0, ptr[j + 1].0);
        if b < a || b > nnz + 1 {
            return Err(format!(
                "line {}: column pointer {b} (column {}) is {} (pointers rise from 1 to NNZERO + 1 = {})",
                ptr[j + 1].1,
                j + 2,
                if b < a { "less than the one before" } else { "beyond the entries" },
                nnz + 1
            ));
        }
        for k in a - 1..b - 1 {
            let (r, rl) = ind[k];
            if r < 1 || r > nrow {
                return Err(format!("line {rl}: row index {r} is outside 1…{nrow}"));
            }
            entries.add(r - 1, j, val[k].0, val[k].1, &name)?;
        }
    }
    let (last, line) = ptr[ncol];
    if last != nnz + 1 {
        return Err(format!(
            "line {line}: the last column pointer is {last}, not NNZERO + 1 = {}",
            nnz + 1
        ));
    }
    let (triplets, symmetric) = entries.finish(ncol, symmetry, &name)?;
    Ok(LabelledMatrix {
        name: String::new(),
        format: "harwell-boeing",
        labels,
        triplets,
        symmetric,
    })
}

/// Dof labels of ANSYS's mapping file for an `n`-equation matrix.
fn read_mapping(text: &str, n: usize) -> Result<Vec<String>, String> {
    let mut labels: Vec<Option<String>> = vec![None; n];
    let mut seen = std::collections::HashMap::new();
    for (i, l) in text.lines().enumerate() {
        let line = i + 1;
        let w: Vec<&str> = l.split_whitespace().collect();
        if w.is_empty() || !is_integer(w[0]) {
            continue; // the header `Matrix Eqn  Node  DOF`
        }
        if w.len() != 3 {
            return Err(format!(
                "mapping line {line}: expected 'equation node dof', got '{}'",
                l.trim()
            ));
        }
        let e = match index(w[0]) {
            Some(e) if e >= 1 && e <= n => e,
            _ => {
                return Err(format!(
                    "mapping line {line}: equation {} is outside the matrix's 1…{n}",
                    w[0]
                ))
            }
        };
        let node = w[1]
            .parse::<i64>()
            .map_err(|_| format!("mapping line {line}: node '{}' is not an integer", w[1]))?;
        let label = format!("{node}_{}", ansys_component(w[2]));
        if labels[e - 1].is_some() {
            return Err(format!("mapping line {line}: equation {e} mapped twice"));
        }
        if let Some(first) = seen.insert(label.clone(), line) {
            return Err(format!(
                "mapping line {line}: dof {label} mapped twice (first on mapping line {first})"
            ));
        }
        labels[e - 1] = Some(label);
    }
    labels
        .into_iter()
        .enumerate()
        .map(|(i, l)| {
            l.ok_or_else(|| format!("the mapping file has no line for equation {}", i + 1))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dmig::tests::{k_sym, u_unsym};
    use crate::labelled::tests::dense_by;

    const NUMBERS: [&str; 5] = ["1", "2", "3", "4", "5"];

    /// Write `a` (lower triangle if `symmetric`) with `per` values per line
    /// in fields of `width` (`{:.prec E}`), pointers and indices as `(8I5)`.
    fn write(a: &[Vec<f64>], symmetric: bool, per: usize, width: usize, prec: usize) -> String {
        let n = a.len();
        let (mut ptr, mut ind, mut val) = (vec![1], Vec::new(), Vec::new());
        for j in 0..n {
            for i in if symmetric { j } else { 0 }..n {
                if a[i][j] != 0.0 {
                    ind.push(i + 1);
                    val.push(a[i][j]);
                }
            }
            ptr.push(ind.len() + 1);
        }
        let lines = |k: usize, per: usize| k.div_ceil(per);
        let (pc, ic, vc) = (
            lines(ptr.len(), 8),
            lines(ind.len(), 8),
            lines(val.len(), per),
        );
        let mut s = format!(
            "{:<72}{:<8}\n{:>14}{:>14}{:>14}{:>14}{:>14}\n{:<14}{:>14}{:>14}{:>14}{:>14}\n{:<16}{:<16}{:<20}\n",
            "test matrix",
            "KEY",
            pc + ic + vc,
            pc,
            ic,
            vc,
            0,
            if symmetric { "RSA" } else { "RUA" },
            n,
            n,
            val.len(),
            0,
            "(8I5)",
            "(8I5)",
            format!("(1P,{per}E{width}.{prec})")
        );
        for chunk in ptr.chunks(8) {
            s.extend(chunk.iter().map(|p| format!("{p:>5}")));
            s.push('\n');
        }
        for chunk in ind.chunks(8) {
            s.extend(chunk.iter().map(|p| format!("{p:>5}")));
            s.push('\n');
        }
        for chunk in val.chunks(per) {
            s.extend(
                chunk
                    .iter()
                    .map(|v| format!("{:>width$}", format!("{v:.prec$E}"))),
            );
            s.push('\n');
        }
        s
    }

    #[test]
    fn rsa_and_rua_give_the_same_matrix() {
        for (per, width, prec) in [(4, 20, 12), (3, 25, 16), (5, 8, 3)] {
            let m = parse(&write(&k_sym(), true, per, width, prec), None).unwrap();
            assert!(m.symmetric);
            assert_eq!(m.format, "harwell-boeing");
            assert_eq!(m.labels, None);
            // 8 stored entries of the lower triangle, 13 expanded
            assert_eq!(m.triplets.entries.len(), 13);
            assert_eq!(dense_by(&m, &NUMBERS), k_sym(), "{per} {width}");
            let m = parse(&write(&u_unsym(), false, per, width, prec), None).unwrap();
            assert!(!m.symmetric);
            assert_eq!(dense_by(&m, &NUMBERS), u_unsym());
        }
        // (1P,5E8.3): the values run together
        let text = write(&k_sym(), true, 5, 8, 3);
        assert!(
            text.contains(" 4.000E0-1.250E05.000E-1 3.000E02.500E-3"),
            "{text}"
        );
    }

    /// ANSYS's layout (HBMAT, ASCII, with a right-hand side and a mapping
    /// file), as in a file exported by ANSYS 2020-era MAPDL.
    const ANSYS: &str = "\
Stiffness matrix from ANSYS FULL file dumped into Harwell-Boeing format         
            14             4             4             4             3
RSA                        3             3             4             0
(I14)           (I14)           (d25.15)            (d25.15)            
F                          1             3
             1
             3
             4
             5
             1
             3
             2
             3
    0.200000000000000D+01
   -0.100000000000000D+01
    0.300000000000000D+01
    0.400000000000000D+01
    0.000000000000000D+00
    0.000000000000000D+00
    0.100000000000000D+01
";
    const MAPPING: &str = "    Matrix Eqn          Node    DOF     
             1           672    UX  
             2           672    ROTY
             3           673    PRES
";

    #[test]
    fn ansys_hbmat_with_rhs_and_mapping() {
        let m = parse(ANSYS, Some(MAPPING)).unwrap();
        assert_eq!(m.labels.as_ref().unwrap(), &["672_1", "672_5", "673_PRES"]);
        assert!(m.symmetric);
        assert_eq!(
            m.triplets.entries,
            vec![
                (0, 0, 2.0),
                (2, 0, -1.0),
                (0, 2, -1.0),
                (1, 1, 3.0),
                (2, 2, 4.0)
            ]
        );
        let m = parse(ANSYS, None).unwrap();
        assert_eq!(m.labels, None);
        assert_eq!(m.triplets.entries.len(), 5);
    }

    #[test]
    fn values_running_together_are_split_by_width() {
        let text = "\
title
3 1 1 1
RUA 2 2 3 0
(3I2) (3I2) (3E10.3)
 1 3 4
 1 2 1
-1.250E+00-3.000E-01 7.500E+02
";
        let m = parse(text, None).unwrap();
        assert_eq!(
            m.triplets.entries,
            vec![(0, 0, -1.25), (1, 0, -0.3), (0, 1, 750.0)]
        );
    }

    #[test]
    fn empty_columns_and_crlf() {
        // column 2 has no entries; Windows line ends
        let text = "t\r\n3 1 1 1\r\nRSA 3 3 2 0\r\n(4I3) (2I3) (2E10.3)\r\n  1  2  2  3\r\n  1  3\r\n 1.000E+00 2.000E+00\r\n";
        let m = parse(text, None).unwrap();
        assert_eq!((m.triplets.rows, m.triplets.cols), (3, 3));
        assert_eq!(m.triplets.entries, vec![(0, 0, 1.0), (2, 2, 2.0)]);
    }

    #[test]
    fn fortran_formats() {
        for (f, want) in [
            ("(10I8)", Some((10, 8))),
            ("(I14)", Some((1, 14))),
            ("(4E20.12)", Some((4, 20))),
            ("(1P4E20.12)", Some((4, 20))),
            ("(1P,4E20.12)", Some((4, 20))),
            ("(5E16.8)", Some((5, 16))),
            ("(d25.15)", Some((1, 25))),
            ("(3E25.16E3)", Some((3, 25))),
            ("( 8F10.3 )", Some((8, 10))),
            ("(4ES20.12)", Some((4, 20))),
            ("(4(1X,E19.12))", None),
            ("(A8)", None),
            ("10I8", None),
        ] {
            assert_eq!(fortran_format(f), want, "{f}");
        }
    }

    #[test]
    fn bad_files_name_the_line() {
        let good = write(&k_sym(), true, 4, 20, 12);
        let lines: Vec<&str> = good.lines().collect();
        let with = |k: usize, l: &str| {
            let mut v = lines.clone();
            v[k] = l;
            v.join("\n")
        };
        let cut = |k: usize| lines[..k].join("\n");
        for (text, needle) in [
            (
                "x\n".to_string(),
                "line 1: the file ends inside the 4-line Harwell-Boeing header",
            ),
            (with(1, "a b c d"), "line 2: expected the card counts"),
            (
                with(2, "PSA 5 5 8 0"),
                "line 3: matrix type PSA is a pattern without values",
            ),
            (with(2, "CUA 5 5 8 0"), "line 3: matrix type CUA is complex"),
            (
                with(2, "RSE 5 5 8 0"),
                "line 3: matrix type RSE is elemental",
            ),
            (
                with(2, "RRA 5 4 8 0"),
                "line 3: matrix type RRA is rectangular",
            ),
            (with(2, "RUA 5 4 8 0"), "line 3: a 5×4 matrix"),
            (
                with(3, "(8I5) (8I5) (4(1X,E19.12))"),
                "line 4: Fortran format (4(1X,E19.12)) is not supported",
            ),
            (
                with(2, "RSA 5 5 10 0"),
                "line 7: 1 of the 2 row indices expected on the line",
            ),
            (
                cut(9),
                "line 9: the file ends after 8 of the 9 values the header promises",
            ),
            (
                with(2, "RSA 500 500 9 0"),
                "line 5: 6 of the 8 column pointers expected on the line",
            ),
            (
                with(2, "RSA 5000000000000 5000000000000 9 0"),
                "line 5: 6 of the 8 column pointers expected",
            ),
            (
                with(
                    7,
                    "  4.000000000000E+00 -1.250000000000E+00  5.000000000000E-01",
                ),
                "line 8: 3 of the 4 values expected on the line",
            ),
            (
                cut(7),
                "line 7: the file ends after 0 of the 9 values the header promises",
            ),
            (
                with(4, "    2    4    6    8    9   10"),
                "line 5: the first column pointer is 2, not 1",
            ),
            (
                with(4, "    1    4    3    8    9   10"),
                "line 5: column pointer 3 (column 3) is less than the one before",
            ),
            (
                with(4, "    1    4    6    8    9   11"),
                "line 5: column pointer 11 (column 6) is beyond the entries",
            ),
            (
                with(4, "    1    4    6    8    9    9"),
                "line 5: the last column pointer is 9, not NNZERO + 1 = 10",
            ),
            (
                with(5, "    1    2    4    2    5    3    4    9"),
                "line 6: row index 9 is outside 1…5",
            ),
            (
                with(5, "    1    1    4    2    5    3    4    4"),
                "line 8: entry (row 1, column 1) given twice (first on line 8)",
            ),
            (
                with(6, "    5    1"),
                "line 7: more than 1 row indices on the line",
            ),
            (
                with(7, "  4.000000000000E+00 -1.250000000000E+00  abc"),
                "line 8: 'abc' is not one of the values",
            ),
            (
                with(
                    7,
                    "  4.000000000000E+00                      5.000000000000E-01",
                ),
                "line 8: blank field 2 among the values",
            ),
            (
                with(7, ""),
                "line 8: blank line where the values should be (0 of 9 read)",
            ),
        ] {
            let e = parse(&text, None).map(|_| ()).expect_err(&text);
            assert!(e.contains(needle), "{text}\n{e}\nwanted: {needle}");
        }
        // a symmetric file giving both triangles with different values
        let text =
            "t\n3 1 1 1\nRSA 2 2 2 0\n(3I2) (3I2) (3E10.3)\n 1 2 3\n 2 1\n 1.000E+00 2.000E+00\n";
        let e = parse(text, None).unwrap_err();
        assert!(e.contains("line 7: entry (row 2, column 1) = 1 disagrees with (row 1, column 2) = 2 on line 7"), "{e}");
        // the mapping file
        for (map, needle) in [
            (
                "Matrix Eqn Node DOF\n1 672 UX\n2 672 UY\n",
                "the mapping file has no line for equation 3",
            ),
            (
                "1 672 UX\n2 672 UY\n3 673 UZ\n4 674 UX\n",
                "mapping line 4: equation 4 is outside the matrix's 1…3",
            ),
            (
                "1 672 UX\n2 672 UX\n3 673 UZ\n",
                "mapping line 2: dof 672_1 mapped twice (first on mapping line 1)",
            ),
            (
                "1 672 UX\n1 672 UY\n3 673 UZ\n",
                "mapping line 2: equation 1 mapped twice",
            ),
            (
                "1 672 UX\n2 672\n3 673 UZ\n",
                "mapping line 2: expected 'equation node dof'",
            ),
            (
                "1 672 UX\n2 x UY\n3 673 UZ\n",
                "mapping line 2: node 'x' is not an integer",
            ),
        ] {
            let e = parse(ANSYS, Some(map)).unwrap_err();
            assert!(e.contains(needle), "{map}\n{e}\nwanted: {needle}");
        }
    }
}
