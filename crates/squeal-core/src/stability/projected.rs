//! Complex eigenvalue analysis of large models by projection onto their
//! undamped modes — what FE packages do in a "complex frequency" step
//! (e.g. Abaqus `*COMPLEX FREQUENCY` after `*FREQUENCY`).
//!
//! The linearised equations of steady sliding are second order,
//!
//! ```text
//! M q̈ + C q̇ + K q = 0,
//! ```
//!
//! with `M` symmetric positive definite and `K`, `C` non-symmetric (friction
//! couples the normal and tangential motion one way only, and `μ'(v)` adds
//! negative damping). A dense eigen-solve of the `2n × 2n` state matrix costs
//! ≈ 25 (2n)³ flops, over a minute for 2000 dofs. The projected method:
//!
//! 1. solves the real **symmetric** generalised problem
//!    `K_s φ = ω² M φ` with `K_s = (K + Kᵀ)/2` (Cholesky `M = L Lᵀ`, then
//!    faer's self-adjoint eigendecomposition of `L⁻¹ K_s L⁻ᵀ`; ≈ 9 n³ flops
//!    for all of them, a few seconds for n = 2000), modes `M`-orthonormal;
//! 2. keeps the `m` lowest of them, `Φ = [φ_1 … φ_m]` ([`Basis`]: a count,
//!    or every mode up to a cut-off frequency, by default
//!    [`CUTOFF_FACTOR`] × [`BAND_HZ`]);
//! 3. projects the **full** non-symmetric stiffness and damping onto them,
//!    `K_r = Φᵀ K Φ`, `C_r = Φᵀ C Φ` (`Φᵀ M Φ = I`), and solves the small
//!    complex problem `λ² y + λ C_r y + K_r y = 0` as a `2m × 2m` state
//!    matrix ([`super::modal::eigenpairs`]);
//! 4. maps each eigenvector back to the physical dofs, `q = Φ y`, state
//!    `(q, λ q)`.
//!
//! It is a reduced-basis (Rayleigh–Ritz) answer: the `2m` eigenvalues
//! approximate the system's modes in the band of the basis, best well below
//! its highest frequency; modes above the cut-off are not computed at all.
//! With `m = n` the basis is complete and the answer equals the dense one to
//! round-off (`Φ` is then an invertible change of coordinates).

use super::modal::{describe, eigenpairs, eigenvalues, finish};
use super::{Analysis, StabilityError};
use nalgebra::{Complex, DMatrix};
use serde::Serialize;

pub use crate::linear::{
    Basis, BasisKind, ModalOptions, SecondOrder, SparseSecondOrder, BAND_HZ, CUTOFF_FACTOR,
    DEFAULT_DENSE_MAX_DOFS, SPARSE_FROM_DOFS,
};
use faer::{Mat, MatRef};

/// Which matrix of a [`Structure`] a product is with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The mass matrix.
    M,
    /// The stiffness, non-symmetric where friction acts.
    K,
    /// The damping.
    C,
    /// The symmetric part of the stiffness, `K_s = (K + Kᵀ)/2`.
    Ks,
}

/// What the projection needs of a linearised system: products with its
/// matrices, a shifted static solve, the dofs where it is non-symmetric and
/// its real modes. [`SecondOrder`] does it densely (every real mode by a
/// dense symmetric eigen-solve), [`SparseSecondOrder`] sparsely (a sparse
/// factorisation and [`super::lanczos`]), so one projection serves both.
pub trait Structure {
    /// Number of dofs.
    fn dofs(&self) -> usize;
    /// `X V` for the matrix `part` (`n × cols`).
    fn mul(&self, part: Part, v: MatRef<'_, f64>) -> Mat<f64>;
    /// `(K_s + s M)⁻¹ B`.
    fn shifted_solve(&self, s: f64, b: MatRef<'_, f64>) -> Result<Mat<f64>, StabilityError>;
    /// The dofs where `K ≠ Kᵀ` or `C ≠ Cᵀ` beyond round-off: the friction
    /// contacts' dofs ([`coupling_dofs`]).
    fn coupling_dofs(&self) -> Vec<usize>;
    /// The undamped modes `K_s φ = ω² M φ` that `basis` asks for,
    /// `M`-orthonormal, ascending.
    fn undamped(&self, basis: Basis) -> Result<UndampedBasis, StabilityError>;
    /// Sizes consistent and every entry finite; the number of dofs.
    fn validate(&self) -> Result<usize, StabilityError>;
    /// The system with dense matrices (Craig–Bampton works densely).
    fn dense(&self) -> std::borrow::Cow<'_, SecondOrder>;
}

impl Structure for SecondOrder {
    fn dofs(&self) -> usize {
        self.m.nrows()
    }
    fn mul(&self, part: Part, v: MatRef<'_, f64>) -> Mat<f64> {
        use faer::linalg::matmul::matmul;
        use faer::{Accum, Par};
        let n = self.m.nrows();
        fn view(a: &DMatrix<f64>, n: usize) -> faer::MatRef<'_, f64> {
            faer::MatRef::from_column_major_slice(a.as_slice(), n, n)
        }
        let mut out = Mat::<f64>::zeros(n, v.ncols());
        match part {
            Part::Ks => {
                let k = view(&self.k, n);
                matmul(out.as_mut(), Accum::Replace, k, v, 0.5, Par::Seq);
                matmul(out.as_mut(), Accum::Add, k.transpose(), v, 0.5, Par::Seq);
            }
            _ => {
                let a = match part {
                    Part::M => &self.m,
                    Part::K => &self.k,
                    _ => &self.c,
                };
                matmul(out.as_mut(), Accum::Replace, view(a, n), v, 1.0, Par::Seq);
            }
        }
        out
    }
    fn shifted_solve(&self, s: f64, b: MatRef<'_, f64>) -> Result<Mat<f64>, StabilityError> {
        use faer::linalg::solvers::Solve;
        let n = self.m.nrows();
        let lu = Mat::<f64>::from_fn(n, n, |i, j| {
            0.5 * (self.k[(i, j)] + self.k[(j, i)]) + s * self.m[(i, j)]
        })
        .partial_piv_lu();
        Ok(lu.solve(b))
    }
    fn coupling_dofs(&self) -> Vec<usize> {
        coupling_dofs(self)
    }
    fn undamped(&self, basis: Basis) -> Result<UndampedBasis, StabilityError> {
        undamped_basis(self, basis)
    }
    fn validate(&self) -> Result<usize, StabilityError> {
        check(self)
    }
    fn dense(&self) -> std::borrow::Cow<'_, SecondOrder> {
        std::borrow::Cow::Borrowed(self)
    }
}

