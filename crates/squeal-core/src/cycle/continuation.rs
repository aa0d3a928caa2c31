//! Continuation of a limit cycle in one parameter `p`, through folds, with
//! the bifurcations along the branch detected.
//!
//! # The extended system
//!
//! A point of the branch is `X = (z₀, T, p)`: the start state on the Poincaré
//! section, the period and the parameter. It solves the `N + 1` equations
//!
//! ```text
//! G(X) = ( φ_T(z₀; p) − z₀ ,  z₀,k − c ) = 0,
//! ∂G/∂X = [[M − I, f(φ_T z₀), ∂φ_T/∂p], [e_kᵀ, 0, 0]]
//! ```
//!
//! (`M` the monodromy with saltation matrices, `∂φ_T/∂p` by a forward
//! difference through the event-driven flow). The branch is a curve in the
//! `N + 2` unknowns, followed in scaled coordinates (states by the orbit's
//! amplitude as in the module [`super`], the period by the current period,
//! the parameter by the grid spacing), rescaled at every point.
//!
//! # Steps
//!
//! The direction of travel is the secant through the last two points
//! (Allgower & Georg 1990, §2.2; the Jacobian's null vector is ill-conditioned
//! where slowly decaying modes put multipliers a hair below 1, as in the
//! disc–pad). Where the branch is parameter-dominated (`|t_p| ≥ ½`) a step
//! fixes the parameter at the next grid value (natural-parameter correction
//! with the secant predictor, so grid rows cost nothing extra). Elsewhere —
//! near a fold, where `p` turns back — it is a pseudo-arclength step
//! (Keller 1977): predictor `X̂ = X + Δs t`, corrector Newton on `G = 0,
//! tᵀ(X − X̂) = 0`, and the grid values it passed are computed afterwards
//! with the parameter fixed. A fold is where the parameter turns between
//! three points; it is located as the extreme of the parabola `p(s)` through
//! them (chord arclength), corrected on the hyperplane normal to the
//! interpolated direction, three times, and added as a point. A step may not
//! shrink the cycle by more than half (Newton's method can fall onto the
//! equilibrium, which solves the equations with any `T`); a failed step is
//! retried at half the length.
//!
//! # Bifurcations
//!
//! Between neighbouring points of a segment: a fold (the parameter turns),
//! period doubling (the number of real multipliers below −1 changes),
//! Neimark–Sacker (the number of complex multipliers outside the unit circle
//! changes), a real multiplier through +1 without a turn (a branch point),
//! and grazing/sliding bifurcations (the events per period change: an event
//! appears on or vanishes from the orbit). In a non-smooth system a
//! multiplier may *jump* across the unit circle at a grazing point
//! (discontinuous bifurcations, Leine & van Campen 2002): both are reported.
//!
//! # Meeting steady sliding
//!
//! Near a Hopf point `p_H` of the equilibrium the cycle's amplitude `A`
//! obeys `A² ≈ a (p − p_H)` and its frequency tends to the linear one. A
//! segment whose amplitude shrinks below [`BranchOptions::amplitude_floor`] of
//! its largest ends there, and `p_H` and the frequency are extrapolated
//! linearly in `A²` from its last two points.

use super::{autonomous_from, block_scales, finish, period_flow, Cycle, CycleError, CycleOptions};
use super::{Multiplier, Section};
use crate::model::System;
use nalgebra::{DMatrix, DVector};

/// A one-parameter family of systems: `visit(p, f)` calls `f` once with the
/// system at parameter value `p` (or returns why `p` is not acceptable).
pub trait Family<const N: usize> {
    /// Call `f` with the system at `p`.
    fn visit(&self, p: f64, f: &mut dyn FnMut(&dyn System<N>)) -> Result<(), String>;
}

impl<F, const N: usize> Family<N> for F
where
    F: Fn(f64, &mut dyn FnMut(&dyn System<N>)) -> Result<(), String>,
{
    fn visit(&self, p: f64, f: &mut dyn FnMut(&dyn System<N>)) -> Result<(), String> {
        self(p, f)
    }
}

/// A system whose named parameter can be varied: calls `f` with a copy whose
/// parameter `name` is `value` (checked by the model's own validation).
pub trait Reparametrise<const N: usize> {
    /// Call `f` with the system at `name = value`.
    fn with_param(
        &self,
        name: &str,
        value: f64,
        f: &mut dyn FnMut(&dyn System<N>),
    ) -> Result<(), String>;
}

