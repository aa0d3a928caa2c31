//! The limit cycle a scenario settles on — period, Floquet multipliers
//! (saltation matrices at every event), amplitudes, events per period — by
//! `squeal_core::cycle`, in a form independent of the state count.

use crate::error::{Cancel, StudyError};
use crate::model::{observe_all, AnyModel};
use crate::scenario::{InputError, Scenario};
use serde_json::{json, Map, Value};
use squeal_core::cycle::{self, CycleError, CycleOptions, Section};
use squeal_core::{EventKind, System};

/// A located cycle, independent of the state count.
#[derive(Debug, Clone)]
pub struct Found {
    /// State names.
    pub names: Vec<String>,
    /// Period (s).
    pub period: f64,
    /// Start state on the section.
    pub z0: Vec<f64>,
    /// Section state name and level.
    pub section: (String, f64),
    /// Multipliers `(re, im, trivial)` sorted by modulus descending.
    pub multipliers: Vec<(f64, f64, bool)>,
    /// Whether every non-trivial multiplier is inside the unit circle.
    pub stable: bool,
    /// Largest non-trivial modulus.
    pub max_multiplier: f64,
    /// Scaled shooting residual.
    pub residual: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Half peak-to-peak of each state.
    pub amplitude: Vec<f64>,
    /// Events per period by kind (order of [`EventKind::ALL`]).
    pub events: [u64; 5],
    /// Simulated settling time (s).
    pub settle_time: f64,
    /// One period, if asked for: columns (t, states, derived) and the event at each row.
    pub orbit: Option<OrbitTable>,
}

/// One period as a table: column names, rows, and the event at each row ("" if none).
pub type OrbitTable = (Vec<String>, Vec<Vec<f64>>, Vec<String>);

/// Build the cycle options from the scenario's solver settings.
pub fn options(sc: &Scenario, settle_steps: u64, settle_time: f64) -> CycleOptions {
    let mut solver = sc.solver;
    solver.rtol = solver.rtol.min(1e-10);
    CycleOptions {
        solver,
        settle_steps,
        settle_time,
        ..CycleOptions::default()
    }
}

/// Most integrator steps one settling run may take (`--settle-steps`):
/// 1e9, about an hour of the disc–pad model; `find_cycle` settles at most
/// seven times, so a cycle's work is bounded by the request.
pub const MAX_SETTLE_STEPS: u64 = 1_000_000_000;

/// Finest `--settle-tol`: returns to the section agree no better than the
/// integrator's tolerance (1e-10) lets them.
pub const MIN_SETTLE_TOL: f64 = 1e-9;

/// The options of `squeal cycle` after its checks (the CLI and the Python
/// bindings call this one function): the settling budget (`settle_steps`
/// returns, at most `settle_time` s simulated, agreement `settle_tol` in
/// (0, 1)), an optional section `STATE[=LEVEL]`, a model that can be
/// simulated, and a linearisation that is finite (named by parameter).
pub fn checked_options(
    sc: &Scenario,
    settle_steps: u64,
    settle_time: f64,
    settle_tol: f64,
    section: Option<&str>,
) -> Result<CycleOptions, StudyError> {
    if !(settle_time > 0.0 && settle_time.is_finite()) {
        return Err(InputError(format!(
            "--settle-time {settle_time}: must be a positive number of seconds"
        ))
        .into());
    }
    if !(settle_tol > 0.0 && settle_tol < 1.0) {
        return Err(InputError(format!("--settle-tol {settle_tol}: must be in (0, 1)")).into());
    }
    if settle_tol < MIN_SETTLE_TOL {
        return Err(InputError(format!(
            "--settle-tol {settle_tol:e}: below {MIN_SETTLE_TOL:e}, finer than the integrator resolves: returns would never agree, and settling would spend its whole budget"
        ))
        .into());
    }
    if settle_steps == 0 {
        return Err(InputError("--settle-steps 0: must be at least 1".into()).into());
    }
    if settle_steps > MAX_SETTLE_STEPS {
        return Err(InputError(format!(
            "--settle-steps {settle_steps}: more than the {MAX_SETTLE_STEPS} steps a settling run may take (about an hour at 0.4 million steps per second; with a few settling attempts per cycle)"
        ))
        .into());
    }
    sc.model.check_cycle_size().map_err(InputError)?;
    // The validation path of a simulated run, the part that applies to a
    // cycle (which budgets its own settling): a linearisation that overflows
    // is named by parameter.
    crate::feasible::scales(&sc.model, Some(sc))
        .map_err(|e| crate::feasible::stability_failure(&sc.model, e))?;
    let mut opts = options(sc, settle_steps, settle_time);
    opts.settle_tol = settle_tol;
    if let Some(spec) = section {
        opts.section = Some(parse_section(spec, &sc.model.state_names())?);
    }
    Ok(opts)
}

/// Parse `--section STATE[=LEVEL]` against the model's state names.
pub fn parse_section(spec: &str, names: &[String]) -> Result<Section, InputError> {
    let (name, level) = match spec.split_once('=') {
        Some((n, l)) => {
            let level: f64 = l
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| {
                    InputError(format!(
                        "--section {spec}: the level must be a finite number"
                    ))
                })?;
            (n.trim(), level)
        }
        None => (spec.trim(), 0.0),
    };
    let index = names.iter().position(|n| n == name).ok_or_else(|| {
        InputError(format!(
            "--section {spec}: unknown state {name} (states: {})",
            names.join(", ")
        ))
    })?;
    Ok(Section { index, level })
}

fn cycle_err(e: CycleError) -> StudyError {
    match e {
        CycleError::Bad(m) => StudyError::Input(InputError(m)),
        other => StudyError::Numerical(format!("cycle: {other}")),
    }
}

