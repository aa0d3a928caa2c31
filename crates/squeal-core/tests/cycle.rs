//! Limit cycles against exact results: the Coulomb belt's stick-slip cycle
//! (period, stick and slip times, multipliers {1, 0}), Leine et al.'s belt
//! against a long simulation, the saltation monodromy of the disc–pad's
//! reversal cycle against finite differences through the event-driven flow.

use squeal_core::cycle::{self, find_cycle, CycleOptions, Multiplier};
use squeal_core::sink::EventLog;
use squeal_core::{simulate, Belt, DiscPad, EventKind, FrictionLaw, Parameters, SolverOptions};

fn belt(m: f64, k: f64, n: f64, v: f64, c: f64, law: FrictionLaw) -> Belt {
    let mut b = Belt {
        friction: law,
        ..Belt::default()
    };
    for (key, val) in [("m", m), ("k", k), ("c", c), ("N", n), ("V", v)] {
        b.set(key, val).unwrap();
    }
    b.validate().unwrap();
    b
}

/// Tight shooting options: `rtol` 1e-12, the given absolute tolerances on
/// positions and velocities, Newton to 1e-11.
pub(crate) fn tight(pos: f64, vel: f64) -> CycleOptions {
    CycleOptions {
        solver: SolverOptions {
            rtol: 1e-12,
            atol_pos: Some(pos),
            atol_vel: Some(vel),
            ..Default::default()
        },
        newton_tol: 1e-11,
        ..CycleOptions::default()
    }
}

fn assert_one_zero(mult: &[Multiplier], tol: f64) {
    assert_eq!(mult.len(), 2);
    assert!(mult[0].trivial, "{mult:?}");
    assert!(
        (mult[0].re - 1.0).abs() <= tol && mult[0].im == 0.0,
        "{mult:?}"
    );
    assert!(mult[1].abs() <= tol, "{mult:?}");
}

#[test]
fn coulomb_belt_cycle_is_exact() {
    let sets = [
        (1.0, 1.0e4, 100.0, 0.1, 0.4, 0.3),
        (0.1, 1.0e9, 500.0, 1.0, 0.12, 0.08),
        (2.0, 500.0, 10.0, 0.05, 0.5, 0.2),
    ];
    for (m, k, n, v, mu_s, mu_k) in sets {
        let model = belt(m, k, n, v, 0.0, FrictionLaw::Coulomb { mu_s, mu_k });
        // The exact cycle (engine test): stick from 2x_k − x_s to x_s, a
        // harmonic slip arc of radius R about x_k through the angle π + 2φ.
        let omega = (k / m).sqrt();
        let (x_s, x_k) = (mu_s * n / k, mu_k * n / k);
        let xi = x_s - x_k;
        let phi = (v / omega).atan2(xi);
        let t_stick = 2.0 * xi / v;
        let t_slip = (std::f64::consts::PI + 2.0 * phi) / omega;
        let radius = (xi * xi + (v / omega).powi(2)).sqrt();
        let period = t_stick + t_slip;
        let opts = tight(1e-9 * x_s, 1e-13 * v);
        let cyc = find_cycle(&model, 0.0, [2.0 * x_k - x_s, v], &opts).unwrap();
        assert!(
            (cyc.period - period).abs() <= 1e-8 * period,
            "period {} vs {period} (k = {k})",
            cyc.period
        );
        assert_one_zero(&cyc.multipliers, 1e-8);
        assert!(cyc.stable);
        assert_eq!(cyc.events_per_period[EventKind::Stick.index()], 1);
        assert_eq!(cyc.events_per_period[EventKind::Slip.index()], 1);
        assert_eq!(cyc.events_per_period.iter().sum::<u64>(), 2);
        // The section is the upward zero of ẋ, at the slip arc's far end
        // (angle π from its top): stick φ/ω later, slip t_stick after that.
        assert_eq!(cyc.section.index, 1);
        let orbit = cycle::orbit(&model, &cyc, &opts).unwrap();
        let at = |kind| {
            orbit
                .t
                .iter()
                .zip(&orbit.event)
                .find(|(_, e)| e.map(|(k, _)| k) == Some(kind))
                .map(|(t, _)| *t)
                .unwrap()
        };
        let want_stick = phi / omega;
        assert!((at(EventKind::Stick) - want_stick).abs() <= 1e-8 * period);
        assert!((at(EventKind::Slip) - want_stick - t_stick).abs() <= 1e-8 * period);
        assert!((cyc.z0[0] - (x_k - radius)).abs() <= 1e-8 * radius);
        // Amplitudes: x spans x_k ± R; ẋ spans −ωR … V (dense sampling: 1e-3).
        assert!((cyc.amplitude[0] - radius).abs() <= 1e-3 * radius);
        let av = 0.5 * (v + omega * radius);
        assert!((cyc.amplitude[1] - av).abs() <= 1e-3 * av);
    }
}

