//! Hill's method against the monodromy of shooting: van der Pol's limit
//! cycle (autonomous: one trivial exponent, the other from the exact flow)
//! and a forced Duffing oscillator past its linear resonance; and the
//! refusal of an orbit with switches, whose saltation Hill's series cannot
//! hold.

use crate::hb_forced::oscillator;
use squeal_core::cycle::{self, find_cycle, forced_floquet, CycleOptions};
use squeal_core::hb::hill::hill;
use squeal_core::hb::{forced_response, harmonic_balance, Fourier, HbOptions};
use squeal_core::model::lumped::Fixed;
use squeal_core::System;
use std::f64::consts::TAU;

fn harmonics(h: usize) -> HbOptions {
    HbOptions {
        harmonics: h,
        ..HbOptions::default()
    }
}

/// Van der Pol, ε = 1: Liouville's formula makes the non-trivial exponent
/// the mean of the trace, `⟨ε(1 − x²)⟩` over the period (the trivial one is
/// zero), here from the H = 40 series sampled densely (spectrally
/// accurate). Hill's method on the HB orbit converges to it exponentially
/// in H, as the orbit does, and agrees with shooting's multiplier
/// (μ ≈ 8.6e-4, `ln|μ|/T`) to that multiplier's own accuracy.
#[test]
fn hill_gives_van_der_pols_floquet_exponent() {
    let model = crate::cycle::VanDerPol(1.0);
    let cyc = find_cycle(&model, 0.0, [0.5, 0.0], &crate::cycle::tight(1e-12, 1e-12)).unwrap();
    let mu = cyc.multipliers.iter().find(|m| !m.trivial).unwrap();
    let exact = mu.abs().ln() / cyc.period;
    let o = cycle::orbit(&model, &cyc, &crate::cycle::tight(1e-12, 1e-12)).unwrap();
    let fine = Fourier::from_orbit(&o, cyc.period, 1, 40);
    let fine = harmonic_balance(&model, &fine, &harmonics(40))
        .unwrap()
        .fourier;
    let samples = 4096;
    let trace: f64 = (0..samples)
        .map(|j| {
            let z: [f64; 2] = fine.state(TAU * j as f64 / samples as f64);
            1.0 - z[0] * z[0]
        })
        .sum::<f64>()
        / samples as f64;
    assert!((trace / exact - 1.0).abs() < 1e-6, "{trace} vs {exact}");
    let exact = trace;
    let mut guess = Fourier::from_orbit(&o, cyc.period, 1, 6);
    let mut errors = Vec::new();
    for h in [6, 12, 24] {
        let orbit = harmonic_balance(&model, &guess, &harmonics(h)).unwrap();
        let found = hill(&model, &orbit).unwrap();
        assert_eq!(found.exponents.len(), 2);
        let k = found.trivial.unwrap();
        let other = found.exponents[1 - k];
        let err = (other.re / exact - 1.0).abs();
        eprintln!(
            "H = {h}: exponent {other} vs {exact} ({err:.2e}), trivial {}, max |μ| {:.6e} vs {:.6e}",
            found.exponents[k],
            found.max_multiplier,
            mu.abs()
        );
        assert!(other.im.abs() < 1e-9, "{other}");
        assert!(found.exponents[k].norm() * cyc.period < 1e-3 * err.max(1e-9) + 1e-9);
        errors.push(err);
        guess = orbit.fourier;
    }
    // Measured 9.9e-4, 3.1e-7, 2.4e-11 at H = 6, 12, 24 (the last at the
    // trivial exponent's 3e-11: the orbit's own accuracy).
    assert!(errors[1] < 1e-3 * errors[0], "{errors:?}");
    assert!(
        errors[2] < 1e-3 * errors[1] && errors[2] < 1e-10,
        "{errors:?}"
    );
}

/// A forced Duffing oscillator above its linear resonance, where the
/// hardening spring has bent the response (smooth): Hill's multipliers
/// equal the monodromy's over one forcing period to 1e-9.
#[test]
fn hill_gives_the_forced_duffing_oscillators_multipliers() {
    let (k, c, k3, f) = (1.0e4, 4.0, 1.0e7, 1.0);
    let hz = 17.0;
    let l = oscillator(1.0, k, c, k3, f, hz, None);
    let sys = Fixed::<2>(&l);
    let guess = Fourier {
        omega: 1.0,
        coeffs: vec![vec![0.0, 1e-4, 0.0]],
    };
    let orbit = forced_response(&sys, &guess, &harmonics(20)).unwrap();
    let found = hill(&sys, &orbit).unwrap();
    assert!(found.trivial.is_none());
    let z0: [f64; 2] = orbit.fourier.state(0.0);
    let (exact, defect, _) =
        forced_floquet(&sys, &z0, 1.0 / hz, &crate::cycle::tight(1e-12, 1e-12)).unwrap();
    assert!(defect < 1e-8, "{defect}");
    assert_eq!(exact.len(), 2);
    // Each Hill multiplier next to one of the monodromy's.
    for mu in &found.multipliers {
        let d = exact
            .iter()
            .map(|e| (mu.re - e.re).hypot(mu.im - e.im))
            .fold(f64::INFINITY, f64::min);
        eprintln!("Hill {mu}, nearest monodromy multiplier at {d:.2e}");
        assert!(d < 1e-9, "{mu} vs {exact:?}");
    }
    // Damped: |μ₁μ₂| = det = exp(−cT/m) (Liouville).
    let det = found.multipliers[0] * found.multipliers[1];
    assert!((det.norm() / (-c / hz).exp() - 1.0).abs() < 1e-9, "{det}");
    assert!(found.max_multiplier < 1.0);
}

/// Hoffmann's orbit loses contact twice a period: refused, naming why.
#[test]
fn hill_refuses_an_orbit_with_switches() {
    let model = squeal_core::Hoffmann::default();
    let mut z = model.steady_sliding().unwrap();
    z[0] += 1e-4;
    let cyc = find_cycle(&model, 0.0, z, &CycleOptions::default()).unwrap();
    let o = cycle::orbit(&model, &cyc, &CycleOptions::default()).unwrap();
    let guess = Fourier::from_orbit(&o, cyc.period, 2, 10);
    let orbit = harmonic_balance(&model, &guess, &harmonics(10)).unwrap();
    let e = hill(&model, &orbit).unwrap_err().to_string();
    assert!(
        e.contains("smooth orbit") && e.contains("2 mode switches"),
        "{e}"
    );
}
