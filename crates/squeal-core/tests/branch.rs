//! Continuation of limit cycles (pseudo-arclength through folds) against
//! exact results and independent computations: a belt whose branch folds
//! (fold multiplier 1, both cycles at one speed, each a true periodic orbit,
//! the stable ones against settled simulations), the branch meeting steady
//! sliding at the analytic Hopf speed, and period doubling and
//! Neimark–Sacker bifurcations on cycles with known multipliers.

use squeal_core::cycle::continuation::{
    branch, BifurcationKind, Branch, BranchOptions, PointKind, SegmentEnd,
};
use squeal_core::cycle::{find_cycle, Cycle, CycleOptions};
use squeal_core::model::{GuardKind, Guards, Observables};
use squeal_core::sink::Recorder;
use squeal_core::{
    simulate, Belt, EventKind, FrictionLaw, Mode, Model, Parameters, SolverOptions, System,
};

/// `μ(v) = 0.5 + 0.5 exp(−v²)`: velocity weakening on a bump, smooth in slip.
const GAUSS: FrictionLaw = FrictionLaw::Stribeck {
    mu_s: 1.0,
    mu_k: 0.5,
    v_s: 1.0,
    delta: 2.0,
    sigma: 0.0,
};

fn belt(c: f64, v: f64) -> Belt {
    let mut b = Belt {
        friction: GAUSS,
        ..Belt::default()
    };
    for (key, val) in [("m", 1.0), ("k", 1.0), ("c", c), ("N", 1.0), ("V", v)] {
        b.set(key, val).unwrap();
    }
    b.validate().unwrap();
    b
}

fn tight() -> CycleOptions {
    CycleOptions {
        solver: SolverOptions {
            rtol: 1e-11,
            atol_pos: Some(1e-12),
            atol_vel: Some(1e-12),
            ..Default::default()
        },
        newton_tol: 1e-10,
        ..CycleOptions::default()
    }
}

fn belt_branch(c: f64, grid: &[f64], opts: &BranchOptions) -> Branch<2> {
    let fam = move |p: f64, f: &mut dyn FnMut(&dyn System<2>)| -> Result<(), String> {
        f(&belt(c, p));
        Ok(())
    };
    let copts = opts.cycle;
    let mut settle = move |p: f64| find_cycle(&belt(c, p), 0.0, [0.0, 0.0], &copts);
    branch(&fam, grid, &mut settle, opts)
}

fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The Hopf speed of steady sliding, `c = −N μ'(V)` with
/// `μ'(v) = −v e^{−v²}` here, on the falling side of the bump (v > 1/√2).
fn hopf_speed(c: f64) -> f64 {
    let (mut a, mut b) = (std::f64::consts::FRAC_1_SQRT_2, 5.0);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m * (-m * m).exp() > c {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Simulate one period from the cycle's start: the orbit must close.
fn closes<M: Model<2>>(model: &M, cyc: &Cycle<2>, opts: SolverOptions) -> f64 {
    let mut rec = Recorder::<2>::new();
    simulate(
        model,
        0.0,
        cyc.z0,
        cyc.period,
        1.0 / cyc.period,
        opts,
        &mut rec,
    )
    .unwrap();
    let end = rec.z.last().unwrap();
    (0..2)
        .map(|i| (end[i] - cyc.z0[i]).abs() / cyc.amplitude[i])
        .fold(0.0, f64::max)
}

/// Period and velocity amplitude of the motion settled from rest (long
/// event-driven simulation; period from upward zeros of ẋ, refined linearly).
fn settled(model: &Belt, opts: SolverOptions) -> (f64, f64) {
    let mut rec = Recorder::<2>::new();
    let (t_end, rate) = (3000.0, 200.0);
    simulate(model, 0.0, [0.0, 0.0], t_end, rate, opts, &mut rec).unwrap();
    let n = rec.t.len();
    let tail = n - (200.0 * rate) as usize;
    let mut ups = Vec::new();
    for k in tail..n - 1 {
        let (a, b) = (rec.z[k][1], rec.z[k + 1][1]);
        if a < 0.0 && b >= 0.0 {
            ups.push(rec.t[k] + (rec.t[k + 1] - rec.t[k]) * a / (a - b));
        }
    }
    let m = ups.len() - 1;
    let period = (ups[m] - ups[0]) / m as f64;
    let (lo, hi) = rec.z[tail..]
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), z| (l.min(z[1]), h.max(z[1])));
    (period, 0.5 * (hi - lo))
}

