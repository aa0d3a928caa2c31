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
//! lane-wise [`LaneField`] ([`simulate_ensemble_lanes`]) the disc–pad runs
//! 1.25–1.45× as many steps per CPU-second as one at a time on the default
//! x86-64-v3 build (BENCHMARKS.md, issue 16). Transient maps of the
//! disc–pad use it.
//!
//! A lane whose run ends (finished, stopped by its sink, or failed) takes
//! the next job at once, so a sweep of many short runs keeps all lanes busy.

use super::tableau::{A, B, C, D, E3, E5};
use super::{check_rate, Feed, IntegrateError, RunInfo, Sink, Solver, SolverOptions};
use crate::model::{Modes, System};
use wide::f64x4;

/// Lanes of an ensemble: one [`f64x4`] holds a number of each.
pub const LANES: usize = 4;
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

/// A right-hand side evaluated for [`LANES`] runs at once, lane-wise, for
/// [`simulate_ensemble_lanes`]: the stage combinations already run across
/// lanes; with this the slopes do too, and no lane's state is copied out of
/// (or its slope into) the lane-wise arrays.
///
/// The contract is [`System::field`]'s, lane by lane and bit for bit: each
/// lane's slope must come from the same IEEE operations in the same order as
/// `field` on that lane's model, state and time (lane-wise products, sums
/// and quotients of [`f64x4`] are the scalar ones). A call may leave lanes
/// out (e.g. a mode it does not cover): those lanes are then evaluated by
/// [`System::field`].
pub trait LaneField<const N: usize>: System<N> + Sized {
    /// What the lane-wise field needs of the lanes' models, gathered once
    /// per change of the lanes' jobs (not on every call).
    type Pack;
    /// The pack of the lanes' models (`None`: an empty lane); `None` if these
    /// models cannot be evaluated lane-wise (every call then falls back to
    /// [`System::field`]).
    fn pack(models: [Option<&Self>; LANES]) -> Option<Self::Pack>;
    /// `dz = f(t, z)` lane by lane, each lane in its own `modes`
    /// (`None`: an idle lane, whose `dz` is not used). Returns the lanes it
    /// computed; the others' `dz` may hold anything (they are computed
    /// again by [`System::field`]).
    fn field_lanes(
        pack: &Self::Pack,
        t: f64x4,
        modes: &[Option<Modes>; LANES],
        z: &[f64x4; N],
        dz: &mut [f64x4; N],
    ) -> [bool; LANES];
}

