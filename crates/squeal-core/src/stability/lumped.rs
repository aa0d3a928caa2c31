//! Stability of lumped models of any size: the steady-sliding state by
//! Newton's method, the analytic linearisation, and the size-independent
//! complex eigen-analysis: dense ([`super::modal`]: every eigenvalue of the
//! `2n × 2n` state matrix) up to [`ModalOptions::dense_max_dofs`] dofs, by
//! projection onto the lowest undamped modes above ([`super::projected`]).
//! Models small enough for the fixed-size path
//! ([`crate::model::lumped::MAX_EXACT_DOFS`] dofs) go through
//! [`super::analyse`] instead (the same eigenvalues).
//!
//! [`ModalOptions::dense_max_dofs`]: super::projected::ModalOptions::dense_max_dofs

use super::projected::{self, Method};
use super::{Analysis, StabilityError};
use crate::model::lumped::Lumped;
use nalgebra::DMatrix;

/// Whether a model analysed by projection stays sparse: more than
/// [`crate::linear::SPARSE_FROM_DOFS`] dofs (its real modes by
/// [`super::lanczos`]).
pub fn sparse(l: &Lumped) -> bool {
    l.dof_count() > crate::linear::SPARSE_FROM_DOFS
}

/// The steady-sliding state and the state matrix there, both checked finite.
pub fn state_matrix(l: &Lumped) -> Result<(Vec<f64>, DMatrix<f64>), StabilityError> {
    let z = equilibrium(l)?;
    let a = l.jacobian_dyn(&z);
    if a.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite { what: "Jacobian" });
    }
    Ok((z, a))
}

/// The steady-sliding state, checked finite.
fn equilibrium(l: &Lumped) -> Result<Vec<f64>, StabilityError> {
    let z = l.equilibrium_dyn()?;
    if z.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite {
            what: "equilibrium",
        });
    }
    Ok(z)
}

/// The eigenvalues of steady sliding and how they were computed: every
/// eigenvalue of the state matrix ([`super::modal::eigenvalues`]: the
/// balanced hand-written QR up to 64 states, faer above) for a model of at
/// most `l.modal.dense_max_dofs` dofs, else the `2m` eigenvalues of the
/// projection onto `m` undamped modes ([`projected::projected_eigenvalues`]).
pub fn eigenvalues_with_method(
    l: &Lumped,
) -> Result<(Vec<nalgebra::Complex<f64>>, Method), StabilityError> {
    if l.modal.projects(l.dof_count()) {
        let z = equilibrium(l)?;
        if sparse(l) {
            projected::projected_eigenvalues(
                &l.second_order_sparse(&z),
                l.modal.basis(),
                l.modal.kind,
            )
        } else {
            projected::projected_eigenvalues(&l.second_order_dyn(&z), l.modal.basis(), l.modal.kind)
        }
    } else {
        let (_, a) = state_matrix(l)?;
        Ok((super::modal::eigenvalues(&a)?, Method::Dense))
    }
}

/// The eigenvalues of steady sliding ([`eigenvalues_with_method`]).
pub fn eigenvalues(l: &Lumped) -> Result<Vec<nalgebra::Complex<f64>>, StabilityError> {
    eigenvalues_with_method(l).map(|(ev, _)| ev)
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

/// The truncation table of a model analysed by projection
/// ([`projected::truncation_table`] with its `modal.*` basis); `None` for a
/// model solved dense (nothing is truncated).
pub fn truncation_table(l: &Lumped) -> Option<Result<Vec<projected::Truncation>, StabilityError>> {
    l.modal
        .projects(l.dof_count())
        .then(|| truncation_table_at(l, &equilibrium(l)?))
}

/// [`truncation_table`] at the steady-sliding state `z` already found (an
/// analysis's [`Analysis::equilibrium`]): a large model's steady sliding is
/// one sparse factorisation not worth repeating.
pub fn truncation_table_at(
    l: &Lumped,
    z: &[f64],
) -> Result<Vec<projected::Truncation>, StabilityError> {
    if sparse(l) {
        projected::truncation_table(&l.second_order_sparse(z), l.modal.basis(), l.modal.kind)
    } else {
        projected::truncation_table(&l.second_order_dyn(z), l.modal.basis(), l.modal.kind)
    }
}

/// [`analyse`] with, for a model analysed by projection, its truncation
/// table ([`projected::analyse_projected_with_table`]: the modes and static
/// responses computed once for both); `None` for a model solved dense.
#[allow(clippy::type_complexity)]
pub fn analyse_with_table(
    l: &Lumped,
    masses: Option<&[f64]>,
) -> Result<
    (
        Analysis,
        Option<Result<Vec<projected::Truncation>, StabilityError>>,
    ),
    StabilityError,
> {
    if !l.modal.projects(l.dof_count()) {
        return Ok((analyse(l, masses)?, None));
    }
    let z = equilibrium(l)?;
    let (basis, kind) = (l.modal.basis(), l.modal.kind);
    let (an, table) = if sparse(l) {
        let sys = l.second_order_sparse(&z);
        projected::analyse_projected_with_table(&sys, &z, l.state_names(), masses, basis, kind)?
    } else {
        let sys = l.second_order_dyn(&z);
        projected::analyse_projected_with_table(&sys, &z, l.state_names(), masses, basis, kind)?
    };
    Ok((an, Some(table)))
}

/// Full complex eigenvalue analysis of a lumped model of any size (every
/// mode with its eigenvector, energy shares and dominant coordinate): dense
/// by [`super::modal::analyse_matrix`] up to `l.modal.dense_max_dofs` dofs,
/// above by [`projected::analyse_projected`] ([`Analysis::method`] says which,
/// and with how many modes).
pub fn analyse(l: &Lumped, masses: Option<&[f64]>) -> Result<Analysis, StabilityError> {
    if l.modal.projects(l.dof_count()) {
        let z = equilibrium(l)?;
        let (basis, kind) = (l.modal.basis(), l.modal.kind);
        if sparse(l) {
            let sys = l.second_order_sparse(&z);
            projected::analyse_projected(&sys, &z, l.state_names(), masses, basis, kind)
        } else {
            let sys = l.second_order_dyn(&z);
            projected::analyse_projected(&sys, &z, l.state_names(), masses, basis, kind)
        }
    } else {
        let (z, a) = state_matrix(l)?;
        super::modal::analyse_matrix(&a, &z, l.state_names(), masses)
    }
}