#[test]
fn gaussian_belt_branch_folds() {
    // c = 0.2: stick-slip at V = 1.2, a stable slip cycle from the grazing
    // on, a fold near V = 1.4575 where it meets the unstable cycle of the
    // subcritical Hopf point (μ''' < 0 there), which shrinks onto steady
    // sliding at the Hopf speed.
    let c = 0.2;
    let opts = BranchOptions {
        cycle: tight(),
        ..BranchOptions::default()
    };
    let b = belt_branch(c, &grid(1.2, 2.0, 5), &opts);
    let folds: Vec<_> = b
        .bifurcations
        .iter()
        .filter(|x| x.kind == BifurcationKind::Fold)
        .collect();
    assert_eq!(folds.len(), 1, "{:#?}", b.bifurcations);
    let fold_p = folds[0].value.unwrap();
    assert!((1.45..1.47).contains(&fold_p), "{fold_p}");
    // At the fold a non-trivial multiplier is 1.
    let fold = b.points.iter().find(|p| p.kind == PointKind::Fold).unwrap();
    assert!(
        (fold.cycle.max_multiplier - 1.0).abs() <= 1e-4,
        "{}",
        fold.cycle.max_multiplier
    );
    assert!(fold.slope.abs() <= 1e-2);
    // The grazing: stick-slip at V = 1.2, pure slip at 1.4.
    assert!(b
        .bifurcations
        .iter()
        .any(|x| x.kind == BifurcationKind::GrazingSliding && x.between.0 < 1.4));
    // V = 1.4 holds two cycles: the stable one and the unstable one.
    let at14: Vec<_> = b
        .points
        .iter()
        .filter(|p| p.kind == PointKind::Grid(1))
        .collect();
    assert_eq!(at14.len(), 2);
    assert!(at14[0].cycle.stable && !at14[1].cycle.stable);
    assert!(at14[1].cycle.amplitude[1] < at14[0].cycle.amplitude[1]);
    // Every point is a periodic orbit of the event-driven flow.
    for p in &b.points {
        let gap = closes(&belt(c, p.value), &p.cycle, opts.cycle.solver);
        assert!(
            gap <= 1e-7,
            "V = {}: the orbit misses itself by {gap:e}",
            p.value
        );
    }
    // The stable grid points against settled simulations (period 1e-6,
    // amplitude 1 %).
    for p in b.points.iter().filter(|p| p.cycle.stable) {
        if !matches!(p.kind, PointKind::Grid(_)) {
            continue;
        }
        let (t_sim, a_sim) = settled(&belt(c, p.value), opts.cycle.solver);
        assert!(
            (p.cycle.period - t_sim).abs() <= 1e-6 * t_sim,
            "V = {}: period {} vs settled {t_sim}",
            p.value,
            p.cycle.period
        );
        assert!(
            (p.cycle.amplitude[1] - a_sim).abs() <= 1e-2 * a_sim,
            "V = {}: amplitude {} vs settled {a_sim}",
            p.value,
            p.cycle.amplitude[1]
        );
    }
    // The unstable branch ends on steady sliding at the Hopf speed.
    let v_h = hopf_speed(c);
    match &b.ends[0] {
        SegmentEnd::SteadySliding { value, freq_hz } => {
            assert!((value - v_h).abs() <= 1e-4 * v_h, "{value} vs {v_h}");
            let f = 0.5 / std::f64::consts::PI;
            assert!((freq_hz - f).abs() <= 1e-5 * f, "{freq_hz}");
        }
        other => panic!("{other:?}"),
    }
    // No cycle at V = 1.6 … 2.0 (steady sliding is stable, nothing else).
    assert_eq!(b.failures.len(), 3, "{:?}", b.failures);
}

