//! Lumped models against the hand-written ones and against exact results:
//! the thesis's disc–pad, the belt and Hoffmann's model written as lumped
//! models; two contacts sticking at once (solved by hand); a stick-break guard
//! that is not affine against a run with a tiny maximum step; the analytic
//! Jacobian against finite differences; refused descriptions.

use squeal_core::model::lumped::{ContactSpec, ForceSpec, LumpedSpec, SpringSpec};
use squeal_core::model::System;
use squeal_core::sink::{EventLog, Recorder};
use squeal_core::stability::{analyse, critical, max_growth_rate, CriticalOptions};
use squeal_core::{
    simulate, Belt, DiscPad, EventKind, FrictionLaw, Hoffmann, Lumped, Mode, Modes, Parameters,
    SolverOptions,
};

fn terms(t: &[(&str, f64)]) -> Vec<(String, f64)> {
    t.iter().map(|(n, v)| (n.to_string(), *v)).collect()
}

fn spring(name: &str, on: &[(&str, f64)], k: f64, c: f64) -> SpringSpec {
    SpringSpec {
        name: name.into(),
        on: terms(on),
        k,
        c,
        k3: 0.0,
    }
}

fn force(name: &str, on: &[(&str, f64)], value: f64) -> ForceSpec {
    ForceSpec {
        name: name.into(),
        on: terms(on),
        value,
        ramp: 0.0,
        amplitude: 0.0,
        freq_hz: 0.0,
    }
}

fn prescribed(
    name: &str,
    tangent: &[(&str, f64)],
    n: f64,
    v: f64,
    law: FrictionLaw,
) -> ContactSpec {
    ContactSpec {
        name: name.into(),
        normal: None,
        k: None,
        c: None,
        bilateral: false,
        normal_force: Some(n),
        tangent: Some(terms(tangent)),
        v,
        friction: law,
        alpha: 0.0,
        slope: Vec::new(),
    }
}

/// The thesis's disc–pad as a lumped model, exactly as the issue writes it:
/// springs on x_d, y_d, x_p; the brake force −N on y_p; one contact with
/// normal {y_d: 1, y_p: −1} and tangent {x_d: 1, x_p: −1}.
fn disc_pad_spec(m: &DiscPad) -> LumpedSpec {
    let p = &m.p;
    LumpedSpec {
        dofs: ["x_d", "x_p", "y_d", "y_p"].map(String::from).to_vec(),
        masses: terms(&[
            ("x_d", p.m_d),
            ("x_p", p.m_p),
            ("y_d", p.m_d),
            ("y_p", p.m_p),
        ]),
        springs: vec![
            spring("disc_x", &[("x_d", 1.0)], p.k_dx, p.c_dx),
            spring("disc_y", &[("y_d", 1.0)], p.k_dy, p.c_dy),
            spring("pad_x", &[("x_p", 1.0)], p.k_px, p.c_px),
        ],
        forces: vec![force("brake", &[("y_p", 1.0)], -p.N)],
        contacts: vec![ContactSpec {
            name: "pad".into(),
            normal: Some(terms(&[("y_d", 1.0), ("y_p", -1.0)])),
            k: Some(p.k_py),
            c: Some(p.c_py),
            bilateral: false,
            normal_force: None,
            tangent: Some(terms(&[("x_d", 1.0), ("x_p", -1.0)])),
            v: p.V,
            friction: m.friction,
            alpha: p.alpha,
            slope: terms(&[("y_d", 1.0)]),
        }],
        ..Default::default()
    }
}

fn lumped(spec: &LumpedSpec) -> Lumped {
    Lumped::build(spec).unwrap_or_else(|e| panic!("{e}"))
}

fn disc_pad_opts() -> SolverOptions {
    SolverOptions {
        atol_pos: Some(1e-16),
        atol_vel: Some(1e-11),
        ..Default::default()
    }
}

// ---------------------------------------------------------------------------
// The disc–pad
// ---------------------------------------------------------------------------

#[test]
fn lumped_disc_pad_eigenvalues_equal_the_built_in() {
    for alpha in [0.0, -2.0e4] {
        let mut dp = DiscPad::default();
        dp.set("alpha", alpha).unwrap();
        let lp = lumped(&disc_pad_spec(&dp));
        let a = analyse(&dp).unwrap();
        let b = analyse::<_, 8>(&lp).unwrap();
        for (x, y) in a.eigen.iter().zip(&b.eigen) {
            let mag = x.re.hypot(x.im);
            assert!(
                (x.re - y.re).abs() <= 1e-10 * mag && (x.im - y.im).abs() <= 1e-10 * mag,
                "alpha {alpha}: {} {} vs {} {}",
                x.re,
                x.im,
                y.re,
                y.im
            );
        }
        for (x, y) in a.equilibrium.iter().zip(&b.equilibrium) {
            assert!((x - y).abs() <= 1e-12 * x.abs().max(1e-12), "{x} vs {y}");
        }
        assert_eq!(b.least_stable_mode().dominant_name, "x_p");
    }
}

