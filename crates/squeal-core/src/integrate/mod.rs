//! Event-driven integration of piecewise-smooth models.
//!
//! An adaptive Dormand–Prince 8(5,3) Runge–Kutta method (DOP853, Hairer,
//! Nørsett & Wanner, *Solving Ordinary Differential Equations I*, §II.5 and
//! §II.10) with its 7th-order dense output, written for this job because no
//! crate switches vector fields at events: after every accepted step, every
//! guard of the current mode is projected onto the step's dense output, where
//! it is a degree-7 polynomial, and its first upward crossing is found by
//! root isolation ([`roots`]); the step is cut there, the model's transition
//! rule picks the next mode, and integration restarts. Nothing is smoothed and
//! no crossing inside a step is missed (MODEL.md §8).
//!
//! [`Solver`] is the manual-stepping API; [`simulate`] is a thin loop over it
//! that feeds uniformly sampled states and events into a [`Sink`].

pub mod budget;
pub mod ensemble;
pub mod roots;
mod tableau;

pub use crate::lanes;
use crate::model::{EventKind, Guard, GuardKind, Guards, Mode, Modes, System};
pub use crate::solver_options::{SolverOptions, MAX_STATES};
use tableau::{A, B, C, D, E3, E5};

/// PI stabilisation of the step-size controller (0 = the elementary controller).
const STEP_BETA: f64 = 0.04;

/// Most mode changes in a row at one instant before it counts as chatter.
const SETTLE_LIMIT: usize = 16;

/// Why a run stopped before its end.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegrateError {
    /// The step size fell below round-off of the time.
    #[error("step size underflow at t = {t:.9e} s (h = {h:.3e} s)")]
    StepUnderflow {
        /// Time (s).
        t: f64,
        /// Step size (s).
        h: f64,
    },
    /// Events accumulate (Zeno chatter).
    #[error(
        "endless stick-slip chatter at t = {t:.9e} s: {count} events closer than {gap:.1e} s apart"
    )]
    Chatter {
        /// Time (s).
        t: f64,
        /// Events in a row.
        count: u32,
        /// Gap threshold (s).
        gap: f64,
    },
    /// A guard fires again and again at one instant without changing any
    /// mode: the model keeps the contact's mode, but the state it leaves
    /// crosses the guard again at once (a model's transition that does not
    /// move the state off its surface). The run cannot go on.
    #[error(
        "no progress at t = {t:.9e} s: contact {contact}'s {surface} guard fired {count} times in a row \
         without changing its mode (the model keeps the mode, but its motion crosses the guard again \
         at once)"
    )]
    Stalled {
        /// Time (s).
        t: f64,
        /// The contact's name.
        contact: String,
        /// Its guard's surface (`v_rel = 0`, `stick bound`, `F_n = 0`, `gap = 0`).
        surface: &'static str,
        /// Transitions in a row without progress.
        count: u32,
    },
    /// The event search of a guard that is not affine gave up on every step
    /// down to round-off of the time: the guard stays within round-off of
    /// zero without crossing it clearly (a grazing).
    #[error(
        "the event search gave up at t = {t:.9e} s: contact {contact}'s {surface} guard stays at \
         zero without a clear crossing (a grazing: e.g. the stick force's peak exactly at the \
         friction limit μ_s·F_n), and no step short enough certifies it; change the load or the \
         force slightly"
    )]
    EventSearch {
        /// Time (s).
        t: f64,
        /// The contact's name.
        contact: String,
        /// Its guard's surface (as [`IntegrateError::Stalled`]'s).
        surface: &'static str,
    },
    /// The state became NaN or infinite.
    #[error("the state became non-finite at t = {t:.9e} s")]
    NonFinite {
        /// Time (s).
        t: f64,
    },
    /// Too many steps.
    #[error("more than {steps} steps by t = {t:.9e} s")]
    MaxSteps {
        /// Time (s).
        t: f64,
        /// Step limit.
        steps: u64,
    },
    /// Options out of range.
    #[error("invalid solver option: {0}")]
    BadOptions(String),
}

/// Integrator statistics.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stats {
    /// Accepted steps (a step cut at an event counts once).
    pub accepted: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Events per kind, indexed by [`EventKind::index`].
    pub events: [u64; 5],
    /// Time spent in each mode (s) by the first contact, indexed by [`Mode::index`].
    pub mode_time: [f64; 4],
    /// Time spent sticking (s), per contact.
    pub stick_time: [f64; crate::model::MAX_CONTACTS],
}

impl Stats {
    /// Count of events of one kind.
    pub fn event_count(&self, kind: EventKind) -> u64 {
        self.events[kind.index()]
    }
    /// Fraction of the integrated time spent in true stick.
    pub fn stick_fraction(&self) -> f64 {
        let total: f64 = self.mode_time.iter().sum();
        if total > 0.0 {
            self.mode_time[Mode::Stick.index()] / total
        } else {
            0.0
        }
    }
}

/// One piece of trajectory produced by [`Solver::step`]: the dense output is
/// valid on `[t0, t1]` in `mode`; if `event` is set, the mode changed at `t1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start time.
    pub t0: f64,
    /// End time.
    pub t1: f64,
    /// Mode of the first contact on the segment.
    pub mode: Mode,
    /// Modes of all contacts on the segment.
    pub modes: Modes,
    /// The event that ended the segment, if any (reported kind).
    pub event: Option<EventKind>,
    /// The contact of that event.
    pub contact: usize,
    /// Whether the mode changed at `t1` (also for unreported transitions).
    pub switched: bool,
}

/// What the sink wants after a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Go on.
    Continue,
    /// Stop the run here (e.g. its outcome is certain).
    Stop,
}

