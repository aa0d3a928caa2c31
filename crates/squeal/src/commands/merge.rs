//! Shards of a map and `squeal merge DIR… --out DIR`.
//!
//! `squeal map … --shard K/N` computes the points whose flat index `i`
//! (row-major over y then x, see [`squeal_study::map::point`]) has
//! `i mod N = K` — interleaved, so that the expensive corners of a grid
//! spread over every task — and writes, through the staging swap (a shard
//! folder exists only once it is complete):
//!
//! - `shard.json`: the study it belongs to (command, squeal version, the
//!   resolved scenario and a hash of it, both axes with every value, whether
//!   it simulates), `k`, `n`, how its indices are chosen and how many, and
//!   the length and hash of `part.csv`;
//! - `part.csv`: its rows of `map.csv`, each led by its flat index, numbers
//!   written exactly (`{:e}` round-trips every f64).
//!
//! `merge` refuses (exit 2, one line with the reason) shards of different
//! studies, a missing shard (naming its point indices), a shard given twice,
//! and a shard whose `part.csv` is not the one its manifest describes
//! (truncated, edited); then it writes `map.csv` and the pictures through
//! [`crate::commands::map::write_map`], the writer of the unsharded map, so
//! the result is byte-identical to it.

use crate::commands::map::{report, write_map, write_rows, Labels};
use crate::run::{RunError, Staging};
use clap::Args;
use serde_json::{json, Value};
use squeal_study::map::{Axis, Outcome, CLASSES};
use squeal_study::scenario::InputError;
use squeal_study::Scenario;
use std::path::{Path, PathBuf};

/// The manifest of a shard.
pub const SHARD_FILE: &str = "shard.json";
/// A shard's rows.
pub const PART_FILE: &str = "part.csv";
/// The `format` of [`SHARD_FILE`].
const FORMAT: &str = "squeal-shard-1";

/// Shard `k` of `n` (`0 ≤ k < n`): the flat indices `i` with `i mod n = k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which slice, from 0.
    pub k: usize,
    /// How many slices.
    pub n: usize,
}

impl Shard {
    /// Parse `K/N` (the `--shard` flag).
    pub fn parse(s: &str) -> Result<Shard, InputError> {
        let bad = |why: &str| InputError(format!("--shard {s}: {why}"));
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| bad("expected K/N, e.g. 0/4"))?;
        let k: usize = k
            .trim()
            .parse()
            .map_err(|_| bad("K must be a whole number ≥ 0"))?;
        let n: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("N must be a whole number ≥ 1"))?;
        if n == 0 {
            return Err(bad("N must be at least 1"));
        }
        if k >= n {
            return Err(bad("K counts from 0 and must be less than N"));
        }
        Ok(Shard { k, n })
    }

    /// This shard's flat indices of a grid of `total` points, ascending.
    pub fn points(self, total: usize) -> Vec<usize> {
        (self.k..total).step_by(self.n).collect()
    }
}