#[test]
fn supercritical_hopf_branch_meets_steady_sliding() {
    // c = 0.35: Hopf at V_H ≈ 1.0466 with μ''' > 0 (supercritical): a small
    // smooth cycle for V < V_H whose amplitude vanishes at V_H.
    let c = 0.35;
    let opts = BranchOptions {
        cycle: tight(),
        ..BranchOptions::default()
    };
    let b = belt_branch(c, &grid(0.95, 1.05, 3), &opts);
    // Beyond V_H (1.05) steady sliding is stable: no cycle.
    assert_eq!(b.failures.len(), 1, "{:?}", b.failures);
    assert_eq!(b.failures[0].0, 1.05);
    assert!(b.bifurcations.is_empty(), "{:?}", b.bifurcations);
    let v_h = hopf_speed(c);
    match &b.ends[0] {
        SegmentEnd::SteadySliding { value, freq_hz } => {
            assert!((value - v_h).abs() <= 1e-4 * v_h, "{value} vs {v_h}");
            let f = 0.5 / std::f64::consts::PI;
            assert!((freq_hz - f).abs() <= 1e-5 * f, "{freq_hz}");
        }
        other => panic!("{other:?}"),
    }
    for p in &b.points {
        assert!(p.cycle.stable);
        assert_eq!(p.cycle.events_per_period.iter().sum::<u64>(), 0);
    }
}

/// A stable circle `r = 1` of `(a, b)` (`ṙ = r(1 − r²)`, `θ̇ = 1`) with a
/// transverse plane `(u, w)`: `NS` rotates it at `ω₂` with growth `p`
/// (multipliers `e^{2π(p ± iω₂)}`); otherwise it turns half a turn per period
/// with rates `p` and `−1` along its rotating axes (a Möbius band:
/// multipliers `−e^{2πp}`, `−e^{−2π}`). The radial multiplier is `e^{−4π}`.
#[derive(Clone, Copy)]
struct Torus {
    p: f64,
    ns: bool,
}

const OMEGA2: f64 = 0.3;

impl Model<4> for Torus {
    fn name(&self) -> &'static str {
        "torus"
    }
    fn state_names(&self) -> [&'static str; 4] {
        ["u", "w", "a", "b"]
    }
    fn rhs(&self, _t: f64, _m: Mode, z: &[f64; 4], dz: &mut [f64; 4]) {
        let (u, w, a, b) = (z[0], z[1], z[2], z[3]);
        let r2 = a * a + b * b;
        dz[2] = a - b - a * r2;
        dz[3] = b + a - b * r2;
        if self.ns {
            dz[0] = self.p * u - OMEGA2 * w;
            dz[1] = OMEGA2 * u + self.p * w;
        } else {
            let r = r2.sqrt();
            let (co, si) = (a / r, b / r);
            let (h, k) = (0.5 * (self.p - 1.0), 0.5 * (self.p + 1.0));
            dz[0] = (h + k * co) * u + k * si * w - 0.5 * w;
            dz[1] = k * si * u + (h - k * co) * w + 0.5 * u;
        }
    }
    fn guards(&self, _m: Mode, out: &mut Guards<4>) {
        out.clear();
    }
    fn transition(
        &self,
        _t: f64,
        mode: Mode,
        _g: GuardKind,
        _z: &mut [f64; 4],
    ) -> (Mode, Option<EventKind>) {
        (mode, None)
    }
    fn initial_mode(&self, _t: f64, _z: &[f64; 4]) -> Mode {
        Mode::SlipPos
    }
    fn observe(&self, _t: f64, _m: Mode, _z: &[f64; 4]) -> Observables {
        Default::default()
    }
    fn jacobian(&self, _z: &[f64; 4]) -> [[f64; 4]; 4] {
        [[0.0; 4]; 4]
    }
}

fn torus_branch(ns: bool) -> Branch<4> {
    let fam = move |p: f64, f: &mut dyn FnMut(&dyn System<4>)| -> Result<(), String> {
        f(&Torus { p, ns });
        Ok(())
    };
    let opts = BranchOptions {
        cycle: tight(),
        ..BranchOptions::default()
    };
    let copts = opts.cycle;
    let mut settle = move |p: f64| find_cycle(&Torus { p, ns }, 0.0, [0.01, 0.0, 0.5, 0.0], &copts);
    branch(&fam, &grid(-0.1, 0.1, 4), &mut settle, &opts)
}

