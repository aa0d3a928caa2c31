//! Growth-rate estimation from the Hilbert envelope.

use crate::common;

use common::exp_sine;
use squeal_signal::*;
use std::f64::consts::TAU;

const FS: f64 = 200_000.0;

/// σ = 12.5 1/s at 5 kHz, 1 s at 200 kHz (108 dB of growth): σ recovered within 1 %.
#[test]
fn growing_sine_rate_within_1_percent() {
    let sigma = 12.5;
    let x = exp_sine(sigma, 5000.0, FS, 200_000);
    let est = growth_rate_linear_part(&x, FS, &GrowthOptions::default()).unwrap();
    assert_eq!(est.phase, Phase::Growing);
    let rel = (est.fit.rate - sigma).abs() / sigma;
    assert!(
        rel < 0.01,
        "rate {} vs {sigma} ({:.3} %)",
        est.fit.rate,
        rel * 100.0
    );
    assert!(est.fit.r_squared > 0.999, "R² {}", est.fit.r_squared);
    // the window lies inside the record and spans a useful part of it
    assert!(
        est.fit.t_start >= 0.05 && est.fit.t_end <= 0.95,
        "{:?}",
        est.fit
    );
    assert!(est.fit.t_end - est.fit.t_start > 0.3, "{:?}", est.fit);
    // ln A₀ ≈ 0 (unit initial amplitude) within 0.05 neper
    assert!(est.fit.ln_amp0.abs() < 0.05, "ln A0 {}", est.fit.ln_amp0);
}

/// σ = −12.5 1/s (decaying), and a faster decay σ = −40 1/s over 0.5 s: within 1 %.
#[test]
fn decaying_sine_rate_within_1_percent() {
    for (sigma, n) in [(-12.5, 200_000), (-40.0, 100_000)] {
        let x = exp_sine(sigma, 5000.0, FS, n);
        let est = growth_rate_linear_part(&x, FS, &GrowthOptions::default()).unwrap();
        assert_eq!(est.phase, Phase::Decaying);
        let rel = (est.fit.rate - sigma).abs() / sigma.abs();
        assert!(rel < 0.01, "rate {} vs {sigma}", est.fit.rate);
        assert!(est.fit.r_squared > 0.999);
    }
}

/// Growth that saturates into a limit cycle, `A(t) = A_s / sqrt(1 + (A_s²/A₀² − 1)e^{−2σt})`
/// (the solution of `Ȧ = σA(1 − A²/A_s²)`), σ = 30 1/s, 80 dB of growth, saturating at
/// ~0.3 s of a 0.6 s record: the linear part is found and σ recovered within 2 %, the window
/// ending before saturation, and the total rise reported within 1 dB.
#[test]
fn saturating_growth_rate_before_saturation() {
    let (sigma, a0, a_s) = (30.0, 1e-4, 1.0);
    let n = 120_000;
    let x: Vec<f64> = (0..n)
        .map(|i| {
            let t = i as f64 / FS;
            let a = a_s / (1.0 + (a_s * a_s / (a0 * a0) - 1.0) * (-2.0 * sigma * t).exp()).sqrt();
            a * (TAU * 3000.0 * t).sin()
        })
        .collect();
    let est = growth_rate_linear_part(&x, FS, &GrowthOptions::default()).unwrap();
    assert_eq!(est.phase, Phase::Growing);
    let rel = (est.fit.rate - sigma).abs() / sigma;
    assert!(rel < 0.02, "rate {} vs {sigma}", est.fit.rate);
    // saturation (A = A_s/√2) occurs at t = ln(A_s/A₀)/σ ≈ 0.307 s
    assert!(est.fit.t_end < 0.307, "{:?}", est.fit);
    // total rise: 80 dB less what the 5 % edge trim (0.03 s at σ) cuts off, within 1 dB
    let want = 80.0 - sigma * 0.03 * DB_PER_NEPER;
    assert!(
        (est.total_change_db - want).abs() < 1.0,
        "{} vs {want}",
        est.total_change_db
    );
}

/// Constant amplitude: flat phase, rate ≈ 0 (|σ| < 0.05 1/s).
#[test]
fn steady_sine_is_flat() {
    let x = exp_sine(0.0, 2000.0, FS, 100_000);
    let est = growth_rate_linear_part(&x, FS, &GrowthOptions::default()).unwrap();
    assert_eq!(est.phase, Phase::Flat);
    assert!(est.fit.rate.abs() < 0.05, "{}", est.fit.rate);
}

/// Direct fit on an exact exponential envelope: slope and intercept to 1e-9, R² = 1.
#[test]
fn fit_growth_rate_exact_exponential() {
    let fs = 1000.0;
    let env: Vec<f64> = (0..500)
        .map(|i| 2.0 * (-3.0 * i as f64 / fs).exp())
        .collect();
    let fit = fit_growth_rate(&env, fs, 100..400).unwrap();
    assert!((fit.rate + 3.0).abs() < 1e-9);
    assert!((fit.ln_amp0 - 2f64.ln()).abs() < 1e-9);
    assert!((fit.r_squared - 1.0).abs() < 1e-12);
    assert_eq!(fit.n_points, 300);
    assert!((fit.t_start - 0.1).abs() < 1e-12 && (fit.t_end - 0.399).abs() < 1e-12);
    assert!((fit.change_db() + 3.0 * 0.299 * DB_PER_NEPER).abs() < 1e-9);
}

/// Bad input gives typed errors.
#[test]
fn growth_rejects_bad_input() {
    let env = vec![1.0; 10];
    assert!(fit_growth_rate(&env, 0.0, 0..10).is_err());
    assert!(fit_growth_rate(&env, 1.0, 5..20).is_err());
    assert!(matches!(
        fit_growth_rate(&env, 1.0, 0..2),
        Err(SignalError::TooShort { .. })
    ));
    assert!(matches!(
        fit_growth_rate(&[1.0, 0.0, 1.0, 1.0], 1.0, 0..4),
        Err(SignalError::NonPositiveEnvelope { index: 1, .. })
    ));
    assert!(fit_growth_rate(&[], 1.0, 0..0).is_err());
    let o = GrowthOptions::default();
    assert!(growth_rate_linear_part(&[0.0; 1000], FS, &o).is_err());
    assert!(matches!(
        growth_rate_linear_part(&[1.0; 5], FS, &o),
        Err(SignalError::TooShort { .. })
    ));
    assert!(growth_rate_linear_part(&[f64::INFINITY; 100], FS, &o).is_err());
    let bad = GrowthOptions {
        edge_fraction: 0.6,
        ..o
    };
    assert!(growth_rate_linear_part(&exp_sine(1.0, 10.0, 100.0, 100), 100.0, &bad).is_err());
}