/// FNV-1a, 64 bits: a fingerprint (not a cryptographic hash) of a
/// scenario's content or a part's bytes, to tell studies apart and find a
/// changed file.
pub fn fnv1a(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

fn axis_json(a: &Axis, label: &str) -> Value {
    let values: Vec<String> = a.values.iter().map(|v| format!("{v:e}")).collect();
    json!({ "name": a.name, "log": a.log, "label": label, "values": values })
}

/// The study a shard belongs to: every shard of one study has the same.
pub fn study_json(sc: &Scenario, labels: &Labels, x: &Axis, y: &Axis, transient: bool) -> Value {
    let content = sc.to_json();
    let text = serde_json::to_string(&content).unwrap_or_default();
    json!({
        "command": "map",
        "squeal_version": env!("CARGO_PKG_VERSION"),
        "transient": transient,
        "scenario": { "name": sc.name, "hash": fnv1a(text.as_bytes()), "content": content },
        "grid": { "x": axis_json(x, &labels.xl), "y": axis_json(y, &labels.yl) },
    })
}

/// Write a shard (`part.csv` then `shard.json`) into `stage`.
#[allow(clippy::too_many_arguments)]
pub fn write_part(
    stage: &Staging,
    study: &Value,
    s: Shard,
    x: &Axis,
    y: &Axis,
    points: &[usize],
    lin: &[(f64, f64)],
    trans: Option<&[Outcome]>,
) -> Result<(), RunError> {
    let mut bytes = Vec::new();
    write_rows(&mut bytes, x, y, points, lin, trans, true)
        .map_err(|e| RunError::Io(e.to_string()))?;
    let part = stage.path(PART_FILE);
    std::fs::write(&part, &bytes)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", part.display())))?;
    let doc = json!({
        "format": FORMAT,
        "study": study,
        "k": s.k,
        "n": s.n,
        "slicing": "interleaved: flat index i (row-major, y outer) belongs to shard i mod n",
        "points": points.len(),
        "part": { "file": PART_FILE, "rows": points.len(), "bytes": bytes.len(), "fnv1a": fnv1a(&bytes) },
    });
    let path = stage.path(SHARD_FILE);
    let text = serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?;
    std::fs::write(&path, text + "\n")
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
}

/// Arguments of `squeal merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shard folders (`squeal map … --shard K/N --out DIR`), all N of them.
    #[arg(required = true, value_name = "DIR")]
    shards: Vec<PathBuf>,
    /// Output folder for the merged map.
    #[arg(long)]
    out: PathBuf,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

fn refuse(msg: String) -> RunError {
    RunError::Input(InputError(msg))
}

/// One shard as read back.
struct Read {
    dir: PathBuf,
    doc: Value,
    k: usize,
    n: usize,
}

fn read_manifest(dir: &Path) -> Result<Read, RunError> {
    let d = dir.display();
    let path = dir.join(SHARD_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        refuse(format!(
            "{d}: not a complete shard ({SHARD_FILE}: {e}); recompute it with its `squeal map … --shard K/N`"
        ))
    })?;
    let doc: Value = serde_json::from_str(&text)
        .map_err(|e| refuse(format!("{d}: {SHARD_FILE} is damaged ({e})")))?;
    if doc["format"] != FORMAT {
        return Err(refuse(format!(
            "{d}: {SHARD_FILE} is not a squeal shard manifest (format {})",
            doc["format"]
        )));
    }
    let get = |key: &str| doc[key].as_u64().map(|v| v as usize);
    let (Some(k), Some(n)) = (get("k"), get("n")) else {
        return Err(refuse(format!("{d}: {SHARD_FILE} lacks k or n")));
    };
    if n == 0 || k >= n {
        return Err(refuse(format!("{d}: {SHARD_FILE} has shard {k}/{n}")));
    }
    Ok(Read {
        dir: dir.to_path_buf(),
        doc,
        k,
        n,
    })
}

/// Why two studies differ, in words, or None when they are the same.
fn difference(a: &Value, b: &Value) -> Option<String> {
    if a == b {
        return None;
    }
    let v = |s: &Value| s["squeal_version"].to_string();
    if a["squeal_version"] != b["squeal_version"] {
        return Some(format!("made by squeal {} and {}", v(a), v(b)));
    }
    if a["command"] != b["command"] || a["transient"] != b["transient"] {
        return Some("different kinds of map (linear and --transient)".into());
    }
    let h = |s: &Value| {
        format!(
            "{} (hash {})",
            s["scenario"]["name"].as_str().unwrap_or("?"),
            s["scenario"]["hash"].as_str().unwrap_or("?")
        )
    };
    if a["scenario"] != b["scenario"] {
        return Some(format!("different scenarios: {} and {}", h(a), h(b)));
    }
    if a["grid"] != b["grid"] {
        return Some("different grids (axes or their values)".into());
    }
    Some("different studies".into())
}

fn axis_of(v: &Value) -> Result<Axis, String> {
    let values = v["values"]
        .as_array()
        .ok_or("grid values missing")?
        .iter()
        .map(|s| {
            s.as_str()
                .and_then(|s| s.parse::<f64>().ok())
                .ok_or("bad grid value")
        })
        .collect::<Result<Vec<f64>, _>>()?;
    Ok(Axis {
        name: v["name"].as_str().ok_or("axis name missing")?.to_string(),
        values,
        log: v["log"].as_bool().unwrap_or(false),
    })
}

