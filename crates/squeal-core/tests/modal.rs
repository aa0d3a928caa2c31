//! Complex eigenvalue analysis of runtime-sized state matrices
//! (`stability::modal`): identical to the fixed-size path on every built-in
//! model, exact on systems with known eigenvalues and mode shapes (small and
//! large solver), and mode-shape normalisation.

use nalgebra::{Complex, DMatrix};
use squeal_core::model::hoffmann::Hoffmann;
use squeal_core::stability::modal::{
    amplitude_phase, analyse_matrix, eigenpairs, mode_shape, SMALL_MAX,
};
use squeal_core::stability::{analyse_with_masses, state_matrix, Inertia, StabilityError};
use squeal_core::{Belt, DiscPad, FrictionLaw, Model, Parameters};
use std::f64::consts::PI;

/// `analyse_matrix` on the model's own state matrix equals
/// `analyse_with_masses`: eigenvalues to 1e-12 relative (they are in fact
/// bit-identical: same operations in the same order), same attribution.
fn same_as_fixed<M: Model<N> + Inertia, const N: usize>(model: &M, label: &str) {
    let fixed = analyse_with_masses(model, &model.position_masses()).unwrap();
    let (z, a) = state_matrix(model).unwrap();
    let dm = DMatrix::from_fn(N, N, |i, j| a[i][j]);
    let names: Vec<String> = model.state_names().iter().map(|s| s.to_string()).collect();
    let dynamic = analyse_matrix(&dm, &z, &names, Some(&model.position_masses())).unwrap();
    assert_eq!(fixed.eigen.len(), dynamic.eigen.len());
    for (f, d) in fixed.eigen.iter().zip(&dynamic.eigen) {
        let mag = f.re.hypot(f.im).max(1e-300);
        assert!(
            (f.re - d.re).abs() <= 1e-12 * mag && (f.im - d.im).abs() <= 1e-12 * mag,
            "{label}: {} + {}i vs {} + {}i",
            f.re,
            f.im,
            d.re,
            d.im
        );
        // In fact the same operations in the same order: bit for bit.
        assert_eq!((f.re, f.im), (d.re, d.im), "{label}");
        assert_eq!(f.vector, d.vector, "{label}");
        assert_eq!(f.dominant_name, d.dominant_name, "{label}");
        for (x, y) in f.vector.iter().zip(&d.vector) {
            assert!((x - y).norm() <= 1e-12, "{label}: eigenvector {x} vs {y}");
        }
    }
    assert_eq!(fixed.stable, dynamic.stable, "{label}");
    assert_eq!(fixed.equilibrium, dynamic.equilibrium, "{label}");
}

#[test]
fn analyse_matrix_equals_analyse_on_every_built_in_model() {
    same_as_fixed(&DiscPad::default(), "disc-pad");
    // The thesis's parameter corners: slow and fast sliding, low and high load, other laws.
    for (v, n) in [(0.5, 200.0), (1.0, 2000.0), (10.0, 4000.0), (20.0, 100.0)] {
        let mut m = DiscPad::default();
        m.set("V", v).unwrap();
        m.set("N", n).unwrap();
        same_as_fixed(&m, &format!("disc-pad V={v} N={n}"));
    }
    let m = DiscPad {
        friction: FrictionLaw::Stribeck {
            mu_s: 0.4,
            mu_k: 0.3,
            v_s: 0.5,
            delta: 2.0,
            sigma: 0.0,
        },
        ..DiscPad::default()
    };
    same_as_fixed(&m, "disc-pad stribeck");
    same_as_fixed(&Belt::default(), "belt");
    for mu in [0.1, 0.25, 0.3, 0.6] {
        let mut h = Hoffmann::default();
        h.set("mu", mu).unwrap();
        same_as_fixed(&h, &format!("hoffmann mu={mu}"));
    }
}

