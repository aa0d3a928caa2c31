//! The right-hand side of small lumped models for [`LANES`] runs at once
//! ([`LaneField`] for [`Fixed`]): what `Lumped::field_folded` computes on
//! its folded rows, lane by lane, with the same IEEE operations in the same
//! order (tested bit for bit), so that a transient map of a user's own
//! brake runs as an ensemble.
//!
//! It covers what a map's points share: models of at most
//! [`DENSE_FIELD_DOFS`] dofs with a diagonal mass matrix and no ramped
//! force (off-diagonal stiffness and damping entries are welcome, in the
//! same places in every lane), each contact with the same kind of normal
//! force in every lane and a friction law of the same kind whose `μ(v)` is
//! plain arithmetic (thesis, Coulomb, rational). A lane with a contact in
//! stick is left to `field` (its friction forces are multipliers, solved
//! for), as is every lane of models outside this (no pack).

use super::{DenseField, Fixed, FoldedContact, InvMass, Lumped, DENSE_FIELD_DOFS};
use crate::friction::FrictionLaw;
use crate::lanes::{Lanes, LANES};
use crate::model::contact::Normal;
use crate::model::lane_field::LaneField;
use crate::model::{Mode, Modes, MAX_CONTACTS};

const D: usize = DENSE_FIELD_DOFS;

/// `μ(v)` of one kind of law, its parameters lane by lane.
#[derive(Debug, Clone, Copy)]
enum LaneLaw {
    /// `f0·(1 − f1·v·(1 − v/(2·Uc)))` (`2·Uc` is exact).
    Thesis { f0: Lanes, f1: Lanes, two_uc: Lanes },
    /// `μ_k`.
    Coulomb { mu_k: Lanes },
    /// `μ_s/(1 + δ·v)`.
    Rational { mu_s: Lanes, delta: Lanes },
}

impl LaneLaw {
    /// The law of every lane's contact, if all are of one lane-wise kind.
    fn of(laws: [FrictionLaw; LANES]) -> Option<LaneLaw> {
        let kind = std::mem::discriminant(&laws[0]);
        if laws.iter().any(|l| std::mem::discriminant(l) != kind) {
            return None;
        }
        // Each lane's parameters, in the order of the variant's fields below.
        let p = laws.map(|l| match l {
            FrictionLaw::Thesis { f0, f1, uc } => [f0, f1, 2.0 * uc],
            FrictionLaw::Coulomb { mu_k, .. } => [mu_k, 0.0, 0.0],
            FrictionLaw::Rational { mu_s, delta } => [mu_s, delta, 0.0],
            FrictionLaw::Stribeck { .. } | FrictionLaw::Tanh { .. } => [0.0; 3],
        });
        let col = |j: usize| Lanes::new(std::array::from_fn(|l| p[l][j]));
        match laws[0] {
            FrictionLaw::Thesis { .. } => Some(LaneLaw::Thesis {
                f0: col(0),
                f1: col(1),
                two_uc: col(2),
            }),
            FrictionLaw::Coulomb { .. } => Some(LaneLaw::Coulomb { mu_k: col(0) }),
            FrictionLaw::Rational { .. } => Some(LaneLaw::Rational {
                mu_s: col(0),
                delta: col(1),
            }),
            // (exp, powf and tanh: not bit for bit lane-wise.)
            FrictionLaw::Stribeck { .. } | FrictionLaw::Tanh { .. } => None,
        }
    }

    /// `μ(v)` lane by lane, as [`FrictionLaw::mu`].
    #[inline(always)]
    fn mu(&self, v: Lanes) -> Lanes {
        let one = Lanes::ONE;
        match *self {
            LaneLaw::Thesis { f0, f1, two_uc } => f0 * (one - f1 * v * (one - v / two_uc)),
            LaneLaw::Coulomb { mu_k } => mu_k,
            LaneLaw::Rational { mu_s, delta } => mu_s / (one + delta * v),
        }
    }
}

/// One contact's folded rows and parameters, lane by lane.
#[derive(Debug, Clone)]
pub struct LaneContact {
    /// A prescribed normal load (every lane), else `None` (elastic).
    prescribed: Option<Lanes>,
    fn_q: [Lanes; D],
    fn_u: [Lanes; D],
    normal: [Lanes; D],
    tangent: [Lanes; D],
    slope: [Lanes; D],
    bilateral: bool,
    v: Lanes,
    law: LaneLaw,
    alpha: Lanes,
    /// Mask of the lanes whose `alpha ≠ 0` (the others add no follower force).
    alpha_on: Lanes,
    any_alpha: bool,
}

