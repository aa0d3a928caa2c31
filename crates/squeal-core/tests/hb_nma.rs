//! Nonlinear modes (extended periodic motion concept) against exact
//! results: the Duffing oscillator with mass-proportional damping, whose
//! EPMC orbit is the free conservative one (frequency on the exact elliptic
//! backbone, `ξ` the damping itself), and the Coulomb-damped oscillator,
//! whose `ξ` balances the friction's work per period exactly; and a
//! friction damper that sticks, with stick as a constraint, against the
//! shooting orbit of the model with the EPMC's negative damping.

use squeal_core::cycle;
use squeal_core::hb::nma::{mode_guess, nonlinear_mode};
use squeal_core::hb::{Fourier, HbOptions};
use squeal_core::model::lumped::Fixed;
use squeal_core::Lumped;
use std::f64::consts::{PI, TAU};

fn one_dof(m: f64, k: f64, c: f64, k3: f64, friction: Option<f64>) -> Lumped {
    crate::hb_forced::oscillator(m, k, c, k3, 0.0, 0.0, friction)
}

fn opts(h: usize) -> HbOptions {
    HbOptions {
        harmonics: h,
        ..HbOptions::default()
    }
}

fn peak(f: &Fourier) -> f64 {
    let m = 20_000;
    (0..m)
        .map(|j| {
            let z: [f64; 2] = f.state(TAU * j as f64 / m as f64);
            z[0].abs()
        })
        .fold(0.0, f64::max)
}

fn ellip_k(m: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    for _ in 0..60 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        a = an;
        b = bn;
    }
    PI / (2.0 * a)
}

#[test]
fn a_mass_proportionally_damped_duffing_mode_is_the_exact_backbone() {
    // m = 2, c = α m: ξ = α cancels the damping exactly, and the orbit is
    // the free Duffing oscillation, ω = π ω₀ √(1 + βa²/ω₀²)/(2K(m_e)).
    let (m, k, alpha, k3) = (2.0, 2.0e4, 3.0, 4.0e7);
    let l = one_dof(m, k, alpha * m, k3, None);
    let sys = Fixed::<2>(&l);
    let mass = nalgebra::DMatrix::from_element(1, 1, m);
    let phi = [1.0 / m.sqrt()];
    let w0 = (k / m).sqrt();
    let (beta, mut g, mut xi) = (k3 / m, mode_guess(&[0.0], &phi, w0, 1e-3), 0.0);
    let mut last = 0.0;
    for a in [1e-3, 1e-2, 3e-2, 6e-2] {
        // The last solution scaled to the new amplitude (A = √m |Q₁|).
        let s = a / (m.sqrt() * g.amplitude(0, 1));
        for c in g.coeffs[0].iter_mut().skip(1) {
            *c *= s;
        }
        let p = nonlinear_mode(&sys, &mass, &phi, a, (&g, xi), &opts(16)).unwrap();
        let x = peak(&p.orbit.fourier);
        let s = w0 * w0 + beta * x * x;
        let exact = PI * s.sqrt() / (2.0 * ellip_k(beta * x * x / (2.0 * s)));
        let w = p.orbit.fourier.omega;
        assert!((w / exact - 1.0).abs() < 1e-9, "A = {a}: {w} vs {exact}");
        assert!((p.xi / alpha - 1.0).abs() < 1e-9, "A = {a}: ξ = {}", p.xi);
        assert!(w > last);
        last = w;
        (g, xi) = (p.orbit.fourier, p.xi);
    }
    // Hardening: 6e-2 of modal amplitude is far from linear.
    assert!(last > 1.2 * w0, "{last}");
}

