//! The files of a harmonic-balance orbit (`hb --out`): `hb_orbit.csv`,
//! `summary.json` and the picture (`hb.png`/`.svg`).

use crate::{RunError, Staging};
use serde_json::Value;
use squeal_plot::{Format, Panel, Series};
use squeal_study::hb::HbFound;
use squeal_study::scenario::Scenario;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Write the orbit `found` of `sc`, with its JSON document `doc`, into `stage`.
pub fn write(stage: &Staging, found: &HbFound, sc: &Scenario, doc: &Value) -> Result<(), RunError> {
    write_orbit(found, &stage.path("hb_orbit.csv"))?;
    draw(found, sc, stage.dir())?;
    crate::output::write_json(doc, &stage.path("summary.json"))
}

fn io_err(path: &Path, e: std::io::Error) -> RunError {
    RunError::Io(format!("cannot write {}: {e}", path.display()))
}

/// `hb_orbit.csv`: one period of the series, `t` and the states.
fn write_orbit(f: &HbFound, path: &Path) -> Result<(), RunError> {
    let Some((series, _)) = &f.orbit else {
        return Ok(());
    };
    let file = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = BufWriter::new(file);
    let res = (|| -> std::io::Result<()> {
        writeln!(w, "t,{}", f.names.join(","))?;
        for row in series {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
            writeln!(w, "{}", cells.join(","))?;
        }
        w.flush()
    })();
    res.map_err(|e| io_err(path, e))
}

/// `hb.png`: the velocity of the dof that moves most, the series against
/// the exact flow over one period from its state; the harmonics' amplitudes.
fn draw(f: &HbFound, sc: &Scenario, dir: &Path) -> Result<(), RunError> {
    let Some((series, exact)) = &f.orbit else {
        return Ok(());
    };
    let n = f.spectrum.len();
    let top = f.amplitude[..n].iter().cloned().fold(0.0, f64::max);
    let moving: Vec<usize> = (0..n).filter(|&i| f.amplitude[i] > 1e-6 * top).collect();
    // The dof that moves most, and the one richest in higher harmonics.
    let most = moving
        .iter()
        .copied()
        .max_by(|&a, &b| f.amplitude[a].total_cmp(&f.amplitude[b]))
        .unwrap_or(0);
    let richness = |i: usize| {
        let s = &f.spectrum[i];
        s[2..].iter().map(|a| a * a).sum::<f64>() / s[1].powi(2).max(f64::MIN_POSITIVE)
    };
    let richest = moving
        .iter()
        .copied()
        .max_by(|&a, &b| richness(a).total_cmp(&richness(b)))
        .unwrap_or(most);
    let col = |rows: &[Vec<f64>], c: usize| -> Vec<f64> { rows.iter().map(|r| r[c]).collect() };
    let shown: Vec<usize> = if richest == most {
        vec![most]
    } else {
        vec![most, richest]
    };
    let data: Vec<(String, String, [Vec<f64>; 4])> = shown
        .iter()
        .map(|&i| {
            let v = n + i;
            (
                format!(
                    "{}: {} over one period, {:.6} Hz (harmonic balance, H = {})",
                    sc.name,
                    f.names[v],
                    1.0 / f.period,
                    f.harmonics
                ),
                format!("{} (m/s)", f.names[v]),
                [
                    col(series, 0),
                    col(series, v + 1),
                    col(exact, 0),
                    col(exact, v + 1),
                ],
            )
        })
        .collect();
    let mut panels: Vec<Panel> = data
        .iter()
        .map(|(title, y, [ts, vs, te, ve])| {
            Panel::new(title, "time in the period (s)", y)
                .with_series(Series::new("harmonic balance", ts, vs))
                .with_series(Series::new("exact flow from its state", te, ve).dashed(true))
        })
        .collect();
    // The four dofs that move most.
    let mut dofs = moving.clone();
    dofs.sort_by(|&a, &b| f.amplitude[b].total_cmp(&f.amplitude[a]));
    dofs.truncate(4);
    let ks: Vec<f64> = (1..=f.harmonics).map(|k| k as f64).collect();
    let logs: Vec<(String, Vec<f64>)> = dofs
        .iter()
        .map(|&i| {
            let a: Vec<f64> = f.spectrum[i][1..]
                .iter()
                .map(|&v| if v > 0.0 { v.log10() } else { f64::NAN })
                .collect();
            (f.names[i].clone(), a)
        })
        .collect();
    let title2 = format!("{}: amplitude of each harmonic", sc.name);
    let mut p2 = Panel::new(&title2, "harmonic k", "log10 amplitude (m)");
    for (name, a) in &logs {
        p2 = p2.with_series(Series::new(name, &ks, a).with_gaps());
    }
    panels.push(p2);
    let height = 350 * panels.len() as u32;
    squeal_plot::line_panels(
        dir.join("hb"),
        &[Format::Png, Format::Svg],
        (1200, height),
        &panels,
    )
    .map_err(|e| RunError::Io(format!("plot: {e}")))?;
    Ok(())
}

