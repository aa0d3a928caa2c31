//! The models the command line knows, behind one enum, with their output columns.

use squeal_core::model::lumped::{MAX_SIM_DOFS, MAX_TRANSIENT_DOFS};
use squeal_core::model::{Modes, Observables};
use squeal_core::params::ParamKind;
use squeal_core::stability::{self, Analysis, Inertia, StabilityError};
use squeal_core::{
    Belt, DiscPad, Hoffmann, Lumped, Model, ParamError, ParamSpec, Parameters, System,
};

/// Any model squeal can run. Adding a model: one variant here and one arm in
/// [`with_model!`](crate::with_model) and [`with_system!`](crate::with_system);
/// the integrator and the commands stay unchanged.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyModel {
    /// The 4-DOF disc–pad model of the thesis.
    DiscPad(DiscPad),
    /// The 1-DOF mass on a moving belt.
    Belt(Belt),
    /// The 2-DOF mode-coupling model of Hoffmann et al. (2002).
    Hoffmann(Hoffmann),
    /// A lumped model described in a scenario file (`model = "lumped"`).
    Lumped(Box<Lumped>),
}

/// Run `$body` with `$m` bound to a hand-written model (its `Parameters`
/// and `Model` traits inside); `$lumped` for a lumped model.
#[macro_export]
macro_rules! with_model {
    ($any:expr, $m:ident => $body:expr, lumped $l:ident => $lumped:expr) => {
        match $any {
            $crate::model::AnyModel::DiscPad($m) => $body,
            $crate::model::AnyModel::Belt($m) => $body,
            $crate::model::AnyModel::Hoffmann($m) => $body,
            $crate::model::AnyModel::Lumped($l) => $lumped,
        }
    };
}

/// Run `$body` with `$m` bound to a `&impl System<N>` with a fixed state
/// count (generic code inside: simulation, stability); `$fallback` for a
/// lumped model too large to simulate (more than `MAX_SIM_DOFS` dofs).
#[macro_export]
macro_rules! with_system {
    ($any:expr, $m:ident => $body:expr, else => $fallback:expr) => {
        match $any {
            $crate::model::AnyModel::DiscPad($m) => $body,
            $crate::model::AnyModel::Belt($m) => $body,
            $crate::model::AnyModel::Hoffmann($m) => $body,
            $crate::model::AnyModel::Lumped(l) => {
                squeal_core::with_lumped_size!(&**l, $m => $body, else => $fallback)
            }
        }
    };
}

/// As [`with_system!`](crate::with_system), for simulation only: a lumped
/// model of more than `MAX_EXACT_DOFS` (and at most `MAX_SIM_DOFS`) dofs runs
/// padded with idle dofs (`squeal_core::model::lumped::padding`): run it
/// with `run::sim_options` and `run::initial_of`, and read
/// only its real states. Never for an eigen-analysis (the idle dofs would
/// add their modes); `squeal_core::cycle`'s Floquet analysis leaves them out
/// (it covers [`System::norm_states`](squeal_core::System::norm_states)), so
/// `cycle` and `branch` use it too.
#[macro_export]
macro_rules! with_sim_system {
    ($any:expr, $m:ident => $body:expr, else => $fallback:expr) => {
        match $any {
            $crate::model::AnyModel::DiscPad($m) => $body,
            $crate::model::AnyModel::Belt($m) => $body,
            $crate::model::AnyModel::Hoffmann($m) => $body,
            $crate::model::AnyModel::Lumped(l) => {
                squeal_core::with_lumped_size!(&**l, $m => $body,
                    else => squeal_core::with_padded_size!(&**l, $m => $body, else => $fallback))
            }
        }
    };
}