macro_rules! reparametrise {
    ($t:ty, $n:literal) => {
        impl Reparametrise<$n> for $t {
            fn with_param(
                &self,
                name: &str,
                value: f64,
                f: &mut dyn FnMut(&dyn System<$n>),
            ) -> Result<(), String> {
                use crate::model::Parameters;
                let mut m = self.clone();
                m.set(name, value).map_err(|e| e.to_string())?;
                m.validate().map_err(|e| e.to_string())?;
                f(&m);
                Ok(())
            }
        }
    };
}
reparametrise!(crate::Belt, 2);
reparametrise!(crate::DiscPad, 8);
reparametrise!(crate::Hoffmann, 4);

impl<const N: usize> Reparametrise<N> for crate::model::lumped::Fixed<'_, N> {
    fn with_param(
        &self,
        name: &str,
        value: f64,
        f: &mut dyn FnMut(&dyn System<N>),
    ) -> Result<(), String> {
        let mut l = self.0.clone();
        l.set(name, value).map_err(|e| e.to_string())?;
        l.validate().map_err(|e| e.to_string())?;
        f(&crate::model::lumped::Fixed::<N>(&l));
        Ok(())
    }
}

/// The family of `model` over its parameter `name`.
#[derive(Debug, Clone, Copy)]
pub struct Varied<'a, M: ?Sized> {
    /// The model at the start.
    pub model: &'a M,
    /// The parameter's name.
    pub name: &'a str,
}

impl<M: Reparametrise<N> + ?Sized, const N: usize> Family<N> for Varied<'_, M> {
    fn visit(&self, p: f64, f: &mut dyn FnMut(&dyn System<N>)) -> Result<(), String> {
        self.model.with_param(self.name, p, f)
    }
}

/// Run `f` on the system at `p`.
fn at<R, const N: usize>(
    fam: &dyn Family<N>,
    p: f64,
    f: impl FnOnce(&dyn System<N>) -> R,
) -> Result<R, CycleError> {
    let mut f = Some(f);
    let mut out = None;
    fam.visit(p, &mut |s| {
        if let Some(f) = f.take() {
            out = Some(f(s));
        }
    })
    .map_err(|e| CycleError::Bad(format!("parameter value {p}: {e}")))?;
    out.ok_or_else(|| CycleError::Bad(format!("parameter value {p}: no system")))
}

/// Settings of [`branch`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BranchOptions {
    /// Settings of each cycle (solver, Newton tolerance).
    pub cycle: CycleOptions,
    /// Most continuation steps per segment.
    pub max_steps: usize,
    /// Most Newton iterations of one corrector.
    pub corrector_iterations: usize,
    /// Largest step (scaled arclength; 1 is one grid spacing of a
    /// parameter-dominated branch: steps stop at every grid value anyway).
    pub max_step: f64,
    /// Smallest step before a segment is given up.
    pub min_step: f64,
    /// A segment ends at steady sliding when its largest velocity amplitude
    /// falls below this fraction of the largest met on it.
    pub amplitude_floor: f64,
}

impl Default for BranchOptions {
    fn default() -> Self {
        BranchOptions {
            cycle: CycleOptions::default(),
            max_steps: 2000,
            corrector_iterations: 8,
            max_step: 2.0,
            min_step: 1e-3,
            amplitude_floor: 1e-2,
        }
    }
}

/// What a point of the branch is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointKind {
    /// At the grid value of this index.
    Grid(usize),
    /// A fold: the parameter turns back here.
    Fold,
    /// An intermediate continuation step.
    Step,
}

/// One computed point of the branch.
#[derive(Debug, Clone)]
pub struct BranchPoint<const N: usize> {
    /// Parameter value.
    pub value: f64,
    /// The cycle there.
    pub cycle: Cycle<N>,
    /// What the point is.
    pub kind: PointKind,
    /// Index of the segment (continuation run) it belongs to.
    pub segment: usize,
    /// `dp/ds` of the unit tangent (scaled): its sign is the direction of
    /// travel in the parameter, zero at a fold.
    pub slope: f64,
}

/// How a segment ended.
#[derive(Debug, Clone, PartialEq)]
pub enum SegmentEnd {
    /// The branch left the parameter range.
    LeftRange,
    /// The amplitude shrank to zero: the branch meets steady sliding near
    /// `value`, with the frequency `freq_hz` there (extrapolated in `A²`).
    SteadySliding {
        /// Parameter value where the amplitude vanishes.
        value: f64,
        /// Cycle frequency there (Hz).
        freq_hz: f64,
    },
    /// The corrector failed even with the smallest step.
    Stalled {
        /// Parameter value of the last point.
        value: f64,
        /// Why.
        cause: String,
    },
    /// [`BranchOptions::max_steps`] reached.
    Steps,
}

