//! The 2-DOF mode-coupling model of Hoffmann, Fischer, Allgaier & Gaul
//! (2002), Mech. Res. Commun. 29, "A minimal model for studying properties of
//! the mode-coupling type instability in friction induced oscillations".
//!
//! A mass `m` with in-plane coordinates `q = (x, y)` rides on a belt moving at
//! speed `V` along +x. Its springs give a symmetric stiffness `[[k11, k12],
//! [k12, k22]]`; the contact spring `k3` makes the normal force depend on `y`,
//! `N = N0 + k3·y`, so the friction force `μ·N` couples `y` into the `x`
//! equation. Linearised about steady sliding (Coulomb friction):
//!
//! ```text
//! m q̈ + C q̇ + K q = 0,   C = diag(c1, c2),   K = [[k11, k12 − μ·k3], [k12, k22]]
//! ```
//!
//! `K` is not symmetric: as μ grows the two frequencies approach, coalesce
//! and split into a growing/decaying pair (mode-coupling flutter). For
//! `C = 0` the characteristic polynomial `det(m s² I + K) = 0` is a quadratic
//! in `m s²`; its discriminant vanishes at
//! `μ_c = ((k11 − k22)² + 4 k12²) / (4 k12 k3)`. With the defaults below
//! μ_c = 0.25 (the small equal damping moves it to 0.25014, the Hurwitz
//! condition on the quartic); the default μ = 0.3 flutters at 16.7 Hz with
//! σ ≈ +4.5 1/s.
//!
//! Nonlinear model (for simulation), state `z = (x, y, ẋ, ẏ)`:
//!
//! ```text
//! m ẍ = −c1 ẋ − k11 x − k12 y + F,   F = μ(|v|)·N·sign(v),  v = V − ẋ
//! m ÿ = −c2 ẏ − k12 x − k22 y
//! ```
//!
//! with `N = N0 + k3·y` while in contact (`N > 0`); at `N = 0` the mass loses
//! contact (mode Free: no friction) until `N` crosses zero upwards again. In
//! stick the mass rides the belt (`ẋ = V`, `ẍ = 0`) while the force it needs,
//! `F_s = c1 ẋ + k11 x + k12 y`, satisfies `|F_s| ≤ μ_s·N`.

use super::{
    contact, stick_or_slip, EventKind, GuardKind, Guards, Mode, Model, ModelError, Observables,
    Parameters,
};
use crate::friction::FrictionLaw;
use crate::params::{ParamError, ParamKind, ParamSpec};

/// Hoffmann model parameters (the friction coefficient lives in the friction law).
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_snake_case)]
pub struct HoffmannParams {
    /// Mass (kg).
    pub m: f64,
    /// Damping of x (kg/s).
    pub c1: f64,
    /// Damping of y (kg/s).
    pub c2: f64,
    /// Stiffness k11 (N/m).
    pub k11: f64,
    /// Coupling stiffness k12 = k21 (N/m).
    pub k12: f64,
    /// Stiffness k22 (N/m).
    pub k22: f64,
    /// Contact stiffness k3: `N = N0 + k3·y` (N/m).
    pub k3: f64,
    /// Belt speed (m/s).
    pub V: f64,
    /// Preload normal force at y = 0 (N).
    pub N0: f64,
}

impl HoffmannParams {
    /// The field called `key` (one place maps names to fields, for get and set).
    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        Some(match key {
            "m" => &mut self.m,
            "c1" => &mut self.c1,
            "c2" => &mut self.c2,
            "k11" => &mut self.k11,
            "k12" => &mut self.k12,
            "k22" => &mut self.k22,
            "k3" => &mut self.k3,
            "V" => &mut self.V,
            "N0" => &mut self.N0,
            _ => return None,
        })
    }
}

