//! Periodic orbits (limit cycles) of the non-smooth system: settling by
//! simulation, Newton shooting on a Poincaré section, and Floquet multipliers
//! from the monodromy matrix with a saltation matrix at every event.
//!
//! # The monodromy matrix
//!
//! Along a segment of the flow in a fixed mode the variational equation
//! `Φ̇ = J(z(t)) Φ` (`J = ∂f/∂z` of that mode's field, in a sticking mode the
//! reduced, constrained dynamics) is integrated on the integrator's own dense
//! output with the fourth-order Magnus method
//! `Ω = h/2 (J₁ + J₂) + √3 h²/12 [J₂, J₁]`, `Φ ← exp(Ω) Φ`, with `J` at the two
//! Gauss points (exact when `J` is constant on the segment, as in every
//! piecewise-linear model). At an event where guard `g` fires, taking the
//! state `z⁻` (field `f⁻`) to `z⁺ = R(z⁻)` (field `f⁺`), the perturbation jumps
//! by the saltation matrix (Leine & Nijmeijer 2004, Eq. 7.40; Aizerman &
//! Gantmacher 1958)
//!
//! ```text
//! S = P + (f⁺ − P f⁻) ∇gᵀ / (∇g · f⁻),     P = ∂R/∂z
//! ```
//!
//! where `P` projects onto the sticking constraint when the event is a stick
//! (that is where a sticking phase collapses a direction: a zero multiplier).
//!
//! # Shooting
//!
//! The unknowns are the state `z₀` on the section `z_k = c` and the period
//! `T`; Newton's method solves `φ_T(z₀) − z₀ = 0`, `z₀,k − c = 0` with the
//! bordered matrix `[[M − I, f(φ_T z₀)], [e_kᵀ, 0]]`.
//!
//! # Multipliers
//!
//! The non-trivial multipliers are the eigenvalues of the Poincaré map's
//! Jacobian `(I − f e_kᵀ / f_k) M` (on the section, whose extra eigenvalue 0
//! stands for the flow direction), so that slowly decaying modes (multipliers
//! `exp(σT)` a hair below 1) are never confused with the trivial multiplier;
//! the trivial one is reported separately as the Rayleigh quotient
//! `fᵀ M f / fᵀ f` (1 up to the shooting residual).
//!
//! All matrices are formed in scaled coordinates (positions by the orbit's
//! position amplitude, velocities by its velocity amplitude), so that the
//! eigenvalues do not suffer from the state's units (MODEL.md §8).

pub mod continuation;

use crate::integrate::{IntegrateError, Solver, SolverOptions};
use crate::model::{EventKind, Guards, Modes, System};
use nalgebra::DMatrix;

/// A Poincaré section: an upward crossing of `z[index] = level`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// The state component (a velocity, by default).
    pub index: usize,
    /// The level it crosses upwards.
    pub level: f64,
}

/// Settings of [`find_cycle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleOptions {
    /// Integrator settings (the same for settling, shooting and monodromy).
    pub solver: SolverOptions,
    /// The section; `None` chooses an upward zero of a velocity automatically.
    pub section: Option<Section>,
    /// Most integrator steps spent settling onto the cycle.
    pub settle_steps: u64,
    /// Most simulated time spent settling (s).
    pub settle_time: f64,
    /// Relative tolerance of the settling run (at least the solver's own):
    /// settling only needs to come close, Newton's method does the rest.
    pub settle_rtol: f64,
    /// Two returns to the section count as the same point when they differ
    /// by less than this, relative to the orbit's amplitude.
    pub settle_tol: f64,
    /// Most returns compared when looking for a period (period-m orbits).
    pub max_returns: usize,
    /// Shooting converges when the scaled residual is below this.
    pub newton_tol: f64,
    /// Most Newton iterations.
    pub newton_iterations: usize,
    /// Magnus steps per integrator step for the variational equations.
    pub magnus_substeps: usize,
}

impl Default for CycleOptions {
    fn default() -> Self {
        CycleOptions {
            solver: SolverOptions {
                rtol: 1e-10,
                ..SolverOptions::default()
            },
            section: None,
            settle_steps: 20_000_000,
            settle_time: 1000.0,
            settle_rtol: 1e-8,
            settle_tol: 1e-2,
            max_returns: 8,
            newton_tol: 1e-8,
            newton_iterations: 30,
            magnus_substeps: 2,
        }
    }
}

/// Why no cycle was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CycleError {
    /// The integrator failed.
    #[error(transparent)]
    Integrate(#[from] IntegrateError),
    /// Settling did not reach a periodic orbit within the budget.
    #[error("no periodic orbit found by t = {t:.6} s ({steps} steps): {cause}")]
    NotSettled {
        /// Simulated time reached.
        t: f64,
        /// Integrator steps taken.
        steps: u64,
        /// What was seen.
        cause: String,
    },
    /// Newton's method did not converge.
    #[error("shooting did not converge: {0}")]
    Shooting(String),
    /// Bad settings.
    #[error("{0}")]
    Bad(String),
    /// The oscillation found is too small to be a cycle of the branch.
    #[error("no cycle: {0}")]
    Vanishing(String),
}

/// One Floquet multiplier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Multiplier {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
    /// Whether this is the trivial multiplier (1, along the flow).
    pub trivial: bool,
}

