//! Sparse operators of lumped models: triplets as files give them, and a
//! compressed-row matrix with the products the right-hand side needs.

use nalgebra::DMatrix;

/// A matrix as coordinate triplets (0-based), e.g. read from Matrix Market.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Triplets {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// `(row, col, value)`; repeated entries add up.
    pub entries: Vec<(usize, usize, f64)>,
}

/// A square sparse matrix in compressed rows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sparse {
    /// Size.
    pub n: usize,
    pub(super) row_ptr: Vec<usize>,
    pub(super) col: Vec<usize>,
    pub(super) val: Vec<f64>,
}

impl Sparse {
    /// From triplets (duplicates summed, zeros dropped).
    pub fn from_triplets(t: &Triplets) -> Sparse {
        let n = t.rows;
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &(r, c, v) in &t.entries {
            rows[r].push((c, v));
        }
        let mut s = Sparse {
            n,
            row_ptr: vec![0],
            col: Vec::new(),
            val: Vec::new(),
        };
        for mut row in rows {
            row.sort_by_key(|e| e.0);
            let mut merged: Vec<(usize, f64)> = Vec::new();
            for (c, v) in row {
                match merged.last_mut() {
                    Some(last) if last.0 == c => last.1 += v,
                    _ => merged.push((c, v)),
                }
            }
            for (c, v) in merged.into_iter().filter(|e| e.1 != 0.0) {
                s.col.push(c);
                s.val.push(v);
            }
            s.row_ptr.push(s.col.len());
        }
        s
    }
    /// `out += a·(A x)`.
    #[inline]
    pub fn mul_add(&self, x: &[f64], out: &mut [f64], a: f64) {
        for r in 0..self.n {
            let (lo, hi) = (self.row_ptr[r], self.row_ptr[r + 1]);
            // Four interleaved partial sums (entry `lo + i` into sum `i mod 4`):
            // independent additions instead of one dependent chain, for the
            // dense rows of a reduced FE model. A fixed order: the same bits on
            // every call, and in every padded size (the rows are the same).
            let (vals, cols) = (&self.val[lo..hi], &self.col[lo..hi]);
            let (vc, cc) = (vals.chunks_exact(4), cols.chunks_exact(4));
            let (vr, cr) = (vc.remainder(), cc.remainder());
            let mut p = [0.0; 4];
            for (v, c) in vc.zip(cc) {
                for k in 0..4 {
                    p[k] += v[k] * x[c[k]];
                }
            }
            let mut s = (p[0] + p[1]) + (p[2] + p[3]);
            for (v, &c) in vr.iter().zip(cr) {
                s += v * x[c];
            }
            out[r] += a * s;
        }
    }
    /// Every entry times `f` (`f = 1`: an exact copy).
    pub fn scaled(&self, f: f64) -> Sparse {
        let mut s = self.clone();
        if f != 1.0 {
            for v in &mut s.val {
                *v *= f;
            }
        }
        s
    }
    /// Entry `(r, c)`.
    pub fn get(&self, r: usize, c: usize) -> f64 {
        (self.row_ptr[r]..self.row_ptr[r + 1])
            .find(|&k| self.col[k] == c)
            .map_or(0.0, |k| self.val[k])
    }
    /// Non-zero entries `(row, col, value)`.
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        (0..self.n).flat_map(move |r| {
            (self.row_ptr[r]..self.row_ptr[r + 1]).map(move |k| (r, self.col[k], self.val[k]))
        })
    }
    /// The same matrix in faer's compressed columns (for sparse
    /// factorisations and products).
    pub fn to_faer(&self) -> faer::sparse::SparseColMat<usize, f64> {
        let t: Vec<faer::sparse::Triplet<usize, usize, f64>> = self
            .entries()
            .map(|(r, c, v)| faer::sparse::Triplet::new(r, c, v))
            .collect();
        faer::sparse::SparseColMat::try_new_from_triplets(self.n, self.n, &t)
            .expect("a Sparse's indices are within its size")
    }
    /// Whether `A = Aᵀ` exactly.
    pub fn is_symmetric(&self) -> bool {
        self.entries().all(|(r, c, v)| self.get(c, r) == v)
    }
    /// The same matrix, dense.
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut d = DMatrix::<f64>::zeros(self.n, self.n);
        for (r, c, v) in self.entries() {
            d[(r, c)] += v;
        }
        d
    }
    /// Whether only diagonal entries are non-zero.
    pub fn is_diagonal(&self) -> bool {
        self.entries().all(|(r, c, _)| r == c)
    }
}