/// Receives a run's output as it is produced: a run need not be held in memory.
pub trait Sink<const N: usize> {
    /// A uniformly spaced sample of the state, with the mode it is in.
    fn sample(&mut self, t: f64, z: &[f64; N], mode: Mode) -> Flow;
    /// An event at `t`; `z` is the state there and `mode` the mode after it.
    fn event(&mut self, _t: f64, _kind: EventKind, _z: &[f64; N], _mode: Mode) {}
    /// A sample with the modes of every contact (default: [`Sink::sample`]
    /// with the first contact's mode).
    #[inline]
    fn sample_modes(&mut self, t: f64, z: &[f64; N], modes: &Modes) -> Flow {
        self.sample(t, z, modes.first())
    }
    /// An event of contact `contact` (default: [`Sink::event`] with the
    /// first contact's mode).
    fn contact_event(
        &mut self,
        t: f64,
        kind: EventKind,
        _contact: usize,
        z: &[f64; N],
        modes: &Modes,
    ) {
        self.event(t, kind, z, modes.first())
    }
}

/// An event fired while settling a mode: kind, contact, state, modes after it.
type Pending<const N: usize> = (EventKind, usize, [f64; N], Modes);

/// Most guard evaluations of the Lipschitz search on one step before the
/// step is retried at a quarter of its size.
const LIPSCHITZ_EVALS: usize = 256;

/// DOP853 stepper with event location, for one model.
pub struct Solver<'m, M: System<N> + ?Sized, const N: usize> {
    model: &'m M,
    opts: SolverOptions,
    atol: [f64; N],
    /// The state count the error norm averages over ([`System::norm_states`]).
    norm_n: f64,
    t: f64,
    t_end: f64,
    z: [f64; N],
    f: [f64; N],
    modes: Modes,
    h: f64,
    last_rejected: bool,
    /// `β`-th power of the last accepted error (at least 1e-4) for the PI
    /// controller, computed at acceptance (off the critical path), so
    /// that only one `powf` lies on the path from a step's error to the next
    /// step size.
    err_old_pow: f64,
    k: [[f64; N]; 16],
    /// Dense output of the last segment: y_old and F0..F6.
    y_old: [f64; N],
    dense: [[f64; N]; 7],
    t_old: f64,
    h_dense: f64,
    guards: Guards<N>,
    stats: Stats,
    last_event_t: f64,
    zeno_run: u32,
    /// Transitions in a row that changed no mode and advanced no time.
    stall_run: u32,
    /// 1 + the index of the guard whose event search gave up on the last
    /// attempt (the step was retried shorter); 0 if none.
    gave_up: u32,
    /// Events fired while settling a mode (at most [`SETTLE_LIMIT`]), oldest first.
    pending: [Pending<N>; SETTLE_LIMIT],
    pending_len: usize,
    pending_next: usize,
}

/// Default absolute tolerances: positions, velocities (a model-dependent scale
/// is chosen by the caller; these are MODEL.md's disc–pad values).
pub const DEFAULT_ATOL_POS: f64 = 1e-16;
/// See [`DEFAULT_ATOL_POS`].
pub const DEFAULT_ATOL_VEL: f64 = 1e-11;

