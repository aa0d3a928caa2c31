//! Linear stability of steady sliding (MODEL.md §5).
//!
//! At the steady-sliding equilibrium `z*` of a model (all velocities zero,
//! sliding velocity `v = V`), the slip equations linearise to `ż = A z` with
//! `A = ∂f/∂z(z*)` the model's analytic Jacobian ([`System::state_jacobian`]). Its
//! eigenvalues `λ = σ ± iω` give each mode's growth rate σ (1/s), frequency
//! `ω/2π` and damping ratio `−σ/|λ|`; by Lyapunov's indirect method the
//! equilibrium is asymptotically stable if every σ < 0 and unstable if some
//! σ > 0 (thesis Ch. 1).
//!
//! **Neutral modes.** An undamped model has purely imaginary eigenvalues whose
//! computed σ is round-off: the balanced QR iteration's backward error is
//! `ε·‖B‖` (B the balanced matrix), which for the models here is below
//! 1e-13·|λ| for every mode (≈ 1e-15·|λ| typically). This module calls a mode
//! *neutral* iff `|σ| ≤ NEUTRAL_TOL·|λ|` with [`NEUTRAL_TOL`] = 1e-12 (of the
//! order of that round-off, no wider), *growing* iff `σ > NEUTRAL_TOL·|λ|`
//! ([`is_growing`]) and *damped* otherwise. The equilibrium is *stable* iff
//! every mode is damped (every σ < 0 beyond round-off), *unstable* iff some
//! mode grows, and *neutral* otherwise (linear analysis cannot decide). The
//! onset of mode-coupling flutter — where σ jumps from 0 to positive at the
//! coalescence of two undamped frequencies — is a stability change that
//! [`critical`] locates.
//!
//! - [`analyse`]: all eigenvalues, eigenvectors and mode descriptions;
//! - [`max_growth_rate`]: the fast path for stability maps (eigenvalues only,
//!   no heap allocation, ≈ 2 µs for the 8-state disc–pad model);
//! - [`modal::analyse_matrix`]: the same analysis for a state matrix of any
//!   size known at run time (faer for thousands of states), and complex mode
//!   shapes ([`modal::mode_shape`]);
//! - [`projected::analyse_projected`]: the complex eigenvalue analysis of
//!   large models by projection onto their lowest undamped modes (as FE
//!   packages do);
//! - [`sweep::sweep`]: every eigenvalue along a one-parameter sweep, tracked
//!   continuously (MAC + Hungarian assignment), with located onsets and
//!   coalescences (the mode-coupling diagram);
//! - [`critical`]: a grid scan plus Brent's method for the parameter value
//!   at which the stability changes;
//! - [`track`]: eigenvalues followed along a parameter path.
//!
//! The eigen-solver is [`eigen`] (balancing + Hessenberg + Francis QR, with
//! the reasons it is hand-written).

pub mod coupling;
pub mod craig_bampton;
pub mod eigen;
pub mod lanczos;
pub mod lumped;
pub mod modal;
pub mod projected;
pub mod sensitivity;
pub mod sweep;
pub mod track;

use crate::model::{ModelError, System};
use crate::params::ParamError;
use nalgebra::Complex;
use serde::Serialize;

/// Relative threshold below which a growth rate counts as zero (round-off of
/// the balanced eigen-solver): a mode grows iff `σ > NEUTRAL_TOL·|λ|`, is
/// neutral iff `|σ| ≤ NEUTRAL_TOL·|λ|` (see the module docs).
pub const NEUTRAL_TOL: f64 = 1e-12;

/// Why a stability analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StabilityError {
    /// The model has no steady-sliding state (the model's message).
    #[error("no steady sliding: {0}")]
    NoSteadySliding(String),
    /// A parameter is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The equilibrium or the Jacobian there has NaN or infinite entries.
    #[error("the {what} at steady sliding is not finite")]
    NonFinite {
        /// `equilibrium`, `Jacobian` or `spectrum (eigenvalues)`.
        what: &'static str,
    },
    /// The QR iteration needed more than `eigen::MAX_QR_ITERATIONS` steps
    /// for an eigenvalue.
    #[error("the eigenvalue iteration did not converge")]
    NoConvergence,
    /// The search interval of [`critical`] is empty or not finite.
    #[error("bad parameter interval [{lo}, {hi}]: need finite lo < hi")]
    BadInterval {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// Options or inputs out of range.
    #[error("invalid input: {0}")]
    BadInput(String),
    /// Brent's method did not reach the tolerance.
    #[error("root finding did not converge in {iterations} iterations on [{lo}, {hi}]")]
    RootNotFound {
        /// Iterations spent.
        iterations: usize,
        /// Bracket lower end.
        lo: f64,
        /// Bracket upper end.
        hi: f64,
    },
}

