//! `squeal map [SCENARIO] --x NAME=LO:HI:N --y NAME=LO:HI:N [--log-x] [--log-y] --out DIR [--transient]`:
//! stability over a grid of any two parameters, linear (eigenvalues) or
//! nonlinear (simulation), in parallel and deterministic.

use crate::commands::simulate::{resolve, resolve_run};
use crate::run::{bars, RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::json;
use squeal_files::map::{Labels, MapStudy};
use squeal_files::shard::Shard;
use squeal_study::map::{check_distinct, parse_axis, Axis};
use std::path::PathBuf;

/// Arguments of `squeal map`.
#[derive(Args, Debug)]
pub struct MapArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// First parameter and its range: NAME=LO:HI:N.
    #[arg(long = "x", value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    pub x: String,
    /// Second parameter and its range: NAME=LO:HI:N.
    #[arg(long = "y", value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    pub y: String,
    /// Space the x values logarithmically.
    #[arg(long)]
    pub log_x: bool,
    /// Space the y values logarithmically.
    #[arg(long)]
    pub log_y: bool,
    /// Output folder (default: out/SCENARIO-map).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Classify every point by simulation too (decays / grows / stick-slip / steady / out-of-range / too-short).
    #[arg(long)]
    pub transient: bool,
    /// Simulated time per point for --transient (default: the scenario's).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
    /// Compute only shard K of N (K from 0): the points whose flat index i
    /// has i mod N = K (interleaved), written as `shard.json` + `part.csv`
    /// for `squeal merge`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
}

/// What a transient map's summary counts.
#[derive(Debug, Clone, Copy)]
pub struct Transient {
    /// Points whose linear verdict and simulated outcome disagree.
    pub disagree: usize,
    /// Points whose run never moved beyond integration noise (`too-short`).
    pub too_short: usize,
}

impl Transient {
    /// The counts of a transient map whose outcomes are `trans`, `disagree`
    /// of them disagreeing with the linear verdict.
    pub fn of(disagree: usize, trans: &[squeal_study::map::Outcome]) -> Self {
        Transient {
            disagree,
            too_short: trans.iter().filter(|o| o.class == "too-short").count(),
        }
    }
}

/// The summary `map` and `merge` print (or `--json`).
pub fn report(
    labels: &Labels,
    x: &Axis,
    y: &Axis,
    lin: &[(f64, f64)],
    transient: Option<Transient>,
    dest: &std::path::Path,
    json: bool,
) -> Result<(), RunError> {
    let n = lin.len();
    let unstable = lin.iter().filter(|s| s.0 > 0.0).count();
    let nan = lin.iter().filter(|s| s.0.is_nan()).count();
    if json {
        let doc = json!({
            "x": x.name, "y": y.name, "points": n, "unstable": unstable, "no_steady_sliding": nan,
            "linear_nonlinear_disagree": transient.map(|t| t.disagree),
            "too_short": transient.map(|t| t.too_short), "out": dest,
        });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
        return Ok(());
    }
    crate::outln!(
        "{}: {n} points ({} × {}), {unstable} unstable, {nan} without steady sliding",
        labels.name,
        x.values.len(),
        y.values.len()
    );
    if let Some(t) = transient {
        crate::outln!(
            "linear verdict and simulated outcome disagree at {} points (see map.csv)",
            t.disagree
        );
        if t.too_short > 0 {
            crate::outln!(
                "{} points too-short: their runs never moved beyond integration noise (a start at round-off); give the scenario an offset or a longer --duration",
                t.too_short
            );
        }
    }
    crate::outln!(
        "output: {} (map.csv, map.png{})",
        dest.display(),
        match transient {
            Some(_) if dest.join("spl_dba.png").exists() => ", transient.png, spl_dba.png",
            Some(_) => ", transient.png",
            None => "",
        }
    );
    Ok(())
}

/// The map `a` asks for, its scenario and both axes checked (as `simulate`
/// checks whenever the map simulates) before anything is written.
pub fn prepare(a: &MapArgs) -> Result<MapStudy, RunError> {
    let sc = if a.transient || a.duration.is_some() {
        resolve_run(&a.scenario, a.duration)?
    } else {
        resolve(&a.scenario)?
    };
    let x = parse_axis(&a.x, "--x", a.log_x, &sc.model)?;
    let y = parse_axis(&a.y, "--y", a.log_y, &sc.model)?;
    check_distinct(&x, &y)?;
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    Ok(MapStudy {
        sc,
        x,
        y,
        transient: a.transient,
        shard,
    })
}

/// Run the command.
pub fn run(a: MapArgs) -> Result<(), RunError> {
    let study = prepare(&a)?;
    let stage = Staging::for_out(a.out.as_deref(), &study.folder())?;
    let points = study.points();
    if let Some(p) = squeal_study::plan::plan(&study.sc, "map", points.len()) {
        crate::errln!("{p}");
    }
    let r = study.compute(&bars, &NEVER)?;
    let disagree = study.write(&stage, &r)?;
    let dest = stage.commit()?;
    let n = study.grid_points();
    let Some(s) = study.shard else {
        return report(
            &study.labels(),
            &study.x,
            &study.y,
            &r.lin,
            disagree
                .zip(r.trans.as_deref())
                .map(|(d, t)| Transient::of(d, t)),
            &dest,
            a.json,
        );
    };
    if a.json {
        let doc = json!({ "shard": s.k, "shards": s.n, "points": points.len(), "grid_points": n, "out": dest });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!(
            "{}: shard {}/{} — {} of {n} points; output: {} (shard.json, part.csv); gather with `squeal merge`",
            study.sc.name,
            s.k,
            s.n,
            points.len(),
            dest.display()
        );
    }
    Ok(())
}