/// Period of the settled motion from a long event-driven simulation: the
/// mean spacing of the last stick events.
fn simulated_period(model: &Belt, z0: [f64; 2], t_end: f64, opts: SolverOptions) -> f64 {
    let mut log = EventLog::<2>::default();
    simulate(model, 0.0, z0, t_end, 1.0, opts, &mut log).unwrap();
    let sticks: Vec<f64> = log
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Stick)
        .map(|e| e.t)
        .collect();
    let n = sticks.len();
    assert!(n > 20, "{n} sticks");
    (sticks[n - 1] - sticks[n - 11]) / 10.0
}

#[test]
fn leine_rational_belt_matches_a_long_simulation() {
    // Leine, van Campen, de Kraker & van den Steen (1998): m = k = N = 1,
    // μ(v) = 1 / (1 + 3|v|), V = 0.2.
    let law = FrictionLaw::Rational {
        mu_s: 1.0,
        delta: 3.0,
    };
    let model = belt(1.0, 1.0, 1.0, 0.2, 0.0, law);
    let opts = tight(1e-13, 1e-13);
    let cyc = find_cycle(&model, 0.0, [0.0, 0.0], &opts).unwrap();
    let t_sim = simulated_period(&model, [0.0, 0.0], 400.0, opts.solver);
    assert!(
        (cyc.period - t_sim).abs() <= 1e-8 * t_sim,
        "shooting {} vs simulation {t_sim}",
        cyc.period
    );
    assert_one_zero(&cyc.multipliers, 1e-8);
    assert_eq!(cyc.events_per_period[EventKind::Stick.index()], 1);
}

/// Largest entry of `a − b` relative to the largest entry of `b`, both scaled.
fn scaled_difference<const N: usize>(a: &[[f64; N]; N], b: &[[f64; N]; N], s: &[f64; N]) -> f64 {
    let mut diff = 0.0f64;
    let mut size = 0.0f64;
    for i in 0..N {
        for j in 0..N {
            let k = s[j] / s[i];
            diff = diff.max(((a[i][j] - b[i][j]) * k).abs());
            size = size.max((b[i][j] * k).abs());
        }
    }
    diff / size
}

fn disc_pad_saltation_vs_finite_differences(n: f64) {
    let mut brake = DiscPad::default();
    brake.set("N", n).unwrap();
    let opts = CycleOptions::default();
    let cyc = find_cycle(&brake, 0.0, [0.0; 8], &opts).unwrap();
    assert!(cyc.residual <= 1e-8, "residual {}", cyc.residual);
    assert!(
        cyc.events_per_period[EventKind::Reverse.index()] >= 2,
        "a reversal cycle: {:?}",
        cyc.events_per_period
    );
    let fd_opts = SolverOptions {
        rtol: 1e-13,
        atol_pos: Some(1e-20),
        atol_vel: Some(1e-15),
        ..Default::default()
    };
    let fd = cycle::finite_difference_monodromy(&brake, &cyc, 1e-6, fd_opts).unwrap();
    let s = cycle::scales(&cyc, &opts.solver);
    let d = scaled_difference(&cyc.monodromy, &fd, &s);
    assert!(
        d <= 1e-5,
        "N = {n}: saltation vs finite differences {d:.3e}"
    );
    // Exactly one trivial multiplier, near 1; the slow normal modes
    // (σ ≈ −0.45 1/s) a hair inside the unit circle, not lost.
    let triv: Vec<_> = cyc.multipliers.iter().filter(|m| m.trivial).collect();
    assert_eq!(triv.len(), 1);
    assert!((triv[0].re - 1.0).abs() <= 1e-6, "{:?}", cyc.multipliers);
}

#[test]
fn disc_pad_monodromy_two_ways_default() {
    disc_pad_saltation_vs_finite_differences(500.0);
}

