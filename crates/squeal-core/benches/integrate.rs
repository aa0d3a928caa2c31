//! Benchmarks of the event-driven integrator (see BENCHMARKS.md).
//!
//! `cargo bench -p squeal-core --bench integrate`
#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{criterion_group, criterion_main, Criterion};
use squeal_core::model::lumped::{disc_pad_spec, Fixed};
use squeal_core::model::{EventKind, GuardKind, Guards, Mode, Model, ModelError, Observables};
use squeal_core::sink::Discard;
use squeal_core::{simulate, Belt, DiscPad, FrictionLaw, Lumped, SolverOptions};
use std::time::Duration;

/// The disc–pad slip equations with no guards: the same method and right-hand
/// side without any event machinery (a "bare loop" for the overhead ratio).
struct Unswitched(DiscPad);

impl Model<8> for Unswitched {
    fn name(&self) -> &'static str {
        "unswitched"
    }
    fn state_names(&self) -> [&'static str; 8] {
        self.0.state_names()
    }
    fn rhs(&self, t: f64, _mode: Mode, z: &[f64; 8], dz: &mut [f64; 8]) {
        self.0.rhs(t, Mode::SlipPos, z, dz)
    }
    fn guards(&self, _mode: Mode, out: &mut Guards<8>) {
        out.clear()
    }
    fn transition(
        &self,
        _: f64,
        m: Mode,
        _: GuardKind,
        _: &mut [f64; 8],
    ) -> (Mode, Option<EventKind>) {
        (m, None)
    }
    fn initial_mode(&self, _: f64, _: &[f64; 8]) -> Mode {
        Mode::SlipPos
    }
    fn observe(&self, t: f64, m: Mode, z: &[f64; 8]) -> Observables {
        self.0.observe(t, m, z)
    }
    fn equilibrium(&self) -> Result<[f64; 8], ModelError> {
        self.0.equilibrium()
    }
    fn jacobian(&self, z: &[f64; 8]) -> [[f64; 8]; 8] {
        self.0.jacobian(z)
    }
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("integrate");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    let disc = DiscPad::default();
    g.bench_function("disc_pad_default_1s_from_rest", |b| {
        b.iter(|| {
            simulate(
                &disc,
                0.0,
                [0.0; 8],
                1.0,
                200_000.0,
                SolverOptions::default(),
                &mut Discard,
            )
            .unwrap()
        })
    });
    // The same brake as a lumped model (BENCHMARKS.md: target ≤ 1.3× the dedicated model).
    let lumped = Lumped::build(&disc_pad_spec(&disc)).unwrap();
    g.bench_function("lumped_disc_pad_default_1s_from_rest", |b| {
        b.iter(|| {
            simulate(
                &Fixed::<8>(&lumped),
                0.0,
                [0.0; 8],
                1.0,
                200_000.0,
                SolverOptions::default(),
                &mut Discard,
            )
            .unwrap()
        })
    });
    // The first 0.3 s are linear growth without events: compare per step.
    let bare = Unswitched(disc);
    g.bench_function("disc_pad_bare_0.3s", |b| {
        b.iter(|| {
            simulate(
                &bare,
                0.0,
                [0.0; 8],
                0.3,
                200_000.0,
                SolverOptions::default(),
                &mut Discard,
            )
            .unwrap()
        })
    });
    g.bench_function("disc_pad_events_0.3s", |b| {
        b.iter(|| {
            simulate(
                &disc,
                0.0,
                [0.0; 8],
                0.3,
                200_000.0,
                SolverOptions::default(),
                &mut Discard,
            )
            .unwrap()
        })
    });
    let belt = Belt {
        friction: FrictionLaw::Coulomb {
            mu_s: 0.4,
            mu_k: 0.3,
        },
        ..Belt::default()
    };
    g.bench_function("belt_coulomb_10s", |b| {
        b.iter(|| {
            simulate(
                &belt,
                0.0,
                [0.0; 2],
                10.0,
                1000.0,
                SolverOptions::default(),
                &mut Discard,
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(integrate, benches);
criterion_main!(integrate);