impl Multiplier {
    /// Modulus.
    pub fn abs(&self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// A located periodic orbit.
#[derive(Debug, Clone)]
pub struct Cycle<const N: usize> {
    /// Period (s).
    pub period: f64,
    /// The state on the section where the orbit starts.
    pub z0: [f64; N],
    /// The section.
    pub section: Section,
    /// The monodromy matrix `∂φ_T/∂z₀` (unscaled, row-major; a padded
    /// model's idle rows and columns are zero, see `real_indices`).
    pub monodromy: [[f64; N]; N],
    /// All multipliers (one per state; a padded model's real states only)
    /// sorted by modulus, descending; one is trivial.
    pub multipliers: Vec<Multiplier>,
    /// Whether every non-trivial multiplier lies inside the unit circle.
    pub stable: bool,
    /// Largest modulus of the non-trivial multipliers.
    pub max_multiplier: f64,
    /// Scaled shooting residual `|φ_T(z₀) − z₀|` at the end.
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// Events on one period, counted by kind (index of [`EventKind::ALL`]).
    pub events_per_period: [u64; 5],
    /// Half peak-to-peak of every state over one period.
    pub amplitude: [f64; N],
    /// Simulated time spent settling (s).
    pub settle_time: f64,
}

/// One period sampled densely: times, states and modes; events with their kind.
#[derive(Debug, Clone, Default)]
pub struct Orbit<const N: usize> {
    /// Sample times from 0 to the period.
    pub t: Vec<f64>,
    /// States.
    pub z: Vec<[f64; N]>,
    /// Modes at each sample (for an event row: after it).
    pub modes: Vec<Modes>,
    /// The event at the sample, if the row is an event.
    pub event: Vec<Option<(EventKind, usize)>>,
}

/// Largest `h·‖ΔJ‖` (scaled, ∞-norm) of one Magnus step.
const MAGNUS_VARIATION: f64 = 1e-4;

/// What integrating one period with the variational equations gives.
struct Period<const N: usize> {
    z_end: [f64; N],
    /// Scaled monodromy `D⁻¹ M D`.
    m: DMatrix<f64>,
    events: [u64; 5],
    lo: [f64; N],
    hi: [f64; N],
}

/// Scale of each state: positions by the largest position amplitude,
/// velocities by the largest velocity amplitude (floored at the tolerances).
fn block_scales<const N: usize>(amp: &[f64; N], atol: &SolverOptions) -> [f64; N] {
    let n = N / 2;
    let pos = amp[..n].iter().fold(0.0f64, |m, a| m.max(*a));
    let vel = amp[n..].iter().fold(0.0f64, |m, a| m.max(*a));
    let pos = pos.max(atol.atol_pos.unwrap_or(crate::integrate::DEFAULT_ATOL_POS) * 1e3);
    let vel = vel.max(atol.atol_vel.unwrap_or(crate::integrate::DEFAULT_ATOL_VEL) * 1e3);
    let mut s = [0.0; N];
    for (i, si) in s.iter_mut().enumerate() {
        *si = if i < n { pos } else { vel };
    }
    s
}

/// Jacobian `∂f/∂z` of the field of `modes` at `(t, z)` by central
/// differences, in scaled coordinates `D⁻¹ J D` (step `1e-6` of each scale).
/// Only the states `idx` (rows and columns; see [`real_indices`]).
fn scaled_jacobian<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t: f64,
    modes: &Modes,
    z: &[f64; N],
    s: &[f64; N],
    idx: &[usize],
    out: &mut DMatrix<f64>,
) {
    let mut fp = [0.0; N];
    let mut fm = [0.0; N];
    for (c, &j) in idx.iter().enumerate() {
        let h = 1e-6 * s[j];
        let mut zp = *z;
        zp[j] += h;
        let mut zm = *z;
        zm[j] -= h;
        sys.field(t, modes, &zp, &mut fp);
        sys.field(t, modes, &zm, &mut fm);
        let dz = zp[j] - zm[j];
        for (r, &i) in idx.iter().enumerate() {
            out[(r, c)] = (fp[i] - fm[i]) / dz * s[j] / s[i];
        }
    }
}

/// The states a Floquet analysis covers: all `N`, or the real states of a
/// model padded with idle dofs ([`crate::model::lumped::padding`], which
/// reports its real state count as [`System::norm_states`]). The idle
/// states are coupled to nothing and stay exactly at rest, so the
/// monodromy matrix is block-diagonal: its real block is the real model's
/// monodromy, and the idle block (a rotation at 1 rad/s) carries nothing
/// of the orbit. It is left out of the variational equations, and the
/// period matrix holds zeros there (an idle perturbation that dies at
/// once: `M − I = −I` keeps the shooting matrix regular).
pub(crate) fn real_indices<S: System<N> + ?Sized, const N: usize>(sys: &S) -> Vec<usize> {
    let r = sys.norm_states();
    if r >= N || r % 2 != 0 {
        (0..N).collect()
    } else {
        crate::model::lumped::real_states::<N>(r / 2).collect()
    }
}

/// The guard of `modes` that `z` lies on (smallest scaled `|g|`).
fn guard_on<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t: f64,
    modes: &Modes,
    z: &[f64; N],
    s: &[f64; N],
) -> Option<crate::model::Guard<N>> {
    let mut guards = Guards::default();
    sys.mode_guards(modes, &mut guards);
    let mut best: Option<(f64, crate::model::Guard<N>)> = None;
    for g in guards.as_slice() {
        let c = sys.guard_gradient(t, modes, g, z);
        let norm: f64 = (0..N).map(|i| (c[i] * s[i]).abs()).sum();
        if norm == 0.0 {
            continue;
        }
        let v = (sys.guard_value(t, modes, g, z) / norm).abs();
        if best.is_none_or(|(b, _)| v < b) {
            best = Some((v, *g));
        }
    }
    best.map(|(_, g)| g)
}

/// Saltation matrix (scaled) at an event from `modes_m` at `z_m` to
/// `modes_p` at `z_p` (see the module documentation).
#[allow(clippy::too_many_arguments)]
fn saltation<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t: f64,
    modes_m: &Modes,
    z_m: &[f64; N],
    modes_p: &Modes,
    z_p: &[f64; N],
    s: &[f64; N],
    idx: &[usize],
) -> DMatrix<f64> {
    let r = idx.len();
    let Some(g) = guard_on(sys, t, modes_m, z_m, s) else {
        return DMatrix::identity(r, r);
    };
    // P = ∂R/∂z by central differences of the reset map (exact for the
    // affine projections of the models here).
    let mut p = DMatrix::<f64>::identity(r, r);
    for (c, &j) in idx.iter().enumerate() {
        let h = 1e-6 * s[j];
        let mut zp = *z_m;
        zp[j] += h;
        let mut zm = *z_m;
        zm[j] -= h;
        sys.switch(t, modes_m, &g, &mut zp);
        sys.switch(t, modes_m, &g, &mut zm);
        for (row, &i) in idx.iter().enumerate() {
            p[(row, c)] = (zp[i] - zm[i]) / (2.0 * h) * s[j] / s[i];
        }
    }
    let mut fm = [0.0; N];
    let mut fp = [0.0; N];
    sys.field(t, modes_m, z_m, &mut fm);
    sys.field(t, modes_p, z_p, &mut fp);
    let grad = sys.guard_gradient(t, modes_m, &g, z_m);
    let fm_s = DMatrix::from_fn(r, 1, |i, _| fm[idx[i]] / s[idx[i]]);
    let fp_s = DMatrix::from_fn(r, 1, |i, _| fp[idx[i]] / s[idx[i]]);
    let g_s = DMatrix::from_fn(1, r, |_, j| grad[idx[j]] * s[idx[j]]);
    let rate = (&g_s * &fm_s)[(0, 0)];
    if rate == 0.0 || !rate.is_finite() {
        return p;
    }
    let jump = &fp_s - &p * &fm_s;
    &p + jump * g_s / rate
}

