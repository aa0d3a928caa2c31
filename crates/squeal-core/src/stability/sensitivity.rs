//! How an eigenvalue of steady sliding moves when a parameter moves: the
//! first-order perturbation of a simple eigenvalue (issue 26 §4).
//!
//! For a simple eigenvalue `λ` of the state matrix `A(p)` with right
//! eigenvector `x` (`A x = λ x`) and left eigenvector `y` (`yᴴ A = λ yᴴ`),
//!
//! ```text
//! dλ/dp = yᴴ (dA/dp) x / (yᴴ x)
//! ```
//!
//! (J. H. Wilkinson, *The Algebraic Eigenvalue Problem*, 1965, §2.8–2.10;
//! P. Lancaster, *On eigenvalues of matrices dependent on a parameter*,
//! Numer. Math. 6, 1964). `dA/dp` is the whole change of the linearisation,
//! the steady state's own change included (`A` is the Jacobian *at* steady
//! sliding, which moves with `p`). The growth rate's sensitivity is
//! `dσ/dp = Re dλ/dp` and the frequency's `Im(dλ/dp)/2π`.
//!
//! The eigenvalue's condition number `κ = ‖x‖ ‖y‖ / |yᴴ x|` is 1 for a normal
//! matrix and grows without bound as two eigenvalues coalesce (the onset of
//! mode-coupling flutter): there `λ` is not differentiable (it moves like
//! `√(p − p*)`) and [`Eigenvectors::derivative`] is meaningless, which
//! [`Eigenvectors::defective`] says.

use nalgebra::{Complex, DMatrix, DVector};

/// Condition number above which an eigenvalue is treated as defective (at a
/// coalescence): [`Eigenvectors::defective`]. A simple eigenvalue of the
/// models here has `κ` below 1e4; at a coalescence computed eigenvectors
/// give `κ` ≈ 1e7–1e8 (round-off keeps `yᴴx` from vanishing exactly).
pub const DEFECTIVE_CONDITION: f64 = 1e6;

/// The right and left eigenvectors of one eigenvalue of a real matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct Eigenvectors {
    /// The eigenvalue.
    pub lambda: Complex<f64>,
    /// `x`: `A x = λ x`, unit 2-norm.
    pub right: DVector<Complex<f64>>,
    /// `y`: `yᴴ A = λ yᴴ`, unit 2-norm.
    pub left: DVector<Complex<f64>>,
}

impl Eigenvectors {
    /// Both eigenvectors of the eigenvalue `lambda` of `a` (square, finite)
    /// by inverse iteration: three solves with the LU factors of
    /// `A − s I` and of its adjoint, with the shift `s = λ + 64 ε ‖A‖∞ (1 + i)`
    /// (a shift within round-off of `λ` converges to `λ`'s eigenvectors in
    /// one step; the offset keeps the factors regular). `None` if `a` is not
    /// square or a solve fails.
    pub fn of(a: &DMatrix<f64>, lambda: Complex<f64>) -> Option<Self> {
        let n = a.nrows();
        if n == 0 || a.ncols() != n || a.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let norm = a
            .row_iter()
            .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0f64, f64::max)
            .max(f64::MIN_POSITIVE);
        let shift = lambda + Complex::new(1.0, 1.0) * (64.0 * f64::EPSILON * norm);
        let b = DMatrix::from_fn(n, n, |i, j| {
            Complex::new(a[(i, j)], 0.0)
                - if i == j {
                    shift
                } else {
                    Complex::new(0.0, 0.0)
                }
        });
        let right = inverse_iteration(b.clone().lu(), n)?;
        let left = inverse_iteration(b.adjoint().lu(), n)?;
        Some(Eigenvectors {
            lambda,
            right,
            left,
        })
    }

    /// `yᴴ x` of the unit eigenvectors: `1/κ`.
    fn overlap(&self) -> Complex<f64> {
        self.left.dotc(&self.right)
    }

    /// The eigenvalue's condition number `κ = ‖x‖ ‖y‖ / |yᴴ x|` (≥ 1).
    pub fn condition(&self) -> f64 {
        1.0 / self.overlap().norm()
    }

    /// Whether the eigenvalue is (numerically) defective, at a coalescence
    /// of two modes: `κ` > [`DEFECTIVE_CONDITION`]. Its derivative is then
    /// undefined.
    pub fn defective(&self) -> bool {
        let k = self.condition();
        k.is_nan() || k > DEFECTIVE_CONDITION
    }

    /// `dλ/dp = yᴴ (dA/dp) x / (yᴴ x)` for the change `da` = `dA/dp` of the
    /// matrix (same size). Meaningless where [`defective`](Self::defective).
    pub fn derivative(&self, da: &DMatrix<f64>) -> Complex<f64> {
        let dx: DVector<Complex<f64>> = DVector::from_fn(da.nrows(), |i, _| {
            (0..da.ncols())
                .map(|j| self.right[j] * da[(i, j)])
                .sum::<Complex<f64>>()
        });
        self.left.dotc(&dx) / self.overlap()
    }
}