/// How the lanes' slopes are computed: one model call per lane
/// ([`PerLane`]), or a [`LaneField`] for all lanes at once ([`Packed`]).
trait Slopes<M: System<N> + ?Sized, const N: usize> {
    /// The lanes' jobs changed: gather what the lane-wise field needs.
    fn repack(&mut self, lanes: &[Option<Lane<'_, M, N>>; L]);
    /// The slopes at `(t, z)` of the lanes with `modes` in `dz`; returns
    /// the lanes computed (the others are left to [`System::field`]).
    fn lanes(
        &self,
        t: f64x4,
        modes: &[Option<Modes>; L],
        z: &[f64x4; N],
        dz: &mut [f64x4; N],
    ) -> [bool; L];
}

/// Every lane's slope by its own model call.
struct PerLane;

impl<M: System<N> + ?Sized, const N: usize> Slopes<M, N> for PerLane {
    fn repack(&mut self, _lanes: &[Option<Lane<'_, M, N>>; L]) {}
    #[inline(always)]
    fn lanes(
        &self,
        _t: f64x4,
        _modes: &[Option<Modes>; L],
        _z: &[f64x4; N],
        _dz: &mut [f64x4; N],
    ) -> [bool; L] {
        [false; L]
    }
}

/// The lanes' slopes by the model's [`LaneField`].
struct Packed<M: LaneField<N>, const N: usize>(Option<M::Pack>);

impl<M: LaneField<N>, const N: usize> Slopes<M, N> for Packed<M, N> {
    fn repack(&mut self, lanes: &[Option<Lane<'_, M, N>>; L]) {
        self.0 = M::pack(std::array::from_fn(|l| {
            lanes[l].as_ref().map(|lane| lane.solver.model)
        }));
    }
    #[inline(always)]
    fn lanes(
        &self,
        t: f64x4,
        modes: &[Option<Modes>; L],
        z: &[f64x4; N],
        dz: &mut [f64x4; N],
    ) -> [bool; L] {
        match &self.0 {
            Some(pack) => M::field_lanes(pack, t, modes, z, dz),
            None => [false; L],
        }
    }
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
            let (z_new, err) = soa.outcome(l, &lane.solver);
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

/// The Runge–Kutta arithmetic of the lanes, `[stage][state]` of [`f64x4`]
/// (one number per lane; lane-wise IEEE products and sums, no fused
/// multiply–add, so each lane's numbers are those of a single run).
struct Soa<const N: usize> {
    k: [[f64x4; N]; 16],
    z: [f64x4; N],
    z_new: [f64x4; N],
    e5: [f64x4; N],
    e3: [f64x4; N],
    t: [f64; L],
    h: f64x4,
}

/// Lane `l` of every state.
#[inline(always)]
fn lane_of<const N: usize>(v: &[f64x4; N], l: usize) -> [f64; N] {
    std::array::from_fn(|i| v[i].as_array_ref()[l])
}

impl<const N: usize> Soa<N> {
    fn new() -> Self {
        Soa {
            k: [[f64x4::ZERO; N]; 16],
            z: [f64x4::ZERO; N],
            z_new: [f64x4::ZERO; N],
            e5: [f64x4::ZERO; N],
            e3: [f64x4::ZERO; N],
            t: [0.0; L],
            h: f64x4::ZERO,
        }
    }

    /// Stage `S` of every lane in `mask`: its state from the earlier
    /// stages (all lanes at once), its slope from the lane's own model.
    #[inline(always)]
    fn stage<M: System<N> + ?Sized, F: Slopes<M, N>, const S: usize>(
        &mut self,
        lanes: &mut [Option<Lane<'_, M, N>>; L],
        mask: &[bool; L],
        f: &F,
    ) {
        let y = combine_lanes::<N, S>(&self.k, &self.z, &A[S], self.h);
        self.slopes(lanes, mask, S, &y, C[S], f);
    }

    /// `k[s] = f(t + c·h, y)` of every lane in `mask` (0 elsewhere). Not
    /// inlined: one copy of the right-hand side serves every stage, so the
    /// code stays within the instruction cache.
    #[inline(never)]
    fn slopes<M: System<N> + ?Sized, F: Slopes<M, N>>(
        &mut self,
        lanes: &mut [Option<Lane<'_, M, N>>; L],
        mask: &[bool; L],
        s: usize,
        y: &[f64x4; N],
        c: f64,
        f: &F,
    ) {
        // The lanes' times, lane-wise: the same sums as below.
        let t = f64x4::new(self.t);
        let tc = if s == 12 {
            t + self.h
        } else {
            t + f64x4::splat(c) * self.h
        };
        let modes: [Option<Modes>; L] = std::array::from_fn(|l| match (&lanes[l], mask[l]) {
            (Some(lane), true) => Some(lane.solver.modes),
            _ => None,
        });
        let done = f.lanes(tc, &modes, y, &mut self.k[s]);
        let h = self.h.to_array();
        let mut out = [[0.0; N]; L];
        let mut rest = [false; L];
        for (l, lane) in lanes.iter_mut().enumerate() {
            if let (Some(lane), true) = (lane, mask[l]) {
                let solver = &mut lane.solver;
                solver.stats.rhs_evals += 1;
                if done[l] {
                    continue;
                }
                rest[l] = true;
                let tc = if s == 12 {
                    self.t[l] + h[l]
                } else {
                    self.t[l] + c * h[l]
                };
                solver
                    .model
                    .field(tc, &solver.modes, &lane_of(y, l), &mut out[l]);
            }
        }
        // The lanes evaluated one by one go in with one vector per state
        // (not lane by lane: a vector rebuilt from four scalar stores).
        if rest.contains(&true) {
            for i in 0..N {
                let done_i = self.k[s][i].to_array();
                self.k[s][i] = f64x4::new(std::array::from_fn(|l| {
                    if rest[l] {
                        out[l][i]
                    } else {
                        done_i[l]
                    }
                }));
            }
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
        self.h = f64x4::new(h);
        for i in 0..N {
            self.z[i] = f64x4::new(std::array::from_fn(|l| z[l][i]));
            self.k[0][i] = f64x4::new(std::array::from_fn(|l| f[l][i]));
        }
        self.stage::<M, F, 1>(lanes, active, fields);
        self.stage::<M, F, 2>(lanes, active, fields);
        self.stage::<M, F, 3>(lanes, active, fields);
        self.stage::<M, F, 4>(lanes, active, fields);
        self.stage::<M, F, 5>(lanes, active, fields);
        self.stage::<M, F, 6>(lanes, active, fields);
        self.stage::<M, F, 7>(lanes, active, fields);
        self.stage::<M, F, 8>(lanes, active, fields);
        self.stage::<M, F, 9>(lanes, active, fields);
        self.stage::<M, F, 10>(lanes, active, fields);
        self.stage::<M, F, 11>(lanes, active, fields);
        let z_new = combine_lanes::<N, 12>(&self.k, &self.z, &B, self.h);
        self.slopes(lanes, active, 12, &z_new, 1.0, fields);
        self.z_new = z_new;
        let zero = [f64x4::ZERO; N];
        let one = f64x4::splat(1.0);
        self.e5 = combine_lanes::<N, 13>(&self.k, &zero, &E5, one);
        self.e3 = combine_lanes::<N, 13>(&self.k, &zero, &E3, one);
    }

    /// Lane `l`'s new state and error norm.
    fn outcome<M: System<N> + ?Sized>(
        &self,
        l: usize,
        solver: &Solver<'_, M, N>,
    ) -> ([f64; N], f64) {
        let z_new = lane_of(&self.z_new, l);
        let h = self.h.as_array_ref()[l];
        let err = solver.error_norm(
            h,
            &lane_of(&self.z, l),
            &z_new,
            &lane_of(&self.e5, l),
            &lane_of(&self.e3, l),
        );
        (z_new, err)
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
        self.stage::<M, F, 13>(lanes, accepted, f);
        self.stage::<M, F, 14>(lanes, accepted, f);
        self.stage::<M, F, 15>(lanes, accepted, f);
        let zero = [f64x4::ZERO; N];
        let d: [[f64x4; N]; 4] = [
            combine_lanes::<N, 16>(&self.k, &zero, &D[0], self.h),
            combine_lanes::<N, 16>(&self.k, &zero, &D[1], self.h),
            combine_lanes::<N, 16>(&self.k, &zero, &D[2], self.h),
            combine_lanes::<N, 16>(&self.k, &zero, &D[3], self.h),
        ];
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

/// [`super::combine`] for all lanes at once: `base + Σ_{j<J} (h·row[j])·k[j]`
/// lane by lane, the terms in the same order, so each lane's sums are bit
/// for bit those of a single run.
#[inline(always)]
fn combine_lanes<const N: usize, const J: usize>(
    k: &[[f64x4; N]; 16],
    base: &[f64x4; N],
    row: &[f64],
    h: f64x4,
) -> [f64x4; N] {
    // State by state, the terms innermost: one state's lanes stay in a
    // register while its terms are added (all states at once would spill).
    let mut a = [f64x4::ZERO; 16];
    let mut y = *base;
    macro_rules! unrolled {
        ($($j:literal)*) => {
            $(
                if $j < J && row[$j] != 0.0 {
                    a[$j] = h * f64x4::splat(row[$j]);
                }
            )*
            for i in 0..N {
                let mut yi = y[i];
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
    y
}
