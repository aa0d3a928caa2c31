//! The engine against exact results: the belt's Coulomb stick-slip cycle,
//! energy conservation, the steady-sliding equilibrium, convergence of event
//! times, and grazing reversals.

use squeal_core::initial::{initial_state, Initial};
use squeal_core::model::disc_pad::Contact;
use squeal_core::model::{GuardKind, Modes};
use squeal_core::sink::{EventLog, Recorder};
use squeal_core::{
    simulate, Belt, DiscPad, EventKind, FrictionLaw, IntegrateError, Mode, Model, Parameters,
    SolverOptions,
};

/// The exact Coulomb stick-slip cycle of the undamped belt (derived in the
/// test's comments): stick from `2x_k − x_s` to `x_s = μ_s N/k` at the belt
/// speed, then a harmonic slip arc about `x_k = μ_k N/k` of radius
/// `R = √((x_s − x_k)² + (V/ω)²)` through the angle `π + 2φ`,
/// `φ = atan2(V/ω, x_s − x_k)`, back to `ẋ = V` at `2x_k − x_s`.
struct Cycle {
    x_s: f64,
    x_k: f64,
    t_stick: f64,
    t_slip: f64,
    radius: f64,
    omega: f64,
}

fn coulomb_cycle(m: f64, k: f64, n: f64, v: f64, mu_s: f64, mu_k: f64) -> Cycle {
    let omega = (k / m).sqrt();
    let x_s = mu_s * n / k;
    let x_k = mu_k * n / k;
    let xi = x_s - x_k;
    let phi = (v / omega).atan2(xi);
    Cycle {
        x_s,
        x_k,
        t_stick: 2.0 * xi / v,
        t_slip: (std::f64::consts::PI + 2.0 * phi) / omega,
        radius: (xi * xi + (v / omega).powi(2)).sqrt(),
        omega,
    }
}

fn belt(m: f64, k: f64, n: f64, v: f64, mu_s: f64, mu_k: f64) -> Belt {
    let mut b = Belt {
        friction: FrictionLaw::Coulomb { mu_s, mu_k },
        ..Belt::default()
    };
    b.set("m", m).unwrap();
    b.set("k", k).unwrap();
    b.set("c", 0.0).unwrap();
    b.set("N", n).unwrap();
    b.set("V", v).unwrap();
    b.validate().unwrap();
    b
}