#[test]
fn lumped_disc_pad_events_equal_the_built_in_at_n_2000() {
    let mut dp = DiscPad::default();
    dp.set("N", 2000.0).unwrap();
    let lp = lumped(&disc_pad_spec(&dp));
    let (mut a, mut b) = (EventLog::<8>::default(), EventLog::<8>::default());
    simulate(&dp, 0.0, [0.0; 8], 0.5, 1000.0, disc_pad_opts(), &mut a).unwrap();
    simulate(&lp, 0.0, [0.0; 8], 0.5, 1000.0, disc_pad_opts(), &mut b).unwrap();
    eprintln!(
        "{} events, first {:?}",
        a.events.len(),
        a.events.first().map(|e| (e.t, e.kind))
    );
    assert!(a.events.len() >= 16, "only {} events", a.events.len());
    for (k, (x, y)) in a.events.iter().zip(&b.events).take(16).enumerate() {
        assert_eq!(x.kind, y.kind, "event {k}");
        assert!(
            (x.t - y.t).abs() <= 1e-9,
            "event {k} ({:?}): {} vs {}",
            x.kind,
            x.t,
            y.t
        );
        assert_eq!(y.contact, 0);
    }
}

#[test]
fn lumped_disc_pad_rms_equals_the_built_in() {
    let dp = DiscPad::default();
    let lp = lumped(&disc_pad_spec(&dp));
    let (mut a, mut b) = (Recorder::<8>::new(), Recorder::<8>::new());
    simulate(&dp, 0.0, [0.0; 8], 0.5, 200_000.0, disc_pad_opts(), &mut a).unwrap();
    simulate(&lp, 0.0, [0.0; 8], 0.5, 200_000.0, disc_pad_opts(), &mut b).unwrap();
    assert_eq!(a.t.len(), b.t.len());
    let rms = |r: &Recorder<8>, i: usize| {
        (r.z.iter().map(|z| z[i] * z[i]).sum::<f64>() / r.z.len() as f64).sqrt()
    };
    for i in 0..8 {
        let (x, y) = (rms(&a, i), rms(&b, i));
        assert!((x - y).abs() <= 1e-6 * x, "state {i}: RMS {x:e} vs {y:e}");
    }
}

// ---------------------------------------------------------------------------
// The belt: the exact Coulomb stick-slip cycle
// ---------------------------------------------------------------------------

#[test]
fn lumped_belt_follows_the_exact_coulomb_cycle() {
    let (m, k, n, v, mu_s, mu_k) = (1.0, 1.0e4, 100.0, 0.1, 0.4, 0.3);
    let law = FrictionLaw::Coulomb { mu_s, mu_k };
    let spec = LumpedSpec {
        dofs: vec!["x".into()],
        masses: terms(&[("x", m)]),
        springs: vec![spring("spring", &[("x", 1.0)], k, 0.0)],
        contacts: vec![prescribed("belt", &[("x", -1.0)], n, v, law)],
        ..Default::default()
    };
    let lp = lumped(&spec);
    // The cycle (engine.rs derives it): stick from 2x_k − x_s to x_s at speed V,
    // then a slip arc about x_k through the angle π + 2φ.
    let omega = (k / m).sqrt();
    let (x_s, x_k) = (mu_s * n / k, mu_k * n / k);
    let phi = (v / omega).atan2(x_s - x_k);
    let t_stick = 2.0 * (x_s - x_k) / v;
    let t_slip = (std::f64::consts::PI + 2.0 * phi) / omega;
    let opts = SolverOptions {
        rtol: 1e-11,
        atol_pos: Some(1e-9 * x_s),
        atol_vel: Some(1e-13 * v),
        ..Default::default()
    };
    let mut log = EventLog::<2>::default();
    let z0 = [2.0 * x_k - x_s, v];
    assert_eq!(System::<2>::start_modes(&lp, 0.0, &z0).first(), Mode::Stick);
    simulate(
        &lp,
        0.0,
        z0,
        5.5 * (t_stick + t_slip),
        100.0,
        opts,
        &mut log,
    )
    .unwrap();
    let slips: Vec<f64> = log
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Slip)
        .map(|e| e.t)
        .collect();
    let sticks: Vec<f64> = log
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Stick)
        .map(|e| e.t)
        .collect();
    assert_eq!(slips.len(), 6);
    for (j, t) in slips.iter().enumerate() {
        let want = t_stick + j as f64 * (t_stick + t_slip);
        assert!(
            (t - want).abs() <= 1e-8 * (t_stick + t_slip),
            "slip {j}: {t} vs {want}"
        );
    }
    for (j, t) in sticks.iter().enumerate() {
        let want = (j + 1) as f64 * (t_stick + t_slip);
        assert!(
            (t - want).abs() <= 1e-8 * (t_stick + t_slip),
            "stick {j}: {t} vs {want}"
        );
    }
    // The built-in belt gives the same events.
    let mut b = Belt {
        friction: law,
        ..Belt::default()
    };
    b.set("k", k).unwrap();
    b.set("V", v).unwrap();
    let mut log_b = EventLog::<2>::default();
    simulate(
        &b,
        0.0,
        z0,
        5.5 * (t_stick + t_slip),
        100.0,
        opts,
        &mut log_b,
    )
    .unwrap();
    assert_eq!(log_b.events.len(), log.events.len());
}