impl SparseSecondOrder {
    /// `K_s = (K + Kᵀ)/2`, sparse.
    pub fn symmetric_stiffness(&self) -> faer::sparse::SparseColMat<usize, f64> {
        let kt = self
            .k
            .as_ref()
            .transpose()
            .to_col_major()
            .expect("memory for Kᵀ");
        faer::sparse::ops::binary_op(self.k.as_ref(), kt.as_ref(), |a, b| {
            0.5 * (a.copied().unwrap_or(0.0) + b.copied().unwrap_or(0.0))
        })
        .expect("memory for K_s")
    }
}

impl Structure for SparseSecondOrder {
    fn dofs(&self) -> usize {
        SparseSecondOrder::dofs(self)
    }
    fn mul(&self, part: Part, v: MatRef<'_, f64>) -> Mat<f64> {
        use super::lanczos::sparse_mul;
        match part {
            Part::M => sparse_mul(self.m.as_ref(), v),
            Part::K => sparse_mul(self.k.as_ref(), v),
            Part::C => sparse_mul(self.c.as_ref(), v),
            Part::Ks => {
                let mut out = sparse_mul(self.k.as_ref(), v);
                faer::sparse::linalg::matmul::sparse_dense_matmul(
                    out.as_mut(),
                    faer::Accum::Add,
                    self.k.as_ref().transpose(),
                    v,
                    1.0,
                    faer::Par::Seq,
                );
                out * faer::Scale(0.5)
            }
        }
    }
    fn shifted_solve(&self, s: f64, b: MatRef<'_, f64>) -> Result<Mat<f64>, StabilityError> {
        super::lanczos::shifted_solve(self.symmetric_stiffness().as_ref(), self.m.as_ref(), s, b)
    }
    fn coupling_dofs(&self) -> Vec<usize> {
        let n = self.dofs();
        let mut on = vec![false; n];
        for a in [&self.k, &self.c] {
            let scale = a.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let tol = 1e-12 * scale;
            let at = a.as_ref().transpose().to_col_major().expect("allocation");
            // Entries of A − Aᵀ: merge each column of A with the same column of Aᵀ.
            for j in 0..n {
                let mut x: Vec<(usize, f64)> = a
                    .row_idx_of_col(j)
                    .zip(a.val_of_col(j))
                    .map(|(i, v)| (i, *v))
                    .collect();
                x.extend(
                    at.row_idx_of_col(j)
                        .zip(at.val_of_col(j))
                        .map(|(i, v)| (i, -*v)),
                );
                x.sort_by_key(|e| e.0);
                let mut k = 0;
                while k < x.len() {
                    let (i, mut d) = x[k];
                    k += 1;
                    while k < x.len() && x[k].0 == i {
                        d += x[k].1;
                        k += 1;
                    }
                    if i != j && d.abs() > tol {
                        on[i] = true;
                        on[j] = true;
                    }
                }
            }
        }
        (0..n).filter(|&i| on[i]).collect()
    }
    fn undamped(&self, basis: Basis) -> Result<UndampedBasis, StabilityError> {
        super::lanczos::lowest_modes(self.symmetric_stiffness().as_ref(), self.m.as_ref(), basis)
    }
    fn validate(&self) -> Result<usize, StabilityError> {
        let n = self.dofs();
        for (name, a) in [("M", &self.m), ("K", &self.k), ("C", &self.c)] {
            if a.nrows() != n || a.ncols() != n {
                return Err(StabilityError::BadInput(format!(
                    "{name} is {} × {}, expected {n} × {n}",
                    a.nrows(),
                    a.ncols()
                )));
            }
            if a.val().iter().any(|x| !x.is_finite()) {
                return Err(StabilityError::NonFinite { what: "Jacobian" });
            }
        }
        if n == 0 {
            return Err(StabilityError::BadInput("the model has no dofs".into()));
        }
        Ok(n)
    }
    fn dense(&self) -> std::borrow::Cow<'_, SecondOrder> {
        std::borrow::Cow::Owned(self.to_dense())
    }
}

