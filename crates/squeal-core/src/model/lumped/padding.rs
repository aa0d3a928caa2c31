//! Simulating lumped models larger than the sizes compiled exactly.
//!
//! The integrator works on fixed-size state arrays (`[f64; N]`), compiled
//! once per size. Models of up to [`MAX_EXACT_DOFS`] dofs get their own size;
//! a larger one (up to [`MAX_SIM_DOFS`](super::MAX_SIM_DOFS)) runs in the next of a few padded
//! sizes ([`PADDED_DOFS`]): the model gains *idle* dofs — unit mass on a unit
//! spring to ground, coupled to nothing, starting at rest — that stay
//! exactly zero (their force `−1·0` is zero in floating point), so the real
//! dofs move exactly as without them.
//!
//! The error norm would see the padding: DOP853 measures a step's error as
//! an RMS over the states, `‖e‖ = √(Σ (e_i/sc_i)² / n)` with
//! `sc_i = atol_i + rtol·|z_i|`. The idle states add exactly zero to the
//! sum, and the padded model reports its real state count as `n`
//! ([`System::norm_states`](crate::model::System::norm_states)), so a padded
//! run takes the very steps of the unpadded one, bit for bit.
//!
//! Transient runs (not limit cycles) of still larger models, up to
//! [`MAX_TRANSIENT_DOFS`](super::MAX_TRANSIENT_DOFS), run in one of
//! [`TRANSIENT_PADDED_DOFS`] the same way ([`with_transient_padded_size!`](crate::with_transient_padded_size)):
//! a reduced FE brake of a few hundred generalised dofs. Its cost per step
//! is the real model's force evaluation (the sparse or dense `K`, `C` of its
//! own size: the idle rows are empty) plus `O(N)` vector work per stage on
//! the padded size.
//!
//! Simulation and limit cycles run padded. An eigen-analysis of the padded
//! model would add the idle dofs' modes (±i rad/s), so stability uses the
//! size-independent paths or the exact sizes; the Floquet analysis of
//! the cycle module covers the real states only (the monodromy matrix is
//! block-diagonal, its real block the real model's).

use super::{Combination, Lumped, Sparse, Spring};
use crate::solver_options::{SolverOptions, MAX_STATES};

/// Largest model (dofs) compiled at its exact state count.
pub const MAX_EXACT_DOFS: usize = 16;

/// The padded sizes (dofs) a larger model runs in, smallest first.
pub const PADDED_DOFS: [usize; 6] = [24, 32, 48, 64, 96, 128];

/// The larger padded sizes (dofs) for transient runs only (`simulate`,
/// `listen`, `map --transient`), smallest first: above [`PADDED_DOFS`]'s
/// last, up to [`MAX_TRANSIENT_DOFS`](super::MAX_TRANSIENT_DOFS). Limit
/// cycles stop at [`MAX_SIM_DOFS`](super::MAX_SIM_DOFS): their Floquet
/// analysis costs the cube of the state count per step.
pub const TRANSIENT_PADDED_DOFS: [usize; 4] = [192, 256, 384, 512];

/// Prefix of the idle dofs' names (`pad.1`, …): a `.` is not allowed in a
/// user's dof name, so they never collide.
pub const IDLE_PREFIX: &str = "pad.";

/// The padded size (dofs) a model of `dofs` dofs is simulated in: `None` if it
/// has an exact size (≤ [`MAX_EXACT_DOFS`]) or is too large (> [`MAX_SIM_DOFS`](super::MAX_SIM_DOFS)).
pub fn padded_dofs(dofs: usize) -> Option<usize> {
    if dofs <= MAX_EXACT_DOFS {
        return None;
    }
    PADDED_DOFS.iter().copied().find(|&p| p >= dofs)
}

/// The padded size (dofs) a transient run of a model of `dofs` dofs takes
/// when it is larger than [`MAX_SIM_DOFS`](super::MAX_SIM_DOFS): `None` if
/// it is not, or is too large (> [`MAX_TRANSIENT_DOFS`](super::MAX_TRANSIENT_DOFS)).
pub fn transient_padded_dofs(dofs: usize) -> Option<usize> {
    if dofs <= super::MAX_SIM_DOFS {
        return None;
    }
    TRANSIENT_PADDED_DOFS.iter().copied().find(|&p| p >= dofs)
}

impl Sparse {
    /// The same matrix as a `size × size` one (empty rows added).
    fn grown(&self, size: usize) -> Sparse {
        let mut s = self.clone();
        let end = *s.row_ptr.last().unwrap_or(&0);
        s.row_ptr.resize(size + 1, end);
        s.n = size;
        s
    }
}

