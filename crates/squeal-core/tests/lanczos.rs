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
    // The 20th doublet is kept whole: the Sturm count confirms 41.
    assert_eq!(b.sturm_count, Some(41));
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
    assert_eq!(lz.sturm_count, Some(lz.omega2.len()));
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

/// A grid of `a × b` masses `m` on springs `k` to their four neighbours,
/// held at the boundary: `K = k (T_a ⊗ I + I ⊗ T_b)`, `M = m I`, with `T`
/// the (2, −1) matrix; exactly `ω² = (k/m)(λ_i + λ_j)`,
/// `λ_i = 2 − 2 cos(iπ/(a+1))`.
fn grid(a: usize, b: usize, k: f64, m: f64) -> (Entries, Entries, Vec<f64>) {
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    let id = |i: usize, j: usize| i * b + j;
    for i in 0..a {
        for j in 0..b {
            kt.push((id(i, j), id(i, j), 4.0 * k));
            mt.push((id(i, j), id(i, j), m));
            if i + 1 < a {
                kt.push((id(i, j), id(i + 1, j), -k));
                kt.push((id(i + 1, j), id(i, j), -k));
            }
            if j + 1 < b {
                kt.push((id(i, j), id(i, j + 1), -k));
                kt.push((id(i, j + 1), id(i, j), -k));
            }
        }
    }
    let lam =
        |i: usize, n: usize| 2.0 - 2.0 * (std::f64::consts::PI * i as f64 / (n + 1) as f64).cos();
    let mut exact: Vec<f64> = (1..=a)
        .flat_map(|i| (1..=b).map(move |j| k / m * (lam(i, a) + lam(j, b))))
        .collect();
    exact.sort_by(f64::total_cmp);
    (kt, mt, exact)
}

#[test]
fn the_sturm_count_equals_the_exact_count_below_a_shift() {
    use squeal_core::stability::lanczos::{count_below, count_in_gap};
    // A 30 × 37 grid: 1110 dofs, a fill-in heavy pattern (supernodal LDLᵀ)
    // and a 1-d chain (simplicial), both against the exact spectrum.
    for (a, b) in [(30, 37), (1, 200)] {
        let (kt, mt, exact) = grid(a, b, 3.0e6, 0.05);
        let n = a * b;
        let (ks, m) = (sparse(n, &kt), sparse(n, &mt));
        for j in [1usize, 7, 40, n / 2, n - 3] {
            // Halfway between two distinct exact eigenvalues.
            let hi = exact[j..]
                .iter()
                .copied()
                .find(|&w| w > exact[j - 1] * (1.0 + 1e-9))
                .unwrap();
            let lo = exact[j - 1];
            let want = exact.iter().filter(|&&w| w <= lo).count();
            // The grid's middle eigenvalue gap is centred on 4k/m, where
            // every diagonal entry of K − μM vanishes: count_in_gap moves on.
            assert_eq!(
                count_in_gap(ks.as_ref(), m.as_ref(), lo, hi).unwrap(),
                want,
                "{a}×{b}, gap {lo}…{hi}"
            );
        }
        // Below the spectrum: none.
        assert_eq!(
            count_below(ks.as_ref(), m.as_ref(), 0.5 * exact[0]).unwrap(),
            0
        );
    }
}

#[test]
fn a_mode_of_higher_multiplicity_than_the_block_is_found_by_the_sturm_restart() {
    use squeal_core::stability::lanczos::BLOCK;
    // Eight identical, uncoupled grounded chains: every eigenvalue is
    // 8-fold, more than a block of 6 can find (a block Krylov space meets
    // an eigenspace in at most `BLOCK` dimensions). The 16 lowest modes are
    // the first two chain modes, 8 times each.
    let copies = 8;
    assert!(copies > BLOCK);
    let len = 50;
    let (kc, mc, exact_chain) = grid(1, len, 2.0e6, 0.01);
    let n = copies * len;
    let shift = |t: &Entries, c: usize| -> Entries {
        t.iter()
            .map(|&(i, j, v)| (i + c * len, j + c * len, v))
            .collect()
    };
    let kt: Entries = (0..copies).flat_map(|c| shift(&kc, c)).collect();
    let mt: Entries = (0..copies).flat_map(|c| shift(&mc, c)).collect();
    let b = lowest_modes(
        sparse(n, &kt).as_ref(),
        sparse(n, &mt).as_ref(),
        Basis::Modes(16),
    )
    .unwrap();
    assert_eq!(b.omega2.len(), 16);
    for (i, got) in b.omega2.iter().enumerate() {
        let want = exact_chain[i / copies];
        assert!(
            (got - want).abs() <= 1e-10 * want,
            "mode {i}: ω² = {got}, exact {want}"
        );
    }
    assert_eq!(b.sturm_count, Some(16));
    let (res, orth) = residuals(&dense(n, &kt), &dense(n, &mt), &b.phi, &b.omega2);
    assert!(
        res < 1e-9 && orth < 1e-9,
        "residual {res}, orthonormality {orth}"
    );
    // The cut-off basis the same way: every mode below the middle of the
    // second and third.
    let f = (0.5 * (exact_chain[1] + exact_chain[2])).sqrt() / std::f64::consts::TAU;
    let b = lowest_modes(
        sparse(n, &kt).as_ref(),
        sparse(n, &mt).as_ref(),
        Basis::CutoffHz(f),
    )
    .unwrap();
    assert_eq!(b.omega2.len(), 16);
    assert_eq!(b.sturm_count, Some(16));
}
