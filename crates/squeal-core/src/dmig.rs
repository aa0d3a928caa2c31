//! Nastran `DMIG` matrices (direct matrix input at points), as written by
//! `PARAM,EXTOUT,DMIGPCH` (the punch file) or as bulk data, in the MSC,
//! Autodesk and Altair (OptiStruct) Quick Reference Guides' layout:
//!
//! ```text
//! header:  DMIG  NAME  0   IFO  TIN  TOUT  POLAR  (blank)  NCOL
//! column:  DMIG  NAME  GJ  CJ   (blank)  G1 C1 A1 (B1)  G2 C2 A2 (B2) …
//! ```
//!
//! - cards in small field (8-character fields, continuation lines starting
//!   with `+` or a blank), large field (`DMIG*`, 16-character fields,
//!   continuation lines starting with `*`) and free field (comma-separated;
//!   or apart by blanks, `DMIG K 1 2 1 2 29988.`, as ANSYS's `*DMAT` reads);
//!   `$` starts a comment; columns 73–80 (field 10: continuation marker or
//!   punch sequence number) are ignored, except that a marker starting with
//!   `+` or `*` must be followed by a continuation line;
//! - forms `IFO` 1 (square, every entry given) and 6 (symmetric, one
//!   triangle given: expanded; an entry given in both triangles must have
//!   the same value); rectangular forms (2, 9) are refused;
//! - real single (`TIN` 1) and double (`TIN` 2) precision; complex (3, 4) is
//!   refused; numbers in Nastran's forms (`1.5+3`, `-2.-4`, `1.5D+3`, `.5`);
//! - the column layouts of MSC/Autodesk (field 5 blank, `G1` in field 6) and
//!   of OptiStruct (`G1` in field 5) are both read: the entries after `CJ`
//!   are read as a stream of `G C A` with blank fields skipped (a component
//!   left blank, for a scalar point, is 0: the real `A` has a decimal point,
//!   the integer `C` has none).
//!
//! Dofs are named `<G>_<C>` (a scalar point `<G>_0`) in order of first
//! appearance: each column's `GJ_CJ`, then its rows. A file holds several
//! matrices; [`parse`] returns all it can read, in the order their names
//! first appear, and [`parse_named`] the one of a given name.
//! `NCOL` is used only by rectangular forms and is ignored. Other cards
//! (`GRID`, `BEGIN BULK`, …) are skipped; reading stops at `ENDDATA`.
//! Pure: takes text; errors are one line, `line N: what is wrong`.

use crate::labelled::{fortran_real, is_integer, Entries, LabelledMatrix, Labels, Symmetry};
use std::borrow::Cow;
use std::collections::HashMap;

/// A field of a card: its text (trimmed; empty if blank) and 1-based line.
#[derive(Debug, Clone)]
struct Field<'a> {
    text: Cow<'a, str>,
    line: usize,
}

/// A DMIG card: fields 2… in order (field 1 and the continuation markers
/// dropped), each line's fields padded to its nominal count (8, large 4).
#[derive(Debug, Clone)]
struct Card<'a> {
    first: usize,
    last: usize,
    fields: Vec<Field<'a>>,
}

impl Card<'_> {
    fn field(&self, k: usize) -> &str {
        self.fields.get(k).map_or("", |f| &f.text)
    }
    fn line_of(&self, k: usize) -> usize {
        self.fields.get(k).map_or(self.first, |f| f.line)
    }
}

/// Is field 1 that of a large-field line (`DMIG*`, or `*` continuing)?
fn is_large(field1: &str) -> bool {
    field1.starts_with('*') || field1.ends_with('*')
}

/// One line of a card with its fields apart by blanks (`DMIG K 1 2 1 2
/// 29988.`, as ANSYS's `*DMAT` import takes): field 1 (empty on a
/// continuation line without a marker) and the data fields.
fn split_blanks(body: &str, first: bool) -> (Cow<'_, str>, Vec<Cow<'_, str>>) {
    let mut tokens: Vec<Cow<str>> = body.split_whitespace().map(Cow::Borrowed).collect();
    let marker = !tokens.is_empty()
        && (first || (tokens[0].starts_with(['+', '*']) && fortran_real(&tokens[0]).is_none()));
    let field1 = if marker {
        tokens.remove(0)
    } else {
        Cow::Borrowed("")
    };
    let nominal = if is_large(&field1) { 4 } else { 8 };
    tokens.resize(tokens.len().max(nominal), Cow::Borrowed(""));
    (field1, tokens)
}