impl<'m, M: System<N> + ?Sized, const N: usize> Solver<'m, M, N> {
    /// A solver at `(t0, z0)` integrating to `t_end`. The initial mode is
    /// the model's; it is settled at once (a guard already violated fires).
    pub fn new(
        model: &'m M,
        t0: f64,
        z0: [f64; N],
        t_end: f64,
        opts: SolverOptions,
    ) -> Result<Self, IntegrateError> {
        if !(opts.rtol > 0.0 && opts.rtol < 1.0 && opts.rtol >= 1e-14) {
            return Err(IntegrateError::BadOptions(format!(
                "rtol = {} (must be in [1e-14, 1))",
                opts.rtol
            )));
        }
        let per_state = opts.atol_state.iter().take(N).map(|a| ("atol_state", *a));
        for (name, v) in [("atol_pos", opts.atol_pos), ("atol_vel", opts.atol_vel)]
            .into_iter()
            .chain(per_state)
        {
            if let Some(v) = v {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(IntegrateError::BadOptions(format!(
                        "{name} = {v} (must be > 0)"
                    )));
                }
            }
        }
        if opts.h_max.is_nan() || opts.h_max <= 0.0 {
            return Err(IntegrateError::BadOptions(format!(
                "h_max = {} (must be > 0)",
                opts.h_max
            )));
        }
        if !(t_end.is_finite() && t0.is_finite() && t_end >= t0)
            || z0.iter().any(|x| !x.is_finite())
        {
            return Err(IntegrateError::BadOptions("non-finite start or end".into()));
        }
        let mut atol = [0.0; N];
        let half = N / 2;
        for i in 0..N {
            let by_kind = if i < half {
                opts.atol_pos.unwrap_or(DEFAULT_ATOL_POS)
            } else {
                opts.atol_vel.unwrap_or(DEFAULT_ATOL_VEL)
            };
            atol[i] = opts.atol_state.get(i).copied().flatten().unwrap_or(by_kind);
        }
        let modes = model.start_modes(t0, &z0);
        let mut s = Solver {
            model,
            opts,
            atol,
            norm_n: model.norm_states() as f64,
            t: t0,
            t_end,
            z: z0,
            f: [0.0; N],
            modes,
            h: 0.0,
            last_rejected: false,
            err_old_pow: 1e-4f64.powf(STEP_BETA),
            k: [[0.0; N]; 16],
            y_old: z0,
            dense: [[0.0; N]; 7],
            t_old: t0,
            h_dense: 0.0,
            guards: Guards::default(),
            stats: Stats::default(),
            last_event_t: f64::NEG_INFINITY,
            zeno_run: 0,
            stall_run: 0,
            gave_up: 0,
            pending: [(EventKind::Stick, 0, [0.0; N], modes); SETTLE_LIMIT],
            pending_len: 0,
            pending_next: 0,
        };
        s.enter_mode(modes, 0)?;
        s.h = match opts.h_init {
            Some(h) if h > 0.0 => h,
            _ => s.initial_step(),
        };
        Ok(s)
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.t
    }
    /// Current state.
    pub fn state(&self) -> &[f64; N] {
        &self.z
    }
    /// Current mode of the first contact.
    pub fn mode(&self) -> Mode {
        self.modes.first()
    }
    /// Current modes of all contacts.
    pub fn modes(&self) -> Modes {
        self.modes
    }
    /// Statistics so far.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }
    /// Whether the end time is reached.
    pub fn finished(&self) -> bool {
        self.t >= self.t_end
    }
    /// The events the solver fired while settling the mode at the start or
    /// after the last transition, oldest first, each reported once.
    pub fn take_pending_event(&mut self) -> Option<(EventKind, [f64; N], Mode)> {
        self.take_pending_contact_event()
            .map(|(k, _, z, m)| (k, z, m.first()))
    }

    /// As [`Self::take_pending_event`], with the contact and every contact's mode.
    pub fn take_pending_contact_event(&mut self) -> Option<Pending<N>> {
        if self.pending_next < self.pending_len {
            self.pending_next += 1;
            Some(self.pending[self.pending_next - 1])
        } else {
            None
        }
    }

    #[inline]
    fn rhs(&mut self, t: f64, modes: Modes, z: &[f64; N], dz: &mut [f64; N]) {
        self.stats.rhs_evals += 1;
        self.model.field(t, &modes, z, dz);
    }

    /// Switch to `modes` at the current state: load their guards, evaluate
    /// f, and fire at once any guard that is already on its surface and moving
    /// out, or clearly beyond it (a mode that is left as soon as it is entered;
    /// with several contacts, one contact's transition can release another's
    /// stick at the same instant). Guards are tried in order, so simultaneous
    /// transitions resolve deterministically, lowest contact first.
    ///
    /// `broke` has bit `c` set for each contact `c` whose stick just broke at
    /// this instant: its slip-zero guard does not fire at once. Breakaway
    /// starts on that guard's surface with a relative acceleration that is
    /// zero when μ(0⁺) = μ_s (the stick force is the friction bound) and
    /// points out of stick otherwise, so only round-off could make it fire;
    /// and where the guard's rate is a single state's slope (a mass on a
    /// belt of prescribed speed), round-off carries no scale to be judged
    /// against. Firing would re-stick, the stick would break again at once,
    /// and the run would end in endless chatter.
    fn enter_mode(&mut self, mut modes: Modes, mut broke: u64) -> Result<(), IntegrateError> {
        for _ in 0..SETTLE_LIMIT {
            self.modes = modes;
            self.model.mode_guards(&modes, &mut self.guards);
            let (t, z) = (self.t, self.z);
            let mut f = [0.0; N];
            self.rhs(t, modes, &z, &mut f);
            self.f = f;
            let mut fired = None;
            for g in self.guards.as_slice() {
                if g.kind == GuardKind::SlipZero && broke & (1 << g.contact) != 0 {
                    continue;
                }
                let (val, rate, scale, vscale) = if g.affine {
                    let mut rate = 0.0;
                    let mut scale = 0.0;
                    let mut vscale = g.d.abs();
                    for i in 0..N {
                        rate += g.c[i] * self.f[i];
                        scale += (g.c[i] * self.f[i]).abs();
                        vscale += (g.c[i] * self.z[i]).abs();
                    }
                    (g.eval(&self.z), rate, scale, vscale)
                } else {
                    let c = self.model.guard_gradient(t, &modes, g, &z);
                    let mut rate = 0.0;
                    let mut scale = 0.0;
                    let mut vscale = 0.0;
                    for i in 0..N {
                        rate += c[i] * self.f[i];
                        scale += (c[i] * self.f[i]).abs();
                        vscale += (c[i] * self.z[i]).abs();
                    }
                    (
                        self.model.guard_value(t, &modes, g, &z),
                        rate,
                        scale,
                        vscale,
                    )
                };
                // Leaving at once needs a rate clearly above round-off: at a
                // smooth stick→slip transition (μ(0+) = μ_s) the rate is zero
                // and the sign of round-off must not decide. A stick bound
                // clearly exceeded (beyond round-off of its terms: another
                // contact's transition changed this one's multiplier) fires
                // whatever its rate.
                let stick_break =
                    matches!(g.kind, GuardKind::StickBreakPos | GuardKind::StickBreakNeg);
                if (val >= 0.0 && rate > 1e-9 * scale) || (stick_break && val > 1e-9 * vscale) {
                    fired = Some(*g);
                    break;
                }
            }
            let Some(g) = fired else { return Ok(()) };
            broke |= stick_broken(&g);
            let mut z = self.z;
            let (next, ev) = self.model.switch(self.t, &modes, &g, &mut z);
            self.z = z;
            if let Some(ev) = ev {
                self.note_event(ev)?;
                if self.pending_len < SETTLE_LIMIT {
                    self.pending[self.pending_len] = (ev, g.contact as usize, self.z, next);
                    self.pending_len += 1;
                }
            }
            if next == modes {
                return Ok(());
            }
            modes = next;
        }
        Err(IntegrateError::Chatter {
            t: self.t,
            count: SETTLE_LIMIT as u32,
            gap: 0.0,
        })
    }

    fn note_event(&mut self, ev: EventKind) -> Result<(), IntegrateError> {
        self.stats.events[ev.index()] += 1;
        if self.t - self.last_event_t < self.opts.zeno_gap {
            self.zeno_run += 1;
            if self.zeno_run >= self.opts.zeno_count {
                return Err(IntegrateError::Chatter {
                    t: self.t,
                    count: self.zeno_run,
                    gap: self.opts.zeno_gap,
                });
            }
        } else {
            self.zeno_run = 0;
        }
        self.last_event_t = self.t;
        Ok(())
    }

    /// Hairer's initial step size (Solving ODEs I, II.4).
    fn initial_step(&mut self) -> f64 {
        let (t, z, f0, mode) = (self.t, self.z, self.f, self.modes);
        let mut d0 = 0.0;
        let mut d1 = 0.0;
        for i in 0..N {
            let sk = self.atol[i] + self.opts.rtol * z[i].abs();
            d0 += (z[i] / sk).powi(2);
            d1 += (f0[i] / sk).powi(2);
        }
        let (d0, d1) = ((d0 / self.norm_n).sqrt(), (d1 / self.norm_n).sqrt());
        let h0 = if d0 < 1e-10 || d1 < 1e-10 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let h0 = h0.min(self.opts.h_max).min((self.t_end - t).max(1e-300));
        let mut z1 = [0.0; N];
        for i in 0..N {
            z1[i] = z[i] + h0 * f0[i];
        }
        let mut f1 = [0.0; N];
        self.rhs(t + h0, mode, &z1, &mut f1);
        let mut d2 = 0.0;
        for i in 0..N {
            let sk = self.atol[i] + self.opts.rtol * z[i].abs();
            d2 += ((f1[i] - f0[i]) / sk).powi(2);
        }
        let d2 = (d2 / self.norm_n).sqrt() / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 8.0)
        };
        (100.0 * h0).min(h1).min(self.opts.h_max)
    }

    /// Stage `S`: its state `z + h·Σ_j a[S][j]·k[j]` from the earlier
    /// stages, and its slope, written straight into `k[S]` (the caller
    /// counts the evaluations).
    #[inline(always)]
    fn stage<const S: usize>(&mut self, t: f64, z: &[f64; N], modes: &Modes, h: f64) {
        let y = combine::<N, S>(&self.k, z, &A[S], h);
        self.model.field(t + C[S] * h, modes, &y, &mut self.k[S]);
    }

    /// One RK step of size h from the current state; fills `k[0..13]`,
    /// returns the new state and the error norm.
    #[inline]
    fn rk_step(&mut self, h: f64) -> ([f64; N], f64) {
        let (t, z, modes) = (self.t, self.z, self.modes);
        self.k[0] = self.f;
        self.stage::<1>(t, &z, &modes, h);
        self.stage::<2>(t, &z, &modes, h);
        self.stage::<3>(t, &z, &modes, h);
        self.stage::<4>(t, &z, &modes, h);
        self.stage::<5>(t, &z, &modes, h);
        self.stage::<6>(t, &z, &modes, h);
        self.stage::<7>(t, &z, &modes, h);
        self.stage::<8>(t, &z, &modes, h);
        self.stage::<9>(t, &z, &modes, h);
        self.stage::<10>(t, &z, &modes, h);
        self.stage::<11>(t, &z, &modes, h);
        let z_new = combine::<N, 12>(&self.k, &z, &B, h);
        self.stats.rhs_evals += 12; // stages 1…11 and the slope at the end
        self.model.field(t + h, &modes, &z_new, &mut self.k[12]);
        // Error estimate (Hairer's DOP853: 5th- and 3rd-order embedded errors).
        let zero = [0.0; N];
        let e5 = combine::<N, 13>(&self.k, &zero, &E5, 1.0);
        let e3 = combine::<N, 13>(&self.k, &zero, &E3, 1.0);
        (z_new, self.error_norm(h, &z, &z_new, &e5, &e3))
    }

    /// The error norm of a step from `z` to `z_new` with the embedded
    /// error estimates `e5`, `e3` (Hairer's DOP853 norm).
    #[inline]
    fn error_norm(
        &self,
        h: f64,
        z: &[f64; N],
        z_new: &[f64; N],
        e5: &[f64; N],
        e3: &[f64; N],
    ) -> f64 {
        let mut err5 = 0.0;
        let mut err3 = 0.0;
        for i in 0..N {
            let sk = self.atol[i] + self.opts.rtol * z[i].abs().max(z_new[i].abs());
            err5 += (e5[i] / sk).powi(2);
            err3 += (e3[i] / sk).powi(2);
        }
        if err5 == 0.0 && err3 == 0.0 {
            0.0
        } else {
            h.abs() * err5 / ((err5 + 0.01 * err3) * self.norm_n).sqrt()
        }
    }

    /// Dense output coefficients of the accepted step (three more stages).
    #[inline]
    fn build_dense(&mut self, h: f64, z_new: &[f64; N]) {
        let (t, z, modes) = (self.t, self.z, self.modes);
        self.stage::<13>(t, &z, &modes, h);
        self.stage::<14>(t, &z, &modes, h);
        self.stage::<15>(t, &z, &modes, h);
        self.stats.rhs_evals += 3;
        self.dense_coefficients(h, z_new);
    }

    /// The dense output's coefficients once all 16 slopes are known.
    #[inline]
    fn dense_coefficients(&mut self, h: f64, z_new: &[f64; N]) {
        let zero = [0.0; N];
        self.dense[3] = combine::<N, 16>(&self.k, &zero, &D[0], h);
        self.dense[4] = combine::<N, 16>(&self.k, &zero, &D[1], h);
        self.dense[5] = combine::<N, 16>(&self.k, &zero, &D[2], h);
        self.dense[6] = combine::<N, 16>(&self.k, &zero, &D[3], h);
        self.dense_low(h, z_new);
    }

    /// The dense output's low-order coefficients (from the step's ends) and
    /// its origin, once `dense[3..7]` are in place.
    #[inline]
    fn dense_low(&mut self, h: f64, z_new: &[f64; N]) {
        let z = self.z;
        for i in 0..N {
            let dy = z_new[i] - z[i];
            let f_old = self.k[0][i];
            let f_new = self.k[12][i];
            self.dense[0][i] = dy;
            self.dense[1][i] = h * f_old - dy;
            self.dense[2][i] = 2.0 * dy - h * (f_new + f_old);
        }
        self.y_old = z;
        self.t_old = self.t;
        self.h_dense = h;
    }

    /// State on the last segment at time `t` (dense output, order 7).
    #[inline]
    pub fn dense_at(&self, t: f64) -> [f64; N] {
        let x = if self.h_dense > 0.0 {
            (t - self.t_old) / self.h_dense
        } else {
            0.0
        };
        self.dense_theta(x)
    }

    /// State on the last segment at the fraction `x` of its step.
    #[inline]
    fn dense_theta(&self, x: f64) -> [f64; N] {
        let x1 = 1.0 - x;
        let d = &self.dense;
        let mut out = [0.0; N];
        for i in 0..N {
            let mut y = d[6][i] * x;
            y = (y + d[5][i]) * x1;
            y = (y + d[4][i]) * x;
            y = (y + d[3][i]) * x1;
            y = (y + d[2][i]) * x;
            y = (y + d[1][i]) * x1;
            y = (y + d[0][i]) * x;
            out[i] = self.y_old[i] + y;
        }
        out
    }

    /// The guard `c·y(θ) + d` on the step in the dense output's own nested
    /// form: its value `g0` at θ = 0 and the projections `g_r = c·F_r`.
    #[inline]
    fn guard_dense(&self, c: &[f64; N], d: f64) -> (f64, [f64; 7]) {
        let mut g = [0.0; 7];
        let mut g0 = d;
        for i in 0..N {
            g0 += c[i] * self.y_old[i];
            for r in 0..7 {
                g[r] += c[i] * self.dense[r][i];
            }
        }
        (g0, g)
    }

    /// Power-basis coefficients in θ of the guard `c·y(θ) + d` on the step.
    #[inline]
    fn guard_poly(&self, c: &[f64; N], d: f64) -> [f64; 8] {
        let (g0, g) = self.guard_dense(c, d);
        power_basis(g0, &g)
    }

    /// Advance by one accepted step, cut at the first event if one occurs in it.
    /// Returns the segment on which [`Self::dense_at`] is now valid, or `None`
    /// once the end time is reached.
    pub fn step(&mut self) -> Result<Option<Segment>, IntegrateError> {
        let Some(t_stop) = self.begin_step()? else {
            return Ok(None);
        };
        loop {
            let (h, hits_stop) = self.attempt_size(t_stop)?;
            let (z_new, err) = self.rk_step(h);
            if !self.judge(h, hits_stop, &z_new, err)? {
                continue;
            }
            self.build_dense(h, &z_new);
            if let Some(seg) = self.settle(h, t_stop, z_new)? {
                return Ok(Some(seg));
            }
        }
    }

    /// Start a step: `None` at the end time; else the time the step may not
    /// pass (the end, or the model's next breakpoint).
    fn begin_step(&mut self) -> Result<Option<f64>, IntegrateError> {
        if self.t >= self.t_end {
            return Ok(None);
        }
        if self.stats.accepted >= self.opts.max_steps {
            return Err(IntegrateError::MaxSteps {
                t: self.t,
                steps: self.opts.max_steps,
            });
        }
        let mut t_stop = self.t_end;
        if let Some(b) = self.model.breakpoint_after(self.t) {
            if b > self.t && b < t_stop {
                t_stop = b;
            }
        }
        Ok(Some(t_stop))
    }

    /// Size of the next attempt, and whether it is clipped to `t_stop`.
    #[inline]
    fn attempt_size(&self, t_stop: f64) -> Result<(f64, bool), IntegrateError> {
        let mut h = self.h.min(self.opts.h_max);
        let remaining = t_stop - self.t;
        let mut hits_stop = false;
        if h >= remaining * (1.0 - 1e-12) {
            h = remaining;
            hits_stop = true;
        }
        if h < self.h_min() && !hits_stop {
            if let Some(g) = self
                .gave_up
                .checked_sub(1)
                .map(|i| self.guards.as_slice()[i as usize])
            {
                return Err(IntegrateError::EventSearch {
                    t: self.t,
                    contact: self.model.contact_name(g.contact as usize).to_string(),
                    surface: surface_name(g.kind),
                });
            }
            return Err(IntegrateError::StepUnderflow { t: self.t, h });
        }
        Ok((h, hits_stop))
    }

    /// Smallest step above round-off of the time.
    #[inline]
    fn h_min(&self) -> f64 {
        16.0 * f64::EPSILON * self.t.abs().max(1e-6)
    }

    /// Accept or reject an attempt of size `h` with error norm `err`, and
    /// choose the next size. `Ok(true)`: accepted (counted).
    #[inline]
    fn judge(
        &mut self,
        h: f64,
        hits_stop: bool,
        z_new: &[f64; N],
        err: f64,
    ) -> Result<bool, IntegrateError> {
        const SAFE: f64 = 0.9;
        const FAC_MIN: f64 = 1.0 / 3.0; // step may shrink to a third…
        const FAC_MAX: f64 = 6.0; // …or grow sixfold
        const BETA: f64 = STEP_BETA;
        if !err.is_finite() || z_new.iter().any(|x| !x.is_finite()) {
            if h < self.h_min() {
                return Err(IntegrateError::NonFinite { t: self.t });
            }
            self.stats.rejected += 1;
            self.h = h * 0.1;
            self.last_rejected = true;
            return Ok(false);
        }
        // Proportional-integral step control (Gustafsson; Hairer–Nørsett–
        // Wanner II.4 and the DOP853 code's BETA): the memory of the last
        // accepted error damps the controller's oscillation on this
        // oscillatory problem, which otherwise rejects one step in five.
        let fac11 = err.powf(1.0 / 8.0 - 0.75 * BETA);
        if err <= 1.0 {
            let fac = (fac11 / self.err_old_pow / SAFE).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
            self.err_old_pow = err.max(1e-4).powf(BETA);
            let mut h_new = h / fac;
            if self.last_rejected {
                h_new = h_new.min(h);
            }
            self.last_rejected = false;
            // After a step clipped to a stop, keep the unclipped proposal.
            self.h = if hits_stop { self.h.max(h_new) } else { h_new };
            self.stats.accepted += 1;
            return Ok(true);
        }
        self.stats.rejected += 1;
        self.last_rejected = true;
        self.h = h / (fac11 / SAFE).min(1.0 / FAC_MIN);
        Ok(false)
    }

    /// Finish an accepted step whose dense output is built: locate the
    /// earliest guard crossing, and cut the step there or take it whole.
    /// `Ok(None)`: the step must be retried shorter (the search gave up).
    fn settle(
        &mut self,
        h: f64,
        t_stop: f64,
        z_new: [f64; N],
    ) -> Result<Option<Segment>, IntegrateError> {
        // Earliest upward crossing of any guard on the step.
        let tol = (self.opts.event_tol / h).clamp(4.0 * f64::EPSILON, 1e-9);
        let mut first: Option<(f64, usize)> = None;
        let mut bounds = None;
        for gi in 0..self.guards.len() {
            let g = self.guards.as_slice()[gi];
            let found = if g.affine {
                let (g0, gr) = self.guard_dense(&g.c, g.d);
                if clearly_negative(g0, &gr) {
                    None
                } else {
                    roots::first_upcrossing(&power_basis(g0, &gr), tol)
                }
            } else {
                let b = *bounds.get_or_insert_with(|| self.step_bounds());
                match self.lipschitz_upcrossing(&g, h, &b, tol) {
                    Ok(found) => found,
                    Err(()) => {
                        // The bound is too loose on a step this long: retry at a quarter.
                        self.gave_up = gi as u32 + 1;
                        self.stats.accepted -= 1;
                        self.stats.rejected += 1;
                        self.last_rejected = true;
                        self.h = 0.25 * h;
                        return Ok(None);
                    }
                }
            };
            if let Some(theta) = found {
                if first.is_none_or(|(best, _)| theta < best) {
                    first = Some((theta, gi));
                }
            }
        }
        self.gave_up = 0;
        self.finish(h, t_stop, z_new, first).map(Some)
    }

    /// Take the accepted step to its end, or to the first event `first`
    /// (fraction of the step, guard index) and through the transition.
    fn finish(
        &mut self,
        h: f64,
        t_stop: f64,
        z_new: [f64; N],
        first: Option<(f64, usize)>,
    ) -> Result<Segment, IntegrateError> {
        let modes = self.modes;
        let mode = modes.first();
        let t0 = self.t;
        match first {
            None => {
                let t1 = if (t_stop - (t0 + h)).abs() <= 1e-12 * h {
                    t_stop
                } else {
                    t0 + h
                };
                self.note_time(t1 - t0);
                self.t = t1;
                self.z = z_new;
                self.f = self.k[12];
                Ok(Segment {
                    t0,
                    t1,
                    mode,
                    modes,
                    event: None,
                    contact: 0,
                    switched: false,
                })
            }
            Some((theta, gi)) => {
                let t1 = t0 + theta * h;
                // The state at θ itself (not at t0 + θh rounded): on the
                // non-negative side of the guard, so the transition sees it fired.
                let mut z = self.dense_theta(theta);
                let g = self.guards.as_slice()[gi];
                self.note_time(t1 - t0);
                self.t = t1;
                let (next, ev) = self.model.switch(t1, &modes, &g, &mut z);
                self.z = z;
                if let Some(ev) = ev {
                    self.note_event(ev)?;
                }
                self.note_progress(t0, t1, next == modes && ev.is_none(), &g)?;
                (self.pending_len, self.pending_next) = (0, 0);
                self.enter_mode(next, stick_broken(&g))?;
                // A step cut short by an event: restart no larger than the part used.
                self.h = self.h.min(h);
                Ok(Segment {
                    t0,
                    t1,
                    mode,
                    modes,
                    event: ev,
                    contact: g.contact as usize,
                    switched: next != modes || ev.is_some(),
                })
            }
        }
    }

    /// Count transitions that change nothing at the instant they start from
    /// (a guard re-firing where its model keeps the mode): as many in a row
    /// as chatter needs ([`SolverOptions::zeno_count`]) end the run with
    /// [`IntegrateError::Stalled`] rather than spending its step budget
    /// standing still.
    fn note_progress(
        &mut self,
        t0: f64,
        t1: f64,
        unchanged: bool,
        g: &Guard<N>,
    ) -> Result<(), IntegrateError> {
        if !(unchanged && t1 - t0 < self.opts.zeno_gap) {
            self.stall_run = 0;
            return Ok(());
        }
        self.stall_run += 1;
        if self.stall_run < self.opts.zeno_count {
            return Ok(());
        }
        Err(IntegrateError::Stalled {
            t: t1,
            contact: self.model.contact_name(g.contact as usize).to_string(),
            surface: surface_name(g.kind),
            count: self.stall_run,
        })
    }

    /// Add `dt` to the time statistics of the current modes.
    #[inline]
    fn note_time(&mut self, dt: f64) {
        self.stats.mode_time[self.modes.first().index()] += dt;
        for (i, m) in self.modes.as_slice().iter().enumerate() {
            if *m == Mode::Stick {
                self.stats.stick_time[i] += dt;
            }
        }
    }

    /// Range `[lo, hi]` of every state over the last step, and a bound of
    /// `|dy_i/dθ|`, from the Bernstein coefficients of the dense output (whose
    /// convex hull contains the polynomial).
    fn step_bounds(&self) -> StepBounds<N> {
        let mut b = StepBounds {
            lo: [0.0; N],
            hi: [0.0; N],
            rate: [0.0; N],
        };
        for i in 0..N {
            let mut e = [0.0; N];
            e[i] = 1.0;
            let p = self.guard_poly(&e, 0.0);
            let (lo, hi) = roots::range(&p);
            let mut dp = [0.0; 8];
            for k in 1..8 {
                dp[k - 1] = k as f64 * p[k];
            }
            let (dlo, dhi) = roots::range(&dp);
            // A little slack for the round-off of the conversions.
            let pad = 1e-12 * (lo.abs().max(hi.abs()));
            b.lo[i] = lo - pad;
            b.hi[i] = hi + pad;
            b.rate[i] = dlo.abs().max(dhi.abs()) * (1.0 + 1e-12);
        }
        b
    }

    /// First upward crossing on the last step of a guard that is not affine:
    /// walk from θ = 0 in jumps of `|g(θ)|/L`, where `L` bounds `|dg/dθ|` on
    /// the step ([`System::guard_slope_bound`]), so that no crossing is
    /// stepped over (none is shorter than a jump can skip, up to the event
    /// tolerance `tol` in θ); refine a bracketed crossing by bisection.
    /// `Err` if the walk needs more than [`LIPSCHITZ_EVALS`] evaluations
    /// (then the step is retried shorter).
    fn lipschitz_upcrossing(
        &self,
        g: &Guard<N>,
        h: f64,
        b: &StepBounds<N>,
        tol: f64,
    ) -> Result<Option<f64>, ()> {
        let t0 = self.t_old;
        let modes = self.modes;
        let value = |th: f64| {
            let y = self.dense_theta(th);
            self.model.guard_value(t0 + th * h, &modes, g, &y)
        };
        let l = self
            .model
            .guard_slope_bound(t0, h, &modes, g, &b.lo, &b.hi, &b.rate);
        let l = if l.is_finite() {
            l.max(f64::MIN_POSITIVE)
        } else {
            f64::INFINITY
        };
        let mut th = 0.0;
        let mut gv = value(0.0);
        for _ in 0..LIPSCHITZ_EVALS {
            let jump = (gv.abs() / l).max(tol);
            let next = (th + jump).min(1.0);
            let gn = value(next);
            if gv < 0.0 && gn >= 0.0 {
                // Bisection on [th, next] down to tol.
                let (mut a, mut c) = (th, next);
                while c - a > tol {
                    let m = 0.5 * (a + c);
                    if value(m) >= 0.0 {
                        c = m;
                    } else {
                        a = m;
                    }
                }
                return Ok(Some(c));
            }
            if next >= 1.0 {
                return Ok(None);
            }
            th = next;
            gv = gn;
        }
        Err(())
    }
}