/// The time from which the model is autonomous (after its last breakpoint,
/// e.g. the end of a load ramp): every period is integrated from there.
/// A model forced at one frequency `f` is periodic, not autonomous: the
/// time is then the first whole forcing period `k/f` after the last
/// breakpoint, so that its harmonic force is `amplitude·cos 2πf(t − t_a)`.
pub fn autonomous_from<S: System<N> + ?Sized, const N: usize>(sys: &S) -> f64 {
    let mut t = 0.0;
    for _ in 0..1000 {
        match sys.breakpoint_after(t) {
            Some(b) if b > t => t = b,
            _ => break,
        }
    }
    if let [f] = sys.forcing_hz().as_slice() {
        t = (t * f).ceil() / f;
    }
    t
}

/// The refusal of shooting for a forced model (its period is the
/// forcing's, and its flow has no trivial multiplier).
pub fn refuse_forced<S: System<N> + ?Sized, const N: usize>(sys: &S) -> Result<(), CycleError> {
    let f = sys.forcing_hz();
    if f.is_empty() {
        return Ok(());
    }
    Err(CycleError::Bad(format!(
        "the model is forced (a harmonic force at {} Hz): shooting here finds self-excited orbits of an autonomous model; its periodic response is computed by `squeal hb`",
        f.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(", ")
    )))
}

/// One period from `z0` with the variational equations, in the block scales
/// of a first plain period's amplitudes; the scales and the scaled defect
/// `|φ_T(z₀) − z₀|`.
fn scaled_period<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z0: &[f64; N],
    period: f64,
    opts: &CycleOptions,
) -> Result<(Period<N>, [f64; N], f64), CycleError> {
    if !(period > 0.0 && period.is_finite()) {
        return Err(CycleError::Bad(format!("period {period}")));
    }
    let first = period_flow(sys, z0, period, &[1.0; N], opts, false, None)?;
    let mut amp = [0.0; N];
    for i in 0..N {
        amp[i] = 0.5 * (first.hi[i] - first.lo[i]);
    }
    let s = block_scales(&amp, &opts.solver);
    let p = period_flow(sys, z0, period, &s, opts, true, None)?;
    let defect = (0..N)
        .map(|i| ((p.z_end[i] - z0[i]) / s[i]).abs())
        .fold(0.0, f64::max);
    Ok((p, s, defect))
}

/// The Floquet multipliers of a periodic response of a forced model: the
/// eigenvalues of the monodromy over one forcing period `period` from `z0`
/// at [`autonomous_from`] (variational equations and saltation matrices, as
/// for [`floquet_from`]); none is trivial. Returns the multipliers (largest
/// first), the scaled defect `|φ_T(z₀) − z₀|` and the events per period.
pub fn forced_floquet<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z0: &[f64; N],
    period: f64,
    opts: &CycleOptions,
) -> Result<(Vec<Multiplier>, f64, [u64; 5]), CycleError> {
    let (p, _, defect) = scaled_period(sys, z0, period, opts)?;
    let mut list = eigen_multipliers(&p.m);
    sort_multipliers(&mut list);
    Ok((list, defect, p.events))
}

/// Integrate one period `T` from `z0` with the variational equations.
fn period_flow<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z0: &[f64; N],
    period: f64,
    s: &[f64; N],
    opts: &CycleOptions,
    variational: bool,
    mut orbit: Option<&mut Orbit<N>>,
) -> Result<Period<N>, CycleError> {
    let t_a = autonomous_from(sys);
    let mut solver = Solver::new(sys, t_a, *z0, t_a + period, opts.solver)?;
    let idx = real_indices(sys);
    let r = idx.len();
    let mut phi = DMatrix::<f64>::identity(r, r);
    let mut j1 = DMatrix::<f64>::zeros(r, r);
    let mut j2 = DMatrix::<f64>::zeros(r, r);
    let mut events = [0u64; 5];
    let mut last_switch: Option<(f64, [u64; 5], Modes)> = None;
    let mut lo = *z0;
    let mut hi = *z0;
    let g = 3f64.sqrt() / 6.0;
    let subs = opts.magnus_substeps.max(1);
    if let Some(o) = orbit.as_deref_mut() {
        o.t.push(0.0);
        o.z.push(*z0);
        o.modes.push(solver.modes());
        o.event.push(None);
    }
    while let Some(seg) = solver.step()? {
        // Magnus steps short enough that the variation of J over one,
        // h·‖J(t₁) − J(t₀)‖ (scaled), stays below MAGNUS_VARIATION: the
        // method is exact for constant J, and its error grows with J's change.
        let len = if variational { seg.t1 - seg.t0 } else { 0.0 };
        let mut subs = subs;
        if len > 0.0 {
            scaled_jacobian(
                sys,
                seg.t0,
                &seg.modes,
                &solver.dense_at(seg.t0),
                s,
                &idx,
                &mut j1,
            );
            scaled_jacobian(
                sys,
                seg.t1,
                &seg.modes,
                &solver.dense_at(seg.t1),
                s,
                &idx,
                &mut j2,
            );
            let var = (0..r)
                .map(|i| (0..r).map(|j| (j2[(i, j)] - j1[(i, j)]).abs()).sum::<f64>())
                .fold(0.0, f64::max);
            // J's change over a substep is var/subs, times its length len/subs.
            let need = (len * var / MAGNUS_VARIATION).sqrt().ceil();
            if need.is_finite() && need > subs as f64 {
                subs = (need as usize).min(4096);
            }
        }
        let h = len / subs as f64;
        if h > 0.0 {
            for k in 0..subs {
                let a = seg.t0 + k as f64 * h;
                let (ta, tb) = (a + (0.5 - g) * h, a + (0.5 + g) * h);
                scaled_jacobian(sys, ta, &seg.modes, &solver.dense_at(ta), s, &idx, &mut j1);
                scaled_jacobian(sys, tb, &seg.modes, &solver.dense_at(tb), s, &idx, &mut j2);
                let omega = (&j1 + &j2) * (0.5 * h)
                    + (&j2 * &j1 - &j1 * &j2) * (3f64.sqrt() / 12.0 * h * h);
                phi = omega.exp() * phi;
            }
        }
        // Extremes over the segment (dense output at a few points).
        const PTS: usize = 8;
        for k in 1..=PTS {
            let t = seg.t0 + (seg.t1 - seg.t0) * k as f64 / PTS as f64;
            let z = solver.dense_at(t);
            for i in 0..N {
                lo[i] = lo[i].min(z[i]);
                hi[i] = hi[i].max(z[i]);
            }
            if let Some(o) = orbit.as_deref_mut() {
                if k < PTS || !seg.switched {
                    o.t.push(t - t_a);
                    o.z.push(z);
                    o.modes.push(seg.modes);
                    o.event.push(None);
                }
            }
        }
        if seg.switched {
            let z_m = solver.dense_at(seg.t1);
            let z_p = *solver.state();
            let modes_p = solver.modes();
            if variational {
                let sm = saltation(sys, seg.t1, &seg.modes, &z_m, &modes_p, &z_p, s, &idx);
                phi = sm * phi;
            }
            if let Some(o) = orbit.as_deref_mut() {
                o.t.push(seg.t1 - t_a);
                o.z.push(z_m);
                o.modes.push(seg.modes);
                o.event.push(None);
                o.t.push(seg.t1 - t_a);
                o.z.push(z_p);
                o.modes.push(modes_p);
                o.event.push(seg.event.map(|e| (e, seg.contact)));
            }
            // This switch's events: the located one and those fired while
            // the mode settled after it.
            let mut fired = [0u64; 5];
            if let Some(ev) = seg.event {
                fired[ev.index()] += 1;
            }
            while let Some((ev, c, _, _)) = solver.take_pending_contact_event() {
                fired[ev.index()] += 1;
                if let Some(o) = orbit.as_deref_mut() {
                    if let Some(last) = o.event.last_mut() {
                        if last.is_none() {
                            *last = Some((ev, c));
                        }
                    }
                }
            }
            // Counted unless they change no mode, or undo the switch just
            // before at the same instant (a zero-duration excursion, e.g. a
            // slip and an immediate re-stick at breakaway): the structure of
            // the orbit is counted, not the integrator's path through it.
            let undo = last_switch
                .filter(|(t, _, before)| (seg.t1 - t).abs() <= 1e-9 * period && *before == modes_p);
            if let Some((_, prev, _)) = undo {
                for k in 0..5 {
                    events[k] = events[k].saturating_sub(prev[k]);
                }
                last_switch = None;
            } else if modes_p != seg.modes {
                for k in 0..5 {
                    events[k] += fired[k];
                }
                last_switch = Some((seg.t1, fired, seg.modes));
            }
        }
    }
    if phi.iter().any(|x| !x.is_finite()) {
        return Err(CycleError::Shooting(
            "the monodromy matrix is not finite".into(),
        ));
    }
    // The real block in place; an idle state's row and column stay zero.
    let m = if r == N {
        phi
    } else {
        let mut m = DMatrix::<f64>::zeros(N, N);
        for (c, &j) in idx.iter().enumerate() {
            for (row, &i) in idx.iter().enumerate() {
                m[(i, j)] = phi[(row, c)];
            }
        }
        m
    };
    Ok(Period {
        z_end: *solver.state(),
        m,
        events,
        lo,
        hi,
    })
}

