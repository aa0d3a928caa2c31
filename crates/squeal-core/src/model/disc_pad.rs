//! The 4-DOF disc–pad model of the thesis (MODEL.md §1–5): disc and pad,
//! each with a tangential and a normal coordinate, coupled by a Kelvin–Voigt
//! contact layer carrying friction and a follower force.
//!
//! State `z = (x_d, x_p, y_d, y_p, ẋ_d, ẋ_p, ẏ_d, ẏ_p)`.

use super::Modes;
use super::{
    contact, stick_or_slip, EventKind, GuardKind, Guards, Mode, Model, ModelError, Observables,
    Parameters,
};
use crate::friction::FrictionLaw;
use crate::lanes::{Lanes, LANES};
use crate::model::lane_field::LaneField;
use crate::params::{ParamError, ParamKind, ParamSpec};

/// Unilateral (the pad can lift off) or bilateral (never opens) contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Contact {
    /// The pad is in contact while `δ > 0` and `k_py·δ + c_py·δ̇ > 0` (default).
    #[default]
    Unilateral,
    /// The normal spring–damper never opens; friction acts on `max(F_y, 0)`.
    Bilateral,
}

impl Contact {
    /// Name as typed by users.
    pub fn as_str(self) -> &'static str {
        match self {
            Contact::Unilateral => "unilateral",
            Contact::Bilateral => "bilateral",
        }
    }
    /// Parse `unilateral` / `bilateral`.
    pub fn parse(s: &str) -> Result<Self, ParamError> {
        match s {
            "unilateral" => Ok(Contact::Unilateral),
            "bilateral" => Ok(Contact::Bilateral),
            _ => Err(ParamError::BadChoice {
                key: "contact".into(),
                value: s.into(),
                allowed: "unilateral, bilateral".into(),
            }),
        }
    }
}

/// Disc–pad parameters, under MODEL.md §2's names and defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_snake_case)]
pub struct DiscPadParams {
    /// Disc effective (modal) mass (kg).
    pub m_d: f64,
    /// Pad mass (kg).
    pub m_p: f64,
    /// Disc tangential stiffness (N/m).
    pub k_dx: f64,
    /// Disc tangential damping (kg/s).
    pub c_dx: f64,
    /// Disc normal stiffness (N/m).
    pub k_dy: f64,
    /// Disc normal damping (kg/s).
    pub c_dy: f64,
    /// Pad tangential (shear) stiffness (N/m).
    pub k_px: f64,
    /// Pad tangential damping (kg/s).
    pub c_px: f64,
    /// Pad normal (contact layer) stiffness (N/m).
    pub k_py: f64,
    /// Pad normal (contact layer) damping (kg/s).
    pub c_py: f64,
    /// Normal brake force on the pad (N).
    pub N: f64,
    /// Disc surface speed (m/s).
    pub V: f64,
    /// Follower-force coefficient α (1/m).
    pub alpha: f64,
    /// Ramp time of the normal force (s); 0 applies N as a step at t = 0.
    pub t_ramp: f64,
}

impl DiscPadParams {
    /// The field called `key` (one place maps names to fields, for get and set).
    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        Some(match key {
            "m_d" => &mut self.m_d,
            "m_p" => &mut self.m_p,
            "k_dx" => &mut self.k_dx,
            "c_dx" => &mut self.c_dx,
            "k_dy" => &mut self.k_dy,
            "c_dy" => &mut self.c_dy,
            "k_px" => &mut self.k_px,
            "c_px" => &mut self.c_px,
            "k_py" => &mut self.k_py,
            "c_py" => &mut self.c_py,
            "N" => &mut self.N,
            "V" => &mut self.V,
            "alpha" => &mut self.alpha,
            "t_ramp" => &mut self.t_ramp,
            _ => return None,
        })
    }
}

impl Default for DiscPadParams {
    fn default() -> Self {
        DiscPadParams {
            m_d: 1.0,
            m_p: 0.1,
            k_dx: 1.0e9,
            c_dx: 1.0,
            k_dy: 8.0e6,
            c_dy: 1.0,
            k_px: 1.7e9,
            c_px: 0.2,
            k_py: 4.25e9,
            c_py: 0.2,
            N: 500.0,
            V: 1.0,
            alpha: 0.0,
            t_ramp: 0.0,
        }
    }
}

