//! The lowest undamped modes of a large sparse structure, `K_s φ = ω² M φ`,
//! by block shift-invert Lanczos (Ericsson & Ruhe 1980, Math. Comp. 35;
//! Grimes, Lewis & Simon 1994, SIAM J. Matrix Anal. Appl. 15: the method of
//! the FE packages' normal-modes solvers).
//!
//! With a shift `σ` below the spectrum the operator
//!
//! ```text
//! S = (K_s − σ M)⁻¹ M,      S φ = θ φ,   θ = 1/(ω² − σ),
//! ```
//!
//! is self-adjoint in the `M` inner product and maps the lowest modes to its
//! largest eigenvalues `θ`, well separated from the rest: a Krylov method
//! finds them first. One sparse Cholesky factorisation of `K_s − σM` (faer;
//! a sparse LU if `K_s` is indefinite) serves every step. `σ = −(2π·1 Hz)²`
//! keeps a free structure's rigid-body modes (`ω = 0`) regular.
//!
//! A block of [`BLOCK`] vectors at a time finds repeated eigenvalues (the
//! doublet modes of an axisymmetric disc) that a single-vector Lanczos
//! misses; every new block is `M`-orthogonalised against all earlier ones,
//! twice (full reorthogonalisation: no spurious copies). The projected
//! matrix `H = Qᵀ M S Q` is block tridiagonal; its eigenpairs `(θ, y)` are
//! the Ritz pairs, with the residual `‖S x − θ x‖_M = ‖B y_last‖` (`B` the
//! next block's coefficients, `y_last` the last block of `y`). The search
//! stops when every wanted Ritz pair — the `m` lowest, or all with
//! `ω/2π ≤` the cut-off — and the [`BLOCK`] next ones beyond have converged,
//! `‖S x − θ x‖_M ≤` [`RESIDUAL_TOL`]`·θ`.
//!
//! A Krylov search can miss a mode: one whose multiplicity exceeds the
//! block, or to which the start block is (nearly) orthogonal. So the
//! result is checked as the FE packages check theirs, by a Sturm-sequence
//! count: the inertia of `K_s − μM` (an `LDLᵀ` factorisation's negative
//! pivots) is the number of eigenvalues below `μ`, taken in a gap above the
//! modes kept; if it exceeds the Ritz values found below `μ`, the search is
//! restarted from a fresh block `M`-orthogonal to the modes found
//! ([`count_below`], [`STURM_RESTARTS`]).
//!
//! No well-kept Rust crate does a sparse generalised symmetric
//! eigen-solve (faer's eigen-solvers are dense; ARPACK bindings need a
//! Fortran toolchain), hence the Krylov iteration here; the factorisation,
//! the matrix products and the small dense eigen-solves are faer's.

use super::projected::{Basis, UndampedBasis};
use super::StabilityError;
use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, SparseColMatRef};
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

/// Vectors per Lanczos block: the largest eigenvalue multiplicity found
/// reliably (a disc's doublets need 2; pads split them only slightly).
pub const BLOCK: usize = 6;

/// A Ritz pair counts as converged when `‖S x − θ x‖_M ≤ RESIDUAL_TOL · θ`:
/// the eigenvalue is then exact to about `RESIDUAL_TOL²` relative, the
/// mode shape to `RESIDUAL_TOL`.
pub const RESIDUAL_TOL: f64 = 1e-9;

/// The shift `σ = −(2π · 1 Hz)²` (rad²/s²) below the spectrum.
pub const SHIFT: f64 = -(2.0 * std::f64::consts::PI) * (2.0 * std::f64::consts::PI);

/// Most Lanczos vectors kept, times the model's dofs: memory is two
/// `n × s` matrices (`Q` and `M Q`), so `s ≤` this `/ n` bounds them at
/// about 2.4 GB.
pub const MAX_VECTOR_ENTRIES: usize = 150_000_000;

