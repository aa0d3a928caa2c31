//! `squeal sweep [SCENARIO] --param NAME=LO:HI:N [--out DIR] [--json]`: every
//! eigenvalue of steady sliding along a one-parameter sweep, modes tracked
//! continuously by shape (`squeal_core::stability::sweep`), written as
//! `sweep.csv` and drawn as the mode-coupling diagram (`sweep.png/.svg`).

use crate::commands::merge::Shard;
use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::json;
use squeal_core::stability::sweep::Sweep;
use squeal_core::stability::Direction;
use squeal_plot::{BranchSeries, Format, ModeCouplingSpec};
use squeal_study::map::{parse_axis, unit_of, Axis};
use squeal_study::sweep::sweep_model;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `squeal sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// The swept parameter and its grid, e.g. mu=0.1:0.5:81 (N points, ends included).
    #[arg(long, value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    pub param: String,
    /// Output folder (default: out/SCENARIO-sweep).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the onsets and coalescences as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Compute only shard K of N (K from 0): the K-th of N contiguous
    /// slices of the values (and the two values before it, to track the
    /// modes across the boundary), written as `shard.json` + `part.json`
    /// for `squeal merge`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
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
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    if let Some(s) = shard {
        if s.n > axis.values.len() {
            return Err(squeal_study::scenario::InputError(format!(
                "--shard {}/{}: more shards than the {} values of --param {}",
                s.k,
                s.n,
                axis.values.len(),
                a.param
            ))
            .into());
        }
    }
    let name = Shard::folder(&format!("{}-sweep", sc.name), shard);
    let stage = Staging::for_out(a.out.as_deref(), &name)?;
    if let Some(p) = squeal_study::plan::plan(&sc, "sweep", axis.values.len()) {
        crate::errln!("{p}");
    }
    let unit = unit_of(&sc.model, &axis.name);
    let xl = if unit.is_empty() {
        axis.name.clone()
    } else {
        format!("{} ({unit})", axis.name)
    };
    if let Some(s) = shard {
        use squeal_study::sweep::shard::{part_of, slice};
        let (_, computed) = slice(axis.values.len(), s.k, s.n);
        let sw = sweep_model(
            &sc.model,
            &axis.name,
            &axis.values[computed.clone()],
            &a.param,
            &NEVER,
        )?;
        let part = part_of(&axis.values, s.k, s.n, &sw);
        let study = crate::commands::merge::sweep_study(&sc, &axis, &xl);
        crate::commands::merge::write_sweep_part(&stage, &study, s, &part)?;
        let out = stage.commit()?;
        let (own, _) = slice(axis.values.len(), s.k, s.n);
        if a.json {
            let doc = json!({ "shard": s.k, "shards": s.n, "values": own.len(), "first": own.start, "computed_from": computed.start, "out": out });
            crate::outln!(
                "{}",
                serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
            );
        } else {
            crate::outln!(
                "{}: shard {}/{} — values {}–{} of {} (tracked from value {}); output: {} (shard.json, part.json); gather with `squeal merge`",
                sc.name,
                s.k,
                s.n,
                own.start,
                own.end - 1,
                axis.values.len(),
                computed.start,
                out.display()
            );
        }
        return Ok(());
    }
    let sw = sweep_model(&sc.model, &axis.name, &axis.values, &a.param, &NEVER)?;
    write_sweep(&stage, &sc.name, &axis, &xl, &sw)?;
    let out = stage.commit()?;
    report(&sc.name, &axis.name, &sw, &out, a.json)
}

/// Write `sweep.csv` and the mode-coupling diagram (`sweep.png`/`.svg`) of
/// `sw` into `stage`. `sweep` and `merge` both write through this, so a
/// merged sweep is the unsharded one byte for byte.
pub fn write_sweep(
    stage: &Staging,
    name: &str,
    axis: &Axis,
    xl: &str,
    sw: &Sweep,
) -> Result<(), RunError> {
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
    let title = format!("{name}: mode-coupling diagram");
    let spec = ModeCouplingSpec {
        title: &title,
        x_label: xl,
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
    Ok(())
}

/// The terminal lines (or with `json` the JSON document) of a sweep.
pub fn report(
    name: &str,
    param: &str,
    sw: &Sweep,
    out: &std::path::Path,
    json: bool,
) -> Result<(), RunError> {
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
    if json {
        let doc = json!({
            "param": param,
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
        name,
        sw.listed.len(),
        sw.values.len(),
        param,
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
            param,
            o.value,
            o.freq_hz,
            o.mode
                .map_or(String::new(), |m| format!(", mode {}", m + 1))
        );
    }
    Ok(())
}
