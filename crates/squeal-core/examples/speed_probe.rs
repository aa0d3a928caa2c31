//! Fingerprints and a timing window for the integrator (BENCHMARKS.md, issue 16).
//!
//! `cargo run --release -p squeal-core --example speed_probe -- fingerprint`
//! prints, per scenario, the step counts, events and a hash of every sample
//! and event bit, so that a change meant to keep the method bit-for-bit can
//! be checked. `… -- window` runs only the default disc–pad's 0.3 s
//! event-free window from rest (the run measured under callgrind).

use squeal_core::integrate::ensemble::{simulate_ensemble, simulate_ensemble_lanes, Job};
use squeal_core::model::lumped::{disc_pad_spec, Fixed};
use squeal_core::model::{EventKind, Mode};
use squeal_core::sink::Discard;
use squeal_core::{
    simulate, Belt, DiscPad, Flow, FrictionLaw, Hoffmann, Lumped, Sink, SolverOptions, System,
};

/// FNV-1a over the bits of every sample and event.
struct Hash(u64, u64);

impl Hash {
    fn eat(&mut self, x: f64) {
        for b in x.to_bits().to_le_bytes() {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x100000001b3);
        }
        self.1 += 1;
    }
}

impl<const N: usize> Sink<N> for Hash {
    fn sample(&mut self, t: f64, z: &[f64; N], mode: Mode) -> Flow {
        self.eat(t);
        self.eat(mode.index() as f64);
        z.iter().for_each(|&x| self.eat(x));
        Flow::Continue
    }
    fn event(&mut self, t: f64, kind: EventKind, z: &[f64; N], mode: Mode) {
        self.eat(t);
        self.eat(kind.index() as f64 + 10.0 * mode.index() as f64);
        z.iter().for_each(|&x| self.eat(x));
    }
}

fn run<M: System<N>, const N: usize>(name: &str, m: &M, z0: [f64; N], t_end: f64, rate: f64) {
    let mut h = Hash(0xcbf29ce484222325, 0);
    let info = simulate(m, 0.0, z0, t_end, rate, SolverOptions::default(), &mut h).unwrap();
    let s = info.stats;
    println!(
        "{name}: accepted {} rejected {} rhs {} events {:?} hash {:016x} ({} numbers)",
        s.accepted, s.rejected, s.rhs_evals, s.events, h.0, h.1
    );
}

fn lanes(models: &[DiscPad], lane_field: bool) -> u64 {
    let mut jobs: Vec<Job<'_, DiscPad, Discard, 8>> = models
        .iter()
        .map(|m| Job {
            model: m,
            t0: 0.0,
            z0: [0.0; 8],
            t_end: 0.3,
            opts: SolverOptions::default(),
            sink: Discard,
        })
        .collect();
    let runs = if lane_field {
        simulate_ensemble_lanes::<DiscPad, Discard, 8>(&mut jobs, 200_000.0)
    } else {
        simulate_ensemble::<DiscPad, Discard, 8>(&mut jobs, 200_000.0)
    };
    runs.iter()
        .map(|r| r.as_ref().unwrap().stats.accepted)
        .sum()
}

/// Lawson RK4 (Hochbruck & Ostermann 2010, Acta Numerica, §2.4) with a
/// fixed step on the disc–pad in positive slip.
fn lawson(disc: &DiscPad, h: f64, t_end: f64) -> ([f64; 8], u64, u64, f64) {
    use nalgebra::{SMatrix, SVector};
    use squeal_core::Model;
    type V8 = SVector<f64, 8>;
    let zs = disc.equilibrium().unwrap();
    let jac = disc.jacobian(&zs);
    let j = SMatrix::<f64, 8, 8>::from_fn(|r, c| jac[r][c]);
    let e1 = (j * h).exp();
    let e2 = (j * (0.5 * h)).exp();
    let zsv = V8::from_column_slice(&zs);
    let mut evals = 0u64;
    let mut rest = |u: &V8| -> V8 {
        evals += 1;
        let z: [f64; 8] = (zsv + u).into();
        let mut dz = [0.0; 8];
        disc.rhs(0.0, Mode::SlipPos, &z, &mut dz);
        V8::from_column_slice(&dz) - j * u
    };
    let clock = std::time::Instant::now();
    let mut u = V8::from_column_slice(&[0.0; 8]) - zsv;
    let n = (t_end / h).round() as u64;
    for _ in 0..n {
        let g1 = rest(&u);
        let eu = e2 * u;
        let u2 = eu + e2 * g1 * (0.5 * h);
        let g2 = rest(&u2);
        let u3 = eu + g2 * (0.5 * h);
        let g3 = rest(&u3);
        let u4 = e1 * u + e2 * g3 * h;
        let g4 = rest(&u4);
        u = e1 * u + (e1 * g1 + e2 * (g2 + g3) * 2.0 + g4) * (h / 6.0);
    }
    let secs = clock.elapsed().as_secs_f64();
    ((zsv + u).into(), n, evals, secs)
}

