//! Deterministic test signals.
#![allow(dead_code)]

use std::f64::consts::TAU;

/// Linear congruential generator (Numerical Recipes constants) giving uniform values in
/// `[-0.5, 0.5)`: deterministic "noise" with variance 1/12.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// `Σ a·sin(2πft + φ)` sampled at `fs` for `n` samples; `tones` = (f, a, φ).
pub fn tones(tones: &[(f64, f64, f64)], fs: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            tones
                .iter()
                .map(|&(f, a, p)| a * (TAU * f * t + p).sin())
                .sum()
        })
        .collect()
}

/// `e^{σt}·sin(2πft + 0.3)`.
pub fn exp_sine(sigma: f64, f: f64, fs: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let t = i as f64 / fs;
            (sigma * t).exp() * (TAU * f * t + 0.3).sin()
        })
        .collect()
}

/// Population variance.
pub fn variance(x: &[f64]) -> f64 {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / x.len() as f64
}
