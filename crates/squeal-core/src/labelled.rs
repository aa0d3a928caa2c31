//! Matrices read from FE files, with the names of their dofs: the common
//! output of the `dmig` (Nastran DMIG), `abaqus` (Abaqus
//! `*MATRIX OUTPUT`) and `harwell_boeing` (Harwell–Boeing, with
//! ANSYS's mapping file).
//!
//! Dofs are named `<node>_<component>` (`1203_3`); a Nastran scalar point is
//! `<id>_0`; an Abaqus internal node with negative label −L is `m<L>_<dof>`;
//! ANSYS's labels `UX, UY, UZ, ROTX, ROTY, ROTZ` become components 1…6 and
//! other labels keep their name (`1203_PRES`). Labels are numbered in order
//! of first appearance in the file (row and column labels of every entry, in
//! file order).
//!
//! Also here: the reader of Fortran real numbers shared by the formats
//! ([`fortran_real`]): `1.5E3`, `1.5D+3`, Nastran's `1.5+3` and `-2.-4`,
//! `.5`.

use crate::model::lumped::Triplets;
use std::collections::HashMap;

/// A matrix read from an FE file, with the names of its dofs.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelledMatrix {
    /// DMIG name, or `""` where the format has none.
    pub name: String,
    /// `"dmig"`, `"abaqus"`, `"abaqus-coordinate"` or `"harwell-boeing"`.
    pub format: &'static str,
    /// Dof names in order of index (`None`: numbered dofs, the 0-based
    /// index + 1 is the file's dof number).
    pub labels: Option<Vec<String>>,
    /// The entries, 0-based, square; a symmetric matrix given by one
    /// triangle is expanded to both triangles.
    pub triplets: Triplets,
    /// Symmetric as declared by the file: DMIG form 6, Harwell–Boeing `RSA`,
    /// an Abaqus file giving one triangle (or both, equal).
    pub symmetric: bool,
}

/// Parse a Fortran or Nastran real number: `1.5E3`, `1.5e-3`, `1.5D+3`,
/// `1.5+3` (Nastran's exponent without a letter), `-2.-4`, `.5`, `7.`,
/// `12`. `None` if it is not one or not finite.
pub fn fortran_real(s: &str) -> Option<f64> {
    let t = s.trim();
    if t.is_empty()
        || !t
            .bytes()
            .all(|b| b.is_ascii_digit() || b"+-.eEdD".contains(&b))
        || !t.bytes().any(|b| b.is_ascii_digit())
    {
        return None;
    }
    let t = t.replace(['d', 'D', 'e'], "E");
    let x: f64 = if t.contains('E') {
        t.parse().ok()?
    } else if let Some(i) = t[1..].find(['+', '-']).map(|i| i + 1) {
        format!("{}E{}", &t[..i], &t[i..]).parse().ok()?
    } else {
        t.parse().ok()?
    };
    x.is_finite().then_some(x)
}

/// Is `s` a plain integer (`12`, `-3`, `+4`)?
pub(crate) fn is_integer(s: &str) -> bool {
    let t = s.trim();
    let d = t.strip_prefix(['+', '-']).unwrap_or(t);
    !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit())
}

/// The name of an ANSYS dof label as a component: `UX…ROTZ` → `1…6`, any
/// other label kept (`PRES`).
pub(crate) fn ansys_component(label: &str) -> String {
    match label.to_ascii_uppercase().as_str() {
        "UX" => "1".into(),
        "UY" => "2".into(),
        "UZ" => "3".into(),
        "ROTX" => "4".into(),
        "ROTY" => "5".into(),
        "ROTZ" => "6".into(),
        other => other.to_string(),
    }
}

/// How a file's entries are to be taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Symmetry {
    /// As given (a square or unsymmetric matrix: DMIG form 1, HB `RUA`).
    General,
    /// Declared symmetric, one triangle given (DMIG form 6, HB `RSA`):
    /// mirrored; an entry given in both triangles must have equal values.
    Declared,
    /// Decide from the entries (Abaqus): no off-diagonal entry given with
    /// its mirror: one triangle, symmetric, mirrored; some given both ways:
    /// both triangles, as given (an unsymmetric matrix may have one-sided
    /// entries, as friction couplings), symmetric if every entry equals
    /// its mirror; an error if most entries are one-sided but some are not.
    Detect,
}

/// Dof labels in order of first appearance.
#[derive(Debug, Default)]
pub(crate) struct Labels {
    pub names: Vec<String>,
    index: HashMap<String, usize>,
}

impl Labels {
    /// The index of `name`, appended if new.
    pub fn get(&mut self, name: String) -> usize {
        if let Some(&i) = self.index.get(&name) {
            return i;
        }
        let i = self.names.len();
        self.index.insert(name.clone(), i);
        self.names.push(name);
        i
    }
}