/// A factorised `K_s − σ M`.
enum Factor {
    Llt(faer::sparse::linalg::solvers::Llt<usize, f64>),
    Lu(Box<faer::sparse::linalg::solvers::Lu<usize, f64>>),
}

impl Factor {
    fn solve_in_place(&self, x: MatMut<'_, f64>) {
        match self {
            Factor::Llt(f) => f.solve_in_place(x),
            Factor::Lu(f) => f.solve_in_place(x),
        }
    }
}

/// Every eigenpair of the symmetric matrix `a` (lower triangle read),
/// eigenvalues ascending: faer's tridiagonalisation and implicit QR.
///
/// faer's default (divide and conquer above 128 rows) loses accuracy on
/// matrices whose eigenvalues spread over many decades, which a structure's
/// `M⁻¹ᐟ² K M⁻¹ᐟ²` does: on a 304-dof chain with `ω²` from 3e6 to 7e11 its
/// lowest eigenpair had a residual `‖A v − λ v‖` of 3 λ (nalgebra's and
/// this QR path: 1e-10 λ; test `projected::dense_real_modes_are_accurate`).
/// The QR path costs somewhat more for large matrices and is used
/// everywhere squeal needs symmetric eigenpairs.
pub fn symmetric_eigen(a: MatRef<'_, f64>) -> Result<(Vec<f64>, Mat<f64>), StabilityError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{self, ComputeEigenvectors, SelfAdjointEvdParams};
    let n = a.nrows();
    let mut params: SelfAdjointEvdParams = faer::Auto::<f64>::auto();
    params.recursion_threshold = usize::MAX;
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    let scratch =
        evd::self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::Yes, Par::Seq, params.into());
    evd::self_adjoint_evd(
        a,
        s.as_mut(),
        Some(u.as_mut()),
        Par::Seq,
        MemStack::new(&mut MemBuffer::new(scratch)),
        params.into(),
    )
    .map_err(|_| StabilityError::NoConvergence)?;
    let values: Vec<f64> = (0..n).map(|i| s[i]).collect();
    if values.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NoConvergence);
    }
    Ok((values, u))
}

/// `dst = A x` for a sparse `A`.
pub fn sparse_mul(a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(a.nrows(), x.ncols());
    faer::sparse::linalg::matmul::sparse_dense_matmul(
        out.as_mut(),
        Accum::Replace,
        a,
        x,
        1.0,
        Par::Seq,
    );
    out
}

/// `Aᵀ B` (dense).
fn at_b(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(a.ncols(), b.ncols());
    matmul(
        out.as_mut(),
        Accum::Replace,
        a.transpose(),
        b,
        1.0,
        Par::Seq,
    );
    out
}

/// `K_s + s M` for sparse `K_s`, `M` (same size).
pub fn shifted(
    ks: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    s: f64,
) -> Result<SparseColMat<usize, f64>, StabilityError> {
    // A linear-time merge of the two patterns (no sort of triplets).
    faer::sparse::ops::binary_op(ks, m, |a, b| {
        a.copied().unwrap_or(0.0) + s * b.copied().unwrap_or(0.0)
    })
    .map_err(|_| StabilityError::BadInput("cannot assemble K_s + s M".into()))
}

/// Factorise `A` (symmetric): Cholesky, or LU when it is not positive
/// definite.
fn factorise(a: &SparseColMat<usize, f64>) -> Result<Factor, StabilityError> {
    match a.sp_cholesky(Side::Lower) {
        Ok(f) => Ok(Factor::Llt(f)),
        Err(_) => a.sp_lu().map(|f| Factor::Lu(Box::new(f))).map_err(|_| {
            StabilityError::BadInput(
                "the stiffness K_s − σM is singular: the structure has a mechanism".into(),
            )
        }),
    }
}

