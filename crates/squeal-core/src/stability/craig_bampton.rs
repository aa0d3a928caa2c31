//! Craig–Bampton reduction (Craig & Bampton 1968, AIAA J. 6(7) 1313–1319):
//! the boundary dofs (those the contacts, forces and springs act on) stay
//! physical, the interior is represented by its static response to the
//! boundary (constraint modes) and its fixed-interface modes up to a
//! cut-off.
//!
//! With the dofs split into boundary `b` and interior `i`,
//!
//! ```text
//! q = T [q_b; η],   T = [[I, 0], [Ψ, Φ_i]],   Ψ = −K_ii⁻¹ K_ib,
//! K_ii φ = ω² M_ii φ   (the interior with the boundary held fixed),
//! ```
//!
//! and the reduced matrices are `Tᵀ M T`, `Tᵀ K T`, `Tᵀ C T`. The reduced
//! model is exact for static loads on the boundary (`Ψ` is the interior's
//! exact static response), exact altogether when every fixed-interface mode
//! is kept (`T` is then invertible), and converges from above in the
//! frequencies as modes are added. Because the boundary dofs keep their
//! names and meaning, a contact, force or spring written on them acts on
//! the reduced model unchanged: it can be simulated, not only analysed.
//!
//! The stiffness used for `Ψ` and `Φ_i` is the symmetric part
//! `K_s = (K + Kᵀ)/2` (an FE export's `K` is symmetric; friction, which
//! makes the linearised `K` non-symmetric, acts on the boundary). When
//! `K_ii` is singular — an interior part that the boundary does not hold,
//! such as a free disc — `Ψ` uses `K_ii + s M_ii` with `s = (2π · 1 Hz)²`,
//! as the static correction of [`super::projected`] does, and
//! [`CraigBampton::shifted`] says so.

use super::projected::undamped_basis;
use super::StabilityError;
use crate::linear::{Basis, SecondOrder};
use nalgebra::DMatrix;

/// A Craig–Bampton basis of an `n`-dof model.
#[derive(Debug, Clone)]
pub struct CraigBampton {
    /// The transformation `T` (`n × (b + m)`): column `j < b` is the
    /// constraint mode of boundary dof `boundary[j]` (1 there, 0 at the other
    /// boundary dofs, `Ψ` inside), column `b + k` the fixed-interface mode
    /// `k` (0 on the boundary, `M_ii`-normalised).
    pub t: DMatrix<f64>,
    /// The boundary dofs (indices into the model's dofs), in the order of
    /// `t`'s first columns.
    pub boundary: Vec<usize>,
    /// `ω²` (rad²/s²) of the fixed-interface modes kept, ascending.
    pub omega2: Vec<f64>,
    /// How many fixed-interface modes the interior has in all.
    pub interior_modes: usize,
    /// Whether the constraint modes needed the shift `(2π · 1 Hz)² M_ii`
    /// (a singular `K_ii`).
    pub shifted: bool,
}

impl CraigBampton {
    /// `Tᵀ A T` (the reduced matrix of `A`).
    pub fn project(&self, a: &DMatrix<f64>) -> DMatrix<f64> {
        self.t.transpose() * (a * &self.t)
    }
}