impl Default for HoffmannParams {
    /// m = 1 kg, c1 = c2 = 0.5 kg/s, k11 = 1e4, k12 = 2e3, k22 = 1.2e4,
    /// k3 = 1e4 N/m, V = 1 m/s, N0 = 100 N: frequencies 14.8 and 18.3 Hz at
    /// μ = 0, coalescing at 16.7 Hz at μ_c = 0.25.
    fn default() -> Self {
        HoffmannParams {
            m: 1.0,
            c1: 0.5,
            c2: 0.5,
            k11: 1.0e4,
            k12: 2.0e3,
            k22: 1.2e4,
            k3: 1.0e4,
            V: 1.0,
            N0: 100.0,
        }
    }
}

const SPECS: &[ParamSpec] = &[
    ParamSpec::new("m", "kg", "mass", ParamKind::Positive),
    ParamSpec::new("c1", "kg/s", "damping of x", ParamKind::NonNegative),
    ParamSpec::new("c2", "kg/s", "damping of y", ParamKind::NonNegative),
    ParamSpec::new("k11", "N/m", "stiffness k11", ParamKind::Positive),
    ParamSpec::new("k12", "N/m", "coupling stiffness k12 = k21", ParamKind::Any),
    ParamSpec::new("k22", "N/m", "stiffness k22", ParamKind::Positive),
    ParamSpec::new(
        "k3",
        "N/m",
        "contact stiffness: normal force N = N0 + k3·y",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "mu",
        "1",
        "friction coefficient (coulomb law: sets mu_s = mu_k)",
        ParamKind::NonNegative,
    ),
    ParamSpec::new("V", "m/s", "belt speed", ParamKind::NonNegative),
    ParamSpec::new("N0", "N", "preload normal force", ParamKind::NonNegative),
];

/// The Hoffmann et al. (2002) mode-coupling model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hoffmann {
    /// Mechanical parameters.
    pub p: HoffmannParams,
    /// Friction law μ(v); default Coulomb with `mu_s = mu_k = 0.3`.
    pub friction: FrictionLaw,
}

impl Default for Hoffmann {
    fn default() -> Self {
        Hoffmann {
            p: HoffmannParams::default(),
            friction: FrictionLaw::Coulomb {
                mu_s: 0.3,
                mu_k: 0.3,
            },
        }
    }
}

/// State indices.
const X: usize = 0;
const Y: usize = 1;
const VX: usize = 2;
const VY: usize = 3;

impl Hoffmann {
    /// Normal force `N0 + k3·y` (not clipped).
    #[inline]
    pub fn normal_force(&self, z: &[f64; 4]) -> f64 {
        self.p.N0 + self.p.k3 * z[Y]
    }

    /// Sliding velocity of the belt relative to the mass, `v = V − ẋ`.
    #[inline]
    pub fn sliding_velocity(&self, z: &[f64; 4]) -> f64 {
        self.p.V - z[VX]
    }

    /// Force the friction must supply to keep `ẍ = 0`: `c1 ẋ + k11 x + k12 y`.
    #[inline]
    fn stick_force(&self, z: &[f64; 4]) -> f64 {
        self.p.c1 * z[VX] + self.p.k11 * z[X] + self.p.k12 * z[Y]
    }

    /// Whether the contact can open or close: `N` depends on the state.
    #[inline]
    fn contact_varies(&self) -> bool {
        self.p.k3 != 0.0
    }

    /// Friction mode for a state in contact, from the sign of v (stick test at v = 0).
    fn friction_mode(&self, z: &[f64; 4]) -> Mode {
        contact::friction_mode(
            self.sliding_velocity(z),
            self.stick_force(z),
            self.stick_bound(z),
        )
    }

    /// `μ_s·max(N, 0)`.
    #[inline]
    fn stick_bound(&self, z: &[f64; 4]) -> f64 {
        self.friction.mu_static() * self.normal_force(z).max(0.0)
    }