/// How an [`Analysis`] was computed (reported with it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum Method {
    /// Every eigenvalue of the full state matrix.
    #[default]
    Dense,
    /// Projection onto `modes` undamped modes of a `dofs`-dof model, the
    /// highest at `basis_max_hz`: a reduced-basis answer for the modes in
    /// that band.
    Projected {
        /// Number of undamped modes kept (`m`).
        modes: usize,
        /// Number of dofs of the model (`n`).
        dofs: usize,
        /// Undamped frequency of the highest mode kept (Hz).
        basis_max_hz: f64,
        /// Static-correction vectors added at the contact dofs
        /// ([`with_static_correction`]); for a Craig–Bampton basis, the
        /// contact dofs kept physical.
        static_vectors: usize,
        /// What spans the basis (`modal.basis`); `modes` then counts the
        /// fixed-interface modes of a Craig–Bampton basis.
        basis: BasisKind,
        /// The sparse Lanczos path's Sturm-sequence count of the undamped
        /// modes below the basis's top (equal to `modes`: none was missed);
        /// absent where every mode was computed by a dense solve.
        #[serde(skip_serializing_if = "Option::is_none")]
        sturm_count: Option<usize>,
    },
}

/// An `M`-orthonormal basis of undamped modes: `Φ` (`n × m`, column `i` is
/// `φ_i`) and `ω_i²`, ascending; after
/// [`with_static_correction`], followed by the static-correction vectors
/// (`static_vectors` columns, `M`-orthonormal to the modes and diagonal in
/// `K_s`, their Ritz values in `omega2`).
#[derive(Debug, Clone)]
pub struct UndampedBasis {
    /// The modes, column-major `n × m`.
    pub phi: faer::Mat<f64>,
    /// Their `ω²` (rad²/s²), ascending over the modes.
    pub omega2: Vec<f64>,
    /// How many of the last columns are static-correction vectors.
    pub static_vectors: usize,
    /// For a sparse Lanczos basis: the modes kept, when a Sturm-sequence
    /// count (the inertia of `K_s − μM`, [`super::lanczos::count_below`])
    /// confirmed that none below the highest kept was missed; `None` where
    /// every mode was computed (dense solves) or no gap allowed the count.
    pub sturm_count: Option<usize>,
}

/// The dofs where the linearised coupling is non-symmetric, `K ≠ Kᵀ` or
/// `C ≠ Cᵀ` beyond round-off: the dofs of the friction contacts (the
/// follower and friction forces act there).
pub fn coupling_dofs(sys: &SecondOrder) -> Vec<usize> {
    let n = sys.m.nrows();
    let scale = |a: &DMatrix<f64>| a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut on = vec![false; n];
    for a in [&sys.k, &sys.c] {
        let tol = 1e-12 * scale(a);
        for j in 0..n {
            for i in 0..j {
                if (a[(i, j)] - a[(j, i)]).abs() > tol {
                    on[i] = true;
                    on[j] = true;
                }
            }
        }
    }
    (0..n).filter(|&i| on[i]).collect()
}

/// The basis `b` augmented by the static correction at `dofs` (residual
/// flexibility; modal truncation augmentation, Dickens, Nakagawa & Wittbrodt
/// 1997, Comput. Struct. 62; what Nastran's `RESVEC` adds): the static
/// responses `(K_s + s M)⁻¹ e_j` to a unit load at each dof `j`, with a
/// small shift `s = (2π · 1 Hz)²` that keeps a free (rigid-body) structure
/// regular, `M`-orthogonalised against the modes and each other (twice;
/// responses the basis already holds are dropped), then diagonalised in
/// `K_s` (Rayleigh–Ritz). The reduced model then represents static loads at
/// those dofs exactly up to the shift: a truncated basis of modes alone
/// cannot (a contact's stiffness coupling deforms the structure locally).
pub fn with_static_correction<S: Structure + ?Sized>(
    sys: &S,
    b: UndampedBasis,
    dofs: &[usize],
) -> Result<UndampedBasis, StabilityError> {
    if dofs.is_empty() || b.phi.ncols() >= sys.dofs() {
        return Ok(b);
    }
    augment(sys, b, &static_responses(sys, dofs)?)
}

