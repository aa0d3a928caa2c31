//! Stability of lumped models of any size: the steady-sliding state by
//! Newton's method, the analytic state matrix (dense, `2n × 2n`), balancing,
//! and a dense eigen-solve. Models small enough for the fixed-size path
//! ([`crate::model::lumped::MAX_SIM_DOFS`] dofs) go through
//! [`super::analyse`] instead.

use super::{is_growing, Analysis, Eigen, StabilityError};
use crate::model::lumped::Lumped;
use nalgebra::DMatrix;

/// The steady-sliding state and the state matrix there, both checked finite.
pub fn state_matrix(l: &Lumped) -> Result<(Vec<f64>, DMatrix<f64>), StabilityError> {
    let z = l.equilibrium_dyn()?;
    if z.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite {
            what: "equilibrium",
        });
    }
    let a = l.jacobian_dyn(&z);
    if a.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite { what: "Jacobian" });
    }
    Ok((z, a))
}

/// Parlett–Reinsch balancing with radix 2 (as [`super::eigen::balance`]), in
/// place; returns the diagonal of `D` (`a ← D⁻¹ a D`).
pub fn balance(a: &mut DMatrix<f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut d = vec![1.0; n];
    for _ in 0..super::eigen::MAX_BALANCE_SWEEPS {
        let mut done = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += a[(j, i)].abs();
                    r += a[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            while c < r / 2.0 {
                f *= 2.0;
                c *= 4.0;
            }
            while c > r * 2.0 {
                f /= 2.0;
                c /= 4.0;
            }
            if (c + r) / f < 0.95 * s {
                done = false;
                d[i] *= f;
                for j in 0..n {
                    a[(i, j)] /= f;
                }
                for j in 0..n {
                    a[(j, i)] *= f;
                }
            }
        }
        if done {
            break;
        }
    }
    d
}

/// All eigenvalues of the balanced state matrix (Schur decomposition).
pub fn eigenvalues(l: &Lumped) -> Result<Vec<nalgebra::Complex<f64>>, StabilityError> {
    let (_, mut a) = state_matrix(l)?;
    balance(&mut a);
    let ev = a
        .try_schur(f64::EPSILON, 10_000)
        .ok_or(StabilityError::NoConvergence)?
        .complex_eigenvalues();
    Ok(ev.iter().copied().collect())
}

/// Largest growth rate and its frequency (Hz), for maps and `critical`.
pub fn max_growth_rate(l: &Lumped) -> Result<(f64, f64), StabilityError> {
    let ev = eigenvalues(l)?;
    let mut best = nalgebra::Complex::new(f64::NEG_INFINITY, 0.0);
    for e in ev {
        if e.re > best.re || (e.re == best.re && e.im > best.im) {
            best = e;
        }
    }
    Ok((best.re, best.im.abs() / (2.0 * std::f64::consts::PI)))
}

/// Eigenvalues of a large lumped model as an [`Analysis`]: growth rates,
/// frequencies and damping ratios of every mode. Mode shapes are not
/// computed on this path (`vector` and `participation` are empty,
/// `dominant_name` is empty).
pub fn analyse(l: &Lumped, _masses: Option<&[f64]>) -> Result<Analysis, StabilityError> {
    let z = l.equilibrium_dyn()?;
    let ev = eigenvalues(l)?;
    let mut modes: Vec<Eigen> = ev
        .iter()
        .map(|lambda| {
            let mag = lambda.norm();
            Eigen {
                re: lambda.re,
                im: lambda.im,
                freq_hz: lambda.im.abs() / (2.0 * std::f64::consts::PI),
                damping_ratio: if mag > 0.0 { -lambda.re / mag } else { 0.0 },
                growing: is_growing(lambda.re, lambda.im),
                dominant: 0,
                dominant_name: String::new(),
                participation: Vec::new(),
                vector: Vec::new(),
            }
        })
        .collect();
    modes.sort_by(|p, q| q.re.total_cmp(&p.re).then(q.im.total_cmp(&p.im)));
    Ok(Analysis {
        max_growth_rate: modes.first().map_or(f64::NEG_INFINITY, |m| m.re),
        stable: !modes.iter().any(|m| m.growing),
        least_stable: 0,
        equilibrium: z,
        eigen: modes,
    })
}
