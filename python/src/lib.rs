//! `squeal._squeal`: the compiled half of the Python package `squeal`.
//!
//! Every function here only converts types between Python/NumPy and
//! [`squeal_study`], which computes exactly what the command line computes
//! (the friendly classes live in `squeal/__init__.py`). Each computation runs
//! on a worker thread with the GIL released (`compute`); the calling thread
//! wakes every `POLL` to let Python handle signals, and on
//! `KeyboardInterrupt` sets the study's [`Cancel`] token, joins the worker
//! and re-raises. No panic crosses into Python: a panicking worker becomes a
//! `SquealError`.

use numpy::ndarray::Array2;
use numpy::{Complex64, IntoPyArray};
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use squeal_files::map::MapStudy;
use squeal_files::shard::Shard;
use squeal_files::Staging;
use squeal_study::map::{self, Axis};
use squeal_study::scenario::{self, Source};
use squeal_study::{Cancel, NoProgress, Scenario, StudyError};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::{Condvar, Mutex, PoisonError};
use std::time::Duration;

create_exception!(
    _squeal,
    SquealError,
    PyRuntimeError,
    "A computation failed (numerical trouble, with the time and the cause), or was interrupted."
);
create_exception!(
    _squeal,
    ScenarioError,
    PyValueError,
    "Bad input: the message names the offending key and value (the CLI's exit code 2)."
);

/// Stack of the worker thread a computation runs on (the CLI's main thread's).
const WORKER_STACK: usize = 8 << 20;

/// How often the calling thread looks for signals while a worker computes.
const POLL: Duration = Duration::from_millis(20);

fn study_err(e: StudyError) -> PyErr {
    match e {
        StudyError::Input(i) => ScenarioError::new_err(i.0),
        StudyError::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
        other => SquealError::new_err(other.to_string()),
    }
}

/// A files-layer error as Python's: bad input → ScenarioError, an
/// interruption → KeyboardInterrupt, the rest → SquealError.
fn run_err(e: squeal_files::RunError) -> PyErr {
    use squeal_files::RunError;
    match e {
        RunError::Input(i) => ScenarioError::new_err(i.0),
        RunError::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
        other => SquealError::new_err(other.to_string()),
    }
}

fn input_err(e: scenario::InputError) -> PyErr {
    ScenarioError::new_err(e.0)
}

fn panic_err(panic: Box<dyn std::any::Any + Send>) -> PyErr {
    let why = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown cause".into());
    SquealError::new_err(format!("internal error (a bug): {why}"))
}

/// Run `work` — microseconds of work, nothing to interrupt — on this thread
/// with the GIL released (a worker thread would cost more than the work).
fn compute_quick<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Cancel) -> Result<T, StudyError> + Send,
{
    let cancel = Cancel::new();
    match py.allow_threads(|| catch_unwind(AssertUnwindSafe(|| work(&cancel)))) {
        Ok(r) => r.map_err(study_err),
        Err(panic) => Err(panic_err(panic)),
    }
}

/// Run `work` on a worker thread with the GIL released; see the module docs.
fn compute<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Cancel) -> Result<T, StudyError> + Send,
{
    compute_with(py, work, study_err)
}

/// [`compute`] for work whose error is `E`, turned into Python's by `to_py`.
fn compute_with<T, E, F>(py: Python<'_>, work: F, to_py: fn(E) -> PyErr) -> PyResult<T>
where
    T: Send,
    E: Send,
    F: FnOnce(&Cancel) -> Result<T, E> + Send,
{
    let cancel = Cancel::new();
    // Set by the worker when it is done; the caller waits on it in slices of POLL.
    let done = (Mutex::new(false), Condvar::new());
    std::thread::scope(|s| {
        let (cancel, done) = (&cancel, &done);
        // The CLI computes on its main thread (8 MB of stack); the worker
        // gets as much, not a spawned thread's default 2 MB.
        let worker = std::thread::Builder::new()
            .stack_size(WORKER_STACK)
            .spawn_scoped(s, move || {
                let r = catch_unwind(AssertUnwindSafe(|| work(cancel)));
                *done.0.lock().unwrap_or_else(PoisonError::into_inner) = true;
                done.1.notify_all();
                r
            })
            .map_err(|e| SquealError::new_err(format!("cannot start a worker thread: {e}")))?;
        loop {
            let finished = py.allow_threads(|| {
                let g = done.0.lock().unwrap_or_else(PoisonError::into_inner);
                let (g, _) = done
                    .1
                    .wait_timeout_while(g, POLL, |d| !*d)
                    .unwrap_or_else(PoisonError::into_inner);
                *g
            });
            if finished {
                break;
            }
            if let Err(e) = py.check_signals() {
                cancel.cancel();
                py.allow_threads(|| {
                    let _ = worker.join();
                });
                return Err(e);
            }
        }
        match py.allow_threads(|| worker.join()) {
            Ok(Ok(r)) => r.map_err(to_py),
            Ok(Err(panic)) | Err(panic) => Err(panic_err(panic)),
        }
    })
}

/// A scenario source as Python hands it over: `kind` is `"spec"` (a
/// built-in name or a path) or `"json"` (a dict, serialised by Python's
/// `json`, which round-trips floats).
fn with_source<T>(
    kind: &str,
    text: &str,
    f: impl FnOnce(Source<'_>) -> Result<T, StudyError>,
) -> PyResult<T> {
    match kind {
        "spec" => f(Source::Spec(text)).map_err(study_err),
        "json" => {
            let table: toml::Table = serde_json::from_str(text).map_err(|e| {
                ScenarioError::new_err(format!(
                    "scenario dict: not a TOML document ({e}; null values have no TOML form)"
                ))
            })?;
            f(Source::Table(&table)).map_err(study_err)
        }
        other => Err(PyValueError::new_err(format!(
            "scenario source kind {other}"
        ))),
    }
}

fn resolve(kind: &str, text: &str, sets: &[String]) -> PyResult<Scenario> {
    with_source(kind, text, |s| Ok(scenario::resolve(s, sets)?))
}

fn json_text(v: &serde_json::Value) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| SquealError::new_err(e.to_string()))
}