/// The Craig–Bampton basis of `(M, K)` with `boundary` kept physical and the
/// fixed-interface modes `basis` asks for (a count, or every mode up to a
/// cut-off; zero modes is allowed: a Guyan reduction). Errors: bad sizes or
/// indices, a mass matrix that is not positive definite on the interior,
/// an interior stiffness singular even with the shift.
pub fn craig_bampton(
    m: &DMatrix<f64>,
    k: &DMatrix<f64>,
    boundary: &[usize],
    basis: Basis,
) -> Result<CraigBampton, StabilityError> {
    let n = m.nrows();
    if m.ncols() != n || k.nrows() != n || k.ncols() != n {
        return Err(StabilityError::BadInput(format!(
            "M is {} × {} and K {} × {}: expected both square and equal",
            m.nrows(),
            m.ncols(),
            k.nrows(),
            k.ncols()
        )));
    }
    if m.iter().chain(k.iter()).any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite { what: "M or K" });
    }
    let mut is_b = vec![false; n];
    for &j in boundary {
        if j >= n || is_b[j] {
            return Err(StabilityError::BadInput(format!(
                "boundary dof {j} out of range or repeated ({n} dofs)"
            )));
        }
        is_b[j] = true;
    }
    let interior: Vec<usize> = (0..n).filter(|&i| !is_b[i]).collect();
    let (nb, ni) = (boundary.len(), interior.len());
    let ks = |r: usize, c: usize| 0.5 * (k[(r, c)] + k[(c, r)]);
    let kii = DMatrix::from_fn(ni, ni, |r, c| ks(interior[r], interior[c]));
    let mii = DMatrix::from_fn(ni, ni, |r, c| m[(interior[r], interior[c])]);
    let kib = DMatrix::from_fn(ni, nb, |r, c| ks(interior[r], boundary[c]));
    // Ψ = −K_ii⁻¹ K_ib, checked by its residual; with the shift if K_ii is
    // singular (a free interior part).
    let solve = |a: &DMatrix<f64>| -> Option<DMatrix<f64>> {
        let x = a.clone().lu().solve(&(-&kib))?;
        let res = (a * &x + &kib).amax();
        (x.iter().all(|v| v.is_finite()) && res <= 1e-8 * kib.amax().max(f64::MIN_POSITIVE))
            .then_some(x)
    };
    let (psi, shifted) = if ni == 0 || nb == 0 {
        (DMatrix::zeros(ni, nb), false)
    } else if let Some(x) = solve(&kii) {
        (x, false)
    } else {
        let shift = std::f64::consts::TAU.powi(2);
        let x = solve(&(&kii + &mii * shift)).ok_or_else(|| {
            StabilityError::BadInput(
                "Craig–Bampton: the interior's stiffness K_ii is singular even with a 1 Hz shift"
                    .into(),
            )
        })?;
        (x, true)
    };
    // Every fixed-interface mode (dense: the interior's own eigenproblem),
    // then the ones `basis` asks for.
    let (phi, omega2) = if ni == 0 {
        (DMatrix::zeros(0, 0), Vec::new())
    } else {
        let interior_sys = SecondOrder {
            m: mii,
            k: kii,
            c: DMatrix::zeros(ni, ni),
        };
        let all = undamped_basis(&interior_sys, Basis::Modes(ni)).map_err(|e| match e {
            StabilityError::BadInput(msg) => {
                StabilityError::BadInput(format!("Craig–Bampton, the interior: {msg}"))
            }
            other => other,
        })?;
        let phi = DMatrix::from_fn(ni, ni, |r, c| all.phi[(r, c)]);
        (phi, all.omega2)
    };
    let kept = match basis {
        Basis::Modes(c) => c.min(ni),
        Basis::CutoffHz(f) => {
            let w2 = (std::f64::consts::TAU * f).powi(2);
            omega2.iter().take_while(|&&x| x <= w2).count()
        }
    };
    let mut t = DMatrix::<f64>::zeros(n, nb + kept);
    for (c, &j) in boundary.iter().enumerate() {
        t[(j, c)] = 1.0;
        for (r, &i) in interior.iter().enumerate() {
            t[(i, c)] = psi[(r, c)];
        }
    }
    for c in 0..kept {
        for (r, &i) in interior.iter().enumerate() {
            t[(i, nb + c)] = phi[(r, c)];
        }
    }
    Ok(CraigBampton {
        t,
        boundary: boundary.to_vec(),
        omega2: omega2[..kept].to_vec(),
        interior_modes: ni,
        shifted,
    })
}

