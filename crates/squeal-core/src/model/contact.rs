//! One frictional contact: the piece of physics every model with friction
//! shares (MODEL.md §3–4), written once. A contact has a normal force (a
//! Kelvin–Voigt layer `F_n = k·δ + c·δ̇` on a compression `δ = n·q`, unilateral
//! or bilateral, or a prescribed load), a sliding velocity `v = V + t·q̇`, a
//! friction law μ(|v|) and an optional follower force. Its mode is slip+,
//! slip−, stick or free.
//!
//! The transition logic of a contact is here once, for every model — the
//! hand-written disc–pad, belt and Hoffmann models and the lumped models:
//!
//! - [`friction_mode`]: the mode of a contact that touches, from the sign of
//!   its sliding velocity, and at `v = 0` stick or slip by the force needed
//!   to stick ([`stick_or_slip`], MODEL.md §4);
//! - the guards of a mode as affine functions `g = c·z + d` of the state
//!   (an event when `g` crosses zero upwards): [`slip_zero_guard`] (`−s·v`),
//!   [`stick_break_guards`] (`±F_s − μ_s·F_n`), [`separation_guard`]
//!   (`−F_n`); an open contact's guard is its closing quantity itself;
//! - [`after_guard`]: the next mode and the event when a guard fires
//!   ([`friction_event`] names friction events).
//!
//! A model supplies only what is its own: the affine forms of its sliding
//! velocity, normal force and stick force, and where the state is projected
//! onto a switching surface.

use super::{friction_event, stick_or_slip, EventKind, GuardKind, Mode};

/// An affine function of the state `g(z) = c·z + d`: `(c, d)`.
pub type Affine<const N: usize> = ([f64; N], f64);

/// The friction mode of a contact that touches: slip+ for `v > 0`, slip−
/// for `v < 0`, and at `v = 0` stick if the force needed to stick,
/// `f_stick`, is within `bound = μ_s·max(F_n, 0)`, else slip in its
/// direction ([`stick_or_slip`]).
#[inline]
pub fn friction_mode(v: f64, f_stick: f64, bound: f64) -> Mode {
    if v > 0.0 {
        Mode::SlipPos
    } else if v < 0.0 {
        Mode::SlipNeg
    } else {
        stick_or_slip(f_stick, bound)
    }
}

/// The guard of a slip mode: `g = −s·v` (s = ±1 the slip direction), which
/// crosses zero upwards when the sliding velocity `v = c·z + d` reaches
/// zero. Zero coefficients stay zero.
#[inline]
pub fn slip_zero_guard<const N: usize>(mode: Mode, v: &Affine<N>) -> Affine<N> {
    let s = mode.slip_sign();
    let mut c = [0.0; N];
    for (ci, vi) in c.iter_mut().zip(&v.0) {
        if *vi != 0.0 {
            *ci = -s * vi;
        }
    }
    (c, -s * v.1)
}

/// The two guards of stick, `+F_s − μ_s·F_n` ([`GuardKind::StickBreakPos`])
/// and `−F_s − μ_s·F_n` ([`GuardKind::StickBreakNeg`]), for a stick force
/// `F_s` and the normal force carrying friction `F_n`, both affine.
#[inline]
pub fn stick_break_guards<const N: usize>(
    f_stick: &Affine<N>,
    f_n: &Affine<N>,
    mu_s: f64,
) -> [(GuardKind, Affine<N>); 2] {
    let mut up = [0.0; N];
    let mut dn = [0.0; N];
    for i in 0..N {
        up[i] = f_stick.0[i] - mu_s * f_n.0[i];
        dn[i] = -f_stick.0[i] - mu_s * f_n.0[i];
    }
    [
        (GuardKind::StickBreakPos, (up, f_stick.1 - mu_s * f_n.1)),
        (GuardKind::StickBreakNeg, (dn, -f_stick.1 - mu_s * f_n.1)),
    ]
}

/// The guard of a contact that can open: `−F_n`, crossing zero upwards when
/// the normal force falls to zero.
#[inline]
pub fn separation_guard<const N: usize>(f_n: &Affine<N>) -> Affine<N> {
    (f_n.0.map(|x| -x), 0.0 - f_n.1)
}

/// The next mode of a contact and the event when its `guard` fires in
/// `mode`: at a zero of the sliding velocity, `decide()` (called on the
/// switching surface, e.g. [`friction_mode`] with `v = 0`) and the friction
/// event if the mode changed (stick, slip, reverse); stick breaks into the
/// slip of its sign; separation frees the contact; on closing, `decide()`
/// gives the friction mode in contact.
#[inline]
pub fn after_guard(
    guard: GuardKind,
    mode: Mode,
    decide: impl FnOnce() -> Mode,
) -> (Mode, Option<EventKind>) {
    match guard {
        GuardKind::SlipZero => {
            let next = decide();
            (next, friction_event(mode, next))
        }
        GuardKind::StickBreakPos => (Mode::SlipPos, Some(EventKind::Slip)),
        GuardKind::StickBreakNeg => (Mode::SlipNeg, Some(EventKind::Slip)),
        GuardKind::Separation => (Mode::Free, Some(EventKind::Separate)),
        GuardKind::Contact => (decide(), Some(EventKind::Contact)),
    }
}
use crate::friction::FrictionLaw;

/// A linear combination `Σ coef_k·x_{idx_k}` of degrees of freedom (sparse).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Combination {
    /// Dof indices.
    pub idx: Vec<usize>,
    /// Coefficients, one per index.
    pub coef: Vec<f64>,
}