#[test]
fn a_coulomb_damped_mode_balances_the_friction_work() {
    // ξ m ∮ẋ² dt = F_f ∮|ẋ| dt = 4 F_f X for any orbit with two reversals
    // (ẋ lies in the series' span, so the Galerkin equations keep this
    // energy balance exactly); with one harmonic, ω = ω₀ and ξ = 4F_f/(π m
    // ω X), the equivalent viscous damping.
    let (m, k, ff) = (1.5, 6.0e4, 2.0);
    let l = one_dof(m, k, 0.0, 0.0, Some(ff));
    let sys = Fixed::<2>(&l);
    let mass = nalgebra::DMatrix::from_element(1, 1, m);
    let phi = [1.0 / m.sqrt()];
    let w0 = (k / m).sqrt();
    let a = 2e-3;
    let g = mode_guess(&[0.0], &phi, w0, a);
    let p1 = nonlinear_mode(&sys, &mass, &phi, a, (&g, 0.0), &opts(1)).unwrap();
    let x1 = p1.orbit.fourier.amplitude(0, 1);
    assert!((p1.orbit.fourier.omega / w0 - 1.0).abs() < 1e-9);
    let eq = 4.0 * ff / (PI * m * w0 * x1);
    assert!((p1.xi / eq - 1.0).abs() < 1e-9, "{} vs {eq}", p1.xi);
    let p = nonlinear_mode(&sys, &mass, &phi, a, (&p1.orbit.fourier, p1.xi), &opts(30)).unwrap();
    let f = &p.orbit.fourier;
    let w = f.omega;
    let h = f.harmonics();
    let v2: f64 = PI
        * w
        * (1..=h)
            .map(|j| (j * j) as f64 * (f.amplitude(0, j)).powi(2))
            .sum::<f64>();
    let work = 4.0 * ff * peak(f);
    assert!(
        (p.xi * m * v2 / work - 1.0).abs() < 1e-6,
        "{} vs {work}",
        p.xi * m * v2
    );
    assert_eq!(p.orbit.switches, 2);
    // Friction damps: D = ξ/(2ω) > 0, and falls as the amplitude grows.
    let big = nonlinear_mode(
        &sys,
        &mass,
        &phi,
        4.0 * a,
        (&p.orbit.fourier, p.xi),
        &opts(30),
    )
    .unwrap();
    assert!(p.damping_ratio() > 0.0 && big.damping_ratio() < 0.5 * p.damping_ratio());
}

