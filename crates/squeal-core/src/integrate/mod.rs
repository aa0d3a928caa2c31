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
pub mod roots;
mod tableau;

use crate::model::{EventKind, Guards, Mode, Model};
use tableau::{A, B, C, D, E3, E5};

/// Tuning knobs of the integrator. Times in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Relative tolerance (default 1e-8).
    pub rtol: f64,
    /// Absolute tolerance of position states (m); `None`: the model's default.
    pub atol_pos: Option<f64>,
    /// Absolute tolerance of velocity states (m/s); `None`: the model's default.
    pub atol_vel: Option<f64>,
    /// Per-state absolute tolerances, overriding `atol_pos`/`atol_vel` for
    /// the states that have one (index = state index; at most [`MAX_STATES`]).
    pub atol_state: [Option<f64>; MAX_STATES],
    /// Largest step (s).
    pub h_max: f64,
    /// First step (s); `None`: chosen automatically (Hairer's rule).
    pub h_init: Option<f64>,
    /// Most accepted steps before the run is abandoned.
    pub max_steps: u64,
    /// Event location tolerance (s): roots are located to within
    /// `max(event_tol, 1e-9·h)`; they are in practice refined to round-off.
    pub event_tol: f64,
    /// Two events closer than this (s) count as chatter…
    pub zeno_gap: f64,
    /// …and this many such events in a row end the run with [`IntegrateError::Chatter`].
    pub zeno_count: u32,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            rtol: 1e-8,
            atol_pos: None,
            atol_vel: None,
            atol_state: [None; MAX_STATES],
            h_max: f64::INFINITY,
            h_init: None,
            max_steps: 500_000_000,
            event_tol: 1e-12,
            zeno_gap: 1e-13,
            zeno_count: 100,
        }
    }
}

/// Most mode changes in a row at one instant before it counts as chatter.
const SETTLE_LIMIT: usize = 16;

/// Most states a per-state tolerance can be given for.
pub const MAX_STATES: usize = 16;

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
    /// Time spent in each mode (s), indexed by [`Mode::index`].
    pub mode_time: [f64; 4],
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
    /// Mode on the segment.
    pub mode: Mode,
    /// The event that ended the segment, if any (reported kind).
    pub event: Option<EventKind>,
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
}

/// DOP853 stepper with event location, for one model.
pub struct Solver<'m, M: Model<N>, const N: usize> {
    model: &'m M,
    opts: SolverOptions,
    atol: [f64; N],
    t: f64,
    t_end: f64,
    z: [f64; N],
    f: [f64; N],
    mode: Mode,
    h: f64,
    last_rejected: bool,
    err_old: f64,
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
    /// Events fired while settling a mode (at most [`SETTLE_LIMIT`]), oldest first.
    pending: [(EventKind, [f64; N], Mode); SETTLE_LIMIT],
    pending_len: usize,
    pending_next: usize,
}

/// Default absolute tolerances: positions, velocities (a model-dependent scale
/// is chosen by the caller; these are MODEL.md's disc–pad values).
pub const DEFAULT_ATOL_POS: f64 = 1e-16;
/// See [`DEFAULT_ATOL_POS`].
pub const DEFAULT_ATOL_VEL: f64 = 1e-11;

impl<'m, M: Model<N>, const N: usize> Solver<'m, M, N> {
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
        let mode = model.initial_mode(t0, &z0);
        let mut s = Solver {
            model,
            opts,
            atol,
            t: t0,
            t_end,
            z: z0,
            f: [0.0; N],
            mode,
            h: 0.0,
            last_rejected: false,
            err_old: 1e-4,
            k: [[0.0; N]; 16],
            y_old: z0,
            dense: [[0.0; N]; 7],
            t_old: t0,
            h_dense: 0.0,
            guards: Guards::default(),
            stats: Stats::default(),
            last_event_t: f64::NEG_INFINITY,
            zeno_run: 0,
            pending: [(EventKind::Stick, [0.0; N], Mode::Free); SETTLE_LIMIT],
            pending_len: 0,
            pending_next: 0,
        };
        s.enter_mode(mode)?;
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
    /// Current mode.
    pub fn mode(&self) -> Mode {
        self.mode
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
        if self.pending_next < self.pending_len {
            self.pending_next += 1;
            Some(self.pending[self.pending_next - 1])
        } else {
            None
        }
    }