/// The kind of a bifurcation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BifurcationKind {
    /// The parameter turns back (a saddle-node of cycles).
    Fold,
    /// A real multiplier crosses −1.
    PeriodDoubling,
    /// A complex pair of multipliers crosses the unit circle.
    NeimarkSacker,
    /// A real multiplier crosses +1 without a turn of the parameter.
    BranchPoint,
    /// The events per period change (an event appears on or vanishes from the orbit).
    GrazingSliding,
    /// The period jumps by more than half: another cycle.
    PeriodJump,
}

impl BifurcationKind {
    /// The name used in reports (`fold`, `period_doubling`, …).
    pub fn as_str(&self) -> &'static str {
        match self {
            BifurcationKind::Fold => "fold",
            BifurcationKind::PeriodDoubling => "period_doubling",
            BifurcationKind::NeimarkSacker => "neimark_sacker",
            BifurcationKind::BranchPoint => "branch_point",
            BifurcationKind::GrazingSliding => "grazing_sliding",
            BifurcationKind::PeriodJump => "period_jump",
        }
    }
}

/// A bifurcation detected between two neighbouring points.
#[derive(Debug, Clone, PartialEq)]
pub struct Bifurcation {
    /// What happens.
    pub kind: BifurcationKind,
    /// The parameter values of the two points it lies between.
    pub between: (f64, f64),
    /// Where it is located (a fold: the fold point's value).
    pub value: Option<f64>,
    /// A human description (multipliers, events, stability).
    pub detail: String,
}

/// A followed branch.
#[derive(Debug, Clone, Default)]
pub struct Branch<const N: usize> {
    /// Points, segment by segment, each segment in the order followed.
    pub points: Vec<BranchPoint<N>>,
    /// How each segment ended.
    pub ends: Vec<SegmentEnd>,
    /// Grid values where no cycle was found, with the reason.
    pub failures: Vec<(f64, CycleError)>,
    /// Bifurcations along the segments.
    pub bifurcations: Vec<Bifurcation>,
}

/// Scales of the unknowns at the current point.
#[derive(Clone, Copy)]
struct Scale<const N: usize> {
    s: [f64; N],
    t: f64,
    p: f64,
}

impl<const N: usize> Scale<N> {
    fn of(cycle: &Cycle<N>, opts: &CycleOptions, dp: f64) -> Self {
        Scale {
            s: block_scales(&cycle.amplitude, &opts.solver),
            t: cycle.period,
            p: dp,
        }
    }
    /// Scaled vector of `(z, T, p)`.
    fn x(&self, z: &[f64; N], t: f64, p: f64) -> DVector<f64> {
        DVector::from_fn(N + 2, |i, _| match i {
            i if i < N => z[i] / self.s[i],
            i if i == N => t / self.t,
            _ => p / self.p,
        })
    }
    fn unx(&self, x: &DVector<f64>) -> ([f64; N], f64, f64) {
        let mut z = [0.0; N];
        for i in 0..N {
            z[i] = x[i] * self.s[i];
        }
        (z, x[N] * self.t, x[N + 1] * self.p)
    }
}

/// A converged point.
struct Solved<const N: usize> {
    cycle: Cycle<N>,
    p: f64,
}