/// The built-in scenario names.
#[pyfunction]
fn scenarios() -> Vec<&'static str> {
    scenario::BUILTINS.to_vec()
}

/// A resolved scenario: its TOML text and the same document as JSON text
/// (Python parses that into the dict `squeal.scenario` returns).
#[pyfunction]
fn scenario_doc(kind: &str, text: &str, sets: Vec<String>) -> PyResult<(String, String)> {
    let toml_text = resolve(kind, text, &sets)?.to_toml();
    let table: toml::Table =
        toml::from_str(&toml_text).map_err(|e| SquealError::new_err(e.to_string()))?;
    let json = serde_json::to_string(&table).map_err(|e| SquealError::new_err(e.to_string()))?;
    Ok((toml_text, json))
}

/// Simulate: a dict with `columns`, `data` (samples × columns, Fortran
/// order: each column contiguous), the events, the summary (JSON text) and
/// the spectra of the analysed velocities.
#[pyfunction]
#[pyo3(signature = (kind, text, sets, duration=None, out=None, formats=vec!["csv".to_string()], plots=true, wav=false))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    duration: Option<f64>,
    out: Option<String>,
    formats: Vec<String>,
    plots: bool,
    wav: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = with_source(kind, text, |s| {
        squeal_study::feasible::resolve_run(s, &sets, duration)
    })?;
    for f in &formats {
        if f != "csv" && f != "npy" {
            return Err(ScenarioError::new_err(format!(
                "formats {f:?}: expected \"csv\" or \"npy\""
            )));
        }
    }
    let stage = out
        .as_deref()
        .map(|o| stage_for(Some(o), &sc.name))
        .transpose()?;
    let run = compute(py, |cancel| {
        let start = std::time::Instant::now();
        let mut run = squeal_study::run::run(&sc, &NoProgress, cancel)?;
        run.integrate_s = start.elapsed().as_secs_f64();
        Ok(run)
    })?;
    // The run's analysis once: by the run folder's writer with `out`
    // (whose summary.json is the summary), else here.
    let (summary, an, dest) = match stage {
        Some(stage) => {
            use squeal_files::analysis::{PlotSettings, SpectrumSettings};
            let t0 = std::time::Instant::now();
            let (spectrum, plot) = (SpectrumSettings::default(), PlotSettings::default());
            let files = squeal_files::run_dir::RunFiles {
                csv: formats.iter().any(|f| f == "csv"),
                npy: formats.iter().any(|f| f == "npy"),
                plots,
                wav,
                spectrum: &spectrum,
                plot: &plot,
                signals: &[],
            };
            let write = |_: &Cancel| {
                let w = squeal_files::run_dir::write_run(&stage, &sc, &run, &files)?;
                let mut summary = w.summary;
                let output_s = t0.elapsed().as_secs_f64();
                summary["timing"] =
                    serde_json::json!({ "integrate_s": run.integrate_s, "output_s": output_s });
                squeal_files::output::write_json(&summary, &stage.path("summary.json"))?;
                Ok((summary, w.analysis))
            };
            let (summary, an) = compute_with(py, write, run_err)?;
            (summary, an, Some(commit(py, stage)?))
        }
        None => {
            let (summary, an) = compute(py, |_| {
                let an = squeal_study::analysis::analyse(
                    &run,
                    &sc.model.channels(),
                    &squeal_study::analysis::SpectrumSettings::default(),
                    sc.validity,
                    &[],
                );
                let mut summary = squeal_study::answer::summary_json(&sc, &run, &an);
                summary["timing"] = serde_json::json!({ "integrate_s": run.integrate_s });
                Ok((summary, an))
            })?;
            (summary, an, None)
        }
    };
    let spectra = an
        .spectra
        .into_iter()
        .map(|c| (c.signal, c.spectrum.freq, c.spectrum.psd));
    let (rows, cols) = (run.len(), run.columns.len());
    let mut flat = Vec::with_capacity(rows * cols);
    for c in &run.data {
        flat.extend_from_slice(c);
    }
    let data = Array2::from_shape_vec((cols, rows), flat)
        .map_err(|e| SquealError::new_err(e.to_string()))?
        .reversed_axes();
    let out = PyDict::new(py);
    out.set_item("columns", &run.columns)?;
    out.set_item("data", data.into_pyarray(py))?;
    let ev_t: Vec<f64> = run.events.iter().map(|e| e.0).collect();
    let ev_kind: Vec<&str> = run.events.iter().map(|e| e.1.as_str()).collect();
    let ev_contact: Vec<&str> = run
        .event_contacts
        .iter()
        .map(|&i| run.contact_names.get(i).map_or("", String::as_str))
        .collect();
    out.set_item("event_t", ev_t.into_pyarray(py))?;
    out.set_item("event_kind", ev_kind)?;
    out.set_item("event_contact", ev_contact)?;
    out.set_item("summary", json_text(&summary)?)?;
    out.set_item("sample_rate", run.sample_rate)?;
    let sp = PyDict::new(py);
    for (name, f, p) in spectra {
        sp.set_item(name, (f.into_pyarray(py), p.into_pyarray(py)))?;
    }
    out.set_item("spectra", sp)?;
    out.set_item("out", dest)?;
    Ok(out)
}

/// Redraw the pictures of a saved run folder (`squeal plot RUN_DIR`) with
/// these spectrum and picture settings; returns the notes the CLI prints.
#[pyfunction]
#[pyo3(signature = (run_dir, window="hann", segment=squeal_study::analysis::SEGMENT, overlap=0.5, amplitude=false, signals=Vec::new(), fmax=None, frange=None, log_f=false))]
#[allow(clippy::too_many_arguments)]
fn plot(
    py: Python<'_>,
    run_dir: String,
    window: &str,
    segment: usize,
    overlap: f64,
    amplitude: bool,
    signals: Vec<String>,
    fmax: Option<f64>,
    frange: Option<String>,
    log_f: bool,
) -> PyResult<Vec<String>> {
    use squeal_files::analysis::{PlotSettings, SpectrumSettings};
    let settings =
        SpectrumSettings::from_flags(window, segment, overlap, amplitude).map_err(input_err)?;
    let plot = PlotSettings::from_flags(fmax, frange.as_deref(), log_f).map_err(input_err)?;
    let dir = Path::new(&run_dir);
    py.allow_threads(|| squeal_files::run_dir::redraw(dir, &settings, &plot, &signals))
        .map_err(run_err)
}