/// SplitMix64, uniform in [−1, 1).
fn rng(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *seed;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

/// `n` decoupled oscillators `p̈_i + 2ζ_iω_i ṗ_i + ω_i² p_i = 0` seen through
/// the orthogonal change of coordinates `q = Q p` (`Q` a product of three
/// random Householder reflections): `M = I`, `K = Q Ω² Qᵀ`, `C = Q Z Qᵀ`,
/// state matrix `[[0, I], [−K, −C]]`, dense. Eigenvalues exactly
/// `λ = −ζω ± iω√(1−ζ²)`; the mode shape of oscillator `i` is column `i` of
/// `Q` (real). Some ζ are negative (growing modes); one mode is overdamped
/// (ζ = 1.5, two real eigenvalues). Frequencies span 1 … 1e4 rad/s (the
/// brake matrices' stiffness spread of 1e8 in ω²).
struct Oscillators {
    a: DMatrix<f64>,
    q: DMatrix<f64>,
    omega: Vec<f64>,
    zeta: Vec<f64>,
}

fn oscillators(n: usize, seed: u64) -> Oscillators {
    let mut s = seed;
    let omega: Vec<f64> = (0..n)
        .map(|i| 10f64.powf(4.0 * i as f64 / (n - 1) as f64) * (1.0 + 0.01 * rng(&mut s)))
        .collect();
    let zeta: Vec<f64> = (0..n)
        .map(|i| match i % 7 {
            3 => -0.02 * (1.0 + rng(&mut s).abs()),
            5 if i == 5 => 1.5,
            _ => 0.05 * (1.0 + rng(&mut s).abs()),
        })
        .collect();
    let mut q = DMatrix::<f64>::identity(n, n);
    for _ in 0..3 {
        let v = nalgebra::DVector::<f64>::from_fn(n, |_, _| rng(&mut s)).normalize();
        // Q ← Q (I − 2 v vᵀ)
        let qv = &q * &v;
        q -= 2.0 * qv * v.transpose();
    }
    let k = &q
        * DMatrix::from_diagonal(&nalgebra::DVector::from_fn(n, |i, _| omega[i] * omega[i]))
        * q.transpose();
    let c =
        &q * DMatrix::from_diagonal(&nalgebra::DVector::from_fn(n, |i, _| {
            2.0 * zeta[i] * omega[i]
        })) * q.transpose();
    let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -k[(i, j)];
            a[(n + i, n + j)] = -c[(i, j)];
        }
    }
    Oscillators { a, q, omega, zeta }
}

impl Oscillators {
    /// The exact eigenvalues, each with the oscillator it belongs to.
    fn exact(&self) -> Vec<(Complex<f64>, usize)> {
        let mut out = Vec::new();
        for (i, (&w, &z)) in self.omega.iter().zip(&self.zeta).enumerate() {
            if z.abs() < 1.0 {
                let wd = w * (1.0 - z * z).sqrt();
                out.push((Complex::new(-z * w, wd), i));
                out.push((Complex::new(-z * w, -wd), i));
            } else {
                let r = w * (z * z - 1.0).sqrt();
                out.push((Complex::new(-z * w + r, 0.0), i));
                out.push((Complex::new(-z * w - r, 0.0), i));
            }
        }
        out
    }
}

