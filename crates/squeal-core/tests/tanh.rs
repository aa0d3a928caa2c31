//! The regularised Coulomb law `μ(v) = μ_k·tanh(v/ε)` (`friction = "tanh"`)
//! against exact results on the mass on a belt, `m ẍ + c ẋ + k x =
//! N μ(V − ẋ)`: its steady sliding `x* = N μ(V)/k`, the eigenvalues of its
//! linearisation `m ẍ + (c + N μ'(V)) ẋ + k x = 0` with
//! `μ'(V) = μ_k/ε · sech²(V/ε)`, and a small motion about steady sliding
//! against that linear solution.

use squeal_core::sink::Recorder;
use squeal_core::stability::eigenvalues;
use squeal_core::{simulate, Belt, FrictionLaw, Model, Parameters, SolverOptions};

fn belt(mu_k: f64, eps: f64) -> Belt {
    let mut b = Belt {
        friction: FrictionLaw::Tanh { mu_k, eps },
        ..Belt::default()
    };
    b.set("c", 0.2).unwrap();
    b.set("V", 1.0).unwrap();
    b
}

/// `(x*, a, ω_d)`: steady sliding, decay rate `(c + N μ'(V))/2m` and damped
/// frequency `√(k/m − a²)` from the formulas.
fn exact(b: &Belt, mu_k: f64, eps: f64) -> (f64, f64, f64) {
    let p = b.p;
    let x = p.N * mu_k * (p.V / eps).tanh() / p.k;
    let sech = 1.0 / (p.V / eps).cosh();
    let a = (p.c + p.N * mu_k / eps * sech * sech) / (2.0 * p.m);
    (x, a, (p.k / p.m - a * a).sqrt())
}

#[test]
fn steady_sliding_and_eigenvalues_are_the_exact_ones() {
    for (mu_k, eps) in [(0.3, 0.5), (0.3, 2.0), (0.8, 1.0)] {
        let b = belt(mu_k, eps);
        let (x, a, w) = exact(&b, mu_k, eps);
        let z = b.equilibrium().unwrap();
        assert!((z[0] - x).abs() <= 1e-14 * x, "x* {} vs {x}", z[0]);
        assert_eq!(z[1], 0.0);
        let ev = eigenvalues(&b).unwrap();
        for l in ev {
            assert!((l.re + a).abs() <= 1e-9 * a, "σ {} vs {}", l.re, -a);
            assert!((l.im.abs() - w).abs() <= 1e-9 * w, "ω {} vs {w}", l.im);
        }
    }
}

/// From steady sliding with a velocity kick `v₀` = 1e-4 m/s (ten thousand
/// times below V and ε), the motion is the linear one,
/// `x − x* = v₀/ω_d · e^{−a t} sin(ω_d t)`, to the law's curvature: the
/// next term is `N μ''(V) ẋ²/2`, relative size `v₀ μ''/μ'` ≈ 2e-4 here;
/// the run agrees to 1e-3 of the amplitude at every sample over 0.5 s
/// (eight periods), and no event occurs (it never stops sliding).
#[test]
fn a_small_motion_about_steady_sliding_is_the_linear_one() {
    let (mu_k, eps) = (0.3, 0.5);
    let b = belt(mu_k, eps);
    let (x, a, w) = exact(&b, mu_k, eps);
    let v0 = 1e-4;
    let opts = SolverOptions {
        rtol: 1e-10,
        atol_pos: Some(1e-14),
        atol_vel: Some(1e-12),
        ..SolverOptions::default()
    };
    let mut rec = Recorder::<2>::new();
    simulate(&b, 0.0, [x, v0], 0.5, 2000.0, opts, &mut rec).unwrap();
    assert!(rec.events.is_empty(), "{} events", rec.events.len());
    assert!(rec.t.len() > 900);
    let amp = v0 / w;
    for (t, z) in rec.t.iter().zip(&rec.z) {
        let lin = x + amp * (-a * t).exp() * (w * t).sin();
        assert!(
            (z[0] - lin).abs() <= 1e-3 * amp,
            "t = {t}: x {} vs linear {lin} (amplitude {amp:e})",
            z[0]
        );
    }
}

/// The law itself: odd, bounded by μ_k, slope μ_k/ε at 0, and it never
/// sticks (static coefficient μ(0) = 0).
#[test]
fn the_law_is_odd_bounded_and_never_sticks() {
    let law = FrictionLaw::by_name("tanh").unwrap();
    assert_eq!(law.get("mu_k"), Some(0.08));
    assert_eq!(law.get("eps"), Some(1e-3));
    let law = FrictionLaw::Tanh {
        mu_k: 0.4,
        eps: 0.01,
    };
    assert_eq!(law.mu_static(), 0.0);
    assert_eq!(law.mu(0.0), 0.0);
    assert!((law.dmu(0.0) - 40.0).abs() < 1e-12);
    for v in [1e-3, 0.02, 0.5, 30.0] {
        assert_eq!(law.mu(-v), -law.mu(v));
        assert!(law.mu(v) > 0.0 && law.mu(v) <= 0.4);
    }
    assert_eq!(law.mu(30.0), 0.4);
    let mut bad = law;
    assert!(bad.set("eps", 0.0).is_err());
    // Switching from Coulomb keeps the kinetic coefficient.
    let mut c = FrictionLaw::by_name("coulomb").unwrap();
    c.set("mu_k", 0.033).unwrap();
    let t = c.switch_to("tanh").unwrap();
    assert_eq!((t.get("mu_k"), t.get("eps")), (Some(0.033), Some(1e-3)));
}
