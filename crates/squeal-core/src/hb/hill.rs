//! Hill's method: the Floquet exponents of a smooth HB orbit from the
//! Fourier series of its linearisation, without integrating a period.
//!
//! Perturb the orbit, `q + δq`, with `δq̈ = A^q(t) δq + A^v(t) δq̇` (the
//! field's derivatives along the orbit, periodic), and seek Floquet
//! solutions `δq = e^{λt} p(θ)`, `p` a series of the orbit's `H` harmonics,
//! `θ = ωt`. With `Λ = λ/ω` the Galerkin projection onto the same basis
//! (`D` the derivative `d/dθ` on it, `G^q`, `G^v` the projections of
//! `A^q`, `A^v`) gives the quadratic eigenproblem
//!
//! ```text
//! (Λ² I + Λ (2D − G^v/ω) + D² − G^q/ω² − G^v D/ω) P = 0,
//! ```
//!
//! of size `n(2H+1)`, solved as a companion problem of twice that size.
//! Each true exponent appears `2H+1` times, shifted by `ikω` (the same
//! solution written with `p e^{−ikθ}`); the `2n` kept are those whose
//! eigenvectors are centred on the lowest harmonics — the mean signed
//! harmonic index `Σ k|c_k|² / Σ|c_k|²` of `p` in complex exponentials
//! closest to zero (Lazarus & Thomas, C. R. Mécanique 338 (2010) 510–517;
//! Krack & Gross 2019, §3.5). The multipliers are `e^{λT}`.
//!
//! The projection is exact only where the field is smooth along the orbit:
//! a switch (a slip reversal, the loss of contact) makes `A` jump, and the
//! saltation at the switch, which the monodromy of [`crate::cycle`]
//! carries, has no place in `A`'s series. Orbits with switches are refused.

use super::{forcing_omega, Balance, HbError, HbOrbit, Layout};
use crate::model::System;
use crate::stability::modal::eigenpairs;
use nalgebra::{Complex, DMatrix};

/// The Floquet exponents and multipliers of a smooth orbit by Hill's method.
#[derive(Debug, Clone)]
pub struct Hill {
    /// The `2n` Floquet exponents `λ` (1/s), by real part, largest first.
    pub exponents: Vec<Complex<f64>>,
    /// `e^{λT}`, in the same order.
    pub multipliers: Vec<Complex<f64>>,
    /// Of an autonomous orbit, the index of the trivial exponent (the one
    /// nearest zero: the orbit's own phase shift).
    pub trivial: Option<usize>,
    /// The largest modulus among the non-trivial multipliers.
    pub max_multiplier: f64,
}

