//! Every eigenvalue of steady sliding along a one-parameter sweep, modes
//! tracked continuously by shape.

use crate::error::{Cancel, StudyError};
use crate::model::AnyModel;
use crate::scenario::InputError;
use nalgebra::DMatrix;
use squeal_core::stability::sweep::{sweep, Sweep, SweepOptions};
use squeal_core::stability::{state_matrix, StabilityError};

/// The state matrix `A = ∂f/∂z` and equilibrium of any model, as runtime-sized values.
pub fn model_state_matrix(model: &AnyModel) -> Result<(DMatrix<f64>, Vec<f64>), StabilityError> {
    crate::with_model!(model, m => {
        let (z, a) = state_matrix(m)?;
        let n = z.len();
        Ok((DMatrix::from_fn(n, n, |i, j| a[i][j]), z.to_vec()))
    }, lumped l => {
        let (z, a) = squeal_core::stability::lumped::state_matrix(l)?;
        Ok((a, z))
    })
}

/// Sweep `name` over `values` for any model (built-in or lumped),
/// tracking every mode by shape ([`squeal_core::stability::sweep`]). On
/// failure, also the parameter value where it happened.
pub fn sweep_at(
    model: &AnyModel,
    name: &str,
    values: &[f64],
    cancel: &Cancel,
) -> Result<Sweep, (StabilityError, f64)> {
    let mut at = f64::NAN;
    sweep(
        values,
        |p| {
            at = p;
            if cancel.is_cancelled() {
                return Err(StabilityError::BadInput("interrupted".into()));
            }
            let mut m = model.clone();
            m.set(name, p)?;
            m.validate()?;
            model_state_matrix(&m)
        },
        &SweepOptions::default(),
    )
    .map_err(|e| (e, at))
}

/// [`sweep_at`] with its failures as study errors: `spec` is the sweep as
/// the user wrote it (`NAME=LO:HI:N`), quoted as `--param SPEC` in messages.
pub fn sweep_model(
    model: &AnyModel,
    name: &str,
    values: &[f64],
    spec: &str,
    cancel: &Cancel,
) -> Result<Sweep, StudyError> {
    let r = sweep_at(model, name, values, cancel);
    cancel.check()?;
    r.map_err(|(e, at)| match e {
        StabilityError::Param(_) => StudyError::Input(InputError(format!("--param {spec}: {e}"))),
        StabilityError::NoSteadySliding(_) => {
            StudyError::Input(InputError(format!("--param {spec}: at {name} = {at}: {e}")))
        }
        other => StudyError::Numerical(format!("eigen-analysis at {name} = {at}: {other}")),
    })
}