/// A line's fields: field 1, the data fields and field 10.
type Split<'a> = (Cow<'a, str>, Vec<Cow<'a, str>>, Cow<'a, str>);

/// One line split into field 1, the data fields and field 10.
fn split_line(body: &str) -> Split<'_> {
    if body.contains(',') {
        let mut tokens: Vec<Cow<str>> = body.split(',').map(|t| Cow::Borrowed(t.trim())).collect();
        let field1 = tokens.remove(0);
        let nominal = if is_large(&field1) { 4 } else { 8 };
        let mut marker = Cow::Borrowed("");
        if tokens.len() > nominal && fortran_real(&tokens[nominal]).is_none() {
            marker = tokens.remove(nominal);
        } else if tokens
            .last()
            .is_some_and(|t| t.starts_with(['+', '*']) && fortran_real(t).is_none())
        {
            // a continuation marker after fewer than 8 fields
            marker = tokens.pop().unwrap_or_default();
        }
        tokens.resize(tokens.len().max(nominal), Cow::Borrowed(""));
        return (field1, tokens, marker);
    }
    if body.is_ascii() && !body.contains('\t') {
        // fixed field, the common case: fields are slices of the line
        let cut = |a: usize, b: usize| -> Cow<str> {
            Cow::Borrowed(
                body.get(a.min(body.len())..b.min(body.len()))
                    .unwrap_or("")
                    .trim(),
            )
        };
        let field1 = cut(0, 8);
        let (width, nominal) = if is_large(&field1) { (16, 4) } else { (8, 8) };
        let data = (0..nominal)
            .map(|k| cut(8 + k * width, 8 + (k + 1) * width))
            .collect();
        return (field1, data, cut(72, 80));
    }
    // fixed field: expand tabs to 8-column stops
    let mut chars: Vec<char> = Vec::with_capacity(body.len());
    for ch in body.chars() {
        if ch == '\t' {
            chars.resize((chars.len() / 8 + 1) * 8, ' ');
        } else {
            chars.push(ch);
        }
    }
    let cut = |a: usize, b: usize| -> Cow<str> {
        Cow::Owned(
            chars[a.min(chars.len())..b.min(chars.len())]
                .iter()
                .collect::<String>()
                .trim()
                .to_string(),
        )
    };
    let field1 = cut(0, 8);
    let (width, nominal) = if is_large(&field1) { (16, 4) } else { (8, 8) };
    let data = (0..nominal)
        .map(|k| cut(8 + k * width, 8 + (k + 1) * width))
        .collect();
    (field1, data, cut(72, 80))
}

/// The DMIG cards of a bulk-data or punch text.
fn cards(text: &str) -> Result<Vec<Card<'_>>, String> {
    let mut out = Vec::new();
    let mut current: Option<Card> = None;
    let mut pending: Option<(usize, String)> = None;
    let mut blanks = false;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let body = raw.find('$').map_or(raw, |k| &raw[..k]);
        if body.trim().is_empty() {
            continue;
        }
        let new_card = body.starts_with(|c: char| c.is_ascii_alphabetic());
        if let Some((l, m)) = pending.take() {
            if new_card {
                return Err(format!(
                    "line {l}: the DMIG card continues (field 10 '{m}') but line {line} starts a new card: a missing continuation line"
                ));
            }
        }
        let (mut field1, mut data, mut marker) = split_line(body);
        if new_card {
            out.extend(current.take());
            let first = body.split_whitespace().next().unwrap_or("");
            blanks = !body.contains(',')
                && !matches!(field1.to_ascii_uppercase().as_str(), "DMIG" | "DMIG*")
                && matches!(first.to_ascii_uppercase().as_str(), "DMIG" | "DMIG*");
            if blanks {
                (field1, data) = split_blanks(body, true);
                marker = Cow::Borrowed("");
            }
            let name = field1.to_ascii_uppercase();
            if name == "ENDDATA" {
                break;
            }
            if name == "DMIG" || name == "DMIG*" {
                current = Some(Card {
                    first: line,
                    last: line,
                    fields: Vec::new(),
                });
            }
        }
        if let Some(card) = current.as_mut() {
            if blanks && !new_card {
                data = split_blanks(body, false).1;
                marker = Cow::Borrowed("");
            }
            card.last = line;
            card.fields
                .extend(data.into_iter().map(|text| Field { text, line }));
            if marker.starts_with(['+', '*']) {
                pending = Some((line, marker.to_string()));
            }
        }
    }
    if let Some((l, m)) = pending {
        return Err(format!(
            "line {l}: the DMIG card continues (field 10 '{m}') but the file ends: a missing continuation line"
        ));
    }
    out.extend(current);
    Ok(out)
}

