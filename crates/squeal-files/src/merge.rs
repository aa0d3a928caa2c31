//! `merge`: the shards of one study (all of them, checked to belong
//! together and to be whole, see [`crate::shard`]) gathered into the files
//! of the unsharded study, byte for byte.

use crate::map::{write_map, Labels};
use crate::reproduce::{finish, reproduce_study};
use crate::shard::{fnv1a, write_file, Shard, FORMAT, PART_FILE, SETS_FILE, SHARD_FILE};
use crate::sweep::write_sweep;
use crate::{RunError, Staging};
use serde_json::Value;
use squeal_core::stability::sweep::Sweep;
use squeal_study::input::{read_regular, read_regular_text, MAX_RECORD_BYTES, MAX_TABLE_BYTES};
use squeal_study::map::{Axis, Outcome, CLASSES};
use squeal_study::reproduce::{Conclusion, SetResult};
use squeal_study::scenario::InputError;
use squeal_study::Cancel;
use std::path::{Path, PathBuf};

/// What a merge gathered: the unsharded study's result, whose files it
/// wrote into its output folder.
pub enum Merged {
    /// A map.
    Map {
        /// Title and axis labels.
        labels: Labels,
        /// First parameter.
        x: Axis,
        /// Second parameter.
        y: Axis,
        /// (σ in 1/s, frequency in Hz) at every point, flat order.
        lin: Vec<(f64, f64)>,
        /// The simulated outcomes (a `--transient` map).
        trans: Option<Vec<Outcome>>,
        /// Points whose linear verdict and simulated outcome disagree.
        disagree: Option<usize>,
        /// Points whose simulation failed.
        failed: Vec<usize>,
    },
    /// A sweep.
    Sweep {
        /// The scenario's name.
        name: String,
        /// The swept parameter.
        param: Axis,
        /// Its axis label, `NAME (UNIT)` or the name alone.
        label: String,
        /// The sweep, modes tracked across the shards' boundaries.
        sweep: Sweep,
    },
    /// The thesis reproduced.
    Reproduce {
        /// Every set's result, set 1 first.
        results: Vec<SetResult>,
        /// The graded conclusions.
        conclusions: Vec<Conclusion>,
        /// How many pictures the shards brought.
        figures: usize,
    },
}

/// A merge: what was gathered, from how many shards, into which folder.
pub struct Merge {
    /// The gathered study.
    pub merged: Merged,
    /// How many shards.
    pub shards: usize,
    /// The output folder, committed.
    pub dest: PathBuf,
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
pub fn some(indices: &[usize]) -> String {
    let head: Vec<String> = indices.iter().take(12).map(|i| i.to_string()).collect();
    if indices.len() > 12 {
        format!("{} … ({} in all)", head.join(", "), indices.len())
    } else {
        head.join(", ")
    }
}

/// Gather the shard folders `dirs` (every shard of one study, in any order)
/// into `out`, refusing (bad input, one line with the reason) shards of
/// different studies, a missing shard (naming its points, values or sets),
/// a shard given twice and a changed or truncated file.
pub fn merge(dirs: &[PathBuf], out: &Path, cancel: &Cancel) -> Result<Merge, RunError> {
    if dirs.is_empty() {
        return Err(refuse("merge: no shard folders given".into()));
    }
    let shards = dirs
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
        (Some(p), None) => return merge_sweep(&shards, n, p, out),
        _ => return merge_reproduce(&shards, n, out, cancel),
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
    let stage = Staging::new(out)?;
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
    Ok(Merge {
        merged: Merged::Map {
            labels,
            disagree: trans.as_ref().map(|_| disagree),
            x,
            y,
            lin,
            trans,
            failed,
        },
        shards: n,
        dest,
    })
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
fn merge_sweep(shards: &[Read], n: usize, p: Axis, out: &Path) -> Result<Merge, RunError> {
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
    write_sweep(&stage, name, &p, label, &sw)?;
    let dest = stage.commit()?;
    Ok(Merge {
        merged: Merged::Sweep {
            name: name.to_string(),
            label: label.to_string(),
            param: p,
            sweep: sw,
        },
        shards: n,
        dest,
    })
}

/// Merge `reproduce` shards (already checked to be one whole study) into
/// the report of the unsharded `reproduce`.
fn merge_reproduce(
    shards: &[Read],
    n: usize,
    out: &Path,
    cancel: &Cancel,
) -> Result<Merge, RunError> {
    use squeal_study::reproduce::{exact, prepared_sets};
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
    let cs = finish(&stage, &rs, scale, figures, cancel)?;
    let dest = stage.commit()?;
    Ok(Merge {
        merged: Merged::Reproduce {
            figures: pictures.len(),
            results: rs,
            conclusions: cs,
        },
        shards: n,
        dest,
    })
}
