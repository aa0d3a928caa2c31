//! Running a scenario: integrate and collect columns and events (outputs
//! are staged by [`crate::staging::Staging`], re-exported here).

use crate::model::observe_all;
use crate::model::AnyModel;
use crate::scenario::{InputError, Scenario};
use indicatif::{ProgressBar, ProgressStyle};
use squeal_core::initial::initial_state;
use squeal_core::integrate::{Flow, Sink};
use squeal_core::model::{Modes, Observables};
use squeal_core::{simulate, EventKind, Mode, RunInfo, System};
use std::io::IsTerminal;

pub use crate::staging::Staging;
use std::time::Instant;

/// Why a run failed: bad input (exit code 2) or trouble during the run (exit code 1).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Bad input, detected before anything was written.
    #[error(transparent)]
    Input(#[from] InputError),
    /// Numerical failure (step underflow, chatter, …) with its time and cause.
    #[error("simulation failed: {0}")]
    Numerical(String),
    /// Writing output failed.
    #[error("{0}")]
    Io(String),
}

/// A finished run: uniformly sampled columns and the event list.
#[derive(Debug, Clone)]
pub struct Run {
    /// Column names: `t`, the states, then the model's derived columns.
    pub columns: Vec<String>,
    /// Column data, same order as `columns`.
    pub data: Vec<Vec<f64>>,
    /// Events `(t, kind)` in order.
    pub events: Vec<(f64, EventKind)>,
    /// The contact of each event (index into `contact_names`).
    pub event_contacts: Vec<usize>,
    /// Names of the model's contacts.
    pub contact_names: Vec<String>,
    /// Integrator statistics and end time.
    pub info: RunInfo,
    /// Wall time of the integration (s).
    pub integrate_s: f64,
    /// Output sample rate (Hz).
    pub sample_rate: f64,
}

impl Run {
    /// The column called `name`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .position(|c| c == name)
            .map(|i| self.data[i].as_slice())
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }
}

struct Collect<'a, M: ?Sized> {
    model: &'a M,
    any: &'a AnyModel,
    data: Vec<Vec<f64>>,
    derived: Vec<f64>,
    obs: Vec<Observables>,
    events: Vec<(f64, EventKind)>,
    event_contacts: Vec<usize>,
    progress: &'a ProgressBar,
    t_end: f64,
    next_tick: f64,
}

impl<M: System<N> + ?Sized, const N: usize> Sink<N> for Collect<'_, M> {
    fn sample(&mut self, t: f64, z: &[f64; N], mode: Mode) -> Flow {
        self.sample_modes(t, z, &Modes::single(mode))
    }
    fn sample_modes(&mut self, t: f64, z: &[f64; N], modes: &Modes) -> Flow {
        self.data[0].push(t);
        for i in 0..N {
            self.data[1 + i].push(z[i]);
        }
        observe_all(self.model, t, modes, z, &mut self.obs);
        self.any.derived_values(&self.obs, modes, &mut self.derived);
        for (j, v) in self.derived.iter().enumerate() {
            self.data[1 + N + j].push(*v);
        }
        if t >= self.next_tick {
            self.progress.set_position((1000.0 * t / self.t_end) as u64);
            self.next_tick = t + self.t_end / 200.0;
        }
        Flow::Continue
    }
    fn event(&mut self, t: f64, kind: EventKind, _z: &[f64; N], _mode: Mode) {
        self.events.push((t, kind));
        self.event_contacts.push(0);
    }
    fn contact_event(
        &mut self,
        t: f64,
        kind: EventKind,
        contact: usize,
        _z: &[f64; N],
        _m: &Modes,
    ) {
        self.events.push((t, kind));
        self.event_contacts.push(contact);
    }
}

/// A progress bar on a terminal, nothing otherwise.
pub fn progress_bar(len: u64, what: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(len);
    pb.set_style(
        ProgressStyle::with_template(
            "{msg} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb
}

/// The scenario's initial state (`rest` or `equilibrium`, plus its offsets).
pub fn initial_of<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    sc: &Scenario,
) -> Result<[f64; N], RunError> {
    let mut offsets = [0.0; N];
    offsets.copy_from_slice(&sc.offsets);
    initial_state(model, sc.initial, &offsets).map_err(|e| {
        RunError::Input(InputError(format!(
            "initial = {}: {e}",
            sc.initial.as_str()
        )))
    })
}

fn run_model<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    any: &AnyModel,
    sc: &Scenario,
    progress: &ProgressBar,
) -> Result<Run, RunError> {
    let z0 = initial_of(model, sc)?;
    let mut columns = vec!["t".to_string()];
    columns.extend(model.names());
    columns.extend(any.derived_columns());
    let expected = (sc.duration * sc.sample_rate) as usize + 2;
    let mut sink = Collect {
        model,
        any,
        data: (0..columns.len())
            .map(|_| Vec::with_capacity(expected))
            .collect(),
        derived: Vec::with_capacity(8),
        obs: Vec::with_capacity(model.contacts()),
        events: Vec::new(),
        event_contacts: Vec::new(),
        progress,
        t_end: sc.duration,
        next_tick: 0.0,
    };
    let start = Instant::now();
    let info = simulate(
        model,
        0.0,
        z0,
        sc.duration,
        sc.sample_rate,
        sc.solver,
        &mut sink,
    )
    .map_err(|e| RunError::Numerical(explain(e, sc.duration)))?;
    let integrate_s = start.elapsed().as_secs_f64();
    progress.finish_and_clear();
    Ok(Run {
        columns,
        data: sink.data,
        events: sink.events,
        event_contacts: sink.event_contacts,
        contact_names: (0..model.contacts())
            .map(|i| model.contact_name(i).to_string())
            .collect(),
        info,
        integrate_s,
        sample_rate: sc.sample_rate,
    })
}

/// An integration failure in words; an exhausted step budget says why the
/// run could be that expensive.
pub fn explain(e: squeal_core::IntegrateError, duration: f64) -> String {
    match e {
        squeal_core::IntegrateError::MaxSteps { t, steps } => format!(
            "work budget exhausted at t = {t:.9e} s of {duration} s: {steps} steps (mean step {:.3e} s), \
             far more than the fastest mode of steady sliding needs: the run became stiff (a steep \
             friction law near v_rel = 0, chatter, or contact): check extreme parameter values, or loosen rtol/atol",
            t / steps.max(1) as f64
        ),
        other => other.to_string(),
    }
}

/// Integrate a scenario, with a progress bar on a terminal.
pub fn run(sc: &Scenario) -> Result<Run, RunError> {
    let pb = progress_bar(1000, &format!("simulating {}", sc.name));
    run_with(sc, &pb)
}

/// Integrate a scenario, reporting progress to `pb` (hidden for sweeps).
pub fn run_with(sc: &Scenario, pb: &ProgressBar) -> Result<Run, RunError> {
    crate::with_system!(&sc.model, m => run_model(m, &sc.model, sc, pb),
        else => Err(RunError::Input(InputError(sc.model.check_simulable().err().unwrap_or_default()))))
}