/// `(K_s + s M)⁻¹ B` (columns of `b`), by one sparse factorisation.
pub fn shifted_solve(
    ks: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    s: f64,
    b: MatRef<'_, f64>,
) -> Result<Mat<f64>, StabilityError> {
    let f = factorise(&shifted(ks, m, s)?)?;
    let mut x = b.to_owned();
    f.solve_in_place(x.as_mut());
    Ok(x)
}

/// A deterministic pseudo-random block (xorshift64* from `seed`: the same
/// vectors on every machine; no random-number crate needed for start
/// vectors).
fn pseudo_random(n: usize, p: usize, seed: u64) -> Mat<f64> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0xD1B5_4A32_D192_ED03);
    Mat::from_fn(n, p, |_, _| {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let r = state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (r >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    })
}

/// The Lanczos basis so far: `Q` (`n × s`, `M`-orthonormal columns) and
/// `M Q`.
struct Krylov {
    q: Mat<f64>,
    mq: Mat<f64>,
    s: usize,
}

impl Krylov {
    /// `M`-orthogonalise the block `w` against the basis (twice, classical
    /// Gram–Schmidt by blocks), returning the coefficients (`s × p`), then
    /// `M`-orthonormalise its columns among themselves (modified
    /// Gram–Schmidt, returning the `p × p` upper-triangular `R`); a column
    /// that vanishes (an invariant subspace was found) is replaced by a
    /// fresh vector orthogonal to everything, with a zero row in `R`.
    fn orthonormalise(
        &self,
        m: SparseColMatRef<'_, usize, f64>,
        w: &mut Mat<f64>,
        fresh: &mut u64,
    ) -> (Mat<f64>, Mat<f64>) {
        let (n, p) = (w.nrows(), w.ncols());
        let q = self.q.as_ref().subcols(0, self.s);
        let mq = self.mq.as_ref().subcols(0, self.s);
        let mut coef = Mat::<f64>::zeros(self.s, p);
        for _ in 0..2 {
            if self.s == 0 {
                break;
            }
            let c = at_b(mq, w.as_ref());
            matmul(w.as_mut(), Accum::Add, q, c.as_ref(), -1.0, Par::Seq);
            coef += &c;
        }
        let mut r = Mat::<f64>::zeros(p, p);
        let mut mw = sparse_mul(m, w.as_ref());
        for j in 0..p {
            let norm0 = dot(w.col(j), mw.col(j)).max(0.0).sqrt();
            for _ in 0..2 {
                for i in 0..j {
                    let c = dot(w.col(i), mw.col(j));
                    r[(i, j)] += c;
                    for k in 0..n {
                        let wi = w[(k, i)];
                        w[(k, j)] -= c * wi;
                        let mwi = mw[(k, i)];
                        mw[(k, j)] -= c * mwi;
                    }
                }
            }
            let norm = dot(w.col(j), mw.col(j)).max(0.0).sqrt();
            if norm > 1e-10 * norm0 && norm > 0.0 {
                r[(j, j)] = norm;
                for k in 0..n {
                    w[(k, j)] /= norm;
                    mw[(k, j)] /= norm;
                }
            } else {
                // Breakdown: a new direction, orthogonal to the basis and to
                // the block's earlier columns.
                *fresh += 1;
                let mut col = pseudo_random(n, 1, *fresh);
                for _ in 0..2 {
                    if self.s > 0 {
                        let c = at_b(mq, col.as_ref());
                        matmul(col.as_mut(), Accum::Add, q, c.as_ref(), -1.0, Par::Seq);
                    }
                    let mc = sparse_mul(m, col.as_ref());
                    for i in 0..j {
                        let c = dot(w.col(i), mc.col(0));
                        for k in 0..n {
                            col[(k, 0)] -= c * w[(k, i)];
                        }
                    }
                }
                let mc = sparse_mul(m, col.as_ref());
                let norm = dot(col.col(0), mc.col(0)).max(0.0).sqrt();
                for k in 0..n {
                    w[(k, j)] = col[(k, 0)] / norm;
                    mw[(k, j)] = mc[(k, 0)] / norm;
                }
            }
        }
        (coef, r)
    }

