//! Harmonic balance (HB) of self-excited periodic motion: the orbit as a
//! truncated Fourier series of `H` harmonics of an unknown frequency `ω`,
//! for every [`System`] whose states are positions and their velocities.
//!
//! Each real dof `q_i(θ) = a₀ + Σ_k (a_k cos kθ + b_k sin kθ)`, `θ = ωt`,
//! and `q̇_i = ω dq_i/dθ`. The equations of motion `q̈ = a(q, q̇)` (the
//! second half of the model's vector field, in the mode each contact is in
//! at that state) are balanced harmonic by harmonic (Galerkin):
//!
//! ```text
//! R₀ = −⟨a_i⟩,  R_ck = −ω²k² a_k − (1/π)∫ a_i cos kθ dθ,  R_sk = −ω²k² b_k − (1/π)∫ a_i sin kθ dθ,
//! ```
//!
//! closed by the phase condition `b₁ = 0` of the dof with the largest first
//! harmonic (the time origin of an autonomous orbit is free): `n(2H+1)+1`
//! equations for the `n(2H+1)` coefficients and `ω`, solved by Newton's
//! method with a backtracking line search and the Jacobian assembled from
//! the field's own derivatives at the quadrature nodes and the motion of the
//! switching phases (module `jacobian`).
//!
//! **The frequency–time step, exact at switches.** The classic alternating
//! frequency–time scheme samples `a` at equidistant times and takes an FFT.
//! Friction flips sign where the sliding velocity changes sign, and the
//! normal force has a kink where a contact opens: sampled, such a force
//! gives Fourier coefficients with an `O(1/M)` error and a residual that is
//! piecewise *constant* in the unknowns (a switch jumps from one sample to
//! the next), on which Newton's method stalls. Here the period is cut into
//! `P` panels; in every panel where a contact's mode differs between its
//! ends the switching phase is located by bisection (to round-off) and the
//! panel split there, so that the force is smooth on every piece, and each
//! piece is integrated by 4-point Gauss–Legendre quadrature (order 8). The
//! projections are then exact to the quadrature's order, the switching
//! phases move smoothly with the unknowns, and Newton converges
//! quadratically onto the truncated series of the exact non-smooth law:
//! no regularisation. (The nodes are not equidistant, so the projections
//! are direct sums, `n·(2H+1)` per node, rather than an FFT; at the sizes
//! HB is used for this is not the cost that matters.)
//!
//! # Stick: the dynamic Lagrangian step
//!
//! In stick the friction force is a constraint force, not a function of
//! the state. With [`HbOptions::lagrangian`] every phase's friction forces
//! are predicted from the series and the stick-or-slip rules decide each
//! contact's mode there (module `lagrangian`: a dynamic Lagrangian
//! frequency–time step in the velocities, whose limit as `H` grows is the
//! exact non-smooth law, static and kinetic coefficients apart); the
//! switching phases are found and integrated across as above. Without it a
//! sampled orbit whose sliding velocity merely touches zero is reported by
//! [`HbOrbit::sticks`], and callers refuse it.
//!
//! References: Krack & Gross, *Harmonic Balance for Nonlinear Vibration
//! Problems* (Springer 2019), ch. 2–4 (HB, AFT, autonomous systems and the
//! phase condition); Cameron & Griffin, J. Appl. Mech. 56 (1989) 149–154
//! (alternating frequency–time).

pub mod continuation;
pub mod hill;
mod jacobian;
mod lagrangian;
pub mod nma;

use crate::cycle::{autonomous_from, real_indices};
use crate::model::{Mode, Modes, System};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// 4-point Gauss–Legendre nodes and weights on `[−1, 1]`.
const GAUSS: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
];

/// Settings of [`harmonic_balance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HbOptions {
    /// Harmonics `H` kept (besides the mean).
    pub harmonics: usize,
    /// Panels per period (0: `max(64, 8(2H+1))`).
    pub panels: usize,
    /// Newton converges when the largest scaled residual is below this.
    pub newton_tol: f64,
    /// Most Newton iterations.
    pub newton_iterations: usize,
    /// Stick as a constraint: the dynamic Lagrangian step of
    /// [module documentation](self#stick-the-dynamic-lagrangian-step) decides stick
    /// or slip at every phase and gives a sticking contact its constraint
    /// force. Off, friction is slip at the sign of the sliding velocity
    /// (exact for orbits that never stick, and cheaper).
    pub lagrangian: bool,
    /// Factor on the dynamic Lagrangian step's weight `ε = ω/|g·b|` (1 by
    /// default). The exact orbit solves the equations for any `ε > 0`; at
    /// finite `H` the orbit moves slightly with it (measured in the tests).
    pub lagrangian_weight: f64,
}

impl Default for HbOptions {
    fn default() -> Self {
        HbOptions {
            harmonics: 20,
            panels: 0,
            newton_tol: 1e-10,
            newton_iterations: 40,
            lagrangian: false,
            lagrangian_weight: 1.0,
        }
    }
}

impl HbOptions {
    /// The panels per period actually used.
    pub fn panel_count(&self) -> usize {
        if self.panels > 0 {
            self.panels
        } else {
            (8 * (2 * self.harmonics + 1)).max(64)
        }
    }
}