/// Newton's method on `G(X) = 0`, `rowᵀ (X − X̂) = 0` from the predictor
/// `X̂` (scaled by `scale`).
fn correct<const N: usize>(
    fam: &dyn Family<N>,
    section: Section,
    scale: &Scale<N>,
    pred: &DVector<f64>,
    row: &DVector<f64>,
    opts: &BranchOptions,
) -> Result<Solved<N>, CycleError> {
    let copts = &opts.cycle;
    let mut x = pred.clone();
    let s = scale.s;
    let mut dphi_dp: Option<DVector<f64>> = None;
    let mut last_res = f64::INFINITY;
    for iteration in 0..=opts.corrector_iterations {
        let (mut z, t, p) = scale.unx(&x);
        z[section.index] = section.level;
        if !(t > 0.0 && t.is_finite() && p.is_finite()) {
            return Err(CycleError::Shooting(format!(
                "continuation left the valid range (period {t:e} s, parameter {p})"
            )));
        }
        let (flow, f_end) = at(fam, p, |sys| -> Result<_, CycleError> {
            let flow = period_flow(sys, &z, t, &s, copts, true, None)?;
            let t_end = autonomous_from(sys) + t;
            let modes = sys.start_modes(t_end, &flow.z_end);
            let mut f = [0.0; N];
            sys.field(t_end, &modes, &flow.z_end, &mut f);
            Ok((flow, f))
        })??;
        let res = (0..N)
            .map(|i| ((flow.z_end[i] - z[i]) / s[i]).abs())
            .fold(0.0, f64::max);
        // ∂φ_T/∂p by a forward difference (once per corrector: Newton's
        // method needs it only approximately, the residual is exact).
        // With the parameter fixed (row e_p) its column does not matter.
        let fixed_p = row[N + 1] == 1.0;
        if dphi_dp.is_none() && fixed_p {
            dphi_dp = Some(DVector::zeros(N));
        }
        if dphi_dp.is_none() {
            let h = 1e-6 * scale.p;
            let end = at(fam, p + h, |sys| {
                period_flow(sys, &z, t, &s, copts, false, None).map(|f| f.z_end)
            })??;
            dphi_dp = Some(DVector::from_fn(N, |i, _| {
                (end[i] - flow.z_end[i]) / h * scale.p / s[i]
            }));
        }
        let dpp = dphi_dp.as_ref().expect("computed above");
        let mut jac = DMatrix::<f64>::zeros(N + 1, N + 2);
        for i in 0..N {
            for j in 0..N {
                jac[(i, j)] = flow.m[(i, j)] - if i == j { 1.0 } else { 0.0 };
            }
            jac[(i, N)] = f_end[i] / s[i] * t;
            jac[(i, N + 1)] = dpp[i];
        }
        jac[(N, section.index)] = 1.0;
        let constraint = row.dot(&(&x - pred));
        if res <= copts.newton_tol && constraint.abs() <= 1e-6 {
            let cycle = at(fam, p, |sys| {
                finish(sys, z, t, section, s, res, iteration, flow)
            })??;
            return Ok(Solved { cycle, p });
        }
        // Diverging: give up early (the step is retried shorter).
        if iteration >= 2 && res > 2.0 * last_res {
            return Err(CycleError::Shooting(format!(
                "the corrector diverges (residual {last_res:.3e} → {res:.3e}) at parameter {p}"
            )));
        }
        last_res = res;
        if iteration == opts.corrector_iterations {
            return Err(CycleError::Shooting(format!(
                "residual {res:.3e} after {iteration} corrector iterations at parameter {p}"
            )));
        }
        let mut a = DMatrix::<f64>::zeros(N + 2, N + 2);
        a.view_mut((0, 0), (N + 1, N + 2)).copy_from(&jac);
        for j in 0..N + 2 {
            a[(N + 1, j)] = row[j];
        }
        let mut b = DVector::<f64>::zeros(N + 2);
        for i in 0..N {
            b[i] = -(flow.z_end[i] - z[i]) / s[i];
        }
        b[N] = -(z[section.index] - section.level) / s[section.index];
        b[N + 1] = -constraint;
        let dx = a.lu().solve(&b).ok_or_else(|| {
            CycleError::Shooting(format!("singular continuation matrix at parameter {p}"))
        })?;
        if dx.iter().any(|v| !v.is_finite()) {
            return Err(CycleError::Shooting("Newton step not finite".into()));
        }
        // Damped: never move the period by more than a third.
        let rel_t = dx[N] / x[N];
        let lambda = if rel_t.abs() > 1.0 / 3.0 {
            (1.0 / 3.0) / rel_t.abs()
        } else {
            1.0
        };
        x += dx * lambda;
    }
    unreachable!("the loop returns")
}

fn velocity_amplitude<const N: usize>(c: &Cycle<N>) -> f64 {
    c.amplitude[N / 2..].iter().fold(0.0f64, |a, b| a.max(*b))
}

