//! `squeal nma SCENARIO --mode K --modal-amplitude LO:HI:N`: the nonlinear
//! mode K of a lumped or matrix model by the extended periodic motion
//! concept (`squeal_core::hb::nma`): its frequency and damping ratio at
//! log-spaced mass-normalised modal amplitudes. Mode K is the K-th (by
//! frequency, from 1) undamped mode of the model linearised with its
//! contacts stuck (`Lumped::stuck_modes`), the low-amplitude limit of a
//! friction-damped mode, at steady sliding (or at rest where the model has
//! none, e.g. contacts on a fixed surface, V = 0).

use crate::error::{Cancel, StudyError};
use crate::model::AnyModel;
use crate::scenario::{InputError, Scenario};
use serde_json::{json, Value};
use squeal_core::hb::nma::{mode_guess, nonlinear_mode, ModePoint};
use squeal_core::hb::{Fourier, HbOptions};
use squeal_core::System;

/// Most modal amplitudes of one `nma` run.
pub const MAX_AMPLITUDES: usize = 1000;

/// One amplitude of a nonlinear mode.
#[derive(Debug, Clone, PartialEq)]
pub struct NmaRow {
    /// Mass-normalised modal amplitude (m·√kg).
    pub modal_amplitude: f64,
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// The EPMC's artificial damping ξ (1/s).
    pub xi: f64,
    /// Modal damping ratio `ξ / 2ω`.
    pub damping_ratio: f64,
    /// Half peak-to-peak of each state over the period.
    pub amplitude: Vec<f64>,
    /// Scaled HB residual.
    pub residual: f64,
    /// Whether a contact sticks somewhere on the orbit.
    pub sticks: bool,
    /// Whether stick was a constraint (the dynamic Lagrangian step): an
    /// orbit that sticks is then exact in the limit of many harmonics;
    /// without it HB treats stick as slip at zero speed (not exact).
    pub stick_constraint: bool,
}

/// A nonlinear mode over amplitudes.
#[derive(Debug, Clone)]
pub struct NmaFound {
    /// The mode's number (from 1).
    pub mode: usize,
    /// Its linear (stuck) frequency (Hz).
    pub linear_hz: f64,
    /// Harmonics.
    pub harmonics: usize,
    /// State names.
    pub names: Vec<String>,
    /// The solved amplitudes, ascending.
    pub rows: Vec<NmaRow>,
    /// `(modal amplitude, why)` where HB gave no solution.
    pub failures: Vec<(f64, String)>,
    /// What the numbers do not support.
    pub warnings: Vec<String>,
}

/// Parse `--modal-amplitude LO:HI:N` (0 < LO < HI, 2 ≤ N ≤
/// [`MAX_AMPLITUDES`]; log-spaced).
pub fn parse_amplitudes(spec: &str) -> Result<Vec<f64>, InputError> {
    let bad = || {
        InputError(format!(
            "--modal-amplitude {spec}: expected LO:HI:N with 0 < LO < HI and 2 ≤ N ≤ {MAX_AMPLITUDES} (log-spaced mass-normalised modal amplitudes)"
        ))
    };
    let p: Vec<&str> = spec.split(':').collect();
    if p.len() != 3 {
        return Err(bad());
    }
    let lo: f64 = p[0].trim().parse().map_err(|_| bad())?;
    let hi: f64 = p[1].trim().parse().map_err(|_| bad())?;
    let n: usize = p[2].trim().parse().map_err(|_| bad())?;
    if !(lo > 0.0 && hi > lo && hi.is_finite() && (2..=MAX_AMPLITUDES).contains(&n)) {
        return Err(bad());
    }
    let (a, b) = (lo.ln(), hi.ln());
    Ok((0..n)
        .map(|i| (a + (b - a) * i as f64 / (n - 1) as f64).exp())
        .collect())
}