/// Every computed eigenvalue matches a distinct exact one, its mode shape is
/// column `i` of `Q` scaled to a largest entry of exactly 1, and its
/// eigenvector residual `‖Au − λu‖₂ / ‖A‖₁` (`‖u‖₂ = 1`) is below 1e-12.
///
/// Tolerances are those of a backward-stable dense solver: the computed
/// eigenvalues are exact for `A + E` with `‖E‖ ≈ ε‖A‖` (after balancing,
/// `‖A‖` is of the order of the spectral radius ρ), so the absolute error of
/// a well-conditioned eigenvalue is ≈ ε·ρ·κ; we allow `|Δλ| ≤ tol·ρ`, not
/// `tol·|λ|`: with ω from 1 to 1e4 rad/s the slow modes cannot be more
/// accurate than ≈ 1e-16·1e4·κ absolute. By the first-order perturbation
/// bound, an eigenvector moves by ≈ ‖E‖/gap, with gap the distance to the
/// nearest other eigenvalue and `‖E‖ ≤ ε‖A‖₁` for the unbalanced matrix:
/// we allow `shape_tol·‖A‖₁/gap` per entry.
fn check_oscillators(o: &Oscillators, tol: f64, shape_tol: f64) {
    let n = o.omega.len();
    let names: Vec<String> = (0..2 * n).map(|i| format!("s{i}")).collect();
    let t0 = std::time::Instant::now();
    let an = analyse_matrix(&o.a, &vec![0.0; 2 * n], &names, None).unwrap();
    let elapsed = t0.elapsed();
    assert_eq!(an.eigen.len(), 2 * n);
    let mut exact = o.exact();
    let all: Vec<Complex<f64>> = exact.iter().map(|(x, _)| *x).collect();
    let rho = all.iter().map(|x| x.norm()).fold(0.0, f64::max);
    let norm1 = (0..2 * n)
        .map(|j| o.a.column(j).iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    let mut worst_shape: f64 = 0.0;
    // Residuals of (at most) 100 eigenvectors spread over the spectrum:
    // A·Re u and A·Im u, O(n²) each.
    let stride = (2 * n).div_ceil(100);
    for (idx, e) in an.eigen.iter().enumerate() {
        let l = Complex::new(e.re, e.im);
        let (k, _) = exact
            .iter()
            .enumerate()
            .map(|(k, (x, _))| (k, (x - l).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let (x, osc) = exact.swap_remove(k);
        let err = (x - l).norm() / rho;
        worst = worst.max(err);
        assert!(
            err <= tol,
            "λ = {l}: exact {x}, error {err:e} of the spectral radius"
        );
        let gap = all
            .iter()
            .filter(|y| (*y - x).norm() > 0.0)
            .map(|y| (y - x).norm())
            .fold(f64::INFINITY, f64::min);
        // Residual of the eigenvector.
        if idx % stride == 0 {
            let ur = nalgebra::DVector::from_iterator(2 * n, e.vector.iter().map(|c| c.re));
            let ui = nalgebra::DVector::from_iterator(2 * n, e.vector.iter().map(|c| c.im));
            let (ar, ai) = (&o.a * ur, &o.a * ui);
            let r = (0..2 * n)
                .map(|i| (Complex::new(ar[i], ai[i]) - l * e.vector[i]).norm_sqr())
                .sum::<f64>()
                .sqrt();
            assert!(
                r <= 1e-12 * norm1,
                "λ = {l}: residual {r:e} (‖A‖₁ = {norm1:e})"
            );
        }
        // Mode shape: column `osc` of Q, largest entry scaled to exactly 1.
        let shape = mode_shape(e);
        let col = o.q.column(osc);
        let big = (0..n)
            .max_by(|&i, &j| col[i].abs().total_cmp(&col[j].abs()))
            .unwrap();
        assert_eq!(
            shape[big],
            Complex::new(1.0, 0.0),
            "λ = {l}: normalised entry"
        );
        for i in 0..n {
            let want = col[i] / col[big];
            worst_shape = worst_shape.max((shape[i] - want).norm() * gap / norm1);
            assert!(
                (shape[i] - want).norm() <= shape_tol * norm1 / gap,
                "λ = {l}: shape[{i}] = {} vs {want}",
                shape[i]
            );
        }
    }
    assert!(exact.is_empty());
    eprintln!(
        "{n} oscillators ({elapsed:.2?} for analyse_matrix): worst eigenvalue error {worst:e} of the spectral radius, \
         worst shape error {worst_shape:e}·‖A‖₁/gap"
    );
}

#[test]
fn small_path_is_exact_on_rotated_oscillators() {
    // 24 dofs = 48 states ≤ SMALL_MAX: balanced Francis QR + inverse iteration.
    const { assert!(48 <= SMALL_MAX) };
    check_oscillators(&oscillators(24, 11), 1e-12, 1e-14);
}

#[test]
fn large_path_is_exact_on_rotated_oscillators() {
    // 60 dofs = 120 states > SMALL_MAX: faer.
    const { assert!(120 > SMALL_MAX) };
    check_oscillators(&oscillators(60, 5), 1e-12, 1e-14);
}

/// 1000 dofs (2000 states), dense, against the exact eigenvalues and mode
/// shapes (≈ 10 s in the optimised test profile on one loaded core).
#[test]
fn thousand_dof_system_matches_exact_eigenvalues() {
    let o = oscillators(1000, 3);
    check_oscillators(&o, 1e-12, 1e-14);
}

#[test]
fn mode_shape_normalisation_and_phase() {
    // One mode of a hand-made vector: q = (0.5i, −1, 0.25), velocities λq.
    let lambda = Complex::new(-1.0, 10.0);
    let q = [
        Complex::new(0.0, 0.5),
        Complex::new(-1.0, 0.0),
        Complex::new(0.25, 0.0),
    ];
    let mut v: Vec<Complex<f64>> = q.to_vec();
    v.extend(q.iter().map(|c| c * lambda));
    let mut a = DMatrix::<f64>::zeros(6, 6); // only to build an Eigen through analyse_matrix
    for i in 0..3 {
        a[(i, 3 + i)] = 1.0;
        a[(3 + i, i)] = -(((i + 1) * (i + 1)) as f64);
    }
    let names: Vec<String> = ["x", "y", "z", "vx", "vy", "vz"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let an = analyse_matrix(&a, &[0.0; 6], &names, None).unwrap();
    let mut e = an.eigen[0].clone();
    e.vector = v;
    let shape = mode_shape(&e);
    let ap = amplitude_phase(&shape);
    // Largest |q_i| is y = −1 → reference: y becomes 1, x = −0.5i, z = −0.25.
    assert_eq!(shape[1], Complex::new(1.0, 0.0));
    assert!(
        (ap[0].0 - 0.5).abs() < 1e-15 && (ap[0].1 + 90.0).abs() < 1e-12,
        "{:?}",
        ap[0]
    );
    assert!(
        (ap[1].0 - 1.0).abs() < 1e-15 && ap[1].1 == 0.0,
        "{:?}",
        ap[1]
    );
    assert!(
        (ap[2].0 - 0.25).abs() < 1e-15 && ap[2].1 == 180.0,
        "{:?}",
        ap[2]
    );
    // Undamped oscillators ω = 1, 2, 3: frequencies exact, each mode a single coordinate.
    for e in &an.eigen {
        let w = e.im.abs();
        assert!(((w - w.round()).abs()) < 1e-14, "{}", e.im);
        let k = w.round() as usize - 1;
        assert_eq!(e.dominant_name, names[k]);
        let ap = amplitude_phase(&mode_shape(e));
        for (i, (amp, _)) in ap.iter().enumerate() {
            assert!((amp - if i == k { 1.0 } else { 0.0 }).abs() < 1e-12);
        }
    }
    let _ = PI;
}

#[test]
fn bad_matrices_are_refused_with_a_reason() {
    let names: Vec<String> = (0..4).map(|i| format!("s{i}")).collect();
    let z = [0.0; 4];
    let odd = DMatrix::<f64>::zeros(3, 3);
    assert!(matches!(
        analyse_matrix(&odd, &z[..3], &names[..3], None),
        Err(StabilityError::BadInput(_))
    ));
    let rect = DMatrix::<f64>::zeros(4, 2);
    assert!(matches!(
        analyse_matrix(&rect, &z, &names, None),
        Err(StabilityError::BadInput(_))
    ));
    let mut nan = DMatrix::<f64>::zeros(4, 4);
    nan[(1, 2)] = f64::NAN;
    assert!(matches!(
        analyse_matrix(&nan, &z, &names, None),
        Err(StabilityError::NonFinite { .. })
    ));
    let ok = DMatrix::<f64>::identity(4, 4);
    assert!(matches!(
        analyse_matrix(&ok, &z, &names, Some(&[1.0, -1.0])),
        Err(StabilityError::BadInput(_))
    ));
    assert!(matches!(
        analyse_matrix(&ok, &z[..2], &names, None),
        Err(StabilityError::BadInput(_))
    ));
    assert!(eigenpairs(&DMatrix::<f64>::zeros(0, 0)).unwrap().is_empty());
    // The zero matrix: every pivot of A − 0·I is zero; eigenvectors still finite, unit.
    for (l, u) in eigenpairs(&DMatrix::<f64>::zeros(4, 4)).unwrap() {
        assert_eq!(l, Complex::new(0.0, 0.0));
        let n2: f64 = u.iter().map(|c| c.norm_sqr()).sum();
        assert!((n2 - 1.0).abs() < 1e-15, "{u:?}");
    }
}
