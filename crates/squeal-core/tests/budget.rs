//! The work budget: `min_steps` is a true lower bound on DOP853's steps, and
//! the budget leaves ordinary runs far inside it.

use squeal_core::integrate::budget::{min_steps, step_budget, STABILITY_REACH};
use squeal_core::sink::Discard;
use squeal_core::{simulate, Belt, FrictionLaw, Parameters, SolverOptions};

/// A belt oscillator without friction load (N = 0), so it is the linear
/// system m x'' + c x' + k x = 0 with eigenvalues λ = (−c ± √(c² − 4mk))/2m.
fn oscillator(m: f64, c: f64, k: f64) -> Belt {
    let mut b = Belt {
        friction: FrictionLaw::Coulomb {
            mu_s: 0.3,
            mu_k: 0.3,
        },
        ..Belt::default()
    };
    for (key, v) in [("m", m), ("c", c), ("k", k), ("N", 0.0), ("V", 1.0)] {
        b.set(key, v).unwrap();
    }
    b.validate().unwrap();
    b
}

fn steps(model: &Belt, t_end: f64) -> u64 {
    let opts = SolverOptions {
        rtol: 1e-6,
        atol_pos: Some(1e-9),
        atol_vel: Some(1e-9),
        ..SolverOptions::default()
    };
    let info = simulate(model, 0.0, [1e-3, 0.0], t_end, 10.0, opts, &mut Discard).unwrap();
    info.stats.accepted
}

#[test]
fn min_steps_bounds_stiff_and_oscillatory_runs_from_below() {
    // Overdamped: λ_fast = −(c + √(c² − 4mk))/2m ≈ −1e5 1/s; the step is
    // held at the edge of the stability region, so the bound is nearly tight.
    let (m, c, k): (f64, f64, f64) = (1.0, 1.0e5, 1.0);
    let lambda = (c + (c * c - 4.0 * m * k).sqrt()) / (2.0 * m);
    let t = 0.05;
    let n = steps(&oscillator(m, c, k), t) as f64;
    let bound = min_steps(lambda, t, f64::INFINITY);
    assert!(n >= bound, "{n} steps < bound {bound}");
    assert!(n <= 2.0 * bound, "{n} steps: the bound {bound} is loose");
    // Undamped: |λ| = ω = 1e5 rad/s; accuracy, not stability, limits the step.
    let n = steps(&oscillator(1.0, 0.0, 1.0e10), t) as f64;
    let bound = min_steps(1.0e5, t, f64::INFINITY);
    assert!(
        n >= bound && (n as u64) < step_budget(bound),
        "{n} vs {bound}"
    );
}

#[test]
fn h_max_and_the_budget_scale_as_documented() {
    assert_eq!(min_steps(0.0, 2.0, 1e-3), 2000.0);
    assert_eq!(
        min_steps(6.5e3, 1.0, f64::INFINITY),
        1e3 / (STABILITY_REACH / 6.5)
    );
    assert_eq!(step_budget(0.0), 2_000_000);
    assert_eq!(step_budget(1e4), 2_500_000);
    assert_eq!(step_budget(f64::INFINITY), u64::MAX);
    assert_eq!(step_budget(1e300), u64::MAX);
}