/// Power-basis coefficients of the dense output's nested form
/// `g0 + θ(g_0 + (1−θ)(g_1 + θ(g_2 + (1−θ)(g_3 + θ(g_4 + (1−θ)(g_5 + θ g_6))))))`.
#[inline]
fn power_basis(g0: f64, g: &[f64; 7]) -> [f64; 8] {
    // From the inside out, add g_r then multiply by θ (r even) or 1 − θ (r odd).
    let mut p = [0.0; 8];
    for r in (0..7).rev() {
        p[0] += g[r];
        let mut q = [0.0; 8];
        for i in 0..7 {
            if r % 2 == 0 {
                q[i + 1] = p[i];
            } else {
                q[i] += p[i];
                q[i + 1] -= p[i];
            }
        }
        p = q;
    }
    p[0] += g0;
    p
}

/// A guard's surface, as errors name it.
fn surface_name(kind: GuardKind) -> &'static str {
    match kind {
        GuardKind::SlipZero => "v_rel = 0",
        GuardKind::StickBreakPos | GuardKind::StickBreakNeg => "stick bound",
        GuardKind::Separation => "F_n = 0",
        GuardKind::Contact => "gap = 0",
    }
}

/// The bit of [`Solver::enter_mode`]'s `broke` that guard `g` sets when it
/// fires: its contact's, if it is a stick-break guard.
fn stick_broken<const N: usize>(g: &Guard<N>) -> u64 {
    match g.kind {
        GuardKind::StickBreakPos | GuardKind::StickBreakNeg => 1 << g.contact,
        _ => 0,
    }
}

