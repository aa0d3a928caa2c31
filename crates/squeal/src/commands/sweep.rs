//! `squeal sweep [SCENARIO] --param NAME=LO:HI:N [--out DIR] [--json]`: every
//! eigenvalue of steady sliding along a one-parameter sweep, modes tracked
//! continuously by shape (`squeal_core::stability::sweep`), written as
//! `sweep.csv` and drawn as the mode-coupling diagram (`sweep.png/.svg`).

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::json;
use squeal_core::stability::sweep::Sweep;
use squeal_core::stability::Direction;
use squeal_files::shard::Shard;
use squeal_files::sweep::{SweepResult, SweepStudy};
use squeal_study::map::parse_axis;
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

/// Run the command.
pub fn run(a: SweepArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let axis = parse_axis(&a.param, "--param", false, &sc.model)?;
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    let study = SweepStudy::new(sc, axis, &a.param, shard)?;
    let stage = Staging::for_out(a.out.as_deref(), &study.folder())?;
    let n = study.param.values.len();
    if let Some(p) = squeal_study::plan::plan(&study.sc, "sweep", n) {
        crate::errln!("{p}");
    }
    let r = study.compute(&NEVER)?;
    study.write(&stage, &r)?;
    let out = stage.commit()?;
    let (s, own, computed) = match &r {
        SweepResult::Shard {
            shard,
            own,
            computed,
            ..
        } => (shard, own, computed),
        SweepResult::Whole(sw) => {
            return report(&study.sc.name, &study.param.name, sw, &out, a.json)
        }
    };
    if a.json {
        let doc = json!({ "shard": s.k, "shards": s.n, "values": own.len(), "first": own.start, "computed_from": computed.start, "out": out });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!(
            "{}: shard {}/{} — values {}–{} of {n} (tracked from value {}); output: {} (shard.json, part.json); gather with `squeal merge`",
            study.sc.name,
            s.k,
            s.n,
            own.start,
            own.end - 1,
            computed.start,
            out.display()
        );
    }
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
