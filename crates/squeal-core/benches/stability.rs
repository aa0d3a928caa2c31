//! Benchmarks of the linear stability analysis (MODEL.md §5).
//!
//! `cargo bench -p squeal-core --bench stability`
//!
//! - `analyse_disc_pad`: full analysis (eigenvalues, eigenvectors, mode
//!   attribution) of the default disc–pad model, single thread;
//! - `max_growth_rate_disc_pad`: the allocation-free fast path, single thread;
//! - `map_500x500_VxN_rayon`: a 500 × 500 map of σ_max over V ∈ [0.1, 30] m/s
//!   and N ∈ [100, 5000] N with the fast path, `par_iter` over all cores.
#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use rayon::prelude::*;
use squeal_core::model::lumped::{two_pad_spec, Fixed};
use squeal_core::stability::{analyse, max_growth_rate};
use squeal_core::{DiscPad, Lumped};
use std::time::Duration;

const SIDE: usize = 500;

fn map(base: &DiscPad) -> Vec<f64> {
    (0..SIDE * SIDE)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k / SIDE, k % SIDE);
            let mut m = *base;
            m.p.V = 0.1 + (30.0 - 0.1) * i as f64 / (SIDE - 1) as f64;
            m.p.N = 100.0 + (5000.0 - 100.0) * j as f64 / (SIDE - 1) as f64;
            max_growth_rate(&m).map_or(f64::NAN, |(s, _)| s)
        })
        .collect()
}

fn benches(c: &mut Criterion) {
    let disc = DiscPad::default();
    let mut g = c.benchmark_group("stability");
    g.sample_size(50).measurement_time(Duration::from_secs(5));
    g.throughput(Throughput::Elements(1));
    g.bench_function("analyse_disc_pad", |b| {
        b.iter(|| analyse(black_box(&disc)).unwrap())
    });
    g.bench_function("max_growth_rate_disc_pad", |b| {
        b.iter(|| max_growth_rate(black_box(&disc)).unwrap())
    });
    // The 6-dof two-pad brake (lumped, 2 contacts): BENCHMARKS.md's target is
    // ≥ 20 000 full analyses per second per core.
    let two = Lumped::build(&two_pad_spec()).unwrap();
    g.bench_function("analyse_two_pad_brake", |b| {
        b.iter(|| analyse(&Fixed::<12>(black_box(&two))).unwrap())
    });
    g.bench_function("equilibrium_jacobian_two_pad_brake", |b| {
        b.iter(|| {
            let z = black_box(&two).equilibrium_dyn().unwrap();
            two.jacobian_dyn(&z)
        })
    });
    g.bench_function("max_growth_rate_two_pad_brake", |b| {
        b.iter(|| max_growth_rate(&Fixed::<12>(black_box(&two))).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("stability_map");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.throughput(Throughput::Elements((SIDE * SIDE) as u64));
    g.bench_function("map_500x500_VxN_rayon", |b| {
        b.iter(|| {
            let v = map(black_box(&disc));
            assert!(v.iter().all(|x| x.is_finite()));
            v
        })
    });
    g.finish();
}

criterion_group!(stability, benches);
criterion_main!(stability);
