//! Running a scenario: integrate and collect columns and events.

use crate::error::{Cancel, Progress, StudyError};
use crate::model::observe_all;
use crate::model::AnyModel;
use crate::scenario::{InputError, Scenario};
use squeal_core::initial::initial_state;
use squeal_core::integrate::ensemble::{simulate_ensemble_lanes, Job};
use squeal_core::integrate::{Flow, Sink};
use squeal_core::model::lumped::padding;
use squeal_core::model::{Modes, Observables};
use squeal_core::{simulate, DiscPad, EventKind, IntegrateError, Mode, RunInfo, System};
use std::borrow::Borrow;

/// How many samples pass between two looks at the [`Cancel`] token.
const CANCEL_EVERY: u32 = 1024;

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
    /// Wall time of the integration (s): measured by the caller (the
    /// library reads no clock), 0 until then.
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
    /// Whether the run has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

struct Collect<'a, M: ?Sized> {
    model: &'a M,
    any: &'a AnyModel,
    /// Column names, see [`Run::columns`].
    columns: Vec<String>,
    /// See [`Run::contact_names`].
    contact_names: Vec<String>,
    data: Vec<Vec<f64>>,
    /// The states written, in order (all `N`, or a padded model's real ones).
    states: Vec<usize>,
    derived: Vec<f64>,
    obs: Vec<Observables>,
    events: Vec<(f64, EventKind)>,
    event_contacts: Vec<usize>,
    progress: &'a dyn Progress,
    cancel: &'a Cancel,
    until_check: u32,
    t_end: f64,
    next_tick: f64,
    ticks: u64,
}