/// Follow the cycle over the parameter `grid` (increasing, evenly spaced):
/// `settle(p)` finds a cycle afresh at a grid value (by simulation); from it
/// the branch is continued upwards until it leaves the range, meets steady
/// sliding or stalls; grid values it did not reach are settled afresh and
/// continued from in turn.
pub fn branch<const N: usize>(
    family: &dyn Family<N>,
    grid: &[f64],
    settle: &mut dyn FnMut(f64) -> Result<Cycle<N>, CycleError>,
    opts: &BranchOptions,
) -> Branch<N> {
    let mut out = Branch {
        points: Vec::new(),
        ends: Vec::new(),
        failures: Vec::new(),
        bifurcations: Vec::new(),
    };
    if grid.is_empty() {
        return out;
    }
    let (lo, hi) = (grid[0], grid[grid.len() - 1]);
    let dp = if grid.len() > 1 {
        (hi - lo) / (grid.len() - 1) as f64
    } else {
        lo.abs().max(1.0)
    };
    let mut covered = vec![false; grid.len()];
    let mut a_max = 0.0f64;
    while let Some(i) = covered.iter().position(|c| !c) {
        covered[i] = true;
        let cycle = match settle(grid[i]) {
            // An oscillation far below the branch's is a slowly decaying
            // one that settling took for a cycle (beyond a Hopf point).
            Ok(c) if velocity_amplitude(&c) < opts.amplitude_floor * a_max => {
                out.failures.push((
                    grid[i],
                    CycleError::Vanishing(format!(
                        "velocity amplitude {:.3e}, below {} of the branch's largest ({a_max:.3e}): steady sliding",
                        velocity_amplitude(&c),
                        opts.amplitude_floor
                    )),
                ));
                continue;
            }
            Ok(c) => c,
            Err(e) => {
                out.failures.push((grid[i], e));
                continue;
            }
        };
        let segment = out.ends.len();
        let first = out.points.len();
        let end = follow(
            family,
            grid,
            (lo, hi, dp),
            i,
            cycle,
            segment,
            &mut covered,
            &mut out.points,
            opts,
        );
        out.ends.push(end);
        let pts = &out.points[first..];
        a_max = pts
            .iter()
            .map(|p| velocity_amplitude(&p.cycle))
            .fold(a_max, f64::max);
        out.bifurcations.extend(bifurcations(pts));
    }
    out
}

