//! Shards of a map or of `reproduce`, and `squeal merge DIR… --out DIR`.
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
//!
//! `squeal reproduce … --shard K/N` measures the thesis sets whose index
//! `i` (set `i + 1`) has `i mod N = K` and writes `shard.json`, `part.json`
//! (each set's results, every number as exact text, see
//! [`squeal_study::reproduce::exact`]) and, unless `--no-figures`, the sets'
//! Appendix A pictures under `figures/` (each listed in the manifest with
//! its length and hash). `merge` recognises such shards by their manifest's
//! `study.command`, refuses them for the same reasons as map shards (a
//! missing shard names its sets), rebuilds the 40 scenarios with
//! [`squeal_study::reproduce::prepared_sets`] (and refuses shards made from
//! other sets), copies the pictures and ends through
//! [`crate::commands::reproduce::finish`] — the same sweeps, conclusions,
//! map and report as the unsharded `reproduce`, byte for byte.

use crate::commands::map::{report, write_map, write_rows, Labels};
use crate::run::{RunError, Staging};
use clap::Args;
use serde_json::{json, Value};
use squeal_study::input::{read_regular, read_regular_text, MAX_RECORD_BYTES, MAX_TABLE_BYTES};
use squeal_study::map::{Axis, Outcome, CLASSES};
use squeal_study::scenario::InputError;
use squeal_study::Scenario;
use std::path::{Path, PathBuf};

/// The manifest of a shard.
pub const SHARD_FILE: &str = "shard.json";
/// A shard's rows.
pub const PART_FILE: &str = "part.csv";
/// A `reproduce` shard's sets.
pub const SETS_FILE: &str = "part.json";
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
    /// The default output folder's name of a study called `base`: `base`, or
    /// `base-shard-K-of-N` for a shard.
    pub fn folder(base: &str, shard: Option<Shard>) -> String {
        match shard {
            Some(s) => format!("{base}-shard-{}-of-{}", s.k, s.n),
            None => base.to_string(),
        }
    }

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

/// The study a `reproduce` shard belongs to: the squeal version, the
/// duration scale, whether it draws figures, and a hash of the 40 prepared
/// scenarios (their resolved content).
pub fn reproduce_study(sets: &[Scenario], duration_scale: f64, figures: bool) -> Value {
    let content: Vec<Value> = sets.iter().map(Scenario::to_json).collect();
    let text = serde_json::to_string(&content).unwrap_or_default();
    json!({
        "command": "reproduce",
        "squeal_version": env!("CARGO_PKG_VERSION"),
        "duration_scale": format!("{duration_scale:e}"),
        "figures": figures,
        "sets": { "count": sets.len(), "hash": fnv1a(text.as_bytes()) },
    })
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), RunError> {
    std::fs::write(path, bytes)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
}

