//! `squeal cycle [SCENARIO] [--set K=V]… [--json] [--out DIR]`: the limit
//! cycle the scenario settles on — period, Floquet multipliers (saltation
//! matrices at every event), amplitudes, events per period — by
//! `squeal_core::cycle`.

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use squeal_core::cycle::CycleOptions;
use squeal_core::EventKind;
use squeal_plot::{Format, Labels, Panel, Series};
use squeal_study::cycle::{checked_options, of_scenario, Found};
use squeal_study::scenario::Scenario;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// How a settling run looks for a periodic orbit (`cycle`, `hb`).
#[derive(Args, Debug)]
pub struct SettleArgs {
    /// Most integrator steps spent settling onto the cycle.
    #[arg(long, default_value_t = 20_000_000)]
    pub settle_steps: u64,
    /// Most simulated time spent settling (s), whatever the scenario's duration.
    #[arg(long, default_value_t = 1000.0, allow_hyphen_values = true)]
    pub settle_time: f64,
    /// Settled when two returns to the section agree to this, relative to
    /// the orbit's amplitude (Newton's method does the rest).
    #[arg(long, default_value_t = CycleOptions::default().settle_tol)]
    pub settle_tol: f64,
}

/// Arguments of `squeal cycle`.
#[derive(Args, Debug)]
pub struct CycleArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Poincaré section: a state name, optionally with its level
    /// (`vx_p` or `vx_p=0.1`); default an upward zero of a velocity.
    #[arg(long, value_name = "STATE[=LEVEL]", allow_hyphen_values = true)]
    pub section: Option<String>,
    #[command(flatten)]
    pub settle: SettleArgs,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write orbit.csv, cycle.json and the pictures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
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

/// Run the command.
pub fn run(a: CycleArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let opts = checked_options(
        &sc,
        a.settle.settle_steps,
        a.settle.settle_time,
        a.settle.settle_tol,
        a.section.as_deref(),
    )?;
    let stage = a.out.as_deref().map(Staging::new).transpose()?;
    let found = of_scenario(&sc, &opts, a.out.is_some(), &NEVER)?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        write_orbit(&found, &stage.path("orbit.csv"))?;
        draw(&found, &sc, stage.dir())?;
        crate::output::write_json(&doc, &stage.path("summary.json"))?;
        stage.commit()?;
    }
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        print_human(&found, &sc, a.out.as_deref());
    }
    Ok(())
}

fn print_human(f: &Found, sc: &Scenario, out: Option<&Path>) {
    crate::outln!(
        "{} ({}): limit cycle of period {:.9e} s ({:.3} Hz), {} (largest non-trivial |multiplier| {:.9})",
        sc.name,
        sc.model.name(),
        f.period,
        1.0 / f.period,
        if f.stable { "stable" } else { "unstable" },
        f.max_multiplier
    );
    crate::outln!(
        "section: upward crossing of {} = {}; shooting residual {:.2e} after {} Newton iterations; settled in {:.4} s simulated",
        f.section.0, f.section.1, f.residual, f.iterations, f.settle_time
    );
    crate::outln!("multipliers (|·| descending):");
    for &(re, im, trivial) in &f.multipliers {
        crate::outln!(
            "  {re:+.12e} {im:+.12e}i  |{:.12}|{}",
            re.hypot(im),
            if trivial {
                "  trivial (along the flow)"
            } else {
                ""
            }
        );
    }
    let ev: Vec<String> = EventKind::ALL
        .iter()
        .filter(|k| f.events[k.index()] > 0)
        .map(|k| format!("{} {}", f.events[k.index()], k.as_str()))
        .collect();
    crate::outln!(
        "events per period: {}",
        if ev.is_empty() {
            "none".to_string()
        } else {
            ev.join(", ")
        }
    );
    let amp: Vec<String> = f
        .names
        .iter()
        .zip(&f.amplitude)
        .map(|(n, a)| format!("{n} {a:.4e}"))
        .collect();
    crate::outln!("amplitude (half peak-to-peak): {}", amp.join(", "));
    if let Some(d) = out {
        crate::outln!("output: {}", d.display());
    }
}