impl<M: System<N> + ?Sized, const N: usize> Sink<N> for Collect<'_, M> {
    fn sample(&mut self, t: f64, z: &[f64; N], mode: Mode) -> Flow {
        self.sample_modes(t, z, &Modes::single(mode))
    }
    fn sample_modes(&mut self, t: f64, z: &[f64; N], modes: &Modes) -> Flow {
        self.data[0].push(t);
        for (col, &i) in self.data[1..].iter_mut().zip(&self.states) {
            col.push(z[i]);
        }
        observe_all(self.model, t, modes, z, &mut self.obs);
        self.any.derived_values(&self.obs, modes, &mut self.derived);
        let first = 1 + self.states.len();
        for (col, v) in self.data[first..].iter_mut().zip(&self.derived) {
            col.push(*v);
        }
        if t >= self.next_tick {
            let ticks = ((1000.0 * t / self.t_end) as u64).max(self.ticks);
            self.progress.inc(ticks - self.ticks);
            self.ticks = ticks;
            self.next_tick = t + self.t_end / 200.0;
        }
        self.until_check -= 1;
        if self.until_check == 0 {
            self.until_check = CANCEL_EVERY;
            if self.cancel.is_cancelled() {
                return Flow::Stop;
            }
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

/// The scenario's initial state (`rest` or `equilibrium`, plus its offsets).
/// For a model padded with idle dofs ([`with_sim_system!`](crate::with_sim_system)),
/// the real state placed in the padded one, the idle states zero.
pub fn initial_of<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    sc: &Scenario,
) -> Result<[f64; N], StudyError> {
    let real = sc.offsets.len();
    let offsets: [f64; N] = if real == N {
        let mut o = [0.0; N];
        o.copy_from_slice(&sc.offsets);
        o
    } else {
        padding::embed(&sc.offsets)
    };
    let z = initial_state(model, sc.initial, &offsets).map_err(|e| {
        StudyError::Input(InputError(format!(
            "initial = {}: {e}",
            sc.initial.as_str()
        )))
    })?;
    if real == N {
        return Ok(z);
    }
    // The idle dofs start exactly at rest (so they stay there).
    let mut out = [0.0; N];
    for k in padding::real_states::<N>(real / 2) {
        out[k] = z[k];
    }
    Ok(out)
}

/// The solver options of a run of `sc` on `N` states: the scenario's, with
/// a padded model's per-state tolerances moved to its padded state indices
/// (`squeal_core::model::lumped::padding`).
pub fn sim_options<const N: usize>(sc: &Scenario) -> squeal_core::SolverOptions {
    padding::padded_solver::<N>(&sc.solver, sc.offsets.len())
}

impl<'a, M: ?Sized> Collect<'a, M> {
    /// An empty collector for a run of `sc` on `model` (`N` states, or a
    /// padded model's real ones), with its column names.
    fn new<const N: usize>(
        model: &'a M,
        any: &'a AnyModel,
        sc: &Scenario,
        progress: &'a dyn Progress,
        cancel: &'a Cancel,
    ) -> Self
    where
        M: System<N>,
    {
        // A padded model's idle dofs are not written: the run reads as the real model's.
        let states: Vec<usize> = padding::real_states::<N>(sc.offsets.len() / 2).collect();
        let names = model.names();
        let mut columns = vec!["t".to_string()];
        columns.extend(states.iter().map(|&i| names[i].clone()));
        columns.extend(any.derived_columns());
        let expected = (sc.duration * sc.sample_rate) as usize + 2;
        Collect {
            model,
            any,
            data: (0..columns.len())
                .map(|_| Vec::with_capacity(expected))
                .collect(),
            columns,
            contact_names: (0..model.contacts())
                .map(|i| model.contact_name(i).to_string())
                .collect(),
            states,
            derived: Vec::with_capacity(8),
            obs: Vec::with_capacity(model.contacts()),
            events: Vec::new(),
            event_contacts: Vec::new(),
            progress,
            cancel,
            until_check: CANCEL_EVERY,
            t_end: sc.duration,
            next_tick: 0.0,
            ticks: 0,
        }
    }

    /// The finished [`Run`] of `sc` from the integrator's result `info`: a
    /// failure explained, [`StudyError::Interrupted`] if `cancel` was set.
    fn into_run(
        self,
        info: Result<RunInfo, IntegrateError>,
        sc: &Scenario,
    ) -> Result<Run, StudyError> {
        let info = info.map_err(|e| StudyError::Numerical(explain(e, sc.duration)))?;
        self.progress.finish();
        self.cancel.check()?;
        Ok(Run {
            columns: self.columns,
            data: self.data,
            events: self.events,
            event_contacts: self.event_contacts,
            contact_names: self.contact_names,
            info,
            integrate_s: 0.0,
            sample_rate: sc.sample_rate,
        })
    }
}

fn run_model<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    any: &AnyModel,
    sc: &Scenario,
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<Run, StudyError> {
    cancel.check()?;
    let z0 = initial_of(model, sc)?;
    let mut sink = Collect::new::<N>(model, any, sc, progress, cancel);
    let info = simulate(
        model,
        0.0,
        z0,
        sc.duration,
        sc.sample_rate,
        sim_options::<N>(sc),
        &mut sink,
    );
    sink.into_run(info, sc)
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

/// Integrate a scenario (checked by `feasible::prepare` first),
/// reporting thousandths of its duration to `progress`, stopping with
/// [`StudyError::Interrupted`] soon after `cancel` is set.
pub fn run(sc: &Scenario, progress: &dyn Progress, cancel: &Cancel) -> Result<Run, StudyError> {
    crate::with_transient_system!(&sc.model, m => run_model(m, &sc.model, sc, progress, cancel),
        else => Err(StudyError::Input(InputError(sc.model.check_simulable().err().unwrap_or_default()))))
}

/// Most memory (bytes) the series of one [`run_many`] task may hold at once
/// when grouped by [`tasks`]: the scenarios of an ensemble are in memory
/// together, so four long runs would take four times one run's memory.
pub const TASK_SERIES_BYTES: f64 = 256.0 * 1024.0 * 1024.0;

/// The scenarios `scs` cut into consecutive groups for [`run_many`], each
/// of at most [`LANES`](squeal_core::integrate::ensemble::LANES)
/// scenarios whose series together take at most [`TASK_SERIES_BYTES`]
/// (a scenario larger than that alone is a group of one). Grouping changes
/// no result: `run_many` gives the bits of [`run`] however it is called.
pub fn tasks<S: Borrow<Scenario>>(scs: &[S]) -> Vec<std::ops::Range<usize>> {
    let lanes = squeal_core::integrate::ensemble::LANES;
    let mut out = Vec::new();
    let (mut start, mut bytes) = (0, 0.0);
    for (i, sc) in scs.iter().enumerate() {
        let b = series_bytes(sc.borrow());
        if i > start && (i - start == lanes || bytes + b > TASK_SERIES_BYTES) {
            out.push(start..i);
            (start, bytes) = (i, 0.0);
        }
        bytes += b;
    }
    if start < scs.len() {
        out.push(start..scs.len());
    }
    out
}

/// A [`Progress`] passing on every `inc` but not `finish` (the runs of
/// [`run_many`] share one bar, finished once when all are done).
struct Unfinished<'a>(&'a dyn Progress);

impl Progress for Unfinished<'_> {
    fn inc(&self, n: u64) {
        self.0.inc(n);
    }
}