/// The shifted static responses `(K_s + s M)⁻¹ e_j` to unit loads at
/// `dofs` (`n × dofs.len()`), `s = (2π · 1 Hz)²` ([`with_static_correction`]).
fn static_responses<S: Structure + ?Sized>(
    sys: &S,
    dofs: &[usize],
) -> Result<faer::Mat<f64>, StabilityError> {
    let shift = (2.0 * std::f64::consts::PI).powi(2);
    let mut e = Mat::<f64>::zeros(sys.dofs(), dofs.len());
    for (c, &j) in dofs.iter().enumerate() {
        e[(j, c)] = 1.0;
    }
    sys.shifted_solve(shift, e.as_ref())
}

/// `b` augmented by the static responses `r` (columns), `M`-orthogonalised
/// against the modes and each other and diagonalised in `K_s`
/// ([`with_static_correction`]).
fn augment<S: Structure + ?Sized>(
    sys: &S,
    b: UndampedBasis,
    r: &faer::Mat<f64>,
) -> Result<UndampedBasis, StabilityError> {
    use faer::linalg::matmul::matmul;
    use faer::{Accum, Par};
    let n = sys.dofs();
    let m = b.phi.ncols();
    if m >= n || r.ncols() == 0 {
        return Ok(b);
    }
    // `M`-orthogonalise each response against the modes and the responses
    // kept so far (twice: classical Gram–Schmidt by blocks, the modes'
    // `M Φ` computed once).
    let mphi = sys.mul(Part::M, b.phi.as_ref());
    let mut kept = Mat::<f64>::zeros(n, 0);
    let mut mkept = Mat::<f64>::zeros(n, 0);
    for c in 0..r.ncols() {
        let mut v = r.as_ref().subcols(c, 1).to_owned();
        if v.col(0).iter().any(|x| !x.is_finite()) {
            continue;
        }
        let norm0 = m_norm(sys, &v);
        for _ in 0..2 {
            for (basis, mbasis) in [(&b.phi, &mphi), (&kept, &mkept)] {
                if basis.ncols() == 0 {
                    continue;
                }
                let coef = mbasis.transpose() * &v;
                matmul(
                    v.as_mut(),
                    Accum::Add,
                    basis.as_ref(),
                    coef.as_ref(),
                    -1.0,
                    Par::Seq,
                );
            }
        }
        let norm = m_norm(sys, &v);
        if norm > 1e-8 * norm0 && norm.is_finite() {
            v *= faer::Scale(1.0 / norm);
            let mv = sys.mul(Part::M, v.as_ref());
            kept = concat(&kept, &v);
            mkept = concat(&mkept, &mv);
        }
    }
    let r = kept.ncols();
    if r == 0 {
        return Ok(b);
    }
    // Rayleigh–Ritz in the static block: Rᵀ K_s R = W Λ Wᵀ (the block is
    // K_s-orthogonal to the modes, which are eigenvectors).
    let ksr = sys.mul(Part::Ks, kept.as_ref());
    let small = kept.transpose() * &ksr;
    let small = Mat::<f64>::from_fn(r, r, |i, j| 0.5 * (small[(i, j)] + small[(j, i)]));
    let (values, w) = super::lanczos::symmetric_eigen(small.as_ref())?;
    let rot = &kept * &w;
    let phi = concat(&b.phi, &rot);
    let mut omega2 = b.omega2;
    omega2.extend(values);
    Ok(UndampedBasis {
        phi,
        omega2,
        static_vectors: r,
        sturm_count: b.sturm_count,
    })
}

/// `√(vᵀ M v)` of one column.
fn m_norm<S: Structure + ?Sized>(sys: &S, v: &Mat<f64>) -> f64 {
    let mv = sys.mul(Part::M, v.as_ref());
    (0..v.nrows())
        .map(|i| v[(i, 0)] * mv[(i, 0)])
        .sum::<f64>()
        .max(0.0)
        .sqrt()
}

/// `[a b]`, side by side.
fn concat(a: &Mat<f64>, b: &Mat<f64>) -> Mat<f64> {
    let (ca, cb) = (a.ncols(), b.ncols());
    Mat::from_fn(a.nrows().max(b.nrows()), ca + cb, |i, j| {
        if j < ca {
            a[(i, j)]
        } else {
            b[(i, j - ca)]
        }
    })
}

fn to_faer(a: &DMatrix<f64>) -> faer::Mat<f64> {
    faer::Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)])
}

fn check(sys: &SecondOrder) -> Result<usize, StabilityError> {
    let n = sys.m.nrows();
    for (name, a) in [("M", &sys.m), ("K", &sys.k), ("C", &sys.c)] {
        if a.nrows() != n || a.ncols() != n {
            return Err(StabilityError::BadInput(format!(
                "{name} is {} × {}, expected {n} × {n}",
                a.nrows(),
                a.ncols()
            )));
        }
        if a.iter().any(|x| !x.is_finite()) {
            return Err(StabilityError::NonFinite { what: "Jacobian" });
        }
    }
    if n == 0 {
        return Err(StabilityError::BadInput("the model has no dofs".into()));
    }
    Ok(n)
}

