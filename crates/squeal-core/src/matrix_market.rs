//! Matrix Market text (the exchange format FE packages and SciPy's
//! `scipy.io.mmwrite` write): `%%MatrixMarket matrix coordinate|array
//! real|integer general|symmetric`, comments with `%`, a size line, then
//! 1-based `row col value` triplets (coordinate) or the values column by
//! column (array; for symmetric arrays the lower triangle). Symmetric
//! matrices are expanded to both triangles. Pure: takes text, returns
//! [`Triplets`]; the caller reads the file.

use crate::model::lumped::Triplets;

/// Parse Matrix Market text. Errors say what is wrong and on which line.
pub fn parse(text: &str) -> Result<Triplets, String> {
    let mut lines = text.lines().enumerate();
    let (_, header) = lines.next().ok_or("empty file")?;
    let words: Vec<String> = header.split_whitespace().map(str::to_lowercase).collect();
    if words.len() < 5 || words[0] != "%%matrixmarket" || words[1] != "matrix" {
        return Err(format!(
            "line 1: expected a header '%%MatrixMarket matrix coordinate real general', got '{}'",
            header.trim()
        ));
    }
    let coordinate = match words[2].as_str() {
        "coordinate" => true,
        "array" => false,
        f => {
            return Err(format!(
                "line 1: format '{f}' not supported (coordinate or array)"
            ))
        }
    };
    match words[3].as_str() {
        "real" | "integer" | "double" => {}
        f => {
            return Err(format!(
                "line 1: field '{f}' not supported (real or integer; a mass, stiffness or damping matrix is real)"
            ))
        }
    }
    let symmetric = match words[4].as_str() {
        "general" => false,
        "symmetric" => true,
        f => {
            return Err(format!(
                "line 1: symmetry '{f}' not supported (general or symmetric)"
            ))
        }
    };
    let mut data = lines.filter(|(_, l)| {
        let t = l.trim();
        !t.is_empty() && !t.starts_with('%')
    });
    let (size_line, size) = data.next().ok_or("no size line")?;
    let dims: Vec<usize> = size
        .split_whitespace()
        .map(|w| w.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("line {}: bad size line '{}'", size_line + 1, size.trim()))?;
    let num = |w: &str, line: usize| -> Result<f64, String> {
        let x: f64 = w
            .parse()
            .map_err(|_| format!("line {}: '{w}' is not a number", line + 1))?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(format!("line {}: {w} is not finite", line + 1))
        }
    };
    let mut t = Triplets::default();
    if coordinate {
        let [rows, cols, nnz] = dims[..] else {
            return Err(format!(
                "line {}: expected 'rows cols entries', got '{}'",
                size_line + 1,
                size.trim()
            ));
        };
        (t.rows, t.cols) = (rows, cols);
        for (line, l) in data.by_ref().take(nnz) {
            let w: Vec<&str> = l.split_whitespace().collect();
            if w.len() != 3 {
                return Err(format!(
                    "line {}: expected 'row col value', got '{}'",
                    line + 1,
                    l.trim()
                ));
            }
            let idx = |s: &str, max: usize| -> Result<usize, String> {
                match s.parse::<usize>() {
                    Ok(i) if i >= 1 && i <= max => Ok(i - 1),
                    _ => Err(format!(
                        "line {}: index '{s}' out of range 1..={max}",
                        line + 1
                    )),
                }
            };
            let (r, c, v) = (idx(w[0], rows)?, idx(w[1], cols)?, num(w[2], line)?);
            if symmetric && c > r {
                return Err(format!(
                    "line {}: a symmetric file lists the lower triangle only (row ≥ col), got ({}, {})",
                    line + 1,
                    r + 1,
                    c + 1
                ));
            }
            t.entries.push((r, c, v));
            if symmetric && r != c {
                t.entries.push((c, r, v));
            }
        }
        let got = t
            .entries
            .iter()
            .filter(|e| !symmetric || e.0 >= e.1)
            .count();
        if got != nnz {
            return Err(format!(
                "the size line promises {nnz} entries, the file has {got}"
            ));
        }
    } else {
        let [rows, cols] = dims[..] else {
            return Err(format!(
                "line {}: expected 'rows cols', got '{}'",
                size_line + 1,
                size.trim()
            ));
        };
        (t.rows, t.cols) = (rows, cols);
        let mut values = Vec::new();
        for (line, l) in data.by_ref() {
            for w in l.split_whitespace() {
                values.push(num(w, line)?);
            }
        }
        let mut k = 0;
        for c in 0..cols {
            let start = if symmetric { c } else { 0 };
            for r in start..rows {
                let v = *values
                    .get(k)
                    .ok_or_else(|| format!("too few values for a {rows}×{cols} array"))?;
                k += 1;
                if v != 0.0 {
                    t.entries.push((r, c, v));
                    if symmetric && r != c {
                        t.entries.push((c, r, v));
                    }
                }
            }
        }
        if k != values.len() {
            return Err(format!("too many values for a {rows}×{cols} array"));
        }
    }
    if let Some((line, l)) = data.next() {
        return Err(format!(
            "line {}: unexpected data after the last entry: '{}'",
            line + 1,
            l.trim()
        ));
    }
    Ok(t)
}

/// Write triplets as Matrix Market coordinate text (general, 1-based), e.g.
/// for test fixtures and examples.
pub fn write(t: &Triplets) -> String {
    let mut s = format!(
        "%%MatrixMarket matrix coordinate real general\n{} {} {}\n",
        t.rows,
        t.cols,
        t.entries.len()
    );
    for (r, c, v) in &t.entries {
        s.push_str(&format!("{} {} {v:e}\n", r + 1, c + 1));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense(t: &Triplets) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; t.cols]; t.rows];
        for (r, c, v) in &t.entries {
            d[*r][*c] += v;
        }
        d
    }

    #[test]
    fn coordinate_symmetric_and_array_agree() {
        let coord = "%%MatrixMarket matrix coordinate real symmetric\n% a comment\n3 3 4\n1 1 2.0\n2 1 -1\n2 2 2\n3 3 1.5e0\n";
        let array =
            "%%MatrixMarket matrix array real general\n3 3\n2\n-1\n0\n-1\n2\n0\n0\n0\n1.5\n";
        let sym_array = "%%MatrixMarket matrix array real symmetric\n3 3\n2 -1 0\n2 0\n1.5\n";
        let want = vec![
            vec![2.0, -1.0, 0.0],
            vec![-1.0, 2.0, 0.0],
            vec![0.0, 0.0, 1.5],
        ];
        assert_eq!(dense(&parse(coord).unwrap()), want);
        assert_eq!(dense(&parse(array).unwrap()), want);
        assert_eq!(dense(&parse(sym_array).unwrap()), want);
        let back = parse(&write(&parse(coord).unwrap())).unwrap();
        assert_eq!(dense(&back), want);
    }

    #[test]
    fn bad_files_say_where() {
        for (text, needle) in [
            ("", "empty"),
            (
                "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1\n",
                "complex",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1.0\n",
                "line 3",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1.0\n",
                "promises 2",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 abc\n",
                "abc",
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 2 1.0\n",
                "lower triangle",
            ),
            (
                "%%MatrixMarket matrix array real general\n2 2\n1 2 3\n",
                "too few",
            ),
            ("hello\n", "header"),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }
}