#[test]
fn disc_pad_monodromy_two_ways_n2000() {
    disc_pad_saltation_vs_finite_differences(2000.0);
}

/// The van der Pol oscillator `ẍ − ε(1 − x²)ẋ + x = 0`: a smooth limit cycle
/// with no events (one mode, no guards).
/// Van der Pol's oscillator `ẍ − ε(1 − x²)ẋ + x = 0` (smooth; tests/hb.rs uses it too).
pub struct VanDerPol(pub f64);

impl squeal_core::Model<2> for VanDerPol {
    fn name(&self) -> &'static str {
        "van-der-pol"
    }
    fn state_names(&self) -> [&'static str; 2] {
        ["x", "v"]
    }
    fn rhs(&self, _t: f64, _m: squeal_core::Mode, z: &[f64; 2], dz: &mut [f64; 2]) {
        dz[0] = z[1];
        dz[1] = self.0 * (1.0 - z[0] * z[0]) * z[1] - z[0];
    }
    fn guards(&self, _m: squeal_core::Mode, out: &mut squeal_core::model::Guards<2>) {
        out.clear();
    }
    fn transition(
        &self,
        _t: f64,
        mode: squeal_core::Mode,
        _g: squeal_core::model::GuardKind,
        _z: &mut [f64; 2],
    ) -> (squeal_core::Mode, Option<EventKind>) {
        (mode, None)
    }
    fn initial_mode(&self, _t: f64, _z: &[f64; 2]) -> squeal_core::Mode {
        squeal_core::Mode::SlipPos
    }
    fn observe(
        &self,
        _t: f64,
        _m: squeal_core::Mode,
        _z: &[f64; 2],
    ) -> squeal_core::model::Observables {
        Default::default()
    }
    fn jacobian(&self, z: &[f64; 2]) -> [[f64; 2]; 2] {
        [
            [0.0, 1.0],
            [
                -1.0 - 2.0 * self.0 * z[0] * z[1],
                self.0 * (1.0 - z[0] * z[0]),
            ],
        ]
    }
}