// ---------------------------------------------------------------------------
// Hoffmann: the critical friction coefficient
// ---------------------------------------------------------------------------

/// Hoffmann's model as a lumped model, with `y` measured from where the
/// contact spring is unstressed (`y' = y + N0/k3`), so that the contact's
/// normal force is `k3·y' = N0 + k3·y`: the stiffness matrix splits into
/// springs `(k11 − k12) e_x e_xᵀ + (k22 − k3 − k12) e_y e_yᵀ + k12 (e_x+e_y)(e_x+e_y)ᵀ`
/// plus the contact's `k3 e_y e_yᵀ`, and the shift becomes constant forces
/// `k12·y0` on x and `k22·y0` on y'.
fn hoffmann_spec(h: &Hoffmann, mu: f64) -> LumpedSpec {
    let p = &h.p;
    let y0 = p.N0 / p.k3;
    LumpedSpec {
        dofs: vec!["x".into(), "y".into()],
        masses: terms(&[("x", p.m), ("y", p.m)]),
        springs: vec![
            spring("kx", &[("x", 1.0)], p.k11 - p.k12, p.c1),
            spring("ky", &[("y", 1.0)], p.k22 - p.k3 - p.k12, p.c2),
            spring("kxy", &[("x", 1.0), ("y", 1.0)], p.k12, 0.0),
        ],
        forces: vec![
            force("fx", &[("x", 1.0)], p.k12 * y0),
            force("fy", &[("y", 1.0)], p.k22 * y0),
        ],
        contacts: vec![ContactSpec {
            name: "belt".into(),
            normal: Some(terms(&[("y", 1.0)])),
            k: Some(p.k3),
            c: Some(0.0),
            bilateral: false,
            normal_force: None,
            tangent: Some(terms(&[("x", -1.0)])),
            v: p.V,
            friction: FrictionLaw::Coulomb {
                mu_s: 1.0,
                mu_k: mu,
            },
            alpha: 0.0,
            slope: Vec::new(),
        }],
        ..Default::default()
    }
}

#[test]
fn lumped_hoffmann_has_the_same_critical_mu() {
    let mut h = Hoffmann::default();
    // The shifted springs must be non-negative: k22 − k3 − k12 ≥ 0.
    h.set("k22", 1.3e4).unwrap();
    let opts = CriticalOptions {
        rtol: 1e-13,
        ..Default::default()
    };
    let built_in = critical(
        |mu| {
            let mut m = h;
            m.set("mu", mu).unwrap();
            max_growth_rate(&m)
        },
        0.01,
        1.0,
        &opts,
    )
    .unwrap()
    .unwrap();
    let lumped_c = critical(
        |mu| max_growth_rate::<_, 4>(&lumped(&hoffmann_spec(&h, mu))),
        0.01,
        1.0,
        &opts,
    )
    .unwrap()
    .unwrap();
    assert!(
        (built_in.value - lumped_c.value).abs() <= 1e-9 * built_in.value,
        "{} vs {}",
        built_in.value,
        lumped_c.value
    );
}

// ---------------------------------------------------------------------------
// Several contacts sticking at once
// ---------------------------------------------------------------------------

/// A carrier (mass 1) on a belt moving at V and a slider (mass 2) on the
/// carrier, each held by a spring to ground; Coulomb friction with prescribed
/// normal loads. Contact `a`: carrier on belt, `v_a = V − ẋ1`; contact `b`:
/// slider on carrier, `v_b = ẋ1 − ẋ2`. The stick constraints are coupled
/// (`t_a·M⁻¹·t_b = −1/m1`).
fn carrier(law_b: FrictionLaw) -> (LumpedSpec, [f64; 8]) {
    let (m1, m2, k1, k2, v, na, nb) = (1.0, 5.0, 1.0e4, 5.0e3, 0.1, 400.0, 100.0);
    let spec = LumpedSpec {
        dofs: vec!["x1".into(), "x2".into()],
        masses: terms(&[("x1", m1), ("x2", m2)]),
        springs: vec![
            spring("k1", &[("x1", 1.0)], k1, 0.0),
            spring("k2", &[("x2", 1.0)], k2, 0.0),
        ],
        contacts: vec![
            prescribed(
                "a",
                &[("x1", -1.0)],
                na,
                v,
                FrictionLaw::Coulomb {
                    mu_s: 0.5,
                    mu_k: 0.3,
                },
            ),
            prescribed("b", &[("x1", 1.0), ("x2", -1.0)], nb, 0.0, law_b),
        ],
        ..Default::default()
    };
    (spec, [m1, m2, k1, k2, v, na, nb, 0.0])
}

