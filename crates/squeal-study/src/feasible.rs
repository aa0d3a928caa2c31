//! What a run will cost, checked before it starts — the same way for every
//! command that simulates (`simulate`, `listen`, `map --transient`,
//! `reproduce`): the memory of its series, its sample rate against the
//! model's fastest mode, and the work an explicit integrator needs for its
//! stiffest time scale (which also sets the run's step budget).

use crate::error::StudyError;
use crate::model::AnyModel;
use crate::scenario::{InputError, Scenario};
use nalgebra::Complex;
use squeal_core::integrate::budget::{min_steps, step_budget};
use squeal_core::stability::{self, Analysis, StabilityError};
use squeal_core::System;

/// Most bytes the sampled series of one run may take in memory (1 GiB).
pub const MAX_SERIES_BYTES: f64 = 1024.0 * 1024.0 * 1024.0;

/// Memory a run takes per byte of its series: the series, its CSV text
/// and the analyses (spectra, envelope) made from it. Measured: `squeal
/// simulate belt --set sample_rate=1e7 --duration 1` (0.48 GB of series)
/// needs 1.3–1.4 GB of address space (`ulimit -v`), 5e6 Hz 0.8–0.9 GB:
/// about 2.4 bytes per series byte above a fixed 0.2 GB; 3 leaves a margin.
pub const RUN_MEMORY_PER_SERIES_BYTE: f64 = 3.0;

pub use crate::memory::{
    analysis_bytes, check_model_memory, dense_analysis_bytes, sparse_analysis_bytes,
    MEMORY_CHECK_FROM,
};

/// Most steps a run may need at the least (its [`min_steps`]): beyond this
/// it would run for minutes (about 1 µs per step, and an accurate run takes
/// ten times its bound), so it is refused before it starts. The default
/// disc–pad model reaches it after 300 s of simulated time, beyond its
/// memory limit.
pub const MAX_MIN_STEPS: f64 = 1.0e7;

/// The model's fastest time scales, from the eigenvalues of its state
/// matrix at steady sliding and at the initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct Scales {
    /// Largest eigenvalue modulus |λ| (1/s).
    pub lambda_max: f64,
    /// The coordinate dominating that mode ("" if it is a mode at the
    /// initial state rather than at steady sliding).
    pub dominant: String,
    /// Highest mode frequency |Im λ|/2π (Hz).
    pub f_max_hz: f64,
}

fn scales_of(
    an: Result<Analysis, StabilityError>,
    at_start: Option<Vec<Complex<f64>>>,
) -> Result<Option<Scales>, StabilityError> {
    let mut s: Option<Scales> = None;
    let mut take = |modulus: f64, im: f64, dominant: &str| {
        let f = im.abs() / (2.0 * std::f64::consts::PI);
        match &mut s {
            None => {
                s = Some(Scales {
                    lambda_max: modulus,
                    dominant: dominant.to_string(),
                    f_max_hz: f,
                })
            }
            Some(s) => {
                s.f_max_hz = s.f_max_hz.max(f);
                if modulus > s.lambda_max {
                    s.lambda_max = modulus;
                    s.dominant = dominant.to_string();
                }
            }
        }
    };
    match an {
        Ok(an) => {
            for e in &an.eigen {
                if !(e.re.is_finite() && e.im.is_finite()) {
                    return Err(StabilityError::NonFinite {
                        what: "spectrum (eigenvalues)",
                    });
                }
                take(e.re.hypot(e.im), e.im, &e.dominant_name);
            }
        }
        Err(e @ StabilityError::NonFinite { .. }) => return Err(e),
        Err(_) => {}
    }
    for l in at_start.unwrap_or_default() {
        if l.re.is_finite() && l.im.is_finite() {
            take(l.re.hypot(l.im), l.im, "");
        }
    }
    Ok(s)
}

/// The fastest time scales of a model (at steady sliding, and at `sc`'s
/// initial state if given); `None` if neither can be linearised. A lumped
/// model too large to simulate is judged at steady sliding only.
pub fn scales(model: &AnyModel, sc: Option<&Scenario>) -> Result<Option<Scales>, StabilityError> {
    let an = model.analyse();
    let at_start = crate::with_system!(model, m => {
        sc.and_then(|sc| crate::run::initial_of(m, sc).ok())
            .and_then(|z| stability::eigen::eigenvalues(&m.state_jacobian(&z)))
            .map(|ev| ev.to_vec())
    }, else => None);
    scales_of(an, at_start)
}