    #[inline]
    fn rhs(&mut self, t: f64, mode: Mode, z: &[f64; N], dz: &mut [f64; N]) {
        self.stats.rhs_evals += 1;
        self.model.rhs(t, mode, z, dz);
    }

    /// Switch to `mode` at the current state: load its guards, evaluate f,
    /// and fire at once any guard that is already on its surface and moving out
    /// (a mode that is left as soon as it is entered).
    fn enter_mode(&mut self, mut mode: Mode) -> Result<(), IntegrateError> {
        for _ in 0..SETTLE_LIMIT {
            self.mode = mode;
            self.model.guards(mode, &mut self.guards);
            let (t, z) = (self.t, self.z);
            let mut f = [0.0; N];
            self.rhs(t, mode, &z, &mut f);
            self.f = f;
            let mut fired = None;
            for g in self.guards.as_slice() {
                let val = g.eval(&self.z);
                let mut rate = 0.0;
                let mut scale = 0.0;
                for i in 0..N {
                    rate += g.c[i] * self.f[i];
                    scale += (g.c[i] * self.f[i]).abs();
                }
                // Leaving at once needs a rate clearly above round-off: at a
                // smooth stick→slip transition (μ(0+) = μ_s) the rate is zero
                // and the sign of round-off must not decide.
                if val >= 0.0 && rate > 1e-9 * scale {
                    fired = Some(g.kind);
                    break;
                }
            }
            let Some(kind) = fired else { return Ok(()) };
            let mut z = self.z;
            let (next, ev) = self.model.transition(self.t, mode, kind, &mut z);
            self.z = z;
            if let Some(ev) = ev {
                self.note_event(ev)?;
                if self.pending_len < SETTLE_LIMIT {
                    self.pending[self.pending_len] = (ev, self.z, next);
                    self.pending_len += 1;
                }
            }
            if next == mode {
                return Ok(());
            }
            mode = next;
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
        let (t, z, f0, mode) = (self.t, self.z, self.f, self.mode);
        let mut d0 = 0.0;
        let mut d1 = 0.0;
        for i in 0..N {
            let sk = self.atol[i] + self.opts.rtol * z[i].abs();
            d0 += (z[i] / sk).powi(2);
            d1 += (f0[i] / sk).powi(2);
        }
        let (d0, d1) = ((d0 / N as f64).sqrt(), (d1 / N as f64).sqrt());
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
        let d2 = (d2 / N as f64).sqrt() / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 8.0)
        };
        (100.0 * h0).min(h1).min(self.opts.h_max)
    }

    /// `base + h·Σ_j row[j]·k[j]` over the first `upto` stages, skipping the
    /// tableau's zeros; the state index is innermost so the loop vectorises.
    #[inline(always)]
    fn combine(&self, base: &[f64; N], row: &[f64], upto: usize, h: f64) -> [f64; N] {
        let mut y = *base;
        for j in 0..upto {
            let a = h * row[j];
            if a != 0.0 {
                let kj = &self.k[j];
                for i in 0..N {
                    y[i] += a * kj[i];
                }
            }
        }
        y
    }

    /// Stage `s`: its state from the earlier stages, and its slope.
    #[inline(always)]
    fn stage(&mut self, s: usize, t: f64, z: &[f64; N], mode: Mode, h: f64) {
        let y = self.combine(z, &A[s], s, h);
        let mut ks = [0.0; N];
        self.rhs(t + C[s] * h, mode, &y, &mut ks);
        self.k[s] = ks;
    }

    /// One RK step of size h from the current state; fills `k[0..13]`,
    /// returns the new state and the error norm.
    #[inline]
    fn rk_step(&mut self, h: f64) -> ([f64; N], f64) {
        let (t, z, mode) = (self.t, self.z, self.mode);
        self.k[0] = self.f;
        for s in 1..12 {
            self.stage(s, t, &z, mode, h);
        }
        let z_new = self.combine(&z, &B, 12, h);
        let mut f_new = [0.0; N];
        self.rhs(t + h, mode, &z_new, &mut f_new);
        self.k[12] = f_new;
        // Error estimate (Hairer's DOP853: 5th- and 3rd-order embedded errors).
        let zero = [0.0; N];
        let e5 = self.combine(&zero, &E5, 13, 1.0);
        let e3 = self.combine(&zero, &E3, 13, 1.0);
        let mut err5 = 0.0;
        let mut err3 = 0.0;
        for i in 0..N {
            let sk = self.atol[i] + self.opts.rtol * z[i].abs().max(z_new[i].abs());
            err5 += (e5[i] / sk).powi(2);
            err3 += (e3[i] / sk).powi(2);
        }
        let err = if err5 == 0.0 && err3 == 0.0 {
            0.0
        } else {
            h.abs() * err5 / ((err5 + 0.01 * err3) * N as f64).sqrt()
        };
        (z_new, err)
    }

    /// Dense output coefficients of the accepted step (three more stages).
    #[inline]
    fn build_dense(&mut self, h: f64, z_new: &[f64; N]) {
        let (t, z, mode) = (self.t, self.z, self.mode);
        for s in 13..16 {
            self.stage(s, t, &z, mode, h);
        }
        let zero = [0.0; N];
        for r in 0..4 {
            self.dense[3 + r] = self.combine(&zero, &D[r], 16, h);
        }
        for i in 0..N {
            let dy = z_new[i] - z[i];
            let f_old = self.k[0][i];
            let f_new = self.k[12][i];
            self.dense[0][i] = dy;
            self.dense[1][i] = h * f_old - dy;
            self.dense[2][i] = 2.0 * dy - h * (f_new + f_old);
        }
        self.y_old = z;
        self.t_old = t;
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

    /// Power-basis coefficients in θ of the guard `c·y(θ) + d` on the step.
    #[inline]
    fn guard_poly(&self, c: &[f64; N], d: f64) -> [f64; 8] {
        let mut g = [0.0; 7];
        let mut g0 = d;
        for i in 0..N {
            g0 += c[i] * self.y_old[i];
            for r in 0..7 {
                g[r] += c[i] * self.dense[r][i];
            }
        }
        // y(θ) = y_old + θ(F0 + (1−θ)(F1 + θ(F2 + (1−θ)(F3 + θ(F4 + (1−θ)(F5 + θ F6)))))):
        // from the inside out, add g_r then multiply by θ (r even) or 1 − θ (r odd).
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

    /// Advance by one accepted step, cut at the first event if one occurs in it.
    /// Returns the segment on which [`Self::dense_at`] is now valid, or `None`
    /// once the end time is reached.
    pub fn step(&mut self) -> Result<Option<Segment>, IntegrateError> {
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
        if let Some(b) = self.model.next_breakpoint(self.t) {
            if b > self.t && b < t_stop {
                t_stop = b;
            }
        }
        const SAFE: f64 = 0.9;
        const FAC_MIN: f64 = 1.0 / 3.0; // step may shrink to a third…
        const FAC_MAX: f64 = 6.0; // …or grow sixfold
        const BETA: f64 = 0.04; // PI stabilisation (0 = the elementary controller)
        let (z_new, h) = loop {
            let mut h = self.h.min(self.opts.h_max);
            let remaining = t_stop - self.t;
            let mut hits_stop = false;
            if h >= remaining * (1.0 - 1e-12) {
                h = remaining;
                hits_stop = true;
            }
            let h_min = 16.0 * f64::EPSILON * self.t.abs().max(1e-6);
            if h < h_min && !hits_stop {
                return Err(IntegrateError::StepUnderflow { t: self.t, h });
            }
            let (z_new, err) = self.rk_step(h);
            if !err.is_finite() || z_new.iter().any(|x| !x.is_finite()) {
                if h < h_min {
                    return Err(IntegrateError::NonFinite { t: self.t });
                }
                self.stats.rejected += 1;
                self.h = h * 0.1;
                self.last_rejected = true;
                continue;
            }
            // Proportional-integral step control (Gustafsson; Hairer–Nørsett–
            // Wanner II.4 and the DOP853 code's BETA): the memory of the last
            // accepted error damps the controller's oscillation on this
            // oscillatory problem, which otherwise rejects one step in five.
            let fac11 = err.powf(1.0 / 8.0 - 0.75 * BETA);
            if err <= 1.0 {
                let fac =
                    (fac11 / self.err_old.powf(BETA) / SAFE).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                self.err_old = err.max(1e-4);
                let mut h_new = h / fac;
                if self.last_rejected {
                    h_new = h_new.min(h);
                }
                self.last_rejected = false;
                // After a step clipped to a stop, keep the unclipped proposal.
                self.h = if hits_stop { self.h.max(h_new) } else { h_new };
                break (z_new, h);
            }
            self.stats.rejected += 1;
            self.last_rejected = true;
            self.h = h / (fac11 / SAFE).min(1.0 / FAC_MIN);
        };
        self.stats.accepted += 1;
        self.build_dense(h, &z_new);

        // Earliest upward crossing of any guard on the step.
        let tol = (self.opts.event_tol / h).clamp(4.0 * f64::EPSILON, 1e-9);
        let mut first: Option<(f64, usize)> = None;
        for (gi, g) in self.guards.as_slice().iter().enumerate() {
            let p = self.guard_poly(&g.c, g.d);
            if let Some(theta) = roots::first_upcrossing(&p, tol) {
                if first.is_none_or(|(best, _)| theta < best) {
                    first = Some((theta, gi));
                }
            }
        }
        let mode = self.mode;
        let t0 = self.t;
        match first {
            None => {
                let t1 = if (t_stop - (t0 + h)).abs() <= 1e-12 * h {
                    t_stop
                } else {
                    t0 + h
                };
                self.stats.mode_time[mode.index()] += t1 - t0;
                self.t = t1;
                self.z = z_new;
                self.f = self.k[12];
                Ok(Some(Segment {
                    t0,
                    t1,
                    mode,
                    event: None,
                    switched: false,
                }))
            }
            Some((theta, gi)) => {
                let t1 = t0 + theta * h;
                // The state at θ itself (not at t0 + θh rounded): on the
                // non-negative side of the guard, so the transition sees it fired.
                let mut z = self.dense_theta(theta);
                let kind = self.guards.as_slice()[gi].kind;
                self.stats.mode_time[mode.index()] += t1 - t0;
                self.t = t1;
                let (next, ev) = self.model.transition(t1, mode, kind, &mut z);
                self.z = z;
                if let Some(ev) = ev {
                    self.note_event(ev)?;
                }
                (self.pending_len, self.pending_next) = (0, 0);
                self.enter_mode(next)?;
                // A step cut short by an event: restart no larger than the part used.
                self.h = self.h.min(h);
                Ok(Some(Segment {
                    t0,
                    t1,
                    mode,
                    event: ev,
                    switched: next != mode || ev.is_some(),
                }))
            }
        }
    }
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
pub fn simulate<M: Model<N>, S: Sink<N>, const N: usize>(
    model: &M,
    t0: f64,
    z0: [f64; N],
    t_end: f64,
    sample_rate: f64,
    opts: SolverOptions,
    sink: &mut S,
) -> Result<RunInfo, IntegrateError> {
    if !(sample_rate > 0.0 && sample_rate.is_finite()) {
        return Err(IntegrateError::BadOptions(format!(
            "sample_rate = {sample_rate} (must be > 0)"
        )));
    }
    let mut solver = Solver::new(model, t0, z0, t_end, opts)?;
    while let Some((ev, z, m)) = solver.take_pending_event() {
        sink.event(t0, ev, &z, m);
    }
    let dt = 1.0 / sample_rate;
    let mut k: u64 = 0;
    if sink.sample(t0, solver.state(), solver.mode()) == Flow::Stop {
        return Ok(RunInfo {
            stats: *solver.stats(),
            t_final: t0,
            stopped_early: true,
        });
    }
    k += 1;
    while let Some(seg) = solver.step()? {
        loop {
            // k/rate, not k·dt: exact for every representable sample time, so the
            // sample at t_end is not lost to round-off (0.03 s at 10 kHz is k = 300).
            let ts = t0 + k as f64 / sample_rate;
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
            k += 1;
            if sink.sample(ts, &z, seg.mode) == Flow::Stop {
                return Ok(RunInfo {
                    stats: *solver.stats(),
                    t_final: ts,
                    stopped_early: true,
                });
            }
        }
        if let Some(ev) = seg.event {
            sink.event(seg.t1, ev, solver.state(), solver.mode());
        }
        while let Some((ev, z, m)) = solver.take_pending_event() {
            sink.event(seg.t1, ev, &z, m);
        }
    }
    Ok(RunInfo {
        stats: *solver.stats(),
        t_final: solver.t(),
        stopped_early: false,
    })
}
