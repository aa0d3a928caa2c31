//! Stick in harmonic balance: a dynamic Lagrangian frequency–time step in
//! the velocities (after Nacivet, Pierre, Thouverez & Jézéquel, J. Sound
//! Vib. 265 (2003) 201–219, whose displacement form it follows), written
//! against any [`System`], with the exact non-smooth law as its limit.
//!
//! In stick a contact's friction force is a constraint force, not a
//! function of the state, and a truncated series cannot hold a sliding
//! velocity at zero over an interval. At every phase of the period the
//! friction force `λ_i` of each touching contact is therefore *predicted*
//! from the series itself:
//!
//! ```text
//! λ_X = λ_b + (G B)⁻¹ G (ż_series − f(z, modes_b)),     λ_p = λ_X + ε v,
//! ```
//!
//! where `modes_b` lets every touching contact slip in the direction of its
//! sliding velocity `v_i` (friction force `λ_b`), `G` holds the gradients
//! `∂v_i/∂z`, and `B` the accelerations per unit friction force,
//! `b_i = ∂f/∂λ_i` (the field is affine in the friction forces). `λ_X` is the
//! friction force the series' own motion implies; `ε_i = ω/|g_i·b_i|` (an
//! effective mass times ω) weighs the sliding velocity against it. Then:
//!
//! - `|λ_p| > μ_s F_n`: slip in the direction of `λ_p`;
//! - else, if `v ≠ 0` and `sign(v)·(λ_p − λ_b) > 0` (the predicted force
//!   goes beyond the slip force in the sliding direction): slip on;
//! - else stick, with `λ = λ_p`: the acceleration is `f(z, modes_b) +
//!   Σ b_i (λ_p,i − λ_b,i)`.
//!
//! In stick the balance along the contact is `g_i·(ż − f) = −ω v_i·sign`:
//! its Galerkin projection drives the sliding velocity to zero in the
//! harmonics kept. The exact orbit satisfies every rule pointwise (in slip
//! `λ_X = λ_b`, so the second rule holds for any `ε > 0`, also where the
//! slip force is below `μ_s F_n`, as in a velocity-weakening law; in stick
//! `v = 0` and `λ_X` is the stick force), so the truncated series converge
//! to the exact non-smooth orbit as `H` grows: `ε` shapes the iteration, not
//! the limit (its effect at finite `H` is measured in the tests). The
//! second rule is what makes this exact for a velocity-weakening law: the
//! classic rule (stick whenever `|λ_p| ≤ μ_s F_n`) would stick early,
//! wherever `ε|v| < (μ_s − μ(|v|)) F_n` before a stop.
//!
//! **Limitation.** Where the static coefficient exceeds the kinetic one at
//! zero speed (Coulomb with `μ_s > μ_k`), a stick force between `μ_k F_n`
//! and `μ_s F_n` is both a stick and a slip state for these history-free
//! rules (the ripple of the series' `v` decides), and Newton's method
//! stalls (the Coulomb belt with `μ_s = 0.4`, `μ_k = 0.3` fails at H = 10
//! and 20). Rules that remember the mode before, marched twice round the
//! period, were tried and stall the same way: just after a breakaway the
//! series' implied force dips below the slip force and sticks again.
//!
//! Every quantity comes from the system's own field, observables and guards:
//! `λ_b` and `v` from [`System::observe_contact`]; `g_i` from the slip-zero
//! guard `−s·v`; the stick force and `μ_s F_n` from the two stick-break
//! guards `±F_s − μ_s F_n`; `b_i` from the field in stick against the field
//! in slip, divided by the difference of their friction forces.

use super::Fourier;
use crate::model::{GuardKind, Guards, Mode, Modes, System, MAX_CONTACTS};
use nalgebra::{SMatrix, SVector};

/// The friction forces of one phase, as predicted and as applied.
struct Contact<const N: usize> {
    /// Whether the contact touches and carries friction here.
    active: bool,
    /// Sliding velocity.
    v: f64,
    /// Its slip mode (the sign of `v`, slip+ at 0).
    slip: Mode,
    /// Friction force in that slip mode.
    lambda_b: f64,
    /// `μ_s F_n`.
    bound: f64,
    /// `∂v/∂z`.
    g: [f64; N],
    /// `∂f/∂λ`.
    b: [f64; N],
}

fn slip_of(v: f64) -> Mode {
    if v < 0.0 {
        Mode::SlipNeg
    } else {
        Mode::SlipPos
    }
}

