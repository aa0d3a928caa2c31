//! The L-lane ensemble (issue 16, point 2) against one-at-a-time runs: the
//! same events, the same outcome and the same samples, bit for bit, also for
//! lanes that stop early or fail while the others go on.

use squeal_core::integrate::ensemble::{
    simulate_ensemble, simulate_ensemble_lanes, Job, LaneField, Lanes, LANES,
};
use squeal_core::model::Mode;
use squeal_core::model::Modes;
use squeal_core::sink::Recorder;
use squeal_core::{
    simulate, Belt, DiscPad, EventKind, Flow, FrictionLaw, IntegrateError, RunInfo, Sink,
    SolverOptions, System,
};

/// A recorder that stops the run after `limit` samples.
#[derive(Debug, Clone, Default)]
struct Upto<const N: usize> {
    rec: Recorder<N>,
    limit: usize,
}

impl<const N: usize> Sink<N> for Upto<N> {
    fn sample(&mut self, t: f64, z: &[f64; N], mode: Mode) -> Flow {
        self.rec.sample(t, z, mode);
        if self.rec.t.len() >= self.limit {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }
    fn event(&mut self, t: f64, kind: EventKind, z: &[f64; N], mode: Mode) {
        self.rec.event(t, kind, z, mode)
    }
}

/// A job's description: start, end, options and sample limit.
struct Case<const N: usize> {
    z0: [f64; N],
    t_end: f64,
    opts: SolverOptions,
    limit: usize,
}

/// An ensemble runner: [`simulate_ensemble`] or [`simulate_ensemble_lanes`].
type Ensemble<M, const N: usize> =
    fn(&mut [Job<'_, M, Upto<N>, N>], f64) -> Vec<Result<RunInfo, IntegrateError>>;

/// Run `cases` on `models` one at a time and as an ensemble of `L` lanes;
/// assert identical results. Returns the one-at-a-time results.
fn same_as_single<M: System<N>, const N: usize>(
    models: &[M],
    cases: &[Case<N>],
    rate: f64,
    ensemble: Ensemble<M, N>,
) -> Vec<Result<(RunInfo, Upto<N>), IntegrateError>> {
    let single: Vec<_> = models
        .iter()
        .zip(cases)
        .map(|(m, c)| {
            let mut sink = Upto {
                rec: Recorder::new(),
                limit: c.limit,
            };
            simulate(m, 0.0, c.z0, c.t_end, rate, c.opts, &mut sink).map(|info| (info, sink))
        })
        .collect();
    let mut jobs: Vec<Job<'_, M, Upto<N>, N>> = models
        .iter()
        .zip(cases)
        .map(|(m, c)| Job {
            model: m,
            t0: 0.0,
            z0: c.z0,
            t_end: c.t_end,
            opts: c.opts,
            sink: Upto {
                rec: Recorder::new(),
                limit: c.limit,
            },
        })
        .collect();
    let together = ensemble(&mut jobs, rate);
    assert_eq!(together.len(), single.len());
    for (k, ((one, many), job)) in single.iter().zip(&together).zip(&jobs).enumerate() {
        match (one, many) {
            (Ok((info, sink)), Ok(info_e)) => {
                assert_eq!(info, info_e, "job {k}: run summaries differ");
                let (a, b) = (&sink.rec, &job.sink.rec);
                assert_eq!(a.t.len(), b.t.len(), "job {k}: sample counts");
                for (s, (za, zb)) in a.z.iter().zip(&b.z).enumerate() {
                    for i in 0..N {
                        assert_eq!(
                            za[i].to_bits(),
                            zb[i].to_bits(),
                            "job {k} sample {s} state {i}"
                        );
                    }
                }
                for (ta, tb) in a.t.iter().zip(&b.t) {
                    assert_eq!(ta.to_bits(), tb.to_bits(), "job {k}: sample times");
                }
                assert_eq!(a.mode, b.mode, "job {k}: modes");
                assert_eq!(a.events.len(), b.events.len(), "job {k}: event counts");
                for (ea, eb) in a.events.iter().zip(&b.events) {
                    assert_eq!(ea.t.to_bits(), eb.t.to_bits(), "job {k}: event times");
                    assert_eq!((ea.kind, ea.mode), (eb.kind, eb.mode), "job {k}");
                    assert_eq!(ea.z.map(f64::to_bits), eb.z.map(f64::to_bits), "job {k}");
                }
            }
            (Err(a), Err(b)) => assert_eq!(a, b, "job {k}: errors differ"),
            _ => panic!("job {k}: one run failed and the other did not: {one:?} vs {many:?}"),
        }
    }
    single
}

/// Disc–pad runs of every kind: growth from rest, stick-slip with reversals
/// and sticks from a kicked start, a Stribeck law, a ramped follower force,
/// a run stopped by its sink, a run out of steps, a run refused at start.
#[test]
fn disc_pad_lanes_match_single_runs() {
    let base = DiscPad::default();
    let mut models = Vec::new();
    let mut cases = Vec::new();
    let opts = SolverOptions::default();
    let eq = squeal_core::Model::equilibrium(&base).unwrap();
    let kicked = |vx_p: f64| {
        let mut z = eq;
        z[5] = vx_p;
        z
    };
    let mut push = |m: DiscPad, z0: [f64; 8], t_end: f64, opts: SolverOptions, limit: usize| {
        models.push(m);
        cases.push(Case {
            z0,
            t_end,
            opts,
            limit,
        });
    };
    push(base, [0.0; 8], 0.01, opts, usize::MAX);
    push(base, kicked(1.5), 0.01, opts, usize::MAX);
    let mut strib = base;
    strib.friction = FrictionLaw::by_name("stribeck").unwrap();
    push(strib, kicked(2.0), 0.008, opts, usize::MAX);
    let mut fast = base;
    fast.p.V = 3.0;
    fast.p.N = 2000.0;
    push(fast, kicked(-1.0), 0.012, opts, usize::MAX);
    // Stopped by its sink after 37 samples while the others go on.
    push(base, kicked(1.2), 0.01, opts, 37);
    // Out of steps: fails while the others go on.
    let short = SolverOptions {
        max_steps: 300,
        ..opts
    };
    push(base, kicked(1.5), 0.01, short, usize::MAX);
    // Refused at the start (end before start).
    let mut ramp = base;
    ramp.p.alpha = 2.0;
    ramp.p.t_ramp = 0.002;
    push(ramp, [0.0; 8], -1.0, opts, usize::MAX);
    push(ramp, [0.0; 8], 0.006, opts, usize::MAX);
    let mut soft = base;
    soft.p.k_py = 4.0e8;
    push(soft, kicked(1.8), 0.015, opts, usize::MAX);

    let single = same_as_single::<DiscPad, 8>(&models, &cases, 50_000.0, simulate_ensemble);
    // The same with the lane-wise right-hand side (the Stribeck lane makes
    // its lane set fall back to `field`; without it, lanes in slip, stick
    // and free flight are computed lane-wise together).
    same_as_single::<DiscPad, 8>(&models, &cases, 50_000.0, simulate_ensemble_lanes);
    let thesis: Vec<usize> = (0..models.len()).filter(|&k| k != 2).collect();
    same_as_single::<DiscPad, 8>(
        &thesis.iter().map(|&k| models[k]).collect::<Vec<_>>(),
        &thesis
            .iter()
            .map(|&k| Case { ..cases[k] })
            .collect::<Vec<_>>(),
        50_000.0,
        simulate_ensemble_lanes,
    );
    // The cases are what they claim to be.
    let ok: Vec<_> = single.iter().filter_map(|r| r.as_ref().ok()).collect();
    assert!(
        ok.iter().any(|(i, _)| i.stopped_early),
        "a lane stops early"
    );
    assert!(matches!(single[5], Err(IntegrateError::MaxSteps { .. })));
    assert!(matches!(single[6], Err(IntegrateError::BadOptions(_))));
    let reversals: u64 = ok
        .iter()
        .map(|(i, _)| i.stats.event_count(EventKind::Reverse))
        .sum();
    let sticks: u64 = ok
        .iter()
        .map(|(i, _)| i.stats.event_count(EventKind::Stick))
        .sum();
    assert!(
        reversals > 10 && sticks > 0,
        "{reversals} reversals, {sticks} sticks"
    );
    // Fewer jobs than lanes.
    same_as_single::<DiscPad, 8>(&models[..2], &cases[..2], 50_000.0, simulate_ensemble);
    same_as_single::<DiscPad, 8>(&models[..2], &cases[..2], 50_000.0, simulate_ensemble_lanes);
}

/// The mass on a belt with Coulomb stick-slip (exact sticks and slips),
/// more jobs than lanes so that lanes are refilled.
#[test]
fn belt_lanes_match_single_runs() {
    let mut models = Vec::new();
    let mut cases = Vec::new();
    for k in 0..11 {
        let mut b = Belt {
            friction: FrictionLaw::Coulomb {
                mu_s: 0.4,
                mu_k: 0.3,
            },
            ..Belt::default()
        };
        b.p.V = 0.1 + 0.02 * k as f64;
        models.push(b);
        cases.push(Case {
            z0: [0.0; 2],
            t_end: 1.0 + 0.5 * k as f64,
            opts: SolverOptions::default(),
            limit: if k == 3 { 150 } else { usize::MAX },
        });
    }
    let single = same_as_single::<Belt, 2>(&models, &cases, 1000.0, simulate_ensemble);
    let sticking = single
        .iter()
        .filter(|r| r.as_ref().unwrap().0.stats.event_count(EventKind::Stick) > 0)
        .count();
    assert!(sticking >= 8, "{sticking} of 11 runs stick");
}

/// The disc–pad's lane-wise right-hand side equals `field` lane by lane, bit
/// for bit, in every mode (both slip directions, stick, free flight, mixed
/// across the lanes), for four different models (speeds, loads, follower
/// force, a ramp in progress and one finished); it leaves other friction
/// laws to `field` altogether.
#[test]
fn disc_pad_lane_field_is_field_bit_for_bit() {
    let mut models = [DiscPad::default(); LANES];
    models[1].p.V = 2.5;
    models[1].p.N = 1800.0;
    models[2].p.alpha = 3.0;
    models[2].p.t_ramp = 0.01;
    models[3].p.t_ramp = 1e-4;
    models[3].p.c_py = 7.0;
    let pack = DiscPad::pack(models.each_ref().map(Some)).expect("thesis law, unilateral");
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let scale = [1e-6, 1e-6, 1e-6, 1e-6, 2.0, 2.0, 1.0, 1.0];
    for case in 0..2000 {
        // Displacements from 1 µm to 1 cm, so that the follower force
        // α·F_t·y_d (which carries the stick force) shows in the slopes.
        let grow = [10f64.powi((case % 5) as i32), 1.0];
        let z: [[f64; 8]; LANES] =
            std::array::from_fn(|_| std::array::from_fn(|i| scale[i] * grow[i / 4] * rnd()));
        let t: [f64; LANES] = std::array::from_fn(|_| 0.01 * rnd().abs());
        // Every mix of modes across the lanes comes up (4⁴ = 256 patterns
        // over the cases); slip is the most common, as in a run.
        let modes: [Mode; LANES] =
            std::array::from_fn(|l| match (case / 4usize.pow(l as u32)) % 4 {
                0 => Mode::SlipNeg,
                1 => Mode::Stick,
                2 => Mode::Free,
                _ => Mode::SlipPos,
            });
        let zl: [Lanes; 8] = std::array::from_fn(|i| Lanes::new(std::array::from_fn(|l| z[l][i])));
        let mut dz = [Lanes::ZERO; 8];
        let lane_modes = modes.map(|m| Some(Modes::single(m)));
        let done = DiscPad::field_lanes(&pack, Lanes::new(t), &lane_modes, &zl, &mut dz);
        assert_eq!(done, [true; LANES]);
        for l in 0..LANES {
            let mut one = [0.0; 8];
            models[l].field(t[l], &Modes::single(modes[l]), &z[l], &mut one);
            for i in 0..8 {
                assert_eq!(
                    dz[i].lane(l).to_bits(),
                    one[i].to_bits(),
                    "case {case} lane {l} state {i}: {} vs {}",
                    dz[i].lane(l),
                    one[i]
                );
            }
        }
    }
    // Idle lanes are not computed; lanes in any mode are.
    let zl = [Lanes::ZERO; 8];
    let mut dz = [Lanes::ZERO; 8];
    let mut lane_modes = [None; LANES];
    lane_modes[0] = Some(Modes::single(Mode::SlipPos));
    let done = DiscPad::field_lanes(&pack, Lanes::ZERO, &lane_modes, &zl, &mut dz);
    let only = |set: &[usize]| -> [bool; LANES] { std::array::from_fn(|l| set.contains(&l)) };
    assert_eq!(done, only(&[0]));
    lane_modes[1] = Some(Modes::single(Mode::Stick));
    lane_modes[2] = Some(Modes::single(Mode::Free));
    let done = DiscPad::field_lanes(&pack, Lanes::ZERO, &lane_modes, &zl, &mut dz);
    assert_eq!(done, only(&[0, 1, 2]));
    lane_modes[0] = None;
    let done = DiscPad::field_lanes(&pack, Lanes::ZERO, &lane_modes, &zl, &mut dz);
    assert_eq!(done, only(&[1, 2]));
    let done = DiscPad::field_lanes(&pack, Lanes::ZERO, &[None; LANES], &zl, &mut dz);
    assert_eq!(done, [false; LANES]);
    let mut strib = models;
    strib[3].friction = FrictionLaw::by_name("stribeck").unwrap();
    assert!(DiscPad::pack(strib.each_ref().map(Some)).is_none());
}
