//! One matrix of a lumped scenario's `[matrices]`: the file read (a regular
//! file, within [`crate::input::MAX_MATRIX_BYTES`]), its format recognised
//! from the content or forced (`format = "..."`), and parsed by the pure
//! readers of `squeal-core`: Matrix Market, Nastran DMIG, Abaqus
//! `*MATRIX OUTPUT` and Harwell–Boeing (with ANSYS's mapping file).

use crate::error::InputError;
use squeal_core::labelled::LabelledMatrix;
use squeal_core::model::lumped::Triplets;
use std::path::{Path, PathBuf};

/// The formats `[matrices]` reads, as `format = "..."` names them.
pub const FORMATS: [&str; 4] = ["matrix-market", "dmig", "abaqus", "harwell-boeing"];

/// A matrix as read, with where it came from.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MatrixInfo {
    /// `M`, `K` or `C`.
    pub key: String,
    /// The file as written in the scenario.
    pub file: String,
    /// The matrix's name in the file (DMIG), else empty.
    pub name: String,
    /// The format read (`matrix-market`, `dmig`, `abaqus`,
    /// `abaqus-coordinate`, `harwell-boeing`).
    pub format: String,
    /// The ANSYS mapping file read beside a Harwell–Boeing file, if any.
    pub mapping: Option<String>,
    /// Size (square).
    pub size: usize,
    /// Stored nonzeros, both triangles.
    pub nonzeros: usize,
    /// Declared or given as one triangle.
    pub symmetric: bool,
}

/// Which format `text` is in, from its content: a `%%MatrixMarket` header,
/// DMIG cards, a Harwell–Boeing header (a type such as `RSA` opening its
/// third line), else Abaqus's comma- or blank-separated numbers.
pub fn detect(text: &str) -> Option<&'static str> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let first = lines.clone().next()?.trim_start();
    if first.to_ascii_lowercase().starts_with("%%matrixmarket") {
        return Some("matrix-market");
    }
    if text.lines().any(|l| {
        let u = l.trim_start().to_ascii_uppercase();
        u.starts_with("DMIG") && !u.starts_with("DMIGPCH")
    }) {
        return Some("dmig");
    }
    let third = text
        .lines()
        .nth(2)
        .unwrap_or("")
        .trim_start()
        .to_ascii_uppercase();
    let t = third.as_bytes();
    if t.len() >= 3
        && b"RPC".contains(&t[0])
        && b"SUHZR".contains(&t[1])
        && b"AE".contains(&t[2])
        && third[3..]
            .split_whitespace()
            .all(|w| w.parse::<i64>().is_ok())
    {
        return Some("harwell-boeing");
    }
    let data = lines.find(|l| !l.trim_start().starts_with('*'))?;
    let fields = data
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|w| !w.is_empty())
        .count();
    (fields == 3 || fields == 5).then_some("abaqus")
}

/// The mapping file ANSYS's `HBMAT` writes beside `path`: the file name
/// without its extension, `.mapping`, in any letter case.
fn mapping_beside(path: &Path) -> Option<PathBuf> {
    let stem = path.file_stem()?.to_string_lossy().to_lowercase();
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut found: Vec<PathBuf> = std::fs::read_dir(&dir)
        .ok()?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy().to_lowercase() == format!("{stem}.mapping"))
                .unwrap_or(false)
        })
        .collect();
    found.sort();
    found.into_iter().next()
}

/// Read matrix `key` from `path` (shown as `shown`), in `format` if given
/// (else recognised), the matrix `name` where the file holds several.
pub fn read(
    key: &str,
    path: &Path,
    shown: &str,
    name: Option<&str>,
    format: Option<&str>,
) -> Result<(LabelledMatrix, MatrixInfo), InputError> {
    let fail = |e: String| InputError(format!("matrices: {key} = '{shown}': {e}"));
    let text = crate::input::read_regular_text(path, crate::input::MAX_MATRIX_BYTES)
        .map_err(|e| fail(e.to_string()))?;
    let format = match format {
        Some(f) => FORMATS
            .iter()
            .copied()
            .find(|x| *x == f)
            .ok_or_else(|| fail(format!("format = \"{f}\": expected one of {}", FORMATS.join(", "))))?,
        None => detect(&text).ok_or_else(|| {
            fail(format!(
                "format not recognised (expected {}); name it with {{ file = \"{shown}\", format = \"...\" }}",
                FORMATS.join(", ")
            ))
        })?,
    };
    if name.is_some() && format != "dmig" {
        return Err(fail(format!(
            "name: only a DMIG file holds several matrices (this is {format})"
        )));
    }
    let mut mapping = None;
    let m = match format {
        "matrix-market" => LabelledMatrix {
            name: String::new(),
            format: "matrix-market",
            labels: None,
            symmetric: text
                .lines()
                .next()
                .is_some_and(|h| h.to_ascii_lowercase().contains("symmetric")),
            triplets: squeal_core::matrix_market::parse(&text).map_err(fail)?,
        },
        "dmig" => match name {
            Some(n) => squeal_core::dmig::parse_named(&text, n).map_err(fail)?,
            None => {
                let mut all = squeal_core::dmig::parse(&text).map_err(fail)?;
                if all.len() != 1 {
                    let names: Vec<&str> = all.iter().map(|m| m.name.as_str()).collect();
                    return Err(fail(format!(
                        "holds {} matrices ({}): name one, {{ file = \"{shown}\", name = \"{}\" }}",
                        all.len(),
                        names.join(", "),
                        names[0]
                    )));
                }
                all.remove(0)
            }
        },
        "abaqus" => squeal_core::abaqus::parse(&text).map_err(fail)?,
        _ => {
            let map_path = mapping_beside(path);
            let map_text = match &map_path {
                Some(p) => Some(
                    crate::input::read_regular_text(p, crate::input::MAX_MATRIX_BYTES)
                        .map_err(|e| fail(format!("mapping file {}: {e}", p.display())))?,
                ),
                None => None,
            };
            // Shown beside the matrix file as the scenario names it.
            mapping = map_path.and_then(|p| {
                let f = p.file_name()?.to_owned();
                Some(Path::new(shown).with_file_name(f).display().to_string())
            });
            squeal_core::harwell_boeing::parse(&text, map_text.as_deref()).map_err(fail)?
        }
    };
    let t: &Triplets = &m.triplets;
    let info = MatrixInfo {
        key: key.into(),
        file: shown.into(),
        name: m.name.clone(),
        format: m.format.into(),
        mapping,
        size: t.rows,
        nonzeros: t.entries.len(),
        symmetric: m.symmetric,
    };
    Ok((m, info))
}