/// Whether a guard in the nested form of [`power_basis`] is negative on the
/// whole step with a margin far above round-off, so that the root search
/// would find no crossing: θ and 1 − θ lie in [0, 1], so every Bernstein
/// coefficient of `g − g0` on [0, 1] is at most `Σ|g_r|` in magnitude (the
/// Bernstein coefficients of a product are convex combinations of products
/// of the factors' coefficients). The 1e-9 relative margin covers the
/// round-off of the power and Bernstein conversions (≈ 1e-12 relative), so
/// [`roots::first_upcrossing`] would see only negative coefficients and
/// return `None`: the answer is the same, without either conversion.
#[inline]
fn clearly_negative(g0: f64, g: &[f64; 7]) -> bool {
    let s: f64 = g.iter().map(|x| x.abs()).sum();
    g0 < 0.0 && s + 1e-9 * (s - g0) < -g0
}

/// `base + Σ_{j<J} (h·row[j])·k[j]`, the stage combination of a tableau row.
/// `row` is a constant of [`tableau`] and `J` a constant, so once inlined the
/// terms are written out one by one (no loop) and the tableau's zeros vanish
/// at compile time (the test is on the constant; `h·row[j]` is never zero
/// for a non-zero entry). The state index is innermost, so each term is a
/// few vector instructions. The terms are added in the order of `j`: the
/// same sums, bit for bit, as a loop.
#[inline(always)]
fn combine<const N: usize, const J: usize>(
    k: &[[f64; N]; 16],
    base: &[f64; N],
    row: &[f64],
    h: f64,
) -> [f64; N] {
    let mut y = *base;
    macro_rules! terms {
        ($($j:literal)*) => {$(
            if $j < J && row[$j] != 0.0 {
                let a = h * row[$j];
                let kj = &k[$j];
                for i in 0..N {
                    y[i] += a * kj[i];
                }
            }
        )*};
    }
    terms!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15);
    y
}