impl From<ModelError> for StabilityError {
    fn from(e: ModelError) -> Self {
        match e {
            ModelError::Param(p) => StabilityError::Param(p),
            ModelError::NoSteadySliding(msg) => StabilityError::NoSteadySliding(msg),
        }
    }
}

/// Round-off of σ at a (nearly) double eigenvalue, relative to |λ|: √ε. Below
/// the coalescence of two undamped frequencies σ is 0 but its computed value
/// can reach this; [`critical`] locates the onset of mode-coupling growth as
/// the root of `σ_max − COALESCENCE_TOL·|λ|`.
pub const COALESCENCE_TOL: f64 = 1.4901161193847656e-8;

/// Whether an eigenvalue `re + i·im` counts as growing: `re > NEUTRAL_TOL·|λ|`.
#[inline]
pub fn is_growing(re: f64, im: f64) -> bool {
    re > NEUTRAL_TOL * re.hypot(im)
}

/// Whether an eigenvalue `re + i·im` is neutral: `|re| ≤ NEUTRAL_TOL·|λ|`
/// (zero within the eigen-solver's round-off).
#[inline]
pub fn is_neutral(re: f64, im: f64) -> bool {
    re.abs() <= NEUTRAL_TOL * re.hypot(im)
}

/// One eigenvalue of the state matrix and the mode it belongs to.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Eigen {
    /// Growth rate σ = Re λ (1/s).
    pub re: f64,
    /// Im λ (rad/s); conjugate pairs are both listed, `+ω` first.
    pub im: f64,
    /// Frequency `|Im λ|/2π` (Hz).
    pub freq_hz: f64,
    /// Damping ratio `−σ/|λ|` (0 for λ = 0).
    pub damping_ratio: f64,
    /// Whether the mode grows: `σ > NEUTRAL_TOL·|λ|`.
    pub growing: bool,
    /// Whether the mode is neutral: `|σ| ≤ NEUTRAL_TOL·|λ|` (zero within round-off).
    pub neutral: bool,
    /// Index of the position coordinate with the largest share of the
    /// mode's energy (see [`Eigen::participation`]).
    pub dominant: usize,
    /// Name of that coordinate (`System::names`, or the names given to
    /// [`modal::analyse_matrix`]).
    pub dominant_name: String,
    /// Energy share of each position coordinate `i < N/2` (sums to 1):
    /// `E_i ∝ m_i·(|u_{n+i}|² + |λ|²·|u_i|²)` with `u` the eigenvector and
    /// `n = N/2`, i.e. twice the kinetic energy of coordinate `i` counted
    /// from its velocity component and from `λ·q_i` (equal for a mechanical
    /// state `(q, q̇)`). [`analyse`] uses unit masses `m_i = 1`: coordinates
    /// are compared by velocity amplitude; [`analyse_with_masses`] weights by
    /// the true masses. For λ = 0 the shares are `|u_i|²`.
    pub participation: Vec<f64>,
    /// Right eigenvector `u` of the original (unbalanced) state matrix, unit
    /// 2-norm, largest component real positive. Serialised as `[re, im]` pairs.
    #[serde(serialize_with = "serialize_complex")]
    pub vector: Vec<Complex<f64>>,
}

fn serialize_complex<S: serde::Serializer>(v: &[Complex<f64>], s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for c in v {
        seq.serialize_element(&[c.re, c.im])?;
    }
    seq.end()
}

/// Result of [`analyse`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Analysis {
    /// All N eigenvalues, by growth rate descending (ties: `+ω` first).
    pub eigen: Vec<Eigen>,
    /// Largest growth rate σ_max (1/s).
    pub max_growth_rate: f64,
    /// Every mode is damped beyond round-off (every `σ < −NEUTRAL_TOL·|λ|`).
    pub stable: bool,
    /// No mode grows but some mode is neutral (`|σ| ≤ NEUTRAL_TOL·|λ|`):
    /// marginally stable, linear analysis cannot decide.
    pub neutral: bool,
    /// Index in `eigen` of the least stable mode (0 by the sort order).
    pub least_stable: usize,
    /// The steady-sliding state `z*`.
    pub equilibrium: Vec<f64>,
    /// How the eigenvalues were computed: every one of the full state matrix
    /// ([`projected::Method::Dense`]), or by projection onto undamped modes
    /// ([`projected::Method::Projected`], a reduced-basis answer).
    pub method: projected::Method,
}

