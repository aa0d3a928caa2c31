//! Several trajectories at once on one core: `L` lanes, each its own run
//! (model, start, end, step size, modes, events, sink), stepped together.
//!
//! Every lane goes through exactly the code path of [`super::simulate`]
//! (the same step-size control, event search, transitions and sink feeding,
//! through the same [`Solver`] methods); only the Runge–Kutta arithmetic of
//! an attempt is done for all lanes together, in a structure-of-arrays
//! layout (`[stage][state][lane]`) whose innermost loop runs across lanes.
//! Each lane's numbers go through the same operations in the same order as
//! in a run of its own, so the ensemble's results are bit-for-bit those of
//! one-at-a-time runs. What it gains: the lanes' right-hand sides are
//! independent, so the processor overlaps their latencies, which a single
//! trajectory's serial chain of stages cannot do, and with AVX2 a stage
//! combination serves four lanes per instruction. With each lane's
//! right-hand side called on its own ([`simulate_ensemble`]) that is eaten
//! by copying states and slopes in and out of the lanes; with a model's
//! lane-wise [`LaneField`] ([`simulate_ensemble_lanes`]), the lanes' modes
//! turned into masks once per attempt and the error norms computed
//! lane-wise too, the disc–pad runs 1.5–1.7× as many steps per CPU-second
//! as one at a time on the default x86-64-v3 build, in 29 % fewer
//! instructions (BENCHMARKS.md, issue 16). Transient maps of the disc–pad
//! use it. What stays per lane: the step-size control (two `powf`), the
//! event search on the dense output, transitions and the sink.
//!
//! A lane whose run ends (finished, stopped by its sink, or failed) takes
//! the next job at once, so a sweep of many short runs keeps all lanes busy.

pub use super::lanes::{Lanes, LANES};
use super::tableau::{A, B, C, D, E3, E5};
use super::{check_rate, Feed, IntegrateError, RunInfo, Sink, Solver, SolverOptions};
pub use crate::model::lane_field::LaneField;
use crate::model::{Modes, System};

const L: usize = LANES;

/// One run of an ensemble: what [`super::simulate`] takes, per lane.
pub struct Job<'m, M: System<N> + ?Sized, S: Sink<N>, const N: usize> {
    /// The model (each job may have its own parameters).
    pub model: &'m M,
    /// Start time (s).
    pub t0: f64,
    /// Start state.
    pub z0: [f64; N],
    /// End time (s).
    pub t_end: f64,
    /// Solver options (each job may have its own step budget).
    pub opts: SolverOptions,
    /// Where the samples and events go.
    pub sink: S,
}

