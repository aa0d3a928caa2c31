//! Stability of lumped models of any size: the steady-sliding state by
//! Newton's method, the analytic state matrix (dense, `2n × 2n`), and the
//! size-independent complex eigen-analysis of [`super::modal`]. Models small
//! enough for the fixed-size path ([`crate::model::lumped::MAX_SIM_DOFS`]
//! dofs) go through [`super::analyse`] instead (the same eigenvalues).

use super::{Analysis, StabilityError};
use crate::model::lumped::Lumped;
use nalgebra::DMatrix;

/// The steady-sliding state and the state matrix there, both checked finite.
pub fn state_matrix(l: &Lumped) -> Result<(Vec<f64>, DMatrix<f64>), StabilityError> {
    let z = l.equilibrium_dyn()?;
    if z.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite {
            what: "equilibrium",
        });
    }
    let a = l.jacobian_dyn(&z);
    if a.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite { what: "Jacobian" });
    }
    Ok((z, a))
}

/// All eigenvalues of the state matrix ([`super::modal::eigenvalues`]: the
/// balanced hand-written QR up to 64 states, faer above).
pub fn eigenvalues(l: &Lumped) -> Result<Vec<nalgebra::Complex<f64>>, StabilityError> {
    let (_, a) = state_matrix(l)?;
    super::modal::eigenvalues(&a)
}

/// Largest growth rate and its frequency (Hz), for maps and `critical`.
pub fn max_growth_rate(l: &Lumped) -> Result<(f64, f64), StabilityError> {
    let ev = eigenvalues(l)?;
    let mut best = nalgebra::Complex::new(f64::NEG_INFINITY, 0.0);
    for e in ev {
        if e.re > best.re || (e.re == best.re && e.im > best.im) {
            best = e;
        }
    }
    Ok((best.re, best.im.abs() / (2.0 * std::f64::consts::PI)))
}

/// Full complex eigenvalue analysis of a lumped model of any size (every
/// mode with its eigenvector, energy shares and dominant coordinate), by
/// [`super::modal::analyse_matrix`].
pub fn analyse(l: &Lumped, masses: Option<&[f64]>) -> Result<Analysis, StabilityError> {
    let (z, a) = state_matrix(l)?;
    super::modal::analyse_matrix(&a, &z, l.state_names(), masses)
}
