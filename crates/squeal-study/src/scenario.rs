//! Scenarios: everything a run needs (model, parameters, friction law,
//! initial state, duration, sampling, tolerances), read from TOML or taken
//! from the built-ins, then overridden with `--set KEY=VALUE`.
//!
//! Raw input (TOML tables, `--set` strings) is validated into a resolved
//! [`Scenario`] before anything runs; every error names its key and value.

use crate::lumped_file::{MatrixFiles, LUMPED_KEYS};
use crate::model::{AnyModel, MODEL_NAMES};
use crate::radiation::Radiation;
use serde_json::{json, Map, Value};
use squeal_core::friction::LAW_NAMES;
use squeal_core::initial::Initial;
use squeal_core::model::disc_pad::Contact;
use squeal_core::{FrictionLaw, SolverOptions};
use std::fmt::Write as _;
use std::path::Path;

pub use crate::error::InputError;

fn err<T>(msg: impl Into<String>) -> Result<T, InputError> {
    Err(InputError(msg.into()))
}

/// Largest scenario file read (64 MiB).
pub use crate::input::MAX_SCENARIO_BYTES;

/// Most samples a run may write (guards memory against a typo in `sample_rate`).
pub const MAX_SAMPLES: f64 = 5.0e7;

/// Default validity bound (m): a tenth of a metre, far beyond any elastic
/// deflection a lumped brake or belt model describes.
pub const VALIDITY: f64 = 0.1;

/// A resolved, validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Scenario name (also the default output folder `out/<name>`).
    pub name: String,
    /// One line saying what the scenario is for.
    pub description: String,
    /// Model with its parameters and friction law.
    pub model: AnyModel,
    /// Simulated time (s).
    pub duration: f64,
    /// Output sample rate (Hz).
    pub sample_rate: f64,
    /// Largest displacement (m) the model means anything at: a run whose
    /// positions go beyond it is judged `out-of-range` (default [`VALIDITY`]).
    pub validity: f64,
    /// Initial state before offsets.
    pub initial: Initial,
    /// Offsets added to the initial state, one per state.
    pub offsets: Vec<f64>,
    /// Integrator settings.
    pub solver: SolverOptions,
    /// A lumped model's matrix files (for `scenario show`).
    pub matrices: MatrixFiles,
    /// The radiating surfaces and the listener (`[radiation]`, docs/physics.md §5f).
    pub radiation: Radiation,
}

/// The 40 reconstructed sets of Table 11.1, embedded so that the command
/// works from any folder (the same files users can run one by one).
pub const THESIS_SETS: [&str; 40] = [
    include_str!("../../../scenarios/thesis/set01.toml"),
    include_str!("../../../scenarios/thesis/set02.toml"),
    include_str!("../../../scenarios/thesis/set03.toml"),
    include_str!("../../../scenarios/thesis/set04.toml"),
    include_str!("../../../scenarios/thesis/set05.toml"),
    include_str!("../../../scenarios/thesis/set06.toml"),
    include_str!("../../../scenarios/thesis/set07.toml"),
    include_str!("../../../scenarios/thesis/set08.toml"),
    include_str!("../../../scenarios/thesis/set09.toml"),
    include_str!("../../../scenarios/thesis/set10.toml"),
    include_str!("../../../scenarios/thesis/set11.toml"),
    include_str!("../../../scenarios/thesis/set12.toml"),
    include_str!("../../../scenarios/thesis/set13.toml"),
    include_str!("../../../scenarios/thesis/set14.toml"),
    include_str!("../../../scenarios/thesis/set15.toml"),
    include_str!("../../../scenarios/thesis/set16.toml"),
    include_str!("../../../scenarios/thesis/set17.toml"),
    include_str!("../../../scenarios/thesis/set18.toml"),
    include_str!("../../../scenarios/thesis/set19.toml"),
    include_str!("../../../scenarios/thesis/set20.toml"),
    include_str!("../../../scenarios/thesis/set21.toml"),
    include_str!("../../../scenarios/thesis/set22.toml"),
    include_str!("../../../scenarios/thesis/set23.toml"),
    include_str!("../../../scenarios/thesis/set24.toml"),
    include_str!("../../../scenarios/thesis/set25.toml"),
    include_str!("../../../scenarios/thesis/set26.toml"),
    include_str!("../../../scenarios/thesis/set27.toml"),
    include_str!("../../../scenarios/thesis/set28.toml"),
    include_str!("../../../scenarios/thesis/set29.toml"),
    include_str!("../../../scenarios/thesis/set30.toml"),
    include_str!("../../../scenarios/thesis/set31.toml"),
    include_str!("../../../scenarios/thesis/set32.toml"),
    include_str!("../../../scenarios/thesis/set33.toml"),
    include_str!("../../../scenarios/thesis/set34.toml"),
    include_str!("../../../scenarios/thesis/set35.toml"),
    include_str!("../../../scenarios/thesis/set36.toml"),
    include_str!("../../../scenarios/thesis/set37.toml"),
    include_str!("../../../scenarios/thesis/set38.toml"),
    include_str!("../../../scenarios/thesis/set39.toml"),
    include_str!("../../../scenarios/thesis/set40.toml"),
];

/// The reconstructed thesis sets as scenarios (`thesis-01` … `thesis-40`).
pub fn thesis_sets() -> Vec<Scenario> {
    THESIS_SETS
        .iter()
        .map(|t| Scenario::from_toml(t).expect("the shipped thesis sets are valid"))
        .collect()
}

