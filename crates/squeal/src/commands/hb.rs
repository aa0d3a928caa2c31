//! `squeal hb [SCENARIO] [--harmonics H] [--json]`: the self-excited
//! periodic orbit by harmonic balance (`squeal_study::hb`).

use crate::commands::cycle::SettleArgs;
use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use squeal_plot::{Format, Panel, Series};
use squeal_study::cycle::checked_options;
use squeal_study::hb::{of_scenario, HbFound};
use squeal_study::scenario::Scenario;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Arguments of `squeal hb`.
#[derive(Args, Debug)]
pub struct HbArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Harmonics kept (the table also shows H/4 and H/2).
    #[arg(long, default_value_t = 20)]
    pub harmonics: usize,
    #[command(flatten)]
    pub settle: SettleArgs,
    /// Where the first guess comes from: `settle` (a settled simulation, the
    /// orbit the scenario's motion settles on) or `hopf` (steady sliding's
    /// growing mode, no simulation; settles if that finds no stable orbit).
    #[arg(long, default_value = "settle")]
    pub guess: String,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write summary.json, hb_orbit.csv and hb.png/.svg (the series against
    /// the exact flow from it, and the harmonics) into this new folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
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

/// Run the command.
pub fn run(a: HbArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    squeal_study::hb::check_harmonics(a.harmonics)?;
    let opts = checked_options(
        &sc,
        a.settle.settle_steps,
        a.settle.settle_time,
        a.settle.settle_tol,
        None,
    )?;
    let stage = a.out.as_deref().map(Staging::new).transpose()?;
    let guess = squeal_study::hb::Guess::parse(&a.guess)?;
    let found = of_scenario(&sc, a.harmonics, &opts, guess, a.out.is_some(), &NEVER)?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        write_orbit(&found, &stage.path("hb_orbit.csv"))?;
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
        print_human(&found, &sc);
        if let Some(d) = &a.out {
            crate::outln!("output: {}", d.display());
        }
    }
    Ok(())
}

fn print_human(f: &HbFound, sc: &Scenario) {
    crate::outln!(
        "{} ({}): periodic orbit by harmonic balance, H = {}: {:.6} Hz (period {:.9e} s), {} (largest non-trivial |multiplier| {:.9}, by one exact period from the HB orbit)",
        sc.name,
        sc.model.name(),
        f.harmonics,
        1.0 / f.period,
        f.period,
        if f.stable { "stable" } else { "unstable" },
        f.max_multiplier
    );
    crate::outln!(
        "residual {:.2e} after {} Newton iterations; {} panels, {} mode switches per period; exact period from the HB state misses it by {:.2e} (scaled)",
        f.residual, f.iterations, f.panels, f.switches, f.defect
    );
    crate::outln!("convergence in the harmonics:");
    crate::outln!("      H        frequency (Hz)   amplitude change   residual");
    for t in &f.convergence {
        crate::outln!(
            "  {:5}  {:20.10}   {:>16}   {:.1e}",
            t.harmonics,
            t.freq_hz,
            if t.amplitude_change.is_finite() {
                format!("{:.2e}", t.amplitude_change)
            } else {
                "–".into()
            },
            t.residual
        );
    }
    for (name, fr) in &f.fractions {
        crate::outln!(
            "contact {name}: slip+ {:.4}, slip− {:.4}, stick {:.4}, no contact {:.4} of the period",
            fr[0],
            fr[1],
            fr[2],
            fr[3]
        );
    }
    let n = f.spectrum.len();
    let show = f.harmonics.min(5);
    crate::outln!("amplitude per dof and harmonic (m; mean, then k = 1…{show}):");
    for (name, s) in f.names[..n].iter().zip(&f.spectrum) {
        let parts: Vec<String> = s[..=show].iter().map(|v| format!("{v:.4e}")).collect();
        crate::outln!("  {name}: {}", parts.join("  "));
    }
    let amp: Vec<String> = f
        .names
        .iter()
        .zip(&f.amplitude)
        .map(|(n, a)| format!("{n} {a:.4e}"))
        .collect();
    crate::outln!("amplitude (half peak-to-peak): {}", amp.join(", "));
    crate::outln!("multipliers (|·| descending):");
    for &(re, im, trivial) in &f.multipliers {
        crate::outln!(
            "  {re:+.9e} {im:+.9e}i  |{:.9}|{}",
            re.hypot(im),
            if trivial { "  trivial" } else { "" }
        );
    }
    for w in &f.warnings {
        crate::outln!("warning: {w}");
    }
}