#[test]
fn belt_coulomb_cycle_is_exact() {
    // (m, k, N, V, μ_s, μ_k): lab scale, pad-like scale (k ≈ 1e9 N/m), and a soft one.
    let sets = [
        (1.0, 1.0e4, 100.0, 0.1, 0.4, 0.3),
        (0.1, 1.0e9, 500.0, 1.0, 0.12, 0.08),
        (2.0, 500.0, 10.0, 0.05, 0.5, 0.2),
    ];
    for (m, k, n, v, mu_s, mu_k) in sets {
        let model = belt(m, k, n, v, mu_s, mu_k);
        let cyc = coulomb_cycle(m, k, n, v, mu_s, mu_k);
        let period = cyc.t_stick + cyc.t_slip;
        // Start on the cycle: riding the belt at 2x_k − x_s.
        let z0 = [2.0 * cyc.x_k - cyc.x_s, v];
        assert_eq!(model.initial_mode(0.0, &z0), Mode::Stick);
        let opts = SolverOptions {
            rtol: 1e-11,
            atol_pos: Some(1e-9 * cyc.x_s),
            atol_vel: Some(1e-13 * v),
            ..Default::default()
        };
        let mut rec = Recorder::<2>::new();
        let t_end = 5.5 * period;
        // Sample finely enough to see the extremes of the slip arc.
        let rate = 4000.0 / period;
        simulate(&model, 0.0, z0, t_end, rate, opts, &mut rec).unwrap();
        let slips: Vec<_> = rec.events_of(EventKind::Slip).collect();
        let sticks: Vec<_> = rec.events_of(EventKind::Stick).collect();
        assert_eq!(slips.len(), 6, "set k = {k}");
        assert_eq!(sticks.len(), 5, "set k = {k}");
        assert_eq!(rec.events.len(), 11, "no other events");
        for (i, e) in slips.iter().enumerate() {
            let want = cyc.t_stick + i as f64 * period;
            assert!(
                (e.t - want).abs() <= 1e-8 * period,
                "slip {i}: {} vs {want} (k = {k})",
                e.t
            );
            // Positions to 1e-8 of the cycle's size (the slip arc's radius or x_s).
            let size = cyc.radius.max(cyc.x_s);
            assert!(
                (e.z[0] - cyc.x_s).abs() <= 1e-8 * size,
                "slip position {}",
                e.z[0]
            );
        }
        for (i, e) in sticks.iter().enumerate() {
            let want = (i + 1) as f64 * period;
            assert!(
                (e.t - want).abs() <= 1e-8 * period,
                "stick {i}: {} vs {want} (k = {k})",
                e.t
            );
            let x = 2.0 * cyc.x_k - cyc.x_s;
            assert!(
                (e.z[0] - x).abs() <= 1e-8 * cyc.radius.max(cyc.x_s),
                "stick position {} vs {x}",
                e.z[0]
            );
        }
        // Extremes of the slip arc: x_k ± R, and the fastest backward speed −ωR.
        let xs = rec.component(0);
        let vs = rec.component(1);
        let xmax = xs.iter().cloned().fold(f64::MIN, f64::max);
        let xmin = xs.iter().cloned().fold(f64::MAX, f64::min);
        let vmin = vs.iter().cloned().fold(f64::MAX, f64::min);
        let tol = 2e-6 * cyc.radius; // sampling resolution of the extremum
        assert!((xmax - (cyc.x_k + cyc.radius)).abs() <= tol, "x_max {xmax}");
        assert!((xmin - (cyc.x_k - cyc.radius)).abs() <= tol, "x_min {xmin}");
        assert!(
            (vmin + cyc.omega * cyc.radius).abs() <= 2e-6 * cyc.omega * cyc.radius,
            "v_min {vmin}"
        );
    }
}

fn mechanical_energy(m: &DiscPad, z: &[f64; 8]) -> f64 {
    let p = &m.p;
    let kinetic =
        0.5 * p.m_d * (z[4] * z[4] + z[6] * z[6]) + 0.5 * p.m_p * (z[5] * z[5] + z[7] * z[7]);
    let delta = (z[2] - z[3]).max(0.0);
    let springs = 0.5
        * (p.k_dx * z[0] * z[0]
            + p.k_px * z[1] * z[1]
            + p.k_dy * z[2] * z[2]
            + p.k_py * delta * delta);
    // The constant load N does work −N·Δy_p: its potential is N·y_p.
    kinetic + springs + p.N * z[3]
}

#[test]
fn undamped_static_disc_conserves_energy() {
    let mut m = DiscPad::default();
    for key in ["c_dx", "c_dy", "c_px", "c_py", "V", "f1", "alpha"] {
        m.set(key, 0.0).unwrap();
    }
    let opts = SolverOptions {
        rtol: 1e-10,
        ..Default::default()
    };
    let mut rec = Recorder::<8>::new();
    let z0 = initial_state(&m, Initial::Rest, &[0.0; 8]).unwrap();
    simulate(&m, 0.0, z0, 0.05, 200_000.0, opts, &mut rec).unwrap();
    let scale = 0.5 * m.p.N * m.p.N * (1.0 / m.p.k_dy + 1.0 / m.p.k_py);
    let e0 = mechanical_energy(&m, &rec.z[0]);
    let worst = rec
        .z
        .iter()
        .map(|z| (mechanical_energy(&m, z) - e0).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= 1e-7 * scale,
        "energy drift {worst:e} J of {scale:e} J"
    );
    // No friction at V = 0: the tangential motion stays exactly zero.
    assert!(rec
        .z
        .iter()
        .all(|z| z[0] == 0.0 && z[1] == 0.0 && z[4] == 0.0 && z[5] == 0.0));
    // It did move normally: the disc's normal displacement reaches ~2N/k_dy.
    let ymin = rec.z.iter().map(|z| z[2]).fold(f64::MAX, f64::min);
    assert!(ymin < -1.5 * m.p.N / m.p.k_dy, "{ymin}");
}