    /// Append the (orthonormal) block `w` with `M w`.
    fn push(&mut self, m: SparseColMatRef<'_, usize, f64>, w: &Mat<f64>) {
        let p = w.ncols();
        let mw = sparse_mul(m, w.as_ref());
        for j in 0..p {
            for k in 0..w.nrows() {
                self.q[(k, self.s + j)] = w[(k, j)];
                self.mq[(k, self.s + j)] = mw[(k, j)];
            }
        }
        self.s += p;
    }
}

fn dot(a: faer::ColRef<'_, f64>, b: faer::ColRef<'_, f64>) -> f64 {
    (0..a.nrows()).map(|k| a[k] * b[k]).sum()
}

/// The lowest undamped modes of the sparse symmetric pencil `(K_s, M)`
/// that `basis` asks for, `M`-orthonormal, by block shift-invert Lanczos
/// (see the module docs). `K_s` symmetric, `M` symmetric positive definite
/// (both full, not one triangle).
///
/// The shift: `σ = −(ω_c/5)²` for a cut-off `ω_c` (the wanted `θ` then
/// span at most a factor 26, so round-off relative to the largest `θ`
/// stays round-off for the smallest), at least [`SHIFT`]. For a count of
/// modes the range is not known beforehand: a first search at [`SHIFT`]
/// finds it, and when its highest mode is above 100 × 1 Hz a second search
/// at `σ = −(ω_m/5)²` refines them (a free structure's rigid-body modes
/// at `θ = 1/|σ|` otherwise cost the high modes digits).
///
/// Errors: `M` not positive definite, a singular `K_s − σM`, no mode below
/// the cut-off, or no convergence within [`MAX_VECTOR_ENTRIES`].
pub fn lowest_modes(
    ks: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    basis: Basis,
) -> Result<UndampedBasis, StabilityError> {
    match basis {
        Basis::CutoffHz(f) => {
            let shift = -(std::f64::consts::TAU * f / 5.0).powi(2);
            sturm_checked(ks, m, basis, shift.min(SHIFT), None)
        }
        Basis::Modes(_) => {
            let first = lowest_modes_at(ks, m, basis, SHIFT, None)?;
            let top = first.0.omega2.last().copied().unwrap_or(0.0);
            if top > 1e4 * SHIFT.abs() {
                sturm_checked(ks, m, basis, -top / 25.0, None)
            } else {
                sturm_checked(ks, m, basis, SHIFT, Some(first))
            }
        }
    }
}

/// A search's modes, with its converged Ritz values `ω²` ascending (the
/// modes kept and at least a block beyond; `None`: the basis spans the
/// whole space).
type Search = (UndampedBasis, Option<Vec<f64>>);

/// Restarts after a Sturm count finds modes the search missed.
pub const STURM_RESTARTS: usize = 3;