/// What the lane-wise field needs of [`LANES`] lumped models: the folded
/// operators, lane by lane.
#[derive(Debug, Clone)]
pub struct LumpedLanes {
    f0: [Lanes; D],
    kd: [Lanes; D],
    cd: [Lanes; D],
    /// The off-diagonal entries `(row, column on z, value)`, in the order
    /// of every lane's own list.
    off: Vec<(usize, usize, Lanes)>,
    inv_mass: [Lanes; D],
    contacts: Vec<LaneContact>,
}

/// The modes of [`LANES`] lumped models as lane masks, per contact.
#[derive(Debug, Clone, Copy)]
pub struct LumpedMasks {
    /// Lanes in negative slip.
    neg: [Lanes; MAX_CONTACTS],
    /// Lanes in slip (either sign): the contact acts.
    slip: [Lanes; MAX_CONTACTS],
}

/// The folded operators of a model that [`LaneField::pack`] accepted.
fn dense(m: &Lumped) -> &DenseField {
    m.dense
        .as_ref()
        .expect("packed models have folded operators")
}

/// The lanes' rows `row(lane)` as one row of lane numbers.
fn rows(models: &[&Lumped; LANES], row: &dyn Fn(&Lumped) -> &[f64; D]) -> [Lanes; D] {
    std::array::from_fn(|i| Lanes::new(std::array::from_fn(|l| row(models[l])[i])))
}

/// The pack of one contact `ci` of every lane, if the lanes agree on its kind.
fn contact_pack(models: &[&Lumped; LANES], ci: usize) -> Option<LaneContact> {
    let contact = |l: usize| &models[l].contacts[ci];
    // The normal force: a prescribed load, or a layer (bilateral or not).
    let normal = |l: usize| match contact(l).normal {
        Normal::Prescribed(f) => (Some(f), false),
        Normal::Elastic { bilateral, .. } => (None, bilateral),
    };
    let (load, bilateral) = normal(0);
    let kind = |l: usize| (normal(l).0.is_some(), normal(l).1);
    if (1..LANES).any(|l| kind(l) != kind(0)) {
        return None;
    }
    let law = LaneLaw::of(std::array::from_fn(|l| contact(l).friction))?;
    let num = |f: &dyn Fn(usize) -> f64| Lanes::new(std::array::from_fn(f));
    let alpha_on = Lanes::mask(std::array::from_fn(|l| contact(l).alpha != 0.0));
    let folded = |row: fn(&FoldedContact) -> &[f64; D]| {
        rows(models, &|m: &Lumped| row(&dense(m).contacts[ci]))
    };
    Some(LaneContact {
        prescribed: load.map(|_| num(&|l| normal(l).0.unwrap_or(0.0))),
        fn_q: folded(|c| &c.fn_q),
        fn_u: folded(|c| &c.fn_u),
        normal: folded(|c| &c.normal),
        tangent: folded(|c| &c.tangent),
        slope: folded(|c| &c.slope),
        bilateral,
        v: num(&|l| contact(l).v),
        law,
        alpha: num(&|l| contact(l).alpha),
        alpha_on,
        any_alpha: alpha_on.any(),
    })
}

/// `Σ a_i·b_i` lane by lane, as the scalar `dot`: from the first product,
/// in index order.
#[inline(always)]
fn dot_lanes(a: &[Lanes], b: &[Lanes]) -> Lanes {
    let mut s = a[0] * b[0];
    for (x, y) in a[1..].iter().zip(&b[1..]) {
        s += *x * *y;
    }
    s
}

/// `s + Σ a_i·b_i` lane by lane, as the scalar `dot_from`.
#[inline(always)]
fn dot_from_lanes(mut s: Lanes, a: &[Lanes], b: &[Lanes]) -> Lanes {
    for (x, y) in a.iter().zip(b) {
        s += *x * *y;
    }
    s
}

