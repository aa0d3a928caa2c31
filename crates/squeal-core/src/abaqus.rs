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
//! The format is recognised by the number of fields (5 or 3) of the first
//! data line; every line must have the same. Blank lines and `**` comments
//! are skipped; a keyword line (`*USER ELEMENT`, `*MATRIX`, … as in element
//! matrix output) is refused: only assembled matrices are read. A matrix
//! given by one triangle (upper or lower) is symmetric and mirrored; one
//! given by both is symmetric if every entry equals its mirror, and is read
//! as given (unsymmetric) otherwise. An entry given twice is an error.
//! Pure: takes text; errors are one line, `line N: what is wrong`.

use crate::labelled::{fortran_real, Entries, LabelledMatrix, Labels, Symmetry};

/// Parse the text of an Abaqus `*MATRIX OUTPUT` file (see the module docs).
pub fn parse(text: &str) -> Result<LabelledMatrix, String> {
    let mut labels = Labels::default();
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
                "line {line}: keyword line '{t}': squeal reads the assembled matrices of *MATRIX GENERATE with *MATRIX OUTPUT (FORMAT=MATRIX INPUT or COORDINATE), not element matrix output"
            ));
        }
        let mut w: Vec<&str> = t.split(',').map(str::trim).collect();
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
                    let name = if node < 0 {
                        format!("m{}_{d}", node.unsigned_abs())
                    } else {
                        format!("{node}_{d}")
                    };
                    Ok(labels.get(name))
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
