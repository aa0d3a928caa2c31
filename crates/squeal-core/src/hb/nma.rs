//! Nonlinear modes by the extended periodic motion concept (EPMC, Krack
//! 2015): the amplitude-dependent frequency and damping of a mode of a
//! damped (friction-damped) system.
//!
//! A damped system has no periodic free motion; the EPMC adds the
//! artificial negative damping `−ξ M q̇` that makes one, `M q̈ + … − ξ M q̇ =
//! 0` — in squeal's acceleration form `q̈ = a(q, q̇) + ξ q̇` — and solves for
//! the orbit, its frequency `ω` and `ξ` at a prescribed amplitude. The
//! energy `ξ ∮ q̇ᵀ M q̇ dt` it feeds in per period is what the system
//! dissipates, so `D = ξ / (2ω)` is the mode's damping ratio at that
//! amplitude (exact for the linear mode of a mass-proportionally damped
//! system, where `ξ` is the damping itself). The harmonic balance of
//! [`super`] with two more equations closes the unknowns (coefficients,
//! `ω`, `ξ`): the phase of the mode's first harmonic, `φᵀ M b₁ = 0`, and
//! its mass-normalised amplitude, `a₁ᵀ M a₁ + b₁ᵀ M b₁ = A²` (a mode `q = A φ
//! cos ωt`, `φᵀMφ = 1`, has amplitude `A`).
//!
//! Krack, "Nonlinear modal analysis of nonconservative systems: extension
//! of the periodic motion concept", Computers & Structures 154 (2015)
//! 59–71; Krack & Gross (2019), §4.5.

use super::{
    checked_guess, forcing_omega, harmonic_amplitudes, newton, Balance, Fourier, HbError,
    HbOptions, HbOrbit, Layout, ModeNorm,
};
use nalgebra::DMatrix;

/// A point of a nonlinear mode.
#[derive(Debug, Clone)]
pub struct ModePoint {
    /// The mass-normalised modal amplitude `A`.
    pub amplitude: f64,
    /// The orbit (its series, frequency, contact modes).
    pub orbit: HbOrbit,
    /// The artificial damping `ξ` (1/s).
    pub xi: f64,
}

impl ModePoint {
    /// The frequency (Hz).
    pub fn freq_hz(&self) -> f64 {
        self.orbit.fourier.omega / std::f64::consts::TAU
    }

    /// The modal damping ratio `D = ξ / (2ω)`.
    pub fn damping_ratio(&self) -> f64 {
        self.xi / (2.0 * self.orbit.fourier.omega)
    }
}

/// The guess of a mode at amplitude `A` from its linear shape: `q = q* +
/// A φ cos θ` at frequency `omega`.
pub fn mode_guess(static_q: &[f64], phi: &[f64], omega: f64, amplitude: f64) -> Fourier {
    Fourier {
        omega,
        coeffs: static_q
            .iter()
            .zip(phi)
            .map(|(q, p)| vec![*q, amplitude * p, 0.0])
            .collect(),
    }
}

/// The nonlinear mode of the autonomous system `sys` (mass matrix `mass`)
/// whose low-amplitude shape is `phi` (mass normalised), at the modal
/// amplitude `amplitude`, from the guess `guess` (the series and `ξ`; a
/// neighbouring amplitude's solution, or [`mode_guess`] with `ξ` the
/// linear mode's damping), module documentation.
pub fn nonlinear_mode<S: crate::model::System<N> + ?Sized, const N: usize>(
    sys: &S,
    mass: &DMatrix<f64>,
    phi: &[f64],
    amplitude: f64,
    guess: (&Fourier, f64),
    opts: &HbOptions,
) -> Result<ModePoint, HbError> {
    if forcing_omega(sys)?.is_some() {
        return Err(HbError::Bad(
            "the model is forced: nonlinear modes are of the autonomous model (drop the harmonic forces)".into(),
        ));
    }
    if !(amplitude > 0.0 && amplitude.is_finite()) {
        return Err(HbError::Bad(format!("modal amplitude {amplitude}")));
    }
    let (g, n) = checked_guess(sys, guess.0, opts)?;
    if phi.len() != n || mass.nrows() != n || mass.ncols() != n {
        return Err(HbError::Bad(format!(
            "the mode has {} entries and the mass matrix {}×{}, the model {n} dofs",
            phi.len(),
            mass.nrows(),
            mass.ncols()
        )));
    }
    let m_phi: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| mass[(i, j)] * phi[j]).sum())
        .collect();
    let amp = harmonic_amplitudes(&g);
    let top = amp.iter().cloned().fold(0.0, f64::max);
    if !(top > 0.0 && top.is_finite()) {
        return Err(HbError::Bad(
            "the guess does not oscillate (zero first harmonics)".into(),
        ));
    }
    let phase_dof = (0..n)
        .max_by(|&a, &b| phi[a].abs().total_cmp(&phi[b].abs()))
        .unwrap_or(0);
    let lay = Layout {
        n,
        h: opts.harmonics,
        panels: opts.panel_count(),
        scale: amp.iter().map(|a| a.max(1e-6 * top)).collect(),
        omega0: g.omega,
        phase_dof: Some(phase_dof),
        mode: Some(ModeNorm {
            mass: mass.clone(),
            m_phi,
            amplitude,
        }),
        lagrangian: opts.lagrangian.then_some(opts.lagrangian_weight),
    };
    let bal = Balance::<S, N>::new(sys, &lay)?;
    let m = lay.unknowns();
    let mut x0 = lay.to_x(&g);
    x0[m - 1] = guess.1 / g.omega;
    let res = |x: &[f64], out: &mut [f64]| bal.residual(x, out);
    let w = lay.n * lay.width();
    let solved = newton(
        &res,
        &|x, r, d| bal.jacobian(x, r, d),
        &|x| x[w] > 0.0,
        x0,
        opts.newton_tol,
        opts.newton_iterations,
        &format!("nonlinear mode, H = {}", opts.harmonics),
    )?;
    Ok(ModePoint {
        amplitude,
        xi: solved.x[m - 1] * lay.omega0,
        orbit: bal.orbit(
            &solved.x,
            solved.residual,
            solved.iterations,
            solved.converged,
        ),
    })
}