/// One return to the section while settling.
#[derive(Clone, Copy)]
struct Return<const N: usize> {
    t: f64,
    z: [f64; N],
    lo: [f64; N],
    hi: [f64; N],
}

/// Settle onto a cycle by simulation from `(t0, z0)`: returns the section,
/// the state on it and a first guess of the period.
pub fn settle<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t0: f64,
    z0: [f64; N],
    opts: &CycleOptions,
) -> Result<(Section, [f64; N], f64, f64), CycleError> {
    refuse_forced(sys)?;
    let n = N / 2;
    let t_end = t0 + opts.settle_time;
    let mut sopts = opts.solver;
    sopts.max_steps = opts.settle_steps;
    sopts.rtol = sopts.rtol.max(opts.settle_rtol);
    let mut solver = Solver::new(sys, t0, z0, t_end, sopts)?;
    let candidates: Vec<Section> = match opts.section {
        Some(s) => vec![s],
        None => (n..N).map(|index| Section { index, level: 0.0 }).collect(),
    };
    let mut lo = vec![z0; candidates.len()];
    let mut hi = vec![z0; candidates.len()];
    let mut returns: Vec<Vec<Return<N>>> = vec![Vec::new(); candidates.len()];
    let keep = 2 * opts.max_returns + 2;
    let mut prev = z0;
    loop {
        let seg = match solver.step() {
            Ok(Some(seg)) => seg,
            Ok(None) => {
                return Err(CycleError::NotSettled {
                    t: solver.t(),
                    steps: solver.stats().accepted,
                    cause: not_settled_cause(&returns),
                })
            }
            Err(IntegrateError::MaxSteps { t, steps }) => {
                return Err(CycleError::NotSettled {
                    t,
                    steps,
                    cause: not_settled_cause(&returns),
                })
            }
            Err(e) => return Err(e.into()),
        };
        let z1 = solver.dense_at(seg.t1);
        for (c, sec) in candidates.iter().enumerate() {
            for i in 0..N {
                lo[c][i] = lo[c][i].min(z1[i]);
                hi[c][i] = hi[c][i].max(z1[i]);
            }
            let (g0, g1) = (prev[sec.index] - sec.level, z1[sec.index] - sec.level);
            if !(g0 < 0.0 && g1 >= 0.0) {
                continue;
            }
            // The crossing by linear interpolation (enough to compare returns
            // to settle_tol); refined by bisection on the dense output once a
            // period is found.
            let th = g0 / (g0 - g1);
            let tc = seg.t0 + th * (seg.t1 - seg.t0);
            let z = solver.dense_at(tc);
            let r = Return {
                t: tc,
                z,
                lo: lo[c],
                hi: hi[c],
            };
            lo[c] = z;
            hi[c] = z;
            let list = &mut returns[c];
            list.push(r);
            if list.len() > keep {
                list.remove(0);
            }
            if let Some(found) = periodic(list, opts, n, sec.index) {
                let (_, z_start) = upward_crossing(&solver, seg.t0, seg.t1, *sec);
                return Ok((*sec, z_start, found, solver.t() - t0));
            }
        }
        prev = if seg.switched { *solver.state() } else { z1 };
    }
}

/// The upward crossing of `section` within the last step `[t0, t1]` of
/// `solver` (the state is below the level at `t0`, at or above it at `t1`),
/// by bisection on the dense output to the last bit of `t`: the time and the
/// state there, its section component set to the level exactly.
fn upward_crossing<S: System<N> + ?Sized, const N: usize>(
    solver: &Solver<'_, S, N>,
    t0: f64,
    t1: f64,
    section: Section,
) -> (f64, [f64; N]) {
    let (mut a, mut b) = (t0, t1);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if solver.dense_at(m)[section.index] - section.level < 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    let mut z = solver.dense_at(b);
    z[section.index] = section.level;
    (b, z)
}

fn not_settled_cause<const N: usize>(returns: &[Vec<Return<N>>]) -> String {
    if returns.iter().all(|r| r.len() < 2) {
        "the motion does not oscillate (it may settle on steady sliding or stick)".into()
    } else {
        "the returns to the section never repeated (the oscillation may be dying out onto steady sliding, still growing, quasi-periodic or chaotic)".into()
    }
}

