//! Exact (exponential) propagation against DOP853 on one event-free window
//! of a lumped model, for BENCHMARKS.md (issue 27 §3: "modes far above the
//! band … integrated exactly: measure both on the same model").
//!
//! In a mode where every contact slides with a constant friction
//! coefficient (the Coulomb law) and stays closed, a lumped model is affine:
//! `ż = A (z − z*) + f(z*)` with `A = ∂f/∂z` at steady sliding `z*`
//! (`Lumped::jacobian_dyn`; `f(z*)` is the steady state's round-off).
//! Between samples `Δt` apart the exact flow is then
//! `u_{k+1} = P u_k + q` (`u = z − z*`, `[[P, q], [0, 1]]` the exponential of
//! `[[A, f(z*)], [0, 0]]·Δt`): one matrix exponential (nalgebra's Padé with
//! scaling and squaring) and one `2n × 2n` matrix–vector product per
//! sample, at any stiffness.
//!
//! The probe starts from steady sliding with the first contact's tangential
//! velocity perturbed by `DV`, runs `T` seconds at the scenario's sample
//! rate by DOP853 (the scenario's tolerances, rtol 1e-6, and as the
//! reference rtol 1e-12 with absolute tolerances 1e-19 m and 1e-14 m/s) and by the exponential, and prints each one's time and its
//! largest error over the samples relative to the largest excursion
//! `max |u|`. A run with an event (stick, contact loss) is not affine and
//! is reported as such.
//!
//! `cargo run --release -p squeal-study --example exponential_probe -- SCENARIO T [--set K=V …]`
//! (with `PROBE_WHERE=1`: also the sample and state of the exponential's
//! largest error).

use nalgebra::{DMatrix, DVector};
use squeal_core::model::lumped::padding;
use squeal_core::sink::Recorder;
use squeal_core::{simulate, System};
use squeal_study::model::AnyModel;
use squeal_study::Scenario;
use std::time::Instant;

/// The perturbation of the first contact's tangential velocity (m/s).
const DV: f64 = 1e-4;

/// Samples (real states) of a DOP853 run of `m` from `z0` over `t_end` at
/// `rate`, with relative tolerance `rtol`; its wall time and event count.
fn dop853<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    sc: &Scenario,
    z0: &[f64],
    t_end: f64,
    rtol: f64,
) -> (Vec<Vec<f64>>, f64, u64) {
    let n = z0.len();
    let start: [f64; N] = if n == N {
        let mut s = [0.0; N];
        s.copy_from_slice(z0);
        s
    } else {
        padding::embed(z0)
    };
    let mut opts = squeal_study::run::sim_options::<N>(sc);
    opts.rtol = rtol;
    if rtol < 1e-10 {
        // The reference: absolute tolerances far below the motion's too.
        opts.atol_pos = Some(1e-19);
        opts.atol_vel = Some(1e-14);
    }
    let mut rec = Recorder::<N>::new();
    let t = Instant::now();
    let info = simulate(m, 0.0, start, t_end, sc.sample_rate, opts, &mut rec).unwrap();
    let secs = t.elapsed().as_secs_f64();
    let real: Vec<usize> = padding::real_states::<N>(n / 2).collect();
    let samples = rec
        .z
        .iter()
        .map(|z| real.iter().map(|&i| z[i]).collect())
        .collect();
    (samples, secs, info.stats.events.iter().sum::<u64>())
}