/// The undamped modes `K_s φ = ω² M φ`, `K_s = (K + Kᵀ)/2`, that `basis`
/// asks for (see the module docs). Errors: a mass matrix that is not
/// positive definite, an empty basis (no mode below the cut-off), a
/// non-converging eigen-solver.
pub fn undamped_basis(sys: &SecondOrder, basis: Basis) -> Result<UndampedBasis, StabilityError> {
    use faer::linalg::triangular_solve as tri;
    use faer::{Mat, Par, Side};
    let n = check(sys)?;
    let par = Par::Seq;
    let mut a = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (sys.k[(i, j)] + sys.k[(j, i)]));
    let diagonal = (0..n).all(|j| (0..n).all(|i| i == j || sys.m[(i, j)] == 0.0))
        && (0..n).all(|i| sys.m[(i, i)] > 0.0);
    // `A ← L⁻¹ K_s L⁻ᵀ`, and later `Φ = L⁻ᵀ Ψ`.
    let llt = if diagonal {
        let d: Vec<f64> = (0..n).map(|i| 1.0 / sys.m[(i, i)].sqrt()).collect();
        for j in 0..n {
            for i in 0..n {
                a[(i, j)] *= d[i] * d[j];
            }
        }
        Err(d)
    } else {
        let llt = to_faer(&sys.m).llt(Side::Lower).map_err(|_| {
            StabilityError::BadInput("the mass matrix M is not positive definite".into())
        })?;
        let l = llt.L().to_owned();
        tri::solve_lower_triangular_in_place(l.as_ref(), a.as_mut(), par);
        let mut at = a.transpose().to_owned();
        tri::solve_lower_triangular_in_place(l.as_ref(), at.as_mut(), par);
        a = Mat::from_fn(n, n, |i, j| 0.5 * (at[(i, j)] + at[(j, i)]));
        Ok(l)
    };
    let (omega2, u) = super::lanczos::symmetric_eigen(a.as_ref())?;
    drop(a);
    let m = match basis {
        Basis::Modes(m) => m.min(n),
        Basis::CutoffHz(f) => {
            let w2 = (2.0 * std::f64::consts::PI * f).powi(2);
            omega2.iter().take_while(|&&x| x <= w2).count()
        }
    };
    if m == 0 {
        let lowest = omega2[0].max(0.0).sqrt() / (2.0 * std::f64::consts::PI);
        return Err(StabilityError::BadInput(format!(
            "projected modal analysis: no undamped mode at or below modal.cutoff_hz = {} Hz (the lowest is at {lowest:.4e} Hz); raise modal.cutoff_hz or set modal.modes",
            match basis {
                Basis::CutoffHz(f) => f,
                Basis::Modes(_) => f64::NAN,
            }
        )));
    }
    let mut phi = u.subcols(0, m).to_owned();
    match llt {
        Err(d) => {
            for j in 0..m {
                for i in 0..n {
                    phi[(i, j)] *= d[i];
                }
            }
        }
        Ok(l) => tri::solve_upper_triangular_in_place(l.transpose(), phi.as_mut(), par),
    }
    Ok(UndampedBasis {
        phi,
        omega2: omega2[..m].to_vec(),
        static_vectors: 0,
        sturm_count: None,
    })
}

/// `Φᵀ X Φ` (`m × m`) for the matrix `part` of `sys`.
fn project<S: Structure + ?Sized>(sys: &S, part: Part, phi: &Mat<f64>) -> Mat<f64> {
    use faer::linalg::matmul::matmul;
    use faer::{Accum, Par};
    let xphi = sys.mul(part, phi.as_ref());
    let m = phi.ncols();
    let mut out = Mat::<f64>::zeros(m, m);
    matmul(
        out.as_mut(),
        Accum::Replace,
        phi.transpose(),
        xphi.as_ref(),
        1.0,
        Par::Seq,
    );
    out
}

/// The reduced state matrix `[[0, I], [−K_r, −C_r]]` (`2m × 2m`).
fn reduced_state_matrix<S: Structure + ?Sized>(sys: &S, b: &UndampedBasis) -> DMatrix<f64> {
    let m = b.phi.ncols();
    let kr = project(sys, Part::K, &b.phi);
    let cr = project(sys, Part::C, &b.phi);
    let mut a = DMatrix::<f64>::zeros(2 * m, 2 * m);
    for i in 0..m {
        a[(i, m + i)] = 1.0;
        for j in 0..m {
            a[(m + i, j)] = -kr[(i, j)];
            a[(m + i, m + j)] = -cr[(i, j)];
        }
    }
    a
}