/// A matrix being gathered: its header card and its column cards.
struct Gathered<'a> {
    name: String,
    header: Option<Card<'a>>,
    columns: Vec<Card<'a>>,
}

/// Parse every DMIG matrix of a Nastran bulk-data or punch text (see the
/// module docs), in the order their names first appear. A matrix of a form
/// or type squeal does not read (rectangular forms 2 and 9, complex types 3
/// and 4) is left out, as the `VAX` matrix (form 9) that
/// `PARAM,EXTOUT,DMIGPCH` punches beside `KAAX` and `MAAX`; if no matrix is
/// left, the first one's reason is the error. Errors name the line and what
/// is wrong.
pub fn parse(text: &str) -> Result<Vec<LabelledMatrix>, String> {
    let mut out = Vec::new();
    let mut refused = Vec::new();
    for g in gather(text)? {
        match matrix(g)? {
            Ok(m) => out.push(m),
            Err(why) => refused.push(why),
        }
    }
    if out.is_empty() {
        return Err(refused.swap_remove(0));
    }
    Ok(out)
}

/// Parse the DMIG matrix `name` (any letter case) of a Nastran bulk-data or
/// punch text: as [`parse`], but a form or type squeal does not read is an
/// error, and so is a name the file does not have (the message lists the
/// names it has).
pub fn parse_named(text: &str, name: &str) -> Result<LabelledMatrix, String> {
    let gathered = gather(text)?;
    let names: Vec<String> = gathered.iter().map(|g| g.name.clone()).collect();
    let g = gathered
        .into_iter()
        .find(|g| g.name.eq_ignore_ascii_case(name))
        .ok_or_else(|| {
            format!(
                "no DMIG matrix {name} in the file (it has {})",
                names.join(", ")
            )
        })?;
    matrix(g)?
}

/// The DMIG cards of a text gathered by matrix name, in order of first
/// appearance (at least one).
fn gather(text: &str) -> Result<Vec<Gathered<'_>>, String> {
    let mut gathered: Vec<Gathered> = Vec::new();
    let mut by_name: HashMap<String, usize> = HashMap::new();
    for card in cards(text)? {
        let name = card.field(0).to_string();
        if name.is_empty() {
            return Err(format!("line {}: DMIG card without a name", card.first));
        }
        if name.eq_ignore_ascii_case("UACCEL") {
            continue; // DMIG,UACCEL: enforced accelerations, another layout
        }
        let k = *by_name.entry(name.to_ascii_uppercase()).or_insert_with(|| {
            gathered.push(Gathered {
                name: name.clone(),
                header: None,
                columns: Vec::new(),
            });
            gathered.len() - 1
        });
        let g = &mut gathered[k];
        if card.field(1) == "0" {
            if let Some(h) = &g.header {
                return Err(format!(
                    "line {}: DMIG {name}: a second header card (the first is on line {})",
                    card.first, h.first
                ));
            }
            g.header = Some(card);
        } else {
            g.columns.push(card);
        }
    }
    if gathered.is_empty() {
        return Err("no DMIG card in the file".into());
    }
    Ok(gathered)
}