/// Names of the built-in scenarios.
pub const BUILTINS: [&str; 7] = [
    "disc-pad",
    "belt-coulomb",
    "belt",
    "hoffmann",
    "two-pad-brake",
    "two-pad-brake-asymmetric",
    "floating-caliper",
];

/// The lumped built-ins: the two-pad brake, symmetric and asymmetric, and
/// the 8-dof floating caliper (the files of `scenarios/lumped/`, embedded).
pub const LUMPED_BUILTINS: [(&str, &str); 3] = [
    (
        "two-pad-brake",
        include_str!("../../../scenarios/lumped/two-pad-brake.toml"),
    ),
    (
        "two-pad-brake-asymmetric",
        include_str!("../../../scenarios/lumped/two-pad-brake-asymmetric.toml"),
    ),
    (
        "floating-caliper",
        include_str!("../../../scenarios/lumped/floating-caliper.toml"),
    ),
];

impl Scenario {
    /// A built-in scenario by name.
    pub fn builtin(name: &str) -> Option<Scenario> {
        let base = |model: AnyModel, description: &str| Scenario {
            name: name.to_string(),
            description: description.to_string(),
            radiation: Radiation::default_for(&model),
            offsets: vec![0.0; model.state_names().len()],
            model,
            duration: 0.5,
            sample_rate: 200_000.0,
            validity: VALIDITY,
            initial: Initial::Rest,
            solver: SolverOptions::default(),
            matrices: MatrixFiles::default(),
        };
        if let Some(n) = name
            .strip_prefix("thesis-")
            .and_then(|n| n.parse::<usize>().ok())
        {
            return (1..=40).contains(&n).then(|| {
                Scenario::from_toml(THESIS_SETS[n - 1]).expect("the shipped thesis sets are valid")
            });
        }
        if let Some((_, text)) = LUMPED_BUILTINS.iter().find(|(n, _)| *n == name) {
            return Some(
                Scenario::from_toml(text).expect("the shipped lumped scenarios are valid"),
            );
        }
        Some(match name {
            "disc-pad" => {
                let mut s = base(
                    AnyModel::by_name("disc-pad").unwrap(),
                    "The thesis's disc–pad brake with MODEL.md's defaults, from rest: it squeals.",
                );
                s.solver.atol_pos = Some(1e-16);
                s.solver.atol_vel = Some(1e-11);
                s
            }
            "belt-coulomb" => {
                let mut m = AnyModel::by_name("belt").unwrap();
                m.set_friction(FrictionLaw::Coulomb {
                    mu_s: 0.4,
                    mu_k: 0.3,
                });
                let mut s = base(
                    m,
                    "Mass on a belt with Coulomb friction: the classic stick-slip limit cycle.",
                );
                s.duration = 1.0;
                s.sample_rate = 1000.0;
                s.solver.atol_pos = Some(1e-12);
                s.solver.atol_vel = Some(1e-10);
                s
            }
            "belt" => {
                let mut m = AnyModel::by_name("belt").unwrap();
                m.set("V", 1.0).unwrap();
                m.set("c", 0.2).unwrap();
                let mut s = base(
                    m,
                    "Mass on a belt with the thesis friction law below its Hopf speed: negative damping grows into stick-slip.",
                );
                s.duration = 5.0;
                s.sample_rate = 1000.0;
                s.initial = Initial::Equilibrium;
                s.offsets[1] = 1e-3;
                s.solver.atol_pos = Some(1e-12);
                s.solver.atol_vel = Some(1e-10);
                s
            }
            "hoffmann" => {
                let mut s = base(
                    AnyModel::by_name("hoffmann").unwrap(),
                    "Hoffmann et al.'s 2-DOF mode-coupling model above its critical friction: flutter grows into a limit cycle.",
                );
                s.duration = 5.0;
                s.sample_rate = 2000.0;
                s.initial = Initial::Equilibrium;
                s.offsets[1] = 1e-4;
                s.solver.atol_pos = Some(1e-12);
                s.solver.atol_vel = Some(1e-10);
                s
            }
            _ => return None,
        })
    }

    /// A built-in name or a TOML file path.
    pub fn load(spec: &str) -> Result<Scenario, InputError> {
        let path = Path::new(spec);
        if crate::input::names_a_non_folder(path) || spec.ends_with(".toml") {
            // A scenario is a few kB: a regular file or a pipe (`<(…)`),
            // at most 64 MiB, a silent pipe given up after 10 s; a device
            // or folder is refused by name.
            let text = crate::input::read_text_or_pipe(
                path,
                MAX_SCENARIO_BYTES,
                crate::input::PIPE_TIMEOUT,
            )
            .map_err(|e| InputError(format!("scenario file {spec}: {e}")))?;
            let mut sc = Scenario::from_toml_in(&text, path.parent())
                .map_err(|e| InputError(format!("{spec}: {}", e.0)))?;
            // A file without a `name` is named after itself (out/<file stem>).
            let named = text
                .parse::<toml::Table>()
                .is_ok_and(|t| t.contains_key("name"));
            if !named {
                if let Some(stem) = path.file_stem() {
                    sc.name = stem.to_string_lossy().into_owned();
                    check_name(&sc.name)
                        .map_err(|e| InputError(format!("{spec}: no `name` key, and {}", e.0)))?;
                }
            }
            return Ok(sc);
        }
        Scenario::builtin(spec).ok_or_else(|| {
            InputError(format!(
                "scenario '{spec}': no such file, and no built-in of that name (built-ins: {}, thesis-01 … thesis-40)",
                BUILTINS.join(", ")
            ))
        })
    }

