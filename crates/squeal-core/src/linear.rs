//! The linearised second-order system of a model, `M q̈ + C q̇ + K q = 0`,
//! and the options that say how its complex eigenvalues are solved (dense,
//! or projected onto undamped modes: `stability::projected`). The models
//! build the system and hold the options; the stability layer above solves.

use nalgebra::DMatrix;
use serde::Serialize;

/// The highest frequency of interest for brake squeal (Hz): the top of the
/// audible range.
pub const BAND_HZ: f64 = 20_000.0;

/// The default cut-off of the projection basis is this multiple of
/// [`BAND_HZ`]: modes up to twice the highest frequency of interest, the
/// usual rule for modal truncation (a mode's influence on the modes below
/// falls off as `(f/f_k)²`).
pub const CUTOFF_FACTOR: f64 = 2.0;

/// Models with more dofs than this are analysed by projection unless told
/// otherwise ([`ModalOptions::dense_max_dofs`]); a dense solve of 500 dofs
/// (1000 states) takes about a second.
pub const DEFAULT_DENSE_MAX_DOFS: usize = 500;

/// How a model's complex eigenvalue analysis is solved. The `--set` keys of a
/// lumped model are `modal.dense_max_dofs`, `modal.modes` and
/// `modal.cutoff_hz`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModalOptions {
    /// Models with at most this many dofs are solved dense (every
    /// eigenvalue, exact to round-off); larger ones by projection. `0`:
    /// always project; a large value: always dense.
    pub dense_max_dofs: usize,
    /// Keep exactly this many lowest undamped modes (`0`: use
    /// [`ModalOptions::cutoff_hz`]).
    pub modes: usize,
    /// Keep every undamped mode up to this frequency (Hz).
    pub cutoff_hz: f64,
    /// Free-interface modes with static correction, or Craig–Bampton
    /// (key `modal.basis`).
    #[serde(rename = "basis")]
    pub kind: BasisKind,
}

/// What spans a projection basis (key `modal.basis`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BasisKind {
    /// The undamped (free-interface) modes of the whole model, with the
    /// static correction at the contact dofs (`"modes"`).
    #[default]
    Modes,
    /// The contact dofs kept physical with their constraint modes, plus the
    /// fixed-interface modes of the rest (`"craig-bampton"`).
    CraigBampton,
}

impl BasisKind {
    /// Every kind's key value.
    pub const NAMES: [&'static str; 2] = ["modes", "craig-bampton"];
    /// The key value (`"modes"`, `"craig-bampton"`).
    pub fn as_str(&self) -> &'static str {
        match self {
            BasisKind::Modes => "modes",
            BasisKind::CraigBampton => "craig-bampton",
        }
    }
    /// From the key value.
    pub fn parse(s: &str) -> Option<BasisKind> {
        match s {
            "modes" => Some(BasisKind::Modes),
            "craig-bampton" => Some(BasisKind::CraigBampton),
            _ => None,
        }
    }
}

impl Default for ModalOptions {
    fn default() -> Self {
        ModalOptions {
            dense_max_dofs: DEFAULT_DENSE_MAX_DOFS,
            modes: 0,
            cutoff_hz: CUTOFF_FACTOR * BAND_HZ,
            kind: BasisKind::Modes,
        }
    }
}

impl ModalOptions {
    /// Whether a model of `dofs` dofs is solved by projection.
    pub fn projects(&self, dofs: usize) -> bool {
        dofs > self.dense_max_dofs
    }
    /// The projection basis these options ask for.
    pub fn basis(&self) -> Basis {
        if self.modes > 0 {
            Basis::Modes(self.modes)
        } else {
            Basis::CutoffHz(self.cutoff_hz)
        }
    }
}

/// Which undamped modes span the projection basis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Basis {
    /// The `m` lowest (all of them if `m ≥ n`).
    Modes(usize),
    /// Every mode with `ω/2π ≤` this frequency (Hz); modes with `ω² ≤ 0` are
    /// included.
    CutoffHz(f64),
}

/// The linearised second-order system `M q̈ + C q̇ + K q = 0` (each `n × n`,
/// `M` symmetric positive definite).
#[derive(Debug, Clone, PartialEq)]
pub struct SecondOrder {
    /// Mass matrix.
    pub m: DMatrix<f64>,
    /// Stiffness (`−∂force/∂q`), any symmetry.
    pub k: DMatrix<f64>,
    /// Damping (`−∂force/∂q̇`), any symmetry.
    pub c: DMatrix<f64>,
}

/// Models with more dofs than this that are analysed by projection keep
/// their matrices sparse from the file to the solver
/// ([`SparseSecondOrder`]; the real modes by block shift-invert Lanczos,
/// `stability::lanczos`): a dense solve of their real modes would take
/// `9 n³` flops (a minute at 2000 dofs) and `8 n²` bytes.
pub const SPARSE_FROM_DOFS: usize = 2000;

/// The linearised second-order system `M q̈ + C q̇ + K q = 0` with sparse
/// matrices (compressed columns, both triangles stored): what a
/// large FE model linearises to (its matrices plus a few contact terms).
#[derive(Debug, Clone)]
pub struct SparseSecondOrder {
    /// Mass matrix (symmetric positive definite).
    pub m: faer::sparse::SparseColMat<usize, f64>,
    /// Stiffness (`−∂force/∂q`), any symmetry.
    pub k: faer::sparse::SparseColMat<usize, f64>,
    /// Damping (`−∂force/∂q̇`), any symmetry.
    pub c: faer::sparse::SparseColMat<usize, f64>,
}

impl SparseSecondOrder {
    /// From `(row, col, value)` triplets of an `n × n` system (duplicates
    /// summed). `None` if an index is out of range.
    pub fn from_triplets(
        n: usize,
        m: &[(usize, usize, f64)],
        k: &[(usize, usize, f64)],
        c: &[(usize, usize, f64)],
    ) -> Option<SparseSecondOrder> {
        let build = |t: &[(usize, usize, f64)]| {
            let t: Vec<faer::sparse::Triplet<usize, usize, f64>> = t
                .iter()
                .map(|&(i, j, v)| faer::sparse::Triplet::new(i, j, v))
                .collect();
            faer::sparse::SparseColMat::try_new_from_triplets(n, n, &t).ok()
        };
        Some(SparseSecondOrder {
            m: build(m)?,
            k: build(k)?,
            c: build(c)?,
        })
    }
    /// Number of dofs.
    pub fn dofs(&self) -> usize {
        self.m.nrows()
    }
    /// Stored entries of `K` (the size of the problem).
    pub fn nonzeros(&self) -> usize {
        self.k.compute_nnz()
    }
    /// The same system with dense matrices.
    pub fn to_dense(&self) -> SecondOrder {
        let n = self.dofs();
        let dense = |a: &faer::sparse::SparseColMat<usize, f64>| {
            let mut d = DMatrix::<f64>::zeros(n, n);
            for j in 0..n {
                for (i, &v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                    d[(i, j)] += v;
                }
            }
            d
        };
        SecondOrder {
            m: dense(&self.m),
            k: dense(&self.k),
            c: dense(&self.c),
        }
    }
}