#[test]
fn two_contacts_stick_together_and_break_away_in_the_order_derived_by_hand() {
    let (mu_sb, mu_kb) = (0.4, 0.3);
    let (spec, [_m1, _m2, k1, k2, v, na, nb, _]) = carrier(FrictionLaw::Coulomb {
        mu_s: mu_sb,
        mu_k: mu_kb,
    });
    let lp = lumped(&spec);
    // Both ride the belt from x = 0: x1 = x2 = V t. With both accelerations
    // zero, the multipliers are λ_b = k2 V t (slider) and λ_a = (k1 + k2) V t.
    let t_b = mu_sb * nb / (k2 * v); // λ_b reaches μ_s,b N_b: 0.08 s
    assert!(
        (k1 + k2) * v * t_b < 0.5 * na,
        "a must still stick when b breaks"
    );
    // Then the carrier still rides the belt (x1 = V t) while the slider slips
    // (v_b > 0, F_b = μ_k,b N_b): λ_a = k1 V t + μ_k,b N_b reaches μ_s,a N_a at
    let t_a = (0.5 * na - mu_kb * nb) / (k1 * v); // 0.17 s
                                                  // Premise: the slider has not come back to v_b = 0 by then. Its motion is
                                                  // harmonic about μ_k N_b/k2 with ω² = k2/m2, from x2 = V t_b, ẋ2 = V.
    let (m2, w) = (5.0, (k2 / 5.0f64).sqrt());
    let xe = mu_kb * nb / k2;
    let x_dot = |t: f64| {
        let tau = t - t_b;
        v * (w * tau).cos() - w * (v * t_b - xe) * (w * tau).sin()
    };
    for i in 1..=100 {
        let t = t_b + (t_a - t_b) * i as f64 / 100.0;
        assert!(
            v - x_dot(t) > 0.0,
            "premise: the slider slips on at t = {t}"
        );
    }
    let _ = m2;
    let z0 = [0.0, 0.0, 0.0, 0.0];
    let z0 = [z0[0], z0[1], v, v];
    let modes = System::<4>::start_modes(&lp, 0.0, &z0);
    assert_eq!(modes.as_slice(), &[Mode::Stick, Mode::Stick]);
    let opts = SolverOptions {
        rtol: 1e-11,
        atol_pos: Some(1e-12),
        atol_vel: Some(1e-12),
        ..Default::default()
    };
    let mut log = EventLog::<4>::default();
    simulate(&lp, 0.0, z0, t_a + 0.001, 1000.0, opts, &mut log).unwrap();
    let ev: Vec<(f64, EventKind, usize)> = log
        .events
        .iter()
        .map(|e| (e.t, e.kind, e.contact))
        .collect();
    assert_eq!(ev.len(), 2, "{ev:?}");
    assert_eq!(
        (ev[0].1, ev[0].2),
        (EventKind::Slip, 1),
        "the slider breaks away first"
    );
    assert!((ev[0].0 - t_b).abs() <= 1e-9, "{} vs {t_b}", ev[0].0);
    assert_eq!((ev[1].1, ev[1].2), (EventKind::Slip, 0), "then the carrier");
    assert!((ev[1].0 - t_a).abs() <= 1e-9, "{} vs {t_a}", ev[1].0);
    // While both stick, the multipliers are the hand-derived ones.
    let mut rec = Recorder::<4>::new();
    simulate(&lp, 0.0, z0, 0.05, 100.0, opts, &mut rec).unwrap();
    let both = Modes::all(2, Mode::Stick);
    for (t, z) in rec.t.iter().zip(&rec.z) {
        let a = lp.observe_dyn(*t, &both, z, 0).friction_force;
        let b = lp.observe_dyn(*t, &both, z, 1).friction_force;
        assert!(
            (a - (k1 + k2) * v * t).abs() <= 1e-9 * (1.0 + a.abs()),
            "t = {t}: λ_a = {a}"
        );
        assert!(
            (b - k2 * v * t).abs() <= 1e-9 * (1.0 + b.abs()),
            "t = {t}: λ_b = {b}"
        );
    }
}

#[test]
fn stick_break_with_velocity_dependent_friction_elsewhere_is_found_as_with_a_tiny_step() {
    // The slider's friction depends on its speed (rational law): the
    // carrier's stick-break guard contains μ(v_b) and is not affine.
    let (spec, _) = carrier(FrictionLaw::Rational {
        mu_s: 0.4,
        delta: 30.0,
    });
    let lp = lumped(&spec);
    let v = 0.1;
    let z0 = [0.0, 0.0, v, v];
    let run = |h_max: f64| {
        let opts = SolverOptions {
            rtol: 1e-11,
            atol_pos: Some(1e-12),
            atol_vel: Some(1e-12),
            h_max,
            ..Default::default()
        };
        let mut log = EventLog::<4>::default();
        simulate(&lp, 0.0, z0, 0.6, 1000.0, opts, &mut log).unwrap();
        log.events
    };
    let coarse = run(f64::INFINITY);
    let fine = run(1e-5);
    assert!(coarse.len() >= 3, "{} events", coarse.len());
    assert_eq!(coarse.len(), fine.len());
    for (a, b) in coarse.iter().zip(&fine) {
        assert_eq!((a.kind, a.contact), (b.kind, b.contact));
        assert!(
            (a.t - b.t).abs() <= 1e-8,
            "{:?}: {} vs {}",
            a.kind,
            a.t,
            b.t
        );
    }
    assert!(
        coarse
            .iter()
            .any(|e| e.kind == EventKind::Slip && e.contact == 0),
        "the carrier breaks away while the slider slips"
    );
}