/// Why harmonic balance gave no orbit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HbError {
    /// Bad settings or a model HB cannot take.
    #[error("{0}")]
    Bad(String),
    /// Newton's method did not converge.
    #[error("harmonic balance did not converge: {0}")]
    NotConverged(String),
    /// Newton's method converged onto the steady state (every harmonic
    /// zero solves the equations of an autonomous system for any ω).
    #[error("harmonic balance converged onto steady sliding itself (amplitude {0:.3e} of the guess's): no periodic orbit near the guess")]
    Collapsed(f64),
}

/// A truncated Fourier series of the real dofs' positions at frequency `ω`.
#[derive(Debug, Clone, PartialEq)]
pub struct Fourier {
    /// Angular frequency ω (rad/s).
    pub omega: f64,
    /// Per real dof: `[a₀, a₁, b₁, a₂, b₂, …]` (m), `2H+1` each.
    pub coeffs: Vec<Vec<f64>>,
}

impl Fourier {
    /// Harmonics kept.
    pub fn harmonics(&self) -> usize {
        self.coeffs.first().map_or(0, |c| (c.len() - 1) / 2)
    }

    /// The same series with `h` harmonics (higher ones dropped, missing ones zero).
    pub fn resized(&self, h: usize) -> Fourier {
        Fourier {
            omega: self.omega,
            coeffs: self
                .coeffs
                .iter()
                .map(|c| {
                    let mut d = vec![0.0; 2 * h + 1];
                    let m = d.len().min(c.len());
                    d[..m].copy_from_slice(&c[..m]);
                    d
                })
                .collect(),
        }
    }

    /// The coefficients from `m` equidistant samples per dof over one
    /// period, `samples[i][j] = q_i(2πj/m)` (trapezoidal rule).
    pub fn fit(omega: f64, samples: &[Vec<f64>], h: usize) -> Fourier {
        let coeffs = samples
            .iter()
            .map(|s| {
                let m = s.len() as f64;
                let mut c = vec![0.0; 2 * h + 1];
                c[0] = s.iter().sum::<f64>() / m;
                for k in 1..=h {
                    let (mut a, mut b) = (0.0, 0.0);
                    for (j, q) in s.iter().enumerate() {
                        let th = std::f64::consts::TAU * (k * j) as f64 / m;
                        a += q * th.cos();
                        b += q * th.sin();
                    }
                    c[2 * k - 1] = 2.0 * a / m;
                    c[2 * k] = 2.0 * b / m;
                }
                c
            })
            .collect();
        Fourier { omega, coeffs }
    }