impl<const N: usize> LaneField<N> for Fixed<'_, N> {
    type Pack = LumpedLanes;
    type Masks = LumpedMasks;

    fn pack(models: [Option<&Self>; LANES]) -> Option<LumpedLanes> {
        let first = models.iter().flatten().next()?.0;
        let models: [&Lumped; LANES] = std::array::from_fn(|l| models[l].map_or(first, |m| m.0));
        let n = N / 2;
        let fits = |m: &Lumped| {
            n <= D
                && m.dofs.len() == n
                && m.dense.is_some()
                && matches!(m.inv_mass, InvMass::Diagonal(_))
                && !m.time_varying
                && m.contacts.len() == first.contacts.len()
        };
        if !models.iter().all(|m| fits(m)) {
            return None;
        }
        // The off-diagonal entries in the same places in every lane.
        let pattern = |l: usize| dense(models[l]).off.iter().map(|&(r, c, _)| (r, c));
        if (1..LANES).any(|l| !pattern(l).eq(pattern(0))) {
            return None;
        }
        let off = dense(models[0])
            .off
            .iter()
            .enumerate()
            .map(|(k, &(r, c, _))| (r, c, Lanes::new(models.map(|m| dense(m).off[k].2))))
            .collect();
        let contacts = (0..first.contacts.len())
            .map(|ci| contact_pack(&models, ci))
            .collect::<Option<Vec<_>>>()?;
        Some(LumpedLanes {
            f0: rows(&models, &|m| &dense(m).f0),
            kd: rows(&models, &|m| &dense(m).kd),
            cd: rows(&models, &|m| &dense(m).cd),
            off,
            inv_mass: rows(&models, &|m| &dense(m).inv_mass),
            contacts,
        })
    }

    fn masks(modes: &[Option<Modes>; LANES]) -> (LumpedMasks, [bool; LANES]) {
        let of = |ci: usize, pick: &dyn Fn(Mode) -> bool| {
            Lanes::mask(modes.map(|m| m.is_some_and(|m| ci < m.len() && pick(m.get(ci)))))
        };
        let masks = LumpedMasks {
            neg: std::array::from_fn(|ci| of(ci, &|m| m == Mode::SlipNeg)),
            slip: std::array::from_fn(|ci| of(ci, &|m| matches!(m, Mode::SlipPos | Mode::SlipNeg))),
        };
        let done = modes.map(|m| m.is_some_and(|m| !m.as_slice().contains(&Mode::Stick)));
        (masks, done)
    }

    // `Lumped::field_folded` lane by lane: the force `f0 + kd·q + cd·q̇`,
    // the off-diagonal entries, each contact's forces where it slips
    // (`contact_folded`), then `M⁻¹` (all of it in `dz[n..]`).
    #[inline(always)]
    fn field_masked(
        p: &LumpedLanes,
        masks: &LumpedMasks,
        _t: Lanes,
        z: &[Lanes; N],
        dz: &mut [Lanes; N],
    ) {
        let n = N / 2;
        let (q, u) = z.split_at(n);
        let (dq, acc) = dz.split_at_mut(n);
        dq.copy_from_slice(u);
        for i in 0..n {
            acc[i] = p.f0[i] + p.kd[i] * q[i] + p.cd[i] * u[i];
        }
        for &(r, c, v) in &p.off {
            acc[r] += v * z[c];
        }
        for (ci, c) in p.contacts.iter().enumerate() {
            let (neg, slip) = (masks.neg[ci], masks.slip[ci]);
            if !slip.any() {
                continue;
            }
            // `normal_folded`, then `slip_folded` with its sign as negations.
            let f_n = match c.prescribed {
                Some(f) => f,
                None => dot_from_lanes(dot_lanes(&c.fn_q[..n], q), &c.fn_u[..n], u),
            };
            let v = c.v + dot_lanes(&c.tangent[..n], u);
            let f_nf = if c.bilateral {
                f_n.max(Lanes::ZERO)
            } else {
                f_n
            };
            let mu = c.law.mu(neg.blend(-v, v));
            let f_t = neg.blend(-mu * f_nf, mu * f_nf);
            for i in 0..n {
                let a = acc[i] - f_n * c.normal[i] - f_t * c.tangent[i];
                acc[i] = slip.blend(a, acc[i]);
            }
            if c.any_alpha {
                let on = c.alpha_on & slip;
                let f_f = c.alpha * f_t * dot_lanes(&c.slope[..n], q);
                for i in 0..n {
                    acc[i] = on.blend(acc[i] + f_f * c.normal[i], acc[i]);
                }
            }
        }
        for i in 0..n {
            acc[i] = acc[i] * p.inv_mass[i];
        }
    }
}