/// How the lanes' slopes are computed: one model call per lane
/// ([`PerLane`]), or a [`LaneField`] for all lanes at once ([`Packed`]).
trait Slopes<M: System<N> + ?Sized, const N: usize> {
    /// What [`lanes`](Self::lanes) needs of the lanes' modes.
    type Masks;
    /// The lanes' jobs changed: gather what the lane-wise field needs.
    fn repack(&mut self, lanes: &[Option<Lane<'_, M, N>>; L]);
    /// The masks of the lanes' `modes`, and the lanes that
    /// [`lanes`](Self::lanes) computes (the others are left to
    /// [`System::field`]).
    fn masks(&self, modes: &[Option<Modes>; L]) -> (Self::Masks, [bool; L]);
    /// The slopes at `(t, z)` of the lanes it computes, in `dz`.
    fn lanes(&self, masks: &Self::Masks, t: Lanes, z: &[Lanes; N], dz: &mut [Lanes; N]);
}

/// Every lane's slope by its own model call.
struct PerLane;

impl<M: System<N> + ?Sized, const N: usize> Slopes<M, N> for PerLane {
    type Masks = ();
    fn repack(&mut self, _lanes: &[Option<Lane<'_, M, N>>; L]) {}
    fn masks(&self, _modes: &[Option<Modes>; L]) -> ((), [bool; L]) {
        ((), [false; L])
    }
    #[inline(always)]
    fn lanes(&self, _masks: &(), _t: Lanes, _z: &[Lanes; N], _dz: &mut [Lanes; N]) {}
}

/// The lanes' slopes by the model's [`LaneField`].
struct Packed<M: LaneField<N>, const N: usize>(Option<M::Pack>);

impl<M: LaneField<N>, const N: usize> Slopes<M, N> for Packed<M, N> {
    type Masks = Option<M::Masks>;
    fn repack(&mut self, lanes: &[Option<Lane<'_, M, N>>; L]) {
        self.0 = M::pack(std::array::from_fn(|l| {
            lanes[l].as_ref().map(|lane| lane.solver.model)
        }));
    }
    fn masks(&self, modes: &[Option<Modes>; L]) -> (Option<M::Masks>, [bool; L]) {
        match &self.0 {
            Some(_) => {
                let (masks, done) = M::masks(modes);
                (Some(masks), done)
            }
            None => (None, [false; L]),
        }
    }
    #[inline(always)]
    fn lanes(&self, masks: &Option<M::Masks>, t: Lanes, z: &[Lanes; N], dz: &mut [Lanes; N]) {
        if let (Some(pack), Some(masks)) = (&self.0, masks) {
            M::field_masked(pack, masks, t, z, dz);
        }
    }
}

/// The lanes of an attempt (or of the dense output's stages) and their
/// modes, as every stage's slopes need them: made once, used by each stage.
struct Batch<Mk> {
    /// The modes of the lanes taking part (`None`: left out).
    modes: [Option<Modes>; L],
    /// The lane-wise field's masks of these modes.
    masks: Mk,
    /// Lanes taking part that the lane-wise field does not compute.
    rest: [bool; L],
    /// Whether the lane-wise field computes any lane.
    any: bool,
}

/// A lane at work: its job's index, solver, feed, and the step in progress.
struct Lane<'m, M: System<N> + ?Sized, const N: usize> {
    job: usize,
    solver: Solver<'m, M, N>,
    feed: Feed,
    /// `t_stop` of the step in progress, if one is.
    step: Option<f64>,
    /// Size of the attempt in progress, and whether it is clipped to `t_stop`.
    attempt: (f64, bool),
}

/// Integrate every job as [`super::simulate`] would, `L` at a time, feeding
/// samples at `t0 + k/sample_rate` and events into each job's sink. Returns
/// each job's result, in order; a job that fails does not stop the others.
pub fn simulate_ensemble<'m, M, S, const N: usize>(
    jobs: &mut [Job<'m, M, S, N>],
    sample_rate: f64,
) -> Vec<Result<RunInfo, IntegrateError>>
where
    M: System<N> + ?Sized,
    S: Sink<N>,
{
    run_ensemble(jobs, sample_rate, PerLane)
}

/// [`simulate_ensemble`] with the slopes of every stage computed for all
/// lanes at once by the model's [`LaneField`] (falling back to one call per
/// lane where it declines): the same results, bit for bit.
pub fn simulate_ensemble_lanes<'m, M, S, const N: usize>(
    jobs: &mut [Job<'m, M, S, N>],
    sample_rate: f64,
) -> Vec<Result<RunInfo, IntegrateError>>
where
    M: LaneField<N>,
    S: Sink<N>,
{
    run_ensemble(jobs, sample_rate, Packed::<M, N>(None))
}

/// The ensemble's loop, with the lanes' slopes computed by `slopes`.
fn run_ensemble<'m, M, S, F, const N: usize>(
    jobs: &mut [Job<'m, M, S, N>],
    sample_rate: f64,
    mut slopes: F,
) -> Vec<Result<RunInfo, IntegrateError>>
where
    M: System<N> + ?Sized,
    S: Sink<N>,
    F: Slopes<M, N>,
{
    let mut results: Vec<Option<Result<RunInfo, IntegrateError>>> =
        (0..jobs.len()).map(|_| None).collect();
    if let Err(e) = check_rate(sample_rate) {
        return jobs.iter().map(|_| Err(e.clone())).collect();
    }
    let mut lanes: [Option<Lane<'m, M, N>>; L] = std::array::from_fn(|_| None);
    let mut next_job = 0;
    let mut soa = Soa::<N>::new();
    // The job of each lane when the slopes were last packed.
    let mut packed_jobs = [None; L];
    loop {
        // Fill idle lanes, start their steps and size their attempts; a lane
        // whose run ends here is emptied and filled again.
        let mut active = [false; L];
        for l in 0..L {
            loop {
                if lanes[l].is_none() {
                    if next_job >= jobs.len() {
                        break;
                    }
                    let j = next_job;
                    next_job += 1;
                    lanes[l] = start_lane(j, &mut jobs[j], sample_rate, &mut results);
                    continue;
                }
                let lane = lanes[l].as_mut().expect("filled above");
                match prepare(lane) {
                    Ok(true) => {
                        active[l] = true;
                        break;
                    }
                    Ok(false) => {
                        let info = RunInfo {
                            stats: *lane.solver.stats(),
                            t_final: lane.solver.t(),
                            stopped_early: false,
                        };
                        results[lane.job] = Some(Ok(info));
                        lanes[l] = None;
                    }
                    Err(e) => {
                        results[lane.job] = Some(Err(e));
                        lanes[l] = None;
                    }
                }
            }
        }
        if !active.contains(&true) {
            break;
        }
        let jobs_now = std::array::from_fn(|l| lanes[l].as_ref().map(|lane| lane.job));
        if jobs_now != packed_jobs {
            slopes.repack(&lanes);
            soa.tolerances(&lanes);
            packed_jobs = jobs_now;
        }
        // One attempt of every active lane, together.
        soa.attempt(&mut lanes, &active, &slopes);
        let mut accepted = [false; L];
        for l in 0..L {
            if !active[l] {
                continue;
            }
            let lane = lanes[l].as_mut().expect("active");
            let (h, hits_stop) = lane.attempt;
            let (z_new, err) = soa.outcome(l);
            match lane.solver.judge(h, hits_stop, &z_new, err) {
                Ok(ok) => accepted[l] = ok,
                Err(e) => {
                    results[lane.job] = Some(Err(e));
                    lanes[l] = None;
                }
            }
        }
        if !accepted.contains(&true) {
            continue;
        }
        soa.dense_stages(&mut lanes, &accepted, &slopes);
        for l in 0..L {
            if !accepted[l] {
                continue;
            }
            let lane = lanes[l].as_mut().expect("accepted");
            let job = &mut jobs[lane.job];
            let (h, _) = lane.attempt;
            let t_stop = lane.step.expect("a step in progress");
            let z_new = soa.z_new_of(l);
            lane.solver.dense_low(h, &z_new);
            match lane.solver.settle(h, t_stop, z_new) {
                Ok(None) => {} // retried shorter
                Ok(Some(seg)) => {
                    lane.step = None;
                    if let Some(info) = lane.feed.segment(&mut lane.solver, &seg, &mut job.sink) {
                        results[lane.job] = Some(Ok(info));
                        lanes[l] = None;
                    }
                }
                Err(e) => {
                    results[lane.job] = Some(Err(e));
                    lanes[l] = None;
                }
            }
        }
    }
    results
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect()
}

/// Start job `j` in a lane: `None` if it ended at once (its result is recorded).
fn start_lane<'m, M, S, const N: usize>(
    j: usize,
    job: &mut Job<'m, M, S, N>,
    sample_rate: f64,
    results: &mut [Option<Result<RunInfo, IntegrateError>>],
) -> Option<Lane<'m, M, N>>
where
    M: System<N> + ?Sized,
    S: Sink<N>,
{
    let mut solver = match Solver::new(job.model, job.t0, job.z0, job.t_end, job.opts) {
        Ok(s) => s,
        Err(e) => {
            results[j] = Some(Err(e));
            return None;
        }
    };
    let mut feed = Feed::new(job.t0, job.t_end, sample_rate);
    if let Some(info) = feed.start(&mut solver, &mut job.sink) {
        results[j] = Some(Ok(info));
        return None;
    }
    Some(Lane {
        job: j,
        solver,
        feed,
        step: None,
        attempt: (0.0, false),
    })
}

/// Begin a step if none is in progress and size the lane's next attempt:
/// `Ok(false)` once its run is at its end.
fn prepare<M: System<N> + ?Sized, const N: usize>(
    lane: &mut Lane<'_, M, N>,
) -> Result<bool, IntegrateError> {
    let t_stop = match lane.step {
        Some(t) => t,
        None => match lane.solver.begin_step()? {
            Some(t) => t,
            None => return Ok(false),
        },
    };
    lane.step = Some(t_stop);
    lane.attempt = lane.solver.attempt_size(t_stop)?;
    Ok(true)
}

/// The Runge–Kutta arithmetic of the lanes, `[stage][state]` of [`Lanes`]
/// (one number per lane; lane-wise IEEE products and sums, no fused
/// multiply–add, so each lane's numbers are those of a single run).
struct Soa<const N: usize> {
    k: [[Lanes; N]; 16],
    z: [Lanes; N],
    z_new: [Lanes; N],
    e5: [Lanes; N],
    e3: [Lanes; N],
    /// The dense output's high-order coefficients of the last step.
    d: [[Lanes; N]; 4],
    t: [f64; L],
    h: Lanes,
    /// The lanes' tolerances and norm sizes (as their solvers hold them),
    /// gathered once per change of the lanes' jobs.
    atol: [Lanes; N],
    rtol: Lanes,
    norm_n: Lanes,
    /// The lanes' error norms of the last attempt.
    err: [f64; L],
}

/// Lane `l` of every state.
#[inline(always)]
fn lane_of<const N: usize>(v: &[Lanes; N], l: usize) -> [f64; N] {
    std::array::from_fn(|i| v[i].lane(l))
}

impl<const N: usize> Soa<N> {
    fn new() -> Self {
        Soa {
            k: [[Lanes::ZERO; N]; 16],
            z: [Lanes::ZERO; N],
            z_new: [Lanes::ZERO; N],
            e5: [Lanes::ZERO; N],
            e3: [Lanes::ZERO; N],
            d: [[Lanes::ZERO; N]; 4],
            t: [0.0; L],
            h: Lanes::ZERO,
            atol: [Lanes::ONE; N],
            rtol: Lanes::ONE,
            norm_n: Lanes::ONE,
            err: [0.0; L],
        }
    }

    /// Gather the lanes' tolerances (idle lanes: ones, never used).
    fn tolerances<M: System<N> + ?Sized>(&mut self, lanes: &[Option<Lane<'_, M, N>>; L]) {
        let of = |f: &dyn Fn(&Solver<'_, M, N>) -> f64| {
            Lanes::new(std::array::from_fn(|l| {
                lanes[l].as_ref().map_or(1.0, |lane| f(&lane.solver))
            }))
        };
        self.atol = std::array::from_fn(|i| of(&|s| s.atol[i]));
        self.rtol = of(&|s| s.opts.rtol);
        self.norm_n = of(&|s| s.norm_n);
    }

    /// Stage `S` of the lanes of `batch`: its state from the earlier stages
    /// (all lanes at once), its slope.
    #[inline(always)]
    fn stage<M: System<N> + ?Sized, F: Slopes<M, N>, const S: usize>(
        &mut self,
        lanes: &[Option<Lane<'_, M, N>>; L],
        batch: &Batch<F::Masks>,
        f: &F,
    ) {
        let mut y = [Lanes::ZERO; N];
        combine_lanes::<N, S>(&self.k, Some(&self.z), &A[S], self.h, &mut y);
        // The stage's times, as `Solver::stage`'s `t + c·h`.
        let tc = Lanes::new(self.t) + Lanes::splat(C[S]) * self.h;
        Self::slopes(&mut self.k[S], tc, lanes, batch, &y, f);
    }

    /// `k_s = f(tc, y)` of the lanes of `batch` (anything elsewhere):
    /// lane-wise by `f` where it can, by the lane's own model at its own
    /// time where it declines. Not inlined: one copy of the right-hand side
    /// serves every stage, so the code stays within the instruction cache.
    #[inline(never)]
    fn slopes<M: System<N> + ?Sized, F: Slopes<M, N>>(
        k_s: &mut [Lanes; N],
        tc: Lanes,
        lanes: &[Option<Lane<'_, M, N>>; L],
        batch: &Batch<F::Masks>,
        y: &[Lanes; N],
        f: &F,
    ) {
        if batch.any {
            f.lanes(&batch.masks, tc, y, k_s);
        }
        let (modes, rest) = (&batch.modes, batch.rest);
        if !rest.contains(&true) {
            return;
        }
        let mut out = [[0.0; N]; L];
        for l in 0..L {
            if let (Some(lane), Some(m), true) = (&lanes[l], &modes[l], rest[l]) {
                lane.solver
                    .model
                    .field(tc.lane(l), m, &lane_of(y, l), &mut out[l]);
            }
        }
        // The lanes evaluated one by one go in with one vector per state
        // (not lane by lane: a vector rebuilt from four scalar stores).
        for i in 0..N {
            let done_i = k_s[i].to_array();
            k_s[i] = Lanes::new(std::array::from_fn(|l| {
                if rest[l] {
                    out[l][i]
                } else {
                    done_i[l]
                }
            }));
        }
    }

    /// The batch of the lanes in `mask`, each lane's right-hand-side count
    /// raised by `evals` (the slopes about to be computed for it).
    fn batch<M: System<N> + ?Sized, F: Slopes<M, N>>(
        lanes: &mut [Option<Lane<'_, M, N>>; L],
        mask: &[bool; L],
        evals: u64,
        f: &F,
    ) -> Batch<F::Masks> {
        let modes = std::array::from_fn(|l| match (&mut lanes[l], mask[l]) {
            (Some(lane), true) => {
                lane.solver.stats.rhs_evals += evals;
                Some(lane.solver.modes)
            }
            _ => None,
        });
        let (masks, done) = f.masks(&modes);
        Batch {
            modes,
            masks,
            rest: std::array::from_fn(|l| modes[l].is_some() && !done[l]),
            any: done.contains(&true),
        }
    }

    /// One attempt of every active lane (its size is in the lane): stages
    /// 1…12 as [`Solver::rk_step`] computes them, and the error estimates.
    fn attempt<M: System<N> + ?Sized, F: Slopes<M, N>>(
        &mut self,
        lanes: &mut [Option<Lane<'_, M, N>>; L],
        active: &[bool; L],
        fields: &F,
    ) {
        let mut h = [0.0; L];
        let mut z = [[0.0; N]; L];
        let mut f = [[0.0; N]; L];
        for l in 0..L {
            if let (Some(lane), true) = (&lanes[l], active[l]) {
                self.t[l] = lane.solver.t;
                h[l] = lane.attempt.0;
                z[l] = lane.solver.z;
                f[l] = lane.solver.f;
            }
        }
        self.h = Lanes::new(h);
        for i in 0..N {
            self.z[i] = Lanes::new(std::array::from_fn(|l| z[l][i]));
            self.k[0][i] = Lanes::new(std::array::from_fn(|l| f[l][i]));
        }
        // Stages 1…11 and the slope at the new state: 12 evaluations.
        let batch = Self::batch(lanes, active, 12, fields);
        self.stage::<M, F, 1>(lanes, &batch, fields);
        self.stage::<M, F, 2>(lanes, &batch, fields);
        self.stage::<M, F, 3>(lanes, &batch, fields);
        self.stage::<M, F, 4>(lanes, &batch, fields);
        self.stage::<M, F, 5>(lanes, &batch, fields);
        self.stage::<M, F, 6>(lanes, &batch, fields);
        self.stage::<M, F, 7>(lanes, &batch, fields);
        self.stage::<M, F, 8>(lanes, &batch, fields);
        self.stage::<M, F, 9>(lanes, &batch, fields);
        self.stage::<M, F, 10>(lanes, &batch, fields);
        self.stage::<M, F, 11>(lanes, &batch, fields);
        combine_lanes::<N, 12>(&self.k, Some(&self.z), &B, self.h, &mut self.z_new);
        // The slope at the new state, at `t + h` as `Solver::rk_step`'s.
        let tc = Lanes::new(self.t) + self.h;
        Self::slopes(&mut self.k[12], tc, lanes, &batch, &self.z_new, fields);
        combine_lanes::<N, 13>(&self.k, None, &E5, Lanes::ONE, &mut self.e5);
        combine_lanes::<N, 13>(&self.k, None, &E3, Lanes::ONE, &mut self.e3);
        self.err = self.error_norms();
    }

    /// [`Solver::error_norm`] of every lane at once: the same operations in
    /// the same order, lane-wise (`max` chooses the other lane of a NaN,
    /// as `f64::max` does; `x·x` is `powi(2)`).
    fn error_norms(&self) -> [f64; L] {
        let (mut err5, mut err3) = (Lanes::ZERO, Lanes::ZERO);
        for i in 0..N {
            let sk = self.atol[i] + self.rtol * self.z[i].abs().max(self.z_new[i].abs());
            let (a, b) = (self.e5[i] / sk, self.e3[i] / sk);
            err5 += a * a;
            err3 += b * b;
        }
        let norm = self.h.abs() * err5 / ((err5 + Lanes::splat(0.01) * err3) * self.norm_n).sqrt();
        let zero = Lanes::ZERO;
        let both_zero = err5.cmp_eq(zero) & err3.cmp_eq(zero);
        both_zero.blend(zero, norm).to_array()
    }

    /// Lane `l`'s new state and error norm.
    fn outcome(&self, l: usize) -> ([f64; N], f64) {
        (lane_of(&self.z_new, l), self.err[l])
    }

    /// Lane `l`'s new state.
    fn z_new_of(&self, l: usize) -> [f64; N] {
        lane_of(&self.z_new, l)
    }

    /// The dense output's three extra stages of the accepted lanes and its
    /// high-order coefficients, copied into their solvers (with the slopes
    /// at both ends of the step).
    fn dense_stages<M: System<N> + ?Sized, F: Slopes<M, N>>(
        &mut self,
        lanes: &mut [Option<Lane<'_, M, N>>; L],
        accepted: &[bool; L],
        f: &F,
    ) {
        let batch = Self::batch(lanes, accepted, 3, f);
        self.stage::<M, F, 13>(lanes, &batch, f);
        self.stage::<M, F, 14>(lanes, &batch, f);
        self.stage::<M, F, 15>(lanes, &batch, f);
        // (Row by row with constant rows, so that their zeros vanish at
        // compile time.)
        combine_lanes::<N, 16>(&self.k, None, &D[0], self.h, &mut self.d[0]);
        combine_lanes::<N, 16>(&self.k, None, &D[1], self.h, &mut self.d[1]);
        combine_lanes::<N, 16>(&self.k, None, &D[2], self.h, &mut self.d[2]);
        combine_lanes::<N, 16>(&self.k, None, &D[3], self.h, &mut self.d[3]);
        let d = &self.d;
        for (l, lane) in lanes.iter_mut().enumerate() {
            let (Some(lane), true) = (lane, accepted[l]) else {
                continue;
            };
            let solver = &mut lane.solver;
            for r in 0..4 {
                solver.dense[3 + r] = lane_of(&d[r], l);
            }
            solver.k[0] = lane_of(&self.k[0], l);
            solver.k[12] = lane_of(&self.k[12], l);
        }
    }
}

/// [`super::combine`] for all lanes at once, into `y`:
/// `base + Σ_{j<J} (h·row[j])·k[j]` lane by lane (`base` zero if `None`),
/// the terms in the same order, so each lane's sums are bit for bit those
/// of a single run.
#[inline(always)]
fn combine_lanes<const N: usize, const J: usize>(
    k: &[[Lanes; N]; 16],
    base: Option<&[Lanes; N]>,
    row: &[f64],
    h: Lanes,
    y: &mut [Lanes; N],
) {
    // State by state, the terms innermost: one state's lanes stay in a
    // register while its terms are added (all states at once would spill).
    let mut a = [Lanes::ZERO; 16];
    macro_rules! unrolled {
        ($($j:literal)*) => {
            $(
                if $j < J && row[$j] != 0.0 {
                    a[$j] = h * Lanes::splat(row[$j]);
                }
            )*
            for i in 0..N {
                let mut yi = base.map_or(Lanes::ZERO, |b| b[i]);
                $(
                    if $j < J && row[$j] != 0.0 {
                        yi += a[$j] * k[$j][i];
                    }
                )*
                y[i] = yi;
            }
        };
    }
    unrolled!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15);
}