#[test]
fn smooth_van_der_pol_cycle_obeys_liouville() {
    // Liouville: det M = exp(∮ tr J dt), and one multiplier is the trivial 1,
    // so the other is exp(∮ ε(1 − x²) dt), integrated here independently by
    // Simpson's rule on a fine uniform sampling of the simulated orbit.
    for eps in [0.1, 1.0] {
        let model = VanDerPol(eps);
        let opts = tight(1e-12, 1e-12);
        let cyc = find_cycle(&model, 0.0, [0.5, 0.0], &opts).unwrap();
        assert_eq!(cyc.events_per_period.iter().sum::<u64>(), 0);
        let k = 20_000;
        let mut rec = squeal_core::sink::Recorder::<2>::new();
        simulate(
            &model,
            0.0,
            cyc.z0,
            cyc.period,
            k as f64 / cyc.period,
            opts.solver,
            &mut rec,
        )
        .unwrap();
        assert_eq!(rec.t.len(), k + 1);
        let h = cyc.period / k as f64;
        let integral: f64 = (0..=k)
            .map(|i| {
                let w = if i == 0 || i == k {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * eps * (1.0 - rec.z[i][0] * rec.z[i][0])
            })
            .sum::<f64>()
            * h
            / 3.0;
        let want = integral.exp();
        let triv: Vec<_> = cyc.multipliers.iter().filter(|m| m.trivial).collect();
        assert_eq!(triv.len(), 1);
        assert!((triv[0].re - 1.0).abs() <= 1e-8, "{:?}", cyc.multipliers);
        let other = cyc.multipliers.iter().find(|m| !m.trivial).unwrap();
        assert!(other.im == 0.0);
        assert!(
            (other.re - want).abs() <= 1e-6 * want,
            "ε = {eps}: {} vs exp(∮ tr J) = {want}",
            other.re
        );
        // The orbit returns to itself (the limit cycle of amplitude ≈ 2).
        assert!((rec.z[k][0] - cyc.z0[0]).abs() <= 1e-8);
        assert!((cyc.amplitude[0] - 2.0).abs() <= 0.02);
    }
}

/// The Floquet multipliers from the simulated return map alone (no
/// variational equations, saltation or projection) against the shooting's:
/// the disc–pad's reversal cycle, every one of the 7 non-trivial
/// multipliers within 1e-6 (central differences at 1e-6 of the state
/// scales: measured 5.6e-9; their O(h²) error at 1e-5 is 1.6e-6, so the
/// tolerance also rejects a return map taken too coarsely), and the period
/// against the mean return time of 2000 returns to 1e-9 (measured 4e-12).
#[test]
fn disc_pad_multipliers_from_the_return_map() {
    let brake = DiscPad::default();
    let cyc = find_cycle(&brake, 0.0, [0.0; 8], &CycleOptions::default()).unwrap();
    let so = SolverOptions {
        rtol: 1e-12,
        atol_pos: Some(1e-20),
        atol_vel: Some(1e-15),
        ..Default::default()
    };
    let r =
        cycle::section_returns(&brake, 0.0, cyc.z0, 2000.5 * cyc.period, cyc.section, so).unwrap();
    assert_eq!(r.len(), 2000);
    let t_mean = r[1999].0 / 2000.0;
    assert!(
        ((t_mean - cyc.period) / cyc.period).abs() <= 1e-9,
        "{t_mean} vs {}",
        cyc.period
    );
    for (_, z) in &r {
        assert_eq!(z[cyc.section.index], cyc.section.level);
    }
    let mu = cycle::return_map_multipliers(&brake, &cyc, 1e-6, so).unwrap();
    assert_eq!(mu.len(), 7);
    let shot: Vec<_> = cyc.multipliers.iter().filter(|m| !m.trivial).collect();
    assert_eq!(shot.len(), 7);
    for a in &shot {
        let d = mu
            .iter()
            .map(|b| (a.re - b.re).hypot(a.im - b.im))
            .fold(f64::INFINITY, f64::min);
        assert!(d <= 1e-6, "{a:?} is {d:.3e} from the return map's {mu:?}");
    }
}

/// The Coulomb belt's stick collapses the return map: its one non-trivial
/// multiplier is 0 exactly, which the simulated return map reproduces (its
/// differences vanish to round-off).
#[test]
fn coulomb_belt_return_map_is_zero() {
    let (m, k, n, v, mu_s, mu_k) = (1.0, 1.0e4, 100.0, 0.1, 0.4, 0.3);
    let model = belt(m, k, n, v, 0.0, FrictionLaw::Coulomb { mu_s, mu_k });
    let x_s = mu_s * n / k;
    let x_k = mu_k * n / k;
    let opts = tight(1e-9 * x_s, 1e-13 * v);
    let cyc = find_cycle(&model, 0.0, [2.0 * x_k - x_s, v], &opts).unwrap();
    let mu = cycle::return_map_multipliers(&model, &cyc, 1e-6, opts.solver).unwrap();
    assert_eq!(mu.len(), 1);
    assert!(mu[0].abs() <= 1e-6, "{mu:?}");
}

/// A mass on a belt with regularised friction (`tanh`, ε = 0.01 m/s) at
/// V = 1 m/s: its steady sliding is stable, its one mode decays at
/// `σ = −(c + N μ_k/ε · sech²(V/ε))/2m = −c/2m` (sech²(100) is 1e-86), and
/// a velocity kick of 0.05 m/s never reverses the sliding, so the motion is
/// a dying oscillation, not a limit cycle. Shooting converges on it all the
/// same: onto steady sliding itself when the decay per period is above
/// its tolerance (c = 2e-3: 6e-5 a period), or onto a small oscillation
/// that loses 6e-7 a period (c = 2e-5). `find_cycle` must say that there is
/// no cycle (with the decay rate where it has one) instead of reporting a
/// stable limit cycle (before: one of zero amplitude with a NaN multiplier,
/// and one whose multiplier along the flow was 0.9999994).
#[test]
fn a_slowly_dying_oscillation_is_no_limit_cycle() {
    let law = FrictionLaw::Tanh {
        mu_k: 0.3,
        eps: 0.01,
    };
    let x = 100.0 * 0.3 * (100.0f64).tanh() / 1e4;
    for (c, says) in [(2e-3, "zero amplitude"), (2e-5, "decays at σ = -1.0")] {
        let b = belt(1.0, 1e4, 100.0, 1.0, c, law);
        match find_cycle(&b, 0.0, [x, 0.05], &CycleOptions::default()) {
            Err(cycle::CycleError::Vanishing(m)) => assert!(m.contains(says), "c = {c}: {m}"),
            other => panic!("c = {c}: expected no cycle, got {other:?}"),
        }
    }
}