/// One segment from the cycle at grid index `i`.
#[allow(clippy::too_many_arguments)]
fn follow<const N: usize>(
    fam: &dyn Family<N>,
    grid: &[f64],
    (lo, hi, dp): (f64, f64, f64),
    i: usize,
    cycle: Cycle<N>,
    segment: usize,
    covered: &mut [bool],
    points: &mut Vec<BranchPoint<N>>,
    opts: &BranchOptions,
) -> SegmentEnd {
    let section = cycle.section;
    let first = points.len();
    let p0 = grid[i];
    let settle_time = cycle.settle_time;
    // The first point: a corrector from the cycle itself with the parameter
    // fixed (converges at once).
    let scale = Scale::of(&cycle, &opts.cycle, dp);
    let x0 = scale.x(&cycle.z0, cycle.period, p0);
    let e_p = DVector::from_fn(N + 2, |k, _| if k == N + 1 { 1.0 } else { 0.0 });
    let mut cur = match correct(fam, section, &scale, &x0, &e_p, opts) {
        Ok(mut s) => {
            s.cycle.settle_time = settle_time;
            s
        }
        Err(e) => {
            points.push(BranchPoint {
                value: p0,
                cycle,
                kind: PointKind::Grid(i),
                segment,
                slope: 1.0,
            });
            return SegmentEnd::Stalled {
                value: p0,
                cause: e.to_string(),
            };
        }
    };
    points.push(BranchPoint {
        value: p0,
        cycle: cur.cycle.clone(),
        kind: PointKind::Grid(i),
        segment,
        slope: 1.0,
    });
    // The previous point (unscaled z, T, p): the secant through it and the
    // current one is the direction of travel (upwards in p at the start).
    let mut prev: Option<([f64; N], f64, f64)> = None;
    let mut a_max = velocity_amplitude(&cur.cycle);
    // The first step has no secant to predict with: short.
    let mut ds = 0.0625 * opts.max_step;
    for _ in 0..opts.max_steps {
        // Scaled to the current point.
        let scale = Scale::of(&cur.cycle, &opts.cycle, dp);
        let x = scale.x(&cur.cycle.z0, cur.cycle.period, cur.p);
        let t_here = match prev {
            Some((z, t, p)) => {
                let d = &x - scale.x(&z, t, p);
                let n = d.norm();
                if n > 0.0 {
                    d / n
                } else {
                    e_p.clone()
                }
            }
            None => e_p.clone(),
        };
        let tp = t_here[N + 1];
        let step = if tp.abs() >= 0.5 {
            // Parameter-dominated: to the next grid value, at most ds, with
            // the parameter fixed (the secant predicts the rest).
            let dir = tp.signum();
            let next = grid
                .iter()
                .enumerate()
                .filter(|(_, g)| (**g - cur.p) * dir > 1e-9 * dp)
                .min_by(|a, b| ((a.1 - cur.p).abs()).total_cmp(&(b.1 - cur.p).abs()));
            let max_dp = ds * tp.abs();
            match next {
                Some((k, g)) if (g - cur.p).abs() / dp <= max_dp * (1.0 + 1e-9) => {
                    let h = (g - cur.p) / dp / tp;
                    let mut pred = &x + &t_here * h;
                    pred[N + 1] = g / dp;
                    correct(fam, section, &scale, &pred, &e_p, opts).map(|s| (s, Some(k), h.abs()))
                }
                _ => {
                    let pred = &x + &t_here * ds;
                    correct(fam, section, &scale, &pred, &e_p, opts).map(|s| (s, None, ds))
                }
            }
        } else {
            let pred = &x + &t_here * ds;
            correct(fam, section, &scale, &pred, &t_here, opts).map(|s| (s, None, ds))
        };
        // A step may not shrink the cycle by more than half: near an
        // equilibrium every `(z*, T)` solves the equations, and Newton's
        // method can fall onto it; a genuine approach to a Hopf point is
        // followed in smaller steps.
        let step = step.and_then(|v| {
            let (a0, a1) = (
                velocity_amplitude(&cur.cycle),
                velocity_amplitude(&v.0.cycle),
            );
            if a1 < 0.5 * a0 {
                Err(CycleError::Shooting(format!(
                    "the cycle collapsed in one step (amplitude {a0:.3e} → {a1:.3e}) at parameter {}",
                    v.0.p
                )))
            } else {
                Ok(v)
            }
        });
        let (next, grid_index, used) = match step {
            Ok(v) => v,
            Err(e) => {
                ds *= 0.5;
                if ds < opts.min_step {
                    return SegmentEnd::Stalled {
                        value: cur.p,
                        cause: e.to_string(),
                    };
                }
                continue;
            }
        };
        // The step grows after an easy corrector (a step cut short by a grid
        // value counts as the full allowed one), shrinks after a hard one.
        let iters = next.cycle.iterations;
        let base = if grid_index.is_some() {
            ds.max(used)
        } else {
            used
        };
        ds = if iters <= 2 {
            (base * 1.5).min(opts.max_step)
        } else if iters >= 5 {
            (base * 0.6).max(opts.min_step)
        } else {
            base.min(opts.max_step)
        };
        let inside = next.p >= lo - 1e-9 * dp && next.p <= hi + 1e-9 * dp;
        let xb = scale.x(&next.cycle.z0, next.cycle.period, next.p);
        // Grid values passed over by an arclength step: corrected with the
        // parameter fixed, from the chord.
        if grid_index.is_none() {
            let (pa, pb) = (cur.p, next.p);
            let mut passed: Vec<(usize, f64)> = grid
                .iter()
                .enumerate()
                .filter(|(_, g)| {
                    ((**g - pa) * (**g - pb) < 0.0 || **g == pb) && (**g - pa).abs() > 1e-9 * dp
                })
                .map(|(k, g)| (k, (g - pa) / (pb - pa)))
                .filter(|(_, th)| th.is_finite())
                .collect();
            passed.sort_by(|a, b| a.1.total_cmp(&b.1));
            for (k, th) in passed {
                let mut pred = &x + (&xb - &x) * th;
                pred[N + 1] = grid[k] / dp;
                if let Ok(s) = correct(fam, section, &scale, &pred, &e_p, opts) {
                    covered[k] = true;
                    points.push(BranchPoint {
                        value: grid[k],
                        cycle: s.cycle,
                        kind: PointKind::Grid(k),
                        segment,
                        slope: (pb - pa).signum() * tp.abs(),
                    });
                }
            }
        }
        // A fold: the parameter turned at the current point (not where the
        // cycle has shrunk onto the equilibrium: at a Hopf point p − p_H ∝ A²
        // turns too).
        let small = 0.05 * a_max;
        if let Some((zp, tp_, pp)) = prev {
            if (next.p - cur.p) * (cur.p - pp) < 0.0
                && velocity_amplitude(&cur.cycle) > small
                && velocity_amplitude(&next.cycle) > small
            {
                let xa = scale.x(&zp, tp_, pp);
                if let Some(f) = locate_fold(fam, section, &scale, [&xa, &x, &xb], opts) {
                    if f.p >= lo - 1e-9 * dp && f.p <= hi + 1e-9 * dp {
                        points.push(BranchPoint {
                            value: f.p,
                            cycle: f.cycle,
                            kind: PointKind::Fold,
                            segment,
                            slope: 0.0,
                        });
                    }
                }
            }
        }
        if !inside {
            return SegmentEnd::LeftRange;
        }
        if let Some(k) = grid_index {
            covered[k] = true;
        }
        let d = &xb - &x;
        let slope = d[N + 1] / d.norm().max(f64::MIN_POSITIVE);
        points.push(BranchPoint {
            value: grid_index.map_or(next.p, |k| grid[k]),
            cycle: next.cycle.clone(),
            kind: grid_index.map_or(PointKind::Step, PointKind::Grid),
            segment,
            slope,
        });
        let a = velocity_amplitude(&next.cycle);
        a_max = a_max.max(a);
        prev = Some((cur.cycle.z0, cur.cycle.period, cur.p));
        cur = next;
        if a < opts.amplitude_floor * a_max {
            let seg = &points[first..];
            return match steady_sliding_estimate(seg) {
                Some((value, freq_hz)) => SegmentEnd::SteadySliding { value, freq_hz },
                None => SegmentEnd::Stalled {
                    value: cur.p,
                    cause: "the amplitude vanishes".into(),
                },
            };
        }
    }
    SegmentEnd::Steps
}

