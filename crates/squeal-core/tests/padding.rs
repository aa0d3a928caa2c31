//! Lumped models simulated in a padded state size
//! (`squeal_core::model::lumped::padding`): idle dofs stay exactly at rest,
//! and with the scaled tolerances the real dofs move as in the exact size.

use squeal_core::model::lumped::{
    disc_pad_spec, padded_dofs, padded_solver, transient_padded_dofs, LumpedSpec, SpringSpec,
    MAX_EXACT_DOFS, MAX_SIM_DOFS, MAX_TRANSIENT_DOFS, PADDED_DOFS, TRANSIENT_PADDED_DOFS,
};
use squeal_core::sink::{EventLog, Recorder};
// `padded_solver` only moves per-state tolerances; these runs have none.
use squeal_core::{simulate, DiscPad, Lumped, Parameters, SolverOptions};

fn disc_pad_opts() -> SolverOptions {
    SolverOptions {
        atol_pos: Some(1e-16),
        atol_vel: Some(1e-11),
        ..Default::default()
    }
}

fn disc_pad_at_n_2000() -> Lumped {
    let mut dp = DiscPad::default();
    dp.set("N", 2000.0).unwrap();
    Lumped::build(&disc_pad_spec(&dp)).unwrap()
}

#[test]
fn padded_sizes_cover_every_model_up_to_the_limit() {
    for dofs in 1..=MAX_EXACT_DOFS {
        assert_eq!(padded_dofs(dofs), None, "{dofs} dofs have an exact size");
    }
    for dofs in MAX_EXACT_DOFS + 1..=MAX_SIM_DOFS {
        let p = padded_dofs(dofs).unwrap_or_else(|| panic!("{dofs} dofs: no size"));
        assert!(p >= dofs && p <= MAX_SIM_DOFS, "{dofs} → {p}");
    }
    assert_eq!(padded_dofs(MAX_SIM_DOFS + 1), None);
    assert_eq!(padded_dofs(17), Some(24));
    assert_eq!(padded_dofs(64), Some(64));
    assert_eq!(padded_dofs(65), Some(96));
    assert_eq!(padded_dofs(128), Some(128));
    // Transient runs go on in larger sizes, limit cycles do not.
    for dofs in 1..=MAX_SIM_DOFS {
        assert_eq!(transient_padded_dofs(dofs), None, "{dofs} dofs");
    }
    for dofs in MAX_SIM_DOFS + 1..=MAX_TRANSIENT_DOFS {
        let p = transient_padded_dofs(dofs).unwrap_or_else(|| panic!("{dofs} dofs: no size"));
        assert!(p >= dofs && p <= MAX_TRANSIENT_DOFS, "{dofs} → {p}");
        assert_eq!(padded_dofs(dofs), None);
    }
    assert_eq!(transient_padded_dofs(MAX_TRANSIENT_DOFS + 1), None);
    assert_eq!(transient_padded_dofs(129), Some(192));
    assert_eq!(transient_padded_dofs(187), Some(192));
    assert_eq!(transient_padded_dofs(512), Some(512));
}

/// The state count a model is dispatched at.
fn states<M: squeal_core::System<N>, const N: usize>(_: &M) -> usize {
    N
}

/// Every padded size is compiled in: a model of exactly that many dofs is
/// dispatched to it (not to the refusal), by its own macro only.
#[test]
fn every_padded_size_is_dispatched() {
    let lp = disc_pad_at_n_2000();
    for d in PADDED_DOFS {
        let p = lp.padded_to(d);
        let n = squeal_core::with_padded_size!(&p, m => states(m), else => 0);
        assert_eq!(n, 2 * d, "{d} dofs");
        let t = squeal_core::with_transient_padded_size!(&p, m => states(m), else => 0);
        assert_eq!(t, 0, "{d} dofs: not a transient-only size");
    }
    for d in TRANSIENT_PADDED_DOFS {
        let p = lp.padded_to(d);
        let n = squeal_core::with_transient_padded_size!(&p, m => states(m), else => 0);
        assert_eq!(n, 2 * d, "{d} dofs");
        let c = squeal_core::with_padded_size!(&p, m => states(m), else => 0);
        assert_eq!(c, 0, "{d} dofs: above the cycle sizes");
    }
}

