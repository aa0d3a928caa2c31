//! The lane-wise right-hand side of lumped models (`LaneField for Fixed`):
//! bit for bit `field` in every mix of modes it covers, and whole ensembles
//! of lumped brakes bit for bit their single runs (stick–slip included).

use squeal_core::integrate::ensemble::{simulate_ensemble_lanes, Job, LaneField, Lanes, LANES};
use squeal_core::model::lumped::{self, Fixed, LumpedSpec, SpringSpec};
use squeal_core::model::System;
use squeal_core::sink::Recorder;
use squeal_core::{simulate, EventKind, FrictionLaw, Lumped, Mode, Modes, SolverOptions};

/// The two-pad brake of `scenarios/lumped/two-pad-brake.toml`
/// (`lumped::two_pad_spec`) made to exercise every part of the lane-wise
/// field: a spring coupling the disc's two directions (off-diagonal
/// stiffness and damping), a follower force on the first pad, a bilateral
/// layer on the second, stronger and velocity-weakening friction.
fn two_pad_spec() -> LumpedSpec {
    let mut spec = lumped::two_pad_spec();
    spec.springs.push(SpringSpec {
        name: "disc_xy".into(),
        on: vec![("x_d".into(), 0.3), ("y_d".into(), 1.0)],
        k: 1.0e6,
        c: 0.5,
        k3: 0.0,
    });
    for c in &mut spec.contacts {
        c.v = 1.0;
        c.friction = FrictionLaw::Thesis {
            f0: 0.3,
            f1: 0.09,
            uc: 10.0,
        };
    }
    spec.contacts[0].alpha = 0.2;
    spec.contacts[0].slope = vec![("y_d".into(), 1.0)];
    spec.contacts[1].bilateral = true;
    spec
}

/// Four (or [`LANES`]) brakes that differ in speed, friction and stiffness.
fn brakes() -> Vec<Lumped> {
    (0..LANES)
        .map(|l| {
            let mut m = Lumped::build(&two_pad_spec()).expect("a valid model");
            let x = l as f64;
            m.set("pad1.V", 0.5 + 0.4 * x).unwrap();
            m.set("pad2.V", 0.5 + 0.4 * x).unwrap();
            m.set("pad1.f1", 0.05 + 0.02 * x).unwrap();
            m.set("disc_xy.k", 1.0e6 * (1.0 + x)).unwrap();
            m.set("brake_1.value", -300.0 - 100.0 * x).unwrap();
            m.set("brake_2.value", 300.0 + 100.0 * x).unwrap();
            m
        })
        .collect()
}

#[test]
fn lumped_lane_field_is_field_bit_for_bit() {
    let models = brakes();
    let fixed: Vec<Fixed<'_, 12>> = models.iter().map(Fixed).collect();
    let pack = Fixed::pack(std::array::from_fn(|l| Some(&fixed[l])))
        .expect("two thesis contacts on a plain small model are lane-wise");
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let modes_all = [Mode::SlipPos, Mode::SlipNeg, Mode::Stick, Mode::Free];
    let mut covered = [0usize; 2];
    for _ in 0..400 {
        let z: [[f64; 12]; LANES] = std::array::from_fn(|_| {
            std::array::from_fn(|i| if i < 6 { 1e-4 } else { 1.0 } * rnd())
        });
        let t: [f64; LANES] = std::array::from_fn(|_| 0.01 * rnd().abs());
        let modes: [Modes; LANES] = std::array::from_fn(|_| {
            let mut m = Modes::all(2, Mode::SlipPos);
            for ci in 0..2 {
                m.set(ci, modes_all[((rnd() + 1.0) * 2.0) as usize % 4]);
            }
            m
        });
        let zl: [Lanes; 12] = std::array::from_fn(|i| Lanes::new(std::array::from_fn(|l| z[l][i])));
        let mut dz = [Lanes::ZERO; 12];
        let lane_modes = modes.map(Some);
        let done = Fixed::field_lanes(&pack, Lanes::new(t), &lane_modes, &zl, &mut dz);
        for l in 0..LANES {
            let sticks = modes[l].as_slice().contains(&Mode::Stick);
            assert_eq!(
                done[l], !sticks,
                "lanes with a stuck contact are left to field"
            );
            covered[usize::from(done[l])] += 1;
            if !done[l] {
                continue;
            }
            let mut want = [0.0; 12];
            fixed[l].field(t[l], &modes[l], &z[l], &mut want);
            for i in 0..12 {
                assert_eq!(
                    dz[i].lane(l).to_bits(),
                    want[i].to_bits(),
                    "state {i} lane {l} in {:?}: {} vs {}",
                    modes[l],
                    dz[i].lane(l),
                    want[i]
                );
            }
        }
    }
    assert!(
        covered[0] > 100 && covered[1] > 100,
        "both kinds drawn: {covered:?}"
    );
}