/// The fold near three points `x` (scaled, in the order followed) whose
/// parameter turns at the middle one: parabolas through the fold's estimate
/// and its neighbours, three times.
fn locate_fold<const N: usize>(
    fam: &dyn Family<N>,
    section: Section,
    scale: &Scale<N>,
    x: [&DVector<f64>; 3],
    opts: &BranchOptions,
) -> Option<Solved<N>> {
    let mut pts = [x[0].clone(), x[1].clone(), x[2].clone()];
    let mut best = None;
    for _ in 0..3 {
        let Some((f, before_middle)) =
            fold_once(fam, section, scale, [&pts[0], &pts[1], &pts[2]], opts)
        else {
            break;
        };
        let xf = scale.x(&f.cycle.z0, f.cycle.period, f.p);
        pts = if before_middle {
            [pts[0].clone(), xf, pts[1].clone()]
        } else {
            [pts[1].clone(), xf, pts[2].clone()]
        };
        best = Some(f);
    }
    best
}

/// One parabola: the extreme of `p(s)` through the three points (chord
/// arclength `s`), corrected on the hyperplane through the interpolated point
/// normal to the interpolated direction; whether it lies before the middle one.
fn fold_once<const N: usize>(
    fam: &dyn Family<N>,
    section: Section,
    scale: &Scale<N>,
    x: [&DVector<f64>; 3],
    opts: &BranchOptions,
) -> Option<(Solved<N>, bool)> {
    let s1 = (x[1] - x[0]).norm();
    let s2 = s1 + (x[2] - x[1]).norm();
    let s = [0.0, s1, s2];
    // Lagrange basis and its derivative at t.
    let basis = |t: f64| -> ([f64; 3], [f64; 3]) {
        let mut l = [0.0; 3];
        let mut dl = [0.0; 3];
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let den = (s[i] - s[j]) * (s[i] - s[k]);
            l[i] = (t - s[j]) * (t - s[k]) / den;
            dl[i] = ((t - s[j]) + (t - s[k])) / den;
        }
        (l, dl)
    };
    // p(s) = Σ p_i l_i(s) is quadratic: p'(s) = 2a s + b.
    let p: Vec<f64> = x.iter().map(|v| v[N + 1]).collect();
    let (_, d0) = basis(0.0);
    let (_, d1) = basis(1.0);
    let b = (0..3).map(|i| p[i] * d0[i]).sum::<f64>();
    let two_a = (0..3).map(|i| p[i] * (d1[i] - d0[i])).sum::<f64>();
    if two_a == 0.0 {
        return None;
    }
    let t = -b / two_a;
    if !(t > 0.0 && t < s2) {
        return None;
    }
    let (l, dl) = basis(t);
    let pred = x[0] * l[0] + x[1] * l[1] + x[2] * l[2];
    let dir = x[0] * dl[0] + x[1] * dl[1] + x[2] * dl[2];
    let n = dir.norm();
    if n == 0.0 {
        return None;
    }
    let f = correct(fam, section, scale, &pred, &(dir / n), opts).ok()?;
    Some((f, t < s1))
}

