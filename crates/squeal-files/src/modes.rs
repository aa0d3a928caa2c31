//! `modes.csv` (`stability --out`): every mode's eigenvalue and shape.

use crate::RunError;
use squeal_core::stability::Analysis;
use squeal_study::model::AnyModel;
use squeal_study::stability::shape_of;

/// Write `modes.csv`: one row per mode and position dof,
/// `mode,growth_rate,freq_hz,damping_ratio,dof,amplitude,phase_deg`, modes
/// numbered as in the table (by growth rate).
pub fn write_modes_csv(
    path: &std::path::Path,
    model: &AnyModel,
    an: &Analysis,
) -> Result<(), RunError> {
    use std::io::Write;
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    writeln!(
        w,
        "mode,growth_rate,freq_hz,damping_ratio,dof,amplitude,phase_deg"
    )
    .map_err(io)?;
    let names = model.state_names();
    for (k, e) in an.eigen.iter().enumerate() {
        for (i, (amp, ph)) in shape_of(e).into_iter().enumerate() {
            writeln!(
                w,
                "{},{:e},{:e},{:e},{},{:e},{:e}",
                k + 1,
                e.re,
                e.freq_hz,
                e.damping_ratio,
                names.get(i).map_or("", String::as_str),
                amp,
                ph
            )
            .map_err(io)?;
        }
    }
    w.flush().map_err(io)
}
