//! Nonlinear modes (extended periodic motion concept) against exact
//! results: the Duffing oscillator with mass-proportional damping, whose
//! EPMC orbit is the free conservative one (frequency on the exact elliptic
//! backbone, `ξ` the damping itself), and the Coulomb-damped oscillator,
//! whose `ξ` balances the friction's work per period exactly.

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