// ---------------------------------------------------------------------------
// Jacobian, refused descriptions
// ---------------------------------------------------------------------------

#[test]
fn lumped_jacobian_matches_central_differences() {
    // A two-pad brake with a follower force and different laws.
    let spec = LumpedSpec {
        dofs: ["x_d", "y_d", "x_p1", "y_p1", "x_p2", "y_p2"]
            .map(String::from)
            .to_vec(),
        masses: terms(&[
            ("x_d", 2.0),
            ("y_d", 2.0),
            ("x_p1", 0.1),
            ("y_p1", 0.1),
            ("x_p2", 0.12),
            ("y_p2", 0.12),
        ]),
        springs: vec![
            spring("disc_x", &[("x_d", 1.0)], 2e9, 2.0),
            spring("disc_y", &[("y_d", 1.0)], 1.6e7, 2.0),
            spring("pad1_x", &[("x_p1", 1.0)], 1.7e9, 0.2),
            spring("pad2_x", &[("x_p2", 1.0), ("x_d", 0.1)], 1.5e9, 0.2),
        ],
        forces: vec![
            force("b1", &[("y_p1", 1.0)], -500.0),
            force("b2", &[("y_p2", 1.0)], 500.0),
        ],
        contacts: vec![
            ContactSpec {
                name: "pad1".into(),
                normal: Some(terms(&[("y_d", 1.0), ("y_p1", -1.0)])),
                k: Some(4.25e9),
                c: Some(0.2),
                bilateral: false,
                normal_force: None,
                tangent: Some(terms(&[("x_d", 1.0), ("x_p1", -1.0)])),
                v: 1.0,
                friction: FrictionLaw::default(),
                alpha: -1e4,
                slope: terms(&[("y_d", 1.0)]),
            },
            ContactSpec {
                name: "pad2".into(),
                normal: Some(terms(&[("y_p2", 1.0), ("y_d", -1.0)])),
                k: Some(3.0e9),
                c: Some(0.3),
                bilateral: false,
                normal_force: None,
                tangent: Some(terms(&[("x_d", 1.0), ("x_p2", -1.0)])),
                v: 1.0,
                friction: FrictionLaw::by_name("stribeck").unwrap(),
                alpha: 0.0,
                slope: Vec::new(),
            },
        ],
        ..Default::default()
    };
    let lp = lumped(&spec);
    let zeq = lp.equilibrium_dyn().unwrap();
    let z: Vec<f64> = zeq
        .iter()
        .enumerate()
        .map(|(i, x)| {
            x + if i < 6 {
                1e-8 * (i as f64 - 2.5)
            } else {
                1e-3 * (i as f64 - 8.0)
            }
        })
        .collect();
    let an = lp.jacobian_dyn(&z);
    let modes = lp.steady_modes();
    for j in 0..12 {
        let h = if j < 6 { 1e-10 } else { 1e-6 };
        let (mut zp, mut zm) = (z.clone(), z.clone());
        zp[j] += h;
        zm[j] -= h;
        let fp = lp.field_dyn(0.0, &modes, &zp);
        let fm = lp.field_dyn(0.0, &modes, &zm);
        for i in 0..12 {
            let fd = (fp[i] - fm[i]) / (2.0 * h);
            let row_max = (0..12)
                .map(|k| an[(i, k)].abs() * if k < 6 { 1e-7 } else { 1e-3 })
                .fold(0.0, f64::max);
            let s = if j < 6 { 1e-7 } else { 1e-3 };
            let tol = 1e-6 * (an[(i, j)] * s).abs() + 1e-8 * row_max;
            assert!(
                ((an[(i, j)] - fd) * s).abs() <= tol,
                "J[{i}][{j}]: analytic {:e} vs FD {fd:e}",
                an[(i, j)]
            );
        }
    }
    // Steady sliding: the field vanishes there.
    let f = lp.field_dyn(f64::INFINITY, &modes, &zeq);
    for (i, x) in f.iter().enumerate().skip(6) {
        assert!(x.abs() < 1e-6, "acceleration {i} = {x:e} at steady sliding");
    }
}