/// Stability of steady sliding: a dict of arrays and the JSON document;
/// with `out`, `modes.csv` written there (`stability --out`).
#[pyfunction]
#[pyo3(signature = (kind, text, sets, levers, out=None))]
fn stability<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    levers: bool,
    out: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = resolve(kind, text, &sets)?;
    let stage = out.as_deref().map(new_stage).transpose()?;
    // Without levers the analysis takes microseconds: no worker thread.
    let work = |cancel: &Cancel| {
        let an = squeal_study::stability::analyse(&sc.model)
            .map_err(|e| squeal_study::feasible::stability_failure(&sc.model, e))?;
        let lev = if levers {
            squeal_study::levers::search(&sc.model, &squeal_study::NoProgress, cancel)?
        } else {
            squeal_study::levers::Levers::none()
        };
        Ok((an, lev))
    };
    let (an, lev) = if levers {
        compute(py, work)?
    } else {
        compute_quick(py, work)?
    };
    let dest = match stage {
        Some(stage) => {
            let path = stage.path("modes.csv");
            let write = || squeal_files::modes::write_modes_csv(&path, &sc.model, &an);
            py.allow_threads(write).map_err(run_err)?;
            Some(commit(py, stage)?)
        }
        None => None,
    };
    let n2 = an.eigen.len();
    let eig: Vec<Complex64> = an
        .eigen
        .iter()
        .map(|e| Complex64::new(e.re, e.im))
        .collect();
    let shapes: Vec<Vec<Complex64>> = an
        .eigen
        .iter()
        .map(squeal_core::stability::modal::mode_shape)
        .collect();
    let n = shapes.first().map_or(0, Vec::len);
    let modes = Array2::from_shape_vec((n2, n), shapes.concat())
        .map_err(|e| SquealError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    out.set_item("eigenvalues", eig.into_pyarray(py))?;
    out.set_item(
        "frequencies_hz",
        an.eigen
            .iter()
            .map(|e| e.freq_hz)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    out.set_item(
        "damping_ratios",
        an.eigen
            .iter()
            .map(|e| e.damping_ratio)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    out.set_item("modes", modes.into_pyarray(py))?;
    out.set_item(
        "dominant",
        an.eigen
            .iter()
            .map(|e| e.dominant_name.as_str())
            .collect::<Vec<_>>(),
    )?;
    out.set_item("dofs", &sc.model.state_names()[..n])?;
    out.set_item("stable", an.stable)?;
    out.set_item("neutral", an.neutral)?;
    out.set_item("least_stable", an.least_stable)?;
    out.set_item(
        "document",
        json_text(&squeal_study::stability::document(&sc, &an, &lev))?,
    )?;
    out.set_item("out", dest)?;
    Ok(out)
}

fn axis(spec: (String, f64, f64, usize), flag: &str, log: bool, sc: &Scenario) -> PyResult<Axis> {
    let text = format!("{}={}:{}:{}", spec.0, spec.1, spec.2, spec.3);
    map::parse_axis(&text, flag, log, &sc.model).map_err(input_err)
}

/// An axis as Python gives it: (NAME, LO, HI, N).
type AxisSpec = (String, f64, f64, usize);

/// A map's scenario (checked for simulation with `transient` or a
/// `duration`, as `simulate` checks it) and both axes, checked.
fn map_inputs(
    kind: &str,
    text: &str,
    sets: &[String],
    (x, y): (AxisSpec, AxisSpec),
    (log_x, log_y): (bool, bool),
    transient: bool,
    duration: Option<f64>,
) -> PyResult<(Scenario, Axis, Axis)> {
    let sc = if transient || duration.is_some() {
        with_source(kind, text, |s| {
            squeal_study::feasible::resolve_run(s, sets, duration)
        })?
    } else {
        resolve(kind, text, sets)?
    };
    let xa = axis(x, "--x", log_x, &sc)?;
    let ya = axis(y, "--y", log_y, &sc)?;
    map::check_distinct(&xa, &ya).map_err(input_err)?;
    Ok((sc, xa, ya))
}

/// A `shard=(k, n)` checked as the CLI checks `--shard K/N`.
fn shard_of(shard: Option<(usize, usize)>) -> PyResult<Option<Shard>> {
    shard
        .map(|(k, n)| {
            Shard::parse(&format!("{k}/{n}"))
                .map_err(|e| ScenarioError::new_err(e.0.replacen("--shard", "shard", 1)))
        })
        .transpose()
}

/// The staged output folder `out` (or the CLI's default `out/<folder>` for
/// a shard without one), checked before any work.
fn stage_for(out: Option<&str>, folder: &str) -> PyResult<Staging> {
    Staging::for_out(out.map(Path::new), folder).map_err(run_err)
}

/// The staged output folder `out` (`cycle`, `hb`, `branch`: no default).
fn new_stage(out: &str) -> PyResult<Staging> {
    Staging::new(Path::new(out)).map_err(run_err)
}

fn commit(py: Python<'_>, stage: Staging) -> PyResult<String> {
    let dest = py.allow_threads(|| stage.commit()).map_err(run_err)?;
    Ok(dest.to_string_lossy().into_owned())
}

/// A stability map (and the transient outcome when asked): a dict of the
/// axes and flat row-major (y then x) arrays, in the CLI's point order.
/// With `out`, its files are written there too (`map --out`); with
/// `shard`, only the shard's points are computed and written as the CLI's
/// shard (`shard.json` + `part.csv`), and the dict is `map --shard --json`'s.
#[pyfunction]
#[pyo3(signature = (kind, text, sets, x, y, log_x, log_y, transient, duration=None, threads=None, shard=None, out=None))]
fn stability_map<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    x: (String, f64, f64, usize),
    y: (String, f64, f64, usize),
    log_x: bool,
    log_y: bool,
    transient: bool,
    duration: Option<f64>,
    threads: Option<usize>,
    shard: Option<(usize, usize)>,
    out: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let (sc, xa, ya) = map_inputs(
        kind,
        text,
        &sets,
        (x, y),
        (log_x, log_y),
        transient,
        duration,
    )?;
    let pool = match threads {
        Some(0) => return Err(ScenarioError::new_err("threads 0: must be at least 1")),
        Some(n) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| SquealError::new_err(e.to_string()))?,
        ),
        None => None,
    };
    let study = MapStudy {
        sc,
        x: xa,
        y: ya,
        transient,
        shard: shard_of(shard)?,
    };
    let files = out.is_some() || study.shard.is_some();
    let stage = files
        .then(|| stage_for(out.as_deref(), &study.folder()))
        .transpose()?;
    let r = compute(py, |cancel| {
        let work = || study.compute(&|_, _| Box::new(NoProgress), cancel);
        match &pool {
            Some(p) => p.install(work),
            None => work(),
        }
    })?;
    let dest = match stage {
        Some(stage) => {
            py.allow_threads(|| study.write(&stage, &r))
                .map_err(run_err)?;
            Some(commit(py, stage)?)
        }
        None => None,
    };
    if let Some(s) = study.shard {
        let d = PyDict::new(py);
        d.set_item("shard", s.k)?;
        d.set_item("shards", s.n)?;
        d.set_item("points", r.points.len())?;
        d.set_item("grid_points", study.grid_points())?;
        d.set_item("out", dest)?;
        return Ok(d);
    }
    let (m, xa, ya) = (&study.sc.model, &study.x, &study.y);
    let units = (map::unit_of(m, &xa.name), map::unit_of(m, &ya.name));
    let d = map_dict(py, xa, ya, units, &r.lin, r.trans.as_deref())?;
    d.set_item("out", dest)?;
    Ok(d)
}

