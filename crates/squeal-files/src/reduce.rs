//! The files of a reduced model (`reduce --out`): `scenario.toml`, `M.mtx`,
//! `K.mtx` (and `C.mtx`) and `reduce.json`, checked to read back as the
//! model they describe.

use crate::{RunError, Staging};
use serde_json::Value;
use squeal_study::reduce::Reduction;

fn write_text(path: &std::path::Path, text: &str) -> Result<(), RunError> {
    std::fs::write(path, text)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
}

/// Write the reduced model into `stage` and read it back; returns the
/// record (`reduce.json`'s document).
pub fn write(stage: &Staging, red: &Reduction) -> Result<Value, RunError> {
    write_text(&stage.path("scenario.toml"), &red.toml)?;
    write_text(
        &stage.path("M.mtx"),
        &squeal_core::matrix_market::write(&red.m),
    )?;
    write_text(
        &stage.path("K.mtx"),
        &squeal_core::matrix_market::write(&red.k),
    )?;
    if let Some(c) = &red.c {
        write_text(&stage.path("C.mtx"), &squeal_core::matrix_market::write(c))?;
    }
    let doc = serde_json::to_value(red).map_err(|e| RunError::Io(e.to_string()))?;
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
    Ok(doc)
}