/// The disc–pad padded from 4 to the largest transient size (512 dofs,
/// 1024 states: the largest arrays the integrator is compiled for, run on a
/// test thread's stack) over 0.1 s of stick-slip is bit for bit the same
/// model padded to the smallest padded size (24 dofs): steps, every event,
/// every sample; the idle states stay zero. (Both evaluate the force on the
/// general path; the exact 4-dof size uses the folded operators of
/// `DENSE_FIELD_DOFS`, whose sums are associated differently, so against it
/// the steps are the same and the events agree to 1e-12 s.)
#[test]
fn the_largest_transient_size_is_the_smallest_padded_run_bit_for_bit() {
    let lp = disc_pad_at_n_2000();
    let opts = disc_pad_opts();
    let (small, large) = (lp.padded_to(24), lp.padded_to(MAX_TRANSIENT_DOFS));
    let (mut a, mut b, mut e) = (
        Recorder::<48>::new(),
        Recorder::<1024>::new(),
        Recorder::<8>::new(),
    );
    let ia = simulate(
        &small,
        0.0,
        [0.0; 48],
        0.1,
        1000.0,
        padded_solver::<48>(&opts, 8),
        &mut a,
    );
    let ib = simulate(
        &large,
        0.0,
        [0.0; 1024],
        0.1,
        1000.0,
        padded_solver::<1024>(&opts, 8),
        &mut b,
    );
    let (ia, ib) = (ia.unwrap(), ib.unwrap());
    let ie = simulate(&lp, 0.0, [0.0; 8], 0.1, 1000.0, opts, &mut e).unwrap();
    let counts = |i: &squeal_core::RunInfo| (i.stats.accepted, i.stats.rejected, i.stats.rhs_evals);
    assert_eq!(counts(&ia), counts(&ib));
    assert_eq!(counts(&ia), counts(&ie));
    assert!(a.events.len() > 500, "only {} events", a.events.len());
    assert_eq!(a.events.len(), b.events.len());
    assert_eq!(a.events.len(), e.events.len());
    let real = |z: &[f64]| -> Vec<f64> {
        let h = z.len() / 2;
        z[..4].iter().chain(&z[h..h + 4]).copied().collect()
    };
    let idle_zero = |z: &[f64]| {
        let h = z.len() / 2;
        (4..h).chain(h + 4..z.len()).all(|i| z[i] == 0.0)
    };
    for ((x, y), w) in a.events.iter().zip(&b.events).zip(&e.events) {
        assert_eq!((x.kind, x.contact, x.t), (y.kind, y.contact, y.t));
        assert_eq!(real(&x.z), real(&y.z));
        assert!(idle_zero(&x.z) && idle_zero(&y.z));
        assert_eq!((x.kind, x.contact), (w.kind, w.contact));
        assert!((x.t - w.t).abs() <= 1e-12, "{} vs {}", x.t, w.t);
    }
    assert_eq!(a.t, b.t);
    for (x, y) in a.z.iter().zip(&b.z) {
        assert_eq!(real(x), real(y));
        assert!(idle_zero(y));
    }
}

/// The disc–pad at N = 2000 (stick-slip from rest, over 12 000 events in
/// 0.5 s) padded from 4 to 6 dofs: the idle states are exactly zero at every
/// sample and event, and the run is the exact-size run bit for bit — the
/// same steps, every event's kind, contact, time and state, every sample.
#[test]
fn a_padded_disc_pad_is_the_exact_size_run_bit_for_bit() {
    let lp = disc_pad_at_n_2000();
    let padded = lp.padded_to(6);
    assert_eq!(padded.dof_count(), 6);
    assert_eq!(&padded.dofs()[4..], ["pad.1", "pad.2"]);
    let opts = disc_pad_opts();
    let (mut a, mut b) = (Recorder::<8>::new(), Recorder::<12>::new());
    let ia = simulate(&lp, 0.0, [0.0; 8], 0.5, 1000.0, opts, &mut a).unwrap();
    let ib = simulate(
        &padded,
        0.0,
        [0.0; 12],
        0.5,
        1000.0,
        padded_solver::<12>(&opts, 8),
        &mut b,
    )
    .unwrap();
    let idle = [4, 5, 10, 11];
    let real = |z: &[f64; 12]| -> [f64; 8] {
        let mut r = [0.0; 8];
        r[..4].copy_from_slice(&z[..4]);
        r[4..].copy_from_slice(&z[6..10]);
        r
    };
    for z in b.z.iter().chain(b.events.iter().map(|e| &e.z)) {
        assert!(idle.iter().all(|&i| z[i] == 0.0), "idle state moved: {z:?}");
    }
    assert_eq!(
        (ia.stats.accepted, ia.stats.rejected, ia.stats.rhs_evals),
        (ib.stats.accepted, ib.stats.rejected, ib.stats.rhs_evals)
    );
    assert!(a.events.len() > 10_000, "only {} events", a.events.len());
    assert_eq!(a.events.len(), b.events.len());
    for (k, (x, y)) in a.events.iter().zip(&b.events).enumerate() {
        assert_eq!(
            (x.kind, x.contact, x.t),
            (y.kind, y.contact, y.t),
            "event {k}"
        );
        assert_eq!(x.z, real(&y.z), "event {k}");
    }
    assert_eq!(a.t, b.t);
    for (x, y) in a.z.iter().zip(&b.z) {
        assert_eq!(*x, real(y));
    }
}