fn method<S: Structure + ?Sized>(sys: &S, b: &UndampedBasis, basis: BasisKind) -> Method {
    let modes = b.phi.ncols() - b.static_vectors;
    Method::Projected {
        modes,
        dofs: sys.dofs(),
        basis_max_hz: b.omega2[..modes]
            .last()
            .map_or(0.0, |w2| w2.max(0.0).sqrt())
            / (2.0 * std::f64::consts::PI),
        static_vectors: b.static_vectors,
        basis,
        sturm_count: b.sturm_count,
    }
}

/// The projection basis of a friction-coupled system: the undamped modes
/// `basis` asks for, with the static correction at the dofs where the
/// coupling is non-symmetric ([`coupling_dofs`], [`with_static_correction`]).
pub fn corrected_basis<S: Structure + ?Sized>(
    sys: &S,
    basis: Basis,
) -> Result<UndampedBasis, StabilityError> {
    let b = sys.undamped(basis)?;
    with_static_correction(sys, b, &sys.coupling_dofs())
}

/// The projection basis of `kind`: [`corrected_basis`], or
/// [`craig_bampton_basis`] (of the dense system).
pub fn basis_of<S: Structure + ?Sized>(
    sys: &S,
    basis: Basis,
    kind: BasisKind,
) -> Result<UndampedBasis, StabilityError> {
    match kind {
        BasisKind::Modes => corrected_basis(sys, basis),
        BasisKind::CraigBampton => craig_bampton_basis(&sys.dense(), basis),
    }
}

/// The Craig–Bampton basis ([`super::craig_bampton`]) with the dofs where
/// the coupling is non-symmetric ([`coupling_dofs`]: the friction contacts)
/// kept physical and the fixed-interface modes `basis` asks for, made
/// `M`-orthonormal by Rayleigh–Ritz in its span (`Tᵀ K_s T w = ω² Tᵀ M T w`,
/// `Φ = T W`), so that the projected problem is the one of
/// [`analyse_projected`]: the span, and so the eigenvalues, are those of
/// `T`. `omega2` lists the fixed-interface modes' `ω²`, then the
/// `static_vectors` (= boundary dofs) largest Ritz values.
pub fn craig_bampton_basis(
    sys: &SecondOrder,
    basis: Basis,
) -> Result<UndampedBasis, StabilityError> {
    let cb = super::craig_bampton::craig_bampton(&sys.m, &sys.k, &coupling_dofs(sys), basis)?;
    ritz_basis(sys, &cb, cb.omega2.len())
}

/// The `M`-orthonormal Ritz basis of the span of `cb`'s constraint modes
/// and its `modes` lowest fixed-interface modes ([`craig_bampton_basis`]).
fn ritz_basis(
    sys: &SecondOrder,
    cb: &super::craig_bampton::CraigBampton,
    modes: usize,
) -> Result<UndampedBasis, StabilityError> {
    let n = check(sys)?;
    let nb = cb.boundary.len();
    let r = nb + modes;
    if r == 0 {
        return Err(StabilityError::BadInput(
            "Craig–Bampton basis: no contact dof and no fixed-interface mode below modal.cutoff_hz"
                .into(),
        ));
    }
    let t = cb.t.columns(0, r).into_owned();
    let project = |a: &DMatrix<f64>| t.transpose() * (a * &t);
    let ks = DMatrix::from_fn(n, n, |i, j| 0.5 * (sys.k[(i, j)] + sys.k[(j, i)]));
    let small = SecondOrder {
        m: project(&sys.m),
        k: project(&ks),
        c: DMatrix::zeros(r, r),
    };
    let ritz = undamped_basis(&small, Basis::Modes(r))?;
    let phi = &to_faer(&t) * &ritz.phi;
    let mut omega2 = cb.omega2[..modes].to_vec();
    omega2.extend(ritz.omega2[r - nb..].iter().copied());
    Ok(UndampedBasis {
        phi,
        omega2,
        static_vectors: nb,
        sturm_count: None,
    })
}

/// One row of the truncation table ([`truncation_table`]): the projected
/// eigenvalues with the `modes` lowest undamped modes of the basis (and the
/// static correction).
#[derive(Debug, Clone, PartialEq)]
pub struct Truncation {
    /// Undamped modes kept.
    pub modes: usize,
    /// The highest one's frequency (Hz).
    pub basis_max_hz: f64,
    /// Static-correction vectors added.
    pub static_vectors: usize,
    /// Every eigenvalue with `ω ≥ 0`.
    pub eigenvalues: Vec<Complex<f64>>,
}

/// The truncation error made visible: the projected eigenvalues (with the
/// static correction) for a quarter, half, three quarters and all of the
/// modes `basis` asks for (distinct counts, at least one mode), smallest
/// basis first. The undamped modes and the static responses are computed
/// once; each row costs one reduced eigen-solve. An eigenvalue that still
/// moves between the last two rows has not settled: more modes (a higher
/// `modal.cutoff_hz`) would move it further.
pub fn truncation_table<S: Structure + ?Sized>(
    sys: &S,
    basis: Basis,
    kind: BasisKind,
) -> Result<Vec<Truncation>, StabilityError> {
    if kind == BasisKind::CraigBampton {
        return craig_bampton_truncation(&sys.dense(), basis);
    }
    let full = sys.undamped(basis)?;
    let responses = correction_responses(sys, &full)?;
    table_rows(sys, &full, &responses)
}