/// Settle, shoot and analyse the cycle of `m`, starting from `z0` (or from
/// the guess `(z_guess, period)` if given, skipping the settling).
pub fn find<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    any: &AnyModel,
    z0: &[f64],
    guess: Option<(&[f64], f64, Section)>,
    opts: &CycleOptions,
    with_orbit: bool,
) -> Result<Found, StudyError> {
    let mut start = [0.0; N];
    start.copy_from_slice(z0);
    let c = match guess {
        Some((zg, period, section)) => {
            let mut z = [0.0; N];
            z.copy_from_slice(zg);
            cycle::shoot(m, z, period, section, opts).map_err(cycle_err)?
        }
        None => cycle::find_cycle(m, 0.0, start, opts).map_err(cycle_err)?,
    };
    // A padded model's idle states are not reported: the cycle reads as the real model's.
    let real = real_states::<N>(m.norm_states());
    let names = any.state_names();
    let orbit = if with_orbit {
        let o = cycle::orbit(m, &c, opts).map_err(cycle_err)?;
        let mut columns = vec!["t".to_string()];
        columns.extend(names.iter().cloned());
        columns.extend(any.derived_columns());
        let mut rows = Vec::with_capacity(o.t.len());
        let mut events = Vec::with_capacity(o.t.len());
        let mut obs = Vec::new();
        let mut derived = Vec::new();
        for k in 0..o.t.len() {
            let mut row = vec![o.t[k]];
            row.extend(real.iter().map(|&i| o.z[k][i]));
            observe_all(m, o.t[k], &o.modes[k], &o.z[k], &mut obs);
            any.derived_values(&obs, &o.modes[k], &mut derived);
            row.extend_from_slice(&derived);
            rows.push(row);
            events.push(
                o.event[k]
                    .map(|(e, _)| e.as_str().to_string())
                    .unwrap_or_default(),
            );
        }
        Some((columns, rows, events))
    } else {
        None
    };
    let mut found = found_of(&c, names);
    found.orbit = orbit;
    Ok(found)
}

/// The indices of the `real` states of a model of `N` states (all of them,
/// or a padded model's real ones: `squeal_core::model::lumped::padding`).
pub fn real_states<const N: usize>(real: usize) -> Vec<usize> {
    if real >= N {
        (0..N).collect()
    } else {
        squeal_core::model::lumped::real_states::<N>(real / 2).collect()
    }
}

/// The N-independent form of a located cycle (no orbit table): `names` are
/// the model's real states (a padded model's idle ones are left out).
pub fn found_of<const N: usize>(c: &cycle::Cycle<N>, names: Vec<String>) -> Found {
    let real = real_states::<N>(names.len());
    let section = real
        .iter()
        .position(|&i| i == c.section.index)
        .map_or_else(String::new, |k| names[k].clone());
    Found {
        period: c.period,
        z0: real.iter().map(|&i| c.z0[i]).collect(),
        section: (section, c.section.level),
        multipliers: c
            .multipliers
            .iter()
            .map(|m| (m.re, m.im, m.trivial))
            .collect(),
        stable: c.stable,
        max_multiplier: c.max_multiplier,
        residual: c.residual,
        iterations: c.iterations,
        amplitude: real.iter().map(|&i| c.amplitude[i]).collect(),
        events: c.events_per_period,
        settle_time: c.settle_time,
        orbit: None,
        names,
    }
}

/// The cycle of a scenario, from its initial state. `cancel` is looked at
/// before the work starts and after it ends (`squeal_core::cycle` has no
/// hook inside its settling and shooting).
pub fn of_scenario(
    sc: &Scenario,
    opts: &CycleOptions,
    with_orbit: bool,
    cancel: &Cancel,
) -> Result<Found, StudyError> {
    cancel.check()?;
    let found = crate::with_sim_system!(&sc.model, m => {
        let z0 = crate::run::initial_of(m, sc)?;
        find(m, &sc.model, &z0, None, opts, with_orbit)
    }, else => Err(StudyError::Input(InputError(sc.model.check_cycle_size().err().unwrap_or_default()))));
    cancel.check()?;
    found
}

impl Found {
    /// The JSON document (`period`, `multipliers`, `stable`, `amplitude`,
    /// `events_per_period`, `residual`, …).
    pub fn to_json(&self) -> Value {
        json!({
            "period": self.period,
            "frequency_hz": 1.0 / self.period,
            "multipliers": multipliers_json(&self.multipliers),
            "stable": self.stable,
            "max_multiplier": self.max_multiplier,
            "amplitude": named_json(&self.names, &self.amplitude),
            "events_per_period": events_json(&self.events),
            "residual": self.residual,
            "newton_iterations": self.iterations,
            "section": { "state": self.section.0, "level": self.section.1 },
            "start": named_json(&self.names, &self.z0),
            "settle_time": self.settle_time,
        })
    }
}

/// Multipliers `(re, im, trivial)` as `[{re, im, abs, trivial}]`.
pub fn multipliers_json(m: &[(f64, f64, bool)]) -> Value {
    m.iter()
        .map(|&(re, im, trivial)| {
            json!({ "re": re, "im": im, "abs": re.hypot(im), "trivial": trivial })
        })
        .collect()
}

/// `{name: value}` for names and values paired in order.
pub fn named_json<T: serde::Serialize>(names: &[String], values: &[T]) -> Value {
    let mut m = Map::new();
    for (n, v) in names.iter().zip(values) {
        m.insert(n.clone(), json!(v));
    }
    Value::Object(m)
}

/// `{kind: count}` for every event kind.
pub fn events_json(events: &[u64; 5]) -> Value {
    let mut m = Map::new();
    for k in EventKind::ALL {
        m.insert(k.as_str().to_string(), json!(events[k.index()]));
    }
    Value::Object(m)
}