/// Every file under `dir/figures`, as paths relative to `dir` with `/`,
/// sorted.
fn figure_files(dir: &Path) -> Result<Vec<String>, RunError> {
    let mut out = Vec::new();
    let mut todo = vec![dir.join("figures")];
    while let Some(d) = todo.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries {
            let e = e.map_err(|e| RunError::Io(format!("cannot read {}: {e}", d.display())))?;
            let p = e.path();
            if p.is_dir() {
                todo.push(p);
            } else if let Ok(rel) = p.strip_prefix(dir) {
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push(parts.join("/"));
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Write a `reproduce` shard (`part.json`, then `shard.json` listing
/// `part.json` and every picture under `figures/` with its length and
/// hash) into `stage`, whose `figures/` the sets have drawn into.
pub fn write_reproduce_part(
    stage: &Staging,
    study: &Value,
    s: Shard,
    rs: &[squeal_study::reproduce::SetResult],
) -> Result<(), RunError> {
    let sets: Vec<Value> = rs
        .iter()
        .map(squeal_study::reproduce::exact::to_json)
        .collect();
    let bytes =
        serde_json::to_string_pretty(&sets).map_err(|e| RunError::Io(e.to_string()))? + "\n";
    write_file(&stage.path(SETS_FILE), bytes.as_bytes())?;
    let mut figures = Vec::new();
    for f in figure_files(stage.dir())? {
        let p = stage.dir().join(&f);
        let b = read_regular(&p, MAX_TABLE_BYTES).map_err(RunError::Io)?;
        figures.push(json!({ "file": f, "bytes": b.len(), "fnv1a": fnv1a(&b) }));
    }
    let doc = json!({
        "format": FORMAT,
        "study": study,
        "k": s.k,
        "n": s.n,
        "slicing": "interleaved: set index i (set i + 1) belongs to shard i mod n",
        "points": rs.len(),
        "part": { "file": SETS_FILE, "rows": rs.len(), "bytes": bytes.len(), "fnv1a": fnv1a(bytes.as_bytes()) },
        "figures": figures,
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?;
    write_file(&stage.path(SHARD_FILE), (text + "\n").as_bytes())
}

/// The study a `sweep` shard belongs to: the squeal version, the resolved
/// scenario and its hash, the swept parameter with every value and its label.
pub fn sweep_study(sc: &Scenario, p: &Axis, label: &str) -> Value {
    let content = sc.to_json();
    let text = serde_json::to_string(&content).unwrap_or_default();
    json!({
        "command": "sweep",
        "squeal_version": env!("CARGO_PKG_VERSION"),
        "scenario": { "name": sc.name, "hash": fnv1a(text.as_bytes()), "content": content },
        "param": axis_json(p, label),
    })
}

/// Write a `sweep` shard (`part.json`, then `shard.json`) into `stage`.
pub fn write_sweep_part(
    stage: &Staging,
    study: &Value,
    s: Shard,
    part: &squeal_study::sweep::shard::Part,
) -> Result<(), RunError> {
    let bytes = serde_json::to_string(&squeal_study::sweep::shard::to_json(part))
        .map_err(|e| RunError::Io(e.to_string()))?
        + "\n";
    write_file(&stage.path(SETS_FILE), bytes.as_bytes())?;
    let doc = json!({
        "format": FORMAT,
        "study": study,
        "k": s.k,
        "n": s.n,
        "slicing": "contiguous: shard k owns values [k·m/n, (k+1)·m/n) of m and computes from two values before",
        "points": part.lambda.len(),
        "part": { "file": SETS_FILE, "rows": part.lambda.len(), "bytes": bytes.len(), "fnv1a": fnv1a(bytes.as_bytes()) },
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?;
    write_file(&stage.path(SHARD_FILE), (text + "\n").as_bytes())
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
    /// The shard folders (`squeal map|reproduce … --shard K/N --out DIR`), all N of them.
    #[arg(required = true, value_name = "DIR")]
    shards: Vec<PathBuf>,
    /// Output folder for the merged map or report.
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
    let text = read_regular_text(&path, MAX_RECORD_BYTES).map_err(|e| {
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
    if a["command"] != b["command"] {
        return Some(format!(
            "different commands ({} and {})",
            a["command"], b["command"]
        ));
    }
    if a["transient"] != b["transient"] {
        return Some("different kinds of map (linear and --transient)".into());
    }
    if a["duration_scale"] != b["duration_scale"] {
        return Some(format!(
            "different --duration-scale ({} and {})",
            a["duration_scale"], b["duration_scale"]
        ));
    }
    if a["figures"] != b["figures"] {
        return Some("one draws figures, the other has --no-figures".into());
    }
    if a["sets"] != b["sets"] {
        return Some("different thesis sets".into());
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
    if a["param"] != b["param"] {
        return Some("different --param (name or values)".into());
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
    let bytes = read_regular(&path, MAX_TABLE_BYTES)
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
                // Shards written before the column existed have none.
                spl_dba: num(10).unwrap_or(f64::NAN),
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
    let command = study["command"].as_str().unwrap_or("map").to_string();
    let bad_grid = |e: String| refuse(format!("{}: {SHARD_FILE}: {e}", first.dir.display()));
    let (total, x, y) = match command.as_str() {
        "reproduce" => {
            let count = study["sets"]["count"].as_u64().unwrap_or(0) as usize;
            (count, None, None)
        }
        "sweep" => {
            let p = axis_of(&study["param"]).map_err(bad_grid)?;
            (p.values.len(), Some(p), None)
        }
        _ => {
            let x = axis_of(&study["grid"]["x"]).map_err(bad_grid)?;
            let y = axis_of(&study["grid"]["y"]).map_err(bad_grid)?;
            (x.values.len() * y.values.len(), Some(x), Some(y))
        }
    };
    let missing: Vec<usize> = (0..n).filter(|k| by_k[*k].is_none()).collect();
    if !missing.is_empty() {
        let ks: Vec<String> = missing.iter().map(|k| format!("{k}/{n}")).collect();
        let mut points: Vec<usize> = missing
            .iter()
            .flat_map(|&k| {
                if command == "sweep" {
                    squeal_study::sweep::shard::slice(total, k, n).0.collect()
                } else {
                    Shard { k, n }.points(total)
                }
            })
            .collect();
        points.sort_unstable();
        // Sets are numbered from 1; points and values (their index) from 0.
        let (what, first_no) = match command.as_str() {
            "reproduce" => ("sets", 1),
            "sweep" => ("values", 0),
            _ => ("points", 0),
        };
        let named: Vec<usize> = points.iter().map(|p| p + first_no).collect();
        return Err(refuse(format!(
            "missing shard {} ({what} {}): recompute with `squeal {command} … --shard K/N`",
            ks.join(", "),
            if named.is_empty() {
                "none".into()
            } else {
                some(&named)
            }
        )));
    }
    let (x, y) = match (x, y) {
        (Some(x), Some(y)) => (x, y),
        (Some(p), None) => return merge_sweep(&shards, n, &p, &a.out, a.json),
        _ => return merge_reproduce(&shards, n, &a.out, a.json),
    };
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

/// A file of a shard, read and checked against the length and hash its
/// manifest gives.
fn checked_file(r: &Read, file: &str, entry: &Value) -> Result<Vec<u8>, RunError> {
    let d = r.dir.display();
    let safe = !file.is_empty()
        && !file.starts_with('/')
        && file
            .split('/')
            .all(|c| !c.is_empty() && c != "." && c != "..");
    if !safe {
        return Err(refuse(format!(
            "{d}: {SHARD_FILE} names a file outside the shard: {file:?}"
        )));
    }
    let bytes = read_regular(&r.dir.join(file), MAX_TABLE_BYTES)
        .map_err(|e| refuse(format!("{d}: not a complete shard ({file}: {e})")))?;
    if entry["bytes"].as_u64() != Some(bytes.len() as u64)
        || entry["fnv1a"].as_str() != Some(fnv1a(&bytes).as_str())
    {
        return Err(refuse(format!(
            "{d}: {file} is truncated or changed ({} bytes, the manifest says {}); recompute this shard",
            bytes.len(),
            entry["bytes"]
        )));
    }
    Ok(bytes)
}

/// Merge `sweep` shards (already checked to be one whole study) into the
/// files of the unsharded `sweep`.
fn merge_sweep(
    shards: &[Read],
    n: usize,
    p: &Axis,
    out: &Path,
    json: bool,
) -> Result<(), RunError> {
    use squeal_study::sweep::shard;
    let mut by_k: Vec<&Read> = shards.iter().collect();
    by_k.sort_by_key(|r| r.k);
    let mut parts = Vec::with_capacity(n);
    for r in &by_k {
        let d = r.dir.display();
        let bytes = checked_file(r, SETS_FILE, &r.doc["part"])?;
        let doc: Value = serde_json::from_slice(&bytes)
            .map_err(|e| refuse(format!("{d}: {SETS_FILE} is damaged ({e})")))?;
        let part = shard::from_json(&doc).map_err(|e| refuse(format!("{d}: {SETS_FILE}: {e}")))?;
        parts.push(part);
    }
    let sw = shard::merge(&p.values, &parts).map_err(refuse)?;
    let study = &shards[0].doc["study"];
    let name = study["scenario"]["name"].as_str().unwrap_or("sweep");
    let label = study["param"]["label"].as_str().unwrap_or(&p.name);
    let stage = Staging::new(out)?;
    crate::commands::sweep::write_sweep(&stage, name, p, label, &sw)?;
    let dest = stage.commit()?;
    if !json {
        crate::outln!("merged {} values from {n} shards", p.values.len());
    }
    crate::commands::sweep::report(name, &p.name, &sw, &dest, json)
}

/// Merge `reproduce` shards (already checked to be one whole study) into
/// the report of the unsharded `reproduce`.
fn merge_reproduce(shards: &[Read], n: usize, out: &Path, json: bool) -> Result<(), RunError> {
    use squeal_study::reproduce::{exact, prepared_sets, SetResult};
    let first = &shards[0];
    let study = &first.doc["study"];
    let scale = study["duration_scale"]
        .as_str()
        .and_then(|s| s.parse::<f64>().ok())
        .ok_or_else(|| {
            refuse(format!(
                "{}: {SHARD_FILE} lacks its duration scale",
                first.dir.display()
            ))
        })?;
    let figures = study["figures"].as_bool().unwrap_or(false);
    let sets = prepared_sets(scale)
        .map_err(|e| refuse(format!("{}: {SHARD_FILE}: {e}", first.dir.display())))?;
    if reproduce_study(&sets, scale, figures) != *study {
        return Err(refuse(format!(
            "{}: made from other thesis sets than this squeal's (scenarios changed); recompute the shards",
            first.dir.display()
        )));
    }
    let mut rs: Vec<Option<SetResult>> = vec![None; sets.len()];
    let mut pictures: Vec<(String, Vec<u8>)> = Vec::new();
    for r in shards {
        let d = r.dir.display();
        let want = Shard { k: r.k, n: r.n }.points(sets.len());
        let part = &r.doc["part"];
        if part["rows"].as_u64() != Some(want.len() as u64)
            || r.doc["points"].as_u64() != Some(want.len() as u64)
        {
            return Err(refuse(format!(
                "{d}: shard {}/{} of {} sets should hold {} sets, its manifest says {}",
                r.k,
                r.n,
                sets.len(),
                want.len(),
                part["rows"]
            )));
        }
        let bytes = checked_file(r, SETS_FILE, part)?;
        let doc: Value = serde_json::from_slice(&bytes)
            .map_err(|e| refuse(format!("{d}: {SETS_FILE} is damaged ({e})")))?;
        let list = doc
            .as_array()
            .filter(|l| l.len() == want.len())
            .ok_or_else(|| {
                refuse(format!(
                    "{d}: {SETS_FILE} does not hold its {} sets",
                    want.len()
                ))
            })?;
        for (v, &i) in list.iter().zip(&want) {
            if v["id"].as_u64() != Some(i as u64 + 1) {
                return Err(refuse(format!("{d}: {SETS_FILE}: expected set {}", i + 1)));
            }
            let res = exact::from_json(v, sets[i].clone())
                .map_err(|e| refuse(format!("{d}: {SETS_FILE}: set {}: {e}", i + 1)))?;
            rs[i] = Some(res);
        }
        let listed = r.doc["figures"].as_array().cloned().unwrap_or_default();
        if figures {
            for &i in &want {
                let dir = format!("figures/set{:02}/", i + 1);
                if !listed
                    .iter()
                    .any(|f| f["file"].as_str().is_some_and(|f| f.starts_with(&dir)))
                {
                    return Err(refuse(format!(
                        "{d}: {SHARD_FILE} lists no pictures of set {}; recompute this shard",
                        i + 1
                    )));
                }
            }
        }
        for f in &listed {
            let file = f["file"].as_str().unwrap_or("");
            let b = checked_file(r, file, f)?;
            pictures.push((file.to_string(), b));
        }
    }
    let rs: Vec<SetResult> = rs.into_iter().flatten().collect();
    if rs.len() != sets.len() {
        return Err(refuse(format!(
            "the shards hold {} of the {} sets",
            rs.len(),
            sets.len()
        )));
    }
    let stage = Staging::new(out)?;
    for (file, bytes) in &pictures {
        let p = stage.dir().join(file);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| RunError::Io(format!("cannot create {}: {e}", parent.display())))?;
        }
        write_file(&p, bytes)?;
    }
    let cs = crate::commands::reproduce::finish(&stage, &rs, scale, figures)?;
    let dest = stage.commit()?;
    if json {
        let doc = json!({
            "sets": rs.len(), "shards": n, "figures": pictures.len(),
            "conclusions": cs.iter().map(|c| json!({"id": c.id, "grade": c.grade.as_str()})).collect::<Vec<_>>(),
            "out": dest,
        });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
        return Ok(());
    }
    crate::commands::reproduce::print_summary(
        &format!("merged {} sets from {n} shards", rs.len()),
        &cs,
        &dest,
    );
    Ok(())
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