/// Where the amplitude of a segment that shrinks to zero would vanish, and
/// the frequency there: linear extrapolation in `A²` from its last two points.
pub fn steady_sliding_estimate<const N: usize>(seg: &[BranchPoint<N>]) -> Option<(f64, f64)> {
    let mut it = seg.iter().rev().filter(|p| p.kind != PointKind::Fold);
    let b = it.next()?;
    let a = it.next()?;
    let (a2, b2) = (
        velocity_amplitude(&a.cycle).powi(2),
        velocity_amplitude(&b.cycle).powi(2),
    );
    if b2.partial_cmp(&a2) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    let th = b2 / (a2 - b2);
    let value = b.value - th * (a.value - b.value);
    let (fa, fb) = (1.0 / a.cycle.period, 1.0 / b.cycle.period);
    let freq = fb - th * (fa - fb);
    Some((value, freq))
}

/// Real multipliers beyond +1, beyond −1, and complex ones outside the unit
/// circle (non-trivial only).
fn outside(m: &[Multiplier]) -> (usize, usize, usize) {
    let mut r = (0, 0, 0);
    for x in m.iter().filter(|x| !x.trivial) {
        let complex = x.im.abs() > 1e-9 * x.abs();
        if complex {
            if x.abs() > 1.0 {
                r.2 += 1;
            }
        } else if x.re > 1.0 {
            r.0 += 1;
        } else if x.re < -1.0 {
            r.1 += 1;
        }
    }
    r
}

fn describe_events(e: &[u64; 5]) -> String {
    let list: Vec<String> = crate::model::EventKind::ALL
        .iter()
        .filter(|k| e[k.index()] > 0)
        .map(|k| format!("{} {}", e[k.index()], k.as_str()))
        .collect();
    if list.is_empty() {
        "none".into()
    } else {
        list.join(", ")
    }
}

fn stability(s: bool) -> &'static str {
    if s {
        "stable"
    } else {
        "unstable"
    }
}

/// The bifurcations between neighbouring points of one segment (in the
/// order followed).
pub fn bifurcations<const N: usize>(seg: &[BranchPoint<N>]) -> Vec<Bifurcation> {
    let mut out = Vec::new();
    // Followed order: grid points passed by an arclength step were pushed
    // before the step's point, folds before it too; sort by position along
    // the segment is the push order except those, which lie between the
    // previous point and the step. The push order is already that order.
    for (k, w) in seg.windows(2).enumerate() {
        let (a, b) = (&w[0], &w[1]);
        let between = (a.value, b.value);
        if b.kind == PointKind::Fold {
            out.push(Bifurcation {
                kind: BifurcationKind::Fold,
                between,
                value: Some(b.value),
                detail: format!(
                    "the parameter turns back (largest non-trivial |multiplier| {:.6}; 1 at the exact fold)",
                    b.cycle.max_multiplier
                ),
            });
        }
        let (oa, ob) = (outside(&a.cycle.multipliers), outside(&b.cycle.multipliers));
        let near_fold = a.kind == PointKind::Fold
            || b.kind == PointKind::Fold
            || a.slope * b.slope < 0.0
            || seg.get(k + 2).is_some_and(|c| c.kind == PointKind::Fold);
        let stab = format!(
            "{} → {}",
            stability(a.cycle.stable),
            stability(b.cycle.stable)
        );
        if oa.0 != ob.0 && !near_fold {
            out.push(Bifurcation {
                kind: BifurcationKind::BranchPoint,
                between,
                value: None,
                detail: format!("a real multiplier crosses +1 ({stab})"),
            });
        }
        if oa.1 != ob.1 {
            out.push(Bifurcation {
                kind: BifurcationKind::PeriodDoubling,
                between,
                value: None,
                detail: format!("a real multiplier crosses −1 ({stab})"),
            });
        }
        if oa.2 != ob.2 {
            out.push(Bifurcation {
                kind: BifurcationKind::NeimarkSacker,
                between,
                value: None,
                detail: format!("a complex pair of multipliers crosses the unit circle ({stab})"),
            });
        }
        if a.cycle.events_per_period != b.cycle.events_per_period {
            out.push(Bifurcation {
                kind: BifurcationKind::GrazingSliding,
                between,
                value: None,
                detail: format!(
                    "the events per period change ({} → {})",
                    describe_events(&a.cycle.events_per_period),
                    describe_events(&b.cycle.events_per_period)
                ),
            });
        }
        if (b.cycle.period / a.cycle.period - 1.0).abs() > 0.5 {
            out.push(Bifurcation {
                kind: BifurcationKind::PeriodJump,
                between,
                value: None,
                detail: format!(
                    "the period jumps ({:.6e} → {:.6e} s): another cycle",
                    a.cycle.period, b.cycle.period
                ),
            });
        }
    }
    out
}