    /// Parse a scenario from TOML text (see `squeal scenario show`).
    pub fn from_toml(text: &str) -> Result<Scenario, InputError> {
        Scenario::from_toml_in(text, None)
    }

    /// Parse a scenario from TOML text whose matrix files (lumped models)
    /// are relative to `base`.
    pub fn from_toml_in(text: &str, base: Option<&Path>) -> Result<Scenario, InputError> {
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].lines().count().max(1));
            let msg = e.message().trim().replace('\n', "; ");
            match line {
                Some(l) => InputError(format!("malformed TOML at line {l}: {msg}")),
                None => InputError(format!("malformed TOML: {msg}")),
            }
        })?;
        Scenario::from_table_in(&table, base)
    }

    /// Build a scenario from an already parsed TOML table (the Python
    /// package's dict), matrix files (lumped models) relative to `base`;
    /// the same checks and messages as a file.
    pub fn from_table_in(table: &toml::Table, base: Option<&Path>) -> Result<Scenario, InputError> {
        let model_name = match table.get("model") {
            Some(toml::Value::String(s)) => s.clone(),
            Some(v) => {
                return err(format!(
                    "model = {v}: expected a string ({})",
                    MODEL_NAMES.join(", ")
                ))
            }
            None => "disc-pad".to_string(),
        };
        let mut matrices = MatrixFiles::default();
        let lumped = model_name == "lumped";
        let model = if lumped {
            let (l, files) = crate::lumped_file::parse(table, base)?;
            let nonzeros = files.info.iter().map(|i| i.nonzeros).sum();
            crate::memory::check_model_memory(l.dof_count(), nonzeros)?;
            matrices = files;
            AnyModel::Lumped(Box::new(l))
        } else {
            AnyModel::by_name(&model_name).ok_or_else(|| {
                InputError(format!(
                    "model = '{model_name}': expected one of {}",
                    MODEL_NAMES.join(", ")
                ))
            })?
        };
        let mut s = Scenario {
            name: "scenario".into(),
            description: String::new(),
            radiation: Radiation::default_for(&model),
            offsets: vec![0.0; model.state_names().len()],
            model,
            duration: 0.5,
            sample_rate: 200_000.0,
            validity: VALIDITY,
            initial: Initial::Rest,
            solver: SolverOptions::default(),
            matrices,
        };
        // The friction law first, so that its parameters can follow in any order.
        if let Some(toml::Value::Table(f)) = table.get("friction") {
            if let Some(law) = f.get("law") {
                let law = law.as_str().ok_or_else(|| {
                    InputError(format!("friction.law = {law}: expected a string"))
                })?;
                s.apply("friction", &Setting::Text(law.into()))?;
            }
        }
        for (key, value) in table {
            match (key.as_str(), value) {
                ("model", _) => {}
                (k, _) if lumped && LUMPED_KEYS.contains(&k) => {}
                ("modal", toml::Value::Table(t)) if lumped => {
                    // The eigen-analysis options: `[modal] modes = 200` is `--set modal.modes=200`.
                    for (k, v) in t {
                        let setting = Setting::from_toml(v).ok_or_else(|| {
                            InputError(format!("modal.{k} = {v}: expected a number"))
                        })?;
                        s.apply_in("params", &format!("modal.{k}"), &setting)?;
                    }
                }
                ("radiation", toml::Value::Table(t)) => {
                    for (k, v) in t {
                        match (k.as_str(), v) {
                            ("area_m2", toml::Value::Table(areas)) => {
                                for (dof, a) in areas {
                                    let setting = Setting::from_toml(a).ok_or_else(|| {
                                        InputError(format!(
                                            "radiation.area_m2.{dof} = {a}: expected a number (m²)"
                                        ))
                                    })?;
                                    s.apply_in("radiation", &format!("area_m2.{dof}"), &setting)?;
                                }
                            }
                            ("area_m2", v) => {
                                return err(format!(
                                    "radiation.area_m2 = {v}: expected a table [radiation.area_m2] of dof = area (m²)"
                                ))
                            }
                            (k, v) => {
                                let setting = Setting::from_toml(v).ok_or_else(|| {
                                    InputError(format!("radiation.{k} = {v}: unexpected value"))
                                })?;
                                s.apply_in("radiation", k, &setting)?;
                            }
                        }
                    }
                }
                ("radiation", v) => {
                    return err(format!("radiation = {v}: expected a table [radiation]"))
                }
                ("friction", _) if lumped => {
                    return err(format!(
                        "{key}: a lumped model takes its friction laws in its contacts ([[contact]] friction = …, or --set <contact>.friction=<law>)"
                    ))
                }
                ("name", toml::Value::String(v)) => {
                    check_name(v)?;
                    s.name = v.clone();
                }
                ("description", toml::Value::String(v)) => s.description = v.clone(),
                ("params" | "friction" | "offsets" | "solver", toml::Value::Table(t)) => {
                    for (k, v) in t {
                        if key == "friction" && k == "law" {
                            continue;
                        }
                        let setting = Setting::from_toml(v).ok_or_else(|| {
                            InputError(format!("{key}.{k} = {v}: expected a number"))
                        })?;
                        s.apply_in(key, k, &setting)?;
                    }
                }
                ("params" | "friction" | "offsets" | "solver", v) => {
                    return err(format!("{key} = {v}: expected a table [{key}]"))
                }
                (
                    "duration" | "sample_rate" | "validity" | "initial" | "contact" | "name"
                    | "description",
                    v,
                ) => {
                    let setting = Setting::from_toml(v)
                        .ok_or_else(|| InputError(format!("{key} = {v}: unexpected value")))?;
                    s.apply(key, &setting)?;
                }
                _ => return err(format!("unknown key '{key}'")),
            }
        }
        s.validate()?;
        Ok(s)
    }

    /// Apply `--set KEY=VALUE` overrides: friction-law switches first, then
    /// the rest in order; then validate.
    pub fn apply_overrides(&mut self, sets: &[String]) -> Result<(), InputError> {
        check_set_syntax(sets, "")?;
        let mut parsed = Vec::new();
        for raw in sets {
            let Some((k, v)) = raw.split_once('=') else {
                return err(format!("--set {raw}: --set needs NAME=VALUE"));
            };
            parsed.push((k.trim().to_string(), v.trim().to_string(), raw));
        }
        for (k, v, raw) in parsed.iter().filter(|(k, ..)| k == "friction") {
            self.apply(k, &Setting::Text(v.clone()))
                .map_err(|e| InputError(format!("--set {raw}: {}", e.0)))?;
        }
        // A lumped contact's law: `--set inner.friction=coulomb`, then the
        // new law's keys are required among the other --set values.
        let contacts: Vec<String> = match &self.model {
            AnyModel::Lumped(l) => l.contacts.iter().map(|c| c.name.clone()).collect(),
            _ => Vec::new(),
        };
        let law_key = |k: &str| {
            k.strip_suffix(".friction")
                .filter(|c| contacts.iter().any(|x| x == c))
                .map(str::to_string)
        };
        let switches: Vec<(String, String, &String)> = parsed
            .iter()
            .filter_map(|(k, v, raw)| law_key(k).map(|c| (c, v.clone(), *raw)))
            .collect();
        for (contact, law, raw) in &switches {
            let AnyModel::Lumped(l) = &mut self.model else {
                unreachable!("law_key matches lumped contacts only")
            };
            let new = FrictionLaw::by_name(law).map_err(|_| {
                InputError(format!(
                    "--set {raw}: expected one of {}",
                    LAW_NAMES.join(", ")
                ))
            })?;
            let missing: Vec<String> = new
                .params()
                .iter()
                .map(|p| format!("{contact}.{}", p.name))
                .filter(|k| !parsed.iter().any(|(pk, ..)| pk == k))
                .collect();
            if !missing.is_empty() {
                return err(format!(
                    "--set {raw}: the {law} law needs its keys set too; missing: {} (e.g. --set {}=…)",
                    missing.join(", "),
                    missing[0]
                ));
            }
            l.set_friction_law(contact, new)
                .map_err(|e| InputError(format!("--set {raw}: {e}")))?;
        }
        for (k, v, raw) in parsed
            .iter()
            .filter(|(k, ..)| k != "friction" && law_key(k).is_none())
        {
            let setting = match v.parse::<f64>() {
                Ok(x) => Setting::Number(x),
                Err(_) => Setting::Text(v.clone()),
            };
            self.apply(k, &setting)
                .map_err(|e| InputError(format!("--set {raw}: {}", e.0)))?;
        }
        self.validate()
    }

    /// Apply one flat key (the `--set` namespace).
    pub fn apply(&mut self, key: &str, value: &Setting) -> Result<(), InputError> {
        let section = match key {
            "friction" | "initial" | "contact" | "duration" | "sample_rate" | "validity"
            | "name" | "description" => "",
            "rtol" | "atol_pos" | "atol_vel" | "h_max" => "solver",
            k if self.atol_index(k).is_some() => "solver",
            k if self.offset_index(k).is_some() => "offsets",
            k if k.starts_with("radiation.") => "radiation",
            "modal.basis" if matches!(self.model, AnyModel::Lumped(_)) => "params",
            k if self.model.get(k).is_some() => "params",
            "model" => {
                return err("model cannot be changed by --set: choose a scenario of that model")
            }
            _ => {
                if let AnyModel::Lumped(l) = &self.model {
                    return err(format!(
                        "unknown key '{key}' for this lumped model (keys: {} …; see `squeal scenario show`)",
                        l.keys().iter().take(6).map(|k| k.0.clone()).collect::<Vec<_>>().join(", ")
                    ));
                }
                return err(format!(
                    "unknown key '{key}' for model {} with the {} friction law; {}",
                    self.model.name(),
                    self.model.friction().name(),
                    suggest(key, &self.known_keys())
                ));
            }
        };
        self.apply_in(section, key, value)
    }

    /// Every key `--set` accepts for this scenario's model and friction law.
    pub fn known_keys(&self) -> Vec<String> {
        let mut keys: Vec<String> = self
            .model
            .param_specs()
            .iter()
            .chain(self.model.friction().params())
            .filter(|p| self.model.get(p.name).is_some())
            .map(|p| p.name.to_string())
            .collect();
        keys.extend(
            [
                "friction",
                "initial",
                "duration",
                "sample_rate",
                "name",
                "description",
                "rtol",
                "atol_pos",
                "atol_vel",
                "h_max",
            ]
            .map(String::from),
        );
        if matches!(self.model, AnyModel::DiscPad(_)) {
            keys.push("contact".into());
        }
        keys.extend(Radiation::known_keys(&self.positions()));
        for n in self.model.state_names() {
            keys.push(format!("{n}0"));
            keys.push(format!("atol_{n}"));
        }
        keys
    }

    /// The model's position coordinates (its dofs), the first half of its state.
    pub fn positions(&self) -> Vec<String> {
        let names = self.model.state_names();
        names[..names.len() / 2].to_vec()
    }

    /// `atol_<state>`: a per-state absolute tolerance.
    fn atol_index(&self, key: &str) -> Option<usize> {
        let base = key.strip_prefix("atol_")?;
        self.model.state_names().iter().position(|n| *n == base)
    }

    fn offset_index(&self, key: &str) -> Option<usize> {
        let base = key.strip_suffix('0')?;
        self.model.state_names().iter().position(|n| *n == base)
    }

    /// Apply a key within a section ("" for the top level).
    fn apply_in(&mut self, section: &str, key: &str, value: &Setting) -> Result<(), InputError> {
        let shown = if section.is_empty() {
            key.to_string()
        } else {
            format!("{section}.{key}")
        };
        let number = |v: &Setting| match v {
            Setting::Number(x) => Ok(*x),
            Setting::Text(t) => err(format!("{shown} = '{t}': expected a number")),
        };
        let text = |v: &Setting| match v {
            Setting::Text(t) => Ok(t.clone()),
            Setting::Number(x) => Ok(x.to_string()),
        };
        match (section, key) {
            ("", "friction") => {
                let name = text(value)?;
                let law = self.model.friction().switch_to(&name).map_err(|_| {
                    InputError(format!(
                        "friction = '{name}': expected one of {}",
                        LAW_NAMES.join(", ")
                    ))
                })?;
                self.model.set_friction(law);
            }
            ("", "initial") => {
                let t = text(value)?;
                self.initial = Initial::parse(&t).ok_or_else(|| {
                    InputError(format!("initial = '{t}': expected rest or equilibrium"))
                })?;
            }
            ("params", "modal.basis") => {
                let t = text(value)?;
                let kind = squeal_core::linear::BasisKind::parse(&t).ok_or_else(|| {
                    InputError(format!(
                        "modal.basis = '{t}': expected {}",
                        squeal_core::linear::BasisKind::NAMES.join(" or ")
                    ))
                })?;
                if let AnyModel::Lumped(l) = &mut self.model {
                    l.modal.kind = kind;
                }
            }
            ("", "contact") => {
                let t = text(value)?;
                match &mut self.model {
                    AnyModel::DiscPad(m) => {
                        m.contact = Contact::parse(&t).map_err(|e| InputError(e.to_string()))?;
                    }
                    other => {
                        return err(format!(
                            "contact = '{t}': the {} model has no contact setting",
                            other.name()
                        ))
                    }
                }
            }
            ("", "name") => {
                let name = text(value)?;
                check_name(&name)?;
                self.name = name;
            }
            ("", "description") => self.description = text(value)?,
            ("", "duration") => {
                let x = number(value)?;
                if !(x.is_finite() && x > 0.0) {
                    return err(format!("duration = {x}: must be a finite number > 0 (s)"));
                }
                self.duration = x;
            }
            ("", "sample_rate") => {
                let x = number(value)?;
                if !(x.is_finite() && x > 0.0) {
                    return err(format!(
                        "sample_rate = {x}: must be a finite number > 0 (Hz)"
                    ));
                }
                self.sample_rate = x;
            }
            ("", "validity") => {
                let x = number(value)?;
                if !(x.is_finite() && x > 0.0) {
                    return err(format!(
                        "validity = {x}: must be a finite number > 0 (m, the largest displacement the model means)"
                    ));
                }
                self.validity = x;
            }
            ("solver", "rtol") => {
                let x = number(value)?;
                if !(1e-14..=1e-2).contains(&x) {
                    return err(format!("rtol = {x}: must be between 1e-14 and 1e-2"));
                }
                self.solver.rtol = x;
            }
            ("solver", "atol_pos" | "atol_vel") => {
                let x = number(value)?;
                if !(x.is_finite() && x > 0.0 && x < 1.0) {
                    return err(format!("{key} = {x}: must be > 0 and < 1"));
                }
                if key == "atol_pos" {
                    self.solver.atol_pos = Some(x);
                } else {
                    self.solver.atol_vel = Some(x);
                }
            }
            ("solver", k) if self.atol_index(k).is_some() => {
                let x = number(value)?;
                if !(x.is_finite() && x > 0.0 && x < 1.0) {
                    return err(format!("{k} = {x}: must be > 0 and < 1"));
                }
                let i = self.atol_index(k).unwrap_or(0);
                self.solver.atol_state[i] = Some(x);
            }
            ("solver", "h_max") => {
                let x = number(value)?;
                if x.is_nan() || x <= 0.0 {
                    return err(format!("h_max = {x}: must be > 0 (s)"));
                }
                self.solver.h_max = x;
            }
            ("radiation", k) => {
                let k = k.strip_prefix("radiation.").unwrap_or(k);
                let v = match value {
                    Setting::Number(x) => format!("{x:?}"),
                    Setting::Text(t) => t.clone(),
                };
                let positions = self.positions();
                self.radiation.set(k, &v, &positions).map_err(InputError)?;
            }
            ("offsets", k) => {
                let i = self.offset_index(k).ok_or_else(|| {
                    let names: Vec<String> = self
                        .model
                        .state_names()
                        .iter()
                        .map(|n| format!("{n}0"))
                        .collect();
                    InputError(format!(
                        "unknown offset '{k}' (offsets: {})",
                        names.join(", ")
                    ))
                })?;
                let x = number(value)?;
                if !x.is_finite() {
                    return err(format!("{shown} = {x}: must be a finite number"));
                }
                self.offsets[i] = x;
            }
            ("params" | "friction", k) => {
                let x = number(value)?;
                let known = if let AnyModel::Lumped(l) = &self.model {
                    l.get(k).is_some()
                } else if section == "friction" {
                    self.model.friction().get(k).is_some()
                } else {
                    self.model.param_specs().iter().any(|p| p.name == k)
                        || self.model.friction().get(k).is_some()
                };
                if !known {
                    let mut keys: Vec<String> = self
                        .model
                        .friction()
                        .params()
                        .iter()
                        .map(|p| p.name.to_string())
                        .collect();
                    if section == "params" {
                        keys.extend(self.model.param_specs().iter().map(|p| p.name.to_string()));
                    }
                    return err(format!(
                        "unknown parameter '{shown}' for model {} with the {} friction law; {}",
                        self.model.name(),
                        self.model.friction().name(),
                        suggest(k, &keys)
                    ));
                }
                self.model
                    .set(k, x)
                    .map_err(|e| InputError(e.to_string()))?;
            }
            _ => return err(format!("unknown key '{shown}'")),
        }
        Ok(())
    }

    /// Check relations that single keys cannot (μ_s ≥ μ_k, sample count…).
    pub fn validate(&self) -> Result<(), InputError> {
        self.model
            .validate()
            .map_err(|e| InputError(e.to_string()))?;
        let samples = self.duration * self.sample_rate;
        if samples > MAX_SAMPLES {
            let columns = 1 + self.model.state_names().len() + self.model.derived_columns().len();
            return err(format!(
                "duration = {:e} s at sample_rate = {:e} Hz: {samples:.3e} samples ({:.3e} GB in memory) \
                 exceed the limit of {MAX_SAMPLES:.0e} samples; lower duration or sample_rate",
                self.duration,
                self.sample_rate,
                samples * columns as f64 * 8.0 / 1e9
            ));
        }
        Ok(())
    }

    /// Everything resolved, defaults included, as JSON (summary.json's `scenario`).
    pub fn to_json(&self) -> Value {
        let mut params = Map::new();
        for spec in self.model.param_specs() {
            params.insert(spec.name.into(), json!(self.model.get(spec.name)));
        }
        let law = self.model.friction();
        let mut friction = Map::new();
        friction.insert("law".into(), json!(law.name()));
        for spec in law.params() {
            friction.insert(spec.name.into(), json!(law.get(spec.name)));
        }
        if let AnyModel::Lumped(l) = &self.model {
            params = l.keys().into_iter().map(|(k, v)| (k, json!(v))).collect();
            friction = l
                .contacts
                .iter()
                .map(|c| (c.name.clone(), json!(c.friction.name())))
                .collect();
        }
        let mut offsets = Map::new();
        for (n, v) in self.model.state_names().iter().zip(&self.offsets) {
            offsets.insert(format!("{n}0"), json!(v));
        }
        let mut out = json!({
            "name": self.name,
            "description": self.description,
            "model": self.model.name(),
            "duration": self.duration,
            "sample_rate": self.sample_rate,
            "validity": self.validity,
            "initial": self.initial.as_str(),
            "params": params,
            "friction": friction,
            "offsets": offsets,
            "solver": {
                "rtol": self.solver.rtol,
                "atol_pos": self.solver.atol_pos,
                "atol_vel": self.solver.atol_vel,
                "h_max": if self.solver.h_max.is_finite() { json!(self.solver.h_max) } else { Value::Null },
            },
        });
        for (name, a) in self.model.state_names().iter().zip(&self.solver.atol_state) {
            if let Some(a) = a {
                out["solver"][format!("atol_{name}")] = json!(a);
            }
        }
        if let AnyModel::DiscPad(m) = &self.model {
            out["contact"] = json!(m.contact.as_str());
        }
        out["radiation"] = self.radiation.to_json();
        if let AnyModel::Lumped(l) = &self.model {
            // Keys bound to expressions of [params]: each with its value.
            let b = l.shared().bindings();
            if !b.is_empty() {
                out["expressions"] = b
                    .iter()
                    .map(|b| {
                        (
                            b.key.clone(),
                            json!({ "expr": b.source, "value": l.get(&b.key) }),
                        )
                    })
                    .collect::<Map<String, Value>>()
                    .into();
            }
        }
        out
    }

    /// The scenario as a documented TOML file a user can copy and edit.
    pub fn to_toml(&self) -> String {
        let mut t = String::new();
        let line = |t: &mut String, kv: String, comment: &str| {
            let _ = writeln!(t, "{kv:<34}# {comment}");
        };
        let _ = writeln!(
            t,
            "# squeal scenario '{}'. Run it with: squeal simulate FILE",
            self.name
        );
        let _ = writeln!(
            t,
            "# Every key can be overridden on the command line: --set KEY=VALUE"
        );
        let _ = writeln!(
            t,
            "# (offsets as --set x_d0=1e-9, solver keys as --set rtol=1e-10)."
        );
        let _ = writeln!(
            t,
            "# The equations, friction laws and the origin of every default: docs/physics.md"
        );
        let _ = writeln!(t);
        line(
            &mut t,
            format!("name = {}", toml::Value::String(self.name.clone())),
            "default output folder: out/<name>",
        );
        // TOML's own escaping: Rust's `{:?}` writes `\u{7}`, which TOML cannot read.
        let _ = writeln!(
            t,
            "description = {}",
            toml::Value::String(self.description.clone())
        );
        line(
            &mut t,
            format!("model = {:?}", self.model.name()),
            &MODEL_NAMES.join(" | "),
        );
        line(
            &mut t,
            format!("duration = {:?}", self.duration),
            "s, simulated time",
        );
        line(
            &mut t,
            format!("sample_rate = {:?}", self.sample_rate),
            "Hz, uniform output sampling",
        );
        line(
            &mut t,
            format!("validity = {:?}", self.validity),
            "m, largest displacement the model means (beyond it: verdict out-of-range)",
        );
        line(
            &mut t,
            format!("initial = {:?}", self.initial.as_str()),
            "rest | equilibrium (steady sliding)",
        );
        if let AnyModel::DiscPad(m) = &self.model {
            line(
                &mut t,
                format!("contact = {:?}", m.contact.as_str()),
                "unilateral (pad may lift off) | bilateral",
            );
        }
        if let AnyModel::Lumped(l) = &self.model {
            let _ = writeln!(t, "{}", crate::lumped_file::to_toml(l, &self.matrices));
            self.write_offsets_solver(&mut t);
            t.push_str(&self.radiation.to_toml(&Radiation::default_for(&self.model)));
            return t;
        }
        let _ = writeln!(t, "\n[params]");
        for spec in self.model.param_specs() {
            let v = self.model.get(spec.name).unwrap_or(f64::NAN);
            line(
                &mut t,
                format!("{} = {v:?}", spec.name),
                &format!("{}, {}", spec.unit, spec.doc),
            );
        }
        let law = self.model.friction();
        let _ = writeln!(t, "\n[friction]");
        line(
            &mut t,
            format!("law = {:?}", law.name()),
            &LAW_NAMES.join(" | "),
        );
        for spec in law.params() {
            let v = law.get(spec.name).unwrap_or(f64::NAN);
            line(
                &mut t,
                format!("{} = {v:?}", spec.name),
                &format!("{}, {}", spec.unit, spec.doc),
            );
        }
        self.write_offsets_solver(&mut t);
        t.push_str(&self.radiation.to_toml(&Radiation::default_for(&self.model)));
        t
    }

    /// The `[offsets]` and `[solver]` tables of [`Self::to_toml`].
    fn write_offsets_solver(&self, t: &mut String) {
        let line = |t: &mut String, kv: String, comment: &str| {
            let _ = writeln!(t, "{kv:<34}# {comment}");
        };
        let _ = writeln!(
            t,
            "\n[offsets]                         # added to the initial state"
        );
        let n = self.offsets.len();
        for (i, (name, v)) in self
            .model
            .state_names()
            .iter()
            .zip(&self.offsets)
            .enumerate()
        {
            let unit = if i < n / 2 { "m" } else { "m/s" };
            line(t, format!("{name}0 = {v:?}"), unit);
        }
        let _ = writeln!(t, "\n[solver]");
        line(
            t,
            format!("rtol = {:?}", self.solver.rtol),
            "relative tolerance",
        );
        if let Some(a) = self.solver.atol_pos {
            line(
                t,
                format!("atol_pos = {a:?}"),
                "m, absolute tolerance of positions",
            );
        }
        if let Some(a) = self.solver.atol_vel {
            line(
                t,
                format!("atol_vel = {a:?}"),
                "m/s, absolute tolerance of velocities",
            );
        }
        for (name, a) in self.model.state_names().iter().zip(&self.solver.atol_state) {
            if let Some(a) = a {
                line(
                    t,
                    format!("atol_{name} = {a:?}"),
                    "absolute tolerance of this state alone",
                );
            }
        }
        if self.solver.h_max.is_finite() {
            line(
                t,
                format!("h_max = {:?}", self.solver.h_max),
                "s, largest step",
            );
        } else {
            let _ = writeln!(
                t,
                "# h_max = 1e-6                    # s, largest step (default: unlimited)"
            );
        }
    }
}

