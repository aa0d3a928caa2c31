//! `squeal branch [SCENARIO] --param NAME=LO:HI:N --out DIR [--json]`: the
//! limit cycle followed in one parameter (`squeal_study::branch`:
//! pseudo-arclength continuation through folds), `branch.csv`, the
//! bifurcation diagram (stable solid, unstable dashed) and the report of the
//! bifurcations and of the meeting with steady sliding.

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use squeal_study::branch::{check, follow, parse_range, values};
use squeal_study::NoProgress;
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
    let br = follow(&sc, &name, &values, (lo, hi), &NoProgress, &NEVER)?;
    let points = &br.points;
    let doc = br.to_json(&name, &sc);
    let none = Vec::new();
    let bifurcations = doc["bifurcations"].as_array().unwrap_or(&none);
    let failures = doc["failed"].as_array().unwrap_or(&none);
    let hopf = Some(&doc["hopf"]).filter(|h| !h.is_null());
    squeal_files::branch::write(&stage, &br, &sc, &name, &doc)?;
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
