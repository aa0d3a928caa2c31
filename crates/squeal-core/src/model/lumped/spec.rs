//! A lumped model's description: dofs, masses, springs, forces, contacts and
//! matrices, as a scenario file or a built-in gives them ([`LumpedSpec`]).

use super::*;

/// A spring–damper on `e = on·q`, linear unless `k3 ≠ 0` (a Duffing
/// spring): generalised force `−(k e + k3 e³ + c ė)·on`.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// Element name.
    pub name: String,
    /// The elongation's coefficients.
    pub on: Combination,
    /// Stiffness (N/m).
    pub k: f64,
    /// Damping (kg/s).
    pub c: f64,
    /// Cubic stiffness (N/m³): hardening if positive.
    pub k3: f64,
}

/// A generalised force `(value + amplitude·cos 2πf t)·on`: a static part and
/// an optional harmonic part of frequency `freq_hz`, both optionally ramped
/// up linearly over `ramp` seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Force {
    /// Element name.
    pub name: String,
    /// Where it acts.
    pub on: Combination,
    /// Static value (N).
    pub value: f64,
    /// Ramp time (s); 0: a step at t = 0.
    pub ramp: f64,
    /// Amplitude of the harmonic part (N); 0: none.
    pub amplitude: f64,
    /// Frequency of the harmonic part (Hz).
    pub freq_hz: f64,
}

impl Force {
    /// Factor of the value at time `t` (1 after the ramp).
    #[inline]
    pub fn factor(&self, t: f64) -> f64 {
        if self.ramp > 0.0 && t < self.ramp {
            (t / self.ramp).max(0.0)
        } else {
            1.0
        }
    }

    /// Whether it has a harmonic part.
    #[inline]
    pub fn is_harmonic(&self) -> bool {
        self.amplitude != 0.0
    }

    /// Whether it varies in time (a ramp or a harmonic part).
    #[inline]
    pub fn varies(&self) -> bool {
        self.ramp > 0.0 || self.is_harmonic()
    }

    /// The force at time `t`: `factor(t)·(value + amplitude·cos 2πf t)` (N).
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        let harmonic = if self.is_harmonic() {
            self.amplitude * (std::f64::consts::TAU * self.freq_hz * t).cos()
        } else {
            0.0
        };
        self.factor(t) * (self.value + harmonic)
    }

    /// An upper bound of `|d at/dt|` on `[t0, t0 + h]` (N/s).
    pub fn rate_bound(&self, t0: f64) -> f64 {
        let omega = std::f64::consts::TAU * self.freq_hz;
        let ramping = self.ramp > 0.0 && t0 < self.ramp;
        let mut r = self.amplitude.abs() * omega;
        if ramping {
            r += (self.value.abs() + self.amplitude.abs()) / self.ramp;
        }
        r
    }
}

/// A dof combination as written by users: `(dof name, coefficient)`.
pub type Terms = Vec<(String, f64)>;

/// Description of a spring.
#[derive(Debug, Clone, PartialEq)]
pub struct SpringSpec {
    /// Element name.
    pub name: String,
    /// `on`.
    pub on: Terms,
    /// `k` (N/m).
    pub k: f64,
    /// `c` (kg/s).
    pub c: f64,
    /// `k3` (N/m³): cubic stiffness, 0 for a linear spring.
    pub k3: f64,
}

/// Description of a force.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceSpec {
    /// Element name.
    pub name: String,
    /// `on`.
    pub on: Terms,
    /// `value` (N): the static part.
    pub value: f64,
    /// `ramp` (s).
    pub ramp: f64,
    /// `amplitude` (N): the harmonic part's, 0 for none.
    pub amplitude: f64,
    /// `freq_hz` (Hz): the harmonic part's frequency.
    pub freq_hz: f64,
}

/// Description of a contact (the keys of a `[[contact]]` table).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSpec {
    /// Element name.
    pub name: String,
    /// `normal`: the compression's coefficients (with `k`, `c`).
    pub normal: Option<Terms>,
    /// `k` (N/m).
    pub k: Option<f64>,
    /// `c` (kg/s).
    pub c: Option<f64>,
    /// `contact`: unilateral (default) or bilateral.
    pub bilateral: bool,
    /// `normal_force`: a prescribed load instead of `normal`/`k`/`c`.
    pub normal_force: Option<f64>,
    /// `tangent`.
    pub tangent: Option<Terms>,
    /// `V` (m/s).
    pub v: f64,
    /// The friction law with its parameters.
    pub friction: FrictionLaw,
    /// `alpha` (1/m).
    pub alpha: f64,
    /// `slope`.
    pub slope: Terms,
}

/// Everything a lumped model is built from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LumpedSpec {
    /// Dof names, in state order.
    pub dofs: Vec<String>,
    /// `[masses]`: dof → mass (kg), added to the diagonal of `M`.
    pub masses: Vec<(String, f64)>,
    /// Mass matrix (symmetric positive definite with the masses added).
    pub m: Option<Triplets>,
    /// Stiffness matrix.
    pub k: Option<Triplets>,
    /// Damping matrix.
    pub c: Option<Triplets>,
    /// Springs.
    pub springs: Vec<SpringSpec>,
    /// Forces.
    pub forces: Vec<ForceSpec>,
    /// Contacts.
    pub contacts: Vec<ContactSpec>,
    /// `[params]`: shared, named parameters (`mu = 0.45`), in order.
    pub params: Vec<(String, f64)>,
    /// Element keys bound to expressions of `params` (`("inner.mu_k",
    /// "mu")`); the spec's numbers for these keys are replaced by the
    /// expressions' values when the model is built.
    pub expressions: Vec<(String, String)>,
}