/// Longest scenario name (the output folder `out/<name>-map` must stay a
/// legal file name).
pub const MAX_NAME_BYTES: usize = 200;

/// A scenario's `name` names its output folder `out/<name>`: it must be a
/// plain name, not a path — not empty, no `/` or `\`, no control
/// characters, not starting with `.` (so neither `.`, `..` nor a hidden
/// folder), at most [`MAX_NAME_BYTES`] bytes.
pub fn check_name(name: &str) -> Result<(), InputError> {
    let why = if name.is_empty() {
        Some("is empty")
    } else if name.contains(['/', '\\']) {
        Some("is a path; give a plain name (it names the folder out/<name>)")
    } else if name.starts_with('.') {
        Some("must not start with '.' (it names the folder out/<name>)")
    } else if name.chars().any(char::is_control) {
        Some("contains a control character")
    } else if name.len() > MAX_NAME_BYTES {
        Some("is longer than 200 bytes")
    } else {
        None
    };
    match why {
        Some(why) => err(format!("name = {name:?}: {why}")),
        None => Ok(()),
    }
}

/// Every `--set` must be `NAME=VALUE`. `--set V 2` (a space for the `=`)
/// makes `2` the scenario: say what was meant. `scenario` is the scenario
/// argument as given ("" if unknown).
pub fn check_set_syntax(sets: &[String], scenario: &str) -> Result<(), InputError> {
    let Some(raw) = sets.iter().find(|s| !s.contains('=')) else {
        return Ok(());
    };
    let loose = !scenario.is_empty()
        && !Path::new(scenario).exists()
        && Scenario::builtin(scenario).is_none();
    let hint = if loose {
        format!("; did you mean --set {raw}={scenario}?")
    } else {
        format!("; e.g. --set {}=VALUE", raw.trim())
    };
    err(format!("--set {raw}: --set needs NAME=VALUE{hint}"))
}