/// [`craig_bampton`] of sparse `M` and `K` (symmetric parts taken), for
/// models too large for dense matrices: `K_ii` by a sparse factorisation
/// (with the same 1 Hz shift when the interior is free), and only the
/// fixed-interface modes `basis` asks for, by block shift-invert Lanczos
/// ([`super::lanczos::lowest_modes`]). `omega2` lists those kept (not every
/// interior mode), `t` is dense `n × (boundary + kept)`.
pub fn craig_bampton_sparse(
    m: faer::sparse::SparseColMatRef<'_, usize, f64>,
    k: faer::sparse::SparseColMatRef<'_, usize, f64>,
    boundary: &[usize],
    basis: Basis,
) -> Result<CraigBampton, StabilityError> {
    use faer::sparse::{SparseColMat, Triplet};
    let n = m.nrows();
    if m.ncols() != n || k.nrows() != n || k.ncols() != n {
        return Err(StabilityError::BadInput(
            "M and K must be square and of the same size".into(),
        ));
    }
    let mut slot = vec![usize::MAX; n];
    let mut is_b = vec![false; n];
    for (c, &j) in boundary.iter().enumerate() {
        if j >= n || is_b[j] {
            return Err(StabilityError::BadInput(format!(
                "boundary dof {j} out of range or repeated ({n} dofs)"
            )));
        }
        is_b[j] = true;
        slot[j] = c;
    }
    let interior: Vec<usize> = (0..n).filter(|&i| !is_b[i]).collect();
    for (r, &i) in interior.iter().enumerate() {
        slot[i] = r;
    }
    let (nb, ni) = (boundary.len(), interior.len());
    // The interior blocks of M and K_s = (K + Kᵀ)/2, and K_ib (dense, ni × nb).
    let (mut mt, mut kt) = (Vec::new(), Vec::new());
    let mut kib = faer::Mat::<f64>::zeros(ni, nb);
    for j in 0..n {
        for (i, &v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            if !v.is_finite() {
                return Err(StabilityError::NonFinite { what: "M or K" });
            }
            if !is_b[i] && !is_b[j] {
                mt.push(Triplet::new(slot[i], slot[j], v));
            }
        }
        for (i, &v) in k.row_idx_of_col(j).zip(k.val_of_col(j)) {
            if !v.is_finite() {
                return Err(StabilityError::NonFinite { what: "M or K" });
            }
            for (r, c) in [(i, j), (j, i)] {
                match (is_b[r], is_b[c]) {
                    (false, false) => kt.push(Triplet::new(slot[r], slot[c], 0.5 * v)),
                    (false, true) => kib[(slot[r], slot[c])] += 0.5 * v,
                    _ => {}
                }
            }
        }
    }
    let bad = |_| StabilityError::BadInput("Craig–Bampton: cannot assemble the interior".into());
    let mii = SparseColMat::<usize, f64>::try_new_from_triplets(ni, ni, &mt).map_err(bad)?;
    let kii = SparseColMat::<usize, f64>::try_new_from_triplets(ni, ni, &kt).map_err(bad)?;
    let rhs = -&kib;
    let scale = kib
        .col_iter()
        .flat_map(|c| c.iter().copied())
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    // Ψ = −K_ii⁻¹ K_ib, checked by its residual; shifted if K_ii is singular.
    let attempt = |s: f64| -> Option<faer::Mat<f64>> {
        let x = super::lanczos::shifted_solve(kii.as_ref(), mii.as_ref(), s, rhs.as_ref()).ok()?;
        let mut res = super::lanczos::sparse_mul(kii.as_ref(), x.as_ref());
        res += &kib;
        let r = res
            .col_iter()
            .flat_map(|c| c.iter().copied())
            .fold(0.0f64, |a, v| a.max(v.abs()));
        (x.col_iter().all(|c| c.iter().all(|v| v.is_finite())) && r <= 1e-8 * scale).then_some(x)
    };
    let (psi, shifted) = if ni == 0 || nb == 0 {
        (faer::Mat::<f64>::zeros(ni, nb), false)
    } else if let Some(x) = attempt(0.0) {
        (x, false)
    } else {
        let x = super::lanczos::shifted_solve(
            kii.as_ref(),
            mii.as_ref(),
            std::f64::consts::TAU.powi(2),
            rhs.as_ref(),
        )
        .map_err(|_| {
            StabilityError::BadInput(
                "Craig–Bampton: the interior's stiffness K_ii is singular even with a 1 Hz shift"
                    .into(),
            )
        })?;
        (x, true)
    };
    let modes = if ni == 0 {
        None
    } else {
        Some(
            super::lanczos::lowest_modes(kii.as_ref(), mii.as_ref(), basis).map_err(
                |e| match e {
                    StabilityError::BadInput(msg) => {
                        StabilityError::BadInput(format!("Craig–Bampton, the interior: {msg}"))
                    }
                    other => other,
                },
            )?,
        )
    };
    let kept = modes.as_ref().map_or(0, |b| b.omega2.len());
    let mut t = DMatrix::<f64>::zeros(n, nb + kept);
    for (c, &j) in boundary.iter().enumerate() {
        t[(j, c)] = 1.0;
        for (r, &i) in interior.iter().enumerate() {
            t[(i, c)] = psi[(r, c)];
        }
    }
    if let Some(b) = &modes {
        for c in 0..kept {
            for (r, &i) in interior.iter().enumerate() {
                t[(i, nb + c)] = b.phi[(r, c)];
            }
        }
    }
    Ok(CraigBampton {
        t,
        boundary: boundary.to_vec(),
        omega2: modes.map_or_else(Vec::new, |b| b.omega2),
        interior_modes: ni,
        shifted,
    })
}

impl CraigBampton {
    /// `Tᵀ A T` for a sparse `A`.
    pub fn project_sparse(&self, a: faer::sparse::SparseColMatRef<'_, usize, f64>) -> DMatrix<f64> {
        let (n, r) = (self.t.nrows(), self.t.ncols());
        let t = faer::MatRef::from_column_major_slice(self.t.as_slice(), n, r);
        let at = super::lanczos::sparse_mul(a, t);
        let out = t.transpose() * &at;
        DMatrix::from_fn(r, r, |i, j| out[(i, j)])
    }
}