/// If the last return repeats the one `m` returns earlier (m = 1, 2, …), the period.
fn periodic<const N: usize>(
    list: &[Return<N>],
    opts: &CycleOptions,
    n: usize,
    index: usize,
) -> Option<f64> {
    let last = list.len() - 1;
    for m in 1..=opts.max_returns {
        // Need the amplitude over the m returns before it too.
        if last < 2 * m {
            break;
        }
        let mut amp = [0.0; N];
        for r in &list[last + 1 - 2 * m..=last] {
            for i in 0..N {
                amp[i] = f64::max(amp[i], 0.5 * (r.hi[i] - r.lo[i]));
            }
        }
        // The oscillation must neither decay nor grow between the two halves
        // of the window, and stand clear of the integrator's tolerance.
        let mut amp1 = [0.0f64; N];
        let mut amp2 = [0.0f64; N];
        for (k, r) in list[last + 1 - 2 * m..=last].iter().enumerate() {
            let a = if k < m { &mut amp1 } else { &mut amp2 };
            for i in 0..N {
                a[i] = a[i].max(0.5 * (r.hi[i] - r.lo[i]));
            }
        }
        let (v1, v2) = (
            amp1[n..].iter().fold(0.0f64, |a, b| a.max(*b)),
            amp2[n..].iter().fold(0.0f64, |a, b| a.max(*b)),
        );
        let floor = 1e4
            * opts
                .solver
                .atol_vel
                .unwrap_or(crate::integrate::DEFAULT_ATOL_VEL);
        if v2 <= floor || (v2 - v1).abs() > opts.settle_tol * v2 {
            continue;
        }
        let s = block_scales(&amp, &opts.solver);
        // The section's velocity must carry the largest share of the motion
        // (a small velocity crosses its level several times a period).
        let vel_max = amp[n..].iter().fold(0.0f64, |a, b| a.max(*b));
        if index >= n && amp[index] < 0.5 * vel_max {
            return None;
        }
        let err = (0..N)
            .map(|i| ((list[last].z[i] - list[last - m].z[i]) / s[i]).abs())
            .fold(0.0, f64::max);
        let err2 = (0..N)
            .map(|i| ((list[last - m].z[i] - list[last - 2 * m].z[i]) / s[i]).abs())
            .fold(0.0, f64::max);
        if err <= opts.settle_tol && err2 <= 10.0 * opts.settle_tol {
            return Some(list[last].t - list[last - m].t);
        }
    }
    None
}

/// Find the periodic orbit reached from `(t0, z0)`: settle, shoot, and
/// compute its Floquet multipliers.
pub fn find_cycle<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t0: f64,
    z0: [f64; N],
    opts: &CycleOptions,
) -> Result<Cycle<N>, CycleError> {
    refuse_forced(sys)?;
    // What the motion settles on is stable: an unstable periodic orbit met
    // on the way (the brake's normal vibration while the pad's mode still
    // grows, say) is left by simulating on until its instability has grown
    // a thousandfold, then settling again (at most four times).
    let (mut t, mut z) = (t0, z0);
    let mut spent = 0.0;
    let mut attempt = 0;
    let mut collapses = 0;
    let mut local = *opts;
    loop {
        // Shooting that fails from a settled state (a slowly changing
        // motion that only looked periodic) settles longer, to a tighter match.
        let (c, settled, z_settled) = match settle_and_shoot(sys, t, z, &local) {
            Err(CycleError::Shooting(_)) if attempt < 3 && local.settle_tol > 1e-6 => {
                attempt += 1;
                local.settle_tol *= 0.1;
                continue;
            }
            Err(CycleError::Shooting(why)) => {
                return Err(CycleError::Shooting(slow_growth_hint(
                    sys,
                    why,
                    local.settle_tol,
                )))
            }
            other => other?,
        };
        spent += settled;
        let collapsed = c.amplitude.iter().all(|&a| a == 0.0);
        // An oscillation that grows by less than settle_tol a period looks
        // periodic to settling; shooting from it then falls onto steady
        // sliding. Where steady sliding is unstable (so the oscillation
        // cannot be dying onto it), settle on from where it stopped, to a
        // ten times tighter match (at most three times), until it reaches
        // its limit cycle.
        if collapsed
            && collapses < 3
            && local.settle_tol > 1e-6
            && spent < opts.settle_time
            && steady_growth(sys).is_some()
        {
            collapses += 1;
            local.settle_tol *= 0.1;
            (t, z) = (t + settled, z_settled);
            continue;
        }
        attempt += 1;
        if collapsed
            || !c
                .multipliers
                .iter()
                .all(|m| m.re.is_finite() && m.im.is_finite())
        {
            return Err(CycleError::Vanishing(
                "shooting converged onto steady sliding itself (zero amplitude): the \
                 oscillation dies out, there is no periodic orbit to follow"
                    .into(),
            ));
        }
        if let Some(sigma) = decaying(&c) {
            return Err(CycleError::Vanishing(format!(
                "the oscillation shooting converged on ({:.6} Hz) decays at σ = {sigma:.4e} 1/s: \
                 its multiplier along the flow, {:.9}, is as far below 1 as its slowest \
                 transverse one ({:.9}), so it is a slowly dying oscillation onto steady \
                 sliding, not a periodic orbit",
                1.0 / c.period,
                (sigma * c.period).exp(),
                c.max_multiplier
            )));
        }
        if c.stable || attempt >= 4 || c.max_multiplier <= 1.0 {
            let mut c = c;
            c.settle_time = spent;
            return Ok(c);
        }
        let skip = past_unstable(c.period, c.max_multiplier);
        (t, z) = advance(sys, t + settled, c.z0, skip, opts)?;
        spent += skip;
        if spent >= opts.settle_time {
            let mut c = c;
            c.settle_time = spent;
            return Ok(c);
        }
    }
}

/// The fastest growth of steady sliding, `(σ, ω)` of its growing eigenvalue
/// with the largest `σ` (growing as [`crate::stability::is_growing`] says,
/// the eigenvalues of [`crate::stability::eigenvalues`]); `None` if none
/// grows or there is no steady sliding.
fn steady_growth<S: System<N> + ?Sized, const N: usize>(sys: &S) -> Option<(f64, f64)> {
    let ev = crate::stability::eigenvalues(sys).ok()?;
    ev.iter()
        .filter(|l| crate::stability::is_growing(l.re, l.im))
        .max_by(|a, b| a.re.total_cmp(&b.re))
        .map(|l| (l.re, l.im.abs()))
}

/// A failed shooting's message, with what to try where steady sliding grows
/// so slowly (σ·2π/ω a period below `tol`) that a still-growing
/// oscillation passed the settling match.
fn slow_growth_hint<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    why: String,
    tol: f64,
) -> String {
    match steady_growth(sys) {
        Some((sigma, omega)) if omega > 0.0 && sigma * std::f64::consts::TAU / omega < tol => {
            let per = sigma * std::f64::consts::TAU / omega;
            format!(
                "{why}; steady sliding's mode at {:.6} Hz grows by only {per:.1e} a period \
                 (σ = {sigma:.4e} 1/s), less than the settling match {tol:.0e}: the \
                 motion settled on may still have been growing; try --settle-tol {:.0e}",
                omega / std::f64::consts::TAU,
                (0.1 * per).min(0.1 * tol)
            )
        }
        _ => why,
    }
}