const SPECS: &[ParamSpec] = &[
    ParamSpec::new(
        "m_d",
        "kg",
        "disc effective (modal) mass",
        ParamKind::Positive,
    ),
    ParamSpec::new("m_p", "kg", "pad mass", ParamKind::Positive),
    ParamSpec::new(
        "k_dx",
        "N/m",
        "disc tangential stiffness",
        ParamKind::Positive,
    ),
    ParamSpec::new(
        "c_dx",
        "kg/s",
        "disc tangential damping",
        ParamKind::NonNegative,
    ),
    ParamSpec::new("k_dy", "N/m", "disc normal stiffness", ParamKind::Positive),
    ParamSpec::new(
        "c_dy",
        "kg/s",
        "disc normal damping",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "k_px",
        "N/m",
        "pad tangential (shear) stiffness",
        ParamKind::Positive,
    ),
    ParamSpec::new(
        "c_px",
        "kg/s",
        "pad tangential damping",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "k_py",
        "N/m",
        "pad normal (contact layer) stiffness",
        ParamKind::Positive,
    ),
    ParamSpec::new(
        "c_py",
        "kg/s",
        "pad normal (contact layer) damping",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "N",
        "N",
        "normal brake force on the pad",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "V",
        "m/s",
        "disc surface (rotation) speed",
        ParamKind::NonNegative,
    ),
    ParamSpec::new("alpha", "1/m", "follower-force coefficient", ParamKind::Any),
    ParamSpec::new(
        "t_ramp",
        "s",
        "ramp time of N (0: a step at t = 0)",
        ParamKind::NonNegative,
    ),
];

/// The disc–pad model: parameters, friction law and contact kind.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DiscPad {
    /// Mechanical parameters.
    pub p: DiscPadParams,
    /// Friction law μ(v).
    pub friction: FrictionLaw,
    /// Unilateral or bilateral contact.
    pub contact: Contact,
}

/// State indices.
const XD: usize = 0;
const XP: usize = 1;
const YD: usize = 2;
const YP: usize = 3;
const UD: usize = 4;
const UP: usize = 5;
const WD: usize = 6;
const WP: usize = 7;

impl DiscPad {
    /// Normal force on the pad at time t: a step at t = 0, or a linear ramp over `t_ramp`.
    #[inline]
    pub fn normal_load(&self, t: f64) -> f64 {
        if self.p.t_ramp > 0.0 && t < self.p.t_ramp {
            self.p.N * (t / self.p.t_ramp).max(0.0)
        } else {
            self.p.N
        }
    }

    /// Contact-layer force `F_y = k_py·δ + c_py·δ̇` with `δ = y_d − y_p` (thesis 8.5).
    #[inline]
    fn layer_force(&self, z: &[f64; 8]) -> f64 {
        self.p.k_py * (z[YD] - z[YP]) + self.p.c_py * (z[WD] - z[WP])
    }

    /// Gradient of the layer force.
    fn layer_force_grad(&self) -> [f64; 8] {
        let mut c = [0.0; 8];
        c[YD] = self.p.k_py;
        c[YP] = -self.p.k_py;
        c[WD] = self.p.c_py;
        c[WP] = -self.p.c_py;
        c
    }

    /// Force the pad needs to stay stuck, and the common tangential acceleration (MODEL.md §4).
    #[inline]
    fn stick_force(&self, z: &[f64; 8]) -> (f64, f64) {
        let p = &self.p;
        let a =
            (-p.k_dx * z[XD] - p.c_dx * z[UD] - p.k_px * z[XP] - p.c_px * z[UP]) / (p.m_d + p.m_p);
        (p.m_p * a + p.k_px * z[XP] + p.c_px * z[UP], a)
    }

    /// Gradient of the stick force (it is linear in the state).
    fn stick_force_grad(&self) -> [f64; 8] {
        let p = &self.p;
        let m = p.m_d + p.m_p;
        let mut c = [0.0; 8];
        c[XD] = -p.m_p * p.k_dx / m;
        c[UD] = -p.m_p * p.c_dx / m;
        c[XP] = p.k_px * p.m_d / m;
        c[UP] = p.c_px * p.m_d / m;
        c
    }

    /// Normal force carrying friction: `F_y`, or `max(F_y, 0)` for bilateral contact.
    #[inline]
    fn friction_normal(&self, f_y: f64) -> f64 {
        match self.contact {
            Contact::Unilateral => f_y,
            Contact::Bilateral => f_y.max(0.0),
        }
    }