/// A map's dict (see [`stability_map`]) from its axes, their units and
/// every point's results in flat order.
fn map_dict<'py>(
    py: Python<'py>,
    xa: &Axis,
    ya: &Axis,
    units: (&str, &str),
    lin: &[(f64, f64)],
    trans: Option<&[map::Outcome]>,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("x_name", &xa.name)?;
    out.set_item("y_name", &ya.name)?;
    out.set_item("x_unit", units.0)?;
    out.set_item("y_unit", units.1)?;
    out.set_item("x", xa.values.clone().into_pyarray(py))?;
    out.set_item("y", ya.values.clone().into_pyarray(py))?;
    let col = |f: &dyn Fn(usize) -> f64| (0..lin.len()).map(f).collect::<Vec<f64>>();
    out.set_item("max_growth_rate", col(&|i| lin[i].0).into_pyarray(py))?;
    out.set_item("freq_hz", col(&|i| lin[i].1).into_pyarray(py))?;
    if let Some(t) = trans {
        out.set_item("outcome", t.iter().map(|o| o.class).collect::<Vec<_>>())?;
        out.set_item("rms_tangential", col(&|i| t[i].rms).into_pyarray(py))?;
        out.set_item(
            "stick_fraction",
            col(&|i| t[i].stick_fraction).into_pyarray(py),
        )?;
        out.set_item("t_end", col(&|i| t[i].t_end).into_pyarray(py))?;
        out.set_item("spl_dba", col(&|i| t[i].spl_dba).into_pyarray(py))?;
        let agree = t.iter().zip(lin).map(|(o, (s, _))| map::agree(*s, o));
        out.set_item("agree", agree.collect::<Vec<_>>())?;
    }
    Ok(out)
}

/// The critical value of `name` in `[lo, hi]` (`squeal critical --json`'s
/// document as JSON text; `value` and `freq_hz` null when nothing crosses).
#[pyfunction]
fn critical(
    py: Python<'_>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    name: String,
    lo: f64,
    hi: f64,
    grid: usize,
) -> PyResult<String> {
    let sc = resolve(kind, text, &sets)?;
    let found = compute(py, |cancel| {
        squeal_study::critical::locate(&sc.model, &name, lo, hi, grid, cancel)
    })?;
    let mut doc = match found {
        None => serde_json::json!({ "param": name, "value": null, "freq_hz": null }),
        Some(c) => serde_json::json!({
            "param": name, "value": c.value, "freq_hz": c.freq_hz,
            "direction": c.direction, "from_neutral": c.from_neutral,
        }),
    };
    doc["modal"] = squeal_study::stability::modal_options_json(&sc.model);
    json_text(&doc)
}

/// An eigenvalue sweep: values, the eigenvalues (values × branches) and the
/// indices of the listed branches. With `out`, its files are written there
/// too; with `shard`, only the shard's slice is computed and written as the
/// CLI's shard, and the dict is `sweep --shard --json`'s.
#[pyfunction]
#[pyo3(signature = (kind, text, sets, param, shard=None, out=None))]
fn sweep<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    param: (String, f64, f64, usize),
    shard: Option<(usize, usize)>,
    out: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    use squeal_files::sweep::{SweepResult, SweepStudy};
    let sc = resolve(kind, text, &sets)?;
    let spec = format!("{}={}:{}:{}", param.0, param.1, param.2, param.3);
    let ax = map::parse_axis(&spec, "--param", false, &sc.model).map_err(input_err)?;
    let study = SweepStudy::new(sc, ax, &spec, shard_of(shard)?).map_err(input_err)?;
    let files = out.is_some() || study.shard.is_some();
    let stage = files
        .then(|| stage_for(out.as_deref(), &study.folder()))
        .transpose()?;
    let r = compute(py, |cancel| study.compute(cancel))?;
    let dest = match stage {
        Some(stage) => {
            py.allow_threads(|| study.write(&stage, &r))
                .map_err(run_err)?;
            Some(commit(py, stage)?)
        }
        None => None,
    };
    match &r {
        SweepResult::Shard {
            shard: s,
            own,
            computed,
            ..
        } => {
            let d = PyDict::new(py);
            d.set_item("shard", s.k)?;
            d.set_item("shards", s.n)?;
            d.set_item("values", own.len())?;
            d.set_item("first", own.start)?;
            d.set_item("computed_from", computed.start)?;
            d.set_item("out", dest)?;
            Ok(d)
        }
        SweepResult::Whole(sw) => {
            let unit = map::unit_of(&study.sc.model, &study.param.name);
            let d = sweep_dict(py, &study.param.name, unit, sw)?;
            d.set_item("out", dest)?;
            Ok(d)
        }
    }
}

