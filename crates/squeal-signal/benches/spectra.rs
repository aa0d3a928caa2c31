//! Welch PSD, spectrogram, Hilbert envelope and audio rendering of a 1 s, 200 kHz signal.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use squeal_signal::*;

const FS: f64 = 200_000.0;

/// 200 000 samples: a growing 5 kHz mode, a 12 kHz tone and deterministic LCG noise.
fn signal() -> Vec<f64> {
    let mut s: u64 = 1;
    (0..200_000)
        .map(|i| {
            let t = i as f64 / FS;
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let noise = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            (3.0 * t).exp() * (std::f64::consts::TAU * 5000.0 * t).sin()
                + 0.3 * (std::f64::consts::TAU * 12_000.0 * t).sin()
                + 0.01 * noise
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let x = signal();
    let mut g = c.benchmark_group("1s_200kHz");
    g.sample_size(20);
    g.bench_function("welch_8192_hann", |b| {
        b.iter(|| welch(black_box(&x), FS, &WelchOptions::default()).unwrap())
    });
    g.bench_function("spectrogram_2048_hop512", |b| {
        b.iter(|| spectrogram(black_box(&x), FS, 2048, 512, Window::Hann).unwrap())
    });
    g.bench_function("hilbert_envelope", |b| {
        b.iter(|| hilbert_envelope(black_box(&x)).unwrap())
    });
    g.bench_function("welch+spectrogram+envelope", |b| {
        b.iter(|| {
            let s = welch(black_box(&x), FS, &WelchOptions::default()).unwrap();
            let sg = spectrogram(black_box(&x), FS, 2048, 512, Window::Hann).unwrap();
            let e = hilbert_envelope(black_box(&x)).unwrap();
            (s, sg, e)
        })
    });
    g.bench_function("render_audio_48k", |b| {
        b.iter(|| render_audio(black_box(&x), FS, &AudioOptions::default()).unwrap())
    });
    g.bench_function("growth_rate_linear_part", |b| {
        b.iter(|| growth_rate_linear_part(black_box(&x), FS, &GrowthOptions::default()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