/// Ranges of the states and of their θ-derivatives over one step.
#[derive(Debug, Clone, Copy)]
struct StepBounds<const N: usize> {
    lo: [f64; N],
    hi: [f64; N],
    rate: [f64; N],
}

/// Run summary from [`simulate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunInfo {
    /// Integrator statistics.
    pub stats: Stats,
    /// Time the run ended (the end time, or earlier if the sink stopped it).
    pub t_final: f64,
    /// Whether the sink stopped the run early.
    pub stopped_early: bool,
}

/// Integrate `model` from `(t0, z0)` to `t_end`, feeding the sink with
/// samples at `t0 + k/sample_rate` (k = 0, 1, …) and with every event.
pub fn simulate<M: System<N> + ?Sized, S: Sink<N>, const N: usize>(
    model: &M,
    t0: f64,
    z0: [f64; N],
    t_end: f64,
    sample_rate: f64,
    opts: SolverOptions,
    sink: &mut S,
) -> Result<RunInfo, IntegrateError> {
    check_rate(sample_rate)?;
    let mut solver = Solver::new(model, t0, z0, t_end, opts)?;
    let mut feed = Feed::new(t0, t_end, sample_rate);
    if let Some(info) = feed.start(&mut solver, sink) {
        return Ok(info);
    }
    while let Some(seg) = solver.step()? {
        if let Some(info) = feed.segment(&mut solver, &seg, sink) {
            return Ok(info);
        }
    }
    Ok(RunInfo {
        stats: *solver.stats(),
        t_final: solver.t(),
        stopped_early: false,
    })
}