    /// Sliding velocity `v = V + ẋ_d − ẋ_p` (thesis 8.8).
    #[inline]
    pub fn sliding_velocity(&self, z: &[f64; 8]) -> f64 {
        self.p.V + z[UD] - z[UP]
    }

    /// Friction mode for a state in contact, from the sign of v (stick test at v = 0).
    fn friction_mode(&self, z: &[f64; 8]) -> Mode {
        contact::friction_mode(
            self.sliding_velocity(z),
            self.stick_force(z).0,
            self.stick_bound(z),
        )
    }

    /// `μ_s·max(F_n, 0)` with `F_n` the normal force carrying friction.
    #[inline]
    fn stick_bound(&self, z: &[f64; 8]) -> f64 {
        self.friction.mu_static() * self.friction_normal(self.layer_force(z)).max(0.0)
    }
}

impl Parameters for DiscPad {
    fn param_specs(&self) -> &'static [ParamSpec] {
        SPECS
    }

    fn get(&self, key: &str) -> Option<f64> {
        let mut p = self.p;
        p.slot(key).map(|v| *v).or_else(|| self.friction.get(key))
    }

    fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        let Some(spec) = SPECS.iter().find(|s| s.name == key) else {
            return self.friction.set(key, value);
        };
        spec.check(value)?;
        if let Some(slot) = self.p.slot(key) {
            *slot = value;
        }
        Ok(())
    }

    fn friction_law(&self) -> &FrictionLaw {
        &self.friction
    }
}

