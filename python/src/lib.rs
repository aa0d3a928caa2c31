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
use squeal_study::map::{self, Axis};
use squeal_study::scenario::{self, Source};
use squeal_study::{Cancel, NoProgress, Scenario, StudyError};
use std::panic::{catch_unwind, AssertUnwindSafe};
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

/// How often the calling thread looks for signals while a worker computes.
const POLL: Duration = Duration::from_millis(20);

fn study_err(e: StudyError) -> PyErr {
    match e {
        StudyError::Input(i) => ScenarioError::new_err(i.0),
        StudyError::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
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
    let cancel = Cancel::new();
    // Set by the worker when it is done; the caller waits on it in slices of POLL.
    let done = (Mutex::new(false), Condvar::new());
    std::thread::scope(|s| {
        let (cancel, done) = (&cancel, &done);
        let worker = s.spawn(move || {
            let r = catch_unwind(AssertUnwindSafe(|| work(cancel)));
            *done.0.lock().unwrap_or_else(PoisonError::into_inner) = true;
            done.1.notify_all();
            r
        });
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
            Ok(Ok(r)) => r.map_err(study_err),
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
#[pyo3(signature = (kind, text, sets, duration=None))]
fn simulate<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    duration: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = with_source(kind, text, |s| {
        squeal_study::feasible::resolve_run(s, &sets, duration)
    })?;
    let (run, summary, spectra) = compute(py, |cancel| {
        let start = std::time::Instant::now();
        let mut run = squeal_study::run::run(&sc, &NoProgress, cancel)?;
        run.integrate_s = start.elapsed().as_secs_f64();
        let an = squeal_study::analysis::analyse(
            &run,
            &sc.model.channels(),
            &squeal_study::analysis::SpectrumSettings::default(),
            sc.validity,
            &[],
        );
        let mut summary = squeal_study::answer::summary_json(&sc, &run, &an);
        summary["timing"] = serde_json::json!({ "integrate_s": run.integrate_s });
        let spectra: Vec<(String, Vec<f64>, Vec<f64>)> = an
            .spectra
            .into_iter()
            .map(|c| (c.signal, c.spectrum.freq, c.spectrum.psd))
            .collect();
        Ok((run, summary, spectra))
    })?;
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
    Ok(out)
}

/// Stability of steady sliding: a dict of arrays and the JSON document.
#[pyfunction]
fn stability<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    levers: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = resolve(kind, text, &sets)?;
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
    Ok(out)
}

fn axis(spec: (String, f64, f64, usize), flag: &str, log: bool, sc: &Scenario) -> PyResult<Axis> {
    let text = format!("{}={}:{}:{}", spec.0, spec.1, spec.2, spec.3);
    map::parse_axis(&text, flag, log, &sc.model).map_err(input_err)
}

/// A stability map (and the transient outcome when asked): a dict of the
/// axes and flat row-major (y then x) arrays, in the CLI's point order.
#[pyfunction]
#[pyo3(signature = (kind, text, sets, x, y, log_x, log_y, transient, duration=None, threads=None))]
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
) -> PyResult<Bound<'py, PyDict>> {
    let sc = if transient || duration.is_some() {
        with_source(kind, text, |s| {
            squeal_study::feasible::resolve_run(s, &sets, duration)
        })?
    } else {
        resolve(kind, text, &sets)?
    };
    let xa = axis(x, "--x", log_x, &sc)?;
    let ya = axis(y, "--y", log_y, &sc)?;
    map::check_distinct(&xa, &ya).map_err(input_err)?;
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
    let (lin, trans) = compute(py, |cancel| {
        let work = || {
            let points = map::all_points(&xa, &ya);
            let lin = map::linear_grid(&sc.model, &xa, &ya, &points, &NoProgress, cancel)?;
            let trans = if transient {
                Some(map::transient_grid(
                    &sc,
                    &xa,
                    &ya,
                    &points,
                    &NoProgress,
                    cancel,
                )?)
            } else {
                None
            };
            Ok((lin, trans))
        };
        match &pool {
            Some(p) => p.install(work),
            None => work(),
        }
    })?;
    let out = PyDict::new(py);
    out.set_item("x_name", &xa.name)?;
    out.set_item("y_name", &ya.name)?;
    out.set_item("x_unit", map::unit_of(&sc.model, &xa.name))?;
    out.set_item("y_unit", map::unit_of(&sc.model, &ya.name))?;
    out.set_item("x", xa.values.clone().into_pyarray(py))?;
    out.set_item("y", ya.values.clone().into_pyarray(py))?;
    out.set_item(
        "max_growth_rate",
        lin.iter().map(|p| p.0).collect::<Vec<_>>().into_pyarray(py),
    )?;
    out.set_item(
        "freq_hz",
        lin.iter().map(|p| p.1).collect::<Vec<_>>().into_pyarray(py),
    )?;
    if let Some(t) = trans {
        out.set_item("outcome", t.iter().map(|o| o.class).collect::<Vec<_>>())?;
        out.set_item(
            "rms_tangential",
            t.iter().map(|o| o.rms).collect::<Vec<_>>().into_pyarray(py),
        )?;
        out.set_item(
            "stick_fraction",
            t.iter()
                .map(|o| o.stick_fraction)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        out.set_item(
            "t_end",
            t.iter()
                .map(|o| o.t_end)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        out.set_item(
            "spl_dba",
            t.iter()
                .map(|o| o.spl_dba)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        out.set_item(
            "agree",
            t.iter()
                .zip(&lin)
                .map(|(o, (s, _))| map::agree(*s, o))
                .collect::<Vec<_>>(),
        )?;
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
/// indices of the listed branches.
#[pyfunction]
fn sweep<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    param: (String, f64, f64, usize),
) -> PyResult<Bound<'py, PyDict>> {
    let sc = resolve(kind, text, &sets)?;
    let spec = format!("{}={}:{}:{}", param.0, param.1, param.2, param.3);
    let ax = map::parse_axis(&spec, "--param", false, &sc.model).map_err(input_err)?;
    let sw = compute(py, |cancel| {
        squeal_study::sweep::sweep_model(&sc.model, &ax.name, &ax.values, &spec, cancel)
    })?;
    let k = sw.values.len();
    let b = sw.lambda.first().map_or(0, Vec::len);
    let lambda = Array2::from_shape_vec((k, b), sw.lambda.concat())
        .map_err(|e| SquealError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    out.set_item("param", &ax.name)?;
    out.set_item("values", sw.values.clone().into_pyarray(py))?;
    out.set_item("eigenvalues", lambda.into_pyarray(py))?;
    out.set_item("listed", sw.listed.clone())?;
    out.set_item("unit", map::unit_of(&sc.model, &ax.name))?;
    out.set_item("onsets", json_text(&serde_json::json!(sw.onsets))?)?;
    Ok(out)
}

/// The thesis reproduced (`squeal reproduce`'s content without its files):
/// `table.csv`'s text and `conclusions.json`'s document as JSON text.
#[pyfunction]
#[pyo3(signature = (duration_scale=1.0))]
fn reproduce(py: Python<'_>, duration_scale: f64) -> PyResult<(String, String)> {
    use squeal_study::reproduce as rp;
    let sets = rp::prepared_sets(duration_scale).map_err(study_err)?;
    let (table, conclusions) = compute(py, |cancel| {
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
    })?;
    Ok((table, json_text(&serde_json::Value::Array(conclusions))?))
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
#[pyo3(signature = (kind, text, sets, settle_steps, settle_time, settle_tol, section=None))]
fn cycle<'py>(
    py: Python<'py>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    settle_steps: u64,
    settle_time: f64,
    settle_tol: f64,
    section: Option<String>,
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
    let found = compute(py, |cancel| {
        squeal_study::cycle::of_scenario(&sc, &opts, true, cancel)
    })?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    let out = PyDict::new(py);
    out.set_item("document", json_text(&doc)?)?;
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
/// document as JSON text.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn hb(
    py: Python<'_>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    harmonics: usize,
    settle_steps: u64,
    settle_time: f64,
    settle_tol: f64,
    guess: &str,
) -> PyResult<String> {
    let sc = resolve(kind, text, &sets)?;
    let guess = squeal_study::hb::Guess::parse(guess)
        .map_err(|e| study_err(squeal_study::StudyError::Input(e)))?;
    squeal_study::hb::check_harmonics(harmonics)
        .map_err(|e| study_err(squeal_study::StudyError::Input(e)))?;
    let opts =
        squeal_study::cycle::checked_options(&sc, settle_steps, settle_time, settle_tol, None)
            .map_err(study_err)?;
    let found = compute(py, |cancel| {
        squeal_study::hb::of_scenario(&sc, harmonics, &opts, guess, false, cancel)
    })?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    json_text(&doc)
}

/// A branch of limit cycles (`squeal branch --json`): the document as JSON
/// text.
#[pyfunction]
fn branch(
    py: Python<'_>,
    kind: &str,
    text: &str,
    sets: Vec<String>,
    param: (String, f64, f64, usize),
) -> PyResult<String> {
    let sc = resolve(kind, text, &sets)?;
    let spec = format!("{}={}:{}:{}", param.0, param.1, param.2, param.3);
    let (name, lo, hi, n) = squeal_study::branch::parse_range(&spec).map_err(input_err)?;
    let values = squeal_study::branch::values(lo, hi, n);
    squeal_study::branch::check(&sc, &name, &values).map_err(study_err)?;
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
    json_text(&br.to_json(&name, &sc))
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
    m.add_function(wrap_pyfunction!(branch, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(inspect, m)?)?;
    m.add_function(wrap_pyfunction!(reduce, m)?)?;
    m.add_function(wrap_pyfunction!(listen, m)?)?;
    m.add_function(wrap_pyfunction!(reproduce, m)?)?;
    Ok(())
}
