//! `squeal sweep [SCENARIO] --param NAME=LO:HI:N [--out DIR] [--json]`: every
//! eigenvalue of steady sliding along a one-parameter sweep, modes tracked
//! continuously by shape (`squeal_core::stability::sweep`), written as
//! `sweep.csv` and drawn as the mode-coupling diagram (`sweep.png/.svg`).

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::json;
use squeal_core::stability::Direction;
use squeal_plot::{BranchSeries, Format, ModeCouplingSpec};
use squeal_study::map::{parse_axis, unit_of};
use squeal_study::sweep::sweep_model;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `squeal sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The swept parameter and its grid, e.g. mu=0.1:0.5:81 (N points, ends included).
    #[arg(long, value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    param: String,
    /// Output folder (default: out/SCENARIO-sweep).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the onsets and coalescences as JSON on stdout.
    #[arg(long)]
    json: bool,
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        "nan".into()
    }
}

/// Run the command.
pub fn run(a: SweepArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let axis = parse_axis(&a.param, "--param", false, &sc.model)?;
    let dest = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-sweep", sc.name)));
    let stage = Staging::new(&dest)?;
    let sw = sweep_model(&sc.model, &axis.name, &axis.values, &a.param, &NEVER)?;
    let path = stage.path("sweep.csv");
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io)?);
    writeln!(w, "{},mode,growth_rate,freq_hz,damping_ratio", axis.name).map_err(io)?;
    let two_pi = 2.0 * std::f64::consts::PI;
    for (k, &p) in sw.values.iter().enumerate() {
        for (m, &b) in sw.listed.iter().enumerate() {
            let l = sw.lambda[k][b];
            let mag = l.norm();
            let zeta = if mag > 0.0 { -l.re / mag } else { 0.0 };
            writeln!(
                w,
                "{},{},{},{},{}",
                num(p),
                m + 1,
                num(l.re),
                num(l.im.abs() / two_pi),
                num(zeta)
            )
            .map_err(io)?;
        }
    }
    w.flush().map_err(io)?;
    // The mode-coupling diagram.
    let labels: Vec<String> = (1..=sw.listed.len()).map(|m| format!("mode {m}")).collect();
    let freq: Vec<Vec<f64>> = sw
        .listed
        .iter()
        .map(|&b| sw.lambda.iter().map(|l| l[b].im.abs() / two_pi).collect())
        .collect();
    let sigma: Vec<Vec<f64>> = sw
        .listed
        .iter()
        .map(|&b| sw.lambda.iter().map(|l| l[b].re).collect())
        .collect();
    let growing: Vec<Vec<bool>> = sw
        .listed
        .iter()
        .map(|&b| {
            sw.lambda
                .iter()
                .map(|l| squeal_core::stability::is_growing(l[b].re, l[b].im))
                .collect()
        })
        .collect();
    let branches: Vec<BranchSeries> = (0..sw.listed.len())
        .map(|m| BranchSeries {
            label: &labels[m],
            freq: &freq[m],
            growth: &sigma[m],
            growing: &growing[m],
        })
        .collect();
    let marks: Vec<(f64, f64)> = sw
        .onsets
        .iter()
        .filter(|o| o.coalescence)
        .map(|o| (o.value, o.freq_hz))
        .collect();
    let unit = unit_of(&sc.model, &axis.name);
    let xl = if unit.is_empty() {
        axis.name.clone()
    } else {
        format!("{} ({unit})", axis.name)
    };
    let title = format!("{}: mode-coupling diagram", sc.name);
    let spec = ModeCouplingSpec {
        title: &title,
        x_label: &xl,
        x: &sw.values,
        branches: &branches,
        coalescences: &marks,
    };
    squeal_plot::mode_coupling(
        stage.path("sweep"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_MULTI,
        &spec,
    )
    .map_err(|e| RunError::Io(format!("drawing failed: {e}")))?;
    let out = stage.commit()?;
    let onsets: Vec<_> = sw
        .onsets
        .iter()
        .map(|o| {
            json!({
                "value": o.value,
                "freq_hz": o.freq_hz,
                "mode": o.mode.map(|m| m + 1),
                "direction": o.direction,
                "coalescence": o.coalescence,
            })
        })
        .collect();
    if a.json {
        let doc = json!({
            "param": axis.name,
            "points": sw.values.len(),
            "modes": sw.listed.len(),
            "onsets": onsets,
            "out": out.display().to_string(),
        });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
        return Ok(());
    }
    crate::outln!(
        "{}: {} modes over {} values of {} → {}",
        sc.name,
        sw.listed.len(),
        sw.values.len(),
        axis.name,
        out.display()
    );
    if sw.onsets.is_empty() {
        crate::outln!("  no change of stability in the sweep");
    }
    for o in &sw.onsets {
        let what = match (o.coalescence, o.direction) {
            (true, Direction::Destabilising) => "two modes coalesce and one grows",
            (true, Direction::Stabilising) => "two coalesced modes separate and stop growing",
            (false, Direction::Destabilising) => "a mode starts to grow",
            (false, Direction::Stabilising) => "a mode stops growing",
        };
        crate::outln!(
            "  {} = {:.10e}: {what} ({:.2} Hz{})",
            axis.name,
            o.value,
            o.freq_hz,
            o.mode
                .map_or(String::new(), |m| format!(", mode {}", m + 1))
        );
    }
    Ok(())
}