/// Nonlinear mode `mode` (from 1) of `sc` at `amplitudes` with `harmonics` harmonics.
pub fn of_scenario(
    sc: &Scenario,
    mode: usize,
    amplitudes: &[f64],
    harmonics: usize,
    cancel: &Cancel,
) -> Result<NmaFound, StudyError> {
    crate::hb::check_harmonics(harmonics)?;
    let AnyModel::Lumped(l) = &sc.model else {
        return Err(InputError(format!(
            "nma: model {} is built in; nonlinear modes need a lumped or matrix model (its mass matrix): write it as a lumped scenario",
            sc.model.name()
        ))
        .into());
    };
    if let Some(f) = l.forcing_hz().first() {
        return Err(InputError(format!(
            "nma: the model is forced (a harmonic force at {f} Hz): nonlinear modes are of the autonomous model; set the force's amplitude to 0"
        ))
        .into());
    }
    sc.model.check_cycle_size().map_err(InputError)?;
    let n = l.dof_count();
    let mut warnings = Vec::new();
    let z_static = match l.equilibrium_dyn() {
        Ok(z) => z,
        Err(e) => {
            warnings.push(format!("{e}: the modes are taken at rest (q = 0)"));
            vec![0.0; 2 * n]
        }
    };
    let stuck = l
        .stuck_modes(&z_static)
        .map_err(|e| InputError(format!("nma: {e}")))?;
    let count = stuck.modes.len();
    if mode == 0 || mode > count {
        return Err(InputError(format!(
            "--mode {mode}: the model linearised with its contacts stuck has {count} modes (1…{count})"
        ))
        .into());
    }
    let (w, phi) = stuck.modes[mode - 1].clone();
    if w.is_nan() || w <= 0.0 {
        return Err(InputError(format!(
            "--mode {mode}: a rigid-body mode (zero frequency) of the stuck model"
        ))
        .into());
    }
    // The linear damping of the mode, φᵀ C φ = 2ζω, as the first ξ.
    let c = l.second_order_dyn(&z_static).c;
    let xi0: f64 = (0..n)
        .map(|i| (0..n).map(|j| phi[i] * c[(i, j)] * phi[j]).sum::<f64>())
        .sum();
    let names = sc.model.state_names();
    let opts = HbOptions {
        harmonics,
        ..HbOptions::default()
    };
    let q0: Vec<f64> = z_static[..n].to_vec();
    // A regularised law never sticks: stick as a constraint is tried only
    // where a contact can stick.
    let can_stick = l
        .contacts
        .iter()
        .any(|c| !matches!(c.friction, squeal_core::FrictionLaw::Tanh { .. }));
    let (rows, failures) = crate::with_sim_system!(&sc.model, m => {
        sweep(m, &stuck.mass, &phi, &q0, w, xi0, amplitudes, &opts, can_stick, cancel)?
    }, else => return Err(StudyError::Input(InputError(sc.model.check_cycle_size().err().unwrap_or_default()))));
    let inexact: Vec<f64> = rows
        .iter()
        .filter(|r| r.sticks && !r.stick_constraint)
        .map(|r| r.modal_amplitude)
        .collect();
    if !inexact.is_empty() {
        warnings.push(format!(
            "a contact sticks on the orbits at modal amplitudes {inexact:?}, where stick as a constraint (the dynamic Lagrangian step) did not converge: there harmonic balance treats stick as slip at zero speed, so those points are not exact"
        ));
    }
    if rows.iter().any(|r| r.stick_constraint) {
        warnings.push(
            "where a contact sticks on the orbit (points marked sticks), stick is a constraint (dynamic Lagrangian step): the kinks at stick make the convergence in the harmonics algebraic; compare a higher --harmonics".into(),
        );
    }
    Ok(NmaFound {
        mode,
        linear_hz: w / std::f64::consts::TAU,
        harmonics,
        names,
        rows,
        failures,
        warnings,
    })
}

type Swept = (Vec<NmaRow>, Vec<(f64, String)>);

