//! The general hybrid system the integrator and the stability analysis work
//! on: a mechanical model with any number of frictional contacts, each in its
//! own [`Mode`]; the system's mode is the vector of contact modes ([`Modes`]).
//!
//! Everything a later analysis needs is here, per mode: the vector field
//! ([`System::field`], which in a sticking mode *is* the reduced, constrained
//! dynamics), every guard's value and gradient ([`System::guard_value`],
//! [`System::guard_gradient`]), the reset map ([`System::switch`], which may
//! project the state onto the switching surface), the steady-sliding state and
//! its Jacobian. Saltation matrices of a periodic orbit (Floquet analysis)
//! follow from these alone: `S = P + (f⁺ − P f⁻) ∇gᵀ / (∇g·f⁻)` with `P` the
//! Jacobian of the reset map.
//!
//! Every one-contact [`Model`] is a `System` through a blanket
//! implementation, so the three hand-written models keep their fast paths.

use super::{EventKind, Guard, Guards, Mode, Model, ModelError, Observables};

/// Most contacts a system may have.
pub const MAX_CONTACTS: usize = 8;

/// The mode of every contact: a fixed-capacity vector (no allocation), `Copy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Modes {
    len: u8,
    m: [Mode; MAX_CONTACTS],
}

impl Modes {
    /// One contact in `mode`.
    #[inline]
    pub fn single(mode: Mode) -> Self {
        let mut m = [Mode::Free; MAX_CONTACTS];
        m[0] = mode;
        Modes { len: 1, m }
    }
    /// `n ≤ MAX_CONTACTS` contacts, all in `mode`.
    pub fn all(n: usize, mode: Mode) -> Self {
        assert!(n <= MAX_CONTACTS, "at most {MAX_CONTACTS} contacts");
        let mut m = [Mode::Free; MAX_CONTACTS];
        m[..n].fill(mode);
        Modes { len: n as u8, m }
    }
    /// Number of contacts.
    #[inline]
    pub fn len(&self) -> usize {
        self.len as usize
    }
    /// Whether there is no contact.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Mode of contact `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Mode {
        self.m[i]
    }
    /// Set the mode of contact `i`.
    #[inline]
    pub fn set(&mut self, i: usize, mode: Mode) {
        self.m[i] = mode;
    }
    /// Mode of the first contact (the only one of a [`Model`]).
    #[inline]
    pub fn first(&self) -> Mode {
        self.m[0]
    }
    /// The modes as a slice.
    #[inline]
    pub fn as_slice(&self) -> &[Mode] {
        &self.m[..self.len as usize]
    }
}

