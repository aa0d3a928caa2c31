//! `squeal merge DIR… --out DIR`: the shards of a map, a sweep or
//! `reproduce` gathered into the unsharded study's files
//! ([`squeal_files::merge`]), and its summary printed.

use crate::commands::map::{report, Transient};
use crate::commands::reproduce::print_summary;
use crate::run::{RunError, NEVER};
use clap::Args;
use serde_json::json;
use squeal_files::merge::{merge, some, Merged};
use std::path::PathBuf;

/// Arguments of `squeal merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shard folders (`squeal map|reproduce … --shard K/N --out DIR`), all N of them.
    #[arg(required = true, value_name = "DIR")]
    shards: Vec<PathBuf>,
    /// Output folder for the merged map or report.
    #[arg(long)]
    out: PathBuf,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

/// Run the command.
pub fn run(a: MergeArgs) -> Result<(), RunError> {
    let m = merge(&a.shards, &a.out, &NEVER)?;
    let (n, dest) = (m.shards, &m.dest);
    match &m.merged {
        Merged::Map {
            labels,
            x,
            y,
            lin,
            disagree,
            failed,
            trans,
        } => {
            if !a.json {
                crate::outln!(
                    "merged {} points from {n} shards; {} failed points{}",
                    lin.len(),
                    failed.len(),
                    if failed.is_empty() {
                        String::new()
                    } else {
                        format!(" (recorded as failed in map.csv): {}", some(failed))
                    }
                );
            }
            let transient = disagree
                .zip(trans.as_deref())
                .map(|(d, t)| Transient::of(d, t));
            report(labels, x, y, lin, transient, dest, a.json)
        }
        Merged::Sweep {
            name, param, sweep, ..
        } => {
            if !a.json {
                crate::outln!("merged {} values from {n} shards", param.values.len());
            }
            crate::commands::sweep::report(name, &param.name, sweep, dest, a.json)
        }
        Merged::Reproduce {
            results,
            conclusions: cs,
            figures,
        } => {
            if a.json {
                let doc = json!({
                    "sets": results.len(), "shards": n, "figures": figures,
                    "conclusions": cs.iter().map(|c| json!({"id": c.id, "grade": c.grade.as_str()})).collect::<Vec<_>>(),
                    "out": dest,
                });
                crate::outln!(
                    "{}",
                    serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
                );
                return Ok(());
            }
            print_summary(
                &format!("merged {} sets from {n} shards", results.len()),
                cs,
                dest,
            );
            Ok(())
        }
    }
}
