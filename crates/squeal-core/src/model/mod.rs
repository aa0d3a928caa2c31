//! Models: vector fields per contact mode, event functions (guards) per mode,
//! and the rules that pick the next mode when a guard fires.
//!
//! A model is a plug-in: the integrator (`integrate`) knows nothing
//! of brakes. Every model here is mechanical, with state `z = (q, q̇)`, and
//! every guard is affine in the state, `g(z) = c·z + d`, so along a step of the
//! dense output it is a polynomial whose roots can all be found (MODEL.md §8).

pub mod belt;
pub mod contact;
pub mod disc_pad;
pub mod hoffmann;
pub mod lane_field;
pub mod lumped;
pub mod system;

pub use system::{Modes, System, MAX_CONTACTS};

use crate::params::{ParamError, ParamSpec};

/// Contact/friction mode of a frictional interface. The thesis's flag is
/// [`Mode::flag`]: 0 slip, 1 stick, 2 no contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Sliding with relative velocity v > 0.
    SlipPos,
    /// Sliding with relative velocity v < 0.
    SlipNeg,
    /// Sticking: v ≡ 0, the friction force is whatever keeps it so.
    Stick,
    /// No contact: no normal force, no friction.
    Free,
}

impl Mode {
    /// The thesis's flag: 0 slip, 1 stick, 2 no contact.
    pub fn flag(self) -> u8 {
        match self {
            Mode::SlipPos | Mode::SlipNeg => 0,
            Mode::Stick => 1,
            Mode::Free => 2,
        }
    }

    /// Index 0..4 for per-mode bookkeeping.
    pub fn index(self) -> usize {
        match self {
            Mode::SlipPos => 0,
            Mode::SlipNeg => 1,
            Mode::Stick => 2,
            Mode::Free => 3,
        }
    }

    /// Direction of sliding: +1, −1, or 0 for stick/free.
    pub fn slip_sign(self) -> f64 {
        match self {
            Mode::SlipPos => 1.0,
            Mode::SlipNeg => -1.0,
            _ => 0.0,
        }
    }
}

/// What an event is, as reported to users (`events.csv`'s `kind` column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EventKind {
    /// Slip → stick.
    Stick,
    /// Stick → slip.
    Slip,
    /// Slip reversal: v crosses zero without sticking.
    Reverse,
    /// Loss of contact.
    Separate,
    /// Recontact.
    Contact,
}

impl EventKind {
    /// All kinds, in report order.
    pub const ALL: [EventKind; 5] = [
        EventKind::Stick,
        EventKind::Slip,
        EventKind::Reverse,
        EventKind::Separate,
        EventKind::Contact,
    ];

    /// Name as written to `events.csv`.
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::Stick => "stick",
            EventKind::Slip => "slip",
            EventKind::Reverse => "reverse",
            EventKind::Separate => "separate",
            EventKind::Contact => "contact",
        }
    }

    /// Index into [`EventKind::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// Which switching surface a guard describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GuardKind {
    /// The sliding velocity reaches zero (in slip).
    SlipZero,
    /// The stick force exceeds +μ_s·F_n (in stick).
    StickBreakPos,
    /// The stick force falls below −μ_s·F_n (in stick).
    StickBreakNeg,
    /// The normal force reaches zero (in contact).
    Separation,
    /// The gap closes (no contact).
    Contact,
}

/// An event function, negative inside the mode's domain; the event fires
/// where it crosses zero upwards. Most guards are affine, `g(z) = c·z + d`;
/// a guard with `affine == false` is evaluated by
/// [`System::guard_value`] (`c`, `d` are then unused) and searched for with a
/// Lipschitz bound ([`System::guard_slope_bound`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Guard<const N: usize> {
    /// The surface it describes.
    pub kind: GuardKind,
    /// Gradient of g (affine guards).
    pub c: [f64; N],
    /// Constant term of g (affine guards).
    pub d: f64,
    /// Index of the contact the guard belongs to (0 for one-contact models).
    pub contact: u8,
    /// Whether `g(z) = c·z + d` exactly.
    pub affine: bool,
}

impl<const N: usize> Guard<N> {
    /// Value of g at `z`.
    #[inline]
    pub fn eval(&self, z: &[f64; N]) -> f64 {
        let mut s = self.d;
        for i in 0..N {
            s += self.c[i] * z[i];
        }
        s
    }
}

/// Most guards any mode has: two per contact, at most [`MAX_CONTACTS`] contacts.
pub const MAX_GUARDS: usize = 2 * MAX_CONTACTS;

/// The guards of one mode: a fixed-capacity list (no allocation).
#[derive(Debug, Clone, Copy)]
pub struct Guards<const N: usize> {
    len: usize,
    items: [Guard<N>; MAX_GUARDS],
}