#[test]
fn bad_descriptions_name_the_element_and_key() {
    let base = disc_pad_spec(&DiscPad::default());
    let refused = |f: &dyn Fn(&mut LumpedSpec)| {
        let mut s = base.clone();
        f(&mut s);
        Lumped::build(&s).unwrap_err().0
    };
    let e = refused(&|s| s.springs[0].on = terms(&[("x_q", 1.0)]));
    assert_eq!(e, "spring 'disc_x': on: unknown dof 'x_q'");
    let e = refused(&|s| s.masses[1].1 = -1.0);
    assert!(
        e.contains("masses") && e.contains("x_p") && e.contains("-1"),
        "{e}"
    );
    let e = refused(&|s| s.contacts[0].tangent = None);
    assert!(e.starts_with("contact 'pad': tangent"), "{e}");
    let e = refused(&|s| {
        let mut c = s.contacts[0].clone();
        c.name = "pad2".into();
        s.contacts.push(c);
    });
    assert!(
        e.contains("'pad2'") && e.contains("'pad'") && e.contains("redundant"),
        "{e}"
    );
    let e = refused(&|s| s.springs[1].name = "disc_x".into());
    assert!(e.contains("disc_x") && e.contains("name"), "{e}");
    let e = refused(&|s| {
        s.m = Some(squeal_core::model::lumped::Triplets {
            rows: 4,
            cols: 3,
            entries: vec![],
        })
    });
    assert!(e.contains("M") && e.contains("not square"), "{e}");
    let e = refused(&|s| {
        s.m = Some(squeal_core::model::lumped::Triplets {
            rows: 4,
            cols: 4,
            entries: vec![(0, 1, 1.0)],
        })
    });
    assert!(e.contains("not symmetric"), "{e}");
}

// ---------------------------------------------------------------------------
// The two-pad brake against the half model
// ---------------------------------------------------------------------------

/// A symmetric two-pad brake: a disc (x_d, y_d) of mass `2m_d`, tangential
/// stiffness `2k_dx`, damping `2c_dx` between two identical pads pressed
/// from opposite sides (pad 1 by −N on y_p1, compression y_d − y_p1; pad 2
/// by +N on y_p2, compression y_p2 − y_d).
///
/// **Correspondence.** Motions with `x_p1 = x_p2 = x_p`, `y_p2 = −y_p1 = −y_p`
/// and `y_d = 0` stay so: both compressions equal `−y_p`, so both normal and
/// friction forces are equal; the normal forces on the disc cancel (y_d stays
/// at rest whatever its stiffness, i.e. its normal dof is held as if rigid);
/// the disc's tangential equation `2m_d ẍ_d = −2k_dx x_d − 2c_dx ẋ_d − 2F_t`
/// is the half model's times two. So the half model — disc (x_d) of mass
/// `m_d`, one pad (x_p, y_p), compression `−y_p` — has exactly the
/// eigenvalues of the two-pad brake's symmetric modes: each of its 6
/// eigenvalues is one of the two-pad brake's 12.
#[test]
fn symmetric_two_pad_brake_contains_the_half_models_eigenvalues() {
    let (m_d, k_dx, c_dx, m_p, k_px, c_px, k_py, c_py, n) =
        (1.0, 1.0e9, 1.0, 0.1, 1.7e9, 0.2, 4.25e9, 0.2, 500.0);
    let law = FrictionLaw::default();
    let contact = |name: &str, normal: &[(&str, f64)], tangent: &[(&str, f64)]| ContactSpec {
        name: name.into(),
        normal: Some(terms(normal)),
        k: Some(k_py),
        c: Some(c_py),
        bilateral: false,
        normal_force: None,
        tangent: Some(terms(tangent)),
        v: 1.0,
        friction: law,
        alpha: 0.0,
        slope: Vec::new(),
    };
    let half = lumped(&LumpedSpec {
        dofs: ["x_d", "x_p", "y_p"].map(String::from).to_vec(),
        masses: terms(&[("x_d", m_d), ("x_p", m_p), ("y_p", m_p)]),
        springs: vec![
            spring("disc_x", &[("x_d", 1.0)], k_dx, c_dx),
            spring("pad_x", &[("x_p", 1.0)], k_px, c_px),
        ],
        forces: vec![force("brake", &[("y_p", 1.0)], -n)],
        contacts: vec![contact(
            "pad",
            &[("y_p", -1.0)],
            &[("x_d", 1.0), ("x_p", -1.0)],
        )],
        ..Default::default()
    });
    let two = lumped(&LumpedSpec {
        dofs: ["x_d", "y_d", "x_p1", "y_p1", "x_p2", "y_p2"]
            .map(String::from)
            .to_vec(),
        masses: terms(&[
            ("x_d", 2.0 * m_d),
            ("y_d", 2.0 * m_d),
            ("x_p1", m_p),
            ("y_p1", m_p),
            ("x_p2", m_p),
            ("y_p2", m_p),
        ]),
        springs: vec![
            spring("disc_x", &[("x_d", 1.0)], 2.0 * k_dx, 2.0 * c_dx),
            spring("disc_y", &[("y_d", 1.0)], 1.6e7, 2.0),
            spring("pad1_x", &[("x_p1", 1.0)], k_px, c_px),
            spring("pad2_x", &[("x_p2", 1.0)], k_px, c_px),
        ],
        forces: vec![
            force("brake_1", &[("y_p1", 1.0)], -n),
            force("brake_2", &[("y_p2", 1.0)], n),
        ],
        contacts: vec![
            contact(
                "pad1",
                &[("y_d", 1.0), ("y_p1", -1.0)],
                &[("x_d", 1.0), ("x_p1", -1.0)],
            ),
            contact(
                "pad2",
                &[("y_p2", 1.0), ("y_d", -1.0)],
                &[("x_d", 1.0), ("x_p2", -1.0)],
            ),
        ],
        ..Default::default()
    });
    let h = analyse::<_, 6>(&half).unwrap();
    let t = analyse::<_, 12>(&two).unwrap();
    // The disc's normal dof stays at rest (to round-off of the Newton solve;
    // the pads' static deflection is ≈ 1.2e-7 m).
    assert!(
        t.equilibrium[1].abs() <= 1e-18,
        "y_d* = {:e}",
        t.equilibrium[1]
    );
    for e in &h.eigen {
        let mag = e.re.hypot(e.im);
        let best = t
            .eigen
            .iter()
            .map(|f| (f.re - e.re).hypot(f.im - e.im))
            .fold(f64::INFINITY, f64::min);
        assert!(
            best <= 1e-10 * mag,
            "half-model eigenvalue {} {}: nearest at {best:e}",
            e.re,
            e.im
        );
    }
    // The half model's unstable pad mode is the brake's.
    assert!(
        (h.max_growth_rate - t.max_growth_rate).abs() <= 1e-9 * t.max_growth_rate.abs().max(1.0)
    );
}