/// A 20-dof model (the disc–pad plus a separate chain of 16 masses, ringing
/// from an initial displacement) runs padded to 24 dofs: the disc–pad's
/// events equal those of the 4-dof model to 1e-9 s (the error norm now also
/// weighs the chain's 32 states, so the steps differ; both runs are
/// accurate to rtol = 1e-8).
#[test]
fn a_20_dof_model_runs_padded_and_its_disc_pad_moves_as_alone() {
    let mut dp = DiscPad::default();
    dp.set("N", 2000.0).unwrap();
    let mut spec: LumpedSpec = disc_pad_spec(&dp);
    for i in 1..=16 {
        let name = format!("c{i}");
        spec.dofs.push(name.clone());
        spec.masses.push((name.clone(), 0.5));
        let mut on = vec![(name, 1.0)];
        if i > 1 {
            on.push((format!("c{}", i - 1), -1.0));
        }
        spec.springs.push(SpringSpec {
            name: format!("chain{i}"),
            on,
            k: 1.0e6,
            c: 0.5,
            k3: 0.0,
        });
    }
    let big = Lumped::build(&spec).unwrap();
    assert_eq!(big.dof_count(), 20);
    let padded = big.padded_to(padded_dofs(20).unwrap());
    let mut z0 = [0.0; 48];
    z0[4] = 1e-3; // c1 displaced
    let opts = disc_pad_opts();
    let (mut a, mut b) = (EventLog::<8>::default(), Recorder::<48>::new());
    simulate(
        &disc_pad_at_n_2000(),
        0.0,
        [0.0; 8],
        0.3,
        1000.0,
        opts,
        &mut a,
    )
    .unwrap();
    simulate(
        &padded,
        0.0,
        z0,
        0.3,
        1000.0,
        padded_solver::<48>(&opts, 40),
        &mut b,
    )
    .unwrap();
    // The chain rings (it is simulated, not frozen); the idle dofs do not.
    assert!(
        b.z.iter().any(|z| z[19].abs() > 1e-6),
        "the chain's end never moved"
    );
    for z in &b.z {
        assert!((20..24).chain(44..48).all(|i| z[i] == 0.0));
    }
    assert!(a.events.len() >= 16, "only {} events", a.events.len());
    let mut worst = 0.0f64;
    for (k, (x, y)) in a.events.iter().zip(&b.events).take(16).enumerate() {
        assert_eq!(x.kind, y.kind, "event {k}");
        worst = worst.max((x.t - y.t).abs());
    }
    eprintln!("first 16 events: largest time difference {worst:e} s");
    assert!(worst <= 1e-9, "event times differ by up to {worst:e} s");
}