impl Combination {
    /// `Σ coef_k·x[idx_k]`.
    #[inline]
    pub fn dot(&self, x: &[f64]) -> f64 {
        let mut s = 0.0;
        for (i, c) in self.idx.iter().zip(&self.coef) {
            s += c * x[*i];
        }
        s
    }
    /// `out[idx_k] += a·coef_k`.
    #[inline]
    pub fn add_scaled(&self, out: &mut [f64], a: f64) {
        for (i, c) in self.idx.iter().zip(&self.coef) {
            out[*i] += a * c;
        }
    }
    /// Whether it has no term.
    pub fn is_empty(&self) -> bool {
        self.idx.is_empty()
    }
    /// Dense coefficient vector of length `n`.
    pub fn dense(&self, n: usize) -> Vec<f64> {
        let mut v = vec![0.0; n];
        self.add_scaled(&mut v, 1.0);
        v
    }
    /// `max Σ|coef_k|·max(|lo|, |hi|)` over the box `lo ≤ x ≤ hi` (offset applies to indices).
    pub fn abs_bound(&self, lo: &[f64], hi: &[f64], offset: usize) -> f64 {
        self.idx
            .iter()
            .zip(&self.coef)
            .map(|(i, c)| c.abs() * lo[offset + i].abs().max(hi[offset + i].abs()))
            .sum()
    }
    /// Range `[min, max]` of the combination over the box `lo ≤ x ≤ hi`.
    pub fn range(&self, lo: &[f64], hi: &[f64], offset: usize) -> (f64, f64) {
        let (mut a, mut b) = (0.0, 0.0);
        for (i, c) in self.idx.iter().zip(&self.coef) {
            let (x, y) = (c * lo[offset + i], c * hi[offset + i]);
            a += x.min(y);
            b += x.max(y);
        }
        (a, b)
    }
    /// `Σ|coef_k|·w[offset + idx_k]`.
    pub fn abs_weighted(&self, w: &[f64], offset: usize) -> f64 {
        self.idx
            .iter()
            .zip(&self.coef)
            .map(|(i, c)| c.abs() * w[offset + i])
            .sum()
    }
}

/// How a contact's normal force arises.
#[derive(Debug, Clone, PartialEq)]
pub enum Normal {
    /// A Kelvin–Voigt layer on the compression `δ = normal·q`:
    /// `F_n = k·δ + c·δ̇`, acting as `−F_n·normal`.
    Elastic {
        /// The compression's coefficients.
        normal: Combination,
        /// Layer stiffness (N/m).
        k: f64,
        /// Layer damping (kg/s).
        c: f64,
        /// Bilateral: never opens; friction acts on `max(F_n, 0)`.
        bilateral: bool,
    },
    /// A prescribed normal load (N), as on a belt: no normal dof, never opens.
    Prescribed(f64),
}

/// One frictional contact (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Element name (`pad1`): the prefix of its parameter keys.
    pub name: String,
    /// Normal force law.
    pub normal: Normal,
    /// Sliding velocity `v = V + tangent·q̇`; friction acts as `−F_t·tangent`.
    pub tangent: Combination,
    /// Surface speed V (m/s).
    pub v: f64,
    /// Friction law μ(|v|).
    pub friction: FrictionLaw,
    /// Follower-force coefficient α (1/m): `F_f = α·F_t·(slope·q)`, acting as `+F_f·normal`.
    pub alpha: f64,
    /// The follower force's coordinate combination.
    pub slope: Combination,
}

impl Contact {
    /// Normal force `F_n` at `(q, q̇)` (not clipped).
    #[inline]
    pub fn normal_force(&self, q: &[f64], u: &[f64]) -> f64 {
        match &self.normal {
            Normal::Elastic { normal, k, c, .. } => k * normal.dot(q) + c * normal.dot(u),
            Normal::Prescribed(f) => *f,
        }
    }
    /// The normal force that carries friction: `max(F_n, 0)` for a bilateral layer.
    #[inline]
    pub fn friction_normal(&self, f_n: f64) -> f64 {
        match &self.normal {
            Normal::Elastic {
                bilateral: true, ..
            } => f_n.max(0.0),
            _ => f_n,
        }
    }
    /// Whether the contact can open (an elastic unilateral layer).
    #[inline]
    pub fn can_open(&self) -> bool {
        matches!(
            self.normal,
            Normal::Elastic {
                bilateral: false,
                ..
            }
        )
    }
    /// Sliding velocity `V + tangent·q̇` (summed from V, term by term).
    #[inline]
    pub fn sliding_velocity(&self, u: &[f64]) -> f64 {
        let mut s = self.v;
        for (i, c) in self.tangent.idx.iter().zip(&self.tangent.coef) {
            s += c * u[*i];
        }
        s
    }
    /// Friction force in a slip mode: `s·μ(s·v)·F_n` (the smooth continuation
    /// `s·v`, not `|v|`, so that a step overshooting the guard sees no kink).
    #[inline]
    pub fn slip_force(&self, mode: Mode, v: f64, f_n: f64) -> f64 {
        let s = mode.slip_sign();
        s * self.friction.mu(s * v) * self.friction_normal(f_n)
    }
    /// Stick bound `μ_s·max(F_n, 0)` used to decide stick or slip at `v = 0`.
    #[inline]
    pub fn stick_bound(&self, f_n: f64) -> f64 {
        self.friction.mu_static() * self.friction_normal(f_n).max(0.0)
    }
    /// Mode from the sign of v; at `v = 0`, stick if the force needed to
    /// stick is within the bound, else slip its way (MODEL.md §4).
    #[inline]
    pub fn mode_for(&self, v: f64, f_stick: f64, f_n: f64) -> Mode {
        friction_mode(v, f_stick, self.stick_bound(f_n))
    }
    /// The event for `from → to` at `v = 0`.
    pub fn event(from: Mode, to: Mode) -> Option<EventKind> {
        friction_event(from, to)
    }
}
