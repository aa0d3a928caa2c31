//! Writing a run: `series.csv` (or `series.npy`), `events.csv`, `summary.json`.

use crate::RunError;
use serde_json::Value;
use squeal_core::EventKind;
use squeal_study::input::{read_regular, read_regular_text, MAX_RECORD_BYTES, MAX_TABLE_BYTES};
use squeal_study::run::Run;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Largest series file `read_run_dir` reads (4 GB).
pub const MAX_SERIES_FILE: u64 = 4_000_000_000;

fn io_err(path: &Path, e: std::io::Error) -> RunError {
    RunError::Io(format!("cannot write {}: {e}", path.display()))
}

/// Write the uniformly sampled columns as CSV, header first. Numbers are
/// written in the shortest form that reads back to the same f64 (so outputs
/// are byte-identical between runs); the mode flag as an integer.
pub fn write_series_csv(run: &Run, path: &Path) -> Result<(), RunError> {
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = BufWriter::with_capacity(1 << 20, f);
    let mode_col = run.columns.iter().position(|c| c == "mode");
    let res = (|| -> std::io::Result<()> {
        writeln!(w, "{}", run.columns.join(","))?;
        for r in 0..run.len() {
            for (c, col) in run.data.iter().enumerate() {
                if c > 0 {
                    w.write_all(b",")?;
                }
                if Some(c) == mode_col {
                    write!(w, "{}", col[r] as u8)?;
                } else {
                    write!(w, "{:e}", col[r])?;
                }
            }
            w.write_all(b"\n")?;
        }
        w.flush()
    })();
    res.map_err(|e| io_err(path, e))
}

/// Write the columns as a NumPy `.npy` file (float64, shape rows × columns,
/// C order; the column names are in summary.json's `columns`). The format is
/// simple enough that a dependency would not pay for itself.
pub fn write_series_npy(run: &Run, path: &Path) -> Result<(), RunError> {
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = BufWriter::with_capacity(1 << 20, f);
    let mut header = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {}), }}",
        run.len(),
        run.columns.len()
    );
    // Magic (6) + version (2) + header length (2) + header, padded to 64 bytes with '\n' last.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let res = (|| -> std::io::Result<()> {
        w.write_all(b"\x93NUMPY\x01\x00")?;
        w.write_all(&(header.len() as u16).to_le_bytes())?;
        w.write_all(header.as_bytes())?;
        for r in 0..run.len() {
            for col in &run.data {
                w.write_all(&col[r].to_le_bytes())?;
            }
        }
        w.flush()
    })();
    res.map_err(|e| io_err(path, e))
}

/// Write `events.csv` with columns `t,kind,contact` (the contact's name).
pub fn write_events_csv(run: &Run, path: &Path) -> Result<(), RunError> {
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = BufWriter::new(f);
    let res = (|| -> std::io::Result<()> {
        writeln!(w, "t,kind,contact")?;
        for (i, (t, k)) in run.events.iter().enumerate() {
            let c = run
                .event_contacts
                .get(i)
                .and_then(|c| run.contact_names.get(*c))
                .map_or("", String::as_str);
            writeln!(w, "{t:e},{},{c}", k.as_str())?;
        }
        w.flush()
    })();
    res.map_err(|e| io_err(path, e))
}

/// Write a JSON document, pretty-printed, with a final newline.
pub fn write_json(value: &Value, path: &Path) -> Result<(), RunError> {
    let mut text = serde_json::to_string_pretty(value).map_err(|e| RunError::Io(e.to_string()))?;
    text.push('\n');
    std::fs::write(path, text).map_err(|e| io_err(path, e))
}

/// A run folder's series must be something a run can have written: at
/// least one sample, every value finite, the time column `t` first and
/// strictly increasing. Anything else is refused naming the sample (row 1
/// is the first after the header) and the column.
fn check_series(dir: &Path, columns: &[String], data: &[Vec<f64>]) -> Result<(), RunError> {
    let bad = |msg: String| {
        RunError::Input(squeal_study::scenario::InputError(format!(
            "run folder {}: {msg}",
            dir.display()
        )))
    };
    let rows = data.first().map_or(0, Vec::len);
    if columns.first().map(String::as_str) != Some("t") {
        return Err(bad("the series' first column is not t".into()));
    }
    if rows == 0 {
        return Err(bad(
            "the series has no samples (only a header): nothing to draw or play; run simulate again".into(),
        ));
    }
    if let Some(c) = data.iter().position(|col| col.len() != rows) {
        return Err(bad(format!(
            "column {} has {} values, t has {rows}",
            columns[c],
            data[c].len()
        )));
    }
    for (c, col) in data.iter().enumerate() {
        if let Some(r) = col.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!(
                "sample {}, column {}: {} is not a finite number",
                r + 1,
                columns[c],
                col[r]
            )));
        }
    }
    if let Some(r) = data[0].windows(2).position(|w| w[1] <= w[0]) {
        return Err(bad(format!(
            "sample {}: time t = {:e} does not come after {:e} (t must increase)",
            r + 2,
            data[0][r + 1],
            data[0][r]
        )));
    }
    Ok(())
}