impl Analysis {
    /// The least stable mode.
    pub fn least_stable_mode(&self) -> &Eigen {
        &self.eigen[self.least_stable]
    }
}

/// Masses of a model's position coordinates, for energy-weighted mode
/// attribution ([`analyse_with_masses`]).
pub trait Inertia {
    /// Mass (kg) of each position coordinate, in state order (`N/2` values).
    fn position_masses(&self) -> Vec<f64>;
}

impl Inertia for crate::model::disc_pad::DiscPad {
    /// `(m_d, m_p, m_d, m_p)` for `(x_d, x_p, y_d, y_p)`.
    fn position_masses(&self) -> Vec<f64> {
        vec![self.p.m_d, self.p.m_p, self.p.m_d, self.p.m_p]
    }
}

impl Inertia for crate::model::belt::Belt {
    /// `(m)`.
    fn position_masses(&self) -> Vec<f64> {
        vec![self.p.m]
    }
}

impl Inertia for crate::model::hoffmann::Hoffmann {
    /// `(m, m)`.
    fn position_masses(&self) -> Vec<f64> {
        vec![self.p.m, self.p.m]
    }
}

/// The steady-sliding state `z*` and the state matrix `A = ∂f/∂z(z*)`,
/// both checked finite.
#[allow(clippy::type_complexity)]
pub fn state_matrix<M: System<N> + ?Sized, const N: usize>(
    model: &M,
) -> Result<([f64; N], [[f64; N]; N]), StabilityError> {
    let z = model.steady_sliding()?;
    if z.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite {
            what: "equilibrium",
        });
    }
    let a = model.state_jacobian(&z);
    if a.iter().flatten().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite { what: "Jacobian" });
    }
    Ok((z, a))
}

/// A state matrix with finite entries can still have eigenvalues that
/// overflow (entries near 1e300): an error, like a non-finite matrix.
pub(crate) fn check_finite(ev: &[Complex<f64>]) -> Result<(), StabilityError> {
    if ev.iter().all(|e| e.re.is_finite() && e.im.is_finite()) {
        Ok(())
    } else {
        Err(StabilityError::NonFinite {
            what: "spectrum (eigenvalues)",
        })
    }
}

/// Full linear stability analysis of steady sliding (MODEL.md §5) with unit
/// masses for the mode attribution (see [`Eigen::participation`]).
///
/// Steps: the model's closed-form equilibrium (its
/// [`ModelError::NoSteadySliding`] passes through with its message), the
/// analytic Jacobian there, Parlett–Reinsch balancing, Francis QR for all N
/// eigenvalues, inverse iteration for each eigenvector ([`eigen`]).
pub fn analyse<M: System<N> + ?Sized, const N: usize>(
    model: &M,
) -> Result<Analysis, StabilityError> {
    analyse_impl(model, None)
}

/// [`analyse`] with the energy share of each coordinate weighted by its mass
/// (`masses.len() == N/2`, all > 0; see [`Inertia`]).
pub fn analyse_with_masses<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    masses: &[f64],
) -> Result<Analysis, StabilityError> {
    if masses.len() != N / 2 || masses.iter().any(|m| !(m.is_finite() && *m > 0.0)) {
        return Err(StabilityError::BadInput(format!(
            "masses must be {} finite positive values, got {masses:?}",
            N / 2
        )));
    }
    analyse_impl(model, Some(masses))
}

fn analyse_impl<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    masses: Option<&[f64]>,
) -> Result<Analysis, StabilityError> {
    let (z, a) = state_matrix(model)?;
    let (ev, bal, d) = eigen::eigenvalues_balanced(&a).ok_or(StabilityError::NoConvergence)?;
    check_finite(&ev)?;
    let names = model.names();
    // A real matrix's eigenvector of λ̄ is the conjugate of λ's: computed once per pair.
    let mut done: Vec<(Complex<f64>, Vec<Complex<f64>>)> = Vec::with_capacity(N);
    let modes: Vec<Eigen> = ev
        .iter()
        .map(|&lambda| {
            let pair = done
                .iter()
                .find(|(l, _)| l.im != 0.0 && *l == lambda.conj());
            let u = if let Some((_, v)) = pair {
                v.iter().map(|x| x.conj()).collect()
            } else {
                // Inverse iteration on the balanced matrix, mapped back: u = D ũ.
                let mut u = eigen::eigenvector(&bal, lambda);
                for (ui, di) in u.iter_mut().zip(d.iter()) {
                    *ui *= *di;
                }
                eigen::normalise(&mut u);
                let u = u.to_vec();
                done.push((lambda, u.clone()));
                u
            };
            modal::describe(lambda, u, masses, &names)
        })
        .collect();
    Ok(modal::finish(modes, z.to_vec()))
}