/// A sweep's dict (see [`sweep`]).
fn sweep_dict<'py>(
    py: Python<'py>,
    name: &str,
    unit: &str,
    sw: &squeal_core::stability::sweep::Sweep,
) -> PyResult<Bound<'py, PyDict>> {
    let k = sw.values.len();
    let b = sw.lambda.first().map_or(0, Vec::len);
    let lambda = Array2::from_shape_vec((k, b), sw.lambda.concat())
        .map_err(|e| SquealError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    out.set_item("param", name)?;
    out.set_item("values", sw.values.clone().into_pyarray(py))?;
    out.set_item("eigenvalues", lambda.into_pyarray(py))?;
    out.set_item("listed", sw.listed.clone())?;
    out.set_item("unit", unit)?;
    out.set_item("onsets", json_text(&serde_json::json!(sw.onsets))?)?;
    Ok(out)
}

/// The thesis reproduced: `table.csv`'s text and `conclusions.json`'s
/// document as JSON text, and where its files went (None without `out` or
/// `shard`). With `out`, the whole report is written there (`reproduce
/// --out`, pictures with `figures`); with `shard`, only the shard's sets
/// are measured and written as the CLI's shard (their table rows are
/// returned; no conclusions, which need all 40: an empty list).
#[pyfunction]
#[pyo3(signature = (duration_scale=1.0, figures=true, shard=None, out=None))]
fn reproduce(
    py: Python<'_>,
    duration_scale: f64,
    figures: bool,
    shard: Option<(usize, usize)>,
    out: Option<String>,
) -> PyResult<(String, String, Option<String>)> {
    use squeal_files::reproduce::ReproduceStudy;
    use squeal_study::reproduce as rp;
    let shard = shard_of(shard)?;
    if out.is_none() && shard.is_none() {
        let (table, conclusions) = reproduce_quietly(py, duration_scale)?;
        return Ok((
            table,
            json_text(&serde_json::Value::Array(conclusions))?,
            None,
        ));
    }
    let study = ReproduceStudy::new(duration_scale, figures, shard).map_err(study_err)?;
    let stage = stage_for(out.as_deref(), &study.folder())?;
    let r = compute_with(
        py,
        |cancel| study.run(&stage, &|_, _| Box::new(NoProgress), cancel),
        run_err,
    )?;
    let dest = commit(py, stage)?;
    let cs = r
        .conclusions
        .as_deref()
        .map(rp::conclusions_json)
        .unwrap_or_default();
    let table = rp::table_csv(&r.results);
    Ok((table, json_text(&serde_json::Value::Array(cs))?, Some(dest)))
}

/// The thesis reproduced without files: `table.csv` and the conclusions.
fn reproduce_quietly(
    py: Python<'_>,
    duration_scale: f64,
) -> PyResult<(String, Vec<serde_json::Value>)> {
    use squeal_study::reproduce as rp;
    let sets = rp::prepared_sets(duration_scale).map_err(study_err)?;
    compute(py, |cancel| {
        let ids: Vec<usize> = (0..sets.len()).collect();
        let mut rs = Vec::with_capacity(ids.len());
        for (i, r) in rp::measure_sets(&sets, &ids, |_, _, _, _| Ok(()), &NoProgress, cancel)
            .into_iter()
            .enumerate()
        {
            rs.push(r.map_err(|e: StudyError| match e {
                StudyError::Interrupted => e,
                other => StudyError::Numerical(format!("set {}: {other}", i + 1)),
            })?);
        }
        let sw = rp::sweeps(&rs[14].sc, cancel)?;
        let cs = rp::conclusions(&rs, &sw);
        Ok((rp::table_csv(&rs), rp::conclusions_json(&cs)))
    })
}

