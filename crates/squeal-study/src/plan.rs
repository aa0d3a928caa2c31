//! What a long command will compute, stated before it starts (issue 27 §1):
//! for a lumped model above [`PLAN_FROM_DOFS`] dofs — an FE model — one line
//! with its size, the nonzeros of its matrix files, how its eigenvalues are
//! computed (dense, or projected onto which basis) and the memory that
//! takes, so that a user sees a 10⁴-dof request for what it is before
//! waiting on it.

use crate::model::AnyModel;
use crate::scenario::Scenario;
use squeal_core::linear::{Basis, BasisKind};

/// Models of more dofs than this (the largest a run simulates) get a plan
/// line; the small models answer at once.
pub const PLAN_FROM_DOFS: usize = 64;

/// The plan line of `command` on `sc`, repeated over `points` analyses
/// (`1` for one), or `None` for a small or built-in model.
pub fn plan(sc: &Scenario, command: &str, points: usize) -> Option<String> {
    let AnyModel::Lumped(l) = &sc.model else {
        return None;
    };
    let n = l.dof_count();
    if n <= PLAN_FROM_DOFS {
        return None;
    }
    let files: Vec<String> = sc
        .matrices
        .info
        .iter()
        .map(|i| format!("{} {} nonzeros", i.key, i.nonzeros))
        .collect();
    let files = if files.is_empty() {
        String::new()
    } else {
        format!(" ({})", files.join(", "))
    };
    let basis = match l.modal.basis() {
        Basis::Modes(m) => format!("the {m} lowest"),
        Basis::CutoffHz(f) => format!("those up to {f} Hz"),
    };
    let method = if !l.modal.projects(n) {
        format!(
            "steady sliding, then the dense complex eigenvalue problem of {} states",
            2 * n
        )
    } else {
        match l.modal.kind {
            BasisKind::Modes if n > squeal_core::linear::SPARSE_FROM_DOFS => format!(
                "steady sliding, the real modes {basis} by sparse block shift-invert Lanczos, kept with the static correction at the contact dofs, then the projected complex eigenproblem"
            ),
            BasisKind::Modes => format!(
                "steady sliding, the real modes of all {n} dofs (a dense symmetric eigen-solve), {basis} kept with the static correction at the contact dofs, then the projected complex eigenproblem"
            ),
            BasisKind::CraigBampton => format!(
                "steady sliding, the fixed-interface modes of the interior (a dense symmetric eigen-solve), {basis} kept with the contact dofs physical (Craig–Bampton), then the projected complex eigenproblem"
            ),
        }
    };
    let nonzeros = sc.matrices.info.iter().map(|i| i.nonzeros).sum();
    let mb = crate::memory::analysis_bytes(n, nonzeros).0 / 1e6;
    let times = if points > 1 {
        format!(", {points} times")
    } else {
        String::new()
    };
    Some(format!(
        "{command}: {}: {n} dofs{files}; {method}{times}; up to {mb:.0} MB",
        sc.name
    ))
}