/// How long to simulate on from an unstable periodic orbit of period `t`
/// and largest multiplier `mu > 1` until its instability has grown a
/// thousandfold (at most 10⁶ periods).
pub fn past_unstable(t: f64, mu: f64) -> f64 {
    t * (1e3f64.ln() / mu.ln()).min(1e6)
}

/// Simulate from `(t, z)` for `duration` at the settling tolerance: the
/// time and state at the end.
pub fn advance<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t: f64,
    z: [f64; N],
    duration: f64,
    opts: &CycleOptions,
) -> Result<(f64, [f64; N]), CycleError> {
    let mut sopts = opts.solver;
    sopts.rtol = sopts.rtol.max(opts.settle_rtol);
    sopts.max_steps = opts.settle_steps;
    let mut sol = Solver::new(sys, t, z, t + duration, sopts)?;
    while sol.step()?.is_some() {}
    Ok((sol.t(), *sol.state()))
}

/// The decay rate `σ = ln μ_t / T` if the orbit `c` is no periodic orbit but
/// a slowly dying oscillation: its multiplier along the flow `μ_t` is below
/// 1 by more than the shooting residual could explain (10×) and by at
/// least half the gap `1 − |μ|max` of its slowest transverse multiplier.
/// On a periodic orbit `μ_t = 1` (the flow vector is carried into itself)
/// up to the residual, while an oscillation that decays, e.g. a weakly
/// damped linear mode about stable steady sliding, loses amplitude along
/// the flow as fast as across it: Newton shooting with a tolerance above
/// its decay per period converges on it all the same.
fn decaying<const N: usize>(c: &Cycle<N>) -> Option<f64> {
    let t = c.multipliers.iter().find(|m| m.trivial)?;
    let below = 1.0 - t.abs();
    let gap = 1.0 - c.max_multiplier;
    (below > 10.0 * c.residual && gap > 0.0 && below >= 0.5 * gap).then(|| t.abs().ln() / c.period)
}

/// One settling run from `(t0, z0)` and the shooting that follows it: the
/// cycle, the time settled and the settled state shooting started from.
fn settle_and_shoot<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t0: f64,
    z0: [f64; N],
    opts: &CycleOptions,
) -> Result<(Cycle<N>, f64, [f64; N]), CycleError> {
    // A settling run at the looser settle_rtol that fails (chatter the
    // tighter tolerance resolves, say) is repeated at the solver's own.
    let (section, z, period, settled) = match settle(sys, t0, z0, opts) {
        Err(CycleError::Integrate(_)) if opts.settle_rtol > opts.solver.rtol => {
            let mut strict = *opts;
            strict.settle_rtol = opts.solver.rtol;
            settle(sys, t0, z0, &strict)?
        }
        other => other?,
    };
    let c = shoot(sys, z, period, section, opts)?;
    Ok((c, settled, z))
}

/// Newton shooting from a guess `(z0, period)` on `section`, then the
/// multipliers, over the orbit's minimal period (see `minimal_period`).
pub fn shoot<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z0: [f64; N],
    period: f64,
    section: Section,
    opts: &CycleOptions,
) -> Result<Cycle<N>, CycleError> {
    shoot_over(sys, z0, period, section, opts, true)
}

/// [`shoot`], with the search for a shorter period (`minimal`) or without
/// (the confirming shot over a sub-period: searching again from there
/// would recurse without end on steady sliding, where every `t/k` returns).
fn shoot_over<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z0: [f64; N],
    period: f64,
    section: Section,
    opts: &CycleOptions,
    minimal: bool,
) -> Result<Cycle<N>, CycleError> {
    if section.index >= N {
        return Err(CycleError::Bad(format!(
            "section index {} out of range",
            section.index
        )));
    }
    if !(period > 0.0 && period.is_finite()) {
        return Err(CycleError::Bad(format!("period guess {period}")));
    }
    let mut z = z0;
    let mut t = period;
    // Scales from a first pass.
    let first = period_flow(sys, &z, t, &[1.0; N], opts, false, None)?;
    let mut amp = [0.0; N];
    for i in 0..N {
        amp[i] = 0.5 * (first.hi[i] - first.lo[i]);
    }
    let s = block_scales(&amp, &opts.solver);
    let mut iterations = 0;
    let mut residual;
    let mut last_step = f64::INFINITY;
    loop {
        let p = period_flow(sys, &z, t, &s, opts, true, None)?;
        residual = (0..N)
            .map(|i| ((p.z_end[i] - z[i]) / s[i]).abs())
            .fold(0.0, f64::max);
        if residual <= opts.newton_tol
            || (iterations >= 3 && last_step <= 1e-12 && residual <= 1e3 * opts.newton_tol)
        {
            if minimal {
                if let Some(c) = minimal_period(sys, &z, t, section, &s, opts)? {
                    return Ok(c);
                }
            }
            return finish(sys, z, t, section, s, residual, iterations, p);
        }
        if iterations >= opts.newton_iterations {
            return Err(CycleError::Shooting(format!(
                "residual {residual:.3e} after {iterations} Newton iterations (period {t:.9e} s)"
            )));
        }
        iterations += 1;
        let mut f = [0.0; N];
        let t_end = autonomous_from(sys) + t;
        let modes = sys.start_modes(t_end, &p.z_end);
        sys.field(t_end, &modes, &p.z_end, &mut f);
        let mut a = DMatrix::<f64>::zeros(N + 1, N + 1);
        let mut b = nalgebra::DVector::<f64>::zeros(N + 1);
        for i in 0..N {
            for j in 0..N {
                a[(i, j)] = p.m[(i, j)] - if i == j { 1.0 } else { 0.0 };
            }
            a[(i, N)] = f[i] / s[i] * t;
            b[i] = -(p.z_end[i] - z[i]) / s[i];
        }
        a[(N, section.index)] = 1.0;
        b[N] = -(z[section.index] - section.level) / s[section.index];
        let dx = a.lu().solve(&b).ok_or_else(|| {
            CycleError::Shooting(format!("the shooting matrix is singular (t = {t:.6e} s)"))
        })?;
        // Damped: never move the period by more than a third.
        let mut lambda = 1.0f64;
        if (dx[N]).abs() > 1.0 / 3.0 {
            lambda = (1.0 / 3.0) / dx[N].abs();
        }
        for i in 0..N {
            z[i] += lambda * dx[i] * s[i];
        }
        z[section.index] = section.level;
        t *= 1.0 + lambda * dx[N];
        last_step = dx.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if !last_step.is_finite() {
            return Err(CycleError::Shooting("Newton step not finite".into()));
        }
    }
}