#[test]
fn models_the_lanes_cannot_share_are_not_packed() {
    let models = brakes();
    let fixed: Vec<Fixed<'_, 12>> = models.iter().map(Fixed).collect();
    // A friction law with exp and powf: every lane goes to `field`.
    let mut spec = two_pad_spec();
    spec.contacts[1].friction = FrictionLaw::by_name("stribeck").unwrap();
    let strib = Lumped::build(&spec).expect("a valid model");
    let f = Fixed::<12>(&strib);
    let mut lanes: [Option<&Fixed<'_, 12>>; LANES] = std::array::from_fn(|l| Some(&fixed[l]));
    lanes[LANES - 1] = Some(&f);
    assert!(Fixed::pack(lanes).is_none());
    // A ramped force changes with time along the run: not covered.
    let mut ramped = Lumped::build(&two_pad_spec()).unwrap();
    ramped.set("brake_1.ramp", 0.01).unwrap();
    let r = Fixed::<12>(&ramped);
    lanes[LANES - 1] = Some(&r);
    assert!(Fixed::pack(lanes).is_none());
    // Idle lanes borrow the first model and are fine.
    let mut idle: [Option<&Fixed<'_, 12>>; LANES] = [None; LANES];
    idle[1] = Some(&fixed[1]);
    assert!(Fixed::pack(idle).is_some());
}

/// The brakes of [`brakes`] and as many pressed with `press` (N) at low
/// speed, so that they stick and slip.
fn light_and_hard(press: f64) -> Vec<Lumped> {
    let mut models = brakes();
    for (l, mut m) in brakes().into_iter().enumerate() {
        m.set("pad1.V", 0.05 + 0.05 * l as f64).unwrap();
        m.set("pad2.V", 0.05 + 0.05 * l as f64).unwrap();
        m.set("brake_1.value", -press).unwrap();
        m.set("brake_2.value", press).unwrap();
        models.push(m);
    }
    models
}

#[test]
fn lumped_ensemble_is_single_runs_bit_for_bit() {
    // Each lane's samples, events and outcome (an error included) are its
    // single run's, while the lanes around it go on.
    let models = light_and_hard(1500.0);
    let fixed: Vec<Fixed<'_, 12>> = models.iter().map(Fixed).collect();
    // (A budget, so that a regression cannot hang the test.)
    let opts = SolverOptions {
        max_steps: 2_000_000,
        ..SolverOptions::default()
    };
    let (t_end, rate) = (0.02, 50_000.0);
    let mut jobs: Vec<Job<'_, Fixed<'_, 12>, Recorder<12>, 12>> = fixed
        .iter()
        .map(|m| Job {
            model: m,
            t0: 0.0,
            z0: [0.0; 12],
            t_end,
            opts,
            sink: Recorder::default(),
        })
        .collect();
    let results = simulate_ensemble_lanes(&mut jobs, rate);
    let (mut sticks, mut failed) = (0, 0);
    for (k, (job, got)) in jobs.iter().zip(&results).enumerate() {
        let mut single = Recorder::default();
        let want = simulate(&fixed[k], 0.0, [0.0; 12], t_end, rate, opts, &mut single);
        assert_eq!(format!("{got:?}"), format!("{want:?}"), "run {k}'s outcome");
        assert_eq!(job.sink.t.len(), single.t.len());
        for (a, b) in job.sink.z.iter().zip(&single.z) {
            assert_eq!(
                a.map(f64::to_bits),
                b.map(f64::to_bits),
                "run {k}'s samples"
            );
        }
        let times = |r: &Recorder<12>| r.events.iter().map(|e| e.t.to_bits()).collect::<Vec<_>>();
        assert_eq!(times(&job.sink), times(&single), "run {k}'s events");
        sticks += single
            .events
            .iter()
            .filter(|e| e.kind == EventKind::Stick)
            .count();
        failed += usize::from(want.is_err());
    }
    assert!(
        sticks > 20,
        "the hard-pressed brakes stick ({sticks} sticks)"
    );
    assert_eq!(failed, 0, "every run ends");
}

#[test]
fn hard_pressed_two_pad_brakes_stick_and_slip_to_the_end() {
    // At t = 8.0912e-4 s the first brake pressed with 3 kN brings pad2 to
    // v_rel = 0, where it sticks (its stick force is well within μ_s·F_n).
    // The state projected onto v_rel = 0 still gave V + t·q̇ ≈ −7e-18 by
    // round-off, whose sign chose "slip on, negative": the guard fired again
    // at once, and the run stood still until its step budget ran out. Every
    // brake of this set now runs to the end, sticking and slipping.
    let opts = SolverOptions {
        max_steps: 300_000,
        ..SolverOptions::default()
    };
    for (k, m) in light_and_hard(3000.0)[LANES..].iter().enumerate() {
        let mut log = Recorder::default();
        let info = simulate(
            &Fixed::<12>(m),
            0.0,
            [0.0; 12],
            0.02,
            50_000.0,
            opts,
            &mut log,
        )
        .unwrap_or_else(|e| panic!("brake {k}: {e}"));
        assert_eq!(info.t_final, 0.02);
        assert!(
            info.stats.events[0] > 20,
            "brake {k} sticks: {:?}",
            info.stats.events
        );
    }
}