/// The job scripts of a sharded study (`squeal slurm map|sweep|reproduce`)
/// whose tasks run `program… args… --shard K/N --out …` and whose merge
/// runs `program… merge …`: the study is checked as the CLI checks it (the
/// scenario, the axes, `tasks` against the points, values or sets), the
/// scripts written into `jobs` (default `OUT-slurm`) with the `extra` files
/// (name, text), and with `submit` both jobs submitted. Returns `jobs`,
/// `array`, `merge`, `out`, `submit_line`, `rerun_line` and, when submitted,
/// `array_job` and `merge_job`.
#[pyfunction]
#[pyo3(signature = (study, kind, text, sets, program, args, tasks, x=None, y=None, log_x=false, log_y=false, transient=false, duration=None, param=None, duration_scale=1.0, out=None, partition=None, time=None, cpus_per_task=None, jobs=None, submit=false, extra=Vec::new()))]
fn slurm<'py>(
    py: Python<'py>,
    study: &str,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    program: Vec<String>,
    args: Vec<String>,
    tasks: usize,
    x: Option<(String, f64, f64, usize)>,
    y: Option<(String, f64, f64, usize)>,
    log_x: bool,
    log_y: bool,
    transient: bool,
    duration: Option<f64>,
    param: Option<(String, f64, f64, usize)>,
    duration_scale: f64,
    out: Option<String>,
    partition: Option<String>,
    time: Option<String>,
    cpus_per_task: Option<usize>,
    jobs: Option<String>,
    submit: bool,
    extra: Vec<(String, String)>,
) -> PyResult<Bound<'py, PyDict>> {
    use squeal_files::slurm::{check_job, check_tasks, submit as sbatch, write_scripts, Job};
    let job = Job {
        tasks,
        partition,
        time,
        cpus_per_task,
        jobs: jobs.map(Into::into),
    };
    check_job(&job, false, study).map_err(run_err)?;
    let missing = |what: &str| ScenarioError::new_err(format!("slurm {study}: needs {what}"));
    let (default_out, what, units, unit_words) = match study {
        "map" => {
            let (x, y) = (
                x.ok_or_else(|| missing("x"))?,
                y.ok_or_else(|| missing("y"))?,
            );
            let (sc, xa, ya) = map_inputs(
                kind,
                text,
                &sets,
                (x, y),
                (log_x, log_y),
                transient,
                duration,
            )?;
            let n = xa.values.len() * ya.values.len();
            let what = format!("{} map of {n} points", sc.name);
            (format!("{}-map", sc.name), what, n, "points of the map")
        }
        "sweep" => {
            let p = param.ok_or_else(|| missing("param"))?;
            let sc = resolve(kind, text, &sets)?;
            let spec = format!("{}={}:{}:{}", p.0, p.1, p.2, p.3);
            let ax = map::parse_axis(&spec, "--param", false, &sc.model).map_err(input_err)?;
            let n = ax.values.len();
            let what = format!("{} sweep of {n} values", sc.name);
            (format!("{}-sweep", sc.name), what, n, "values of --param")
        }
        "reproduce" => {
            let sets = squeal_study::reproduce::prepared_sets(duration_scale).map_err(study_err)?;
            let n = sets.len();
            (
                "reproduce".into(),
                format!("the thesis's {n} sets"),
                n,
                "sets of the thesis",
            )
        }
        other => {
            return Err(ScenarioError::new_err(format!(
                "study {other:?}: expected \"map\", \"sweep\" or \"reproduce\""
            )))
        }
    };
    check_tasks(tasks, units, unit_words).map_err(run_err)?;
    let out = out.map_or_else(|| Path::new("out").join(default_out), Into::into);
    let extra: Vec<(&str, &str)> = extra
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    let s = py
        .allow_threads(|| write_scripts(&job, &program, &args, &out, &what, &extra))
        .map_err(run_err)?;
    let d = PyDict::new(py);
    d.set_item("jobs", s.jobs.to_string_lossy().into_owned())?;
    d.set_item("array", s.array.to_string_lossy().into_owned())?;
    d.set_item("merge", s.merge.to_string_lossy().into_owned())?;
    d.set_item("out", s.out.to_string_lossy().into_owned())?;
    d.set_item("submit_line", s.submit_line())?;
    d.set_item("rerun_line", s.rerun_line())?;
    if submit {
        let (a, m) = py.allow_threads(|| sbatch(&s)).map_err(run_err)?;
        d.set_item("array_job", a)?;
        d.set_item("merge_job", m)?;
    }
    Ok(d)
}

/// Gather the shard folders `dirs` into `out` (`squeal merge`): `("map",
/// the map's dict)`, `("sweep", the sweep's dict)` or `("reproduce", a dict
/// of `table` and `conclusions` (JSON text))`, each with `out`.
#[pyfunction]
fn merge<'py>(
    py: Python<'py>,
    dirs: Vec<String>,
    out: String,
) -> PyResult<(String, Bound<'py, PyDict>)> {
    use squeal_files::merge::Merged;
    let dirs: Vec<std::path::PathBuf> = dirs.into_iter().map(Into::into).collect();
    let m = compute_with(
        py,
        |cancel| squeal_files::merge::merge(&dirs, Path::new(&out), cancel),
        run_err,
    )?;
    let unit = |label: &str, name: &str| -> String {
        label
            .strip_prefix(name)
            .and_then(|r| r.trim().strip_prefix('('))
            .and_then(|r| r.strip_suffix(')'))
            .unwrap_or("")
            .to_string()
    };
    let (kind, d) = match &m.merged {
        Merged::Map {
            labels,
            x,
            y,
            lin,
            trans,
            ..
        } => {
            let (ux, uy) = (unit(&labels.xl, &x.name), unit(&labels.yl, &y.name));
            (
                "map",
                map_dict(py, x, y, (&ux, &uy), lin, trans.as_deref())?,
            )
        }
        Merged::Sweep {
            param,
            sweep,
            label,
            ..
        } => {
            let u = unit(label, &param.name);
            ("sweep", sweep_dict(py, &param.name, &u, sweep)?)
        }
        Merged::Reproduce {
            results,
            conclusions,
            ..
        } => {
            use squeal_study::reproduce as rp;
            let d = PyDict::new(py);
            d.set_item("table", rp::table_csv(results))?;
            let cs = serde_json::Value::Array(rp::conclusions_json(conclusions));
            d.set_item("conclusions", json_text(&cs)?)?;
            ("reproduce", d)
        }
    };
    d.set_item("out", m.dest.to_string_lossy().into_owned())?;
    Ok((kind.to_string(), d))
}

/// `squeal validate --json`'s document as JSON text (`filter`: the cases
/// whose name contains it; none matching is bad input, as in the CLI).
#[pyfunction]
#[pyo3(signature = (filter=None))]
fn validate(py: Python<'_>, filter: Option<String>) -> PyResult<String> {
    if let Some(f) = &filter {
        if !squeal_study::validate::specs()
            .iter()
            .any(|s| s.name.contains(f.as_str()))
        {
            return Err(ScenarioError::new_err(format!(
                "no validation case's name contains {f:?}"
            )));
        }
    }
    let cases = compute(py, |_| {
        Ok(squeal_study::validate::run(filter.as_deref(), &NoProgress))
    })?;
    let passed = cases.iter().filter(|c| c.pass).count();
    json_text(&serde_json::json!({
        "cases": cases,
        "passed": passed,
        "failed": cases.len() - passed,
    }))
}

/// `squeal inspect --json`'s document as JSON text.
#[pyfunction]
fn inspect(py: Python<'_>, kind: &str, text: &str, sets: Vec<String>) -> PyResult<String> {
    let sc = resolve(kind, text, &sets)?;
    let report = compute(py, |_| Ok(squeal_study::inspect::inspect(&sc)))?;
    json_text(&serde_json::to_value(&report).map_err(|e| SquealError::new_err(e.to_string()))?)
}