impl<const N: usize> Default for Guards<N> {
    fn default() -> Self {
        Guards {
            len: 0,
            items: [Guard {
                kind: GuardKind::SlipZero,
                c: [0.0; N],
                d: 0.0,
                contact: 0,
                affine: true,
            }; MAX_GUARDS],
        }
    }
}

impl<const N: usize> Guards<N> {
    /// Remove all guards.
    pub fn clear(&mut self) {
        self.len = 0;
    }
    /// Add an affine guard of contact 0.
    pub fn push(&mut self, kind: GuardKind, c: [f64; N], d: f64) {
        self.push_guard(Guard {
            kind,
            c,
            d,
            contact: 0,
            affine: true,
        });
    }
    /// Add a guard.
    pub fn push_guard(&mut self, g: Guard<N>) {
        assert!(
            self.len < MAX_GUARDS,
            "a mode has at most {MAX_GUARDS} guards"
        );
        self.items[self.len] = g;
        self.len += 1;
    }
    /// Number of guards.
    pub fn len(&self) -> usize {
        self.len
    }
    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// The guards as a slice.
    pub fn as_slice(&self) -> &[Guard<N>] {
        &self.items[..self.len]
    }
}

/// Forces and sliding velocity at the interface, derived from a state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Observables {
    /// Normal (contact) force, compressive positive (N). 0 without contact.
    pub normal_force: f64,
    /// Friction force on the slider (pad / mass) (N).
    pub friction_force: f64,
    /// Sliding velocity v of the moving surface relative to the slider (m/s).
    pub v_rel: f64,
}

/// Model failures that are not bad parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A parameter is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// No steady-sliding state exists (V = 0, or a follower force so strong
    /// that the normal force diverges).
    #[error("no steady sliding: {0}")]
    NoSteadySliding(String),
}

/// A frictional mechanical model with `N` states `(q, q̇)`.
///
/// Implementations give the vector field in each [`Mode`], the guards that
/// end each mode, and the transition rule. The integrator calls nothing else
/// in its inner loop; none of these may allocate.
pub trait Model<const N: usize>: Sync {
    /// Model name as typed by users (`disc-pad`, `belt`, …).
    fn name(&self) -> &'static str;
    /// Names of the state variables, positions first (e.g. `x_d`, …, `vy_p`).
    fn state_names(&self) -> [&'static str; N];
    /// Right-hand side `dz = f(t, z)` in `mode`.
    fn rhs(&self, t: f64, mode: Mode, z: &[f64; N], dz: &mut [f64; N]);
    /// The guards active in `mode` (they must not depend on time).
    fn guards(&self, mode: Mode, out: &mut Guards<N>);
    /// The mode after `guard` fired in `mode` at state `z` (which it may
    /// project onto the switching surface), and the event to report, if any.
    fn transition(
        &self,
        t: f64,
        mode: Mode,
        guard: GuardKind,
        z: &mut [f64; N],
    ) -> (Mode, Option<EventKind>);
    /// The mode a run starts in from state `z`.
    fn initial_mode(&self, t: f64, z: &[f64; N]) -> Mode;
    /// Name of the frictional interface (`events.csv`'s `contact` column).
    fn interface_name(&self) -> &'static str {
        "contact"
    }
    /// Interface forces and sliding velocity.
    fn observe(&self, t: f64, mode: Mode, z: &[f64; N]) -> Observables;
    /// The next time after `t` at which the vector field has a kink in time
    /// (e.g. the end of a force ramp); steps do not cross it.
    fn next_breakpoint(&self, _t: f64) -> Option<f64> {
        None
    }
    /// The steady-sliding equilibrium (all velocities zero, v = V). Models
    /// with a closed form override this; the default solves for it by
    /// Newton's method on the slip equations ([`newton_equilibrium`]).
    fn equilibrium(&self) -> Result<[f64; N], ModelError> {
        newton_equilibrium(self, &[0.0; N])
    }
    /// Analytic Jacobian ∂f/∂z of the slip equations (mode [`Mode::SlipPos`]) at `z`.
    fn jacobian(&self, z: &[f64; N]) -> [[f64; N]; N];
}

/// A model's named parameters: get, set and list them by their ASCII keys.
pub trait Parameters {
    /// The model's own parameters (not the friction law's).
    fn param_specs(&self) -> &'static [ParamSpec];
    /// Value of a parameter (model or friction law) by name.
    fn get(&self, key: &str) -> Option<f64>;
    /// Set a parameter (model or friction law) by name, checking its sign.
    fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError>;
    /// The model's friction law.
    fn friction_law(&self) -> &crate::FrictionLaw;
    /// Check every parameter's sign and the relations between them (the
    /// friction law's included).
    fn validate(&self) -> Result<(), ParamError> {
        for spec in self.param_specs() {
            spec.check(self.get(spec.name).unwrap_or(f64::NAN))?;
        }
        self.friction_law().validate()
    }
}

