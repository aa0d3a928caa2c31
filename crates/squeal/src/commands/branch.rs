//! `squeal branch [SCENARIO] --param NAME=LO:HI:N --out DIR [--json]`: the
//! limit cycle followed in one parameter (`squeal_study::branch`:
//! pseudo-arclength continuation through folds), `branch.csv`, the
//! bifurcation diagram (stable solid, unstable dashed) and the report of the
//! bifurcations and of the meeting with steady sliding.

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use squeal_core::EventKind;
use squeal_plot::{Format, Panel, Series};
use squeal_study::branch::{check, follow, parse_range, values, BranchPoint};
use squeal_study::scenario::Scenario;
use squeal_study::NoProgress;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

/// Arguments of `squeal branch`.
#[derive(Args, Debug)]
pub struct BranchArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The parameter and its N evenly spaced values, e.g. V=0.05:0.5:20.
    #[arg(long, value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    param: String,
    /// Write branch.csv, summary.json and the bifurcation diagram here.
    #[arg(long)]
    out: PathBuf,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Run the command.
pub fn run(a: BranchArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let (name, lo, hi, n) = parse_range(&a.param)?;
    let values = values(lo, hi, n);
    check(&sc, &name, &values)?;
    let stage = Staging::new(&a.out)?;
    let names = sc.model.state_names();
    let br = follow(&sc, &name, &values, (lo, hi), &NoProgress, &NEVER)?;
    let points = &br.points;
    let doc = br.to_json(&name, &sc);
    let none = Vec::new();
    let bifurcations = doc["bifurcations"].as_array().unwrap_or(&none);
    let failures = doc["failed"].as_array().unwrap_or(&none);
    let hopf = Some(&doc["hopf"]).filter(|h| !h.is_null());
    write_csv(&name, &names, points, &stage.path("branch.csv"))?;
    draw(
        &sc,
        &name,
        &br.curve,
        br.hopf.as_ref().map(|h| h.value),
        &stage,
    )?;
    crate::output::write_json(&doc, &stage.path("summary.json"))?;
    let dest = stage.commit()?;
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!(
            "{}: {} rows ({} grid values of {n}, {} folds) on the branch over {name} = {lo}…{hi}",
            sc.name,
            points.len(),
            points.iter().filter(|p| p.kind == "grid").count(),
            points.iter().filter(|p| p.kind == "fold").count()
        );
        for b in bifurcations {
            let at = match b["value"].as_f64() {
                Some(v) => format!("at {name} = {v:.9e}"),
                None => format!(
                    "between {name} = {} and {}",
                    b["between"][0], b["between"][1]
                ),
            };
            crate::outln!(
                "  {} {at}: {}",
                b["kind"].as_str().unwrap_or("").replace('_', " "),
                b["detail"].as_str().unwrap_or("")
            );
        }
        for (v, f) in br.steady_sliding() {
            crate::outln!(
                "  the branch meets steady sliding at {name} = {v:.9e} ({f:.6} Hz; amplitude → 0, extrapolated)"
            );
        }
        if let Some(h) = &hopf {
            crate::outln!(
                "  steady sliding changes stability at {name} = {} ({:.6} Hz, `critical`); the nearest cycle, at {}, has {:.6} Hz",
                h["value"],
                h["freq_hz"].as_f64().unwrap_or(f64::NAN),
                h["nearest_point"]["value"],
                h["nearest_point"]["cycle_freq_hz"].as_f64().unwrap_or(f64::NAN)
            );
            if let Some(d) = h["branch_end"]["value_difference"].as_f64() {
                crate::outln!(
                    "  the branch's end on steady sliding differs from it by {d:.3e} in {name} and {:.3e} Hz",
                    h["branch_end"]["freq_difference_hz"].as_f64().unwrap_or(f64::NAN)
                );
            }
        }
        for f in failures {
            crate::outln!("  no cycle at {name} = {}: {}", f["value"], f["error"]);
        }
        crate::outln!("output: {}", dest.display());
    }
    Ok(())
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