/// The Floquet exponents of the smooth orbit `orbit` of `sys` by Hill's
/// method (module documentation). Errors if the orbit has switches, sticks
/// or stick was a constraint (no smooth linearisation), or if the
/// eigenproblem fails.
pub fn hill<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    orbit: &HbOrbit,
) -> Result<Hill, HbError> {
    if orbit.switches > 0 || orbit.sticks || orbit.lagrangian {
        return Err(HbError::Bad(format!(
            "Hill's method needs a smooth orbit; this one has {} mode switches a period{}",
            orbit.switches,
            if orbit.sticks { " and sticks" } else { "" }
        )));
    }
    let f = &orbit.fourier;
    let (n, h) = (f.coeffs.len(), f.harmonics());
    let w = 2 * h + 1;
    let m = n * w;
    let omega = f.omega;
    let forced = forcing_omega(sys)?;
    let lay = Layout {
        n,
        h,
        panels: orbit.panels,
        scale: f
            .coeffs
            .iter()
            .map(|c| c.iter().fold(0.0f64, |a, x| a.max(x.abs())).max(1e-30))
            .collect(),
        omega0: omega,
        phase_dof: forced.is_none().then_some(0),
        mode: None,
        lagrangian: None,
    };
    let bal = Balance::<S, N>::new(sys, &lay)?;
    let pieces = bal.pieces(f);
    let nodes = bal.nodes(f, &pieces, 0.0);
    // G^q and G^v (unscaled), rows i·w + j, columns l·w + c, from the
    // moments of each A_il over the period.
    use super::jacobian::{Moments, Trig};
    let mut mq = vec![Moments::new(h); n * n];
    let mut mv = vec![Moments::new(h); n * n];
    let mut trig = Trig::new(h);
    for nd in &nodes {
        trig.at(nd.theta);
        for k in 0..n * n {
            if nd.aq[k] != 0.0 {
                mq[k].add(&trig, nd.weight * nd.aq[k]);
            }
            if nd.av[k] != 0.0 {
                mv[k].add(&trig, nd.weight * nd.av[k]);
            }
        }
    }
    let mut gq = DMatrix::<f64>::zeros(m, m);
    let mut gv = DMatrix::<f64>::zeros(m, m);
    for i in 0..n {
        for l in 0..n {
            for j in 0..w {
                for c in 0..w {
                    gq[(i * w + j, l * w + c)] = mq[i * n + l].galerkin(j, c);
                    gv[(i * w + j, l * w + c)] = mv[i * n + l].galerkin(j, c);
                }
            }
        }
    }
    // d/dθ on the basis: (cos kθ)' = −k sin kθ, (sin kθ)' = k cos kθ.
    let mut d = DMatrix::<f64>::zeros(m, m);
    for i in 0..n {
        for k in 1..=h {
            let (c, s) = (i * w + 2 * k - 1, i * w + 2 * k);
            d[(s, c)] = -(k as f64);
            d[(c, s)] = k as f64;
        }
    }
    let m1 = &d * 2.0 - &gv / omega;
    let m0 = &d * &d - &gq / (omega * omega) - &gv * &d / omega;
    let mut a = DMatrix::<f64>::zeros(2 * m, 2 * m);
    for r in 0..m {
        a[(r, m + r)] = 1.0;
        for c in 0..m {
            a[(m + r, c)] = -m0[(r, c)];
            a[(m + r, m + c)] = -m1[(r, c)];
        }
    }
    let pairs =
        eigenpairs(&a).map_err(|e| HbError::NotConverged(format!("Hill's eigenproblem: {e}")))?;
    // The mean signed harmonic index of each eigenvector's p.
    let centre = |x: &[Complex<f64>]| {
        let (mut num, mut den) = (0.0, 0.0);
        for l in 0..n {
            den += x[l * w].norm_sqr();
            for k in 1..=h {
                let (a, b) = (x[l * w + 2 * k - 1], x[l * w + 2 * k]);
                let i = Complex::new(0.0, 1.0);
                let plus = (a - i * b) * 0.5;
                let minus = (a + i * b) * 0.5;
                num += k as f64 * (plus.norm_sqr() - minus.norm_sqr());
                den += plus.norm_sqr() + minus.norm_sqr();
            }
        }
        if den > 0.0 {
            (num / den).abs()
        } else {
            f64::INFINITY
        }
    };
    let mut ranked: Vec<(f64, Complex<f64>)> = pairs
        .iter()
        .map(|(lam, x)| (centre(&x[..m]), lam * omega))
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.re.total_cmp(&a.1.re)));
    let mut exponents: Vec<Complex<f64>> = ranked.iter().take(2 * n).map(|r| r.1).collect();
    exponents.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
    let period = std::f64::consts::TAU / omega;
    let multipliers: Vec<Complex<f64>> = exponents.iter().map(|l| (l * period).exp()).collect();
    let trivial = forced.is_none().then(|| {
        (0..exponents.len())
            .min_by(|&a, &b| exponents[a].norm().total_cmp(&exponents[b].norm()))
            .unwrap_or(0)
    });
    let max_multiplier = multipliers
        .iter()
        .enumerate()
        .filter(|&(k, _)| Some(k) != trivial)
        .map(|(_, mu)| mu.norm())
        .fold(0.0, f64::max);
    Ok(Hill {
        exponents,
        multipliers,
        trivial,
        max_multiplier,
    })
}