/// [`lowest_modes_at`] (or its result `first`, at the same `sigma`)
/// checked by a Sturm-sequence count: the number of eigenvalues of
/// `(K_s, M)` below a point of the gap [`sturm_gap`] chooses must equal the
/// converged Ritz values below it. A Krylov search can miss a mode whose
/// multiplicity exceeds the block ([`BLOCK`]) or to which the start block
/// happens to be orthogonal; the count finds that, and the search is
/// restarted from a fresh block `M`-orthogonal to the modes found (they
/// are kept, locked, in the basis), at most [`STURM_RESTARTS`] times.
/// (Ericsson & Ruhe 1980 §4; Grimes, Lewis & Simon 1994 §3: the FE
/// packages' Lanczos solvers check the same way.)
fn sturm_checked(
    ks: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    basis: Basis,
    sigma: f64,
    mut first: Option<Search>,
) -> Result<UndampedBasis, StabilityError> {
    let mut locked: Option<UndampedBasis> = None;
    for _ in 0..=STURM_RESTARTS {
        let (mut b, ritz_w2) = match first.take() {
            Some(done) => done,
            None => lowest_modes_at(ks, m, basis, sigma, locked.as_ref())?,
        };
        let Some(ritz_w2) = ritz_w2 else {
            // Every eigenpair of the pencil was computed: nothing to miss.
            return Ok(b);
        };
        let Some((lo, hi, found)) = sturm_gap(&ritz_w2, b.omega2.len(), basis, sigma) else {
            // No gap to count at (left unchecked, sturm_count None).
            return Ok(b);
        };
        let mu = 0.5 * (lo + hi);
        let count = count_in_gap(ks, m, lo, hi)?;
        if count == found {
            b.sturm_count = Some(b.omega2.len());
            return Ok(b);
        }
        if count < found {
            return Err(StabilityError::BadInput(format!(
                "the Lanczos search found {found} undamped modes below {:.6e} Hz but the Sturm count of K_s − μM has only {count}: its Ritz values are not the pencil's (K_s or M not symmetric, or M not positive definite, as read)",
                mu.max(0.0).sqrt() / std::f64::consts::TAU
            )));
        }
        locked = Some(b);
    }
    let b = locked.expect("at least one search ran");
    Err(StabilityError::BadInput(format!(
        "the Lanczos search for the undamped modes kept missing modes: after {STURM_RESTARTS} restarts it has {} modes where the Sturm count has more; lower modal.cutoff_hz or modal.modes",
        b.omega2.len()
    )))
}

/// Where to take the Sturm count of a search that kept `kept` modes:
/// `(lo, hi, the converged Ritz values at or below lo)`, a gap `(lo, hi)`
/// between two consecutive converged Ritz values, wider than 10⁻⁸ of them.
/// Normally the gap just above the highest kept mode (for a cut-off, the
/// first from the cut-off up). Where the kept modes cut a cluster of
/// repeated eigenvalues (the next Ritz value equals the highest kept one),
/// the gap just below that cluster: the kept copies of a repeated
/// eigenvalue are any of its eigenspace, but no mode below it may be
/// missing. `None` if there is no such gap among the converged values (a
/// cluster from the lowest mode up; nothing to count).
fn sturm_gap(ritz_w2: &[f64], kept: usize, basis: Basis, sigma: f64) -> Option<(f64, f64, usize)> {
    let from = match basis {
        Basis::CutoffHz(f) => {
            let c = (std::f64::consts::TAU * f).powi(2);
            ritz_w2.iter().filter(|&&w2| w2 <= c).count().max(kept)
        }
        Basis::Modes(_) => kept,
    };
    if from == 0 || from > ritz_w2.len() {
        return None;
    }
    let scale = ritz_w2.last().map_or(0.0, |w| w.abs()).max(sigma.abs());
    let gap = |j: usize| ritz_w2[j] - ritz_w2[j - 1] > 1e-8 * scale;
    let at = |j: usize| (ritz_w2[j - 1], ritz_w2[j], j);
    if from < ritz_w2.len() && !gap(from) {
        // A cut cluster: below it.
        return (1..from).rev().find(|&j| gap(j)).map(at);
    }
    (from.max(1)..ritz_w2.len()).find(|&j| gap(j)).map(at)
}

/// [`count_below`] at a point of the gap `(lo, hi)` (no eigenvalue in it,
/// so every point gives the same count): the middle, else other points
/// where the unpivoted `LDLᵀ` meets no (near-)zero pivot.
pub fn count_in_gap(
    ks: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    lo: f64,
    hi: f64,
) -> Result<usize, StabilityError> {
    let mut last = None;
    for f in [0.5, 0.3, 0.7, 0.15, 0.85] {
        match count_below(ks, m, lo + f * (hi - lo)) {
            Ok(c) => return Ok(c),
            Err(e) => last = Some(e),
        }
    }
    Err(last.expect("tried"))
}