/// As [`with_sim_system!`](crate::with_sim_system), for transient runs only
/// (`simulate`, `listen`, `map --transient`): a lumped model of more than
/// `MAX_SIM_DOFS` (and at most `MAX_TRANSIENT_DOFS`) dofs runs in one of the
/// larger padded sizes (`squeal_core::model::lumped::TRANSIENT_PADDED_DOFS`),
/// compiled for these runs alone (a limit cycle of that size is refused).
#[macro_export]
macro_rules! with_transient_system {
    ($any:expr, $m:ident => $body:expr, else => $fallback:expr) => {
        match $any {
            $crate::model::AnyModel::Lumped(l) if l.dof_count() > squeal_core::model::lumped::MAX_SIM_DOFS => {
                squeal_core::with_transient_padded_size!(&**l, $m => $body, else => $fallback)
            }
            any => $crate::with_sim_system!(any, $m => $body, else => $fallback),
        }
    };
}

/// Names of the models, as typed in a scenario's `model` key.
pub const MODEL_NAMES: [&str; 4] = ["disc-pad", "belt", "hoffmann", "lumped"];

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
    /// The frequencies (Hz) of the model's harmonic forces, ascending
    /// (lumped models' `[[force]]` with `amplitude` and `freq_hz`); empty for
    /// an autonomous model.
    pub fn forcing_hz(&self) -> Vec<f64> {
        match self {
            AnyModel::Lumped(l) => l.forcing_hz(),
            _ => Vec::new(),
        }
    }
    /// Model name.
    pub fn name(&self) -> &'static str {
        with_model!(self, m => m.name(), lumped _l => "lumped")
    }
    /// State names (positions then velocities).
    pub fn state_names(&self) -> Vec<String> {
        with_model!(self, m => m.state_names().iter().map(|s| s.to_string()).collect(),
            lumped l => l.state_names().to_vec())
    }
    /// Names of the derived columns written after the states in `series.csv`.
    pub fn derived_columns(&self) -> Vec<String> {
        let fixed = |c: &[&str]| c.iter().map(|s| s.to_string()).collect();
        match self {
            AnyModel::DiscPad(_) => fixed(&["F_y", "F_t", "v_rel", "mode"]),
            AnyModel::Belt(_) => fixed(&["F_t", "v_rel", "mode"]),
            AnyModel::Hoffmann(_) => fixed(&["N", "F_t", "v_rel", "mode"]),
            AnyModel::Lumped(l) => l
                .contacts
                .iter()
                .flat_map(|c| ["F_n", "F_t", "v_rel", "mode"].map(|k| format!("{}.{k}", c.name)))
                .collect(),
        }
    }
    /// Derived values matching [`Self::derived_columns`]: per contact its
    /// observables and mode flag.
    pub fn derived_values(&self, obs: &[Observables], modes: &Modes, out: &mut Vec<f64>) {
        out.clear();
        for (i, o) in obs.iter().enumerate() {
            if !matches!(self, AnyModel::Belt(_)) {
                out.push(o.normal_force);
            }
            out.push(o.friction_force);
            out.push(o.v_rel);
            out.push(modes.get(i).flag() as f64);
        }
    }
    /// The model's own parameters (without the friction law's), for the
    /// hand-written models; empty for a lumped model (see [`Self::keys`]).
    pub fn param_specs(&self) -> &'static [ParamSpec] {
        with_model!(self, m => m.param_specs(), lumped _l => &[])
    }
    /// Every parameter key with its unit, meaning and kind (the friction law's included).
    pub fn keys(&self) -> Vec<(String, &'static str, String, ParamKind)> {
        match self {
            AnyModel::Lumped(l) => l
                .keys()
                .into_iter()
                .map(|(k, _)| {
                    let (unit, doc) = l.describe(&k).unwrap_or(("", String::new()));
                    let kind = l.kind_of(&k);
                    (k, unit, doc, kind)
                })
                .collect(),
            _ => self
                .param_specs()
                .iter()
                .chain(self.friction().params())
                .map(|s| (s.name.to_string(), s.unit, s.doc.to_string(), s.kind))
                .collect(),
        }
    }
    /// The friction law (a lumped model's first contact's).
    pub fn friction(&self) -> squeal_core::FrictionLaw {
        with_model!(self, m => *m.friction_law(),
            lumped l => l.contacts.first().map(|c| c.friction).unwrap_or_default())
    }
    /// Replace the friction law (hand-written models; every contact of a lumped one).
    pub fn set_friction(&mut self, law: squeal_core::FrictionLaw) {
        with_model!(self, m => m.friction = law,
            lumped l => l.contacts.iter_mut().for_each(|c| c.friction = law))
    }
    /// Parameter by name (model or friction law).
    pub fn get(&self, key: &str) -> Option<f64> {
        with_model!(self, m => m.get(key), lumped l => l.get(key))
    }
    /// Set a parameter by name (model or friction law).
    pub fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        with_model!(self, m => m.set(key, value), lumped l => l.set(key, value))
    }
    /// Check relations between parameters.
    pub fn validate(&self) -> Result<(), ParamError> {
        with_model!(self, m => m.validate(), lumped l => l.validate())
    }
    /// The signals shown and analysed for this model.
    pub fn channels(&self) -> Channels {
        match self {
            AnyModel::Lumped(l) => lumped_channels(l),
            _ => channels_for(self.name()),
        }
    }
    /// Whether the model can be simulated (lumped: at most `MAX_TRANSIENT_DOFS` dofs).
    pub fn check_simulable(&self) -> Result<(), String> {
        match self {
            AnyModel::Lumped(l) if l.dof_count() > MAX_TRANSIENT_DOFS => Err(format!(
                "this lumped model has {} dofs: simulation supports up to {MAX_TRANSIENT_DOFS} dofs (stability, map, critical and sweep work for any size; `squeal reduce` makes a Craig–Bampton model of it with the contact dofs kept, which simulates)",
                l.dof_count()
            )),
            _ => Ok(()),
        }
    }
    /// Whether the model's limit cycles can be analysed (`cycle`, `branch`:
    /// Floquet multipliers on fixed-size states; lumped: at most
    /// `MAX_SIM_DOFS` dofs; transient runs go to `MAX_TRANSIENT_DOFS`).
    pub fn check_cycle_size(&self) -> Result<(), String> {
        match self {
            AnyModel::Lumped(l) if l.dof_count() > MAX_SIM_DOFS => Err(format!(
                "this lumped model has {} dofs: cycle and branch support up to {MAX_SIM_DOFS} dofs (their Floquet analysis costs the cube of the state count per step; simulate, listen and map --transient go to {MAX_TRANSIENT_DOFS}, stability, map, critical and sweep any size; `squeal reduce` with a lower modal.cutoff_hz makes a smaller Craig–Bampton model of it)",
                l.dof_count()
            )),
            _ => Ok(()),
        }
    }
    /// Full stability analysis with mass-weighted mode attribution.
    pub fn analyse(&self) -> Result<Analysis, StabilityError> {
        match self {
            AnyModel::Lumped(l) if l.modal.projects(l.dof_count()) => {
                stability::lumped::analyse(l, Some(&l.diagonal_masses()))
            }
            AnyModel::Lumped(l) => {
                let masses = l.diagonal_masses();
                squeal_core::with_lumped_size!(&**l,
                    m => stability::analyse_with_masses(m, &masses),
                    else => stability::lumped::analyse(l, Some(&masses)))
            }
            _ => with_model!(self, m => stability::analyse_with_masses(m, &m.position_masses()),
                lumped _l => unreachable!("handled above")),
        }
    }
    /// Every eigenvalue of steady sliding, as [`max_growth_rate`](Self::max_growth_rate)
    /// finds them (the fixed-size path where it applies, else dense or
    /// projected as `modal` says).
    pub fn eigenvalues(&self) -> Result<Vec<nalgebra::Complex<f64>>, StabilityError> {
        if let AnyModel::Lumped(l) = self {
            if l.modal.projects(l.dof_count()) {
                return stability::lumped::eigenvalues(l);
            }
        }
        crate::with_system!(self, m => stability::eigenvalues(m).map(|e| e.to_vec()),
        else => match self {
            AnyModel::Lumped(l) => stability::lumped::eigenvalues(l),
            _ => unreachable!("only lumped models have no fixed size"),
        })
    }
    /// The steady-sliding state and the full state matrix there, for a
    /// model analysed densely; `None` for a lumped model analysed by
    /// projection (above `modal.dense_max_dofs` dofs).
    #[allow(clippy::type_complexity)]
    pub fn state_matrix(
        &self,
    ) -> Option<Result<(Vec<f64>, nalgebra::DMatrix<f64>), StabilityError>> {
        if let AnyModel::Lumped(l) = self {
            if l.modal.projects(l.dof_count()) {
                return None;
            }
        }
        Some(
            crate::with_system!(self, m => stability::state_matrix(m).map(|(z, a)| {
                let n = z.len();
                (z.to_vec(), nalgebra::DMatrix::from_fn(n, n, |i, j| a[i][j]))
            }),
            else => match self {
                AnyModel::Lumped(l) => stability::lumped::state_matrix(l),
                _ => unreachable!("only lumped models have no fixed size"),
            }),
        )
    }
    /// Largest growth rate of steady sliding and its frequency (the fast path of maps).
    pub fn max_growth_rate(&self) -> Result<(f64, f64), StabilityError> {
        if let AnyModel::Lumped(l) = self {
            if l.modal.projects(l.dof_count()) {
                return stability::lumped::max_growth_rate(l);
            }
        }
        crate::with_system!(self, m => stability::max_growth_rate(m),
        else => match self {
            AnyModel::Lumped(l) => stability::lumped::max_growth_rate(l),
            _ => unreachable!("only lumped models have no fixed size"),
        })
    }
}