/// Read one gathered matrix: `Err` for a bad file, `Ok(Err)` for a form
/// or type squeal does not read.
#[allow(clippy::type_complexity)]
fn matrix(g: Gathered) -> Result<Result<LabelledMatrix, String>, String> {
    let name = g.name;
    let Some(header) = g.header else {
        return Err(format!(
            "line {}: DMIG {name}: columns without a header card (DMIG {name} 0 IFO TIN …)",
            g.columns[0].first
        ));
    };
    let int_at = |k: usize, what: &str| -> Result<i64, String> {
        let s = header.field(k);
        if is_integer(s) {
            s.parse::<i64>().map_err(|_| {
                format!(
                    "line {}: DMIG {name}: {what} '{s}' is too large",
                    header.line_of(k)
                )
            })
        } else {
            Err(format!(
                "line {}: DMIG {name}: {what} '{s}' is not an integer",
                header.line_of(k)
            ))
        }
    };
    let ifo = int_at(2, "form IFO")?;
    let symmetry = match ifo {
        1 => Symmetry::General,
        6 => Symmetry::Declared,
        2 | 9 => {
            return Ok(Err(format!(
                "line {}: DMIG {name}: form IFO={ifo} (rectangular) is not supported: squeal reads square matrices, form 1 (square) or 6 (symmetric)",
                header.line_of(2)
            )))
        }
        _ => {
            return Err(format!(
                "line {}: DMIG {name}: unknown form IFO={ifo} (1 square, 6 symmetric)",
                header.line_of(2)
            ))
        }
    };
    let tin = int_at(3, "type TIN")?;
    match tin {
        1 | 2 => {}
        3 | 4 => {
            return Ok(Err(format!(
                "line {}: DMIG {name}: complex matrix (TIN={tin}) is not supported: a mass, stiffness or damping matrix is real (TIN 1 or 2)",
                header.line_of(3)
            )))
        }
        _ => {
            return Err(format!(
                "line {}: DMIG {name}: unknown type TIN={tin} (1 real single, 2 real double)",
                header.line_of(3)
            ))
        }
    }
    let mut labels = Labels::default();
    // (point, component) → index, so that a label is formatted once per dof
    let mut ids: HashMap<(u64, u64), usize> = HashMap::new();
    let mut dof = |g: u64, c: u64, labels: &mut Labels| {
        *ids.entry((g, c))
            .or_insert_with(|| labels.get(format!("{g}_{c}")))
    };
    let mut entries = Entries::default();
    for card in &g.columns {
        let point = |k: usize| -> Result<u64, String> {
            let s = card.field(k);
            match s.parse::<u64>() {
                Ok(p) if p > 0 && is_integer(s) => Ok(p),
                _ => Err(format!(
                    "line {}: DMIG {name}: '{s}' is not a grid or scalar point id (an integer > 0)",
                    card.line_of(k)
                )),
            }
        };
        let component = |s: &str, line: usize| -> Result<u64, String> {
            if s.is_empty() {
                return Ok(0);
            }
            match s.parse::<u64>() {
                Ok(c) if c <= 6 && is_integer(s) => Ok(c),
                _ => Err(format!(
                    "line {line}: DMIG {name}: component '{s}' is not 0…6 (blank or 0 for a scalar point)"
                )),
            }
        };
        let gj = point(1)?;
        let cj = component(card.field(2), card.line_of(2))?;
        let col = dof(gj, cj, &mut labels);
        let mut stream = card.fields.iter().skip(3).filter(|f| !f.text.is_empty());
        let mut count = 0;
        while let Some(g) = stream.next() {
            let gi = match g.text.parse::<u64>() {
                Ok(p) if p > 0 && is_integer(&g.text) => p,
                _ => {
                    return Err(format!(
                        "line {}: DMIG {name} column {gj}_{cj}: expected a grid or scalar point id, got '{}'{}",
                        g.line,
                        g.text,
                        if fortran_real(&g.text).is_some() {
                            " (an imaginary part, or a field out of place?)"
                        } else {
                            ""
                        }
                    ))
                }
            };
            let cut = || {
                format!(
                    "line {}: DMIG {name} column {gj}_{cj}: the entry of row point {gi} is cut short (G, C, A expected; a truncated card or a missing continuation line?)",
                    card.last
                )
            };
            let next = stream.next().ok_or_else(cut)?;
            let (ci, a) = if is_integer(&next.text) {
                let ci = component(&next.text, next.line)?;
                (ci, stream.next().ok_or_else(cut)?)
            } else {
                (0, next)
            };
            let v = fortran_real(&a.text).ok_or_else(|| {
                format!(
                    "line {}: DMIG {name} column {gj}_{cj}: '{}' is not a real number",
                    a.line, a.text
                )
            })?;
            let row = dof(gi, ci, &mut labels);
            let names = &labels.names;
            entries.add(row, col, v, a.line, &|i| names[i].clone())?;
            count += 1;
        }
        if count == 0 {
            return Err(format!(
                "line {}: DMIG {name} column {gj}_{cj} has no entries (a missing continuation line?)",
                card.first
            ));
        }
    }
    let n = labels.names.len();
    let names = &labels.names;
    let (triplets, symmetric) = entries.finish(n, symmetry, &|i| names[i].clone())?;
    Ok(Ok(LabelledMatrix {
        name,
        format: "dmig",
        labels: Some(labels.names),
        triplets,
        symmetric,
    }))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The test matrix's dofs (a grid's three translations, another grid's
    /// z, a scalar point) and values: symmetric K and an unsymmetric U.
    pub(crate) const DOFS: [(u64, u64); 5] = [(101, 1), (101, 2), (101, 3), (102, 3), (7, 0)];
    pub(crate) fn k_sym() -> Vec<Vec<f64>> {
        vec![
            vec![4.0, -1.25, 0.0, 0.5, 0.0],
            vec![-1.25, 3.0, 0.0, 0.0, 2.5e-3],
            vec![0.0, 0.0, 1500.0, -750.0, 0.0],
            vec![0.5, 0.0, -750.0, 800.0, 0.0],
            vec![0.0, 2.5e-3, 0.0, 0.0, 7.0],
        ]
    }
    pub(crate) fn u_unsym() -> Vec<Vec<f64>> {
        let mut u = k_sym();
        u[0][1] = -1.0;
        u[3][2] = -700.0;
        u
    }

    /// Dense, in the order of `DOFS`, from a labelled matrix.
    pub(crate) fn dense(m: &LabelledMatrix) -> Vec<Vec<f64>> {
        let labels = m.labels.as_ref().unwrap();
        assert_eq!(labels.len(), DOFS.len(), "{labels:?}");
        let pos = |i: usize| {
            DOFS.iter()
                .position(|(g, c)| format!("{g}_{c}") == labels[i])
                .unwrap()
        };
        let mut d = vec![vec![0.0; 5]; 5];
        assert_eq!((m.triplets.rows, m.triplets.cols), (5, 5));
        for &(r, c, v) in &m.triplets.entries {
            assert_eq!(d[pos(r)][pos(c)], 0.0, "entry ({r}, {c}) twice");
            d[pos(r)][pos(c)] = v;
        }
        d
    }

    #[derive(Clone, Copy, PartialEq, Debug)]
    enum Field {
        Small,
        Large,
        Free,
    }
    #[derive(Clone, Copy, PartialEq, Debug)]
    enum Layout {
        /// MSC/Autodesk: field 5 blank, G C A (B blank) in groups of four.
        Msc,
        /// OptiStruct: G1 in field 5, G C A (B blank) in groups of four.
        Opti,
        /// G C A packed, no blank fields.
        Packed,
    }
    #[derive(Clone, Copy, PartialEq, Debug)]
    enum Part {
        Lower,
        Upper,
        Both,
    }

    fn d_form(v: f64) -> String {
        let s = format!("{v:.9E}");
        let (m, e) = s.split_once('E').unwrap();
        format!("{m}D{:+03}", e.parse::<i32>().unwrap())
    }

    /// Write one DMIG matrix of the test's dofs.
    fn write(name: &str, ifo: u32, a: &[Vec<f64>], part: Part, f: Field, layout: Layout) -> String {
        let num = |v: f64| {
            if f == Field::Small {
                format!("{v:?}")
            } else {
                d_form(v)
            }
        };
        let per = if f == Field::Large { 4 } else { 8 };
        let mut cards: Vec<Vec<String>> = vec![vec![
            name.into(),
            "0".into(),
            ifo.to_string(),
            "2".into(),
            "0".into(),
        ]];
        for (j, (gj, cj)) in DOFS.iter().enumerate() {
            let mut fields = vec![name.to_string(), gj.to_string(), cj.to_string()];
            if layout == Layout::Msc {
                fields.push(String::new());
            }
            let mut any = false;
            for (i, (gi, ci)) in DOFS.iter().enumerate() {
                let keep = match part {
                    Part::Lower => i >= j,
                    Part::Upper => i <= j,
                    Part::Both => true,
                };
                if keep && a[i][j] != 0.0 {
                    any = true;
                    fields.extend([gi.to_string(), ci.to_string(), num(a[i][j])]);
                    if layout != Layout::Packed {
                        fields.push(String::new());
                    }
                    if layout == Layout::Opti && fields.len() == 7 {
                        fields.push(String::new()); // field 9 left blank
                    }
                }
            }
            if any {
                cards.push(fields);
            }
        }
        let mut s = String::from("$ written by the test\n");
        for fields in cards {
            for (k, chunk) in fields.chunks(per).enumerate() {
                match f {
                    Field::Small => {
                        s.push_str(if k == 0 { "DMIG    " } else { "+       " });
                        for x in chunk {
                            s.push_str(&format!("{x:<8}"));
                        }
                    }
                    Field::Large => {
                        s.push_str(if k == 0 { "DMIG*   " } else { "*       " });
                        for x in chunk {
                            s.push_str(&format!("{x:>16}"));
                        }
                    }
                    Field::Free => {
                        s.push_str(if k == 0 { "DMIG," } else { "+," });
                        s.push_str(&chunk.join(","));
                    }
                }
                s.push('\n');
            }
        }
        s
    }

    #[test]
    fn every_field_form_and_layout_gives_the_same_matrix() {
        let mut n = 0;
        for f in [Field::Small, Field::Large, Field::Free] {
            for layout in [Layout::Msc, Layout::Opti, Layout::Packed] {
                for part in [Part::Lower, Part::Upper, Part::Both] {
                    let text = write("KAAX", 6, &k_sym(), part, f, layout);
                    let m = parse(&text)
                        .unwrap_or_else(|e| panic!("{f:?} {layout:?} {part:?}: {e}\n{text}"));
                    assert_eq!(m.len(), 1);
                    assert_eq!(m[0].name, "KAAX");
                    assert_eq!(m[0].format, "dmig");
                    assert!(m[0].symmetric);
                    assert_eq!(dense(&m[0]), k_sym(), "{f:?} {layout:?} {part:?}\n{text}");
                    n += 1;
                }
                let text = write("UAAX", 1, &u_unsym(), Part::Both, f, layout);
                let m = parse(&text).unwrap_or_else(|e| panic!("{f:?} {layout:?}: {e}\n{text}"));
                assert!(!m[0].symmetric);
                assert_eq!(dense(&m[0]), u_unsym(), "{f:?} {layout:?}\n{text}");
                n += 1;
            }
        }
        assert_eq!(n, 36);
    }

    #[test]
    fn labels_in_order_of_first_appearance_and_several_matrices() {
        let text = format!(
            "{}{}",
            write("KAAX", 6, &k_sym(), Part::Lower, Field::Small, Layout::Msc),
            write("MAAX", 1, &u_unsym(), Part::Both, Field::Large, Layout::Msc)
        );
        let m = parse(&text).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!((m[0].name.as_str(), m[1].name.as_str()), ("KAAX", "MAAX"));
        // column 101_1's rows 101_1, 101_2, 102_3; then column 101_2's new row 7_0; then 101_3
        assert_eq!(
            m[0].labels.as_ref().unwrap(),
            &["101_1", "101_2", "102_3", "7_0", "101_3"]
        );
        // 8 lower-triangle entries (3 diagonal of the 5 + …) expanded: 5 diagonal + 2×4 off-diagonal
        assert_eq!(m[0].triplets.entries.len(), 13);
        assert_eq!(dense(&m[1]), u_unsym());
    }

    #[test]
    fn hand_written_cards_entry_by_entry() {
        // small field, MSC layout, Nastran numbers, a scalar point with a blank component
        let text = "\
$ a comment
BEGIN BULK
GRID    1               0.      0.      0.
DMIG    STIF    0       6       1                               
DMIG    STIF    27      1               27      1       3.+5            +C1
+C1     120     4       -2.5-1          5               1.5D+3
DMIG    STIF    5                       5               .5
ENDDATA
DMIG    STIF    9       1               9       1       1.
";
        let m = parse(text).unwrap();
        assert_eq!(m.len(), 1);
        let m = &m[0];
        assert_eq!(m.labels.as_ref().unwrap(), &["27_1", "120_4", "5_0"]);
        assert_eq!(
            m.triplets.entries,
            vec![
                (0, 0, 3e5),
                (1, 0, -0.25),
                (0, 1, -0.25),
                (2, 0, 1500.0),
                (0, 2, 1500.0),
                (2, 2, 0.5)
            ]
        );
        // OptiStruct: G1 in field 5 (the Altair QRG's example, made square)
        let text = "\
DMIG,STIF,0,1,2
DMIG,STIF,27,1,120,3,3.+5,+C
+C,120,4,2.5+10
DMIG,STIF,28,1,123,3,6.+7
";
        let m = &parse(text).unwrap()[0];
        assert_eq!(
            m.labels.as_ref().unwrap(),
            &["27_1", "120_3", "120_4", "28_1", "123_3"]
        );
        assert_eq!(
            m.triplets.entries,
            vec![(1, 0, 3e5), (2, 0, 2.5e10), (4, 3, 6e7)]
        );
        assert!(!m.symmetric);
    }

    #[test]
    fn fields_apart_by_blanks_and_marked_large_continuations() {
        // ANSYS *DMAT's "free field with blank separators" example, with a header
        let text =
            "DMIG stiff 0 6 2\nDMIG stiff 1 2 1 2 29988.\n1 6 149940. 2 2 -29988.\n  2 6 149940.\n";
        let m = &parse(text).unwrap()[0];
        assert_eq!(m.name, "stiff");
        // a long line: column 73 is no continuation marker here
        let long = format!("{text}DMIG stiff 3 1 3 1 1.0000000000000000 3 2 2.0000000000000000 3 3        +3.0000000000000000\nDMIG stiff 9 1 9 1 1.\n");
        assert_eq!(parse(&long).unwrap()[0].triplets.entries.len(), 7 + 6);
        assert_eq!(m.labels.as_ref().unwrap(), &["1_2", "1_6", "2_2", "2_6"]);
        assert_eq!(m.triplets.entries.len(), 7);
        assert_eq!(m.triplets.entries[0], (0, 0, 29988.0));
        assert_eq!(m.triplets.entries[1], (1, 0, 149940.0));
        assert_eq!(m.triplets.entries[3], (2, 0, -29988.0));
        // a large-field continuation with a named marker, and a tab
        let text = format!(
            "DMIG\tK\t0\t6\t2\n{:<72}*K1\n{:<72}\n",
            "DMIG*   K                              5               3",
            "*K1                    5               3-2.261491337E+08"
        );
        let m = &parse(&text).unwrap()[0];
        assert_eq!(m.labels.as_ref().unwrap(), &["5_3"]);
        assert_eq!(m.triplets.entries, vec![(0, 0, -2.261491337e8)]);
    }

    /// The layout of an MSC Nastran `PARAM,EXTOUT,DMIGPCH` punch file: the
    /// upper triangle column by column, `NCOL` in field 9 of the header,
    /// and a form-9 `VAX` matrix after `KAAX` and `MAAX`.
    const PUNCH: &str = "\
DMIG    KAAX           0       6       2       0                       4
DMIG*   KAAX                           1               3
*                      1               3 2.000000000D+06
DMIG*   KAAX                           1               4
*                      1               3 5.000000000D+05
*                      1               4 1.000000000D+06
DMIG*   KAAX                           2               3
*                      1               3-2.000000000D+06
*                      2               3 4.000000000D+06
DMIG*   KAAX                           2               4
*                      1               4 2.500000000D+05
*                      2               4 3.000000000D+06
DMIG    MAAX           0       6       2       0                       4
DMIG*   MAAX                           1               3
*                      1               3 1.250000000D+00
DMIG*   MAAX                           2               3
*                      2               3 2.500000000D+00
DMIG    VAX            0       9       2       0                       1
DMIG*   VAX                            1               0
*                      1               3 1.000000000D+00
*                      1               4 1.000000000D+00
";

    #[test]
    fn punch_file_with_a_rectangular_vax_and_named_matrices() {
        let m = parse(PUNCH).unwrap();
        assert_eq!(m.len(), 2);
        let k = &m[0];
        assert_eq!((k.name.as_str(), m[1].name.as_str()), ("KAAX", "MAAX"));
        assert_eq!(k.labels.as_ref().unwrap(), &["1_3", "1_4", "2_3", "2_4"]);
        assert!(k.symmetric);
        assert_eq!(
            k.triplets.entries,
            vec![
                (0, 0, 2e6),
                (0, 1, 5e5),
                (1, 0, 5e5),
                (1, 1, 1e6),
                (0, 2, -2e6),
                (2, 0, -2e6),
                (2, 2, 4e6),
                (1, 3, 2.5e5),
                (3, 1, 2.5e5),
                (3, 3, 3e6)
            ]
        );
        // MAAX names only the dofs with mass
        assert_eq!(m[1].labels.as_ref().unwrap(), &["1_3", "2_3"]);
        assert_eq!(m[1].triplets.entries, vec![(0, 0, 1.25), (1, 1, 2.5)]);
        assert_eq!(parse_named(PUNCH, "maax").unwrap(), m[1]);
        assert_eq!(
            parse_named(PUNCH, "VAX").unwrap_err(),
            "line 18: DMIG VAX: form IFO=9 (rectangular) is not supported: squeal reads square matrices, form 1 (square) or 6 (symmetric)"
        );
        assert_eq!(
            parse_named(PUNCH, "KGG").unwrap_err(),
            "no DMIG matrix KGG in the file (it has KAAX, MAAX, VAX)"
        );
        let only_vax = &PUNCH[PUNCH.find("DMIG    VAX").unwrap()..];
        assert!(parse(only_vax)
            .unwrap_err()
            .starts_with("line 1: DMIG VAX: form IFO=9"));
    }

    #[test]
    fn a_header_without_columns_is_an_empty_matrix() {
        let m = &parse("DMIG    E       0       6       2\n").unwrap()[0];
        assert_eq!((m.name.as_str(), m.triplets.rows), ("E", 0));
        assert_eq!(m.labels.as_deref(), Some(&[][..]));
    }

    #[test]
    fn punch_file_with_sequence_numbers() {
        // PARAM,EXTOUT,DMIGPCH style: large field, `$` lines, columns 73–80 numbered
        let body = [
            "DMIG    KAAX           0       6       2       0",
            "DMIG*   KAAX                         101               1",
            "*                    101               1 4.000000000D+00",
            "*                    101               2-1.250000000D+00",
            "DMIG*   KAAX                         101               2",
            "*                    101               2 3.000000000D+00",
        ];
        let mut text = String::from("$$ punch\n$ KAAX\n");
        for (k, l) in body.iter().enumerate() {
            text.push_str(&format!("{l:<72}{:>8}\n", k + 1));
        }
        let m = &parse(&text).unwrap()[0];
        assert_eq!(m.labels.as_ref().unwrap(), &["101_1", "101_2"]);
        assert_eq!(
            m.triplets.entries,
            vec![(0, 0, 4.0), (1, 0, -1.25), (0, 1, -1.25), (1, 1, 3.0)]
        );
    }

    #[test]
    fn bad_files_name_the_line() {
        let head = "DMIG    K       0       6       2\n";
        let card = "DMIG    K       1       1               1       1       2.";
        for (text, needle) in [
            ("GRID    1\n", "no DMIG card"),
            ("DMIG    K       0       9       2\n", "line 1: DMIG K: form IFO=9 (rectangular)"),
            ("\nDMIG    K       0       3       2\n", "line 2: DMIG K: unknown form IFO=3"),
            ("DMIG    K       0       6       3\n", "line 1: DMIG K: complex matrix (TIN=3)"),
            ("DMIG    K       0       6       x\n", "line 1: DMIG K: type TIN 'x' is not an integer"),
            (
                "DMIG    K       1       1               1       1       2.\nDMIG    K       1       2               1       1       2.\n",
                "line 1: DMIG K: columns without a header",
            ),
            (
                &format!("{head}DMIG    K       1       1               1       1       2.      \n+       1       1       3.\n"),
                "line 3: entry (row 1_1, column 1_1) given twice (first on line 2)",
            ),
            (
                &format!("{head}DMIG    K       1       1               2       1       2.\nDMIG    K       2       1               1       1       3.\n"),
                "line 3: entry (row 1_1, column 2_1) = 3 disagrees with (row 2_1, column 1_1) = 2 on line 2",
            ),
            (
                &format!("{head}DMIG    K       1       1               1       1       2.\n+       2       1\n"),
                "line 3: DMIG K column 1_1: the entry of row point 2 is cut short",
            ),
            (
                &format!("{head}{:<72}+A\nDMIG    K       2       1               2       1       2.\n", card),
                "line 2: the DMIG card continues (field 10 '+A') but line 3 starts a new card",
            ),
            (
                &format!("{head}{:<72}+A\n", card),
                "line 2: the DMIG card continues (field 10 '+A') but the file ends",
            ),
            (
                &format!("{head}DMIG*   K                              1               1\nDMIG    K       2       1               2       1       2.\n"),
                "line 2: DMIG K column 1_1 has no entries (a missing continuation line?)",
            ),
            (
                &format!("{head}DMIG    K       1       1               1       1       1.5x\n"),
                "line 2: DMIG K column 1_1: '1.5x' is not a real number",
            ),
            (
                &format!("{head}DMIG    K       1       7               1       1       1.\n"),
                "line 2: DMIG K: component '7' is not 0…6",
            ),
            (
                &format!("{head}DMIG    K       1       1               1       1       1.      2.\n"),
                "line 2: DMIG K column 1_1: expected a grid or scalar point id, got '2.' (an imaginary part",
            ),
            (
                &format!("{head}DMIG    K       -1      1               1       1       1.\n"),
                "line 2: DMIG K: '-1' is not a grid or scalar point id",
            ),
            (&format!("{head}{head}"), "line 2: DMIG K: a second header card (the first is on line 1)"),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(needle), "{text:?}:\n{e}\nwanted: {needle}");
        }
    }
}
