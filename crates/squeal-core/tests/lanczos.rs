//! Block shift-invert Lanczos against the dense symmetric eigen-solver and
//! against exact results: a ring of equal springs and masses has exactly
//! repeated (doublet) frequencies `ω_k² = 2 (k/m_eff)(1 − cos 2πk/n)`, the
//! case a single-vector Lanczos misses; a free ring has one rigid-body mode.

use faer::sparse::{SparseColMat, Triplet};
use nalgebra::DMatrix;
use squeal_core::linear::{Basis, SecondOrder};
use squeal_core::stability::lanczos::lowest_modes;
use squeal_core::stability::projected::undamped_basis;

/// `(row, col, value)` triplets.
type Entries = Vec<(usize, usize, f64)>;

/// A ring of `n` nodes: springs `k` between neighbours, a consistent mass
/// `m/6 · [[2, 1], [1, 2]]` per spring (a bar element's), and a ground
/// spring `ground` at node 0 (0: free).
fn ring(n: usize, k: f64, m: f64, ground: f64) -> (Entries, Entries) {
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    for e in 0..n {
        let (a, b) = (e, (e + 1) % n);
        for (i, j, s) in [(a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)] {
            kt.push((i, j, s * k));
        }
        for (i, j, s) in [(a, a, 2.0), (b, b, 2.0), (a, b, 1.0), (b, a, 1.0)] {
            mt.push((i, j, s * m / 6.0));
        }
    }
    if ground > 0.0 {
        kt.push((0, 0, ground));
    }
    (kt, mt)
}

fn sparse(n: usize, t: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
    let t: Vec<Triplet<usize, usize, f64>> =
        t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
    SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
}

fn dense(n: usize, t: &[(usize, usize, f64)]) -> DMatrix<f64> {
    let mut d = DMatrix::zeros(n, n);
    for &(i, j, v) in t {
        d[(i, j)] += v;
    }
    d
}

/// `max_j ‖K φ_j − ω_j² M φ_j‖ / (ω_max² ‖M φ_j‖)` and `max |ΦᵀMΦ − I|`.
fn residuals(k: &DMatrix<f64>, m: &DMatrix<f64>, phi: &faer::Mat<f64>, w2: &[f64]) -> (f64, f64) {
    let p = DMatrix::from_fn(phi.nrows(), phi.ncols(), |i, j| phi[(i, j)]);
    let (kp, mp) = (k * &p, m * &p);
    let top = w2.last().unwrap();
    let mut res = 0.0f64;
    for j in 0..p.ncols() {
        let r = kp.column(j) - mp.column(j) * w2[j];
        res = res.max(r.norm() / (top * mp.column(j).norm()));
    }
    let g = p.transpose() * &mp;
    let orth = (g - DMatrix::identity(p.ncols(), p.ncols())).amax();
    (res, orth)
}

#[test]
fn ring_doublets_match_the_exact_frequencies() {
    let n = 400;
    let (k, m) = (1.0e7, 0.02);
    let (kt, mt) = ring(n, k, m, 0.0);
    let b = lowest_modes(
        sparse(n, &kt).as_ref(),
        sparse(n, &mt).as_ref(),
        Basis::Modes(41),
    )
    .unwrap();
    assert_eq!(b.omega2.len(), 41);
    // Exact: the consistent-mass ring's ω² = (k/m) · 6 (1 − c) / (2 + c),
    // c = cos(2π j/n); j = 0 (rigid body) once, then each j twice.
    let mut exact = vec![0.0];
    for j in 1..=20 {
        let c = (std::f64::consts::TAU * j as f64 / n as f64).cos();
        let w2 = k / m * 6.0 * (1.0 - c) / (2.0 + c);
        exact.push(w2);
        exact.push(w2);
    }
    let top = exact[40];
    for (got, want) in b.omega2.iter().zip(&exact) {
        assert!(
            (got - want).abs() <= 1e-12 * top,
            "ω² = {got}, exact {want}"
        );
    }
    let (res, orth) = residuals(&dense(n, &kt), &dense(n, &mt), &b.phi, &b.omega2);
    assert!(res < 1e-9, "residual {res}");
    assert!(orth < 1e-10, "M-orthonormality {orth}");
}

#[test]
fn cutoff_basis_equals_the_dense_solve() {
    let n = 300;
    // A grounded ring with non-uniform masses (no exact doublets).
    let (kt, mut mt) = ring(n, 4.0e6, 0.01, 1.0e6);
    for i in 0..n {
        mt.push((i, i, 1e-3 * (1 + i % 5) as f64));
    }
    let cutoff = 2_000.0;
    let lz = lowest_modes(
        sparse(n, &kt).as_ref(),
        sparse(n, &mt).as_ref(),
        Basis::CutoffHz(cutoff),
    )
    .unwrap();
    let sys = SecondOrder {
        m: dense(n, &mt),
        k: dense(n, &kt),
        c: DMatrix::zeros(n, n),
    };
    let dn = undamped_basis(&sys, Basis::CutoffHz(cutoff)).unwrap();
    assert!(dn.omega2.len() > 20, "{} modes", dn.omega2.len());
    assert_eq!(lz.omega2.len(), dn.omega2.len());
    for (a, b) in lz.omega2.iter().zip(&dn.omega2) {
        assert!(
            (a - b).abs() <= 1e-10 * dn.omega2.last().unwrap(),
            "{a} vs {b}"
        );
    }
    let (res, orth) = residuals(&sys.k, &sys.m, &lz.phi, &lz.omega2);
    assert!(
        res < 1e-8 && orth < 1e-10,
        "residual {res}, orthonormality {orth}"
    );
}