/// The number of eigenvalues `ω²` of the symmetric pencil `(K_s, M)` below
/// `mu` (`M` positive definite): the negative pivots of an `LDLᵀ`
/// factorisation of `K_s − μM` (Sylvester's law of inertia: `LDLᵀ` is a
/// congruence, and `K_s − μM` has as many negative eigenvalues as the
/// pencil has below `μ`). faer's sparse `LDLᵀ` (fill-reducing ordering, no
/// pivoting: `μ` lies in a gap of the spectrum, so the matrix is regular;
/// [`count_in_gap`] tries other points of the gap where a pivot vanishes).
/// Errors if a pivot is not finite or below 10⁻¹⁴ of the largest diagonal
/// entry of `K_s − μM` in magnitude (the count may then be wrong).
pub fn count_below(
    ks: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    mu: f64,
) -> Result<usize, StabilityError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, supernodal::SupernodalLdltRef, CholeskySymbolicParams,
        SymbolicCholeskyRaw, SymmetricOrdering,
    };
    let a = shifted(ks, m, -mu)?;
    let failed = || {
        StabilityError::BadInput(format!(
            "Sturm count: K_s − μM is singular at {:.6e} Hz",
            mu.max(0.0).sqrt() / std::f64::consts::TAU
        ))
    };
    let sym = factorize_symbolic_cholesky(
        a.symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        CholeskySymbolicParams::default(),
    )
    .map_err(|_| failed())?;
    let mut values = vec![0.0f64; sym.len_val()];
    let params = Default::default();
    let mut mem = MemBuffer::new(sym.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, params));
    sym.factorize_numeric_ldlt(
        &mut values,
        a.as_ref(),
        Side::Lower,
        LdltRegularization::default(),
        Par::Seq,
        MemStack::new(&mut mem),
        params,
    )
    .map_err(|_| failed())?;
    let pivots: Vec<f64> = match sym.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            // Each column of the factor starts with its diagonal: D.
            (0..s.nrows()).map(|j| values[s.col_ptr()[j]]).collect()
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let l = SupernodalLdltRef::new(s, &values);
            (0..s.n_supernodes())
                .flat_map(|k| {
                    let node = l.supernode(k).val();
                    (0..node.ncols()).map(move |j| node[(j, j)])
                })
                .collect()
        }
    };
    let diag = (0..a.ncols())
        .flat_map(|j| {
            a.row_idx_of_col(j)
                .zip(a.val_of_col(j))
                .filter(move |(i, _)| *i == j)
                .map(|(_, v)| v.abs())
        })
        .fold(0.0f64, f64::max);
    if pivots
        .iter()
        .any(|d| !d.is_finite() || d.abs() <= 1e-14 * diag)
    {
        return Err(failed());
    }
    Ok(pivots.iter().filter(|&&d| d < 0.0).count())
}