fn dot<const N: usize>(a: &[f64; N], b: &[f64; N]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The mode of one touching contact from the predicted force `lp`
/// (module documentation).
fn decide<const N: usize>(lp: f64, c: &Contact<N>) -> Mode {
    if lp.abs() > c.bound {
        slip_of(lp)
    } else if c.v != 0.0 && c.slip.slip_sign() * (lp - c.lambda_b) > 0.0 {
        c.slip
    } else {
        Mode::Stick
    }
}

/// The dynamic Lagrangian step at phase `θ` of the series `f` (model time
/// `t`): the contacts' modes (decided by the rules of the module
/// documentation, or `given`, a piece's modes) and the field `dz` there.
pub(crate) fn point<S: System<N> + ?Sized, const N: usize>(
    sys: &S,
    f: &Fourier,
    t: f64,
    theta: f64,
    weight: f64,
    given: Option<&Modes>,
    dz: &mut [f64; N],
) -> Modes {
    let z: [f64; N] = f.state(theta);
    let nc = sys.contacts();
    let m0 = match given {
        Some(g) => *g,
        None => sys.start_modes(t, &z),
    };
    // The base: every touching contact slips in the direction of its v.
    let mut base = m0;
    let mut cs: [Option<Contact<N>>; MAX_CONTACTS] = Default::default();
    for (i, c) in cs.iter_mut().enumerate().take(nc) {
        if m0.get(i) == Mode::Free {
            continue;
        }
        let v = sys.observe_contact(t, &m0, &z, i).v_rel;
        base.set(i, slip_of(v));
        *c = Some(Contact {
            active: false,
            v,
            slip: slip_of(v),
            lambda_b: 0.0,
            bound: 0.0,
            g: [0.0; N],
            b: [0.0; N],
        });
    }
    let mut a_base = [0.0; N];
    sys.field(t, &base, &z, &mut a_base);
    if cs.iter().all(Option::is_none) {
        *dz = a_base;
        return m0;
    }
    let mut guards = Guards::<N>::default();
    sys.mode_guards(&base, &mut guards);
    for g in guards.as_slice() {
        if g.kind != GuardKind::SlipZero {
            continue;
        }
        if let Some(c) = cs.get_mut(g.contact as usize).and_then(Option::as_mut) {
            let s = c.slip.slip_sign();
            c.g = sys.guard_gradient(t, &base, g, &z).map(|x| -s * x);
        }
    }
    let mut a_try = [0.0; N];
    for i in 0..nc {
        let Some(c) = cs[i].as_mut() else { continue };
        c.lambda_b = sys.observe_contact(t, &base, &z, i).friction_force;
        let mut stick = base;
        stick.set(i, Mode::Stick);
        sys.mode_guards(&stick, &mut guards);
        let (mut up, mut dn) = (None, None);
        for g in guards.as_slice() {
            if g.contact as usize == i {
                match g.kind {
                    GuardKind::StickBreakPos => up = Some(sys.guard_value(t, &stick, g, &z)),
                    GuardKind::StickBreakNeg => dn = Some(sys.guard_value(t, &stick, g, &z)),
                    _ => {}
                }
            }
        }
        let (Some(up), Some(dn)) = (up, dn) else {
            continue;
        };
        c.bound = (-(up + dn) / 2.0).max(0.0);
        let lambda_stick = (up - dn) / 2.0;
        let scale = c.lambda_b.abs() + c.bound + lambda_stick.abs();
        // `b` from stick against slip; where the slip force happens to equal
        // the stick force, from the opposite slip instead.
        let (mut other, mut d_lambda) = (stick, lambda_stick - c.lambda_b);
        if d_lambda.is_nan() || d_lambda.abs() <= 1e-9 * scale {
            other = base;
            other.set(
                i,
                if c.slip == Mode::SlipPos {
                    Mode::SlipNeg
                } else {
                    Mode::SlipPos
                },
            );
            d_lambda = sys.observe_contact(t, &other, &z, i).friction_force - c.lambda_b;
            if d_lambda.is_nan() || d_lambda.abs() <= 1e-9 * scale {
                continue;
            }
        }
        sys.field(t, &other, &z, &mut a_try);
        for k in 0..N {
            c.b[k] = (a_try[k] - a_base[k]) / d_lambda;
        }
        c.active = dot(&c.g, &c.b) != 0.0;
    }
    // λ_X = λ_b + (G B)⁻¹ G (ż − f_b), over the active contacts (identity
    // rows for the others keep the fixed-size solve regular).
    let rates: [f64; N] = f.rates(theta);
    let mut gb = SMatrix::<f64, MAX_CONTACTS, MAX_CONTACTS>::identity();
    let mut rhs = SVector::<f64, MAX_CONTACTS>::zeros();
    let mut diff = [0.0; N];
    for k in 0..N {
        diff[k] = rates[k] - a_base[k];
    }
    for i in 0..nc {
        let Some(ci) = cs[i].as_ref().filter(|c| c.active) else {
            continue;
        };
        rhs[i] = dot(&ci.g, &diff);
        for j in 0..nc {
            if let Some(cj) = cs[j].as_ref().filter(|c| c.active) {
                gb[(i, j)] = dot(&ci.g, &cj.b);
            }
        }
    }
    let delta = gb.lu().solve(&rhs).unwrap_or_else(|| {
        // A singular coupling: each contact on its own.
        SVector::from_fn(|i, _| rhs[i] / gb[(i, i)])
    });
    let mut modes = m0;
    let mut flipped = base;
    let mut any_flip = false;
    let mut stuck = [0.0f64; MAX_CONTACTS];
    let mut is_stuck = [false; MAX_CONTACTS];
    for i in 0..nc {
        let Some(c) = cs[i].as_ref() else { continue };
        if !c.active {
            modes.set(i, if given.is_some() { m0.get(i) } else { c.slip });
            if modes.get(i) != c.slip && modes.get(i) != Mode::Stick {
                flipped.set(i, modes.get(i));
                any_flip = true;
            }
            continue;
        }
        let eps = weight * f.omega / gb[(i, i)].abs();
        let lp = c.lambda_b + delta[i] + eps * c.v;
        let mode = match given {
            Some(g) => g.get(i),
            None => decide(lp, c),
        };
        modes.set(i, mode);
        match mode {
            Mode::Stick => {
                is_stuck[i] = true;
                stuck[i] = lp - c.lambda_b;
            }
            m if m != c.slip => {
                flipped.set(i, m);
                any_flip = true;
            }
            _ => {}
        }
    }
    if any_flip {
        sys.field(t, &flipped, &z, dz);
    } else {
        *dz = a_base;
    }
    for i in 0..nc {
        if let (true, Some(c)) = (is_stuck[i], cs[i].as_ref()) {
            for k in 0..N {
                dz[k] += c.b[k] * stuck[i];
            }
        }
    }
    modes
}
