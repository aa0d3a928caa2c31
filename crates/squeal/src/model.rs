//! The models the command line knows, behind one enum, with their output columns.

use squeal_core::model::Observables;
use squeal_core::{Belt, DiscPad, Hoffmann, Mode, Model, ParamError, ParamSpec, Parameters};

/// Any model squeal can run. Adding a model: one variant here and one arm in
/// [`with_model!`](crate::with_model); the integrator and the commands stay unchanged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyModel {
    /// The 4-DOF disc–pad model of the thesis.
    DiscPad(DiscPad),
    /// The 1-DOF mass on a moving belt.
    Belt(Belt),
    /// The 2-DOF mode-coupling model of Hoffmann et al. (2002).
    Hoffmann(Hoffmann),
}

/// Run `$body` with `$m` bound to the concrete model (generic code inside).
#[macro_export]
macro_rules! with_model {
    ($any:expr, $m:ident => $body:expr) => {
        match $any {
            $crate::model::AnyModel::DiscPad($m) => $body,
            $crate::model::AnyModel::Belt($m) => $body,
            $crate::model::AnyModel::Hoffmann($m) => $body,
        }
    };
}

/// Names of the models, as typed in a scenario's `model` key.
pub const MODEL_NAMES: [&str; 3] = ["disc-pad", "belt", "hoffmann"];

impl AnyModel {
    /// The model called `name` with its defaults.
    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "disc-pad" => Some(AnyModel::DiscPad(DiscPad::default())),
            "belt" => Some(AnyModel::Belt(Belt::default())),
            "hoffmann" => Some(AnyModel::Hoffmann(Hoffmann::default())),
            _ => None,
        }
    }
    /// Model name.
    pub fn name(&self) -> &'static str {
        with_model!(self, m => m.name())
    }
    /// State names (positions then velocities).
    pub fn state_names(&self) -> Vec<&'static str> {
        with_model!(self, m => m.state_names().to_vec())
    }
    /// Names of the derived columns written after the states in `series.csv`.
    pub fn derived_columns(&self) -> &'static [&'static str] {
        match self {
            AnyModel::DiscPad(_) => &["F_y", "F_t", "v_rel", "mode"],
            AnyModel::Belt(_) => &["F_t", "v_rel", "mode"],
            AnyModel::Hoffmann(_) => &["N", "F_t", "v_rel", "mode"],
        }
    }
    /// Derived values matching [`Self::derived_columns`] (the mode flag last).
    pub fn derived_values(&self, obs: &Observables, mode: Mode, out: &mut Vec<f64>) {
        out.clear();
        if let AnyModel::DiscPad(_) | AnyModel::Hoffmann(_) = self {
            out.push(obs.normal_force);
        }
        out.push(obs.friction_force);
        out.push(obs.v_rel);
        out.push(mode.flag() as f64);
    }
    /// The model's own parameters (without the friction law's).
    pub fn param_specs(&self) -> &'static [ParamSpec] {
        with_model!(self, m => m.param_specs())
    }
    /// The friction law.
    pub fn friction(&self) -> squeal_core::FrictionLaw {
        *with_model!(self, m => m.friction_law())
    }
    /// Replace the friction law.
    pub fn set_friction(&mut self, law: squeal_core::FrictionLaw) {
        with_model!(self, m => m.friction = law)
    }
    /// Parameter by name (model or friction law).
    pub fn get(&self, key: &str) -> Option<f64> {
        with_model!(self, m => m.get(key))
    }
    /// Set a parameter by name (model or friction law).
    pub fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        with_model!(self, m => m.set(key, value))
    }
    /// Check relations between parameters.
    pub fn validate(&self) -> Result<(), ParamError> {
        with_model!(self, m => m.validate())
    }
    /// The signals shown and analysed for this model.
    pub fn channels(&self) -> Channels {
        channels_for(self.name())
    }
}

/// Which columns the pictures and metrics use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Channels {
    /// Tangential velocity (the disc's, or the mass's).
    pub tangential: &'static str,
    /// Normal velocity, if the model has one.
    pub normal: Option<&'static str>,
    /// Displacement and velocity of the phase portrait (the pad's tangential motion).
    pub phase: (&'static str, &'static str),
}

/// Channels by model name (also used for runs read back from disk).
pub fn channels_for(model: &str) -> Channels {
    match model {
        "belt" => Channels {
            tangential: "v",
            normal: None,
            phase: ("x", "v"),
        },
        "hoffmann" => Channels {
            tangential: "vx",
            normal: Some("vy"),
            phase: ("x", "vx"),
        },
        _ => Channels {
            tangential: "vx_d",
            normal: Some("vy_d"),
            phase: ("x_p", "vx_p"),
        },
    }
}

/// Words for a coordinate, for the terminal ("pad tangential" for `x_p`).
pub fn coordinate_words(name: &str) -> Option<&'static str> {
    Some(match name {
        "x_d" => "disc tangential",
        "x_p" => "pad tangential",
        "y_d" => "disc normal",
        "y_p" => "pad normal",
        "x" => "tangential",
        "y" => "normal",
        _ => return None,
    })
}
