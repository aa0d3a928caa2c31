//! Harmonic balance against Newton shooting on the same settled guess, for
//! BENCHMARKS.md (issue 29, speed): the scenario is settled once (as
//! `squeal cycle` and `squeal hb` both do), then timed separately:
//! shooting from the settled state (`squeal_core::cycle::shoot`, with its
//! Floquet analysis) and HB at each H from the settled period
//! (`squeal_core::hb::harmonic_balance`, then `cycle::floquet_from` for the
//! multipliers). Wall time; the machine's two cores are both used by HB's
//! Jacobian.
//!
//! `cargo run --release -p squeal-study --example hb_vs_shooting -- SCENARIO [H…]`

use squeal_core::cycle::{self, CycleOptions};
use squeal_core::hb::{harmonic_balance, Fourier, HbOptions};
use squeal_core::System;
use squeal_study::Scenario;
use std::time::Instant;

fn measure<M: System<N> + ?Sized, const N: usize>(m: &M, z0: &[f64], hs: &[usize]) {
    let opts = CycleOptions::default();
    let mut start = [0.0; N];
    start.copy_from_slice(z0);
    let t = Instant::now();
    let (section, z, period, settled) = cycle::settle(m, 0.0, start, &opts).unwrap();
    println!(
        "settle: {:.2} s wall ({settled:.3} s simulated), period guess {period:.9e} s",
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    let c = cycle::shoot(m, z, period, section, &opts).unwrap();
    println!(
        "shooting + Floquet: {:.2} s, {:.9} Hz, {} Newton iterations, residual {:.1e}",
        t.elapsed().as_secs_f64(),
        1.0 / c.period,
        c.iterations,
        c.residual
    );
    let orbit = cycle::sample_period(m, &z, period, &opts).unwrap();
    let n = m.norm_states() / 2;
    let hmax = hs.iter().copied().max().unwrap_or(20);
    let full = Fourier::from_orbit(&orbit, period, n, 4 * hmax.max(8)).minimal(1e-2);
    for &h in hs {
        let t = Instant::now();
        let o = harmonic_balance(
            m,
            &full.resized(h),
            &HbOptions {
                harmonics: h,
                ..HbOptions::default()
            },
        )
        .unwrap();
        let t_hb = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let z_hb: [f64; N] = o.fourier.state(0.0);
        let f = cycle::floquet_from(m, &z_hb, o.period(), &opts).unwrap();
        println!(
            "HB H = {h}: {t_hb:.2} s ({} Newton iterations, {} unknowns), Floquet {:.2} s; {:.9} Hz, frequency vs shooting {:.1e}, defect {:.1e}, max |multiplier| {:.6} (shooting {:.6})",
            o.iterations,
            n * (2 * h + 1) + 1,
            t.elapsed().as_secs_f64(),
            1.0 / o.period(),
            (c.period / o.period() - 1.0).abs(),
            f.residual,
            f.max_multiplier,
            c.max_multiplier
        );
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let spec = args.next().unwrap_or_else(|| "disc-pad".into());
    let hs: Vec<usize> = args.filter_map(|a| a.parse().ok()).collect();
    let hs = if hs.is_empty() { vec![5, 10, 20] } else { hs };
    let sc = Scenario::load(&spec).unwrap();
    squeal_study::with_sim_system!(&sc.model, m => {
        let z0 = squeal_study::run::initial_of(m, &sc).unwrap();
        measure(m, &z0, &hs);
    }, else => panic!("too large to simulate"));
}