#[test]
fn damped_sliding_settles_on_the_equilibrium() {
    let mut m = DiscPad::default();
    m.set("f1", 0.0).unwrap();
    for (key, c) in [
        ("c_dx", 4000.0),
        ("c_dy", 4000.0),
        ("c_px", 400.0),
        ("c_py", 400.0),
    ] {
        m.set(key, c).unwrap();
    }
    let eq = m.equilibrium().unwrap();
    let mut rec = Recorder::<8>::new();
    simulate(
        &m,
        0.0,
        [0.0; 8],
        0.03,
        1000.0,
        SolverOptions::default(),
        &mut rec,
    )
    .unwrap();
    let z = rec.z.last().unwrap();
    for i in 0..4 {
        assert!(
            (z[i] - eq[i]).abs() <= 1e-6 * eq[i].abs(),
            "state {i}: {} vs {}",
            z[i],
            eq[i]
        );
    }
    for v in &z[4..] {
        assert!(v.abs() < 1e-9, "velocity {v}");
    }
    // MODEL.md §5 closed form, spelled out: F_y* = N with α = 0, x_p* = μ N / k_px.
    assert!((eq[1] - 0.1 * 500.0 / 1.7e9).abs() < 1e-20);
}

#[test]
fn event_times_converge_with_rtol() {
    let (m, k, n, v, mu_s, mu_k) = (1.0, 1.0e4, 100.0, 0.1, 0.4, 0.3);
    let model = belt(m, k, n, v, mu_s, mu_k);
    let cyc = coulomb_cycle(m, k, n, v, mu_s, mu_k);
    let period = cyc.t_stick + cyc.t_slip;
    // Exact stick times from rest: the first when ẋ first reaches V on the
    // slip arc about x_k of radius x_k, at x1; then the ride to x_s, one slip
    // arc, and whole periods.
    let t1 = (v / (cyc.omega * cyc.x_k)).asin() / cyc.omega;
    let x1 = cyc.x_k * (1.0 - (cyc.omega * t1).cos());
    let t2 = t1 + (cyc.x_s - x1) / v + cyc.t_slip;
    let exact = |i: usize| {
        if i == 0 {
            t1
        } else {
            t2 + (i - 1) as f64 * period
        }
    };
    let rtols = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10];
    let mut errors = Vec::new();
    for rtol in rtols {
        let opts = SolverOptions {
            rtol,
            atol_pos: Some(rtol * cyc.x_s),
            atol_vel: Some(rtol * v),
            ..Default::default()
        };
        let mut log = EventLog::<2>::default();
        simulate(&model, 0.0, [0.0, 0.0], 20.0 * period, 1.0, opts, &mut log).unwrap();
        let sticks: Vec<f64> = log
            .events
            .iter()
            .filter(|e| e.kind == EventKind::Stick)
            .map(|e| e.t)
            .collect();
        assert_eq!(sticks.len(), 20);
        let err = sticks
            .iter()
            .enumerate()
            .map(|(i, t)| (t - exact(i)).abs())
            .fold(0.0, f64::max);
        errors.push(err / period);
    }
    // Observed order in rtol: least-squares slope of log error against log rtol;
    // tolerance proportionality makes it ≈ 1.
    let xs: Vec<f64> = rtols.iter().map(|r| r.ln()).collect();
    let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / 5.0, ys.iter().sum::<f64>() / 5.0);
    let slope = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / xs.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
    eprintln!("max relative stick-time errors {errors:?}, order in rtol {slope:.2}");
    assert!(slope > 0.7, "event times do not converge: slope {slope}");
    assert!(errors[4] < 1e-8, "{errors:?}");
}