/// The field at `z` (real states) of the padded model `m`, in the modes
/// `m` starts in there.
fn field_at<M: System<N> + ?Sized, const N: usize>(m: &M, z: &[f64]) -> Vec<f64> {
    let n = z.len();
    let zz: [f64; N] = padding::embed(z);
    let modes = m.start_modes(0.0, &zz);
    let mut dz = [0.0; N];
    m.field(0.0, &modes, &zz, &mut dz);
    padding::real_states::<N>(n / 2).map(|i| dz[i]).collect()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let spec = args.next().expect("SCENARIO");
    let t_end: f64 = args.next().expect("T").parse().expect("T in seconds");
    let mut sc = Scenario::load(&spec).unwrap();
    let sets: Vec<String> = args.filter(|a| a != "--set").collect();
    sc.apply_overrides(&sets).unwrap();
    let AnyModel::Lumped(l) = &sc.model else {
        panic!("a lumped model")
    };
    let zs = l.equilibrium_dyn().unwrap();
    let a = l.jacobian_dyn(&zs);
    let n2 = zs.len();
    let mut z0 = zs.clone();
    let c = &l.contacts[0];
    for (&i, &w) in c.tangent.idx.iter().zip(&c.tangent.coef) {
        z0[n2 / 2 + i] += DV * w.signum();
    }
    // How affine the field is: f(z*) and f(z0) − A (z0 − z*).
    let (f_star, f0) = squeal_study::with_transient_system!(&sc.model,
        m => (field_at(m, &zs), field_at(m, &z0)), else => panic!("too large"));
    let lin = &a * DVector::from_iterator(n2, z0.iter().zip(&zs).map(|(x, s)| x - s));
    let norm = |v: &mut dyn Iterator<Item = f64>| v.fold(0.0_f64, |m, x| m.max(x.abs()));
    println!(
        "max |f(z*)| = {:.3e}, max |f(z0) − A(z0 − z*)| = {:.3e}, max |A(z0 − z*)| = {:.3e}",
        norm(&mut f_star.iter().copied()),
        norm(&mut f0.iter().zip(lin.iter()).map(|(x, y)| x - y)),
        norm(&mut lin.iter().copied())
    );
    println!(
        "{}: {} dofs, {} states; {} samples at {} Hz over {t_end} s",
        sc.name,
        n2 / 2,
        n2,
        (t_end * sc.sample_rate).round(),
        sc.sample_rate
    );
    let runs: Vec<(String, Vec<Vec<f64>>, f64, u64)> = [1e-12, sc.solver.rtol, 1e-6]
        .iter()
        .map(|&rtol| {
            let (s, secs, ev) = squeal_study::with_transient_system!(&sc.model,
                m => dop853(m, &sc, &z0, t_end, rtol), else => panic!("too large"));
            (format!("DOP853 rtol {rtol:e}"), s, secs, ev)
        })
        .collect();
    let reference = &runs[0].1;
    let scale = reference
        .iter()
        .flat_map(|z| z.iter().zip(&zs).map(|(x, s)| (x - s).abs()))
        .fold(0.0, f64::max);
    let error = |s: &[Vec<f64>]| {
        s.iter()
            .zip(reference)
            .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
            .fold(0.0, f64::max)
            / scale
    };
    // The exact flow, sample to sample.
    let t = Instant::now();
    let dt = 1.0 / sc.sample_rate;
    // The exact affine flow: ż = A u + f(z*) (f(z*) is the steady state's
    // round-off residual), by the exponential of the augmented matrix
    // [[A, f*], [0, 0]]·Δt = [[P, q], [0, 1]].
    let mut aug = DMatrix::<f64>::zeros(n2 + 1, n2 + 1);
    aug.view_mut((0, 0), (n2, n2)).copy_from(&a);
    for (i, f) in f_star.iter().enumerate() {
        aug[(i, n2)] = *f;
    }
    let e = (aug * dt).exp();
    let p: DMatrix<f64> = e.view((0, 0), (n2, n2)).into_owned();
    let q = DVector::from_iterator(n2, (0..n2).map(|i| e[(i, n2)]));
    let t_exp = t.elapsed().as_secs_f64();
    let mut u = DVector::from_iterator(n2, z0.iter().zip(&zs).map(|(x, s)| x - s));
    let mut next = DVector::zeros(n2);
    let mut samples = Vec::with_capacity(reference.len());
    samples.push(z0.clone());
    for _ in 1..reference.len() {
        next.copy_from(&q);
        next.gemv(1.0, &p, &u, 1.0);
        std::mem::swap(&mut u, &mut next);
        samples.push(u.iter().zip(&zs).map(|(x, s)| x + s).collect());
    }
    let secs = t.elapsed().as_secs_f64();
    for (name, s, secs, ev) in &runs {
        println!(
            "{name}: {secs:.3} s, {ev} events, max error {:.2e} of max |z − z*| = {scale:.3e}",
            error(s)
        );
    }
    if std::env::var_os("PROBE_WHERE").is_some() {
        let mut worst = (0.0, 0, 0);
        for (k, (x, y)) in samples.iter().zip(reference).enumerate() {
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                if (p - q).abs() > worst.0 {
                    worst = ((p - q).abs(), k, i);
                }
            }
        }
        let (_, k, i) = worst;
        println!(
            "worst: sample {k}, state {i} ({}): exp {:e}, ref {:e}, ref−z* {:e}",
            l.state_names()[i],
            samples[k][i],
            reference[k][i],
            reference[k][i] - zs[i]
        );
    }
    println!(
        "exponential (e^(AΔt) once: {t_exp:.3} s, then one product per sample): {secs:.3} s, max error {:.2e}",
        error(&samples)
    );
}