/// Collects entries, refusing duplicates, then expands by [`Symmetry`].
#[derive(Debug, Default)]
pub(crate) struct Entries {
    /// `(row, col, value, 1-based line)`.
    list: Vec<(usize, usize, f64, usize)>,
    at: HashMap<(usize, usize), usize>,
}

impl Entries {
    /// Add an entry read on `line`; `name` names an index in messages.
    pub fn add(
        &mut self,
        r: usize,
        c: usize,
        v: f64,
        line: usize,
        name: &dyn Fn(usize) -> String,
    ) -> Result<(), String> {
        if let Some(&k) = self.at.get(&(r, c)) {
            return Err(format!(
                "line {line}: entry (row {}, column {}) given twice (first on line {})",
                name(r),
                name(c),
                self.list[k].3
            ));
        }
        self.at.insert((r, c), self.list.len());
        self.list.push((r, c, v, line));
        Ok(())
    }

    /// How many entries were read.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// The `n`×`n` triplets and whether the matrix is symmetric.
    pub fn finish(
        self,
        n: usize,
        mode: Symmetry,
        name: &dyn Fn(usize) -> String,
    ) -> Result<(Triplets, bool), String> {
        let mut t = Triplets {
            rows: n,
            cols: n,
            entries: Vec::with_capacity(self.list.len()),
        };
        let mirror =
            |e: &(usize, usize, f64, usize)| self.at.get(&(e.1, e.0)).map(|&k| self.list[k]);
        let symmetric = match mode {
            Symmetry::General => false,
            Symmetry::Declared => {
                for e in &self.list {
                    if let Some(m) = mirror(e) {
                        if e.0 != e.1 && m.2 != e.2 {
                            let (late, early) = if e.3 >= m.3 { (e, m) } else { (&m, *e) };
                            return Err(format!(
                                "line {}: entry (row {}, column {}) = {} disagrees with (row {}, column {}) = {} on line {} in a symmetric matrix",
                                late.3,
                                name(late.0),
                                name(late.1),
                                late.2,
                                name(early.0),
                                name(early.1),
                                early.2,
                                early.3
                            ));
                        }
                    }
                }
                true
            }
            Symmetry::Detect => {
                let off: Vec<_> = self.list.iter().filter(|e| e.0 != e.1).collect();
                let paired = off.iter().filter(|e| mirror(e).is_some()).count();
                let single = off.len() - paired;
                if paired == 0 {
                    true
                } else if single > paired {
                    let e = off.iter().find(|e| mirror(e).is_some()).unwrap();
                    let m = mirror(e).unwrap();
                    return Err(format!(
                        "line {}: entry (row {}, column {}) is given with its mirror (line {}), but most off-diagonal entries ({single} of {}) are given in one triangle only: give one triangle (symmetric) or both (any matrix)",
                        e.3.max(m.3),
                        name(e.0),
                        name(e.1),
                        e.3.min(m.3),
                        off.len()
                    ));
                } else {
                    single == 0 && off.iter().all(|e| mirror(e).is_some_and(|m| m.2 == e.2))
                }
            }
        };
        // one triangle given: mirror it; both given: as they are
        let mirror_singles = match mode {
            Symmetry::General => false,
            Symmetry::Declared => true,
            Symmetry::Detect => !self.list.iter().any(|e| e.0 != e.1 && mirror(e).is_some()),
        };
        for &(r, c, v, _) in &self.list {
            t.entries.push((r, c, v));
            if mirror_singles && r != c && !self.at.contains_key(&(c, r)) {
                t.entries.push((c, r, v));
            }
        }
        Ok((t, symmetric))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The `n`×`n` dense matrix of `m` with its dofs in the order `order`
    /// (labels, or the numbers `1…n` for numbered dofs); each entry once.
    pub(crate) fn dense_by(m: &LabelledMatrix, order: &[&str]) -> Vec<Vec<f64>> {
        let n = order.len();
        assert_eq!((m.triplets.rows, m.triplets.cols), (n, n));
        let name = |i: usize| match &m.labels {
            Some(l) => l[i].clone(),
            None => (i + 1).to_string(),
        };
        if let Some(l) = &m.labels {
            assert_eq!(l.len(), n, "{l:?}");
        }
        let pos = |i: usize| order.iter().position(|o| *o == name(i)).unwrap();
        let mut d = vec![vec![0.0; n]; n];
        for &(r, c, v) in &m.triplets.entries {
            assert_eq!(d[pos(r)][pos(c)], 0.0, "entry ({r}, {c}) twice");
            d[pos(r)][pos(c)] = v;
        }
        d
    }

    #[test]
    fn fortran_reals() {
        for (s, x) in [
            ("1.5+3", 1.5e3),
            ("-2.-4", -2e-4),
            ("1.5D+3", 1.5e3),
            ("1.5d3", 1.5e3),
            ("1.5E3", 1.5e3),
            ("1.5e-3", 1.5e-3),
            (".5", 0.5),
            ("-.5-1", -0.05),
            ("7.", 7.0),
            ("+7.", 7.0),
            ("12", 12.0),
            (" 0.183133800000000D+12 ", 0.1831338e12),
            ("0.123456-100", 0.123456e-100),
            ("1.E3", 1e3),
        ] {
            assert_eq!(fortran_real(s), Some(x), "{s}");
        }
        for s in ["", "abc", "1.5x", "inf", "nan", ".", "+", "1e999", "1.5++3"] {
            assert_eq!(fortran_real(s), None, "{s}");
        }
        assert!(is_integer("12") && is_integer("-3") && is_integer("+4"));
        assert!(!is_integer("1.") && !is_integer("") && !is_integer("-"));
        assert_eq!(ansys_component("rotz"), "6");
        assert_eq!(ansys_component("PRES"), "PRES");
    }

    #[test]
    fn symmetry_rules() {
        let nm = |i: usize| format!("d{i}");
        // one triangle, declared: mirrored
        let mut e = Entries::default();
        e.add(0, 0, 2.0, 1, &nm).unwrap();
        e.add(1, 0, -1.0, 2, &nm).unwrap();
        let (t, s) = e.finish(2, Symmetry::Declared, &nm).unwrap();
        assert!(s);
        assert_eq!(t.entries, vec![(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0)]);
        // both triangles equal: kept once each
        let mut e = Entries::default();
        e.add(1, 0, -1.0, 1, &nm).unwrap();
        e.add(0, 1, -1.0, 2, &nm).unwrap();
        let (t, s) = e.finish(2, Symmetry::Detect, &nm).unwrap();
        assert!(s);
        assert_eq!(t.entries, vec![(1, 0, -1.0), (0, 1, -1.0)]);
        // disagreeing: error in Declared, unsymmetric in Detect
        let mut e = Entries::default();
        e.add(1, 0, -1.0, 3, &nm).unwrap();
        e.add(0, 1, -1.5, 7, &nm).unwrap();
        let err = e.finish(2, Symmetry::Declared, &nm).unwrap_err();
        assert!(
            err.starts_with("line 7:") && err.contains("line 3"),
            "{err}"
        );
        let mut e = Entries::default();
        e.add(1, 0, -1.0, 3, &nm).unwrap();
        e.add(0, 1, -1.5, 7, &nm).unwrap();
        e.add(1, 1, 3.0, 8, &nm).unwrap();
        e.add(2, 1, 4.0, 9, &nm).unwrap();
        let (t, s) = e.finish(3, Symmetry::Detect, &nm).unwrap();
        assert!(!s);
        assert_eq!(t.entries.len(), 4);
        // both triangles, equal, and a one-sided entry (a friction
        // coupling): unsymmetric, as given, not mirrored
        let mut e = Entries::default();
        e.add(1, 0, -1.0, 3, &nm).unwrap();
        e.add(0, 1, -1.0, 4, &nm).unwrap();
        e.add(2, 1, 0.3, 5, &nm).unwrap();
        let (t, s) = e.finish(3, Symmetry::Detect, &nm).unwrap();
        assert!(!s);
        assert_eq!(t.entries, vec![(1, 0, -1.0), (0, 1, -1.0), (2, 1, 0.3)]);
        // mostly one triangle, one pair both ways: refused
        let mut e = Entries::default();
        e.add(1, 0, -1.0, 3, &nm).unwrap();
        e.add(2, 0, -1.0, 4, &nm).unwrap();
        e.add(2, 1, -1.0, 5, &nm).unwrap();
        e.add(3, 1, -1.0, 6, &nm).unwrap();
        e.add(0, 1, -1.0, 7, &nm).unwrap();
        let err = e.finish(4, Symmetry::Detect, &nm).unwrap_err();
        assert_eq!(err, "line 7: entry (row d1, column d0) is given with its mirror (line 3), but most off-diagonal entries (3 of 5) are given in one triangle only: give one triangle (symmetric) or both (any matrix)");
        // duplicates
        let mut e = Entries::default();
        e.add(1, 0, -1.0, 3, &nm).unwrap();
        let err = e.add(1, 0, -1.0, 5, &nm).unwrap_err();
        assert_eq!(
            err,
            "line 5: entry (row d1, column d0) given twice (first on line 3)"
        );
    }
}
