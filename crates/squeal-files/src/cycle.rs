//! The files of a limit cycle (`cycle --out`): `orbit.csv` (one period,
//! each event as two rows), `summary.json` and the pictures (`cycle.png`,
//! `cycle_phase.png`, with their SVGs).

use crate::{RunError, Staging};
use serde_json::Value;
use squeal_plot::{Format, Labels, Panel, Series};
use squeal_study::cycle::Found;
use squeal_study::scenario::Scenario;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Write the cycle `found` of `sc`, with its JSON document `doc`, into `stage`.
pub fn write(stage: &Staging, found: &Found, sc: &Scenario, doc: &Value) -> Result<(), RunError> {
    write_orbit(found, &stage.path("orbit.csv"))?;
    draw(found, sc, stage.dir())?;
    crate::output::write_json(doc, &stage.path("summary.json"))
}

fn io_err(path: &Path, e: std::io::Error) -> RunError {
    RunError::Io(format!("cannot write {}: {e}", path.display()))
}

/// Write `orbit.csv`: the period's samples, each event as two rows (before
/// and after), the event's kind in the last column.
fn write_orbit(found: &Found, path: &Path) -> Result<(), RunError> {
    let Some((columns, rows, events)) = &found.orbit else {
        return Ok(());
    };
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = BufWriter::new(f);
    let mode_cols: Vec<bool> = columns
        .iter()
        .map(|c| c == "mode" || c.ends_with(".mode"))
        .collect();
    let res = (|| -> std::io::Result<()> {
        writeln!(w, "{},event", columns.join(","))?;
        for (row, ev) in rows.iter().zip(events) {
            for (c, v) in row.iter().enumerate() {
                if c > 0 {
                    w.write_all(b",")?;
                }
                if mode_cols[c] {
                    write!(w, "{}", *v as u8)?;
                } else {
                    write!(w, "{v:e}")?;
                }
            }
            writeln!(w, ",{ev}")?;
        }
        w.flush()
    })();
    res.map_err(|e| io_err(path, e))
}

/// Phase portrait and time series over one period.
fn draw(found: &Found, sc: &Scenario, dir: &Path) -> Result<(), RunError> {
    let Some((columns, rows, _)) = &found.orbit else {
        return Ok(());
    };
    let plot_err = |e: squeal_plot::PlotError| RunError::Io(format!("plot: {e}"));
    let col = |name: &str| -> Option<Vec<f64>> {
        let i = columns.iter().position(|c| c == name)?;
        Some(rows.iter().map(|r| r[i]).collect())
    };
    let formats = [Format::Png, Format::Svg];
    let ch = sc.model.channels();
    let t: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    if let (Some(x), Some(v)) = (col(&ch.phase.0), col(&ch.phase.1)) {
        let title = format!(
            "{}: limit cycle, T = {:.6e} s, phase portrait {} – {}",
            sc.name, found.period, ch.phase.0, ch.phase.1
        );
        let (xl, yl) = (
            format!("{} (m)", ch.phase.0),
            format!("{} (m/s)", ch.phase.1),
        );
        squeal_plot::phase_portrait(
            dir.join("cycle_phase"),
            &formats,
            squeal_plot::SIZE_SINGLE,
            &x,
            &v,
            &Labels {
                title: &title,
                x_label: &xl,
                y_label: &yl,
            },
        )
        .map_err(plot_err)?;
    }
    let n = found.names.len();
    let vel: Vec<(String, Vec<f64>)> = found.names[n / 2..]
        .iter()
        .filter_map(|name| col(name).map(|c| (name.clone(), c)))
        .collect();
    let pos: Vec<(String, Vec<f64>)> = found.names[..n / 2]
        .iter()
        .filter_map(|name| {
            col(name).map(|c| {
                // Deviation from the mean: static offsets would hide the motion.
                let mean = c.iter().sum::<f64>() / c.len().max(1) as f64;
                (name.clone(), c.iter().map(|x| x - mean).collect())
            })
        })
        .collect();
    let title_v = format!("{}: velocities over one period", sc.name);
    let title_x = format!("{}: displacements about their mean", sc.name);
    let mut pv = Panel::new(&title_v, "time in the period (s)", "velocity (m/s)");
    for (name, c) in &vel {
        pv = pv.with_series(Series::new(name, &t, c));
    }
    let mut px = Panel::new(&title_x, "time in the period (s)", "displacement (m)");
    for (name, c) in &pos {
        px = px.with_series(Series::new(name, &t, c));
    }
    squeal_plot::line_panels(dir.join("cycle"), &formats, (1200, 700), &[pv, px])
        .map_err(plot_err)?;
    Ok(())
}