/// Start at equilibrium with the pad's tangential velocity kicked to just
/// under V: the sliding velocity grazes zero over and over. Every reversal
/// must be found, as confirmed by a run with a tiny maximum step.
#[test]
fn grazing_reversals_are_all_found() {
    let m = DiscPad::default();
    let mut offsets = [0.0; 8];
    offsets[5] = 0.98 * m.p.V; // v = V − ẋ_p starts at 0.02 V
    let z0 = initial_state(&m, Initial::Equilibrium, &offsets).unwrap();
    let t_end = 2e-3;
    let run = |h_max: f64| {
        let opts = SolverOptions {
            h_max,
            ..Default::default()
        };
        let mut log = EventLog::<8>::default();
        let info = simulate(&m, 0.0, z0, t_end, 1.0, opts, &mut log).unwrap();
        (log.events, info)
    };
    let (coarse, info) = run(f64::INFINITY);
    let (fine, _) = run(2e-8);
    let rev = |ev: &[squeal_core::sink::EventRecord<8>]| {
        ev.iter().filter(|e| e.kind == EventKind::Reverse).count()
    };
    eprintln!(
        "grazing: {} events ({} reversals) with {} steps; fine run {} events",
        coarse.len(),
        rev(&coarse),
        info.stats.accepted,
        fine.len()
    );
    assert!(
        rev(&coarse) > 20,
        "reversals expected, got {}",
        rev(&coarse)
    );
    assert_eq!(coarse.len(), fine.len());
    // Steps are longer than the excursions: the events are found inside steps.
    let mean_step = t_end / info.stats.accepted as f64;
    let shortest_excursion = coarse
        .windows(2)
        .map(|w| w[1].t - w[0].t)
        .fold(f64::MAX, f64::min);
    assert!(
        shortest_excursion < mean_step,
        "{shortest_excursion:e} vs step {mean_step:e}"
    );
    for (a, b) in coarse.iter().zip(&fine) {
        assert_eq!(a.kind, b.kind);
        assert!((a.t - b.t).abs() < 1e-10, "{} vs {}", a.t, b.t);
    }
}

/// In a default run from rest the squeal grows into reversals; mode and the
/// sign of the sliding velocity never contradict each other.
#[test]
fn default_run_mode_matches_sign_of_sliding_velocity() {
    let m = DiscPad::default();
    let mut rec = Recorder::<8>::new();
    let info = simulate(
        &m,
        0.0,
        [0.0; 8],
        0.5,
        200_000.0,
        SolverOptions::default(),
        &mut rec,
    )
    .unwrap();
    let reversals = info.stats.event_count(EventKind::Reverse);
    eprintln!(
        "default 0.5 s: {} steps, {} rejected, {} rhs, events {:?}, stick {:.3e}",
        info.stats.accepted,
        info.stats.rejected,
        info.stats.rhs_evals,
        info.stats.events,
        info.stats.stick_fraction()
    );
    assert!(
        reversals > 100,
        "the default brake squeals into reversals: {reversals}"
    );
    for (z, mode) in rec.z.iter().zip(&rec.mode) {
        let v = m.sliding_velocity(z);
        match mode {
            Mode::SlipPos => assert!(v >= -1e-12, "SlipPos with v = {v}"),
            Mode::SlipNeg => assert!(v <= 1e-12, "SlipNeg with v = {v}"),
            Mode::Stick => assert!(v.abs() <= 1e-12, "Stick with v = {v}"),
            Mode::Free => {}
        }
    }
    // Every stick ends with a slip: true stick intervals are counted.
    let sticks = info.stats.event_count(EventKind::Stick);
    let slips = info.stats.event_count(EventKind::Slip);
    assert!(slips + 1 >= sticks && slips <= sticks + 1);
}

