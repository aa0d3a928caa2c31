//! `squeal reduce [SCENARIO] [--set K=V]… [--out DIR] [--json]`: a lumped
//! (FE) model reduced by Craig–Bampton and written as a scenario with
//! Matrix Market files ([`squeal_study::reduce`]).

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging};
use crate::ScenarioArgs;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `squeal reduce`.
#[derive(Args, Debug)]
pub struct ReduceArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Output folder (default `out/<name>-reduced`): scenario.toml, M.mtx,
    /// K.mtx, C.mtx, reduce.json.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the record (reduce.json) on stdout instead of the summary.
    #[arg(long)]
    json: bool,
}

/// Run the command.
pub fn run(a: ReduceArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    if let squeal_study::model::AnyModel::Lumped(l) = &sc.model {
        let [m, k, _] = l.file_matrices();
        if m.is_none() || k.is_none() {
            // Refused by the study in one line.
        } else {
            crate::errln!(
                "reduce: {} dofs; fixed-interface modes of the interior {} ({})",
                l.dof_count(),
                if l.modal.modes > 0 {
                    format!("(the {} lowest)", l.modal.modes)
                } else {
                    format!("up to modal.cutoff_hz = {} Hz", l.modal.cutoff_hz)
                },
                if l.dof_count() > squeal_core::linear::SPARSE_FROM_DOFS {
                    "sparse: block shift-invert Lanczos"
                } else {
                    "a dense eigen-solve"
                }
            );
        }
    }
    let red = squeal_study::reduce::reduce(&sc)?;
    let stage = Staging::for_out(a.out.as_deref(), &red.name)?;
    let doc = squeal_files::reduce::write(&stage, &red)?;
    let dir = stage.commit()?;
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!("{}", red.line());
        crate::outln!("boundary: {}", red.boundary.join(" "));
        crate::outln!(
            "output: {} (run it: squeal simulate {})",
            dir.display(),
            dir.join("scenario.toml").display()
        );
    }
    Ok(())
}
