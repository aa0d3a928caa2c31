//! Run verdicts from synthetic velocity signals.

mod common;

use common::{exp_sine, tones, Lcg};
use squeal_signal::*;
use std::f64::consts::TAU;

const FS: f64 = 200_000.0;
const N: usize = 200_000; // 1 s

/// Decaying sines (σ = −20 and −2 1/s) → decays; the tail change is the fitted σ over the
/// tail (within 0.5 dB of σ·T_tail·8.686).
#[test]
fn decaying_signal_decays() {
    for sigma in [-20.0, -2.0] {
        let x = exp_sine(sigma, 3000.0, FS, N);
        let c = classify_with(&x, FS, 0.0, &VerdictOptions::default()).unwrap();
        assert_eq!(c.verdict, Verdict::Decays, "σ={sigma}: {c:?}");
        // tail = last 25 % of the 96 % left after trimming 2 % at each end
        let want = sigma * 0.25 * 0.96 * DB_PER_NEPER;
        assert!((c.tail_change_db - want).abs() < 0.5, "{c:?} want {want}");
        assert!((c.tail_rate - sigma).abs() < 0.02 * sigma.abs(), "{c:?}");
    }
}

/// Growing sines (σ = 8 and 40 1/s) → grows, even with stick events reported.
#[test]
fn growing_signal_grows() {
    for sigma in [8.0, 40.0] {
        let x = exp_sine(sigma, 3000.0, FS, N);
        assert_eq!(classify(&x, FS, 0.0).unwrap(), Verdict::Grows, "σ={sigma}");
        assert_eq!(classify(&x, FS, 0.5).unwrap(), Verdict::Grows, "σ={sigma}");
    }
}

/// Steady oscillation with 1 % noise → limit-cycle; with stick/reversal events in the tail
/// (fraction 0.3) → stick-slip; a tiny fraction (0.005 < 0.01 threshold) stays limit-cycle.
#[test]
fn steady_signal_limit_cycle_or_stick_slip() {
    let mut rng = Lcg(7);
    let x: Vec<f64> = tones(&[(2500.0, 1.0, 0.0), (7500.0, 0.2, 0.4)], FS, N)
        .into_iter()
        .map(|v| v + 0.02 * rng.next())
        .collect();
    let c = classify_with(&x, FS, 0.0, &VerdictOptions::default()).unwrap();
    assert_eq!(c.verdict, Verdict::LimitCycle, "{c:?}");
    assert!(
        c.tail_change_db.abs() < 0.1 && c.drop_from_peak_db < 1.0,
        "{c:?}"
    );
    assert_eq!(classify(&x, FS, 0.3).unwrap(), Verdict::StickSlip);
    assert_eq!(classify(&x, FS, 0.005).unwrap(), Verdict::LimitCycle);
    assert_eq!(Verdict::StickSlip.as_str(), "stick-slip");
    assert_eq!(Verdict::LimitCycle.to_string(), "limit-cycle");
    assert_eq!(Verdict::Decays.as_str(), "decays");
    assert_eq!(Verdict::Grows.as_str(), "grows");
}

/// Growth that saturates at 0.3 s (σ = 30 1/s, 80 dB) then holds: limit-cycle. A sawtooth-like
/// steady stick-slip velocity with an offset and stick fraction 0.4: stick-slip.
#[test]
fn saturated_growth_and_sawtooth() {
    let (sigma, a0) = (30.0, 1e-4);
    let x: Vec<f64> = (0..N)
        .map(|i| {
            let t = i as f64 / FS;
            let a = 1.0 / (1.0 + (1.0 / (a0 * a0) - 1.0) * (-2.0 * sigma * t).exp()).sqrt();
            a * (TAU * 3000.0 * t).sin()
        })
        .collect();
    assert_eq!(classify(&x, FS, 0.0).unwrap(), Verdict::LimitCycle);
    let saw: Vec<f64> = (0..N)
        .map(|i| {
            let ph = (i as f64 / FS * 400.0).fract();
            // stick (constant velocity) for 40 % of the period, then a slip pulse
            if ph < 0.4 {
                1.0
            } else {
                1.0 - (TAU * (ph - 0.4) / 0.6).sin().abs() * 2.0
            }
        })
        .collect();
    assert_eq!(classify(&saw, FS, 0.4).unwrap(), Verdict::StickSlip);
}

/// A signal that dies to exact zeros, and an all-zero signal, both decay.
#[test]
fn dead_signals_decay() {
    let mut x = exp_sine(-50.0, 3000.0, FS, N);
    x[60_000..].iter_mut().for_each(|v| *v = 0.0);
    let c = classify_with(&x, FS, 0.0, &VerdictOptions::default()).unwrap();
    assert_eq!(c.verdict, Verdict::Decays, "{c:?}");
    assert_eq!(
        classify(&vec![0.0; 1000], FS, 0.0).unwrap(),
        Verdict::Decays
    );
    assert_eq!(
        classify(&vec![2.5; 1000], FS, 0.0).unwrap(),
        Verdict::Decays
    );
}

/// Bad input gives typed errors.
#[test]
fn classify_rejects_bad_input() {
    let x = exp_sine(0.0, 3000.0, FS, 1000);
    assert!(classify(&x, FS, 1.5).is_err());
    assert!(classify(&x, FS, f64::NAN).is_err());
    assert!(classify(&x, 0.0, 0.0).is_err());
    assert!(classify(&x[..10], FS, 0.0).is_err());
    assert!(classify(&[], FS, 0.0).is_err());
    let bad = VerdictOptions {
        tail_fraction: 0.0,
        ..Default::default()
    };
    assert!(classify_with(&x, FS, 0.0, &bad).is_err());
}