/// A large lumped model through the dense path (beyond the fixed-size
/// limit): 200 decoupled oscillators `m ẍ + c ẋ + k x = 0`, whose eigenvalues
/// are known in closed form, `λ = −c/2m ± i·√(k/m − (c/2m)²)`.
#[test]
fn large_decoupled_model_has_the_closed_form_eigenvalues() {
    use squeal_core::model::lumped::Triplets;
    let n = 200;
    let mut spec = LumpedSpec {
        dofs: (1..=n).map(|i| format!("q{i}")).collect(),
        ..Default::default()
    };
    let (mut mm, mut kk, mut cc) = (
        Triplets::default(),
        Triplets::default(),
        Triplets::default(),
    );
    for t in [&mut mm, &mut kk, &mut cc] {
        t.rows = n;
        t.cols = n;
    }
    let mut want = Vec::new();
    for i in 0..n {
        let f = i as f64;
        let (m, k, c) = (0.5 + 0.01 * f, 1.0e4 * (1.0 + 0.37 * f), 0.3 + 0.02 * f);
        mm.entries.push((i, i, m));
        kk.entries.push((i, i, k));
        cc.entries.push((i, i, c));
        let a = c / (2.0 * m);
        want.push((-a, (k / m - a * a).sqrt()));
    }
    spec.m = Some(mm);
    spec.k = Some(kk);
    spec.c = Some(cc);
    let l = lumped(&spec);
    let ev = squeal_core::stability::lumped::eigenvalues(&l).unwrap();
    assert_eq!(ev.len(), 2 * n);
    for (re, im) in want {
        for s in [1.0, -1.0] {
            let best = ev
                .iter()
                .map(|e| (e.re - re).hypot(e.im - s * im))
                .fold(f64::INFINITY, f64::min);
            assert!(best <= 1e-10 * re.hypot(im), "{re} {im}: nearest {best:e}");
        }
    }
}