    /// The coefficients of the first `n` position states of an orbit
    /// sampled over one period `period` (times from 0; events as two rows),
    /// resampled at `8(2h+1)` equidistant times by linear interpolation: a
    /// guess for [`harmonic_balance`] from a simulation or a shooting orbit.
    pub fn from_orbit<const N: usize>(
        o: &crate::cycle::Orbit<N>,
        period: f64,
        n: usize,
        h: usize,
    ) -> Fourier {
        let m = (8 * (2 * h + 1)).max(64);
        let mut samples = vec![vec![0.0; m]; n];
        let mut k = 0;
        for j in 0..m {
            let t = period * j as f64 / m as f64;
            while k + 2 < o.t.len() && o.t[k + 1] <= t {
                k += 1;
            }
            let (t0, t1) = (o.t[k], o.t[(k + 1).min(o.t.len() - 1)]);
            let w = if t1 > t0 {
                ((t - t0) / (t1 - t0)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            for (i, s) in samples.iter_mut().enumerate() {
                let (a, b) = (o.z[k][i], o.z[(k + 1).min(o.t.len() - 1)][i]);
                s[j] = a + w * (b - a);
            }
        }
        Fourier::fit(std::f64::consts::TAU / period, &samples, h)
    }

    /// The same orbit at its minimal period: if every harmonic whose
    /// order is not a multiple of some `k ≥ 2` (up to `H/2`) carries less
    /// than `tol` of the oscillating energy `Σ_k a_k² + b_k²`, the series
    /// describes `k` turns of an orbit of frequency `kω` (a settled
    /// simulation's "period" may be several turns): keep the harmonics
    /// `k, 2k, …` as `1, 2, …` of `kω`. The largest such `k` is taken.
    pub fn minimal(&self, tol: f64) -> Fourier {
        let h = self.harmonics();
        let energy = |keep: &dyn Fn(usize) -> bool| -> f64 {
            self.coeffs
                .iter()
                .map(|c| {
                    (1..=h)
                        .filter(|&j| keep(j))
                        .map(|j| c[2 * j - 1].powi(2) + c[2 * j].powi(2))
                        .sum::<f64>()
                })
                .sum()
        };
        let total = energy(&|_| true);
        if total.is_nan() || total <= 0.0 {
            return self.clone();
        }
        let k = (2..=h / 2)
            .rev()
            .find(|&k| energy(&|j| j % k != 0) <= tol * total)
            .unwrap_or(1);
        if k == 1 {
            return self.clone();
        }
        Fourier {
            omega: self.omega * k as f64,
            coeffs: self
                .coeffs
                .iter()
                .map(|c| {
                    let mut d = vec![0.0; 2 * (h / k) + 1];
                    d[0] = c[0];
                    for j in 1..=h / k {
                        d[2 * j - 1] = c[2 * j * k - 1];
                        d[2 * j] = c[2 * j * k];
                    }
                    d
                })
                .collect(),
        }
    }

    /// The same orbit with its time origin moved by `δ` (`q(θ) → q(θ + δ)`).
    pub fn shifted(&self, delta: f64) -> Fourier {
        let mut f = self.clone();
        for c in &mut f.coeffs {
            for k in 1..=(c.len() - 1) / 2 {
                let (s, co) = (k as f64 * delta).sin_cos();
                let (a, b) = (c[2 * k - 1], c[2 * k]);
                c[2 * k - 1] = a * co + b * s;
                c[2 * k] = b * co - a * s;
            }
        }
        f
    }

    /// Amplitude `√(a_k² + b_k²)` of harmonic `k ≥ 1` of dof `i` (m).
    pub fn amplitude(&self, i: usize, k: usize) -> f64 {
        self.coeffs[i][2 * k - 1].hypot(self.coeffs[i][2 * k])
    }

    /// Position and velocity of every real dof at phase `θ`.
    pub fn eval(&self, theta: f64, q: &mut [f64], v: &mut [f64]) {
        let sc = theta.sin_cos();
        for (i, c) in self.coeffs.iter().enumerate() {
            let (x, dx, _) = series_at(c, sc);
            q[i] = x;
            v[i] = self.omega * dx;
        }
    }

    /// Velocity and acceleration of every real dof at phase `θ`, as the
    /// rates `ż = (q̇, q̈)` of the full state (`N` states, idle ones zero).
    pub fn rates<const N: usize>(&self, theta: f64) -> [f64; N] {
        let sc = theta.sin_cos();
        let mut out = [0.0; N];
        for (i, c) in self.coeffs.iter().enumerate() {
            let (_, dx, ddx) = series_at(c, sc);
            out[i] = self.omega * dx;
            out[N / 2 + i] = self.omega * self.omega * ddx;
        }
        out
    }

    /// The full state (`N` states, a padded model's idle ones at rest) at `θ`.
    pub fn state<const N: usize>(&self, theta: f64) -> [f64; N] {
        let n = self.coeffs.len();
        let mut z = [0.0; N];
        let (q, v) = z.split_at_mut(N / 2);
        self.eval(theta, &mut q[..n], &mut v[..n]);
        z
    }
}

/// One dof's series `c = [a₀, a₁, b₁, …]` at the phase whose `(sin θ,
/// cos θ)` is `sc`: `(q, dq/dθ, d²q/dθ²)`, with `cos kθ`, `sin kθ` by the
/// angle-addition recurrence.
#[inline]
fn series_at(c: &[f64], (s1, c1): (f64, f64)) -> (f64, f64, f64) {
    let (mut x, mut dx, mut ddx) = (c[0], 0.0, 0.0);
    let (mut ck, mut sk) = (1.0, 0.0);
    for k in 1..=(c.len() - 1) / 2 {
        let (cn, sn) = (ck * c1 - sk * s1, sk * c1 + ck * s1);
        ck = cn;
        sk = sn;
        let (a, b) = (c[2 * k - 1], c[2 * k]);
        let kf = k as f64;
        x += a * ck + b * sk;
        dx += kf * (b * ck - a * sk);
        ddx -= kf * kf * (a * ck + b * sk);
    }
    (x, dx, ddx)
}

/// A converged harmonic-balance orbit.
#[derive(Debug, Clone)]
pub struct HbOrbit {
    /// The series.
    pub fourier: Fourier,
    /// Largest scaled residual at the end.
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// Fraction of the period each contact spends in each mode
    /// (`[slip+, slip−, stick, free]`, by [`Mode::index`]).
    pub fractions: Vec<[f64; 4]>,
    /// Mode switches per period (all contacts).
    pub switches: usize,
    /// Whether a contact sticks somewhere on the orbit: exact with
    /// [`HbOrbit::lagrangian`]; without it, a sampled state whose sliding
    /// velocity is exactly zero (the scheme is then not exact).
    pub sticks: bool,
    /// Whether stick was a constraint (the dynamic Lagrangian step).
    pub lagrangian: bool,
    /// Panels per period used.
    pub panels: usize,
    /// False if Newton's method stalled above the tolerance but within
    /// [`STALLED`] times it (the orbit is then approximate to `residual`).
    pub converged: bool,
}

/// Newton's method that can lower the residual no further, or runs out of
/// iterations, within this many times the tolerance returns the orbit
/// marked not converged (an orbit that grazes a switch, say, where two
/// switching phases merge and the residual is not smooth); above it, an error.
pub const STALLED: f64 = 1e4;

impl HbOrbit {
    /// Period `2π/ω` (s).
    pub fn period(&self) -> f64 {
        std::f64::consts::TAU / self.fourier.omega
    }
}

/// One smooth piece of the period: `[a, b]` in phase, the modes on it.
#[derive(Clone, Copy)]
struct Piece {
    a: f64,
    b: f64,
    modes: Modes,
}

/// The unknowns of one HB problem: how the coefficients (and `ω`, if
/// unknown) are laid out and scaled in Newton's vector `x`.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    /// Real dofs.
    pub(crate) n: usize,
    pub(crate) h: usize,
    pub(crate) panels: usize,
    /// Scale of each dof's coefficients (m) and of ω (rad/s).
    pub(crate) scale: Vec<f64>,
    pub(crate) omega0: f64,
    /// Autonomous: the dof whose `b₁` is zero (the phase condition), and ω
    /// is an unknown. Forced (`None`): ω is the forcing's.
    pub(crate) phase_dof: Option<usize>,
    /// A nonlinear mode (extended periodic motion concept): the artificial
    /// damping `ξ` is one more unknown, and the phase and amplitude
    /// conditions are the mode's ([`nma`]).
    pub(crate) mode: Option<ModeNorm>,
    /// Stick by the dynamic Lagrangian step ([`HbOptions::lagrangian`]):
    /// `Some(weight)`, the factor on its `ε`.
    pub(crate) lagrangian: Option<f64>,
}

impl Layout {
    pub(crate) fn width(&self) -> usize {
        2 * self.h + 1
    }