/// A Craig–Bampton reduction (`squeal reduce`): the record (`reduce.json`)
/// as JSON text, the reduced scenario's TOML, and the reduced matrices both
/// dense (`M`, `K`, `C`) and as Matrix Market text (`M.mtx`, …).
#[pyfunction]
fn reduce<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = resolve(kind, text, &sets)?;
    let red = compute(py, |_| squeal_study::reduce::reduce(&sc))?;
    let out = PyDict::new(py);
    let doc = serde_json::to_value(&red).map_err(|e| SquealError::new_err(e.to_string()))?;
    out.set_item("document", json_text(&doc)?)?;
    out.set_item("toml", &red.toml)?;
    let n = red.reduced_dofs();
    let mats = [
        ("M", Some(&red.m)),
        ("K", Some(&red.k)),
        ("C", red.c.as_ref()),
    ];
    for (name, t) in mats {
        let Some(t) = t else { continue };
        let mut d = Array2::<f64>::zeros((n, n));
        for &(r, c, v) in &t.entries {
            d[(r, c)] += v;
        }
        out.set_item(name, d.into_pyarray(py))?;
        out.set_item(format!("{name}.mtx"), squeal_core::matrix_market::write(t))?;
    }
    Ok(out)
}

/// A run as sound (`squeal listen`): the scenario simulated, a velocity
/// (`signal`, default the squealing one) rendered at 48 kHz at the fixed
/// level reference, its samples (float32 in [-1, 1]), the WAV file's bytes
/// (`wav`, as `squeal listen` writes them, named `file_name` in its
/// comment), and what the terminal would say.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn listen<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    duration: Option<f64>,
    signal: Option<String>,
    gain: f64,
    transpose: f64,
    float: bool,
    file_name: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let sound =
        squeal_study::audio::SoundSettings::checked(gain, transpose, ("gain = ", "transpose = "))
            .map_err(|e| study_err(e.into()))?;
    let sc = with_source(kind, text, |s| {
        squeal_study::feasible::resolve_run(s, &sets, duration)
    })?;
    let (name, clip, judgement) = compute(py, |cancel| {
        let run = squeal_study::run::run(&sc, &NoProgress, cancel)?;
        squeal_study::audio::listen(
            &run,
            sc.validity,
            signal.as_deref(),
            &sc.model.channels().tangential,
            &sound,
            "signal = ",
        )
    })?;
    let out = PyDict::new(py);
    out.set_item("signal", &name)?;
    out.set_item("sample_rate", clip.sample_rate)?;
    out.set_item("seconds", clip.duration())?;
    out.set_item("looped", clip.looped)?;
    out.set_item("source_seconds", clip.source_seconds)?;
    out.set_item("rms_dbfs", clip.rms_dbfs)?;
    out.set_item("clipped_samples", clip.clipped)?;
    out.set_item("full_scale_m_per_s", squeal_study::audio::FULL_SCALE)?;
    out.set_item("verdict", judgement.verdict.to_string())?;
    out.set_item(
        "squeal_hz",
        judgement.squeal.as_ref().map(|q| q.frequency_hz),
    )?;
    out.set_item("level", sound.describe(&clip))?;
    out.set_item(
        "note",
        squeal_study::audio::hearing_note(&judgement, &sound),
    )?;
    let wav = squeal_study::audio::wav_bytes(&clip, float, file_name, &sound);
    out.set_item("wav", pyo3::types::PyBytes::new(py, &wav))?;
    out.set_item("samples", clip.samples.into_pyarray(py))?;
    Ok(out)
}

/// A limit cycle (`squeal cycle --json`): the document as JSON text, and the
/// orbit over one period (column names, rows × columns, event kinds per row).
#[pyfunction]
#[pyo3(signature = (kind, text, sets, settle_steps, settle_time, settle_tol, section=None, out=None))]
fn cycle<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    settle_steps: u64,
    settle_time: f64,
    settle_tol: f64,
    section: Option<String>,
    out: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = resolve(kind, text, &sets)?;
    let opts = squeal_study::cycle::checked_options(
        &sc,
        settle_steps,
        settle_time,
        settle_tol,
        section.as_deref(),
    )
    .map_err(study_err)?;
    let stage = out.as_deref().map(new_stage).transpose()?;
    let found = compute(py, |cancel| {
        squeal_study::cycle::of_scenario(&sc, &opts, true, cancel)
    })?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    let dest = match stage {
        Some(stage) => {
            let write = || squeal_files::cycle::write(&stage, &found, &sc, &doc);
            py.allow_threads(write).map_err(run_err)?;
            Some(commit(py, stage)?)
        }
        None => None,
    };
    let out = PyDict::new(py);
    out.set_item("document", json_text(&doc)?)?;
    out.set_item("out", dest)?;
    if let Some((names, rows, events)) = &found.orbit {
        let width = names.len();
        let table = Array2::from_shape_vec((rows.len(), width), rows.concat())
            .map_err(|e| SquealError::new_err(e.to_string()))?;
        out.set_item("orbit_columns", names.clone())?;
        out.set_item("orbit", table.into_pyarray(py))?;
        out.set_item("orbit_events", events.clone())?;
    }
    Ok(out)
}

/// The periodic orbit by harmonic balance (`squeal hb --json`): the
/// document as JSON text, where the output went, and the series over one
/// period (column names `t` and the states, rows × columns).
#[pyfunction]
#[pyo3(signature = (kind, text, sets, harmonics, settle_steps, settle_time, settle_tol, guess, out=None))]
#[allow(clippy::too_many_arguments)]
fn hb<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    harmonics: usize,
    settle_steps: u64,
    settle_time: f64,
    settle_tol: f64,
    guess: &str,
    out: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = resolve(kind, text, &sets)?;
    let guess = squeal_study::hb::Guess::parse(guess)
        .map_err(|e| study_err(squeal_study::StudyError::Input(e)))?;
    squeal_study::hb::check_harmonics(harmonics)
        .map_err(|e| study_err(squeal_study::StudyError::Input(e)))?;
    let opts =
        squeal_study::cycle::checked_options(&sc, settle_steps, settle_time, settle_tol, None)
            .map_err(study_err)?;
    let stage = out.as_deref().map(new_stage).transpose()?;
    let found = compute(py, |cancel| {
        squeal_study::hb::of_scenario(&sc, harmonics, &opts, guess, true, cancel)
    })?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    let dest = match stage {
        Some(stage) => {
            let write = || squeal_files::hb::write(&stage, &found, &sc, &doc);
            py.allow_threads(write).map_err(run_err)?;
            Some(commit(py, stage)?)
        }
        None => None,
    };
    let out = PyDict::new(py);
    out.set_item("document", json_text(&doc)?)?;
    out.set_item("out", dest)?;
    if let Some((series, _)) = &found.orbit {
        let mut names = vec!["t".to_string()];
        names.extend(found.names.iter().cloned());
        let table = Array2::from_shape_vec((series.len(), names.len()), series.concat())
            .map_err(|e| SquealError::new_err(e.to_string()))?;
        out.set_item("orbit_columns", names)?;
        out.set_item("orbit", table.into_pyarray(py))?;
    }
    Ok(out)
}