/// The simulation's right-hand side of a small model runs on folded
/// operators (springs, `K`, `C` as two diagonals and the off-diagonal
/// entries, constant forces in one vector, contacts as dense rows; one
/// contact without the contact loop; a "plain" model — no ramp, no
/// off-diagonal entry, diagonal masses — in one pass); the stability and
/// equilibrium code on the element loops. Both are the same force: equal
/// to 1e-12 of the largest term, in every mode combination, with a
/// follower force, a ramped force, a bilateral contact, a prescribed load,
/// a mass matrix with off-diagonal terms, and after parameters changed by
/// `set`.
#[test]
fn folded_field_equals_the_element_loops() {
    use squeal_core::model::lumped::{disc_pad_spec, two_pad_spec, Fixed, Triplets};
    let mut follower = disc_pad_spec(&DiscPad::default());
    follower.contacts[0].alpha = 0.4;
    follower.forces[0].ramp = 0.01;
    // Plain (no ramp, diagonal masses, springs on single dofs), one contact.
    let mut plain = disc_pad_spec(&DiscPad::default());
    plain.contacts[0].alpha = 0.4;
    let mut plain_bilateral = plain.clone();
    plain_bilateral.contacts[0].bilateral = true;
    let mut bilateral = two_pad_spec();
    bilateral.contacts[1].bilateral = true;
    let mut belt = LumpedSpec {
        dofs: vec!["x".into(), "y".into()],
        masses: terms(&[("x", 1.0), ("y", 2.0)]),
        m: Some(Triplets {
            rows: 2,
            cols: 2,
            entries: vec![(0, 1, 0.3), (1, 0, 0.3)],
        }),
        k: Some(Triplets {
            rows: 2,
            cols: 2,
            entries: vec![(0, 0, 1e4), (0, 1, -2e3), (1, 0, -2e3), (1, 1, 3e4)],
        }),
        springs: vec![spring("sx", &[("x", 1.0), ("y", -0.5)], 5e3, 0.7)],
        forces: vec![force("f", &[("y", 1.0)], 20.0)],
        ..Default::default()
    };
    belt.contacts.push(prescribed(
        "belt",
        &[("x", -1.0)],
        100.0,
        0.5,
        FrictionLaw::Stribeck {
            mu_s: 0.5,
            mu_k: 0.3,
            v_s: 0.1,
            delta: 2.0,
            sigma: 0.01,
        },
    ));
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let check = |l: &Lumped, label: &str, z: &[f64]| {
        let nc = l.contacts.len();
        let all = [Mode::SlipPos, Mode::SlipNeg, Mode::Stick, Mode::Free];
        for code in 0..4usize.pow(nc as u32) {
            let mut modes = Modes::all(nc, Mode::SlipPos);
            for i in 0..nc {
                modes.set(i, all[(code / 4usize.pow(i as u32)) % 4]);
            }
            for t in [0.003, 1.0] {
                let want = l.field_dyn(t, &modes, z);
                let got: Vec<f64> = match z.len() {
                    4 => {
                        let mut dz = [0.0; 4];
                        Fixed::<4>(l).field(t, &modes, z.try_into().unwrap(), &mut dz);
                        dz.to_vec()
                    }
                    8 => {
                        let mut dz = [0.0; 8];
                        Fixed::<8>(l).field(t, &modes, z.try_into().unwrap(), &mut dz);
                        dz.to_vec()
                    }
                    12 => {
                        let mut dz = [0.0; 12];
                        Fixed::<12>(l).field(t, &modes, z.try_into().unwrap(), &mut dz);
                        dz.to_vec()
                    }
                    _ => unreachable!(),
                };
                let scale = want.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                for (a, b) in got.iter().zip(&want) {
                    assert!(
                        (a - b).abs() <= 1e-12 * scale,
                        "{label} {modes:?} t={t}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    };
    for (label, spec, pos, vel) in [
        ("follower", follower, 1e-6, 0.5),
        ("plain", plain, 1e-6, 0.5),
        (
            "plain without follower",
            disc_pad_spec(&DiscPad::default()),
            1e-6,
            0.5,
        ),
        ("plain bilateral", plain_bilateral, 1e-6, 0.5),
        ("two-pad bilateral", bilateral, 1e-6, 0.5),
        ("belt with M, K", belt, 1e-2, 0.5),
    ] {
        let mut l = lumped(&spec);
        let n = l.dof_count();
        for round in 0..3 {
            let z: Vec<f64> = (0..2 * n)
                .map(|i| if i < n { pos * rnd() } else { vel * rnd() })
                .collect();
            check(&l, label, &z);
            // Change every parameter a little through `set`, then again.
            for (k, v) in l.keys() {
                if v != 0.0 && !k.starts_with("mass.") && !k.ends_with(".ramp") {
                    l.set(&k, v * (1.0 + 0.01 * (round + 1) as f64)).unwrap();
                }
            }
        }
    }
}

/// Above 64 dofs Newton's steady-sliding solve runs on faer's LU: a dof
/// held by nothing (a zero row and column) is refused as singular, as the
/// small models' nalgebra path does; held, the equilibrium balances every
/// force (residual at round-off).
#[test]
fn large_equilibrium_is_solved_and_a_free_dof_is_refused() {
    let n = 70;
    let mut spec = LumpedSpec {
        dofs: (0..n).map(|i| format!("q{i}")).collect(),
        masses: (0..n).map(|i| (format!("q{i}"), 1.0)).collect(),
        ..Default::default()
    };
    for i in 1..n {
        spec.springs.push(spring(
            &format!("s{i}"),
            &[(&format!("q{i}"), 1.0), (&format!("q{}", i - 1), -1.0)],
            1e5 * (1.0 + i as f64 / n as f64),
            0.1,
        ));
    }
    spec.forces.push(force("f", &[("q5", 1.0)], 3.0));
    spec.contacts.push(prescribed(
        "belt",
        &[("q1", -1.0)],
        100.0,
        1.0,
        FrictionLaw::Coulomb {
            mu_s: 0.5,
            mu_k: 0.3,
        },
    ));
    spec.springs
        .push(spring("ground", &[("q0", 1.0)], 2e5, 0.1));
    let l = lumped(&spec);
    let z = l.equilibrium_dyn().unwrap();
    let f = l.field_dyn(f64::INFINITY, &l.steady_modes(), &z);
    let scale = 100.0;
    assert!(
        f[n..].iter().all(|a| a.abs() <= 1e-9 * scale),
        "{:?}",
        &f[n..]
    );
    spec.dofs.push("loose".into());
    spec.masses.push(("loose".into(), 1.0));
    let l = lumped(&spec);
    let e = l.equilibrium_dyn().unwrap_err().to_string();
    assert!(e.contains("singular"), "{e}");
}