impl Model<8> for DiscPad {
    fn name(&self) -> &'static str {
        "disc-pad"
    }

    fn interface_name(&self) -> &'static str {
        "pad"
    }

    fn state_names(&self) -> [&'static str; 8] {
        ["x_d", "x_p", "y_d", "y_p", "vx_d", "vx_p", "vy_d", "vy_p"]
    }

    /// MODEL.md §3 (slip), §4 (stick), and free flight without contact.
    #[inline(always)]
    fn rhs(&self, t: f64, mode: Mode, z: &[f64; 8], dz: &mut [f64; 8]) {
        let p = &self.p;
        let (f_y, f_t, a_stick) = match mode {
            Mode::Free => (0.0, 0.0, None),
            Mode::Stick => {
                let (f, a) = self.stick_force(z);
                (self.layer_force(z), f, Some(a))
            }
            Mode::SlipPos | Mode::SlipNeg => {
                let f_y = self.layer_force(z);
                // s·v, not |v|: equal in the mode's domain, and smooth past its
                // guard, so a step that overshoots the event sees no kink. The
                // sign s = ±1 is applied as a negation, not a product: the same
                // bits, three cycles less on the stages' critical path.
                let v = self.sliding_velocity(z);
                let s_mu = if mode == Mode::SlipPos {
                    self.friction.mu(v)
                } else {
                    -self.friction.mu(-v)
                };
                (f_y, s_mu * self.friction_normal(f_y), None)
            }
        };
        let f_f = p.alpha * f_t * z[YD];
        dz[XD] = z[UD];
        dz[XP] = z[UP];
        dz[YD] = z[WD];
        dz[YP] = z[WP];
        // Two divisions instead of four: their latency dominates this function.
        let (inv_md, inv_mp) = (1.0 / p.m_d, 1.0 / p.m_p);
        match a_stick {
            Some(a) => {
                dz[UD] = a;
                dz[UP] = a;
            }
            None => {
                dz[UD] = (-p.k_dx * z[XD] - p.c_dx * z[UD] - f_t) * inv_md;
                dz[UP] = (-p.k_px * z[XP] - p.c_px * z[UP] + f_t) * inv_mp;
            }
        }
        dz[WD] = (-p.k_dy * z[YD] - p.c_dy * z[WD] - f_y + f_f) * inv_md;
        dz[WP] = (f_y - self.normal_load(t) - f_f) * inv_mp;
    }

    fn guards(&self, mode: Mode, out: &mut Guards<8>) {
        out.clear();
        let fy = (self.layer_force_grad(), 0.0);
        if mode == Mode::Free {
            // Gap closes: δ = y_d − y_p crosses zero upwards.
            let mut c = [0.0; 8];
            c[YD] = 1.0;
            c[YP] = -1.0;
            out.push(GuardKind::Contact, c, 0.0);
            return;
        }
        if self.contact == Contact::Unilateral {
            let (c, d) = contact::separation_guard(&fy);
            out.push(GuardKind::Separation, c, d);
        }
        match mode {
            Mode::SlipPos | Mode::SlipNeg => {
                // v = V + ẋ_d − ẋ_p.
                let mut c = [0.0; 8];
                c[UD] = 1.0;
                c[UP] = -1.0;
                let (c, d) = contact::slip_zero_guard(mode, &(c, self.p.V));
                out.push(GuardKind::SlipZero, c, d);
            }
            Mode::Stick => {
                let fs = (self.stick_force_grad(), 0.0);
                for (kind, (c, d)) in
                    contact::stick_break_guards(&fs, &fy, self.friction.mu_static())
                {
                    out.push(kind, c, d);
                }
            }
            Mode::Free => unreachable!(),
        }
    }

    fn transition(
        &self,
        _t: f64,
        mode: Mode,
        guard: GuardKind,
        z: &mut [f64; 8],
    ) -> (Mode, Option<EventKind>) {
        if guard == GuardKind::SlipZero {
            // On the surface v = 0 exactly.
            z[UP] = self.p.V + z[UD];
        }
        let z = &*z;
        contact::after_guard(guard, mode, || {
            if guard == GuardKind::SlipZero {
                stick_or_slip(self.stick_force(z).0, self.stick_bound(z))
            } else {
                self.friction_mode(z)
            }
        })
    }

    fn initial_mode(&self, _t: f64, z: &[f64; 8]) -> Mode {
        let delta = z[YD] - z[YP];
        if self.contact == Contact::Unilateral && (delta < 0.0 || self.layer_force(z) < 0.0) {
            return Mode::Free;
        }
        self.friction_mode(z)
    }

    fn observe(&self, _t: f64, mode: Mode, z: &[f64; 8]) -> Observables {
        let v_rel = self.sliding_velocity(z);
        let (normal_force, friction_force) = match mode {
            Mode::Free => (0.0, 0.0),
            Mode::Stick => (self.layer_force(z), self.stick_force(z).0),
            Mode::SlipPos | Mode::SlipNeg => {
                let f_y = self.layer_force(z);
                (
                    f_y,
                    mode.slip_sign() * self.friction.mu(v_rel.abs()) * self.friction_normal(f_y),
                )
            }
        };
        Observables {
            normal_force,
            friction_force,
            v_rel,
        }
    }

    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        (self.p.t_ramp > 0.0 && t < self.p.t_ramp).then_some(self.p.t_ramp)
    }

    /// MODEL.md §5: `y_d* = −N/k_dy`, `F_y* = N/(1 − α μ* y_d*)`, `y_p* = y_d* − F_y*/k_py`,
    /// `F_t* = μ* F_y*`, `x_d* = −F_t*/k_dx`, `x_p* = F_t*/k_px`.
    fn equilibrium(&self) -> Result<[f64; 8], ModelError> {
        let p = &self.p;
        if p.V <= 0.0 {
            return Err(ModelError::NoSteadySliding(format!(
                "V = {} (the disc must turn)",
                p.V
            )));
        }
        let mu = self.friction.mu(p.V);
        let y_d = -p.N / p.k_dy;
        let denom = 1.0 - p.alpha * mu * y_d;
        if denom <= 0.0 {
            return Err(ModelError::NoSteadySliding(format!(
                "alpha = {}: 1 − α·μ(V)·y_d* = {denom:.3e} ≤ 0, the follower force makes the normal force diverge",
                p.alpha
            )));
        }
        let f_y = p.N / denom;
        let f_t = mu * f_y;
        Ok([
            -f_t / p.k_dx,
            f_t / p.k_px,
            y_d,
            y_d - f_y / p.k_py,
            0.0,
            0.0,
            0.0,
            0.0,
        ])
    }

    fn jacobian(&self, z: &[f64; 8]) -> [[f64; 8]; 8] {
        let p = &self.p;
        let f_y = self.layer_force(z);
        let v = self.sliding_velocity(z);
        let (s, vabs) = if v >= 0.0 { (1.0, v) } else { (-1.0, -v) };
        let mu = self.friction.mu(vabs);
        let dmu = self.friction.dmu(vabs);
        let g_fy = self.layer_force_grad();
        let (fn_, g_fn) = match self.contact {
            Contact::Bilateral if f_y < 0.0 => (0.0, [0.0; 8]),
            _ => (f_y, g_fy),
        };
        let f_t = s * mu * fn_;
        // ∂F_t = s·(μ ∂F_n + F_n μ'(|v|) s ∂v), ∂v = e_UD − e_UP.
        let mut g_ft = [0.0; 8];
        for i in 0..8 {
            g_ft[i] = s * mu * g_fn[i];
        }
        g_ft[UD] += fn_ * dmu;
        g_ft[UP] -= fn_ * dmu;
        // F_f = α F_t y_d.
        let mut g_ff = [0.0; 8];
        for i in 0..8 {
            g_ff[i] = p.alpha * z[YD] * g_ft[i];
        }
        g_ff[YD] += p.alpha * f_t;
        let mut j = [[0.0; 8]; 8];
        j[XD][UD] = 1.0;
        j[XP][UP] = 1.0;
        j[YD][WD] = 1.0;
        j[YP][WP] = 1.0;
        for i in 0..8 {
            j[UD][i] = -g_ft[i] / p.m_d;
            j[UP][i] = g_ft[i] / p.m_p;
            j[WD][i] = (-g_fy[i] + g_ff[i]) / p.m_d;
            j[WP][i] = (g_fy[i] - g_ff[i]) / p.m_p;
        }
        j[UD][XD] -= p.k_dx / p.m_d;
        j[UD][UD] -= p.c_dx / p.m_d;
        j[UP][XP] -= p.k_px / p.m_p;
        j[UP][UP] -= p.c_px / p.m_p;
        j[WD][YD] -= p.k_dy / p.m_d;
        j[WD][WD] -= p.c_dy / p.m_d;
        j
    }
}