/// Write the HB branch `br` of `sc` (`hb --param --out`), with its JSON
/// document `doc`: `branch.csv` (one row per point: the parameter,
/// `period`, `freq_hz`, `amplitude_<state>`…, `max_multiplier`, `stable`,
/// `point`), `summary.json` and `hb_branch.png`/`.svg` (the amplitude of
/// the dof that moves most against the parameter, stable solid and
/// unstable dashed, folds marked).
pub fn write_branch(
    stage: &Staging,
    br: &squeal_study::hb_branch::HbBranchFound,
    sc: &Scenario,
    doc: &Value,
) -> Result<(), RunError> {
    let path = stage.path("branch.csv");
    let file = std::fs::File::create(&path).map_err(|e| io_err(&path, e))?;
    let mut w = BufWriter::new(file);
    let res = (|| -> std::io::Result<()> {
        let mut header = vec![br.name.clone(), "period".into(), "freq_hz".into()];
        header.extend(br.names.iter().map(|s| format!("amplitude_{s}")));
        header.extend(["max_multiplier", "stable", "point"].map(String::from));
        writeln!(w, "{}", header.join(","))?;
        for r in &br.rows {
            let mut row = vec![
                format!("{:e}", r.value),
                format!("{:e}", r.period),
                format!("{:e}", 1.0 / r.period),
            ];
            row.extend(r.amplitude.iter().map(|a| format!("{a:e}")));
            row.push(if r.max_multiplier.is_finite() {
                format!("{:e}", r.max_multiplier)
            } else {
                String::new()
            });
            row.push(r.stable.to_string());
            row.push(r.kind.to_string());
            writeln!(w, "{}", row.join(","))?;
        }
        w.flush()
    })();
    res.map_err(|e| io_err(&path, e))?;
    draw_branch(br, sc, stage.dir())?;
    crate::output::write_json(doc, &stage.path("summary.json"))
}

fn draw_branch(
    br: &squeal_study::hb_branch::HbBranchFound,
    sc: &Scenario,
    dir: &Path,
) -> Result<(), RunError> {
    if br.rows.is_empty() {
        return Ok(());
    }
    let n = br.names.len() / 2;
    // The dof that moves most anywhere on the branch.
    let k = (0..n)
        .max_by(|&a, &b| {
            let top = |i: usize| br.rows.iter().map(|r| r.amplitude[i]).fold(0.0, f64::max);
            top(a).total_cmp(&top(b))
        })
        .unwrap_or(0);
    // Two series over the same points: each keeps the pieces of its own
    // stability (a piece starts at the last point of the other's, so the
    // line is unbroken), a NaN breaks it elsewhere.
    let mut xs = [Vec::new(), Vec::new()];
    let mut ys = [Vec::new(), Vec::new()];
    for (i, r) in br.rows.iter().enumerate() {
        let s = usize::from(!r.stable);
        if let Some(p) = i.checked_sub(1).map(|j| &br.rows[j]) {
            if p.stable != r.stable {
                xs[s].push(f64::NAN);
                ys[s].push(f64::NAN);
                xs[s].push(p.value);
                ys[s].push(p.amplitude[k]);
                xs[1 - s].push(f64::NAN);
                ys[1 - s].push(f64::NAN);
            }
        }
        xs[s].push(r.value);
        ys[s].push(r.amplitude[k]);
    }
    let what = if br.forced {
        "frequency response by harmonic balance"
    } else {
        "periodic orbit by harmonic balance"
    };
    let title = format!("{}: {what} over {}", sc.name, br.name);
    let y_label = format!("amplitude of {} (m, half peak-to-peak)", br.names[k]);
    let mut panel = Panel::new(&title, &br.name, &y_label)
        .with_series(Series::new("stable", &xs[0], &ys[0]).colour(0).with_gaps())
        .with_series(
            Series::new("unstable", &xs[1], &ys[1])
                .colour(0)
                .dashed(true)
                .with_gaps(),
        );
    for &f in &br.folds {
        panel = panel.with_peak(f, "fold");
    }
    squeal_plot::line_panels(
        dir.join("hb_branch"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_SINGLE,
        &[panel],
    )
    .map_err(|e| RunError::Io(format!("plot: {e}")))?;
    Ok(())
}
