//! Which real modes a complex mode is made of — what an NVH engineer reads
//! off a mode-coupling analysis before changing a design.
//!
//! The real modes are those of the linearised structure at steady sliding
//! without friction's non-symmetric part: `K_s φ = ω² M φ`, `K_s = (K +
//! Kᵀ)/2` (the basis the projected analysis uses,
//! [`super::projected::undamped_basis`]), `M`-orthonormal. A complex mode
//! shape `q` (the position part of an eigenvector) has the modal
//! coordinates `y = Φᵀ M q`, and its share of real mode `i` is
//! `|y_i|² / Σ_j |y_j|²` (the shares of a complete basis sum to 1; of a
//! truncated one, the part of `q`'s `M`-norm the basis holds is
//! [`Composition::captured`]). A squealing mode of a mode-coupling
//! instability is made of (at least) two real modes with comparable shares.

use super::projected::UndampedBasis;
use nalgebra::Complex;

/// One real mode's share of a complex mode.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Share {
    /// The real mode, 1-based in ascending frequency.
    pub mode: usize,
    /// Its undamped frequency (Hz).
    pub freq_hz: f64,
    /// Its share `|y_i|² / Σ|y_j|²`.
    pub share: f64,
}

/// What a complex mode is made of.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Composition {
    /// The real modes by share, largest first, down to `min_share`.
    pub shares: Vec<Share>,
    /// `‖Φ y‖²_M / ‖q‖²_M`: the part of the mode the basis holds (1 for a
    /// complete basis, to round-off).
    pub captured: f64,
}

/// The real modes of `basis` that the complex mode shape `q` (length `n`)
/// is made of, those with a share of at least `min_share`, at most `max`;
/// `mq` is `M q` (the caller multiplies: `M` dense or sparse).
pub fn composition(
    mq: &[Complex<f64>],
    basis: &UndampedBasis,
    q: &[Complex<f64>],
    min_share: f64,
    max: usize,
) -> Composition {
    let n = q.len();
    let norm_q: f64 = q.iter().zip(mq).map(|(a, b)| (a.conj() * b).re).sum();
    let cols = basis.phi.ncols();
    let y: Vec<Complex<f64>> = (0..cols)
        .map(|c| (0..n).fold(Complex::new(0.0, 0.0), |s, i| s + mq[i] * basis.phi[(i, c)]))
        .collect();
    let total: f64 = y.iter().map(|v| v.norm_sqr()).sum();
    let mut shares: Vec<Share> = y
        .iter()
        .enumerate()
        .map(|(i, v)| Share {
            mode: i + 1,
            freq_hz: basis.omega2[i].max(0.0).sqrt() / (2.0 * std::f64::consts::PI),
            share: if total > 0.0 {
                v.norm_sqr() / total
            } else {
                0.0
            },
        })
        .filter(|s| s.share >= min_share)
        .collect();
    shares.sort_by(|a, b| b.share.total_cmp(&a.share).then(a.mode.cmp(&b.mode)));
    shares.truncate(max);
    Composition {
        shares,
        captured: if norm_q > 0.0 { total / norm_q } else { 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn mass_times(m: &DMatrix<f64>, q: &[Complex<f64>]) -> Vec<Complex<f64>> {
        let n = q.len();
        (0..n)
            .map(|i| (0..n).fold(Complex::new(0.0, 0.0), |s, j| s + q[j] * m[(i, j)]))
            .collect()
    }
    use crate::stability::projected::{undamped_basis, Basis, SecondOrder};

    /// A 3-dof structure with a full mass matrix: a shape built from its
    /// real modes with known coefficients has exactly their shares; in a
    /// basis of two modes, the third's part is what the basis misses.
    #[test]
    fn shares_are_the_modal_coefficients() {
        let m = DMatrix::from_row_slice(3, 3, &[2.0, 0.3, 0.1, 0.3, 1.5, 0.2, 0.1, 0.2, 1.0]);
        let k = DMatrix::from_row_slice(3, 3, &[5e4, -2e4, 0.0, -2e4, 4e4, -1e4, 0.0, -1e4, 3e4]);
        let sys = SecondOrder {
            m: m.clone(),
            k,
            c: DMatrix::zeros(3, 3),
        };
        let full = undamped_basis(&sys, Basis::Modes(3)).unwrap();
        // q = (1 + 2i) φ1 + 0.5 φ3: shares 5 / 5.25 and 0.25 / 5.25.
        let a = Complex::new(1.0, 2.0);
        let b = Complex::new(0.5, 0.0);
        let q: Vec<Complex<f64>> = (0..3)
            .map(|i| a * full.phi[(i, 0)] + b * full.phi[(i, 2)])
            .collect();
        let c = composition(&mass_times(&m, &q), &full, &q, 0.0, 5);
        assert_eq!(c.shares[0].mode, 1);
        assert!((c.shares[0].share - 5.0 / 5.25).abs() < 1e-12);
        assert_eq!(c.shares[1].mode, 3);
        assert!((c.shares[1].share - 0.25 / 5.25).abs() < 1e-12);
        assert!(c.shares[2].share < 1e-24);
        assert!((c.captured - 1.0).abs() < 1e-12);
        assert!(
            (c.shares[0].freq_hz - full.omega2[0].sqrt() / (2.0 * std::f64::consts::PI)).abs()
                < 1e-12
        );
        // Two modes: mode 3 is outside; the basis holds 5 of 5.25.
        let two = undamped_basis(&sys, Basis::Modes(2)).unwrap();
        let c = composition(&mass_times(&m, &q), &two, &q, 0.01, 5);
        assert_eq!(c.shares.len(), 1);
        assert!((c.shares[0].share - 1.0).abs() < 1e-12);
        assert!((c.captured - 5.0 / 5.25).abs() < 1e-12);
    }
}