/// The parameters of [`LANES`] disc–pads, lane by lane, for
/// [`LaneField::field_lanes`] (gathered once per change of the lanes' jobs).
#[derive(Debug, Clone, Copy)]
pub struct DiscPadLanes {
    neg_k_dx: Lanes,
    c_dx: Lanes,
    neg_k_dy: Lanes,
    c_dy: Lanes,
    neg_k_px: Lanes,
    k_px: Lanes,
    c_px: Lanes,
    k_py: Lanes,
    c_py: Lanes,
    n: Lanes,
    v: Lanes,
    alpha: Lanes,
    t_ramp: Lanes,
    inv_md: Lanes,
    inv_mp: Lanes,
    m_p: Lanes,
    m_sum: Lanes,
    f0: Lanes,
    f1: Lanes,
    two_uc: Lanes,
}

/// The modes of [`LANES`] disc–pads as lane masks, for
/// [`LaneField::field_masked`] (made once per attempt).
#[derive(Debug, Clone, Copy)]
pub struct DiscPadMasks {
    any_stick: bool,
    neg: Lanes,
    stick: Lanes,
    free: Lanes,
}

/// Lane-wise [`Model::rhs`] in every mode (slip of either sign, stick, free
/// flight) with the thesis friction law and unilateral contact (the
/// default; any other law or contact: no pack, every lane one by one). Each
/// lane's slope comes from the same operations, in the same order, as `rhs`
/// (tested bit for bit).
impl LaneField<8> for DiscPad {
    type Pack = DiscPadLanes;
    type Masks = DiscPadMasks;

    fn pack(models: [Option<&Self>; LANES]) -> Option<DiscPadLanes> {
        let first = models.iter().flatten().next()?;
        let mut lanes = [**first; LANES];
        for (lane, m) in lanes.iter_mut().zip(models) {
            if let Some(m) = m {
                *lane = *m;
            }
        }
        let mut thesis = [(0.0, 0.0, 0.0); LANES];
        for (l, m) in lanes.iter().enumerate() {
            match (m.friction, m.contact) {
                (FrictionLaw::Thesis { f0, f1, uc }, Contact::Unilateral) => {
                    thesis[l] = (f0, f1, 2.0 * uc)
                }
                _ => return None,
            }
        }
        let get = |f: &dyn Fn(&DiscPad) -> f64| Lanes::new(std::array::from_fn(|l| f(&lanes[l])));
        Some(DiscPadLanes {
            neg_k_dx: get(&|m| -m.p.k_dx),
            c_dx: get(&|m| m.p.c_dx),
            neg_k_dy: get(&|m| -m.p.k_dy),
            c_dy: get(&|m| m.p.c_dy),
            neg_k_px: get(&|m| -m.p.k_px),
            k_px: get(&|m| m.p.k_px),
            c_px: get(&|m| m.p.c_px),
            k_py: get(&|m| m.p.k_py),
            c_py: get(&|m| m.p.c_py),
            n: get(&|m| m.p.N),
            v: get(&|m| m.p.V),
            alpha: get(&|m| m.p.alpha),
            t_ramp: get(&|m| m.p.t_ramp),
            inv_md: get(&|m| 1.0 / m.p.m_d),
            inv_mp: get(&|m| 1.0 / m.p.m_p),
            m_p: get(&|m| m.p.m_p),
            m_sum: get(&|m| m.p.m_d + m.p.m_p),
            f0: Lanes::new(std::array::from_fn(|l| thesis[l].0)),
            f1: Lanes::new(std::array::from_fn(|l| thesis[l].1)),
            two_uc: Lanes::new(std::array::from_fn(|l| thesis[l].2)),
        })
    }