    /// Stiffness matrix `K(μ) = [[k11, k12 − μ k3], [k12, k22]]` of the
    /// linearisation at friction coefficient μ.
    pub fn stiffness(&self, mu: f64) -> [[f64; 2]; 2] {
        let p = &self.p;
        [[p.k11, p.k12 - mu * p.k3], [p.k12, p.k22]]
    }
}

impl Parameters for Hoffmann {
    fn param_specs(&self) -> &'static [ParamSpec] {
        SPECS
    }

    /// `mu` is μ of the Coulomb law (`mu_k`); `None` for other laws.
    fn get(&self, key: &str) -> Option<f64> {
        if key == "mu" {
            return match self.friction {
                FrictionLaw::Coulomb { mu_k, .. } => Some(mu_k),
                _ => None,
            };
        }
        let mut p = self.p;
        p.slot(key).map(|v| *v).or_else(|| self.friction.get(key))
    }

    /// `mu` sets both `mu_s` and `mu_k` of the Coulomb law; with another law
    /// it is an error (set that law's own parameters).
    fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        let Some(spec) = SPECS.iter().find(|s| s.name == key) else {
            return self.friction.set(key, value);
        };
        spec.check(value)?;
        if let Some(slot) = self.p.slot(key) {
            *slot = value;
            return Ok(());
        }
        match &mut self.friction {
            FrictionLaw::Coulomb { mu_s, mu_k } => {
                *mu_s = value;
                *mu_k = value;
                Ok(())
            }
            other => Err(ParamError::Invalid {
                key: key.into(),
                value,
                why: format!(
                    "mu applies to the coulomb friction law; the law is '{}', set its own parameters",
                    other.name()
                ),
            }),
        }
    }

    fn friction_law(&self) -> &FrictionLaw {
        &self.friction
    }

    /// As the default, but `mu` is checked only under the Coulomb law.
    fn validate(&self) -> Result<(), ParamError> {
        for spec in SPECS {
            if spec.name == "mu" && !matches!(self.friction, FrictionLaw::Coulomb { .. }) {
                continue;
            }
            spec.check(self.get(spec.name).unwrap_or(f64::NAN))?;
        }
        self.friction.validate()
    }
}