fn class_of(s: &str) -> Option<&'static str> {
    CLASSES.iter().copied().find(|c| *c == s)
}

/// Read a shard's `part.csv` into the slots of its points.
fn read_part(
    r: &Read,
    total: usize,
    lin: &mut [(f64, f64)],
    trans: &mut Option<Vec<Outcome>>,
) -> Result<(), RunError> {
    let d = r.dir.display();
    let path = r.dir.join(PART_FILE);
    let bytes = std::fs::read(&path)
        .map_err(|e| refuse(format!("{d}: not a complete shard ({PART_FILE}: {e})")))?;
    let part = &r.doc["part"];
    let want = Shard { k: r.k, n: r.n }.points(total);
    let rows = part["rows"].as_u64().unwrap_or(u64::MAX) as usize;
    if rows != want.len() || r.doc["points"].as_u64() != Some(want.len() as u64) {
        return Err(refuse(format!(
            "{d}: shard {}/{} of {total} points should hold {} rows, its manifest says {rows}",
            r.k,
            r.n,
            want.len()
        )));
    }
    if part["bytes"].as_u64() != Some(bytes.len() as u64)
        || part["fnv1a"].as_str() != Some(fnv1a(&bytes).as_str())
    {
        return Err(refuse(format!(
            "{d}: {PART_FILE} is truncated or changed ({} bytes, the manifest says {}); recompute this shard",
            bytes.len(),
            part["bytes"]
        )));
    }
    let text =
        String::from_utf8(bytes).map_err(|_| refuse(format!("{d}: {PART_FILE} is not text")))?;
    let mut lines = text.lines();
    lines.next();
    let bad = |line: usize, why: &str| refuse(format!("{d}: {PART_FILE} line {line}: {why}"));
    let mut count = 0;
    for (row, (line, &k)) in lines.zip(&want).enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f.get(i).and_then(|s| s.parse::<f64>().ok());
        if f.first().and_then(|s| s.parse::<usize>().ok()) != Some(k) {
            return Err(bad(row + 2, &format!("expected point {k}")));
        }
        let (Some(s), Some(fr)) = (num(3), num(4)) else {
            return Err(bad(row + 2, "bad number"));
        };
        lin[k] = (s, fr);
        if let Some(t) = trans.as_mut() {
            let (Some(class), Some(rms), Some(stick), Some(t_end)) =
                (f.get(5).and_then(|c| class_of(c)), num(6), num(7), num(8))
            else {
                return Err(bad(row + 2, "bad outcome"));
            };
            t[k] = Outcome {
                class,
                rms,
                stick_fraction: stick,
                t_end,
            };
        }
        count += 1;
    }
    if count != want.len() {
        return Err(refuse(format!(
            "{d}: {PART_FILE} holds {count} of its {} rows",
            want.len()
        )));
    }
    Ok(())
}

/// Indices as a short list: `2, 9, 16 … (40 in all)`.
fn some(indices: &[usize]) -> String {
    let head: Vec<String> = indices.iter().take(12).map(|i| i.to_string()).collect();
    if indices.len() > 12 {
        format!("{} … ({} in all)", head.join(", "), indices.len())
    } else {
        head.join(", ")
    }
}