fn main() {
    let what = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "fingerprint".into());
    let disc = DiscPad::default();
    if what == "window" {
        let reps: usize = std::env::args()
            .nth(2)
            .and_then(|s| s.parse().ok())
            .unwrap_or(1);
        for _ in 0..reps {
            let opts = SolverOptions::default();
            let info = simulate(&disc, 0.0, [0.0; 8], 0.3, 200_000.0, opts, &mut Discard).unwrap();
            println!("window: {:?}", info.stats);
        }
        return;
    }
    if what == "state" {
        // The end state of the 0.3 s window (for the peers' accuracy check).
        let rtol: f64 = std::env::args()
            .nth(2)
            .and_then(|s| s.parse().ok())
            .unwrap_or(1e-8);
        let opts = SolverOptions {
            rtol,
            ..SolverOptions::default()
        };
        let mut solver = squeal_core::Solver::new(&disc, 0.0, [0.0; 8], 0.3, opts).unwrap();
        while solver.step().unwrap().is_some() {}
        let z = solver.state();
        let s = solver.stats();
        println!("squeal: {} steps, {} rhs", s.accepted, s.rhs_evals);
        println!("end state: {}", z.map(|x| format!("{x:.12e}")).join(" "));
        return;
    }
    if what == "lawson" {
        // `lawson H`: a fixed-step Lawson (exponential) RK4 prototype on the
        // window: u = z − z*, u' = J·u + R(u) with J the Jacobian at steady
        // sliding, the linear part exact (e^{Jh}), the rest R by RK4.
        let h: f64 = std::env::args()
            .nth(2)
            .and_then(|s| s.parse().ok())
            .unwrap_or(1e-5);
        let (z, steps, evals, secs) = lawson(&disc, h, 0.3);
        println!("lawson4 h = {h:e}: {steps} steps, {evals} rhs, {secs:.3} s");
        println!("end state: {}", z.map(|x| format!("{x:.12e}")).join(" "));
        return;
    }
    if what == "lanes" {
        // `lanes L`: 16 disc–pads (V from 0.8 to 1.55 m/s), 0.3 s from rest at
        // 200 kHz, L at a time (L = 1: `simulate` one after the other; 4: the
        // ensemble with one field call per lane; 4f: with the lane-wise field).
        let arg = std::env::args().nth(2).unwrap_or_else(|| "1".into());
        let models: Vec<DiscPad> = (0..16)
            .map(|k| {
                let mut m = disc;
                m.p.V = 0.8 + 0.05 * k as f64;
                m
            })
            .collect();
        let t = std::time::Instant::now();
        let steps: u64 = match arg.as_str() {
            "1" => models
                .iter()
                .map(|m| {
                    let o = SolverOptions::default();
                    let i = simulate(m, 0.0, [0.0; 8], 0.3, 200_000.0, o, &mut Discard).unwrap();
                    i.stats.accepted
                })
                .sum(),
            "4" => lanes(&models, false),
            "4f" => lanes(&models, true),
            _ => panic!("L = 1, 4 or 4f"),
        };
        println!(
            "L = {arg}: {steps} steps in {:.3} s",
            t.elapsed().as_secs_f64()
        );
        return;
    }
    run("disc-pad 0.3 s window", &disc, [0.0; 8], 0.3, 200_000.0);
    run("disc-pad 1 s", &disc, [0.0; 8], 1.0, 20_000.0);
    let mut alpha = disc;
    alpha.p.alpha = 2.0;
    alpha.p.t_ramp = 0.01;
    run("disc-pad alpha ramp 0.5 s", &alpha, [0.0; 8], 0.5, 20_000.0);
    let mut strib = disc;
    strib.friction = FrictionLaw::by_name("stribeck").unwrap();
    run("disc-pad stribeck 0.5 s", &strib, [0.0; 8], 0.5, 20_000.0);
    let belt = Belt {
        friction: FrictionLaw::Coulomb {
            mu_s: 0.4,
            mu_k: 0.3,
        },
        ..Belt::default()
    };
    run("belt coulomb 10 s", &belt, [0.0; 2], 10.0, 1000.0);
    run(
        "belt default 10 s",
        &Belt::default(),
        [0.0; 2],
        10.0,
        1000.0,
    );
    let hoff = Hoffmann::default();
    let z0 = {
        let mut z = [0.0; 4];
        z[0] = 1e-6;
        z
    };
    run("hoffmann 0.5 s", &hoff, z0, 0.5, 10_000.0);
    let lumped = Lumped::build(&disc_pad_spec(&disc)).unwrap();
    run(
        "lumped disc-pad 0.5 s",
        &Fixed::<8>(&lumped),
        [0.0; 8],
        0.5,
        20_000.0,
    );
}