/// A harmonic-balance solution followed in one parameter (`squeal hb
/// --param --json`): the document as JSON text.
#[pyfunction]
#[pyo3(signature = (kind, text, sets, param, harmonics, settle_steps, settle_time, settle_tol, out=None))]
#[allow(clippy::too_many_arguments)]
fn hb_branch(
    py: Python<'_>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    param: (String, f64, f64, usize),
    harmonics: usize,
    settle_steps: u64,
    settle_time: f64,
    settle_tol: f64,
    out: Option<String>,
) -> PyResult<String> {
    let sc = resolve(kind, text, &sets)?;
    let spec = format!("{}={}:{}:{}", param.0, param.1, param.2, param.3);
    let (name, lo, hi, n) = squeal_study::branch::parse_range(&spec).map_err(input_err)?;
    squeal_study::hb::check_harmonics(harmonics)
        .map_err(|e| study_err(squeal_study::StudyError::Input(e)))?;
    let opts =
        squeal_study::cycle::checked_options(&sc, settle_steps, settle_time, settle_tol, None)
            .map_err(study_err)?;
    let stage = out.as_deref().map(new_stage).transpose()?;
    let br = compute(py, |cancel| {
        squeal_study::hb_branch::follow(&sc, &name, lo, hi, n, harmonics, &opts, cancel)
    })?;
    let mut doc = br.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        let write = || squeal_files::hb::write_branch(&stage, &br, &sc, &doc);
        py.allow_threads(write).map_err(run_err)?;
        commit(py, stage)?;
    }
    json_text(&doc)
}

/// A nonlinear mode (`squeal nma --json`): the document as JSON text.
#[pyfunction]
#[pyo3(signature = (kind, text, sets, mode, amplitudes, harmonics, out=None))]
#[allow(clippy::too_many_arguments)]
fn nma(
    py: Python<'_>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    mode: usize,
    amplitudes: (f64, f64, usize),
    harmonics: usize,
    out: Option<String>,
) -> PyResult<String> {
    let sc = resolve(kind, text, &sets)?;
    let spec = format!("{}:{}:{}", amplitudes.0, amplitudes.1, amplitudes.2);
    let amps = squeal_study::nma::parse_amplitudes(&spec).map_err(input_err)?;
    let stage = out.as_deref().map(new_stage).transpose()?;
    let found = compute(py, |cancel| {
        squeal_study::nma::of_scenario(&sc, mode, &amps, harmonics, cancel)
    })?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        let write = || squeal_files::nma::write(&stage, &found, &sc, &doc);
        py.allow_threads(write).map_err(run_err)?;
        commit(py, stage)?;
    }
    json_text(&doc)
}

/// A branch of limit cycles (`squeal branch --json`): the document as JSON
/// text.
#[pyfunction]
#[pyo3(signature = (kind, text, sets, param, out=None))]
fn branch(
    py: Python<'_>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    param: (String, f64, f64, usize),
    out: Option<String>,
) -> PyResult<String> {
    let sc = resolve(kind, text, &sets)?;
    let spec = format!("{}={}:{}:{}", param.0, param.1, param.2, param.3);
    let (name, lo, hi, n) = squeal_study::branch::parse_range(&spec).map_err(input_err)?;
    let values = squeal_study::branch::values(lo, hi, n);
    squeal_study::branch::check(&sc, &name, &values).map_err(study_err)?;
    let stage = out.as_deref().map(new_stage).transpose()?;
    let br = compute(py, |cancel| {
        squeal_study::branch::follow(
            &sc,
            &name,
            &values,
            (lo, hi),
            &squeal_study::NoProgress,
            cancel,
        )
    })?;
    let doc = br.to_json(&name, &sc);
    if let Some(stage) = stage {
        let write = || squeal_files::branch::write(&stage, &br, &sc, &name, &doc);
        py.allow_threads(write).map_err(run_err)?;
        commit(py, stage)?;
    }
    json_text(&doc)
}

/// The compiled module.
#[pymodule]
fn _squeal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // A build for x86-64-v3 (the default) on a processor without AVX2 would
    // die of an illegal instruction later: refuse the import instead.
    if let Some(feature) = squeal_study::cpu::missing_feature() {
        return Err(pyo3::exceptions::PyImportError::new_err(
            squeal_study::cpu::refusal(feature),
        ));
    }
    m.add("SquealError", m.py().get_type::<SquealError>())?;
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add_function(wrap_pyfunction!(scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(scenario_doc, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(stability_map, m)?)?;
    m.add_function(wrap_pyfunction!(critical, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(cycle, m)?)?;
    m.add_function(wrap_pyfunction!(hb, m)?)?;
    m.add_function(wrap_pyfunction!(hb_branch, m)?)?;
    m.add_function(wrap_pyfunction!(nma, m)?)?;
    m.add_function(wrap_pyfunction!(branch, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(inspect, m)?)?;
    m.add_function(wrap_pyfunction!(reduce, m)?)?;
    m.add_function(wrap_pyfunction!(listen, m)?)?;
    m.add_function(wrap_pyfunction!(reproduce, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(slurm, m)?)?;
    m.add_function(wrap_pyfunction!(plot, m)?)?;
    Ok(())
}