/// Read a run folder written by `squeal simulate` back: its columns (from
/// `series.csv`, or `series.npy` with the names from `summary.json`) and
/// its summary.
pub fn read_run_dir(dir: &Path) -> Result<(Run, Value), RunError> {
    let bad = |msg: String| RunError::Input(squeal_study::scenario::InputError(msg));
    if !dir.is_dir() {
        return Err(bad(format!("run folder {}: not a folder", dir.display())));
    }
    let summary_path = dir.join("summary.json");
    let summary: Value = read_regular_text(&summary_path, MAX_RECORD_BYTES)
        .map_err(bad)
        .and_then(|t| {
            serde_json::from_str(&t)
                .map_err(|e| bad(format!("{}: malformed JSON: {e}", summary_path.display())))
        })?;
    let csv = dir.join("series.csv");
    let npy = dir.join("series.npy");
    // Read whole: refuse what squeal could not have written (its series
    // stay below 1 GiB in memory, ~3 GB as text) before reading it.
    for p in [&csv, &npy] {
        if let Ok(m) = std::fs::metadata(p) {
            if m.len() > MAX_SERIES_FILE {
                return Err(bad(format!(
                    "{}: {:.2} GB is larger than any series squeal writes ({:.0} GB at most)",
                    p.display(),
                    m.len() as f64 / 1e9,
                    MAX_SERIES_FILE as f64 / 1e9
                )));
            }
        }
    }
    // Anything by these names is read, so that a device or a pipe is
    // refused by name rather than passed over.
    let (columns, data) = if std::fs::symlink_metadata(&csv).is_ok() {
        let text = read_regular_text(&csv, MAX_TABLE_BYTES).map_err(bad)?;
        let mut lines = text.lines();
        let header: Vec<String> = lines
            .next()
            .unwrap_or("")
            .split(',')
            .map(|s| s.trim().to_string())
            .collect();
        let mut data = vec![Vec::new(); header.len()];
        for (i, line) in lines.enumerate() {
            let mut n = 0;
            for (c, cell) in line.split(',').enumerate() {
                let v: f64 = cell.trim().parse().map_err(|_| {
                    bad(format!(
                        "{}: line {}: '{cell}' is not a number",
                        csv.display(),
                        i + 2
                    ))
                })?;
                if c < data.len() {
                    data[c].push(v);
                }
                n += 1;
            }
            if n != header.len() {
                return Err(bad(format!(
                    "{}: line {}: {n} cells, header has {}",
                    csv.display(),
                    i + 2,
                    header.len()
                )));
            }
        }
        (header, data)
    } else if std::fs::symlink_metadata(&npy).is_ok() {
        let bytes = read_regular(&npy, MAX_TABLE_BYTES).map_err(bad)?;
        let columns: Vec<String> = summary["columns"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|v| v.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default();
        if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" || columns.is_empty() {
            return Err(bad(format!("{}: not a squeal .npy file", npy.display())));
        }
        let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        let body = &bytes[(10 + hlen).min(bytes.len())..];
        let ncol = columns.len();
        let rows = body.len() / 8 / ncol;
        let mut data = vec![Vec::with_capacity(rows); ncol];
        for (k, chunk) in body.chunks_exact(8).enumerate() {
            data[k % ncol].push(f64::from_le_bytes(chunk.try_into().expect("8 bytes")));
        }
        (columns, data)
    } else {
        return Err(bad(format!(
            "run folder {}: no series.csv or series.npy",
            dir.display()
        )));
    };
    check_series(dir, &columns, &data)?;
    let sample_rate = summary["scenario"]["sample_rate"].as_f64().unwrap_or(0.0);
    if !(sample_rate.is_finite() && sample_rate > 0.0) {
        return Err(bad(format!(
            "{}: no scenario.sample_rate",
            summary_path.display()
        )));
    }
    let mut events = Vec::new();
    let mut event_contacts = Vec::new();
    let mut contact_names: Vec<String> = Vec::new();
    let events_path = dir.join("events.csv");
    let events_text = if std::fs::symlink_metadata(&events_path).is_ok() {
        Some(read_regular_text(&events_path, MAX_TABLE_BYTES).map_err(bad)?)
    } else {
        None
    };
    if let Some(text) = events_text {
        for line in text.lines().skip(1) {
            let mut cols = line.split(',');
            let (Some(t), Some(k)) = (cols.next(), cols.next()) else {
                continue;
            };
            let kind = EventKind::ALL.into_iter().find(|e| e.as_str() == k.trim());
            if let (Ok(t), Some(kind)) = (t.parse::<f64>(), kind) {
                events.push((t, kind));
                let c = cols.next().unwrap_or("").trim().to_string();
                let i = contact_names
                    .iter()
                    .position(|n| *n == c)
                    .unwrap_or_else(|| {
                        contact_names.push(c);
                        contact_names.len() - 1
                    });
                event_contacts.push(i);
            }
        }
    }
    let t_final = data.first().and_then(|t| t.last().copied()).unwrap_or(0.0);
    let run = Run {
        columns,
        data,
        events,
        event_contacts,
        contact_names,
        info: squeal_core::RunInfo {
            stats: Default::default(),
            t_final,
            stopped_early: false,
        },
        integrate_s: 0.0,
        sample_rate,
    };
    Ok((run, summary))
}