impl Lumped {
    /// This model with idle dofs appended up to `dofs` (see the module docs):
    /// state order `q_real, q_idle, q̇_real, q̇_idle`. The real dofs keep their
    /// indices; elements, contacts and parameters are unchanged.
    pub fn padded_to(&self, dofs: usize) -> Lumped {
        let n = self.dofs.len();
        let mut p = self.clone();
        for k in n..dofs {
            let name = format!("{IDLE_PREFIX}{}", k - n + 1);
            p.springs.push(Spring {
                name: name.clone(),
                on: Combination {
                    idx: vec![k],
                    coef: vec![1.0],
                },
                k: 1.0,
                c: 0.0,
                k3: 0.0,
            });
            p.dofs.push(name);
            p.masses.push(1.0);
        }
        for m in [&mut p.m_matrix, &mut p.k_matrix, &mut p.c_matrix]
            .into_iter()
            .flatten()
        {
            *m = m.grown(dofs);
        }
        p.states = p
            .dofs
            .iter()
            .cloned()
            .chain(p.dofs.iter().map(|d| format!("v{d}")))
            .collect();
        // The real model passed these checks; the idle dofs add a diagonal unit mass.
        p.refresh()
            .expect("padding adds only unit masses and springs to a valid model");
        p
    }
}

/// A real state vector (`q, q̇` of `n` dofs) placed in a padded one of `N`
/// states (`q_real, 0, q̇_real, 0`).
pub fn embed<const N: usize>(real: &[f64]) -> [f64; N] {
    let n = real.len() / 2;
    let mut z = [0.0; N];
    z[..n].copy_from_slice(&real[..n]);
    z[N / 2..N / 2 + n].copy_from_slice(&real[n..]);
    z
}

/// Indices, in a padded state of `N` states, of the `2·n` real states (in order).
pub fn real_states<const N: usize>(n: usize) -> impl Iterator<Item = usize> {
    (0..n).chain(N / 2..N / 2 + n)
}

/// The solver options for a padded run of `N` states whose real state count
/// is `real`: the per-state tolerances (`atol_state`, indexed by real state)
/// moved to the padded indices. Unchanged when `real == N`.
pub fn padded_solver<const N: usize>(opts: &SolverOptions, real: usize) -> SolverOptions {
    if real >= N {
        return *opts;
    }
    let n = real / 2;
    let mut o = *opts;
    o.atol_state = [None; MAX_STATES];
    for (i, a) in opts.atol_state.iter().enumerate() {
        let padded = if i < n { i } else { N / 2 + i - n };
        if let (Some(a), Some(slot)) = (a, o.atol_state.get_mut(padded)) {
            *slot = Some(*a);
        }
    }
    o
}

impl Lumped {
    /// The real (not idle) state count: `2·dofs` for a model that is not padded.
    pub(super) fn real_state_count(&self) -> usize {
        2 * self
            .dofs
            .iter()
            .filter(|d| !d.starts_with(IDLE_PREFIX))
            .count()
    }
}

/// The padded-size dispatch behind [`with_padded_size!`](crate::with_padded_size)
/// and [`with_transient_padded_size!`](crate::with_transient_padded_size):
/// `$choose(dofs)` picks one of the listed `(dofs, states)` sizes.
#[doc(hidden)]
#[macro_export]
macro_rules! __with_padding {
    ($l:expr, $choose:path, [$(($dofs:literal, $states:literal)),+], $m:ident => $body:expr, else => $fallback:expr) => {{
        use $crate::model::lumped::Fixed;
        let l: &$crate::Lumped = $l;
        match $choose(l.dof_count()) {
            $(Some($dofs) => {
                let p = l.padded_to($dofs);
                let $m = &Fixed::<$states>(&p);
                $body
            })+
            _ => $fallback,
        }
    }};
}

/// Run `$body` with `$m` bound to `&Fixed<N>` of the lumped model `$l`
/// padded to the next of [`PADDED_DOFS`] (models of more than
/// [`MAX_EXACT_DOFS`] and at most [`MAX_SIM_DOFS`](super::MAX_SIM_DOFS) dofs;
/// simulation only, see the module docs), or evaluate `$fallback`.
#[macro_export]
macro_rules! with_padded_size {
    ($l:expr, $m:ident => $body:expr, else => $fallback:expr) => {
        $crate::__with_padding!($l, $crate::model::lumped::padded_dofs,
            [(24, 48), (32, 64), (48, 96), (64, 128), (96, 192), (128, 256)],
            $m => $body, else => $fallback)
    };
}

/// Run `$body` with `$m` bound to `&Fixed<N>` of the lumped model `$l`
/// padded to the next of [`TRANSIENT_PADDED_DOFS`] (models of more than
/// [`MAX_SIM_DOFS`](super::MAX_SIM_DOFS) and at most
/// [`MAX_TRANSIENT_DOFS`](super::MAX_TRANSIENT_DOFS) dofs; transient runs
/// only, see the module docs), or evaluate `$fallback`.
#[macro_export]
macro_rules! with_transient_padded_size {
    ($l:expr, $m:ident => $body:expr, else => $fallback:expr) => {
        $crate::__with_padding!($l, $crate::model::lumped::transient_padded_dofs,
            [(192, 384), (256, 512), (384, 768), (512, 1024)],
            $m => $body, else => $fallback)
    };
}
