//! Breakaway from stick where the friction law is continuous (μ(0⁺) = μ_s):
//! the relative acceleration at the instant of breaking is zero, and only
//! round-off decides its sign. A mass on a belt is the sharp case: its
//! slip-zero guard is a single state (the belt's speed is prescribed), so
//! round-off carries no scale. Before the fix such a run re-stuck at once,
//! broke again at once, and ended in an "endless stick-slip chatter" error
//! at its first stick (23.12 s here); `squeal branch belt` starting at
//! V = 0.2 failed the same way.

use squeal_core::integrate::{Flow, Sink};
use squeal_core::model::belt::Belt;
use squeal_core::{simulate, EventKind, Mode, Model, SolverOptions};

/// Every event: time, kind, state.
struct Events(Vec<(f64, EventKind, [f64; 2])>);

impl Sink<2> for Events {
    fn sample(&mut self, _t: f64, _z: &[f64; 2], _m: Mode) -> Flow {
        Flow::Continue
    }
    fn event(&mut self, t: f64, kind: EventKind, z: &[f64; 2], _mode: Mode) {
        self.0.push((t, kind, *z));
    }
}

/// The `belt` scenario at V = 0.2 m/s (c = 0.2 kg/s: negative damping
/// from the Stribeck slope grows a kick of 1 mm/s into stick-slip) runs for
/// 30 s, and its stick-slip is exact where it can be checked exactly:
/// every stick ends where the spring and damper reach the static bound,
/// `x_b = (μ_s·N − c·V)/k`, and lasts `(x_b − x_stick)/V` (the mass moves
/// with the belt); the cycle repeats at the natural period `2π·√(m/k)`
/// to within the friction's small influence.
#[test]
fn belt_breakaway_with_continuous_friction_does_not_chatter() {
    let mut b = Belt::default();
    b.p.V = 0.2;
    b.p.c = 0.2;
    let mut z0 = b.equilibrium().unwrap();
    z0[1] += 1e-3;
    let opts = SolverOptions {
        atol_pos: Some(1e-12),
        atol_vel: Some(1e-10),
        ..SolverOptions::default()
    };
    let mut ev = Events(Vec::new());
    let info = simulate(&b, 0.0, z0, 30.0, 1000.0, opts, &mut ev).expect("no chatter");
    let sticks: Vec<_> = ev.0.iter().filter(|e| e.1 == EventKind::Stick).collect();
    let slips: Vec<_> = ev.0.iter().filter(|e| e.1 == EventKind::Slip).collect();
    assert!(sticks.len() >= 100, "{} sticks", sticks.len());
    assert!(
        sticks[0].0 > 23.0 && sticks[0].0 < 23.2,
        "first stick at {}",
        sticks[0].0
    );
    assert_eq!(info.stats.event_count(EventKind::Reverse), 0);
    let mu_s_n = b.friction.mu_static() * b.p.N;
    let x_b = (mu_s_n - b.p.c * b.p.V) / b.p.k;
    // Events alternate stick, slip after the first stick.
    for (k, w) in ev.0.windows(2).enumerate() {
        assert_ne!(
            w[0].1,
            w[1].1,
            "events {k} and {}: {:?} twice",
            k + 1,
            w[0].1
        );
    }
    for (s, b_) in sticks.iter().zip(&slips) {
        assert!(b_.0 > s.0);
        // Breaks at the bound, to round-off of x.
        assert!(
            (b_.2[0] - x_b).abs() <= 1e-12 * x_b,
            "break at x = {:e}, bound {x_b:e}",
            b_.2[0]
        );
        // Stick: the mass rides the belt.
        assert_eq!(s.2[1], b.p.V);
        let dt = (x_b - s.2[0]) / b.p.V;
        assert!(
            (b_.0 - s.0 - dt).abs() <= 1e-9,
            "stick of {} s, kinematics {dt} s",
            b_.0 - s.0
        );
    }
    // Once settled, one stick per natural period 2π/100 s, to 1 %.
    let n = sticks.len();
    let period = (sticks[n - 1].0 - sticks[n - 11].0) / 10.0;
    let natural = 2.0 * std::f64::consts::PI * (b.p.m / b.p.k).sqrt();
    assert!(
        (period / natural - 1.0).abs() < 0.01,
        "period {period} s, natural {natural} s"
    );
}
