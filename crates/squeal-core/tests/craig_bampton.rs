//! Craig–Bampton reduction against exact results: with every
//! fixed-interface mode kept the reduced model has the full model's
//! eigenvalues (friction-coupled, non-symmetric, included); with none it
//! has the full model's static response to boundary loads (Guyan); in
//! between the natural frequencies converge from above (Rayleigh–Ritz).

use nalgebra::{Complex, DMatrix};
use squeal_core::linear::Basis;
use squeal_core::stability::craig_bampton::craig_bampton;

/// A chain of `n` masses with ground springs at both ends, unequal
/// masses and stiffnesses (no repeated frequencies).
fn chain(n: usize) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut m = DMatrix::zeros(n, n);
    let mut k = DMatrix::zeros(n, n);
    for i in 0..n {
        m[(i, i)] = 1.0 + 0.1 * (i % 7) as f64;
    }
    for i in 0..=n {
        let ki = 1.0e6 * (1.0 + 0.05 * (i % 5) as f64);
        if i > 0 {
            k[(i - 1, i - 1)] += ki;
        }
        if i < n {
            k[(i, i)] += ki;
        }
        if i > 0 && i < n {
            k[(i - 1, i)] -= ki;
            k[(i, i - 1)] -= ki;
        }
    }
    (m, k)
}

/// Eigenvalues of `M q̈ + C q̇ + K q = 0` (the `2n × 2n` state matrix), `ω ≥ 0`,
/// sorted by imaginary then real part.
fn eigen(m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let n = m.nrows();
    let minv = m.clone().try_inverse().unwrap();
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    let mk = -&minv * k;
    let mc = -&minv * c;
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = mk[(i, j)];
            a[(n + i, n + j)] = mc[(i, j)];
        }
    }
    let mut ev: Vec<Complex<f64>> = a
        .complex_eigenvalues()
        .iter()
        .copied()
        .filter(|e| e.im >= 0.0)
        .collect();
    ev.sort_by(|a, b| a.im.total_cmp(&b.im).then(a.re.total_cmp(&b.re)));
    ev
}

#[test]
fn every_mode_kept_gives_the_full_friction_coupled_eigenvalues() {
    let n = 24;
    let (m, mut k) = chain(n);
    // A friction-like follower coupling between two boundary dofs (K not
    // symmetric), and a little damping there.
    let (a, b) = (5, 17);
    k[(a, b)] += 4.0e5;
    k[(b, a)] -= 1.0e5;
    let mut c = DMatrix::zeros(n, n);
    c[(a, a)] = 2.0;
    c[(b, b)] = -1.0;
    let cb = craig_bampton(&m, &k, &[a, b, 23], Basis::CutoffHz(1e9)).unwrap();
    assert_eq!(cb.t.ncols(), n);
    assert_eq!(cb.interior_modes, n - 3);
    assert!(!cb.shifted);
    let full = eigen(&m, &c, &k);
    let red = eigen(&cb.project(&m), &cb.project(&c), &cb.project(&k));
    assert_eq!(full.len(), red.len());
    for (f, r) in full.iter().zip(&red) {
        assert!((f - r).norm() <= 1e-8 * f.norm(), "{f} vs {r}");
    }
    // Some mode of this coupling grows: the comparison covers one.
    assert!(full.iter().any(|e| e.re > 0.0), "{full:?}");
}

#[test]
fn no_mode_kept_is_guyan_and_exact_for_boundary_loads() {
    let n = 30;
    let (m, k) = chain(n);
    let boundary = [3, 11, 29];
    let cb = craig_bampton(&m, &k, &boundary, Basis::Modes(0)).unwrap();
    assert_eq!(cb.t.ncols(), 3);
    assert!(cb.omega2.is_empty());
    let mut f = nalgebra::DVector::zeros(n);
    f[3] = 2.0;
    f[11] = -1.0;
    f[29] = 0.5;
    let q = k.clone().lu().solve(&f).unwrap();
    let kr = cb.project(&k);
    let qr = kr.lu().solve(&(cb.t.transpose() * &f)).unwrap();
    let back = &cb.t * &qr;
    let scale = q.amax();
    for i in 0..n {
        assert!(
            (back[i] - q[i]).abs() <= 1e-12 * scale,
            "dof {i}: {} vs {}",
            back[i],
            q[i]
        );
    }
    for (j, &i) in boundary.iter().enumerate() {
        assert!((qr[j] - q[i]).abs() <= 1e-12 * scale);
    }
}

#[test]
fn frequencies_converge_from_above_as_modes_are_added() {
    let n = 40;
    let (m, k) = chain(n);
    let zero = DMatrix::zeros(n, n);
    let full = eigen(&m, &zero, &k);
    let mut last = f64::INFINITY;
    for modes in [2, 6, 12, 24, 37] {
        let cb = craig_bampton(&m, &k, &[0, 20, 39], Basis::Modes(modes)).unwrap();
        assert_eq!(cb.omega2.len(), modes);
        let z = DMatrix::zeros(cb.t.ncols(), cb.t.ncols());
        let red = eigen(&cb.project(&m), &z, &cb.project(&k));
        // The 5 lowest: each at or above the full one, the worst error
        // smaller with every basis.
        let mut worst = 0.0f64;
        for (f, r) in full.iter().zip(&red).take(5) {
            assert!(r.im >= f.im * (1.0 - 1e-9), "{r} below {f}");
            worst = worst.max((r.im - f.im) / f.im);
        }
        assert!(
            worst < last || worst < 1e-9,
            "{modes} modes: {worst:e} vs {last:e}"
        );
        last = worst;
    }
    assert!(last < 1e-9, "{last:e}");
}