/// The multipliers of every point equal the exact ones (1e-6).
fn check_multipliers(b: &Branch<4>, exact: impl Fn(f64) -> Vec<(f64, f64)>) {
    for p in &b.points {
        assert!((p.cycle.period - 2.0 * std::f64::consts::PI).abs() <= 1e-8);
        let non: Vec<_> = p.cycle.multipliers.iter().filter(|m| !m.trivial).collect();
        let triv: Vec<_> = p.cycle.multipliers.iter().filter(|m| m.trivial).collect();
        assert_eq!(triv.len(), 1);
        assert!((triv[0].re - 1.0).abs() <= 1e-8);
        for (re, im) in exact(p.value) {
            assert!(
                non.iter()
                    .any(|m| (m.re - re).abs() <= 1e-6 && (m.im - im).abs() <= 1e-6),
                "p = {}: {re} {im}i not in {:?}",
                p.value,
                p.cycle.multipliers
            );
        }
    }
}

#[test]
fn neimark_sacker_of_a_complex_pair() {
    let b = torus_branch(true);
    assert!(b.failures.is_empty(), "{:?}", b.failures);
    let tau = 2.0 * std::f64::consts::PI;
    check_multipliers(&b, |p| {
        let (m, a) = ((tau * p).exp(), tau * OMEGA2);
        vec![
            (m * a.cos(), m * a.sin()),
            (m * a.cos(), -m * a.sin()),
            ((-2.0 * tau).exp(), 0.0),
        ]
    });
    let ns: Vec<_> = b
        .bifurcations
        .iter()
        .filter(|x| x.kind == BifurcationKind::NeimarkSacker)
        .collect();
    assert_eq!(b.bifurcations.len(), 1, "{:?}", b.bifurcations);
    assert_eq!(ns.len(), 1);
    assert!(ns[0].between.0 < 0.0 && ns[0].between.1 > 0.0);
}

#[test]
fn period_doubling_of_a_moebius_band() {
    let b = torus_branch(false);
    assert!(b.failures.is_empty(), "{:?}", b.failures);
    let tau = 2.0 * std::f64::consts::PI;
    check_multipliers(&b, |p| {
        vec![
            (-(tau * p).exp(), 0.0),
            (-(-tau).exp(), 0.0),
            ((-2.0 * tau).exp(), 0.0),
        ]
    });
    let pd: Vec<_> = b
        .bifurcations
        .iter()
        .filter(|x| x.kind == BifurcationKind::PeriodDoubling)
        .collect();
    assert_eq!(b.bifurcations.len(), 1, "{:?}", b.bifurcations);
    assert_eq!(pd.len(), 1);
    assert!(pd[0].between.0 < 0.0 && pd[0].between.1 > 0.0);
}

/// Period (mean spacing of upward zeros of `vx_p`) and half peak-to-peak of
/// `vx_p`, simulated from rest: settled for `t_settle`, then recorded densely.
fn disc_pad_settled(
    model: &squeal_core::DiscPad,
    t_settle: f64,
    opts: SolverOptions,
) -> (f64, f64) {
    let mut sol = squeal_core::Solver::new(model, 0.0, [0.0; 8], t_settle, opts).unwrap();
    while sol.step().unwrap().is_some() {}
    let (t0, z0) = (sol.t(), *sol.state());
    let mut rec = Recorder::<8>::new();
    simulate(model, t0, z0, t0 + 0.005, 4e6, opts, &mut rec).unwrap();
    let mut ups = Vec::new();
    for k in 0..rec.t.len() - 1 {
        let (a, b) = (rec.z[k][5], rec.z[k + 1][5]);
        if a < 0.0 && b >= 0.0 {
            ups.push(rec.t[k] + (rec.t[k + 1] - rec.t[k]) * a / (a - b));
        }
    }
    let m = ups.len() - 1;
    let (lo, hi) = rec
        .z
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), z| (l.min(z[5]), h.max(z[5])));
    ((ups[m] - ups[0]) / m as f64, 0.5 * (hi - lo))
}