/// The mode at each amplitude, each from the last solution scaled to it
/// (else from the linear mode).
#[allow(clippy::too_many_arguments)]
fn sweep<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    mass: &nalgebra::DMatrix<f64>,
    phi: &[f64],
    q0: &[f64],
    w: f64,
    xi0: f64,
    amplitudes: &[f64],
    opts: &HbOptions,
    can_stick: bool,
    cancel: &Cancel,
) -> Result<Swept, StudyError> {
    let real = crate::cycle::real_states::<N>(m.norm_states());
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    let mut last: Option<(Fourier, f64, f64)> = None;
    // From the last solution `(series, ξ, amplitude)` scaled to `a`.
    let scaled = |(f, xi, a0): &(Fourier, f64, f64), a: f64| {
        let mut g = f.clone();
        for (c, q) in g.coeffs.iter_mut().zip(q0) {
            c[0] = q + (c[0] - q) * a / a0;
            for v in c.iter_mut().skip(1) {
                *v *= a / a0;
            }
        }
        (g, *xi)
    };
    // Friction as slip first (cheaper, exact where nothing sticks); an
    // orbit that sticks, or a point where that fails, again with stick as
    // a constraint from the same start (as `squeal hb` does).
    let stick_opts = HbOptions {
        lagrangian: true,
        ..*opts
    };
    let solve = |a: f64, g: &Fourier, xi: f64| {
        let slip = nonlinear_mode(m, mass, phi, a, (g, xi), opts);
        match &slip {
            _ if !can_stick => slip,
            Ok(p) if !p.orbit.sticks => slip,
            Ok(p) => {
                nonlinear_mode(m, mass, phi, a, (&p.orbit.fourier, p.xi), &stick_opts).or(slip)
            }
            Err(_) => nonlinear_mode(m, mass, phi, a, (g, xi), &stick_opts).or(slip),
        }
    };
    for &a in amplitudes {
        cancel.check()?;
        let linear = mode_guess(q0, phi, w, a);
        let mut tried: Result<ModePoint, _> = match &last {
            Some(l) => {
                let (g, xi) = scaled(l, a);
                solve(a, &g, xi)
            }
            None => solve(a, &linear, xi0),
        };
        // Where the mode changes fast (a damper going from stick to slip),
        // walk to `a` in geometrically halved steps from the last solution
        // (at most 64 of them).
        if let (Err(_), Some(l)) = (&tried, &last) {
            let mut from = l.clone();
            let mut step = (a / from.2).ln();
            let mut left = 64;
            while left > 0 && (a / from.2).ln() > 1e-12 {
                left -= 1;
                let next = (from.2 * step.exp()).min(a);
                let (g, xi) = scaled(&from, next);
                match solve(next, &g, xi) {
                    Ok(p) => {
                        from = (p.orbit.fourier.clone(), p.xi, next);
                        step = (step * 1.5).min((a / next).ln().max(0.0));
                        if next >= a {
                            tried = Ok(p);
                            break;
                        }
                    }
                    Err(e) => {
                        step *= 0.5;
                        tried = Err(e);
                    }
                }
            }
        }
        if tried.is_err() {
            tried = solve(a, &linear, xi0);
        }
        match tried {
            Ok(p) => {
                let amp = crate::hb::amplitudes::<N>(&p.orbit.fourier);
                rows.push(NmaRow {
                    modal_amplitude: a,
                    freq_hz: p.freq_hz(),
                    xi: p.xi,
                    damping_ratio: p.damping_ratio(),
                    amplitude: real.iter().map(|&i| amp[i]).collect(),
                    residual: p.orbit.residual,
                    sticks: p.orbit.sticks,
                    stick_constraint: p.orbit.lagrangian,
                });
                last = Some((p.orbit.fourier, p.xi, a));
            }
            Err(e) => failures.push((a, e.to_string())),
        }
    }
    Ok((rows, failures))
}

impl NmaFound {
    /// The JSON document: `mode`, `linear_hz`, `harmonic_count`, `points`
    /// (per amplitude `modal_amplitude`, `freq_hz`, `xi`, `damping_ratio`,
    /// `amplitude` per state, `residual`, `sticks`, `stick_constraint`), `failures` and
    /// `warnings`.
    pub fn to_json(&self) -> Value {
        let points: Vec<Value> = self
            .rows
            .iter()
            .map(|r| {
                json!({
                    "modal_amplitude": r.modal_amplitude,
                    "freq_hz": r.freq_hz,
                    "xi": r.xi,
                    "damping_ratio": r.damping_ratio,
                    "amplitude": crate::cycle::named_json(&self.names, &r.amplitude),
                    "residual": r.residual,
                    "sticks": r.sticks,
                    "stick_constraint": r.stick_constraint,
                })
            })
            .collect();
        json!({
            "method": "nonlinear mode (extended periodic motion concept, harmonic balance)",
            "mode": self.mode,
            "linear_hz": self.linear_hz,
            "harmonic_count": self.harmonics,
            "points": points,
            "failures": self.failures.iter().map(|(a, w)| json!({"modal_amplitude": a, "why": w})).collect::<Vec<_>>(),
            "warnings": self.warnings,
        })
    }
}