/// The parameters of a model with their values and defaults (the model's
/// defaults under the same friction law).
fn params_and_defaults(model: &AnyModel) -> Vec<(&'static str, f64, f64)> {
    let Some(mut d) = AnyModel::by_name(model.name()) else {
        return Vec::new();
    };
    if let Ok(law) = d.friction().switch_to(model.friction().name()) {
        d.set_friction(law);
    }
    model
        .param_specs()
        .iter()
        .chain(model.friction().params())
        .filter_map(|p| Some((p.name, model.get(p.name)?, d.get(p.name)?)))
        .collect()
}

/// The parameter whose reset to its default makes `bad` smallest (and at
/// least `gain` times smaller than now): the one to blame.
fn culprit(
    model: &AnyModel,
    gain: f64,
    bad: impl Fn(&AnyModel) -> f64,
) -> Option<(&'static str, f64, f64)> {
    let now = bad(model);
    let mut best: Option<((&'static str, f64, f64), f64)> = None;
    for (name, value, default) in params_and_defaults(model) {
        if value == default {
            continue;
        }
        let mut m = model.clone();
        if m.set(name, default).is_err() || m.validate().is_err() {
            continue;
        }
        let b = bad(&m);
        if b < now && b * gain <= now && best.as_ref().is_none_or(|(_, bb)| b < *bb) {
            best = Some(((name, value, default), b));
        }
    }
    best.map(|(c, _)| c)
}

/// How the fastest |λ| at steady sliding scales with the parameters (the
/// parameter ratio behind a time scale): `" (|λ| ∝ c_dx^1 · m_d^-1)"`,
/// from logarithmic derivatives by a 1 % change of each parameter; the
/// three strongest, empty if none is found.
fn scaling_law(model: &AnyModel) -> String {
    let lam = |m: &AnyModel| scales(m, None).ok().flatten().map(|s| s.lambda_max);
    let Some(l0) = lam(model).filter(|l| *l > 0.0) else {
        return String::new();
    };
    let mut terms: Vec<(f64, &'static str)> = Vec::new();
    for (name, value, _) in params_and_defaults(model) {
        if value == 0.0 {
            continue;
        }
        let mut m = model.clone();
        if m.set(name, value * 1.01).is_err() || m.validate().is_err() {
            continue;
        }
        if let Some(l1) = lam(&m).filter(|l| *l > 0.0) {
            let k = (l1 / l0).ln() / 1.01f64.ln();
            if k.abs() >= 0.2 {
                terms.push((k, name));
            }
        }
    }
    terms.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()).then(a.1.cmp(b.1)));
    if terms.is_empty() {
        return String::new();
    }
    let parts: Vec<String> = terms
        .iter()
        .take(3)
        .map(|(k, n)| format!("{n}^{}", g((k * 100.0).round() / 100.0)))
        .collect();
    format!(" (|λ| ∝ {})", parts.join(" · "))
}

/// A stability failure as a study error: bad input (a missing steady
/// sliding, a bad parameter or interval, a non-finite matrix) or numerical
/// trouble (the rest).
pub fn stability_error(e: StabilityError) -> StudyError {
    match e {
        StabilityError::NoSteadySliding(_)
        | StabilityError::Param(_)
        | StabilityError::NonFinite { .. }
        | StabilityError::BadInterval { .. } => StudyError::Input(InputError(e.to_string())),
        other => StudyError::Numerical(other.to_string()),
    }
}

/// A stability failure as a study error. A non-finite state matrix or
/// equilibrium is bad input (exit 2) naming the parameter that causes it
/// (the one whose default value makes it finite); see
/// [`stability_error`] for the rest.
pub fn stability_failure(model: &AnyModel, e: StabilityError) -> StudyError {
    let StabilityError::NonFinite { what } = e else {
        return stability_error(e);
    };
    let finite = |m: &AnyModel| match scales(m, None) {
        Err(StabilityError::NonFinite { .. }) => 1.0,
        _ => 0.0,
    };
    let msg = match culprit(model, 1.0, finite) {
        Some((name, value, default)) => format!(
            "{name} = {}: the {what} at steady sliding is not finite (it overflows); \
             with {name} = {} it is",
            g(value),
            g(default)
        ),
        None => format!(
            "the {what} at steady sliding is not finite (it overflows): check the parameters for extreme values"
        ),
    };
    StudyError::Input(InputError(msg))
}

pub use crate::run::series_bytes;
use crate::run::series_shape;

/// Check that `sc` can be run, before any work: the model is one squeal
/// can simulate, the series fits in memory,
/// the sample rate resolves the fastest mode, and the integration needs a
/// bounded number of steps; then set the run's step budget
/// (`sc.solver.max_steps`). Every input limit the request breaks is named
/// in one refusal.
pub fn prepare(sc: &mut Scenario) -> Result<(), StudyError> {
    sc.validate()?;
    // Every limit the request breaks, named in one refusal (not one per attempt).
    let mut broken: Vec<String> = Vec::new();
    if let Err(e) = sc.model.check_simulable() {
        broken.push(e);
    }
    let bytes = series_bytes(sc);
    if bytes > MAX_SERIES_BYTES {
        let (rows, cols) = series_shape(sc);
        broken.push(format!(
            "sample_rate = {}: {} s at {} Hz is {rows:.3e} samples × {cols} columns = {:.2} GB in memory \
             (limit {:.2} GB); lower sample_rate or duration",
            sc.sample_rate,
            sc.duration,
            sc.sample_rate,
            bytes / 1e9,
            MAX_SERIES_BYTES / 1e9
        ));
    } else {
        let need = RUN_MEMORY_PER_SERIES_BYTE * bytes;
        if need > MEMORY_CHECK_FROM {
            if let Err(m) = crate::memory::check(
                need,
                &format!(
                    "sample_rate = {}: {} s at {} Hz ({:.2} GB of series, written as CSV and analysed)",
                    sc.sample_rate,
                    sc.duration,
                    sc.sample_rate,
                    bytes / 1e9
                ),
            ) {
                broken.push(format!("{m}; lower sample_rate or duration"));
            }
        }
    }
    let scales = scales(&sc.model, Some(sc)).map_err(|e| stability_failure(&sc.model, e))?;
    let lambda = scales.as_ref().map_or(0.0, |s| s.lambda_max);
    if let Some(s) = &scales {
        let least = 2.0 * s.f_max_hz;
        if sc.sample_rate < least {
            broken.push(format!(
                "sample_rate = {}: below twice the fastest mode ({:.6e} Hz): the series would alias it; \
                 the least rate that works is {least:.6e} Hz",
                sc.sample_rate, s.f_max_hz
            ));
        }
    }
    match broken.len() {
        0 => {}
        1 => return Err(InputError(broken.remove(0)).into()),
        n => {
            return Err(InputError(format!(
                "{n} limits broken: {}",
                broken
                    .iter()
                    .enumerate()
                    .map(|(i, b)| format!("({}) {b}", i + 1))
                    .collect::<Vec<_>>()
                    .join("; ")
            ))
            .into())
        }
    }
    // An h_max below the integrator's least step (16 ε · 1e-6 s at t = 0)
    // fails at once with a step-size underflow and its time: let it.
    let h_max = if sc.solver.h_max < 16.0 * f64::EPSILON * 1e-6 {
        f64::INFINITY
    } else {
        sc.solver.h_max
    };
    let need = min_steps(lambda, sc.duration, h_max);
    if need > MAX_MIN_STEPS {
        return Err(StudyError::Numerical(stiff_message(
            sc,
            scales.as_ref(),
            need,
        )));
    }
    sc.solver.max_steps = step_budget(need);
    Ok(())
}

fn stiff_message(sc: &Scenario, s: Option<&Scales>, need: f64) -> String {
    let by_h_max = sc.duration / sc.solver.h_max;
    if by_h_max >= need {
        return format!(
            "refused before starting: h_max = {:e} s makes {} s take {need:.2e} steps (limit {MAX_MIN_STEPS:.0e}); \
             raise h_max or shorten duration",
            sc.solver.h_max, sc.duration
        );
    }
    let Some(s) = s else {
        return format!("refused before starting: {need:.2e} steps needed");
    };
    let cause = culprit(&sc.model, 10.0, |m| {
        scales(m, None)
            .ok()
            .flatten()
            .map_or(f64::INFINITY, |s| s.lambda_max)
    });
    let law = scaling_law(&sc.model);
    let (by, fix) = match cause {
        Some((name, value, default)) => (
            format!(", set by {name} = {}{law}", g(value)),
            format!("bring {name} towards {} (its default)", g(default)),
        ),
        None => (String::new(), "shorten duration".to_string()),
    };
    let mode = if s.dominant.is_empty() {
        "at the initial state".to_string()
    } else {
        format!("({})", s.dominant)
    };
    format!(
        "refused before starting: too stiff for an explicit integrator: the fastest mode {mode} has |λ| = {:.3e} 1/s, \
         a time scale of {:.3e} s{by}; {} s would take at least {need:.2e} steps (limit {MAX_MIN_STEPS:.0e}); {fix}",
        s.lambda_max,
        1.0 / s.lambda_max,
        sc.duration
    )
}

/// A number as people write it: 16.6667, 0.001, 1e15, 1e-300.
pub fn g(x: f64) -> String {
    let a = x.abs();
    let trim = |s: String| {
        if let Some((m, e)) = s.split_once('e') {
            let m = if m.contains('.') {
                m.trim_end_matches('0').trim_end_matches('.')
            } else {
                m
            };
            format!("{m}e{e}")
        } else if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e6).contains(&a) {
        trim(format!("{:.6}", x))
    } else {
        trim(format!("{:.5e}", x))
    }
}

/// [`crate::scenario::resolve`] for a run — with `duration` if given —
/// checked the one way every simulating computation is ([`prepare`]:
/// memory, sample rate, stiffness, and the step budget).
pub fn resolve_run(
    source: crate::scenario::Source<'_>,
    sets: &[String],
    duration: Option<f64>,
) -> Result<Scenario, StudyError> {
    let mut sc = crate::scenario::resolve(source, sets)?;
    if let Some(d) = duration {
        sc.apply("duration", &crate::scenario::Setting::Number(d))
            .map_err(|e| InputError(format!("--duration: {}", e.0)))?;
    }
    prepare(&mut sc)?;
    Ok(sc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_follows_from_the_fastest_mode() {
        // The default brake's fastest mode: λ = −1.145469 ± 2.162192e5 i 1/s
        // (34 412.35 Hz, README), over 0.5 s.
        let mut sc = Scenario::builtin("disc-pad").unwrap();
        prepare(&mut sc).unwrap();
        let bound = 0.5 * 2.162192e5_f64.hypot(1.145469) / 6.5;
        let ratio = sc.solver.max_steps as f64 / step_budget(bound) as f64;
        assert!((ratio - 1.0).abs() < 1e-6, "{ratio}");
        // Ten times the duration, ten times the bound.
        let mut long = Scenario::builtin("disc-pad").unwrap();
        long.duration = 5.0;
        prepare(&mut long).unwrap();
        let ratio = long.solver.max_steps as f64 / step_budget(10.0 * bound) as f64;
        assert!((ratio - 1.0).abs() < 1e-6, "{ratio}");
    }

    #[test]
    fn an_exhausted_budget_says_when_and_why() {
        let e = squeal_core::IntegrateError::MaxSteps {
            t: 0.25,
            steps: 1000,
        };
        let msg = crate::run::explain(e, 0.5);
        assert!(msg.contains("t = 2.5") && msg.contains("1000 steps") && msg.contains("stiff"));
        assert!(msg.contains("mean step 2.500e-4 s"), "{msg}");
    }

    #[test]
    fn numbers_read_as_written() {
        assert_eq!(g(1e15), "1e15");
        assert_eq!(g(50.0 / 3.0), "16.666667");
        assert_eq!(g(1.0), "1");
        assert_eq!(g(0.0), "0");
        assert_eq!(g(1e-300), "1e-300");
        assert_eq!(g(-2.5e-7), "-2.5e-7");
    }
}