/// Fast path for stability maps: the largest growth rate σ_max (1/s) of the
/// steady-sliding state and the frequency `|Im λ|/2π` (Hz) of that mode
/// (0 for a real eigenvalue). Eigenvalues only, on stack arrays: no heap
/// allocation. Same equilibrium, Jacobian and eigen-solver as [`analyse`].
pub fn max_growth_rate<M: System<N> + ?Sized, const N: usize>(
    model: &M,
) -> Result<(f64, f64), StabilityError> {
    let ev = eigenvalues(model)?;
    let mut best = Complex::new(f64::NEG_INFINITY, 0.0);
    for e in ev {
        if e.re > best.re || (e.re == best.re && e.im > best.im) {
            best = e;
        }
    }
    Ok((best.re, best.im.abs() / (2.0 * std::f64::consts::PI)))
}

/// Every eigenvalue of the state matrix at steady sliding (the order of
/// [`eigen::hqr`]), on stack arrays: the eigenvalues [`max_growth_rate`]
/// picks from.
pub fn eigenvalues<M: System<N> + ?Sized, const N: usize>(
    model: &M,
) -> Result<[Complex<f64>; N], StabilityError> {
    let (_, a) = state_matrix(model)?;
    let ev = eigen::eigenvalues(&a).ok_or(StabilityError::NoConvergence)?;
    check_finite(&ev)?;
    Ok(ev)
}

/// Options of [`critical`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalOptions {
    /// Grid points of the initial scan, ends included (default 64, ≥ 2).
    pub grid: usize,
    /// Relative tolerance on the parameter value (default 1e-10).
    pub rtol: f64,
    /// Most iterations of Brent's method (default 200).
    pub max_iter: usize,
}

impl Default for CriticalOptions {
    fn default() -> Self {
        CriticalOptions {
            grid: 64,
            rtol: 1e-10,
            max_iter: 200,
        }
    }
}

/// Which way the stability changes as the parameter increases.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Stable below, unstable above.
    Destabilising,
    /// Unstable below, stable above.
    Stabilising,
}

/// A parameter value where the stability of steady sliding changes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Crossing {
    /// The critical parameter value.
    pub value: f64,
    /// Frequency (Hz) of the least stable mode there.
    pub freq_hz: f64,
    /// Stabilising or destabilising as the parameter increases.
    pub direction: Direction,
    /// The stable side is neutral (`|σ| ≤ NEUTRAL_TOL·|λ|`, undamped mode
    /// coupling): `value` is the onset of growth (coalescence of two
    /// frequencies), located as the root of `σ_max − COALESCENCE_TOL·|λ|`.
    /// Otherwise it is the root of `σ_max` (a Hopf point).
    pub from_neutral: bool,
}