/// Levenshtein distance (for suggestions).
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// "did you mean N?" for a near key (same letters in another case, or one
/// or two edits away), else the list of valid keys.
pub fn suggest(key: &str, keys: &[String]) -> String {
    let near = keys
        .iter()
        .map(|k| {
            let d = if k.eq_ignore_ascii_case(key) {
                0
            } else {
                distance(&k.to_lowercase(), &key.to_lowercase()) + 1
            };
            (d, k)
        })
        .min();
    match near {
        Some((d, k)) if d <= 2 || (d <= 3 && key.len() > 4) => format!("did you mean '{k}'?"),
        _ => format!("valid keys: {}", keys.join(", ")),
    }
}

/// A value as given: a number, or a word.
#[derive(Debug, Clone, PartialEq)]
pub enum Setting {
    /// A number.
    Number(f64),
    /// A word (law name, `rest`, …).
    Text(String),
}

impl Setting {
    fn from_toml(v: &toml::Value) -> Option<Setting> {
        match v {
            toml::Value::Float(x) => Some(Setting::Number(*x)),
            toml::Value::Integer(i) => Some(Setting::Number(*i as f64)),
            toml::Value::String(s) => Some(Setting::Text(s.clone())),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_roundtrip_through_toml() {
        for name in BUILTINS {
            let s = Scenario::builtin(name).unwrap();
            let back = Scenario::from_toml(&s.to_toml()).unwrap();
            assert_eq!(s, back, "{name}");
        }
    }

    #[test]
    fn overrides_switch_laws_and_keep_shared_parameters() {
        let refused =
            |s: &Scenario, set: &str| s.clone().apply_overrides(&[set.into()]).unwrap_err().0;
        let mut s = Scenario::builtin("disc-pad").unwrap();
        s.apply_overrides(&[
            "mu_k=0.05".into(),
            "friction=coulomb".into(),
            "N=2000".into(),
        ])
        .unwrap();
        assert_eq!(s.model.get("N"), Some(2000.0));
        assert_eq!(s.model.friction().name(), "coulomb");
        assert_eq!(s.model.get("mu_k"), Some(0.05));
        let e = refused(&s, "mu_k=0.5");
        assert!(e.contains("mu_s") && e.contains("mu_k"), "{e}");
        let e = refused(&s, "k_dx=-1");
        assert!(e.contains("k_dx") && e.contains("-1"), "{e}");
        let e = refused(&s, "bogus=1");
        assert!(e.contains("bogus"), "{e}");
        s.apply_overrides(&["x_p0=1e-9".into(), "initial=equilibrium".into()])
            .unwrap();
        assert_eq!(s.offsets[1], 1e-9);
        // Per-state tolerances, and their round trip through TOML.
        s.apply_overrides(&["atol_vx_p=1e-12".into()]).unwrap();
        assert_eq!(s.solver.atol_state[5], Some(1e-12));
        assert_eq!(Scenario::from_toml(&s.to_toml()).unwrap().solver, s.solver);
        let e = refused(&s, "atol_vx_p=-1");
        assert!(e.contains("atol_vx_p"), "{e}");
    }
}

/// Where a scenario comes from.
#[derive(Debug, Clone, Copy)]
pub enum Source<'a> {
    /// A built-in name or a TOML file path (as the command line takes it).
    Spec(&'a str),
    /// TOML text; matrix files relative to the working directory.
    Toml(&'a str),
    /// A parsed TOML table (a Python dict); matrix files relative to the
    /// working directory.
    Table(&'a toml::Table),
}

/// Resolve a scenario from its source and `--set KEY=VALUE` overrides
/// (syntax checked first, then applied, then validated).
pub fn resolve(source: Source<'_>, sets: &[String]) -> Result<Scenario, InputError> {
    let label = match source {
        Source::Spec(spec) => spec,
        Source::Toml(_) | Source::Table(_) => "scenario",
    };
    check_set_syntax(sets, label)?;
    let mut sc = match source {
        Source::Spec(spec) => Scenario::load(spec)?,
        Source::Toml(text) => Scenario::from_toml(text)?,
        Source::Table(t) => Scenario::from_table_in(t, None)?,
    };
    sc.apply_overrides(sets)?;
    Ok(sc)
}