/// The scaled distance within which a state on a converged orbit counts
/// as the orbit's starting state again (a return at a sub-period), and
/// within which a re-shot orbit counts as the same orbit.
fn same_state_tol(opts: &CycleOptions) -> f64 {
    1e3 * opts.newton_tol
}

/// A periodic orbit's period is its minimal period. For an orbit `z` of
/// converged period `t`, look for the largest `k ≤ max(max_returns, 2)`
/// with `φ(t/k, z) = z` (scaled distance within [`same_state_tol`]), confirm
/// it by shooting over `t/k` from `z`, and return that cycle (its
/// multipliers computed over `t/k`, not as `k`-th roots) if it is the same
/// orbit: the confirmed start must lie within the same tolerance of `z`,
/// so that near a period doubling a genuine period-2 orbit (whose half
/// period lands a finite distance away) is not merged into the period-1
/// orbit. `None`: `t` is minimal.
fn minimal_period<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z: &[f64; N],
    t: f64,
    section: Section,
    s: &[f64; N],
    opts: &CycleOptions,
) -> Result<Option<Cycle<N>>, CycleError> {
    let kmax = opts.max_returns.max(2);
    let tol = same_state_tol(opts);
    let dist = |a: &[f64; N], b: &[f64; N]| {
        (0..N)
            .map(|i| ((a[i] - b[i]) / s[i]).abs())
            .fold(0.0, f64::max)
    };
    let t_a = autonomous_from(sys);
    let mut solver = Solver::new(sys, t_a, *z, t_a + 0.5 * t * (1.0 + 1e-9), opts.solver)?;
    let mut best = None;
    while let Some(seg) = solver.step()? {
        for k in 2..=kmax {
            let tk = t_a + t / k as f64;
            if tk > seg.t0 && tk <= seg.t1 && dist(&solver.dense_at(tk), z) <= tol {
                best = best.max(Some(k));
            }
        }
    }
    let Some(k) = best else { return Ok(None) };
    match shoot_over(sys, *z, t / k as f64, section, opts, false) {
        Ok(c) if dist(&c.z0, z) <= tol => Ok(Some(c)),
        _ => Ok(None),
    }
}

#[allow(clippy::too_many_arguments)]
fn finish<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z: [f64; N],
    t: f64,
    section: Section,
    s: [f64; N],
    residual: f64,
    iterations: usize,
    p: Period<N>,
) -> Result<Cycle<N>, CycleError> {
    let mut f = [0.0; N];
    let t_a = autonomous_from(sys);
    let modes = sys.start_modes(t_a, &z);
    sys.field(t_a, &modes, &z, &mut f);
    // The multipliers of the real states only (see `real_indices`).
    let idx = real_indices(sys);
    let fs = nalgebra::DVector::from_fn(idx.len(), |i, _| f[idx[i]] / s[idx[i]]);
    let k = idx
        .iter()
        .position(|&i| i == section.index)
        .ok_or_else(|| {
            CycleError::Bad(format!(
                "section state {} is an idle (padding) state",
                section.index
            ))
        })?;
    let m_real = p.m.select_rows(&idx).select_columns(&idx);
    let (multipliers, max_multiplier) = multipliers_of(&m_real, &fs, k);
    let mut monodromy = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            monodromy[i][j] = p.m[(i, j)] * s[i] / s[j];
        }
    }
    let mut amplitude = [0.0; N];
    for i in 0..N {
        amplitude[i] = 0.5 * (p.hi[i] - p.lo[i]);
    }
    Ok(Cycle {
        period: t,
        z0: z,
        section,
        monodromy,
        stable: max_multiplier < 1.0,
        max_multiplier,
        multipliers,
        residual,
        iterations,
        events_per_period: p.events,
        amplitude,
        settle_time: 0.0,
    })
}

/// The multipliers of a (scaled) monodromy `m` with flow vector `f` on the
/// section `z_k = c`: the trivial one and the eigenvalues of the Poincaré
/// map's Jacobian (module documentation).
fn multipliers_of(
    m: &DMatrix<f64>,
    f: &nalgebra::DVector<f64>,
    k: usize,
) -> (Vec<Multiplier>, f64) {
    let n = m.nrows();
    let mf = m * f;
    let trivial = mf.dot(f) / f.dot(f);
    let mut proj = DMatrix::<f64>::identity(n, n);
    if f[k] != 0.0 {
        for i in 0..n {
            proj[(i, k)] -= f[i] / f[k];
        }
    }
    let mut list = eigen_multipliers(&(proj * m));
    // The section's own direction: the eigenvalue nearest zero stands for the flow.
    let zero = (0..n)
        .min_by(|&a, &b| list[a].abs().total_cmp(&list[b].abs()))
        .unwrap_or(0);
    list[zero] = Multiplier {
        re: trivial,
        im: 0.0,
        trivial: true,
    };
    let max = list
        .iter()
        .filter(|m| !m.trivial)
        .map(Multiplier::abs)
        .fold(0.0, f64::max);
    sort_multipliers(&mut list);
    (list, max)
}

/// The eigenvalues of `a` as multipliers (none marked trivial).
fn eigen_multipliers(a: &DMatrix<f64>) -> Vec<Multiplier> {
    a.complex_eigenvalues()
        .iter()
        .map(|c| Multiplier {
            re: c.re,
            im: c.im,
            trivial: false,
        })
        .collect()
}

/// Sort by modulus descending, then real part, then imaginary part.
fn sort_multipliers(list: &mut [Multiplier]) {
    list.sort_by(|a, b| {
        b.abs()
            .total_cmp(&a.abs())
            .then(b.re.total_cmp(&a.re))
            .then(b.im.total_cmp(&a.im))
    });
}

/// Sample one period of `cycle` densely (integrator steps, 8 points each, and
/// every event as two rows: the state before and after it).
pub fn orbit<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    cycle: &Cycle<N>,
    opts: &CycleOptions,
) -> Result<Orbit<N>, CycleError> {
    let mut o = Orbit::default();
    period_flow(
        sys,
        &cycle.z0,
        cycle.period,
        &[1.0; N],
        opts,
        false,
        Some(&mut o),
    )?;
    Ok(o)
}

/// One period of length `period` from `z0`, sampled densely (every step's
/// end and every event, before and after): the orbit of an approximate
/// periodic solution (e.g. a harmonic-balance one, or a settling run's
/// last return) that need not close.
pub fn sample_period<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z0: &[f64; N],
    period: f64,
    opts: &CycleOptions,
) -> Result<Orbit<N>, CycleError> {
    let mut o = Orbit::default();
    period_flow(sys, z0, period, &[1.0; N], opts, false, Some(&mut o))?;
    Ok(o)
}

