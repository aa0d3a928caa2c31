//! The files of a limit-cycle branch (`branch --out`): `branch.csv`,
//! `summary.json` and the bifurcation diagram (`branch.png`/`.svg`).

use crate::{RunError, Staging};
use serde_json::Value;
use squeal_core::EventKind;
use squeal_plot::{Format, Panel, Series};
use squeal_study::branch::{Branch, BranchPoint};
use squeal_study::scenario::Scenario;
use std::io::{BufWriter, Write};

/// Write the branch `br` of `sc` over the parameter `name`, with its JSON
/// document `doc`, into `stage`.
pub fn write(
    stage: &Staging,
    br: &Branch,
    sc: &Scenario,
    name: &str,
    doc: &Value,
) -> Result<(), RunError> {
    let names = sc.model.state_names();
    write_csv(name, &names, &br.points, &stage.path("branch.csv"))?;
    draw(
        sc,
        name,
        &br.curve,
        br.hopf.as_ref().map(|h| h.value),
        stage,
    )?;
    crate::output::write_json(doc, &stage.path("summary.json"))
}

fn write_csv(
    name: &str,
    states: &[String],
    points: &[BranchPoint],
    path: &std::path::Path,
) -> Result<(), RunError> {
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let f = std::fs::File::create(path).map_err(io)?;
    let mut w = BufWriter::new(f);
    let mut header = vec![name.to_string(), "period".to_string()];
    header.extend(states.iter().map(|s| format!("amplitude_{s}")));
    header.push("max_multiplier".into());
    header.push("stable".into());
    header.extend(
        EventKind::ALL
            .iter()
            .map(|k| format!("events_{}", k.as_str())),
    );
    header.push("point".into());
    writeln!(w, "{}", header.join(",")).map_err(io)?;
    for p in points {
        let f = &p.found;
        let mut row = vec![format!("{:e}", p.value), format!("{:e}", f.period)];
        row.extend(f.amplitude.iter().map(|a| format!("{a:e}")));
        row.push(format!("{:e}", f.max_multiplier));
        row.push(f.stable.to_string());
        row.extend(
            EventKind::ALL
                .iter()
                .map(|k| f.events[k.index()].to_string()),
        );
        row.push(p.kind.to_string());
        writeln!(w, "{}", row.join(",")).map_err(io)?;
    }
    w.flush().map_err(io)
}

/// Bifurcation diagram: the phase portrait's velocity amplitude against the
/// parameter, every computed point of each segment joined in the order
/// followed, stable solid and unstable dashed; `critical`'s Hopf point marked.
fn draw(
    sc: &Scenario,
    name: &str,
    curve: &[(usize, f64, Vec<f64>, bool)],
    hopf: Option<f64>,
    stage: &Staging,
) -> Result<(), RunError> {
    if curve.is_empty() {
        return Ok(());
    }
    let ch = sc.model.channels();
    let names = sc.model.state_names();
    let Some(k) = names.iter().position(|n| *n == ch.phase.1) else {
        return Ok(());
    };
    // Two series over the same points: each keeps the pieces of its own
    // stability (a piece starts at the last point of the other's, so the
    // line is unbroken), a NaN breaks it elsewhere and between segments.
    let mut xs = [Vec::new(), Vec::new()];
    let mut ys = [Vec::new(), Vec::new()];
    for (i, (seg, v, amp, stable)) in curve.iter().enumerate() {
        let s = usize::from(!*stable);
        let prev = i.checked_sub(1).map(|j| &curve[j]).filter(|p| p.0 == *seg);
        match prev {
            None => {
                for side in 0..2 {
                    xs[side].push(f64::NAN);
                    ys[side].push(f64::NAN);
                }
            }
            Some(p) if p.3 != *stable => {
                xs[s].push(f64::NAN);
                ys[s].push(f64::NAN);
                xs[s].push(p.1);
                ys[s].push(p.2[k]);
                xs[1 - s].push(f64::NAN);
                ys[1 - s].push(f64::NAN);
            }
            Some(_) => {}
        }
        xs[s].push(*v);
        ys[s].push(amp[k]);
    }
    let title = format!("{}: limit cycle branch over {name}", sc.name);
    let y_label = format!("amplitude of {} (m/s)", ch.phase.1);
    let mut panel = Panel::new(&title, name, &y_label)
        .with_series(Series::new("stable", &xs[0], &ys[0]).colour(0).with_gaps())
        .with_series(
            Series::new("unstable", &xs[1], &ys[1])
                .colour(0)
                .dashed(true)
                .with_gaps(),
        );
    if let Some(v) = hopf {
        panel = panel.with_peak(v, "Hopf point of steady sliding (critical)");
    }
    squeal_plot::line_panels(
        stage.dir().join("branch"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_SINGLE,
        &[panel],
    )
    .map_err(|e| RunError::Io(format!("plot: {e}")))?;
    Ok(())
}