/// [`lowest_modes`] with the shift `sigma` (< 0), unchecked; with the
/// converged Ritz values `ω²`, ascending (the modes kept and at least a
/// block beyond; `None`: the basis spans the whole space). `locked`:
/// modes already found (at the same shift), kept in the basis as its first
/// vectors, the search starting `M`-orthogonal to them ([`sturm_checked`]'s
/// restart).
fn lowest_modes_at(
    ks: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    basis: Basis,
    sigma: f64,
    locked: Option<&UndampedBasis>,
) -> Result<Search, StabilityError> {
    let n = ks.nrows();
    if n == 0 || m.nrows() != n || ks.ncols() != n || m.ncols() != n {
        return Err(StabilityError::BadInput(
            "lowest_modes: K_s and M must be square and of the same size".into(),
        ));
    }
    if m.sp_cholesky(Side::Lower).is_err() {
        return Err(StabilityError::BadInput(
            "the mass matrix M is not positive definite".into(),
        ));
    }
    let factor = factorise(&shifted(ks, m, -sigma)?)?;
    let p = BLOCK.min(n);
    // The basis grows by whole blocks: at most the largest multiple of `p`
    // that fits `n` (and the memory bound).
    let cap = ((MAX_VECTOR_ENTRIES / n).max(2 * p).min(n) / p) * p;
    let wanted_w2 = match basis {
        Basis::Modes(0) => return Err(StabilityError::BadInput("modal.modes = 0".into())),
        Basis::Modes(_) => None,
        Basis::CutoffHz(f) => Some((std::f64::consts::TAU * f).powi(2)),
    };
    let want_count = match basis {
        Basis::Modes(k) => k.min(n),
        Basis::CutoffHz(_) => 0,
    };
    // Room for a few blocks beyond what is asked (a cut-off: a few hundred
    // vectors, what a brake's band needs); grown by half when full.
    let start = match wanted_w2 {
        Some(_) => 300,
        None => 2 * want_count + 4 * p,
    };
    let mut room = start.max(8 * p).min(cap);
    let mut kr = Krylov {
        q: Mat::zeros(n, room),
        mq: Mat::zeros(n, room),
        s: 0,
    };
    let mut h = Mat::<f64>::zeros(room, room);
    let mut fresh = 0u64;
    let mut seed = 0u64;
    if let Some(l) = locked {
        // The locked modes are eigenvectors of S: H is diagonal there, θ = 1/(ω² − σ).
        let k = l.phi.ncols();
        if k + 2 * p > cap {
            return Err(StabilityError::BadInput(format!(
                "the Lanczos restart has no room beyond the {k} modes found ({n} dofs); lower modal.cutoff_hz or modal.modes"
            )));
        }
        room = room.max(k + 8 * p).min(cap);
        kr.q.resize_with(n, room, |_, _| 0.0);
        kr.mq.resize_with(n, room, |_, _| 0.0);
        h.resize_with(room, room, |_, _| 0.0);
        let mphi = sparse_mul(m, l.phi.as_ref());
        for j in 0..k {
            for i in 0..n {
                kr.q[(i, j)] = l.phi[(i, j)];
                kr.mq[(i, j)] = mphi[(i, j)];
            }
            h[(j, j)] = 1.0 / (l.omega2[j] - sigma);
        }
        kr.s = k;
        seed = 1 + k as u64;
    }
    let mut w = pseudo_random(n, p, seed);
    let (_, _) = kr.orthonormalise(m, &mut w, &mut fresh);
    kr.push(m, &w);
    let mut last_check = 0usize;
    loop {
        let s0 = kr.s - p;
        // W = S Q_j = (K_s − σM)⁻¹ M Q_j.
        let mut w = kr.mq.as_ref().subcols(s0, p).to_owned();
        factor.solve_in_place(w.as_mut());
        if w.col_iter().any(|c| c.iter().any(|x| !x.is_finite())) {
            return Err(StabilityError::NonFinite {
                what: "Lanczos vector",
            });
        }
        let (coef, r) = kr.orthonormalise(m, &mut w, &mut fresh);
        for j in 0..p {
            for i in 0..kr.s {
                h[(i, s0 + j)] = coef[(i, j)];
            }
        }
        // The basis spans the whole space: every Ritz pair is exact.
        let complete = kr.s == n;
        let last = kr.s + p > cap;
        // Check the Ritz pairs when the basis has grown by a tenth, and
        // before giving up.
        if complete || last || kr.s >= last_check + (kr.s / 10).max(p) {
            last_check = kr.s;
            if let Some(done) = ritz(&kr, &h, &r, p, complete, sigma, wanted_w2, want_count)? {
                return Ok(done);
            }
        }
        if complete {
            return Err(StabilityError::NoConvergence);
        }
        if kr.s + p > room {
            if room >= cap || last {
                return Err(StabilityError::BadInput(format!(
                    "the Lanczos search for the undamped modes did not converge within {cap} vectors ({} dofs); lower modal.cutoff_hz or modal.modes",
                    n
                )));
            }
            let grown = (room + room / 2).max(room + p).min(cap);
            kr.q.resize_with(n, grown, |_, _| 0.0);
            kr.mq.resize_with(n, grown, |_, _| 0.0);
            h.resize_with(grown, grown, |_, _| 0.0);
            room = grown;
        }
        for j in 0..p {
            for i in 0..p {
                h[(kr.s + i, s0 + j)] = r[(i, j)];
            }
        }
        kr.push(m, &w);
    }
}