#[test]
fn an_interior_the_boundary_does_not_hold_is_shifted_and_still_exact() {
    // Dofs 0–1 a free pair (a spring between them only); dofs 2–5 a chain
    // held by the boundary dof 2 and the ground.
    let n = 6;
    let mut m = DMatrix::zeros(n, n);
    let mut k = DMatrix::zeros(n, n);
    for i in 0..n {
        m[(i, i)] = 1.0 + 0.2 * i as f64;
    }
    let mut spring = |a: usize, b: Option<usize>, s: f64| {
        k[(a, a)] += s;
        if let Some(b) = b {
            k[(b, b)] += s;
            k[(a, b)] -= s;
            k[(b, a)] -= s;
        }
    };
    spring(0, Some(1), 3.0e5);
    spring(2, Some(3), 1.0e6);
    spring(3, Some(4), 2.0e6);
    spring(4, Some(5), 1.5e6);
    spring(5, None, 1.0e6);
    spring(2, None, 5.0e5);
    let cb = craig_bampton(&m, &k, &[2], Basis::Modes(usize::MAX)).unwrap();
    assert!(cb.shifted);
    let zero = DMatrix::zeros(n, n);
    let full = eigen(&m, &zero, &k);
    let z = DMatrix::zeros(n, n);
    let red = eigen(&cb.project(&m), &z, &cb.project(&k));
    // The free pair's rigid-body eigenvalue 0 comes out at ~1e-6 in both
    // (round-off of a double root): an absolute tolerance at the scale.
    // (either sign, so each side is matched to the other's nearest).
    let scale = full.iter().map(|e| e.norm()).fold(0.0, f64::max);
    let nearest = |x: &Complex<f64>, set: &[Complex<f64>]| {
        set.iter()
            .map(|y| (x - y).norm())
            .fold(f64::INFINITY, f64::min)
    };
    for (a, b) in [(&full, &red), (&red, &full)] {
        for x in a.iter() {
            assert!(nearest(x, b) <= 1e-8 * scale, "{x} not in {b:?}");
        }
    }
}

#[test]
fn bad_boundaries_are_refused() {
    let (m, k) = chain(4);
    assert!(craig_bampton(&m, &k, &[4], Basis::Modes(1)).is_err());
    assert!(craig_bampton(&m, &k, &[1, 1], Basis::Modes(1)).is_err());
}

/// The sparse reduction (sparse `K_ii` solve, fixed-interface modes by
/// Lanczos) spans what the dense one spans: the same kept interior
/// frequencies (1e-10) and the same reduced natural frequencies (1e-10),
/// for a cut-off basis of a 300-dof chain with three boundary dofs.
#[test]
fn the_sparse_reduction_equals_the_dense_one() {
    use squeal_core::stability::craig_bampton::craig_bampton_sparse;
    let n = 300;
    let (m, k) = chain(n);
    let to_sparse = |a: &DMatrix<f64>| {
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if a[(i, j)] != 0.0 {
                    t.push(faer::sparse::Triplet::new(i, j, a[(i, j)]));
                }
            }
        }
        faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap()
    };
    let boundary = [17, 150, 299];
    let basis = Basis::CutoffHz(60.0);
    let d = craig_bampton(&m, &k, &boundary, basis).unwrap();
    let s = craig_bampton_sparse(
        to_sparse(&m).as_ref(),
        to_sparse(&k).as_ref(),
        &boundary,
        basis,
    )
    .unwrap();
    assert!(s.omega2.len() > 10, "{} modes", s.omega2.len());
    assert_eq!(s.t.ncols(), d.t.ncols());
    for (a, b) in d.omega2.iter().zip(&s.omega2) {
        assert!((a - b).abs() <= 1e-10 * a, "{a} vs {b}");
    }
    let natural = |mr: DMatrix<f64>, kr: DMatrix<f64>| {
        let l = mr.cholesky().unwrap().l();
        let li = l.clone().try_inverse().unwrap();
        let a = &li * kr * li.transpose();
        let mut w: Vec<f64> = a.symmetric_eigenvalues().iter().copied().collect();
        w.sort_by(f64::total_cmp);
        w
    };
    let wd = natural(d.project(&m), d.project(&k));
    let ws = natural(
        s.project_sparse(to_sparse(&m).as_ref()),
        s.project_sparse(to_sparse(&k).as_ref()),
    );
    for (a, b) in wd.iter().zip(&ws) {
        assert!((a - b).abs() <= 1e-10 * a, "{a} vs {b}");
    }
}
