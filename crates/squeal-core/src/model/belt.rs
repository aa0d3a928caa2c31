//! The classic 1-DOF mass on a moving belt: `m ẍ + c ẋ + k x = F`, with the
//! friction force `F = μ(|v|)·N·sign(v)` of the belt on the mass, `v = V − ẋ`.
//! In stick the mass rides the belt (`ẋ = V`) while `|k x + c V| ≤ μ_s N`.
//!
//! State `z = (x, ẋ)`.

use super::{
    contact, stick_or_slip, EventKind, GuardKind, Guards, Mode, Model, ModelError, Observables,
    Parameters,
};
use crate::friction::FrictionLaw;
use crate::params::{ParamError, ParamKind, ParamSpec};

/// Belt parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_snake_case)]
pub struct BeltParams {
    /// Mass (kg).
    pub m: f64,
    /// Spring stiffness (N/m).
    pub k: f64,
    /// Damping (kg/s).
    pub c: f64,
    /// Belt speed (m/s).
    pub V: f64,
    /// Normal force (N).
    pub N: f64,
}

impl BeltParams {
    /// The field called `key` (one place maps names to fields, for get and set).
    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        Some(match key {
            "m" => &mut self.m,
            "k" => &mut self.k,
            "c" => &mut self.c,
            "V" => &mut self.V,
            "N" => &mut self.N,
            _ => return None,
        })
    }
}

impl Default for BeltParams {
    fn default() -> Self {
        BeltParams {
            m: 1.0,
            k: 1.0e4,
            c: 0.0,
            V: 0.1,
            N: 100.0,
        }
    }
}

const SPECS: &[ParamSpec] = &[
    ParamSpec::new("m", "kg", "mass", ParamKind::Positive),
    ParamSpec::new("k", "N/m", "spring stiffness", ParamKind::Positive),
    ParamSpec::new("c", "kg/s", "damping", ParamKind::NonNegative),
    ParamSpec::new("V", "m/s", "belt speed", ParamKind::NonNegative),
    ParamSpec::new("N", "N", "normal force", ParamKind::NonNegative),
];

/// The mass-on-a-belt model.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Belt {
    /// Mechanical parameters.
    pub p: BeltParams,
    /// Friction law μ(v).
    pub friction: FrictionLaw,
}

impl Belt {
    /// Spring–damper force the friction must balance in stick: `k x + c ẋ`.
    #[inline]
    fn stick_force(&self, z: &[f64; 2]) -> f64 {
        self.p.k * z[0] + self.p.c * z[1]
    }
}

impl Parameters for Belt {
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

impl Model<2> for Belt {
    fn name(&self) -> &'static str {
        "belt"
    }
    fn interface_name(&self) -> &'static str {
        "belt"
    }

    fn state_names(&self) -> [&'static str; 2] {
        ["x", "v"]
    }
    #[inline]
    fn rhs(&self, _t: f64, mode: Mode, z: &[f64; 2], dz: &mut [f64; 2]) {
        let p = &self.p;
        dz[0] = z[1];
        dz[1] = match mode {
            Mode::Stick => 0.0,
            Mode::Free => (-p.k * z[0] - p.c * z[1]) / p.m,
            _ => {
                // s·v, not |v|: smooth past the guard (see FrictionLaw::mu).
                let v = mode.slip_sign() * (p.V - z[1]);
                (-p.k * z[0] - p.c * z[1] + mode.slip_sign() * self.friction.mu(v) * p.N) / p.m
            }
        };
    }
    fn guards(&self, mode: Mode, out: &mut Guards<2>) {
        out.clear();
        let p = &self.p;
        match mode {
            Mode::SlipPos | Mode::SlipNeg => {
                // v = V − ẋ.
                let (c, d) = contact::slip_zero_guard(mode, &([0.0, -1.0], p.V));
                out.push(GuardKind::SlipZero, c, d);
            }
            Mode::Stick => {
                // ±(k x + c ẋ) − μ_s N, the load N prescribed.
                let fs = ([p.k, p.c], 0.0);
                let normal = ([0.0, 0.0], p.N);
                for (kind, (c, d)) in
                    contact::stick_break_guards(&fs, &normal, self.friction.mu_static())
                {
                    out.push(kind, c, d);
                }
            }
            Mode::Free => {}
        }
    }
    fn transition(
        &self,
        _t: f64,
        mode: Mode,
        guard: GuardKind,
        z: &mut [f64; 2],
    ) -> (Mode, Option<EventKind>) {
        if matches!(guard, GuardKind::Separation | GuardKind::Contact) {
            // The load is prescribed: the belt never pushes these guards.
            return (mode, None);
        }
        if guard == GuardKind::SlipZero {
            z[1] = self.p.V;
        }
        let z = &*z;
        contact::after_guard(guard, mode, || {
            stick_or_slip(self.stick_force(z), self.friction.mu_static() * self.p.N)
        })
    }
    fn initial_mode(&self, _t: f64, z: &[f64; 2]) -> Mode {
        contact::friction_mode(
            self.p.V - z[1],
            self.stick_force(z),
            self.friction.mu_static() * self.p.N,
        )
    }
    fn observe(&self, _t: f64, mode: Mode, z: &[f64; 2]) -> Observables {
        let v_rel = self.p.V - z[1];
        let friction_force = match mode {
            Mode::Stick => self.stick_force(z),
            Mode::Free => 0.0,
            _ => mode.slip_sign() * self.friction.mu(v_rel.abs()) * self.p.N,
        };
        Observables {
            normal_force: self.p.N,
            friction_force,
            v_rel,
        }
    }
    /// `x* = μ(V)·N/k`, at rest.
    fn equilibrium(&self) -> Result<[f64; 2], ModelError> {
        if self.p.V <= 0.0 {
            return Err(ModelError::NoSteadySliding(format!(
                "V = {} (the belt must move)",
                self.p.V
            )));
        }
        Ok([self.friction.mu(self.p.V) * self.p.N / self.p.k, 0.0])
    }
    /// `[[0, 1], [−k/m, −(c + N μ'(V − ẋ))/m]]` (sign of v taken at `z`).
    fn jacobian(&self, z: &[f64; 2]) -> [[f64; 2]; 2] {
        let p = &self.p;
        let v = p.V - z[1];
        // F = s μ(|v|) N, ∂F/∂ẋ = s μ'(|v|) s (−1) N = −μ'(|v|) N.
        let dfdv = -self.friction.dmu(v.abs()) * p.N;
        [[0.0, 1.0], [-p.k / p.m, (-p.c + dfdv) / p.m]]
    }
}