#[test]
fn disc_pad_branch_matches_settled_simulations() {
    // The default brake's reversal cycle over V = 0.5 … 0.6, where the pad's
    // velocity amplitude is just above V (the reversals are brief): every
    // grid point against a simulation from rest settled as long as `cycle`
    // needed there (+ 50 %), period to 1e-6 and amplitude to 1 %.
    let base = squeal_core::DiscPad::default();
    let opts = BranchOptions::default();
    let fam = squeal_core::cycle::continuation::Varied {
        model: &base,
        name: "V",
    };
    let copts = opts.cycle;
    let mut settle = |v: f64| {
        let mut m = base;
        m.set("V", v).unwrap();
        find_cycle(&m, 0.0, [0.0; 8], &copts)
    };
    let values = grid(0.5, 0.6, 3);
    let b = branch(&fam, &values, &mut settle, &opts);
    assert!(b.failures.is_empty(), "{:?}", b.failures);
    assert!(b.bifurcations.is_empty(), "{:?}", b.bifurcations);
    let grid_points: Vec<_> = b
        .points
        .iter()
        .filter(|p| matches!(p.kind, PointKind::Grid(_)))
        .collect();
    assert_eq!(grid_points.len(), 3);
    let t_settle = 1.5 * b.points[0].cycle.settle_time;
    for p in grid_points {
        let mut m = base;
        m.set("V", p.value).unwrap();
        let (t_sim, a_sim) = disc_pad_settled(&m, t_settle, copts.solver);
        assert!(
            (p.cycle.period - t_sim).abs() <= 1e-6 * t_sim,
            "V = {}: period {} vs settled {t_sim}",
            p.value,
            p.cycle.period
        );
        assert!(
            (p.cycle.amplitude[5] - a_sim).abs() <= 1e-2 * a_sim,
            "V = {}: amplitude {} vs settled {a_sim}",
            p.value,
            p.cycle.amplitude[5]
        );
        assert_eq!(p.cycle.events_per_period[EventKind::Reverse.index()], 2);
    }
}

#[test]
fn disc_pad_branch_reports_minimal_periods() {
    // Issue 29: `branch disc-pad --param V=1:13:4` reported, at V = 5, 9
    // and 13, four turns of the orbit (period 1.9276e-4 s, 8 reversals,
    // the fourth power of the true multiplier). Every grid point's period
    // must be the minimal one: the mean spacing of the pad velocity's
    // upward zeros in a simulation settled as long as `cycle` needed
    // (+ 50 %), to 1e-6, with two reversals per period.
    let base = squeal_core::DiscPad::default();
    let opts = BranchOptions::default();
    let fam = squeal_core::cycle::continuation::Varied {
        model: &base,
        name: "V",
    };
    let copts = opts.cycle;
    let mut settle = |v: f64| {
        let mut m = base;
        m.set("V", v).unwrap();
        find_cycle(&m, 0.0, [0.0; 8], &copts)
    };
    let values = grid(1.0, 13.0, 4);
    let b = branch(&fam, &values, &mut settle, &opts);
    assert!(b.failures.is_empty(), "{:?}", b.failures);
    let grid_points: Vec<_> = b
        .points
        .iter()
        .filter(|p| matches!(p.kind, PointKind::Grid(_)))
        .collect();
    assert_eq!(grid_points.len(), 4);
    for p in grid_points {
        let mut m = base;
        m.set("V", p.value).unwrap();
        let t_settle = 1.5 * p.cycle.settle_time.max(b.points[0].cycle.settle_time);
        let (t_sim, _) = disc_pad_settled(&m, t_settle, copts.solver);
        assert!(
            (p.cycle.period - t_sim).abs() <= 1e-6 * t_sim,
            "V = {}: period {} vs settled {t_sim}",
            p.value,
            p.cycle.period
        );
        assert_eq!(
            p.cycle.events_per_period[EventKind::Reverse.index()],
            2,
            "V = {}",
            p.value
        );
    }
}

#[test]
fn shooting_over_several_turns_returns_the_minimal_period() {
    // Newton shooting started from k turns of a cycle converges on that
    // k-turn orbit; it must report the orbit once, with multipliers
    // computed over one turn (not the k-th power).
    let mut m = squeal_core::DiscPad::default();
    m.set("V", 5.0).unwrap();
    let opts = CycleOptions::default();
    let c = find_cycle(&m, 0.0, [0.0; 8], &opts).unwrap();
    assert_eq!(c.events_per_period[EventKind::Reverse.index()], 2);
    for k in [2.0, 3.0, 4.0] {
        let again = squeal_core::cycle::shoot(&m, c.z0, k * c.period, c.section, &opts).unwrap();
        assert!(
            (again.period - c.period).abs() <= 1e-9 * c.period,
            "{k} turns: period {} vs {}",
            again.period,
            c.period
        );
        assert!(
            (again.max_multiplier - c.max_multiplier).abs() <= 1e-7,
            "{k} turns: multiplier {} vs {}",
            again.max_multiplier,
            c.max_multiplier
        );
        assert_eq!(again.events_per_period, c.events_per_period);
    }
}