impl Model<4> for Hoffmann {
    fn name(&self) -> &'static str {
        "hoffmann"
    }

    fn interface_name(&self) -> &'static str {
        "belt"
    }

    fn state_names(&self) -> [&'static str; 4] {
        ["x", "y", "vx", "vy"]
    }

    #[inline]
    fn rhs(&self, _t: f64, mode: Mode, z: &[f64; 4], dz: &mut [f64; 4]) {
        let p = &self.p;
        let spring_x = -p.c1 * z[VX] - p.k11 * z[X] - p.k12 * z[Y];
        dz[X] = z[VX];
        dz[Y] = z[VY];
        dz[VX] = match mode {
            Mode::Stick => 0.0,
            Mode::Free => spring_x / p.m,
            Mode::SlipPos | Mode::SlipNeg => {
                let n = self.normal_force(z).max(0.0);
                // s·v, not |v|: smooth past the guard (see FrictionLaw::mu).
                let v = mode.slip_sign() * self.sliding_velocity(z);
                (spring_x + mode.slip_sign() * self.friction.mu(v) * n) / p.m
            }
        };
        dz[VY] = (-p.c2 * z[VY] - p.k12 * z[X] - p.k22 * z[Y]) / p.m;
    }

    fn guards(&self, mode: Mode, out: &mut Guards<4>) {
        out.clear();
        let p = &self.p;
        if mode == Mode::Free {
            // Contact: N = N0 + k3 y crosses zero upwards.
            if self.contact_varies() {
                out.push(GuardKind::Contact, [0.0, p.k3, 0.0, 0.0], p.N0);
            }
            return;
        }
        // N = N0 + k3 y.
        let normal = ([0.0, p.k3, 0.0, 0.0], p.N0);
        if self.contact_varies() {
            // Separation: −N crosses zero upwards.
            let (c, d) = contact::separation_guard(&normal);
            out.push(GuardKind::Separation, c, d);
        }
        match mode {
            Mode::SlipPos | Mode::SlipNeg => {
                // v = V − ẋ.
                let (c, d) = contact::slip_zero_guard(mode, &([0.0, 0.0, -1.0, 0.0], p.V));
                out.push(GuardKind::SlipZero, c, d);
            }
            Mode::Stick => {
                // ±F_s − μ_s N, F_s = k11 x + k12 y + c1 ẋ.
                let fs = ([p.k11, p.k12, p.c1, 0.0], 0.0);
                for (kind, (c, d)) in
                    contact::stick_break_guards(&fs, &normal, self.friction.mu_static())
                {
                    out.push(kind, c, d);
                }
            }
            Mode::Free => unreachable!("handled above"),
        }
    }

    fn transition(
        &self,
        _t: f64,
        mode: Mode,
        guard: GuardKind,
        z: &mut [f64; 4],
    ) -> (Mode, Option<EventKind>) {
        if guard == GuardKind::SlipZero {
            // On the surface v = 0 exactly.
            z[VX] = self.p.V;
        }
        let z = &*z;
        contact::after_guard(guard, mode, || {
            if guard == GuardKind::SlipZero {
                stick_or_slip(self.stick_force(z), self.stick_bound(z))
            } else {
                self.friction_mode(z)
            }
        })
    }

    fn initial_mode(&self, _t: f64, z: &[f64; 4]) -> Mode {
        if self.normal_force(z) <= 0.0 {
            return Mode::Free;
        }
        self.friction_mode(z)
    }

    fn observe(&self, _t: f64, mode: Mode, z: &[f64; 4]) -> Observables {
        let v_rel = self.sliding_velocity(z);
        let (normal_force, friction_force) = match mode {
            Mode::Free => (0.0, 0.0),
            Mode::Stick => (self.normal_force(z), self.stick_force(z)),
            Mode::SlipPos | Mode::SlipNeg => {
                let n = self.normal_force(z).max(0.0);
                (n, mode.slip_sign() * self.friction.mu(v_rel.abs()) * n)
            }
        };
        Observables {
            normal_force,
            friction_force,
            v_rel,
        }
    }

    /// Solves `K(μ*)·q* = (μ*·N0, 0)` with `μ* = μ(V)` (Cramer's rule), at
    /// rest. Fails if V ≤ 0, if `det K(μ*) = k11 k22 − k12 (k12 − μ* k3)` is
    /// zero, or if the normal force `N0 + k3 y*` there is not positive.
    fn equilibrium(&self) -> Result<[f64; 4], ModelError> {
        let p = &self.p;
        if p.V <= 0.0 {
            return Err(ModelError::NoSteadySliding(format!(
                "V = {} (the belt must move)",
                p.V
            )));
        }
        let mu = self.friction.mu(p.V);
        let k = self.stiffness(mu);
        let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
        let scale = (k[0][0] * k[1][1]).abs() + (k[0][1] * k[1][0]).abs();
        if det.abs() <= 1e-14 * scale || !det.is_finite() {
            return Err(ModelError::NoSteadySliding(format!(
                "det K(μ(V)) = {det:.3e}: the friction-modified stiffness is singular (μ(V) = {mu})"
            )));
        }
        let f = mu * p.N0;
        let x = f * k[1][1] / det;
        let y = -f * k[1][0] / det;
        let n = p.N0 + p.k3 * y;
        if n <= 0.0 || n.is_nan() {
            return Err(ModelError::NoSteadySliding(format!(
                "the normal force at the sliding equilibrium, N0 + k3·y* = {n:.3e} N, is not positive"
            )));
        }
        Ok([x, y, 0.0, 0.0])
    }

    /// `∂f/∂z` of the slip equations (sliding direction `s` = sign of v at `z`):
    /// with `F = s μ(|v|) N`, `∂F/∂y = s μ k3` and `∂F/∂ẋ = −μ'(|v|) N` while
    /// `N > 0` (both 0 without contact).
    fn jacobian(&self, z: &[f64; 4]) -> [[f64; 4]; 4] {
        let p = &self.p;
        let v = self.sliding_velocity(z);
        let (s, vabs) = if v >= 0.0 { (1.0, v) } else { (-1.0, -v) };
        let n = self.normal_force(z);
        let (dfdy, dfdvx) = if n > 0.0 {
            (
                s * self.friction.mu(vabs) * p.k3,
                -self.friction.dmu(vabs) * n,
            )
        } else {
            (0.0, 0.0)
        };
        [
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [
                -p.k11 / p.m,
                (-p.k12 + dfdy) / p.m,
                (-p.c1 + dfdvx) / p.m,
                0.0,
            ],
            [-p.k12 / p.m, -p.k22 / p.m, 0.0, -p.c2 / p.m],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mu_key_is_the_coulomb_coefficient() {
        let mut h = Hoffmann::default();
        assert_eq!(h.get("mu"), Some(0.3));
        h.set("mu", 0.42).unwrap();
        assert_eq!(
            h.friction,
            FrictionLaw::Coulomb {
                mu_s: 0.42,
                mu_k: 0.42
            }
        );
        assert!(h.set("mu", -1.0).is_err());
        h.validate().unwrap();
        h.friction = FrictionLaw::default();
        let err = h.set("mu", 0.2).unwrap_err().to_string();
        assert!(err.contains("coulomb"), "{err}");
        assert_eq!(h.get("mu"), None);
        h.validate().unwrap();
        // Friction-law keys pass through.
        h.set("f1", 0.0).unwrap();
        assert_eq!(h.get("f1"), Some(0.0));
        assert!(h.set("bogus", 1.0).is_err());
    }

    #[test]
    fn equilibrium_balances_the_forces() {
        let h = Hoffmann::default();
        let z = h.equilibrium().unwrap();
        let mut dz = [0.0; 4];
        h.rhs(0.0, Mode::SlipPos, &z, &mut dz);
        for (i, d) in dz.iter().enumerate() {
            assert!(d.abs() < 1e-12, "dz[{i}] = {d:e}");
        }
        let mut h = Hoffmann::default();
        h.set("V", 0.0).unwrap();
        assert!(matches!(
            h.equilibrium(),
            Err(ModelError::NoSteadySliding(_))
        ));
        // N* = N0 (k11 k22 − k12²)/det K(μ): negative when det K(μ) < 0 < det K(0).
        let mut h = Hoffmann::default();
        h.set("k12", -5.0e3).unwrap();
        h.set("mu", 2.0).unwrap();
        let e = h.equilibrium();
        assert!(
            matches!(e, Err(ModelError::NoSteadySliding(ref m)) if m.contains("normal force")),
            "{e:?}"
        );
    }

    #[test]
    fn guards_are_negative_inside_their_modes() {
        let h = Hoffmann::default();
        let z = h.equilibrium().unwrap();
        let mut g = Guards::default();
        h.guards(Mode::SlipPos, &mut g);
        assert!(g.as_slice().iter().all(|g| g.eval(&z) < 0.0));
        // At v = 0 from the equilibrium position, F_s = μ N* + c1 V > μ_s N*
        // (μ_s = μ_k): the mass slips on.
        let mut zs = z;
        zs[VX] = h.p.V;
        assert!(h.stick_force(&zs) > h.friction.mu_static() * h.normal_force(&zs));
        assert_eq!(h.initial_mode(0.0, &zs), Mode::SlipPos);
        let mut zf = z;
        zf[Y] = -1.0;
        assert_eq!(h.initial_mode(0.0, &zf), Mode::Free);
        h.guards(Mode::Free, &mut g);
        assert!(g.as_slice().iter().all(|g| g.eval(&zf) < 0.0));
    }
}