/// Three steps of inverse iteration with the factors `lu` from a fixed,
/// deterministic start vector; unit 2-norm.
fn inverse_iteration(
    lu: nalgebra::linalg::LU<Complex<f64>, nalgebra::Dyn, nalgebra::Dyn>,
    n: usize,
) -> Option<DVector<Complex<f64>>> {
    // A start with a component along every eigenvector (not a multiple of
    // any structured vector): 1 + i·k/n for k = 0..n.
    let mut v = DVector::from_fn(n, |k, _| Complex::new(1.0, k as f64 / n as f64));
    for _ in 0..3 {
        v = lu.solve(&v)?;
        let s = v.norm();
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        v /= Complex::new(s, 0.0);
    }
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `A(p) = [[p, 1], [−1, −1]]`: λ² − (p − 1) λ + (1 − p) = 0, so
    /// dλ/dp = (λ + 1)/(2λ − p + 1) exactly.
    #[test]
    fn derivative_matches_the_characteristic_polynomial() {
        let p = 0.3;
        let a = DMatrix::from_row_slice(2, 2, &[p, 1.0, -1.0, -1.0]);
        let tr: f64 = p - 1.0;
        let det = 1.0 - p;
        let disc = Complex::new(tr * tr - 4.0 * det, 0.0).sqrt();
        let lambda = (Complex::new(tr, 0.0) + disc) / 2.0;
        let e = Eigenvectors::of(&a, lambda).unwrap();
        let da = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        let exact = (lambda + 1.0) / (lambda * 2.0 - p + 1.0);
        let got = e.derivative(&da);
        assert!(
            (got - exact).norm() <= 1e-13 * exact.norm(),
            "{got} vs {exact}"
        );
        assert!(!e.defective());
    }

    /// A symmetric matrix: left = right, κ = 1, dλ/dp = xᵀ (dA/dp) x.
    #[test]
    fn a_symmetric_matrix_is_perfectly_conditioned() {
        let a = DMatrix::from_row_slice(3, 3, &[2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0]);
        let ev = a.clone().symmetric_eigen();
        let vals: Vec<f64> = ev.eigenvalues.iter().copied().collect();
        let k = (0..3).max_by(|&i, &j| vals[i].total_cmp(&vals[j])).unwrap();
        let e = Eigenvectors::of(&a, Complex::new(vals[k], 0.0)).unwrap();
        assert!((e.condition() - 1.0).abs() < 1e-12, "{}", e.condition());
        let da = DMatrix::from_row_slice(3, 3, &[0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        let x = ev.eigenvectors.column(k);
        let got = e.derivative(&da);
        assert!(
            (got.re - x[1] * x[1]).abs() < 1e-13 && got.im.abs() < 1e-13,
            "{got}"
        );
    }

    /// At a coalescence (a Jordan block) the eigenvalue is defective.
    #[test]
    fn a_jordan_block_is_defective() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0]);
        let e = Eigenvectors::of(&a, Complex::new(1.0, 0.0)).unwrap();
        assert!(e.defective(), "κ = {}", e.condition());
    }
}