/// Observables of every contact of `model` at a sample.
pub fn observe_all<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    t: f64,
    modes: &Modes,
    z: &[f64; N],
    out: &mut Vec<Observables>,
) {
    out.clear();
    for i in 0..model.contacts() {
        out.push(model.observe_contact(t, modes, z, i));
    }
}

/// A lumped model's channels: the first contact's tangential motion (the
/// velocity of its tangent's first dof, the last dof's for the phase
/// portrait) and its normal's first dof.
fn lumped_channels(l: &Lumped) -> Channels {
    let dofs = l.dofs();
    let Some(c) = l.contacts.first() else {
        let d = &dofs[0];
        return Channels {
            tangential: format!("v{d}"),
            normal: None,
            phase: (d.clone(), format!("v{d}")),
        };
    };
    let first = &dofs[c.tangent.idx[0]];
    let last = &dofs[*c.tangent.idx.last().unwrap_or(&c.tangent.idx[0])];
    let normal = match &c.normal {
        squeal_core::model::contact::Normal::Elastic { normal, .. } => {
            Some(format!("v{}", dofs[normal.idx[0]]))
        }
        _ => None,
    };
    Channels {
        tangential: format!("v{first}"),
        normal,
        phase: (last.clone(), format!("v{last}")),
    }
}

/// Which columns the pictures and metrics use.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Channels {
    /// Tangential velocity (the disc's, or the mass's).
    pub tangential: String,
    /// Normal velocity, if the model has one.
    pub normal: Option<String>,
    /// Displacement and velocity of the phase portrait (the pad's tangential motion).
    pub phase: (String, String),
}

/// Channels by model name (also used for runs read back from disk).
pub fn channels_for(model: &str) -> Channels {
    match model {
        "belt" => Channels {
            tangential: "v".into(),
            normal: None,
            phase: ("x".into(), "v".into()),
        },
        "hoffmann" => Channels {
            tangential: "vx".into(),
            normal: Some("vy".into()),
            phase: ("x".into(), "vx".into()),
        },
        _ => Channels {
            tangential: "vx_d".into(),
            normal: Some("vy_d".into()),
            phase: ("x_p".into(), "vx_p".into()),
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