/// The two-dof chain of NLvib's example with an exact Coulomb damper on x2
/// (`μN = 10 N` to ground, `k₁ = k₂ = 10⁴ N/m`, `c₁ = c₂ = 0.2 kg/s`, unit
/// masses), plus an optional damping matrix `C = −ξ I`: with it, the EPMC
/// orbit of modal amplitude `A` is a periodic orbit of the model itself.
fn damper_chain(minus_xi: Option<f64>) -> Lumped {
    use squeal_core::model::lumped::{ContactSpec, LumpedSpec, SpringSpec, Triplets};
    use squeal_core::FrictionLaw;
    let on = |v: &[(&str, f64)]| v.iter().map(|(d, c)| (d.to_string(), *c)).collect();
    let spring = |name: &str, o: Vec<(String, f64)>| SpringSpec {
        name: name.into(),
        on: o,
        k: 1.0e4,
        c: 0.2,
        k3: 0.0,
    };
    let spec = LumpedSpec {
        dofs: vec!["x1".into(), "x2".into()],
        masses: vec![("x1".into(), 1.0), ("x2".into(), 1.0)],
        c: minus_xi.map(|xi| Triplets {
            rows: 2,
            cols: 2,
            entries: vec![(0, 0, -xi), (1, 1, -xi)],
        }),
        springs: vec![
            spring("k1", on(&[("x1", 1.0)])),
            spring("k2", on(&[("x2", 1.0), ("x1", -1.0)])),
        ],
        contacts: vec![ContactSpec {
            name: "damper".into(),
            normal: None,
            k: None,
            c: None,
            bilateral: false,
            normal_force: Some(10.0),
            tangent: Some(on(&[("x2", 1.0)])),
            v: 0.0,
            friction: FrictionLaw::Coulomb {
                mu_s: 1.0,
                mu_k: 1.0,
            },
            alpha: 0.0,
            slope: Vec::new(),
        }],
        ..LumpedSpec::default()
    };
    Lumped::build(&spec).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_mode_whose_damper_sticks_is_the_exact_orbit_with_stick_as_a_constraint() {
    // Mode 1 stuck: x1 alone on k₁ + k₂, ω = √(2·10⁴). At A = 1.2e-3 the
    // damper sticks twice per period. The HB orbit with stick as a
    // constraint, put into the model with C = −ξ I, is a stable periodic
    // orbit of that model (a friction damper under negative damping), which
    // shooting finds exactly (event-driven flow, stick exact): HB's
    // frequency and x1 amplitude approach it as H grows.
    let l = damper_chain(None);
    let sys = Fixed::<4>(&l);
    let mass = nalgebra::DMatrix::<f64>::identity(2, 2);
    let phi = [1.0, 0.0];
    let w = 2.0e4f64.sqrt();
    let stick = |h: usize| HbOptions {
        lagrangian: true,
        ..opts(h)
    };
    // At A = 1e-3 the damper never slips: the stuck linear mode exactly.
    let g = mode_guess(&[0.0, 0.0], &phi, w, 1e-3);
    let stuck = nonlinear_mode(&sys, &mass, &phi, 1e-3, (&g, 0.4), &stick(20)).unwrap();
    assert!((stuck.orbit.fourier.omega / w - 1.0).abs() < 1e-9);
    assert!((stuck.xi / 0.4 - 1.0).abs() < 1e-9, "ξ = {}", stuck.xi);
    let a = 1.2e-3;
    let mut from = stuck.orbit.fourier.clone();
    for c in &mut from.coeffs {
        for v in c.iter_mut() {
            *v *= a / 1e-3;
        }
    }
    // (relative frequency error, relative x1 amplitude error) against
    // shooting on the model with C = −ξ_H I.
    let error = |p: &squeal_core::hb::nma::ModePoint| {
        let f = &p.orbit.fourier;
        let aug = damper_chain(Some(p.xi));
        // At phase π x1 is at its least and ẋ1 crosses zero upwards.
        let z: [f64; 4] = f.state(PI);
        let section = cycle::Section {
            index: 2,
            level: z[2],
        };
        let c = cycle::shoot(
            &Fixed::<4>(&aug),
            z,
            TAU / f.omega,
            section,
            &crate::cycle::tight(1e-12, 1e-12),
        )
        .unwrap();
        assert!(c.stable && c.max_multiplier < 0.5, "{}", c.max_multiplier);
        assert_eq!(c.events_per_period[..2], [2, 2], "two sticks, two slips");
        // x1's half peak-to-peak from the series.
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for j in 0..20_000 {
            let z: [f64; 4] = f.state(TAU * j as f64 / 20_000.0);
            (lo, hi) = (lo.min(z[0]), hi.max(z[0]));
        }
        (
            (f.omega * c.period / TAU - 1.0).abs(),
            (0.5 * (hi - lo) / c.amplitude[0] - 1.0).abs(),
        )
    };
    let p20 = nonlinear_mode(&sys, &mass, &phi, a, (&from, 0.4), &stick(20)).unwrap();
    assert!(p20.orbit.sticks && p20.orbit.lagrangian);
    let p80 = nonlinear_mode(
        &sys,
        &mass,
        &phi,
        a,
        (&p20.orbit.fourier, p20.xi),
        &stick(80),
    )
    .unwrap();
    let (e20, e80) = (error(&p20), error(&p80));
    // Measured: frequency 1.25e-4 → 4.7e-5, amplitude 1.8e-3 → 1.1e-3
    // (algebraic: the kinks at stick; not monotone in H, H = 40 is 1.2e-4
    // and 2.5e-3).
    assert!(
        e20.0 < 2e-4 && e80.0 < 7e-5 && e80.0 < 0.5 * e20.0,
        "{e20:?} {e80:?}"
    );
    assert!(
        e20.1 < 3e-3 && e80.1 < 1.5e-3 && e80.1 < e20.1,
        "{e20:?} {e80:?}"
    );
    // Stick-slip damps the mode far more than the stuck mode's viscous
    // part (ξ = 0.4 1/s).
    assert!(p80.xi > 3.5 && p80.xi < 3.8, "ξ = {}", p80.xi);
}