    /// Unknowns (and equations): the coefficients, and ω if autonomous.
    pub(crate) fn unknowns(&self) -> usize {
        self.n * self.width()
            + usize::from(self.phase_dof.is_some())
            + usize::from(self.mode.is_some())
    }

    /// `x` of the series `f`.
    pub(crate) fn to_x(&self, f: &Fourier) -> Vec<f64> {
        let w = self.width();
        let mut x = vec![0.0; self.unknowns()];
        for i in 0..self.n {
            for c in 0..w {
                x[i * w + c] = f.coeffs[i][c] / self.scale[i];
            }
        }
        if self.phase_dof.is_some() {
            x[self.n * w] = f.omega / self.omega0;
        }
        x
    }

    /// The series of `x`; `forced`: the forcing's ω (for a forced problem).
    pub(crate) fn to_fourier(&self, x: &[f64], forced: Option<f64>) -> Fourier {
        let w = self.width();
        Fourier {
            omega: match (self.phase_dof, forced) {
                (Some(_), _) => x[self.n * w] * self.omega0,
                (None, Some(om)) => om,
                (None, None) => self.omega0,
            },
            coeffs: (0..self.n)
                .map(|i| (0..w).map(|c| x[i * w + c] * self.scale[i]).collect())
                .collect(),
        }
    }
}

/// The phase and amplitude conditions of a nonlinear mode (module `nma`).
#[derive(Debug, Clone)]
pub(crate) struct ModeNorm {
    /// The mass matrix.
    pub(crate) mass: DMatrix<f64>,
    /// `M φ`.
    pub(crate) m_phi: Vec<f64>,
    /// The prescribed amplitude `A`.
    pub(crate) amplitude: f64,
}

impl ModeNorm {
    /// The scaled residuals `(φᵀ M b₁ / A, (a₁ᵀ M a₁ + b₁ᵀ M b₁)/A² − 1)`.
    pub(crate) fn conditions(&self, f: &Fourier) -> (f64, f64) {
        let n = f.coeffs.len();
        let a = |i: usize| f.coeffs[i][1];
        let b = |i: usize| f.coeffs[i][2];
        let phase: f64 = (0..n).map(|i| self.m_phi[i] * b(i)).sum();
        let mut norm = 0.0;
        for i in 0..n {
            for j in 0..n {
                let mij = self.mass[(i, j)];
                if mij != 0.0 {
                    norm += mij * (a(i) * a(j) + b(i) * b(j));
                }
            }
        }
        let a2 = self.amplitude * self.amplitude;
        (phase / self.amplitude, norm / a2 - 1.0)
    }
}

/// The angular frequency of the harmonic forcing of `sys`, if it is forced
/// at one frequency; an error if at several (no common period is assumed).
pub fn forcing_omega<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
) -> Result<Option<f64>, HbError> {
    match sys.forcing_hz().as_slice() {
        [] => Ok(None),
        [f] => Ok(Some(std::f64::consts::TAU * f)),
        several => Err(HbError::Bad(format!(
            "the model is forced at {} frequencies ({}): harmonic balance here takes one forcing frequency",
            several.len(),
            several
                .iter()
                .map(|f| format!("{f} Hz"))
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

/// The residual of the HB equations for one model and one truncation.
pub(crate) struct Balance<'a, S: ?Sized, const N: usize> {
    pub(crate) sys: &'a S,
    pub(crate) lay: &'a Layout,
    /// Where the period starts: the model is autonomous (or periodic with
    /// the forcing's period) from there.
    pub(crate) t_a: f64,
    /// The forcing's ω, for a forced problem.
    pub(crate) forced: Option<f64>,
}

impl<'a, S: System<N> + ?Sized, const N: usize> Balance<'a, S, N> {
    /// The balance of `sys` on the unknowns `lay`.
    pub(crate) fn new(sys: &'a S, lay: &'a Layout) -> Result<Self, HbError> {
        let forced = forcing_omega(sys)?;
        if forced.is_some() == lay.phase_dof.is_some() {
            return Err(HbError::Bad(if forced.is_some() {
                "the model is forced: its periodic response has the forcing's frequency (use forced_response)".into()
            } else {
                "the model is not forced (no force with an amplitude and freq_hz)".into()
            }));
        }
        Ok(Balance {
            sys,
            lay,
            t_a: crate::cycle::autonomous_from(sys),
            forced,
        })
    }

    fn to_fourier(&self, x: &[f64]) -> Fourier {
        self.lay.to_fourier(x, self.forced)
    }

    /// The model's time at phase `θ` of the series of frequency `omega`.
    #[inline]
    fn time(&self, omega: f64, theta: f64) -> f64 {
        match self.forced {
            Some(_) => self.t_a + theta / omega,
            None => self.t_a,
        }
    }

    fn modes_at(&self, f: &Fourier, theta: f64) -> Modes {
        let t = self.time(f.omega, theta);
        if let Some(w) = self.lay.lagrangian {
            let mut dz = [0.0; N];
            return lagrangian::point(self.sys, f, t, theta, w, None, &mut dz);
        }
        let z: [f64; N] = f.state(theta);
        self.sys.start_modes(t, &z)
    }

    /// The smooth pieces of the period: panels, split where the modes change.
    fn pieces(&self, f: &Fourier) -> Vec<Piece> {
        let p = self.lay.panels;
        let step = std::f64::consts::TAU / p as f64;
        let grid: Vec<Modes> = (0..=p)
            .map(|j| {
                if j == p {
                    self.modes_at(f, 0.0)
                } else {
                    self.modes_at(f, j as f64 * step)
                }
            })
            .collect();
        let mut out = Vec::with_capacity(p + 8);
        for j in 0..p {
            let (a, b) = (j as f64 * step, (j + 1) as f64 * step);
            self.split(f, a, grid[j], b, grid[j + 1], &mut out, 0);
        }
        out
    }

    /// Split `[a, b]` (modes `ma` at `a`, `mb` at `b`) at every mode change.
    #[allow(clippy::too_many_arguments)]
    fn split(
        &self,
        f: &Fourier,
        a: f64,
        ma: Modes,
        b: f64,
        mb: Modes,
        out: &mut Vec<Piece>,
        depth: usize,
    ) {
        if ma == mb || depth > 8 {
            out.push(Piece { a, b, modes: ma });
            return;
        }
        // Bisection: modes are ma at lo, not at hi.
        let (mut lo, mut hi) = (a, b);
        let mut m_hi = mb;
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            let m = self.modes_at(f, mid);
            if m == ma {
                lo = mid;
            } else {
                hi = mid;
                m_hi = m;
            }
        }
        out.push(Piece {
            a,
            b: hi,
            modes: ma,
        });
        if hi < b {
            self.split(f, hi, m_hi, b, mb, out, depth + 1);
        }
    }

    /// The projections `(1/π)∫ a_i basis_c dθ` (mean: `1/2π`) of the
    /// accelerations over `pieces`.
    fn project(&self, f: &Fourier, pieces: &[Piece], xi: f64, proj: &mut [f64]) {
        let (n, h, w) = (self.lay.n, self.lay.h, self.lay.width());
        proj.fill(0.0);
        let mut dz = [0.0; N];
        let mut cs = vec![(0.0, 0.0); h + 1];
        for pc in pieces {
            let (mid, half) = (0.5 * (pc.a + pc.b), 0.5 * (pc.b - pc.a));
            if half <= 0.0 {
                continue;
            }
            for &(xg, wg) in &GAUSS {
                let th = mid + half * xg;
                let wt = half * wg;
                let z: [f64; N] = f.state(th);
                let t = self.time(f.omega, th);
                if let Some(w) = self.lay.lagrangian {
                    lagrangian::point(self.sys, f, t, th, w, Some(&pc.modes), &mut dz);
                } else {
                    self.sys.field(t, &pc.modes, &z, &mut dz);
                }
                let (s1, c1) = th.sin_cos();
                cs[0] = (1.0, 0.0);
                for k in 1..=h {
                    let (c, s) = cs[k - 1];
                    cs[k] = (c * c1 - s * s1, s * c1 + c * s1);
                }
                for i in 0..n {
                    // The extended periodic motion concept's negative
                    // damping ξ M q̇, as an acceleration: + ξ q̇.
                    let acc = (dz[N / 2 + i] + xi * z[N / 2 + i]) * wt;
                    let row = &mut proj[i * w..(i + 1) * w];
                    row[0] += acc / std::f64::consts::TAU;
                    for k in 1..=h {
                        row[2 * k - 1] += acc * cs[k].0 / std::f64::consts::PI;
                        row[2 * k] += acc * cs[k].1 / std::f64::consts::PI;
                    }
                }
            }
        }
    }

    /// The scaled residual at `x` (`out` has [`Self::unknowns`] entries).
    pub(crate) fn residual(&self, x: &[f64], out: &mut [f64]) {
        let f = self.to_fourier(x);
        let pieces = self.pieces(&f);
        let lay = self.lay;
        let (n, h, w) = (lay.n, lay.h, lay.width());
        let mut proj = vec![0.0; n * w];
        let xi = match lay.mode {
            Some(_) => x[n * w + 1] * lay.omega0,
            None => 0.0,
        };
        self.project(&f, &pieces, xi, &mut proj);
        let om2 = f.omega * f.omega;
        let norm = lay.omega0 * lay.omega0;
        for i in 0..n {
            let c = &f.coeffs[i];
            let r = &mut out[i * w..(i + 1) * w];
            r[0] = -proj[i * w] / (norm * lay.scale[i]);
            for k in 1..=h {
                let kk = (k * k) as f64;
                for j in [2 * k - 1, 2 * k] {
                    r[j] = (-om2 * kk * c[j] - proj[i * w + j]) / (norm * lay.scale[i]);
                }
            }
        }
        if let Some(mn) = &lay.mode {
            let (phase, amplitude) = mn.conditions(&f);
            out[n * w] = phase;
            out[n * w + 1] = amplitude;
        } else if let Some(d) = lay.phase_dof {
            out[n * w] = x[d * w + 2];
        }
    }

    /// The orbit at the solution `x`: its series, the time each contact
    /// spends in each mode, the switches, whether it sticks.
    pub(crate) fn orbit(
        &self,
        x: &[f64],
        residual: f64,
        iterations: usize,
        converged: bool,
    ) -> HbOrbit {
        let fourier = self.to_fourier(x);
        let pieces = self.pieces(&fourier);
        let contacts = self.sys.contacts();
        let mut fractions = vec![[0.0; 4]; contacts];
        let mut switches = 0;
        let mut sticks = false;
        for (k, pc) in pieces.iter().enumerate() {
            for (c, fr) in fractions.iter_mut().enumerate() {
                let mode = pc.modes.get(c);
                fr[mode.index()] += (pc.b - pc.a) / std::f64::consts::TAU;
                sticks |= mode == Mode::Stick;
            }
            let next = &pieces[(k + 1) % pieces.len()];
            switches += (0..contacts)
                .filter(|&c| next.modes.get(c) != pc.modes.get(c))
                .count();
        }
        HbOrbit {
            fourier,
            residual,
            iterations,
            fractions,
            switches,
            sticks,
            lagrangian: self.lay.lagrangian.is_some(),
            panels: self.lay.panels,
            converged,
        }
    }
}

pub(crate) fn max_abs(r: &[f64]) -> f64 {
    r.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

pub(crate) fn norm2(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The Jacobian of `residual` at `x` (residual `r`) by forward
/// differences, one column per unknown, in parallel (each column is
/// computed alone, so the result does not depend on the thread count).
pub(crate) fn fd_jacobian(
    residual: &(dyn Fn(&[f64], &mut [f64]) + Sync),
    x: &[f64],
    r: &[f64],
) -> DMatrix<f64> {
    let m = r.len();
    let cols: Vec<Vec<f64>> = (0..x.len())
        .into_par_iter()
        .map(|j| {
            let mut xp = x.to_vec();
            let dh = 1e-7 * x[j].abs().max(1.0);
            xp[j] += dh;
            let mut rp = vec![0.0; m];
            residual(&xp, &mut rp);
            rp.iter().zip(r).map(|(a, b)| (a - b) / dh).collect()
        })
        .collect();
    DMatrix::from_fn(m, x.len(), |i, j| cols[j][i])
}

/// The Jacobian at `x` (residual `r`) of a Newton problem; with
/// `differences`, by finite differences of the residual rather than
/// assembled (see [`newton`]).
pub(crate) type JacobianFn<'a> = dyn Fn(&[f64], &[f64], bool) -> DMatrix<f64> + 'a;

/// What [`newton`] ended with.
pub(crate) struct Solved {
    pub(crate) x: Vec<f64>,
    pub(crate) residual: f64,
    pub(crate) iterations: usize,
    /// False if it stalled within [`STALLED`] times the tolerance.
    pub(crate) converged: bool,
}

/// Newton's method on `residual(x) = 0` (as many equations as unknowns)
/// with the Jacobian `jacobian(x, r, differences)` and a backtracking line
/// search on the residual's 2-norm; `admissible` rejects trial points
/// (ω ≤ 0, say). The Jacobian is the assembled one until Newton's method
/// slows down and it disagrees with the residual's derivative along the
/// step, then by differences.
/// `what` names the problem in errors.
pub(crate) fn newton(
    residual: &dyn Fn(&[f64], &mut [f64]),
    jacobian: &JacobianFn<'_>,
    admissible: &dyn Fn(&[f64]) -> bool,
    x0: Vec<f64>,
    tol: f64,
    max_iterations: usize,
    what: &str,
) -> Result<Solved, HbError> {
    let m = x0.len();
    let mut x = x0;
    let mut r = vec![0.0; m];
    residual(&x, &mut r);
    let mut iterations = 0;
    let mut stalled = false;
    let mut approximate = false;
    let mut differences = false;
    let mut last = f64::INFINITY;
    loop {
        let res = max_abs(&r);
        if !res.is_finite() {
            return Err(HbError::NotConverged(format!(
                "the residual is not finite after {iterations} iterations ({what})"
            )));
        }
        if res <= tol || stalled || (res <= 1e2 * tol && res > 0.5 * last) {
            break;
        }
        if iterations >= max_iterations {
            if res <= STALLED * tol {
                approximate = true;
                break;
            }
            return Err(HbError::NotConverged(format!(
                "residual {res:.3e} after {iterations} Newton iterations ({what})"
            )));
        }
        iterations += 1;
        let slow = res > 0.5 * last;
        last = res;
        let rhs = DVector::from_iterator(m, r.iter().map(|v| -v));
        let solve = |jac: DMatrix<f64>| {
            jac.lu().solve(&rhs).ok_or_else(|| {
                HbError::NotConverged(format!(
                    "the Jacobian is singular at iteration {iterations} ({what})"
                ))
            })
        };
        let jac = jacobian(&x, &r, differences);
        let mut dx = solve(jac.clone())?;
        // An assembled Jacobian is exact only where each switch's phase
        // moves smoothly with the unknowns; where Newton's method slows
        // down (the last step did not halve the residual), the Jacobian
        // is checked against the residual's own derivative along the step
        // (central differences) and, if it is off by more than 1e-2,
        // replaced by differences for the rest of the solve.
        if slow && !differences {
            let h = 1e-7 * norm2(&x).max(1.0) / dx.norm().max(f64::MIN_POSITIVE);
            let at = |s: f64| {
                let xs: Vec<f64> = x.iter().zip(dx.iter()).map(|(a, d)| a + s * d).collect();
                let mut rs = vec![0.0; m];
                residual(&xs, &mut rs);
                rs
            };
            let (rp, rm) = (at(h), at(-h));
            let predicted = &jac * &dx;
            let off = rp
                .iter()
                .zip(&rm)
                .zip(predicted.iter())
                .map(|((a, b), p)| ((a - b) / (2.0 * h) - p).powi(2))
                .sum::<f64>()
                .sqrt();
            let agrees = off <= 1e-2 * predicted.norm(); // false if NaN
            if !agrees {
                differences = true;
                dx = solve(jacobian(&x, &r, true))?;
            }
        }
        // Backtracking on the residual's 2-norm.
        let r0 = norm2(&r);
        let mut lambda = 1.0;
        let mut rt = vec![0.0; m];
        loop {
            let xt: Vec<f64> = x
                .iter()
                .zip(dx.iter())
                .map(|(a, d)| a + lambda * d)
                .collect();
            if admissible(&xt) {
                residual(&xt, &mut rt);
                if norm2(&rt) < r0 || lambda < 1e-3 {
                    x = xt;
                    std::mem::swap(&mut r, &mut rt);
                    break;
                }
            }
            lambda *= 0.5;
            if lambda < 1e-3 {
                // At the round-off floor of the projections: converged.
                if max_abs(&r) <= 1e2 * tol {
                    stalled = true;
                    break;
                }
                if max_abs(&r) <= STALLED * tol {
                    stalled = true;
                    approximate = true;
                    break;
                }
                return Err(HbError::NotConverged(format!(
                    "no Newton step lowers the residual {:.3e} (iteration {iterations}, {what})",
                    max_abs(&r)
                )));
            }
        }
    }
    Ok(Solved {
        residual: max_abs(&r),
        x,
        iterations,
        converged: !approximate,
    })
}

/// Check that the first half of the field of `sys` is the velocities
/// (`q̇ = v`), as HB's second-order form needs.
fn check_second_order<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    guess: &Fourier,
    n: usize,
) -> Result<(), HbError> {
    let t_a = autonomous_from(sys);
    let z: [f64; N] = guess.state(0.3);
    let mut dz = [0.0; N];
    sys.field(t_a, &sys.start_modes(t_a, &z), &z, &mut dz);
    if (0..n).any(|i| dz[i] != z[N / 2 + i]) {
        return Err(HbError::Bad(format!(
            "{}: harmonic balance needs states that are positions and their velocities",
            sys.system_name()
        )));
    }
    Ok(())
}

/// The checked guess resized to `opts.harmonics`, and the number of real dofs.
fn checked_guess<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    guess: &Fourier,
    opts: &HbOptions,
) -> Result<(Fourier, usize), HbError> {
    let real = real_indices(sys);
    let n = real.len() / 2;
    if guess.coeffs.len() != n {
        return Err(HbError::Bad(format!(
            "the guess has {} dofs, the model {n}",
            guess.coeffs.len()
        )));
    }
    if opts.harmonics == 0 {
        return Err(HbError::Bad("harmonics: must be at least 1".into()));
    }
    if !(guess.omega > 0.0 && guess.omega.is_finite()) {
        return Err(HbError::Bad(format!(
            "the guess's frequency {} rad/s",
            guess.omega
        )));
    }
    let guess = guess.resized(opts.harmonics);
    check_second_order(sys, &guess, n)?;
    Ok((guess, n))
}

/// Largest harmonic amplitude of each dof of `f`.
fn harmonic_amplitudes(f: &Fourier) -> Vec<f64> {
    let h = f.harmonics();
    (0..f.coeffs.len())
        .map(|i| (1..=h).map(|k| f.amplitude(i, k)).fold(0.0, f64::max))
        .collect()
}

/// Solve the HB equations of the autonomous system `sys` from the guess
/// `guess` (any number of harmonics: it is truncated or padded to
/// `opts.harmonics`), module documentation. The guess should be close: a
/// settled simulation's last period, or a neighbouring solution.
pub fn harmonic_balance<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    guess: &Fourier,
    opts: &HbOptions,
) -> Result<HbOrbit, HbError> {
    if let Some(om) = forcing_omega(sys)? {
        return Err(HbError::Bad(format!(
            "the model is forced at {:.6} Hz: its periodic response has the forcing's frequency (forced response, not a self-excited orbit)",
            om / std::f64::consts::TAU
        )));
    }
    let (guess, n) = checked_guess(sys, guess, opts)?;
    let h = opts.harmonics;
    let amp = harmonic_amplitudes(&guess);
    let top = amp.iter().cloned().fold(0.0, f64::max);
    if !(top > 0.0 && top.is_finite()) {
        return Err(HbError::Bad(
            "the guess does not oscillate (zero first harmonics)".into(),
        ));
    }
    let phase_dof = (0..n)
        .max_by(|&a, &b| guess.amplitude(a, 1).total_cmp(&guess.amplitude(b, 1)))
        .unwrap_or(0);
    let delta = guess.coeffs[phase_dof][2].atan2(guess.coeffs[phase_dof][1]);
    let guess = guess.shifted(delta);
    let lay = Layout {
        n,
        h,
        panels: opts.panel_count(),
        scale: amp.iter().map(|a| a.max(1e-6 * top)).collect(),
        omega0: guess.omega,
        phase_dof: Some(phase_dof),
        mode: None,
        lagrangian: opts.lagrangian.then_some(opts.lagrangian_weight),
    };
    let bal = Balance::<S, N>::new(sys, &lay)?;
    let m = lay.unknowns();
    let res = |x: &[f64], out: &mut [f64]| bal.residual(x, out);
    let solved = newton(
        &res,
        &|x, r, d| bal.jacobian(x, r, d),
        &|x| x[m - 1] > 0.0,
        lay.to_x(&guess),
        opts.newton_tol,
        opts.newton_iterations,
        &format!("H = {h}"),
    )?;
    let fourier = bal.to_fourier(&solved.x);
    let left = harmonic_amplitudes(&fourier)
        .into_iter()
        .fold(0.0, f64::max);
    // Collapsed onto the steady state: relative to the guess, or to the
    // static state itself (an "orbit" of 1e-9 of the static deflection is
    // steady sliding whatever the guess; Newton's method may stall near it
    // rather than converge, and a stalled one below 1e-6 counts too).
    let mean = fourier.coeffs.iter().fold(0.0f64, |m, c| m.max(c[0].abs()));
    let floor = if solved.converged { 1e-9 } else { 1e-6 };
    if left < 1e-6 * top || left < floor * mean {
        return Err(HbError::Collapsed(left / top));
    }
    Ok(bal.orbit(
        &solved.x,
        solved.residual,
        solved.iterations,
        solved.converged,
    ))
}

/// The coefficient scales of a forced problem: each dof's largest harmonic
/// amplitude in `guess`, floored at 1e-6 of the largest, and, where the
/// guess does not move at all, at `floor` (m).
pub(crate) fn forced_scales(guess: &Fourier, floor: f64) -> Vec<f64> {
    let amp = harmonic_amplitudes(guess);
    let top = amp.iter().cloned().fold(0.0, f64::max);
    let base = if top > 0.0 && top.is_finite() {
        top
    } else {
        floor
    };
    amp.iter().map(|a| a.max(1e-6 * base)).collect()
}

/// The periodic response of the system `sys` forced harmonically at one
/// frequency `Ω` (its [`System::forcing_hz`]): the same Galerkin
/// equations as [`harmonic_balance`] with `ω = Ω` given, so no phase
/// condition (the forcing fixes the time origin: the force is
/// `amplitude·cos Ωt` at phase `θ = Ωt`). `guess` gives the starting
/// coefficients (its `omega` is ignored); a series of zero harmonics at
/// the static state is a valid guess. Krack & Gross (2019), ch. 2.
pub fn forced_response<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    guess: &Fourier,
    opts: &HbOptions,
) -> Result<HbOrbit, HbError> {
    let Some(omega) = forcing_omega(sys)? else {
        return Err(HbError::Bad(
            "the model is not forced: give a [[force]] an amplitude and freq_hz".into(),
        ));
    };
    let mut g = guess.clone();
    g.omega = omega;
    let (guess, n) = checked_guess(sys, &g, opts)?;
    let h = opts.harmonics;
    let lay = Layout {
        n,
        h,
        panels: opts.panel_count(),
        scale: forced_scales(&guess, 1.0),
        omega0: omega,
        phase_dof: None,
        mode: None,
        lagrangian: opts.lagrangian.then_some(opts.lagrangian_weight),
    };
    let bal = Balance::<S, N>::new(sys, &lay)?;
    let res = |x: &[f64], out: &mut [f64]| bal.residual(x, out);
    let solved = newton(
        &res,
        &|x, r, d| bal.jacobian(x, r, d),
        &|_| true,
        lay.to_x(&guess),
        opts.newton_tol,
        opts.newton_iterations,
        &format!("H = {h}"),
    )?;
    Ok(bal.orbit(
        &solved.x,
        solved.residual,
        solved.iterations,
        solved.converged,
    ))
}