/// Run the command.
pub fn run(a: MergeArgs) -> Result<(), RunError> {
    let shards = a
        .shards
        .iter()
        .map(|d| read_manifest(d))
        .collect::<Result<Vec<Read>, _>>()?;
    let first = &shards[0];
    let study = &first.doc["study"];
    for r in &shards[1..] {
        if let Some(why) = difference(study, &r.doc["study"]) {
            return Err(refuse(format!(
                "{} and {} belong to different studies: {why}",
                first.dir.display(),
                r.dir.display()
            )));
        }
        if r.n != first.n {
            return Err(refuse(format!(
                "{} is shard {}/{} but {} is shard {}/{}: the same study cut into different numbers of shards",
                first.dir.display(),
                first.k,
                first.n,
                r.dir.display(),
                r.k,
                r.n
            )));
        }
    }
    let n = first.n;
    let mut by_k: Vec<Option<&Read>> = vec![None; n];
    for r in &shards {
        if let Some(other) = by_k[r.k] {
            return Err(refuse(format!(
                "shard {}/{n} given twice: {} and {}",
                r.k,
                other.dir.display(),
                r.dir.display()
            )));
        }
        by_k[r.k] = Some(r);
    }
    let bad_grid = |e: String| refuse(format!("{}: {SHARD_FILE}: {e}", first.dir.display()));
    let x = axis_of(&study["grid"]["x"]).map_err(bad_grid)?;
    let y = axis_of(&study["grid"]["y"]).map_err(bad_grid)?;
    let total = x.values.len() * y.values.len();
    let missing: Vec<usize> = (0..n).filter(|k| by_k[*k].is_none()).collect();
    if !missing.is_empty() {
        let ks: Vec<String> = missing.iter().map(|k| format!("{k}/{n}")).collect();
        let mut points: Vec<usize> = missing
            .iter()
            .flat_map(|&k| Shard { k, n }.points(total))
            .collect();
        points.sort_unstable();
        return Err(refuse(format!(
            "missing shard {} (points {}): recompute with `squeal map … --shard K/N`",
            ks.join(", "),
            if points.is_empty() {
                "none".into()
            } else {
                some(&points)
            }
        )));
    }
    let mut lin = vec![(f64::NAN, f64::NAN); total];
    let mut trans = (study["transient"] == true).then(|| vec![Outcome::FAILED; total]);
    for r in &shards {
        read_part(r, total, &mut lin, &mut trans)?;
    }
    let label = |a: &str| study["grid"][a]["label"].as_str().unwrap_or("").to_string();
    let labels = Labels {
        name: study["scenario"]["name"]
            .as_str()
            .unwrap_or("map")
            .to_string(),
        xl: label("x"),
        yl: label("y"),
    };
    let stage = Staging::new(&a.out)?;
    let disagree = write_map(&stage, &labels, &x, &y, &lin, trans.as_deref())?;
    let dest = stage.commit()?;
    let failed: Vec<usize> = trans
        .as_ref()
        .map(|t| {
            (0..total)
                .filter(|k| t[*k].class == "failed")
                .collect::<Vec<_>>()
        })
        .unwrap_or_default();
    if !a.json {
        crate::outln!(
            "merged {total} points from {n} shards; {} failed points{}",
            failed.len(),
            if failed.is_empty() {
                String::new()
            } else {
                format!(" (recorded as failed in map.csv): {}", some(&failed))
            }
        );
    }
    report(
        &labels,
        &x,
        &y,
        &lin,
        trans.as_ref().map(|_| disagree),
        &dest,
        a.json,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_point_is_in_exactly_one_shard() {
        for total in [0, 1, 5, 12, 13] {
            for n in 1..=8 {
                let mut seen = vec![0; total];
                for k in 0..n {
                    for i in (Shard { k, n }).points(total) {
                        assert_eq!(i % n, k);
                        seen[i] += 1;
                    }
                }
                assert!(seen.iter().all(|c| *c == 1), "{total} points, {n} shards");
            }
        }
    }

    #[test]
    fn shard_flag_is_checked() {
        assert_eq!(Shard::parse("2/7").unwrap(), Shard { k: 2, n: 7 });
        for bad in ["7/7", "1/0", "x/2", "3", "-1/2"] {
            let e = Shard::parse(bad).unwrap_err().0;
            assert!(e.starts_with(&format!("--shard {bad}:")), "{e}");
        }
    }

    #[test]
    fn exponent_text_round_trips_every_f64() {
        for v in [0.1, 1.0 / 3.0, 6.02e23, -2.5e-310, f64::MAX, f64::INFINITY] {
            let s = format!("{v:e}");
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
        assert!(format!("{:e}", f64::NAN).parse::<f64>().unwrap().is_nan());
    }
}
