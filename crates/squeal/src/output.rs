//! Writing a run: `series.csv` (or `series.npy`), `events.csv`, `summary.json`.

use crate::run::{Run, RunError};
use serde_json::{json, Map, Value};
use squeal_core::EventKind;
use std::io::{BufWriter, Write};
use std::path::Path;

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

/// Write `events.csv` with columns `t,kind`.
pub fn write_events_csv(run: &Run, path: &Path) -> Result<(), RunError> {
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = BufWriter::new(f);
    let res = (|| -> std::io::Result<()> {
        writeln!(w, "t,kind")?;
        for (t, k) in &run.events {
            writeln!(w, "{t:e},{}", k.as_str())?;
        }
        w.flush()
    })();
    res.map_err(|e| io_err(path, e))
}

/// RMS of each velocity column over the last 20 % of the run.
pub fn tail_rms(run: &Run, velocity_columns: &[String]) -> Map<String, Value> {
    let n = run.len();
    let start = n - n / 5;
    let mut out = Map::new();
    for name in velocity_columns {
        if let Some(col) = run.column(name) {
            let tail = &col[start.min(n)..];
            let rms = if tail.is_empty() {
                0.0
            } else {
                (tail.iter().map(|x| x * x).sum::<f64>() / tail.len() as f64).sqrt()
            };
            out.insert(name.clone(), json!(rms));
        }
    }
    out
}

/// The parts of summary.json that describe the integration.
pub fn integrator_json(run: &Run) -> Value {
    let s = &run.info.stats;
    let mut events = Map::new();
    for k in EventKind::ALL {
        events.insert(k.as_str().into(), json!(s.event_count(k)));
    }
    json!({
        "integrator": {
            "method": "DOP853 with dense-output event location",
            "accepted_steps": s.accepted,
            "rejected_steps": s.rejected,
            "rhs_evaluations": s.rhs_evals,
            "rhs_per_step": if s.accepted > 0 { s.rhs_evals as f64 / s.accepted as f64 } else { 0.0 },
        },
        "events": events,
        "stick_fraction": s.stick_fraction(),
        "t_final": run.info.t_final,
    })
}

/// Write a JSON document, pretty-printed, with a final newline.
pub fn write_json(value: &Value, path: &Path) -> Result<(), RunError> {
    let mut text = serde_json::to_string_pretty(value).map_err(|e| RunError::Io(e.to_string()))?;
    text.push('\n');
    std::fs::write(path, text).map_err(|e| io_err(path, e))
}