/// A sample rate must be positive and finite.
fn check_rate(sample_rate: f64) -> Result<(), IntegrateError> {
    if !(sample_rate > 0.0 && sample_rate.is_finite()) {
        return Err(IntegrateError::BadOptions(format!(
            "sample_rate = {sample_rate} (must be > 0)"
        )));
    }
    Ok(())
}

/// What [`simulate`] feeds a sink: uniform samples and events, segment by
/// segment (shared with the ensemble, so both feed sinks identically).
struct Feed {
    t0: f64,
    t_end: f64,
    sample_rate: f64,
    /// Index of the next sample.
    k: u64,
}

impl Feed {
    fn new(t0: f64, t_end: f64, sample_rate: f64) -> Self {
        Feed {
            t0,
            t_end,
            sample_rate,
            k: 0,
        }
    }

    /// The events of the start and the first sample; `Some` if the sink stops.
    fn start<M: System<N> + ?Sized, S: Sink<N>, const N: usize>(
        &mut self,
        solver: &mut Solver<'_, M, N>,
        sink: &mut S,
    ) -> Option<RunInfo> {
        let t0 = self.t0;
        while let Some((ev, c, z, m)) = solver.take_pending_contact_event() {
            sink.contact_event(t0, ev, c, &z, &m);
        }
        self.k = 1;
        if sink.sample_modes(t0, solver.state(), &solver.modes()) == Flow::Stop {
            return Some(RunInfo {
                stats: *solver.stats(),
                t_final: t0,
                stopped_early: true,
            });
        }
        None
    }