/// The first parameter value in `[lo, hi]` where the stability of steady
/// sliding changes, or `None` if it does not change on the scan grid.
///
/// `f(p)` evaluates `(σ_max, freq_hz)` at parameter value `p` (typically:
/// set the parameter on a copy of the model, then [`max_growth_rate`]); its
/// errors pass through. The interval is scanned on `opts.grid` equally spaced
/// points for a change of the verdict *growing* (`σ_max > NEUTRAL_TOL·|λ|`,
/// `|λ| = hypot(σ_max, 2π·freq_hz)`); in the first bracket found, Brent's
/// method solves `g(p) = 0` to `opts.rtol` relative in `p`, where
///
/// - `g = σ_max` if the stable end is strictly damped
///   (`σ_max < −NEUTRAL_TOL·|λ|`): a Hopf point, found to round-off;
/// - `g = σ_max − COALESCENCE_TOL·|λ|` if the stable end is neutral
///   (`|σ| ≤ NEUTRAL_TOL·|λ|`: σ_max is 0 below the coalescence of an
///   undamped mode pair and grows like the square root of the distance above
///   it, so this root lies within ~1e-15 relative of the coalescence). A
///   stable end that is neutral only because a Hopf point falls on that grid
///   point (the next grid point is strictly damped) is a Hopf point.
///
/// Crossings closer together than the grid spacing may be missed.
pub fn critical<F>(
    mut f: F,
    lo: f64,
    hi: f64,
    opts: &CriticalOptions,
) -> Result<Option<Crossing>, StabilityError>
where
    F: FnMut(f64) -> Result<(f64, f64), StabilityError>,
{
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(StabilityError::BadInterval { lo, hi });
    }
    if opts.grid < 2 || !(opts.rtol > 0.0 && opts.rtol < 1.0) || opts.max_iter == 0 {
        return Err(StabilityError::BadInput(format!(
            "critical: grid = {} (≥ 2), rtol = {} (in (0, 1)), max_iter = {} (≥ 1)",
            opts.grid, opts.rtol, opts.max_iter
        )));
    }
    let two_pi = 2.0 * std::f64::consts::PI;
    let mag = |s: f64, fr: f64| s.hypot(two_pi * fr);
    let at = |i: usize| {
        if i + 1 == opts.grid {
            hi
        } else {
            lo + (hi - lo) * (i as f64 / (opts.grid - 1) as f64)
        }
    };
    let mut p0 = lo;
    let (mut s0, mut f0) = f(p0)?;
    // The grid point before p0 (further from the bracket on the low side).
    let mut before: Option<(f64, f64, f64)> = None;
    for i in 1..opts.grid {
        let p1 = at(i);
        let (s1, f1) = f(p1)?;
        let g0 = is_growing(s0, two_pi * f0);
        let g1 = is_growing(s1, two_pi * f1);
        if g0 != g1 {
            // The stable end, and the grid point one step further into the stable side.
            let further = if g0 {
                if i + 1 < opts.grid {
                    let p = at(i + 1);
                    let (s, fr) = f(p)?;
                    Some((p, s, fr))
                } else {
                    None
                }
            } else {
                before
            };
            let (mut a, mut sa, mut fa) = if g0 { (p1, s1, f1) } else { (p0, s0, f0) };
            let (b, sb, fb) = if g0 { (p0, s0, f0) } else { (p1, s1, f1) };
            let mut neutral = is_neutral(sa, two_pi * fa);
            // A Hopf point that falls on a grid point looks neutral there (σ = 0
            // within round-off); one step further it is strictly damped: bracket
            // the crossing from there, on σ itself.
            if neutral {
                if let Some((p, s, fr)) = further {
                    if s < -NEUTRAL_TOL * mag(s, fr) {
                        (a, sa, fa) = (p, s, fr);
                        neutral = false;
                    }
                }
            }
            // The threshold for a coalescence: COALESCENCE_TOL, or less where the
            // growing end's σ/|λ| is itself below it (just past the coalescence),
            // so that g changes sign on the bracket; it stays above the neutral
            // end's σ/|λ| (≤ NEUTRAL_TOL), and the root stays within ~tol² of
            // the coalescence.
            let ratio = |s: f64, fr: f64| {
                let m = mag(s, fr);
                if m > 0.0 {
                    s / m
                } else {
                    0.0
                }
            };
            let (ra, rb) = (ratio(sa, fa), ratio(sb, fb));
            let tol = COALESCENCE_TOL.min(if ra > 0.0 { (ra * rb).sqrt() } else { 0.5 * rb });
            let g = |s: f64, fr: f64| {
                if neutral {
                    s - tol * mag(s, fr)
                } else {
                    s
                }
            };
            let root = brent(
                |p| {
                    let (s, fr) = f(p)?;
                    Ok(g(s, fr))
                },
                (a, g(sa, fa)),
                (b, g(sb, fb)),
                opts.rtol,
                4.0 * f64::EPSILON * lo.abs().max(hi.abs()),
                opts.max_iter,
            )?;
            let (_, fr) = f(root)?;
            return Ok(Some(Crossing {
                value: root,
                freq_hz: fr,
                direction: if g1 {
                    Direction::Destabilising
                } else {
                    Direction::Stabilising
                },
                from_neutral: neutral,
            }));
        }
        before = Some((p0, s0, f0));
        (p0, s0, f0) = (p1, s1, f1);
    }
    Ok(None)
}