/// Integrate several scenarios on the calling thread: the results of
/// [`run`] on each, in order, **bit for bit** (columns, data, events,
/// event contacts, [`RunInfo`], and every error with its
/// [`explain`]ed text), however they are grouped.
///
/// The disc–pad scenarios run as ensembles
/// ([`simulate_ensemble_lanes`], [`LANES`](squeal_core::integrate::ensemble::LANES)
/// of them stepped together, one ensemble per sample rate): a lane whose
/// run ends (finished, failed, or stopped by `cancel`) takes the next
/// scenario while the others go on, and the ensemble's runs are the same
/// bits as single runs (`squeal_core::integrate::ensemble`). Every other
/// model runs through [`run`] one after the other. `progress` counts
/// thousandths of each run's duration (1000 per scenario) and is finished
/// once, at the end; a scenario begun after `cancel` is set, or whose run
/// saw it, is [`StudyError::Interrupted`].
pub fn run_many<S: Borrow<Scenario>>(
    scs: &[S],
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Vec<Result<Run, StudyError>> {
    let quiet = Unfinished(progress);
    let mut out: Vec<Option<Result<Run, StudyError>>> = (0..scs.len()).map(|_| None).collect();
    // An ensemble feeds one sample rate: the disc–pads are grouped by theirs.
    let mut rates: Vec<u64> = Vec::new();
    for (slot, sc) in out.iter_mut().zip(scs) {
        let sc = sc.borrow();
        match &sc.model {
            AnyModel::DiscPad(_) => {
                if !rates.contains(&sc.sample_rate.to_bits()) {
                    rates.push(sc.sample_rate.to_bits());
                }
            }
            _ => *slot = Some(run(sc, &quiet, cancel)),
        }
    }
    for rate in rates {
        let mut jobs: Vec<Job<'_, DiscPad, Collect<'_, DiscPad>, 8>> = Vec::new();
        let mut slots = Vec::new();
        for (k, sc) in scs.iter().enumerate() {
            let sc = sc.borrow();
            let AnyModel::DiscPad(m) = &sc.model else {
                continue;
            };
            if sc.sample_rate.to_bits() != rate {
                continue;
            }
            // What `run_model` does before it integrates.
            match cancel.check().and_then(|_| initial_of(m, sc)) {
                Ok(z0) => {
                    jobs.push(Job {
                        model: m,
                        t0: 0.0,
                        z0,
                        t_end: sc.duration,
                        opts: sim_options::<8>(sc),
                        sink: Collect::new::<8>(m, &sc.model, sc, &quiet, cancel),
                    });
                    slots.push(k);
                }
                Err(e) => out[k] = Some(Err(e)),
            }
        }
        let infos = simulate_ensemble_lanes(&mut jobs, f64::from_bits(rate));
        for ((job, info), k) in jobs.into_iter().zip(infos).zip(slots) {
            out[k] = Some(job.sink.into_run(info, scs[k].borrow()));
        }
    }
    progress.finish();
    out.into_iter()
        .map(|r| r.expect("every scenario ran"))
        .collect()
}

/// The samples (rows) and columns of `sc`'s series (time, states, derived columns).
pub fn series_shape(sc: &Scenario) -> (f64, f64) {
    let rows = sc.duration * sc.sample_rate + 2.0;
    let cols = (1 + sc.model.state_names().len() + sc.model.derived_columns().len()) as f64;
    (rows, cols)
}

/// The memory that `sc`'s series takes (bytes): samples × columns × 8.
pub fn series_bytes(sc: &Scenario) -> f64 {
    let (rows, cols) = series_shape(sc);
    rows * cols * 8.0
}