/// Shared decision when the sliding velocity reaches zero, or contact is
/// made with zero sliding velocity: stick if the force needed to stick,
/// `f_stick`, is within `mu_s·f_n`; otherwise slip in the direction of
/// `f_stick` (MODEL.md §4).
#[inline]
pub fn stick_or_slip(f_stick: f64, bound: f64) -> Mode {
    if f_stick.abs() <= bound {
        Mode::Stick
    } else if f_stick > 0.0 {
        Mode::SlipPos
    } else {
        Mode::SlipNeg
    }
}

/// Event kind for a change of friction mode `from → to` at a zero of `v`.
#[inline]
pub fn friction_event(from: Mode, to: Mode) -> Option<EventKind> {
    match (from, to) {
        (a, b) if a == b => None,
        (_, Mode::Stick) => Some(EventKind::Stick),
        (Mode::Stick, _) => Some(EventKind::Slip),
        (Mode::SlipPos, Mode::SlipNeg) | (Mode::SlipNeg, Mode::SlipPos) => Some(EventKind::Reverse),
        _ => None,
    }
}

/// Steady sliding by Newton's method: positions `q` with zero velocities such
/// that the slip accelerations (mode [`Mode::SlipPos`]) vanish, starting from
/// the positions of `guess`. The Newton matrix is the position block of the
/// model's analytic Jacobian; each iteration solves it by LU with partial
/// pivoting. Converges when the update is below 1e-14 of the positions' size.
pub fn newton_equilibrium<M: Model<N> + ?Sized, const N: usize>(
    model: &M,
    guess: &[f64; N],
) -> Result<[f64; N], ModelError> {
    let n = N / 2;
    let mut f = [0.0; N];
    let q = newton_positions(
        &guess[..n],
        |q| {
            let mut z = [0.0; N];
            z[..n].copy_from_slice(q);
            model.rhs(f64::INFINITY, Mode::SlipPos, &z, &mut f);
            let j = model.jacobian(&z);
            (
                nalgebra::DMatrix::from_fn(n, n, |r, c| j[n + r][c]),
                nalgebra::DVector::from_fn(n, |r, _| f[n + r]),
            )
        },
        "the steady-sliding equations are singular",
    )?;
    let mut z = [0.0; N];
    z[..n].copy_from_slice(&q);
    Ok(z)
}

/// Up to this many positions [`newton_positions`] solves with nalgebra's LU;
/// above, with faer's blocked LU.
const NEWTON_SMALL: usize = 64;

/// Newton's method on positions `q` for `r(q) = 0`: `eval(q)` gives the
/// Newton matrix `∂r/∂q` and the residual `r`; each iteration solves by LU
/// with partial pivoting (nalgebra up to 64 positions, faer above). Converges when the update is below 1e-14 of the
/// positions' size (at most 100 iterations); a singular matrix is
/// [`ModelError::NoSteadySliding`] with the message `singular`. Shared by
/// [`newton_equilibrium`] and the lumped models' runtime-size equilibrium.
pub fn newton_positions<F>(q0: &[f64], mut eval: F, singular: &str) -> Result<Vec<f64>, ModelError>
where
    F: FnMut(&[f64]) -> (nalgebra::DMatrix<f64>, nalgebra::DVector<f64>),
{
    let mut q = q0.to_vec();
    for _ in 0..100 {
        let (a, r) = eval(&q);
        let dq = if a.nrows() <= NEWTON_SMALL {
            a.lu()
                .solve(&(-r))
                .ok_or_else(|| ModelError::NoSteadySliding(singular.into()))?
        } else {
            // faer's blocked LU: nalgebra's unblocked one takes seconds at 2000 dofs.
            use faer::linalg::solvers::Solve;
            let n = a.nrows();
            let lu =
                faer::MatRef::from_column_major_slice(a.as_slice(), n, a.ncols()).partial_piv_lu();
            let x = lu.solve(faer::Mat::<f64>::from_fn(n, 1, |i, _| -r[i]));
            let dq = nalgebra::DVector::from_fn(n, |i, _| x[(i, 0)]);
            if dq.iter().any(|d| !d.is_finite()) {
                return Err(ModelError::NoSteadySliding(singular.into()));
            }
            dq
        };
        let size = q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let step = dq.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for (qi, d) in q.iter_mut().zip(dq.iter()) {
            *qi += d;
        }
        if !step.is_finite() {
            break;
        }
        if step <= 1e-14 * size.max(f64::MIN_POSITIVE) || step == 0.0 {
            return Ok(q);
        }
    }
    Err(ModelError::NoSteadySliding(
        "Newton's method did not converge on the steady-sliding state".into(),
    ))
}