/// The dofs of matrices whose files name them (`<node>_<component>`):
/// their union, in order of first appearance through `M`, `K`, `C`, or the
/// order of `dofs` if the scenario lists them (then the same names); each
/// matrix's triplets renumbered onto it. Refuses a mix of named and
/// numbered matrices.
pub fn union_dofs(
    read: &mut [(LabelledMatrix, MatrixInfo)],
    listed: Option<&[String]>,
) -> Result<Vec<String>, InputError> {
    use std::collections::HashMap;
    let named: Vec<bool> = read.iter().map(|(m, _)| m.labels.is_some()).collect();
    if named.iter().any(|x| *x) && !named.iter().all(|x| *x) {
        let (a, b) = (
            read.iter().find(|(m, _)| m.labels.is_some()).unwrap(),
            read.iter().find(|(m, _)| m.labels.is_none()).unwrap(),
        );
        return Err(InputError(format!(
            "matrices: {} = '{}' names its dofs ({}) but {} = '{}' ({}) numbers them: give every matrix in a format with node and dof labels, or all numbered",
            a.1.key, a.1.file, a.1.format, b.1.key, b.1.file, b.1.format
        )));
    }
    let order = |k: &str| ["M", "K", "C"].iter().position(|x| *x == k).unwrap_or(3);
    read.sort_by_key(|(_, i)| order(&i.key));
    let mut union: Vec<String> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    for (m, _) in read.iter() {
        for l in m.labels.as_deref().unwrap_or(&[]) {
            if !index.contains_key(l) {
                index.insert(l.clone(), union.len());
                union.push(l.clone());
            }
        }
    }
    if let Some(listed) = listed {
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for (i, d) in listed.iter().enumerate() {
            if seen.insert(d.as_str(), i).is_some() {
                return Err(InputError(format!("dofs: '{d}' is listed twice")));
            }
            if !index.contains_key(d) {
                return Err(InputError(format!(
                    "dofs: '{d}' is in no matrix (the matrices' dofs are {})",
                    ends(&union)
                )));
            }
        }
        if let Some(d) = union.iter().find(|d| !seen.contains_key(d.as_str())) {
            return Err(InputError(format!(
                "dofs: '{d}' of the matrices is not listed (list every dof of the matrices, or leave dofs out)"
            )));
        }
        union = listed.to_vec();
        index = union
            .iter()
            .enumerate()
            .map(|(i, d)| (d.clone(), i))
            .collect();
    }
    let n = union.len();
    for (m, _) in read.iter_mut() {
        let labels = m.labels.as_deref().unwrap_or(&[]);
        let map: Vec<usize> = labels.iter().map(|l| index[l]).collect();
        for e in &mut m.triplets.entries {
            *e = (map[e.0], map[e.1], e.2);
        }
        m.triplets.rows = n;
        m.triplets.cols = n;
    }
    Ok(union)
}

/// `a, b, c, …, y, z (N)` for a long list.
pub fn ends(names: &[String]) -> String {
    if names.len() <= 8 {
        names.join(", ")
    } else {
        format!(
            "{}, …, {} ({})",
            names[..3].join(", "),
            names[names.len() - 3..].join(", "),
            names.len()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_recognised_from_their_content() {
        assert_eq!(
            detect("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1.0\n"),
            Some("matrix-market")
        );
        assert_eq!(
            detect("$ punch\nDMIG    KAAX           0       6       2       0\n"),
            Some("dmig")
        );
        assert_eq!(
            detect("title                                                                   key\n             3             1             1             1\nRSA                        2             2             3             0\n(10I8)          (10I8)          (4E20.12)\n"),
            Some("harwell-boeing")
        );
        assert_eq!(detect("** Abaqus\n1,1,1,1,2.5e6\n"), Some("abaqus"));
        assert_eq!(detect("1 1 2.5e6\n"), Some("abaqus"));
        assert_eq!(detect("hello world\n"), None);
        assert_eq!(detect(""), None);
    }
}