/// The static responses [`with_static_correction`] adds to `modes`: at the
/// coupling dofs, none when there are none or the modes span the space.
fn correction_responses<S: Structure + ?Sized>(
    sys: &S,
    modes: &UndampedBasis,
) -> Result<faer::Mat<f64>, StabilityError> {
    let dofs = sys.coupling_dofs();
    if dofs.is_empty() || modes.phi.ncols() >= sys.dofs() {
        Ok(faer::Mat::<f64>::zeros(sys.dofs(), 0))
    } else {
        static_responses(sys, &dofs)
    }
}

/// The rows of [`truncation_table`] from the undamped modes `full` and the
/// static responses that correct each row's basis.
fn table_rows<S: Structure + ?Sized>(
    sys: &S,
    full: &UndampedBasis,
    responses: &faer::Mat<f64>,
) -> Result<Vec<Truncation>, StabilityError> {
    let m = full.phi.ncols();
    let mut counts: Vec<usize> = [1usize, 2, 3, 4]
        .iter()
        .map(|q| (m * q).div_ceil(4).max(1))
        .collect();
    counts.dedup();
    counts
        .into_iter()
        .map(|k| {
            let b = UndampedBasis {
                phi: full.phi.subcols(0, k).to_owned(),
                omega2: full.omega2[..k].to_vec(),
                static_vectors: 0,
                sturm_count: None,
            };
            let b = augment(sys, b, responses)?;
            let a = reduced_state_matrix(sys, &b);
            Ok(Truncation {
                modes: k,
                basis_max_hz: full.omega2[k - 1].max(0.0).sqrt() / std::f64::consts::TAU,
                static_vectors: b.static_vectors,
                eigenvalues: upper_eigenvalues(&a)?,
            })
        })
        .collect()
}