/// A frictional mechanical system with `N` states `(q, q̇)` and one or more
/// contacts. The integrator (`integrate`) and the stability analysis
/// (`stability`) are written against this trait; none of the methods
/// the integrator calls in its inner loop may allocate.
pub trait System<const N: usize>: Sync {
    /// Name as typed by users (`disc-pad`, `lumped`, …).
    fn system_name(&self) -> &str;
    /// Names of the state variables, positions first.
    fn names(&self) -> Vec<String>;
    /// Number of contacts (≤ [`MAX_CONTACTS`]).
    fn contacts(&self) -> usize;
    /// Name of contact `i` (`events.csv`'s `contact` column).
    fn contact_name(&self, i: usize) -> &str;
    /// Right-hand side `dz = f(t, z)` in `modes` (in stick: the constrained
    /// dynamics). Every component of `dz` must be written: it holds the last
    /// stage's slope on entry (the integrator writes slopes in place).
    fn field(&self, t: f64, modes: &Modes, z: &[f64; N], dz: &mut [f64; N]);
    /// The guards that end `modes`.
    fn mode_guards(&self, modes: &Modes, out: &mut Guards<N>);
    /// Value of guard `g` at `(t, z)` (affine guards: `c·z + d`).
    #[inline]
    fn guard_value(&self, _t: f64, _modes: &Modes, g: &Guard<N>, z: &[f64; N]) -> f64 {
        g.eval(z)
    }
    /// Gradient `∂g/∂z` of guard `g` at `(t, z)` (affine guards: `c`).
    fn guard_gradient(&self, _t: f64, _modes: &Modes, g: &Guard<N>, _z: &[f64; N]) -> [f64; N] {
        g.c
    }
    /// An upper bound of `|dg/dθ|` along any path `z(θ)`, `θ ∈ [0, 1]`, of a
    /// step from `t0` of length `h` that stays in the box `lo ≤ z ≤ hi` with
    /// `|dz_i/dθ| ≤ rate_i`. Needed for guards that are not affine; the
    /// integrator uses it to prove that no crossing lies between two points.
    #[allow(clippy::too_many_arguments)]
    fn guard_slope_bound(
        &self,
        _t0: f64,
        _h: f64,
        _modes: &Modes,
        g: &Guard<N>,
        _lo: &[f64; N],
        _hi: &[f64; N],
        rate: &[f64; N],
    ) -> f64 {
        (0..N).map(|i| g.c[i].abs() * rate[i]).sum()
    }
    /// The modes after guard `g` fired in `modes` at `(t, z)` (the state may be
    /// projected onto the switching surface), and the event to report (of
    /// contact `g.contact`), if any.
    fn switch(
        &self,
        t: f64,
        modes: &Modes,
        g: &Guard<N>,
        z: &mut [f64; N],
    ) -> (Modes, Option<EventKind>);
    /// The modes a run starts in from `z`.
    fn start_modes(&self, t: f64, z: &[f64; N]) -> Modes;
    /// Forces and sliding velocity of contact `i`.
    fn observe_contact(&self, t: f64, modes: &Modes, z: &[f64; N], i: usize) -> Observables;
    /// The next time after `t` where the field has a kink in time; steps do not cross it.
    fn breakpoint_after(&self, _t: f64) -> Option<f64> {
        None
    }
    /// The distinct frequencies (Hz) of the harmonic forces acting on the
    /// system, ascending; empty for an autonomous system (a ramp's end is
    /// a [`System::breakpoint_after`], not a forcing).
    fn forcing_hz(&self) -> Vec<f64> {
        Vec::new()
    }
    /// The steady-sliding state (all velocities zero, every contact sliding).
    fn steady_sliding(&self) -> Result<[f64; N], ModelError>;
    /// Analytic Jacobian `∂f/∂z` of the sliding equations at `z`.
    fn state_jacobian(&self, z: &[f64; N]) -> [[f64; N]; N];
    /// How many states the integrator's error norm averages over,
    /// `‖e‖ = √(Σ (e_i/sc_i)² / n)`: all `N`, except for a model padded with
    /// idle states that never move ([`crate::model::lumped::padding`]),
    /// whose norm is then the real states' — so it takes the same steps.
    fn norm_states(&self) -> usize {
        N
    }
}

impl<M: Model<N>, const N: usize> System<N> for M {
    fn system_name(&self) -> &str {
        self.name()
    }
    fn names(&self) -> Vec<String> {
        self.state_names().iter().map(|s| s.to_string()).collect()
    }
    fn contacts(&self) -> usize {
        1
    }
    fn contact_name(&self, _i: usize) -> &str {
        self.interface_name()
    }
    #[inline(always)]
    fn field(&self, t: f64, modes: &Modes, z: &[f64; N], dz: &mut [f64; N]) {
        self.rhs(t, modes.first(), z, dz)
    }
    #[inline]
    fn mode_guards(&self, modes: &Modes, out: &mut Guards<N>) {
        self.guards(modes.first(), out)
    }
    fn switch(
        &self,
        t: f64,
        modes: &Modes,
        g: &Guard<N>,
        z: &mut [f64; N],
    ) -> (Modes, Option<EventKind>) {
        let (m, ev) = self.transition(t, modes.first(), g.kind, z);
        (Modes::single(m), ev)
    }
    fn start_modes(&self, t: f64, z: &[f64; N]) -> Modes {
        Modes::single(self.initial_mode(t, z))
    }
    fn observe_contact(&self, t: f64, modes: &Modes, z: &[f64; N], _i: usize) -> Observables {
        self.observe(t, modes.first(), z)
    }
    fn breakpoint_after(&self, t: f64) -> Option<f64> {
        self.next_breakpoint(t)
    }
    fn steady_sliding(&self) -> Result<[f64; N], ModelError> {
        self.equilibrium()
    }
    fn state_jacobian(&self, z: &[f64; N]) -> [[f64; N]; N] {
        self.jacobian(z)
    }
}