    fn masks(modes: &[Option<Modes>; LANES]) -> (DiscPadMasks, [bool; LANES]) {
        let first = modes.map(|m| m.map(|m| m.first()));
        let lanes_in = |mode: Mode| Lanes::mask(first.map(|m| m == Some(mode)));
        let masks = DiscPadMasks {
            any_stick: first.contains(&Some(Mode::Stick)),
            neg: lanes_in(Mode::SlipNeg),
            stick: lanes_in(Mode::Stick),
            free: lanes_in(Mode::Free),
        };
        (masks, modes.map(|m| m.is_some()))
    }

    // Every mode lane-wise: each lane's forces as `rhs` computes them in
    // its mode, picked by masks (the other modes' numbers are computed and
    // dropped; no lane's operations change).
    #[inline(always)]
    fn field_masked(
        p: &DiscPadLanes,
        masks: &DiscPadMasks,
        t: Lanes,
        z: &[Lanes; 8],
        dz: &mut [Lanes; 8],
    ) {
        let DiscPadMasks {
            any_stick,
            neg,
            stick,
            free,
        } = *masks;
        let zero = Lanes::ZERO;
        // Slip, as `rhs`: F_y (thesis 8.5), v (8.8), s·μ(s·v) with the sign
        // as a negation, F_t = s·μ·F_y.
        let layer = p.k_py * (z[YD] - z[YP]) + p.c_py * (z[WD] - z[WP]);
        let v = p.v + z[UD] - z[UP];
        let sv = neg.blend(-v, v);
        let one = Lanes::ONE;
        let mu = p.f0 * (one - p.f1 * sv * (one - sv / p.two_uc));
        let s_mu = neg.blend(-mu, mu);
        let mut f_t = s_mu * layer;
        // Stick (MODEL.md §4): the common acceleration `a` and the force
        // that holds the pad to the disc, as `stick_force`.
        let mut a = zero;
        if any_stick {
            a = (p.neg_k_dx * z[XD] - p.c_dx * z[UD] - p.k_px * z[XP] - p.c_px * z[UP]) / p.m_sum;
            let f_stick = p.m_p * a + p.k_px * z[XP] + p.c_px * z[UP];
            f_t = stick.blend(f_stick, f_t);
        }
        // Free flight: no contact force.
        let f_y = free.blend(zero, layer);
        let f_t = free.blend(zero, f_t);
        let f_f = p.alpha * f_t * z[YD];
        // normal_load: N·max(t/t_ramp, 0) during the ramp, else N.
        // (The quotient only while a lane ramps: the rest of the run pays
        // no division for it.)
        let ramping = p.t_ramp.cmp_gt(zero) & t.cmp_lt(p.t_ramp);
        let load = if ramping.any() {
            ramping.blend(p.n * (t / p.t_ramp).max(zero), p.n)
        } else {
            p.n
        };
        dz[XD] = z[UD];
        dz[XP] = z[UP];
        dz[YD] = z[WD];
        dz[YP] = z[WP];
        dz[UD] = (p.neg_k_dx * z[XD] - p.c_dx * z[UD] - f_t) * p.inv_md;
        dz[UP] = (p.neg_k_px * z[XP] - p.c_px * z[UP] + f_t) * p.inv_mp;
        if any_stick {
            dz[UD] = stick.blend(a, dz[UD]);
            dz[UP] = stick.blend(a, dz[UP]);
        }
        dz[WD] = (p.neg_k_dy * z[YD] - p.c_dy * z[WD] - f_y + f_f) * p.inv_md;
        dz[WP] = (f_y - load - f_f) * p.inv_mp;
    }
}