/// The eigenvalues of `a` with `ω ≥ 0` (a row of the truncation table).
fn upper_eigenvalues(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, StabilityError> {
    Ok(eigenvalues(a)?
        .into_iter()
        .filter(|e| e.im >= 0.0)
        .collect())
}

/// [`truncation_table`] of a Craig–Bampton basis: a quarter, half, three
/// quarters and all of its fixed-interface modes (the contact dofs in every
/// row; the interior's modes computed once, a Ritz solve per row).
fn craig_bampton_truncation(
    sys: &SecondOrder,
    basis: Basis,
) -> Result<Vec<Truncation>, StabilityError> {
    let cb = super::craig_bampton::craig_bampton(&sys.m, &sys.k, &coupling_dofs(sys), basis)?;
    let m = cb.omega2.len();
    let mut counts: Vec<usize> = [1usize, 2, 3, 4]
        .iter()
        .map(|q| (m * q).div_ceil(4))
        .collect();
    counts.dedup();
    counts
        .into_iter()
        .map(|k| {
            let b = ritz_basis(sys, &cb, k)?;
            let a = reduced_state_matrix(sys, &b);
            Ok(Truncation {
                modes: k,
                basis_max_hz: cb.omega2[..k].last().map_or(0.0, |w2| w2.max(0.0).sqrt())
                    / std::f64::consts::TAU,
                static_vectors: b.static_vectors,
                eigenvalues: upper_eigenvalues(&a)?,
            })
        })
        .collect()
}

/// The eigenvalues of the projected problem (see the module docs), without
/// eigenvectors, and the [`Method`] used.
pub fn projected_eigenvalues<S: Structure + ?Sized>(
    sys: &S,
    basis: Basis,
    kind: BasisKind,
) -> Result<(Vec<Complex<f64>>, Method), StabilityError> {
    let b = basis_of(sys, basis, kind)?;
    let a = reduced_state_matrix(sys, &b);
    Ok((eigenvalues(&a)?, method(sys, &b, kind)))
}

/// Most eigenvector entries an analysis by projection keeps (complex
/// numbers, 16 bytes each: 256 MB). A 10⁵-dof brake has hundreds of modes
/// of `2n` entries each; beyond this budget only the growing modes and the
/// least stable others (in the order of [`Analysis::eigen`]) keep their
/// eigenvectors and energy shares, the rest keep their eigenvalue and
/// dominant dof with an empty [`super::Eigen::vector`] and
/// [`super::Eigen::participation`].
pub const VECTOR_BUDGET: usize = 16_000_000;

/// Complex eigenvalue analysis by projection (see the module docs): the
/// same [`Analysis`] as [`super::modal::analyse_matrix`] (modes by growth
/// rate, eigenvectors as states `(q, λ q)` in the physical dofs, unit 2-norm,
/// largest component real positive; energy shares with `masses`), for the
/// `2m` eigenvalues of the reduced problem, with
/// [`Analysis::method`] = [`Method::Projected`]; within the
/// [`VECTOR_BUDGET`] (every eigenvector of models up to a few thousand
/// dofs).
///
/// - `z`: the equilibrium (`2n` values), `state_names`: `2n` names (dofs,
///   then velocities), `masses`: `n` positive masses or `None`.
pub fn analyse_projected<S: Structure + ?Sized>(
    sys: &S,
    z: &[f64],
    state_names: &[String],
    masses: Option<&[f64]>,
    basis: Basis,
    kind: BasisKind,
) -> Result<Analysis, StabilityError> {
    let n = checked(sys, z, state_names, masses)?;
    let b = basis_of(sys, basis, kind)?;
    analyse_in(sys, n, z, state_names, masses, &b, kind)
}

/// The dof count of `sys` once `z`, `state_names` and `masses` are checked
/// against it.
fn checked<S: Structure + ?Sized>(
    sys: &S,
    z: &[f64],
    state_names: &[String],
    masses: Option<&[f64]>,
) -> Result<usize, StabilityError> {
    let n = sys.validate()?;
    if z.len() != 2 * n || state_names.len() != 2 * n {
        return Err(StabilityError::BadInput(format!(
            "{n} dofs but the equilibrium has {} values and there are {} state names",
            z.len(),
            state_names.len()
        )));
    }
    if let Some(ms) = masses {
        if ms.len() != n || ms.iter().any(|m| !(m.is_finite() && *m > 0.0)) {
            return Err(StabilityError::BadInput(format!(
                "masses must be {n} finite positive values"
            )));
        }
    }
    Ok(n)
}

/// [`analyse_projected`] and [`truncation_table`] together: the undamped
/// modes and the static responses, the costly part of both (a Lanczos
/// solve and a factorisation of `K_s + sM` on a sparse model), computed
/// once. The table's error is its own: the analysis stands without it.
#[allow(clippy::type_complexity)]
pub fn analyse_projected_with_table<S: Structure + ?Sized>(
    sys: &S,
    z: &[f64],
    state_names: &[String],
    masses: Option<&[f64]>,
    basis: Basis,
    kind: BasisKind,
) -> Result<(Analysis, Result<Vec<Truncation>, StabilityError>), StabilityError> {
    if kind == BasisKind::CraigBampton {
        let an = analyse_projected(sys, z, state_names, masses, basis, kind)?;
        return Ok((an, truncation_table(sys, basis, kind)));
    }
    let n = checked(sys, z, state_names, masses)?;
    let full = sys.undamped(basis)?;
    let responses = correction_responses(sys, &full)?;
    let table = table_rows(sys, &full, &responses);
    let b = augment(sys, full, &responses)?;
    Ok((analyse_in(sys, n, z, state_names, masses, &b, kind)?, table))
}

/// [`analyse_projected`] of the checked `n`-dof `sys` in the basis `b`
/// (built for `kind`).
fn analyse_in<S: Structure + ?Sized>(
    sys: &S,
    n: usize,
    z: &[f64],
    state_names: &[String],
    masses: Option<&[f64]>,
    b: &UndampedBasis,
    kind: BasisKind,
) -> Result<Analysis, StabilityError> {
    let a = reduced_state_matrix(sys, b);
    let mut pairs = eigenpairs(&a)?;
    // In the order of the analysis (growth rate descending, +ω first), so
    // that the budget keeps the vectors that matter.
    pairs.sort_by(|p, q| q.0.re.total_cmp(&p.0.re).then(q.0.im.total_cmp(&p.0.im)));
    let m = b.phi.ncols();
    let keep = (VECTOR_BUDGET / (2 * n)).max(1);
    // Q = Φ Y by blocks of modes (one matrix product per block, no
    // n × 2m matrix held).
    const CHUNK: usize = 64;
    let mut modes = Vec::with_capacity(pairs.len());
    for (start, chunk) in pairs.chunks(CHUNK).enumerate() {
        let k = chunk.len();
        let y_re = Mat::<f64>::from_fn(m, k, |i, j| chunk[j].1[i].re);
        let y_im = Mat::<f64>::from_fn(m, k, |i, j| chunk[j].1[i].im);
        let (q_re, q_im) = (&b.phi * &y_re, &b.phi * &y_im);
        for (j, (lambda, _)) in chunk.iter().enumerate() {
            let mut u: Vec<Complex<f64>> = (0..n)
                .map(|i| Complex::new(q_re[(i, j)], q_im[(i, j)]))
                .collect();
            for i in 0..n {
                let v = lambda * u[i];
                u.push(v);
            }
            super::eigen::normalise(&mut u);
            let mut e = describe(*lambda, u, masses, state_names);
            if start * CHUNK + j >= keep && !e.growing {
                e.vector = Vec::new();
                e.participation = Vec::new();
            }
            modes.push(e);
        }
    }
    let mut an = finish(modes, z.to_vec());
    an.method = method(sys, b, kind);
    Ok(an)
}