    /// The samples on a segment and the events at its end; `Some` if the sink stops.
    fn segment<M: System<N> + ?Sized, S: Sink<N>, const N: usize>(
        &mut self,
        solver: &mut Solver<'_, M, N>,
        seg: &Segment,
        sink: &mut S,
    ) -> Option<RunInfo> {
        let (t0, t_end, sample_rate) = (self.t0, self.t_end, self.sample_rate);
        let dt = 1.0 / sample_rate;
        loop {
            // k/rate, not k·dt: exact for every representable sample time, so the
            // sample at t_end is not lost to round-off (0.03 s at 10 kHz is k = 300).
            let ts = t0 + self.k as f64 / sample_rate;
            // The last segment also takes a sample a hair past t_end (round-off).
            let limit = if seg.t1 >= t_end {
                t_end + 1e-9 * dt
            } else {
                seg.t1
            };
            if ts > limit {
                break;
            }
            let ts = ts.min(seg.t1);
            let z = solver.dense_at(ts);
            self.k += 1;
            if sink.sample_modes(ts, &z, &seg.modes) == Flow::Stop {
                return Some(RunInfo {
                    stats: *solver.stats(),
                    t_final: ts,
                    stopped_early: true,
                });
            }
        }
        if let Some(ev) = seg.event {
            sink.contact_event(seg.t1, ev, seg.contact, solver.state(), &solver.modes());
        }
        while let Some((ev, c, z, m)) = solver.take_pending_contact_event() {
            sink.contact_event(seg.t1, ev, c, &z, &m);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (no dependency): xorshift64*.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let u = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            u as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// The unrolled combinations add the same terms in the same order as the
    /// plain loop over the tableau row that skips zeros at run time.
    #[test]
    fn unrolled_combinations_equal_the_runtime_loop_bit_for_bit() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for _ in 0..200 {
            let mut k = [[0.0; 8]; 16];
            for row in k.iter_mut() {
                for x in row.iter_mut() {
                    *x = rng.next() * 10f64.powi((rng.next() * 8.0) as i32);
                }
            }
            let base: [f64; 8] = std::array::from_fn(|_| rng.next());
            let h = 1e-6 * (1.5 + rng.next());
            let plain = |row: &[f64], upto: usize, h: f64| {
                let mut y = base;
                for j in 0..upto {
                    let a = h * row[j];
                    if a != 0.0 {
                        for i in 0..8 {
                            y[i] += a * k[j][i];
                        }
                    }
                }
                y
            };
            let bits = |y: [f64; 8]| y.map(f64::to_bits);
            assert_eq!(
                bits(combine::<8, 5>(&k, &base, &A[5], h)),
                bits(plain(&A[5], 5, h))
            );
            assert_eq!(
                bits(combine::<8, 11>(&k, &base, &A[11], h)),
                bits(plain(&A[11], 11, h))
            );
            assert_eq!(
                bits(combine::<8, 15>(&k, &base, &A[15], h)),
                bits(plain(&A[15], 15, h))
            );
            assert_eq!(
                bits(combine::<8, 12>(&k, &base, &B, h)),
                bits(plain(&B, 12, h))
            );
            assert_eq!(
                bits(combine::<8, 13>(&k, &base, &E5, 1.0)),
                bits(plain(&E5, 13, 1.0))
            );
            assert_eq!(
                bits(combine::<8, 16>(&k, &base, &D[2], h)),
                bits(plain(&D[2], 16, h))
            );
        }
    }

    /// Whenever the cheap bound dismisses a guard, the guard is negative on
    /// the whole step (dense sampling) and the root search finds nothing;
    /// and the bound does dismiss the easy cases.
    #[test]
    fn dismissed_guards_have_no_crossing() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        let mut dismissed = 0;
        for n in 0..20_000 {
            let g0 = -rng.next().abs() - 1e-3;
            // Coefficients from tiny to a little more than |g0|.
            let scale = g0.abs() * 10f64.powf(-4.0 * rng.next().abs()) * 0.3;
            let g: [f64; 7] = std::array::from_fn(|_| scale * rng.next());
            if !clearly_negative(g0, &g) {
                continue;
            }
            dismissed += 1;
            let p = power_basis(g0, &g);
            assert_eq!(roots::first_upcrossing(&p, 1e-12), None, "case {n}");
            for s in 0..=200 {
                let x = s as f64 / 200.0;
                assert!(roots::horner(&p, x) < 0.0, "case {n} at θ = {x}");
            }
        }
        assert!(dismissed > 5_000, "{dismissed} dismissed");
        // Not dismissed: a guard that reaches zero within the bound.
        assert!(!clearly_negative(
            -1.0,
            &[0.5, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0]
        ));
        assert!(!clearly_negative(0.0, &[0.0; 7]));
    }
}
