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

fn write(path: &std::path::Path, text: &str) -> Result<(), RunError> {
    std::fs::write(path, text)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
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
    write(&stage.path("scenario.toml"), &red.toml)?;
    write(
        &stage.path("M.mtx"),
        &squeal_core::matrix_market::write(&red.m),
    )?;
    write(
        &stage.path("K.mtx"),
        &squeal_core::matrix_market::write(&red.k),
    )?;
    if let Some(c) = &red.c {
        write(&stage.path("C.mtx"), &squeal_core::matrix_market::write(c))?;
    }
    let doc = serde_json::to_value(&red).map_err(|e| RunError::Io(e.to_string()))?;
    crate::output::write_json(&doc, &stage.path("reduce.json"))?;
    // What was written must read back as the model it describes.
    let path = stage.path("scenario.toml");
    let back = squeal_study::scenario::resolve(
        squeal_study::scenario::Source::Spec(&path.to_string_lossy()),
        &[],
    )
    .map_err(|e| {
        RunError::Io(format!(
            "reduce: the reduced scenario does not read back: {e}"
        ))
    })?;
    if (back.model.state_names().len() / 2) != red.reduced_dofs() {
        return Err(RunError::Io(format!(
            "reduce: the reduced scenario reads back with {} dofs, not {}",
            (back.model.state_names().len() / 2),
            red.reduced_dofs()
        )));
    }
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