/// The Floquet analysis of one period `period` from `z0` without Newton
/// shooting: the monodromy by the variational equations and the saltation
/// matrices along the exact (non-smooth) flow, its multipliers on the
/// section through `z0` of the velocity whose scaled rate is largest, and
/// as `residual` the scaled defect `|φ_T(z₀) − z₀|` (how far `(z0,
/// period)` is from a periodic orbit of the event-driven model). Used to
/// judge the stability of a harmonic-balance orbit with stick and
/// reversal events treated exactly.
pub fn floquet_from<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    z0: &[f64; N],
    period: f64,
    opts: &CycleOptions,
) -> Result<Cycle<N>, CycleError> {
    let (p, s, defect) = scaled_period(sys, z0, period, opts)?;
    let t_a = autonomous_from(sys);
    let mut f = [0.0; N];
    let modes = sys.start_modes(t_a, z0);
    sys.field(t_a, &modes, z0, &mut f);
    let idx = real_indices(sys);
    let index = idx
        .iter()
        .copied()
        .filter(|&i| i >= N / 2)
        .max_by(|&a, &b| (f[a] / s[a]).abs().total_cmp(&(f[b] / s[b]).abs()))
        .ok_or_else(|| CycleError::Bad("no velocity state".into()))?;
    let section = Section {
        index,
        level: z0[index],
    };
    finish(sys, *z0, period, section, s, defect, 0, p)
}

/// The monodromy matrix by finite differences through the event-driven flow:
/// column `j` is `(φ_T(z₀ + h_j e_j) − φ_T(z₀ − h_j e_j)) / 2h_j` with
/// `h_j = rel · scale_j` (scales as in the module documentation). An
/// independent check of the saltation-based monodromy.
pub fn finite_difference_monodromy<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    cycle: &Cycle<N>,
    rel: f64,
    solver: SolverOptions,
) -> Result<[[f64; N]; N], CycleError> {
    let s = block_scales(&cycle.amplitude, &solver);
    let end = |z: [f64; N]| -> Result<[f64; N], CycleError> {
        let t_a = autonomous_from(sys);
        let mut sol = Solver::new(sys, t_a, z, t_a + cycle.period, solver)?;
        while sol.step()?.is_some() {}
        Ok(*sol.state())
    };
    let mut m = [[0.0; N]; N];
    for j in 0..N {
        let h = rel * s[j];
        let mut zp = cycle.z0;
        zp[j] += h;
        let mut zm = cycle.z0;
        zm[j] -= h;
        let (ep, em) = (end(zp)?, end(zm)?);
        for i in 0..N {
            m[i][j] = (ep[i] - em[i]) / (zp[j] - zm[j]);
        }
    }
    Ok(m)
}

/// The state scales used for `cycle`'s norms (positions by the largest
/// position amplitude, velocities by the largest velocity amplitude).
pub fn scales<const N: usize>(cycle: &Cycle<N>, solver: &SolverOptions) -> [f64; N] {
    block_scales(&cycle.amplitude, solver)
}

/// The returns of a simulation from `(t0, z0)` to `section` (upward
/// crossings of `z[section.index] = section.level`, each located by
/// bisection on the integrator's dense output to the last bit of `t`), up
/// to `t_end`: `(t, z)` of every crossing after `t0`, the crossing
/// component set to the level exactly. A start on the section is not a
/// return.
pub fn section_returns<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    t0: f64,
    z0: [f64; N],
    t_end: f64,
    section: Section,
    solver: SolverOptions,
) -> Result<Vec<(f64, [f64; N])>, CycleError> {
    if section.index >= N {
        return Err(CycleError::Bad(format!(
            "section index {} out of range",
            section.index
        )));
    }
    let k = section.index;
    let mut sol = Solver::new(sys, t0, z0, t_end, solver)?;
    let mut out = Vec::new();
    let mut prev = z0;
    while let Some(seg) = sol.step()? {
        let z1 = sol.dense_at(seg.t1);
        if prev[k] - section.level < 0.0 && z1[k] - section.level >= 0.0 {
            out.push(upward_crossing(&sol, seg.t0, seg.t1, section));
        }
        prev = if seg.switched { *sol.state() } else { z1 };
    }
    Ok(out)
}

/// The non-trivial Floquet multipliers of `cycle` from its simulated return
/// map alone: the Poincaré map `P` (state on the section → state at the
/// return nearest one period later) is differentiated by central
/// differences, column `j` being `(P(z₀ + h_j e_j) − P(z₀ − h_j e_j)) / 2h_j`
/// with `h_j = rel · scale_j` for every component but the section's, and its
/// `N − 1` eigenvalues are returned (sorted by modulus, descending; none
/// marked trivial). No variational equation, saltation matrix or
/// projection is involved: an independent check of [`find_cycle`]'s
/// multipliers through the event-driven flow.
pub fn return_map_multipliers<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    cycle: &Cycle<N>,
    rel: f64,
    solver: SolverOptions,
) -> Result<Vec<Multiplier>, CycleError> {
    let s = block_scales(&cycle.amplitude, &solver);
    let k = cycle.section.index;
    let t_a = autonomous_from(sys);
    let period = cycle.period;
    let image = |z: [f64; N]| -> Result<[f64; N], CycleError> {
        let returns = section_returns(sys, t_a, z, t_a + 1.5 * period, cycle.section, solver)?;
        returns
            .into_iter()
            .filter(|(t, _)| *t - t_a > 0.5 * period)
            .min_by(|a, b| {
                (a.0 - t_a - period)
                    .abs()
                    .total_cmp(&(b.0 - t_a - period).abs())
            })
            .map(|(_, z)| z)
            .ok_or_else(|| {
                CycleError::Shooting(format!(
                    "a perturbed start did not return to the section within 1.5 periods \
                     ({period:.6e} s)"
                ))
            })
    };
    let idx: Vec<usize> = real_indices(sys).into_iter().filter(|&i| i != k).collect();
    let m = idx.len();
    let mut jac = DMatrix::<f64>::zeros(m, m);
    for (c, &j) in idx.iter().enumerate() {
        let h = rel * s[j];
        let mut zp = cycle.z0;
        zp[j] += h;
        let mut zm = cycle.z0;
        zm[j] -= h;
        let (ep, em) = (image(zp)?, image(zm)?);
        for (r, &i) in idx.iter().enumerate() {
            jac[(r, c)] = (ep[i] - em[i]) / (zp[j] - zm[j]) * s[j] / s[i];
        }
    }
    if jac.iter().any(|x| !x.is_finite()) {
        return Err(CycleError::Shooting(
            "the return map's Jacobian is not finite".into(),
        ));
    }
    let mut list = eigen_multipliers(&jac);
    sort_multipliers(&mut list);
    Ok(list)
}