/// The converged wanted modes of the current basis, or `None` if some are
/// not yet converged (see [`lowest_modes`]).
fn ritz(
    kr: &Krylov,
    h: &Mat<f64>,
    r: &Mat<f64>,
    p: usize,
    complete: bool,
    sigma: f64,
    wanted_w2: Option<f64>,
    want_count: usize,
) -> Result<Option<Search>, StabilityError> {
    let s = kr.s;
    let hs = Mat::<f64>::from_fn(s, s, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
    let (theta, y) = symmetric_eigen(hs.as_ref())?;
    // Ritz values by ω² ascending: θ > 0 descending (θ < 0 only below σ,
    // possible with an indefinite K_s, lowest of all).
    let mut order: Vec<usize> = (0..s).collect();
    let w2 = |i: usize| sigma + 1.0 / theta[i];
    order.sort_by(|&a, &b| w2(a).total_cmp(&w2(b)));
    let converged = |i: usize| -> bool {
        if complete {
            return true;
        }
        // ‖B y_last‖ with B = R (the next block's coefficients).
        let mut res = 0.0;
        for a in 0..p {
            let mut v = 0.0;
            for b in a..p {
                v += r[(a, b)] * y[(s - p + b, i)];
            }
            res += v * v;
        }
        res.sqrt() <= RESIDUAL_TOL * theta[i].abs()
    };
    let wanted = match wanted_w2 {
        Some(c) => order.iter().take_while(|&&i| w2(i) <= c).count(),
        None => want_count.min(s),
    };
    if wanted == 0 && complete {
        return Err(StabilityError::BadInput(
            "projected modal analysis: no undamped mode at or below modal.cutoff_hz".into(),
        ));
    }
    if !complete {
        // Every wanted pair and the block beyond it converged; and the basis
        // must hold more than the wanted pairs.
        let need = (wanted + p).min(s);
        if wanted_w2.is_none() && want_count > s {
            return Ok(None);
        }
        if need >= s || !order[..need].iter().all(|&i| converged(i)) {
            return Ok(None);
        }
        if wanted == 0 {
            let lowest = w2(order[0]).max(0.0).sqrt() / std::f64::consts::TAU;
            return Err(StabilityError::BadInput(format!(
                "projected modal analysis: no undamped mode at or below modal.cutoff_hz = {} Hz (the lowest is at {lowest:.4e} Hz); raise modal.cutoff_hz or set modal.modes",
                wanted_w2.map_or(f64::NAN, |c| c.sqrt() / std::f64::consts::TAU)
            )));
        }
    }
    let keep = &order[..wanted];
    let ysel = Mat::<f64>::from_fn(s, wanted, |i, j| y[(i, keep[j])]);
    let mut phi = Mat::<f64>::zeros(kr.q.nrows(), wanted);
    matmul(
        phi.as_mut(),
        Accum::Replace,
        kr.q.as_ref().subcols(0, s),
        ysel.as_ref(),
        1.0,
        Par::Seq,
    );
    // The converged Ritz values (ascending: the kept ones and at least a
    // block beyond), where the Sturm count is compared; none when the
    // basis spans the whole space.
    let ritz_w2 = if complete {
        None
    } else {
        Some(
            order
                .iter()
                .take_while(|&&i| converged(i))
                .map(|&i| w2(i))
                .collect(),
        )
    };
    Ok(Some((
        UndampedBasis {
            phi,
            omega2: keep.iter().map(|&i| w2(i)).collect(),
            static_vectors: 0,
            sturm_count: None,
        },
        ritz_w2,
    )))
}