#[test]
fn bilateral_contact_never_separates() {
    let m = DiscPad {
        contact: Contact::Bilateral,
        ..DiscPad::default()
    };
    let mut log = EventLog::<8>::default();
    simulate(
        &m,
        0.0,
        [0.0; 8],
        0.01,
        1.0,
        SolverOptions::default(),
        &mut log,
    )
    .unwrap();
    assert!(log
        .events
        .iter()
        .all(|e| e.kind != EventKind::Separate && e.kind != EventKind::Contact));
}

/// N ramped linearly over t_ramp: with heavy normal damping the disc follows
/// the load quasi-statically, y_d(t) ≈ −N(t)/k_dy, and the end of the ramp is
/// a step boundary (no step crosses it).
#[test]
fn ramped_load_is_followed_quasi_statically() {
    let mut m = DiscPad::default();
    for (k, v) in [
        ("t_ramp", 0.02),
        ("c_dy", 2.0e4),
        ("c_py", 2.0e3),
        ("V", 0.0),
    ] {
        m.set(k, v).unwrap();
    }
    assert_eq!(m.next_breakpoint(0.0), Some(0.02));
    let mut rec = Recorder::<8>::new();
    simulate(
        &m,
        0.0,
        [0.0; 8],
        0.03,
        10_000.0,
        SolverOptions::default(),
        &mut rec,
    )
    .unwrap();
    // Heavily overdamped (ζ ≈ 3.5): the disc's normal motion is the first-order
    // lag c_dy·ẏ + k_dy·y = −N(t), τ = c_dy/k_dy = 2.5 ms (inertia: m/c = 50 µs).
    let (tau, k, big_t) = (2.0e4 / 8.0e6, 8.0e6, 0.02);
    let exact = |t: f64| {
        let rate = 500.0 / (k * big_t);
        if t <= big_t {
            -rate * (t - tau * (1.0 - (-t / tau).exp()))
        } else {
            -500.0 / k + rate * tau * (1.0 - (-big_t / tau).exp()) * (-(t - big_t) / tau).exp()
        }
    };
    for (t, z) in rec.t.iter().zip(&rec.z) {
        let y = exact(*t);
        assert!(
            (z[2] - y).abs() <= 0.01 * 500.0 / k,
            "t = {t}: y_d {} vs {y}",
            z[2]
        );
    }
    assert_eq!(rec.t.len(), 301);
}

/// A model whose every mode is left as soon as it is entered: the run must
/// end with a chatter error that says when, not hang.
#[test]
fn endless_chatter_is_reported_with_its_time() {
    use squeal_core::model::{GuardKind, Guards, ModelError, Observables};
    use squeal_core::IntegrateError;
    struct Chatter;
    impl Model<2> for Chatter {
        fn name(&self) -> &'static str {
            "chatter"
        }
        fn state_names(&self) -> [&'static str; 2] {
            ["x", "v"]
        }
        fn rhs(&self, _t: f64, mode: Mode, _z: &[f64; 2], dz: &mut [f64; 2]) {
            // Always pushed towards v = 0 from either side, and back through it.
            dz[0] = 0.0;
            dz[1] = -mode.slip_sign();
        }
        fn guards(&self, mode: Mode, out: &mut Guards<2>) {
            out.clear();
            let s = mode.slip_sign();
            out.push(GuardKind::SlipZero, [0.0, -s], 0.0);
        }
        fn transition(
            &self,
            _t: f64,
            mode: Mode,
            _g: GuardKind,
            z: &mut [f64; 2],
        ) -> (Mode, Option<EventKind>) {
            z[1] = 0.0;
            let next = if mode == Mode::SlipPos {
                Mode::SlipNeg
            } else {
                Mode::SlipPos
            };
            (next, Some(EventKind::Reverse))
        }
        fn initial_mode(&self, _t: f64, _z: &[f64; 2]) -> Mode {
            Mode::SlipPos
        }
        fn observe(&self, _t: f64, _m: Mode, _z: &[f64; 2]) -> Observables {
            Observables::default()
        }
        fn equilibrium(&self) -> Result<[f64; 2], ModelError> {
            Err(ModelError::NoSteadySliding("test model".into()))
        }
        fn jacobian(&self, _z: &[f64; 2]) -> [[f64; 2]; 2] {
            [[0.0; 2]; 2]
        }
    }
    let mut log = EventLog::<2>::default();
    let err = simulate(
        &Chatter,
        0.0,
        [0.0, 1e-3],
        1.0,
        10.0,
        SolverOptions::default(),
        &mut log,
    )
    .unwrap_err();
    match err {
        IntegrateError::Chatter { t, .. } => assert!((t - 1e-3).abs() < 1e-12, "t = {t}"),
        other => panic!("expected chatter, got {other:?}"),
    }
    assert!(err.to_string().contains("t = 1.000000000e-3"), "{err}");
}