/// Brent's method (R. P. Brent, *Algorithms for Minimization without
/// Derivatives*, 1973, ch. 4, procedure `zero`; as in Numerical Recipes'
/// `zbrent`): inverse quadratic interpolation, secant and bisection on a
/// bracket `[a, b]` with `g(a)·g(b) ≤ 0`, to `|Δp| ≤ rtol·|p| + atol`.
///
/// Hand-written (~50 lines) because the crates that offer it are either
/// unmaintained or pull in a large dependency tree for one function.
pub fn brent<G>(
    mut g: G,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    rtol: f64,
    atol: f64,
    max_iter: usize,
) -> Result<f64, StabilityError>
where
    G: FnMut(f64) -> Result<f64, StabilityError>,
{
    if fa == 0.0 {
        return Ok(a);
    }
    if fb == 0.0 {
        return Ok(b);
    }
    if (fa > 0.0) == (fb > 0.0) || !(fa.is_finite() && fb.is_finite()) {
        return Err(StabilityError::BadInput(format!(
            "brent: no sign change on [{a}, {b}] (g = {fa:e}, {fb:e})"
        )));
    }
    let (lo0, hi0) = (a.min(b), a.max(b));
    let (mut c, mut fc) = (b, fb);
    let (mut d, mut e) = (b - a, b - a);
    for _ in 0..max_iter {
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol1 = 2.0 * f64::EPSILON * b.abs() + 0.5 * (rtol * b.abs() + atol);
        let xm = 0.5 * (c - b);
        if xm.abs() <= tol1 || fb == 0.0 {
            return Ok(b);
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * xm * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * xm * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            }
            p = p.abs();
            let min1 = 3.0 * xm * q - (tol1 * q).abs();
            let min2 = (e * q).abs();
            if 2.0 * p < min1.min(min2) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol1 {
            d
        } else if xm >= 0.0 {
            tol1
        } else {
            -tol1
        };
        fb = g(b)?;
        if !fb.is_finite() {
            return Err(StabilityError::BadInput(format!(
                "brent: non-finite function value at {b}"
            )));
        }
    }
    Err(StabilityError::RootNotFound {
        iterations: max_iter,
        lo: lo0,
        hi: hi0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_roots_to_tolerance() {
        // cos(p) = p at p = 0.739085133215160641655312087673873404... (Dottie number).
        let dottie = 0.739_085_133_215_160_6_f64;
        let g = |p: f64| Ok(p.cos() - p);
        let r = brent(g, (0.0, 1.0), (1.0, 1f64.cos() - 1.0), 1e-14, 0.0, 100).unwrap();
        assert!((r - dottie).abs() < 2e-14, "{r}");
        // A cube-root singularity and a flat plateau: still bracketed.
        let g = |p: f64| Ok((p - 0.3).cbrt());
        let r = brent(
            g,
            (0.0, g(0.0).unwrap()),
            (1.0, g(1.0).unwrap()),
            1e-12,
            0.0,
            200,
        )
        .unwrap();
        assert!((r - 0.3).abs() < 1e-12, "{r}");
        assert!(brent(Ok, (1.0, 1.0), (2.0, 2.0), 1e-10, 0.0, 10).is_err());
    }

    #[test]
    fn critical_rejects_bad_input() {
        let f = |p: f64| Ok((p, 1.0));
        let o = CriticalOptions::default();
        assert!(matches!(
            critical(f, 1.0, 1.0, &o),
            Err(StabilityError::BadInterval { .. })
        ));
        assert!(critical(f, 0.0, f64::NAN, &o).is_err());
        let bad = CriticalOptions { grid: 1, ..o };
        assert!(critical(f, 0.0, 1.0, &bad).is_err());
        // No change of stability: None.
        assert_eq!(critical(|_| Ok((-1.0, 1.0)), 0.0, 1.0, &o).unwrap(), None);
    }

    #[test]
    fn critical_locates_linear_and_neutral_crossings() {
        // σ = 0.3 − p (stabilising at p = 0.3).
        let o = CriticalOptions {
            rtol: 1e-13,
            ..Default::default()
        };
        let c = critical(|p| Ok((0.3 - p, 10.0)), 0.0, 1.0, &o)
            .unwrap()
            .unwrap();
        assert!((c.value - 0.3).abs() < 1e-13, "{}", c.value);
        assert_eq!(c.direction, Direction::Stabilising);
        assert!(!c.from_neutral);
        // Neutral below 0.5, σ = √(p − 0.5) above (coalescence-like).
        let c = critical(|p: f64| Ok(((p - 0.5).max(0.0).sqrt(), 1.0)), 0.0, 1.0, &o)
            .unwrap()
            .unwrap();
        assert!((c.value - 0.5).abs() < 1e-13, "{}", c.value);
        assert_eq!(c.direction, Direction::Destabilising);
        assert!(c.from_neutral);
    }
}