/// The default disc–pad's limit cycle (lumped, 4 dofs) found in its exact
/// size and padded to 6 dofs: the Floquet analysis covers the real states
/// only, so the padded cycle has the same period and start, the same
/// number of multipliers (8, not 12: the idle dofs' would sit on the unit
/// circle) and the same multipliers. The runs take the same steps, so the
/// agreement is at round-off (1e-12 relative in the period, 1e-9 in each
/// multiplier).
#[test]
fn a_padded_model_has_the_exact_size_cycle_and_multipliers() {
    use squeal_core::cycle::{find_cycle, CycleOptions};
    let lp = Lumped::build(&disc_pad_spec(&DiscPad::default())).unwrap();
    let padded = lp.padded_to(6);
    let opts = CycleOptions::default();
    let mut popts = opts;
    popts.solver = padded_solver::<12>(&opts.solver, 8);
    let a = find_cycle(&lp, 0.0, [0.0; 8], &opts).unwrap();
    let b = find_cycle(&padded, 0.0, [0.0; 12], &popts).unwrap();
    assert!(
        (a.period - b.period).abs() <= 1e-12 * a.period,
        "{} vs {}",
        a.period,
        b.period
    );
    assert_eq!(b.multipliers.len(), 8);
    assert_eq!(a.stable, b.stable);
    for (x, y) in a.multipliers.iter().zip(&b.multipliers) {
        assert_eq!(x.trivial, y.trivial);
        assert!(
            (x.re - y.re).abs() <= 1e-9 && (x.im - y.im).abs() <= 1e-9,
            "{x:?} vs {y:?}"
        );
    }
    let real = [0, 1, 2, 3, 6, 7, 8, 9];
    for (k, &i) in real.iter().enumerate() {
        assert!((a.z0[k] - b.z0[i]).abs() <= 1e-12 * a.amplitude[k].max(1e-30) + 1e-300);
    }
    for i in [4, 5, 10, 11] {
        assert_eq!(b.z0[i], 0.0);
        assert_eq!(b.amplitude[i], 0.0);
    }
    assert!(a.max_multiplier > 0.0 && (a.max_multiplier - b.max_multiplier).abs() <= 1e-9);
}

/// An 18-dof model run padded to 24 dofs: the default disc–pad plus 14
/// separate oscillators at rest (mass `m`, spring `k_i` and damper `c_i` to
/// ground). Its limit cycle is the disc–pad's, and its Floquet multipliers
/// are exactly the disc–pad's 8 and, for each oscillator, `exp(λ T)` with
/// `λ = −c/2m ± i √(k/m − (c/2m)²)`: 36 multipliers, each matched to 1e-6
/// (the extra states change the error norm, so the steps and the round-off
/// differ from the 4-dof run's; the period agrees to 1e-8 relative).
#[test]
fn an_18_dof_model_cycles_padded_with_the_exact_multipliers() {
    use squeal_core::cycle::{find_cycle, CycleOptions};
    let spec4 = disc_pad_spec(&DiscPad::default());
    let small = Lumped::build(&spec4).unwrap();
    let mut spec = spec4.clone();
    let (m, extra) = (0.5, 14);
    let mut expected = Vec::new();
    for i in 1..=extra {
        let name = format!("x{i}");
        let (k, c) = (1.0e6 * i as f64, 20.0 * i as f64);
        spec.dofs.push(name.clone());
        spec.masses.push((name.clone(), m));
        spec.springs.push(SpringSpec {
            name: format!("ground{i}"),
            on: vec![(name, 1.0)],
            k,
            c,
            k3: 0.0,
        });
        expected.push((-c / (2.0 * m), (k / m - (c / (2.0 * m)).powi(2)).sqrt()));
    }
    let big = Lumped::build(&spec).unwrap();
    assert_eq!(padded_dofs(big.dof_count()), Some(24));
    let padded = big.padded_to(24);
    let opts = CycleOptions::default();
    let a = find_cycle(&small, 0.0, [0.0; 8], &opts).unwrap();
    let mut popts = opts;
    popts.solver = padded_solver::<48>(&opts.solver, 36);
    let b = find_cycle(&padded, 0.0, [0.0; 48], &popts).unwrap();
    assert!(
        (a.period - b.period).abs() <= 1e-8 * a.period,
        "{} vs {}",
        a.period,
        b.period
    );
    assert_eq!(b.multipliers.len(), 36);
    let mut want: Vec<(f64, f64)> = a.multipliers.iter().map(|m| (m.re, m.im)).collect();
    for (re, im) in expected {
        let (r, phase) = ((re * b.period).exp(), im * b.period);
        want.push((r * phase.cos(), r * phase.sin()));
        want.push((r * phase.cos(), -r * phase.sin()));
    }
    let mut got: Vec<(f64, f64)> = b.multipliers.iter().map(|m| (m.re, m.im)).collect();
    for (re, im) in want {
        let (k, d) = got
            .iter()
            .enumerate()
            .map(|(k, g)| (k, (g.0 - re).hypot(g.1 - im)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap();
        assert!(
            d <= 1e-6,
            "multiplier {re:+.9} {im:+.9}i: nearest off by {d:.2e}"
        );
        got.remove(k);
    }
    assert!((a.max_multiplier - b.max_multiplier).abs() <= 1e-6);
    assert_eq!(a.stable, b.stable);
}