/// A model whose transition keeps its mode and puts the state back a
/// round-off below its guard (`x = 1 − 1e-17·…`, moving up at 1 m/s): the
/// guard crosses again within the same instant, without end.
struct Stubborn;

impl squeal_core::model::System<2> for Stubborn {
    fn system_name(&self) -> &str {
        "stubborn"
    }
    fn names(&self) -> Vec<String> {
        vec!["x".into(), "v".into()]
    }
    fn contacts(&self) -> usize {
        1
    }
    fn contact_name(&self, _i: usize) -> &str {
        "wall"
    }
    fn field(&self, _t: f64, _modes: &Modes, z: &[f64; 2], dz: &mut [f64; 2]) {
        *dz = [z[1], 0.0];
    }
    fn mode_guards(&self, _modes: &Modes, out: &mut squeal_core::model::Guards<2>) {
        out.clear();
        out.push(GuardKind::SlipZero, [1.0, 0.0], -1.0);
    }
    fn switch(
        &self,
        _t: f64,
        modes: &Modes,
        _g: &squeal_core::model::Guard<2>,
        z: &mut [f64; 2],
    ) -> (Modes, Option<EventKind>) {
        z[0] = 1.0 - f64::EPSILON;
        (*modes, None)
    }
    fn start_modes(&self, _t: f64, _z: &[f64; 2]) -> Modes {
        Modes::single(Mode::SlipPos)
    }
    fn observe_contact(
        &self,
        _t: f64,
        _modes: &Modes,
        z: &[f64; 2],
        _i: usize,
    ) -> squeal_core::model::Observables {
        squeal_core::model::Observables {
            normal_force: 0.0,
            friction_force: 0.0,
            v_rel: z[1],
        }
    }
    fn steady_sliding(&self) -> Result<[f64; 2], squeal_core::model::ModelError> {
        Err(squeal_core::model::ModelError::NoSteadySliding(
            "a test model".into(),
        ))
    }
    fn state_jacobian(&self, _z: &[f64; 2]) -> [[f64; 2]; 2] {
        [[0.0, 1.0], [0.0, 0.0]]
    }
}

#[test]
fn a_guard_that_fires_again_without_changing_a_mode_ends_the_run() {
    // Before IntegrateError::Stalled the run took zero-length steps until
    // its step budget ran out (here 10⁶ of them).
    let opts = SolverOptions {
        max_steps: 1_000_000,
        ..SolverOptions::default()
    };
    let err = simulate(
        &Stubborn,
        0.0,
        [0.0, 1.0],
        2.0,
        100.0,
        opts,
        &mut Recorder::default(),
    )
    .expect_err("the run cannot go on");
    match &err {
        IntegrateError::Stalled {
            t,
            contact,
            surface,
            count,
        } => {
            assert!((t - 1.0).abs() < 1e-12, "at the wall: {t}");
            assert_eq!(
                (contact.as_str(), *surface, *count),
                ("wall", "v_rel = 0", 100)
            );
        }
        other => panic!("expected a stall, got {other}"),
    }
    assert!(err.to_string().starts_with("no progress at t = 1.000000000e0 s: contact wall's v_rel = 0 guard fired 100 times in a row"), "{err}");
}
