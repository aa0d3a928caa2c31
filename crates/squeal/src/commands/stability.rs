//! `squeal stability [SCENARIO] [--set …] [--json] [--out DIR]`: every
//! eigenvalue of the steady-sliding state, each mode's growth rate,
//! frequency, damping ratio, dominant coordinate and complex mode shape
//! (amplitude and phase per dof; in `--json` and in `DIR/modes.csv`), and the
//! verdict (MODEL.md §5).

use crate::commands::simulate::resolve;
use crate::model::AnyModel;
use crate::run::RunError;
use crate::scenario::InputError;
use crate::ScenarioArgs;
use clap::Args;
use serde_json::{json, Value};
use squeal_core::stability::{self, Analysis, CriticalOptions, StabilityError};

/// Arguments of `squeal stability`.
#[derive(Args, Debug)]
pub struct StabilityArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Print a JSON document on stdout instead of the table.
    #[arg(long)]
    json: bool,
    /// Write modes.csv (complex mode shapes of every mode) into this folder.
    #[arg(long)]
    out: Option<std::path::PathBuf>,
}

/// How mode shapes are normalised (stated in the JSON and the README).
pub const SHAPE_NORMALISATION: &str = "position part of the eigenvector divided by its largest component: that dof has amplitude 1 and phase 0, every amplitude is in [0, 1], phases in degrees in (-180, 180]";

/// Amplitude and phase (degrees) of every position dof of a mode.
fn shape_of(e: &squeal_core::stability::Eigen) -> Vec<(f64, f64)> {
    use squeal_core::stability::modal::{amplitude_phase, mode_shape};
    amplitude_phase(&mode_shape(e))
}

/// Write `modes.csv`: one row per mode and position dof,
/// `mode,growth_rate,freq_hz,damping_ratio,dof,amplitude,phase_deg`, modes
/// numbered as in the table (by growth rate).
pub fn write_modes_csv(
    path: &std::path::Path,
    model: &AnyModel,
    an: &Analysis,
) -> Result<(), RunError> {
    use std::io::Write;
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    writeln!(
        w,
        "mode,growth_rate,freq_hz,damping_ratio,dof,amplitude,phase_deg"
    )
    .map_err(io)?;
    let names = model.state_names();
    for (k, e) in an.eigen.iter().enumerate() {
        for (i, (amp, ph)) in shape_of(e).into_iter().enumerate() {
            writeln!(
                w,
                "{},{:e},{:e},{:e},{},{:e},{:e}",
                k + 1,
                e.re,
                e.freq_hz,
                e.damping_ratio,
                names.get(i).map_or("", String::as_str),
                amp,
                ph
            )
            .map_err(io)?;
        }
    }
    w.flush().map_err(io)
}

/// A stability failure as a command error: no steady sliding or bad
/// parameters are input errors (exit 2), anything else a run failure.
pub fn stability_error(e: StabilityError) -> RunError {
    match e {
        StabilityError::NoSteadySliding(_)
        | StabilityError::Param(_)
        | StabilityError::NonFinite { .. }
        | StabilityError::BadInterval { .. } => RunError::Input(InputError(e.to_string())),
        other => RunError::Numerical(other.to_string()),
    }
}

/// Full analysis of any model, with mass-weighted mode attribution.
pub fn analyse(model: &AnyModel) -> Result<Analysis, StabilityError> {
    model.analyse()
}

/// The JSON document of an analysis.
pub fn analysis_json(model: &AnyModel, an: &Analysis) -> Value {
    let names = model.state_names();
    let eig: Vec<Value> = an
        .eigen
        .iter()
        .map(|e| {
            let shape: Vec<Value> = shape_of(e)
                .into_iter()
                .enumerate()
                .map(|(i, (a, p))| json!({ "dof": names.get(i).map_or("", String::as_str), "amplitude": a, "phase_deg": p }))
                .collect();
            json!({
                "re": e.re, "im": e.im, "freq_hz": e.freq_hz,
                "damping_ratio": e.damping_ratio, "dominant": e.dominant_name, "growing": e.growing,
                "neutral": e.neutral,
                "shape": shape,
            })
        })
        .collect();
    let eq: serde_json::Map<String, Value> = names
        .iter()
        .zip(&an.equilibrium)
        .map(|(n, v)| (n.to_string(), json!(v)))
        .collect();
    let ls = an.least_stable_mode();
    json!({
        "eigenvalues": eig,
        "max_growth_rate": an.max_growth_rate,
        "stable": an.stable,
        "neutral": an.neutral,
        "verdict": verdict_word(an),
        "least_stable": { "re": ls.re, "im": ls.im, "freq_hz": ls.freq_hz, "dominant": ls.dominant_name },
        "equilibrium": eq,
        "shape_normalisation": SHAPE_NORMALISATION,
        "modal": modal_json(an),
    })
}

/// How the eigenvalues were computed: `{"method": "dense"}` or
/// `{"method": "projected", "modes": m, "dofs": n, "basis_max_hz": f}`.
pub fn modal_json(an: &Analysis) -> Value {
    serde_json::to_value(an.method).unwrap_or(Value::Null)
}

/// One line saying that the analysis is a reduced-basis one, if it is.
pub fn modal_line(an: &Analysis) -> Option<String> {
    match an.method {
        squeal_core::stability::projected::Method::Dense => None,
        squeal_core::stability::projected::Method::Projected {
            modes,
            dofs,
            basis_max_hz,
        } => Some(format!(
            "projected onto the {modes} lowest undamped modes of {dofs} dofs (up to {basis_max_hz:.1} Hz): a reduced-basis answer for the modes in that band, none above it (modal.modes / modal.cutoff_hz / modal.dense_max_dofs choose)"
        )),
    }
}

/// `stable` (every σ < 0 beyond round-off), `neutral` (no mode grows, some
/// mode has σ = 0 within round-off) or `unstable`.
pub fn verdict_word(an: &Analysis) -> &'static str {
    if an.stable {
        "stable"
    } else if an.neutral {
        "neutral"
    } else {
        "unstable"
    }
}

/// One parameter change that alone flips the verdict (all else as is).
#[derive(Debug, Clone, PartialEq)]
pub struct Lever {
    /// Parameter name.
    pub param: String,
    /// Its unit.
    pub unit: &'static str,
    /// Its current value.
    pub from: f64,
    /// The value where the verdict flips.
    pub to: f64,
    /// Frequency (Hz) of the mode that crosses there.
    pub freq_hz: f64,
}

/// "What would stop it" (or, for a quiet brake, what would start it): for
/// every parameter, the nearest value above and below the current one where
/// the stability of steady sliding changes, searched over ×1000 either way
/// (±1e5 for a signed parameter) by [`stability::critical`].
pub fn levers(model: &AnyModel) -> Vec<Lever> {
    use squeal_core::params::ParamKind;
    let mut out = Vec::new();
    for (name, unit, _, kind) in model.keys() {
        if name == "t_ramp" || name.ends_with(".ramp") {
            continue; // a start-up setting, no part of steady sliding
        }
        let Some(cur) = model.get(&name) else {
            continue;
        };
        let (lo, hi) = match kind {
            ParamKind::Positive => (cur / 1000.0, cur * 1000.0),
            ParamKind::NonNegative => (0.0, if cur > 0.0 { cur * 1000.0 } else { 1000.0 }),
            ParamKind::Any => (
                cur - 1e5 * cur.abs().max(1.0),
                cur + 1e5 * cur.abs().max(1.0),
            ),
        };
        for (a, b) in [(cur, hi), (cur, lo)] {
            if (b - a).abs() <= 1e-12 * a.abs().max(1e-300) {
                continue;
            }
            // Search outwards from the current value: s ∈ [0, 1] maps to a + s (b − a).
            let f = |s: f64| crate::commands::critical::growth_at(model, &name, a + s * (b - a));
            let opts = CriticalOptions {
                grid: 48,
                ..CriticalOptions::default()
            };
            if let Ok(Some(c)) = stability::critical(f, 0.0, 1.0, &opts) {
                let rough = a + c.value * (b - a);
                // The scan's root is exact in s, i.e. to 1e-10·|b − a| in the
                // parameter; refine it on the parameter itself, with the same
                // Brent iteration and tolerance as `critical`, so a lever and
                // `squeal critical` give the same boundary.
                let (to, freq_hz) = refine(model, &name, rough, (b - a).abs(), (a, b))
                    .unwrap_or((rough, c.freq_hz));
                out.push(Lever {
                    param: name.clone(),
                    unit,
                    from: cur,
                    to,
                    freq_hz,
                });
            }
        }
    }
    out
}

/// The crossing near `rough` located on the parameter itself: a bracket of
/// ±1e-9·`span` around it (inside the searched segment `seg`), then
/// [`stability::critical`] with its default 1e-10 relative tolerance.
fn refine(
    model: &AnyModel,
    name: &str,
    rough: f64,
    span: f64,
    seg: (f64, f64),
) -> Option<(f64, f64)> {
    let (lo_seg, hi_seg) = (seg.0.min(seg.1), seg.0.max(seg.1));
    let d = 1e-9 * span + 4.0 * f64::EPSILON * rough.abs();
    let (lo, hi) = ((rough - d).max(lo_seg), (rough + d).min(hi_seg));
    if lo >= hi {
        return None;
    }
    let opts = CriticalOptions {
        grid: 2,
        ..CriticalOptions::default()
    };
    let f = |p: f64| crate::commands::critical::growth_at(model, name, p);
    match stability::critical(f, lo, hi, &opts) {
        Ok(Some(c)) => Some((c.value, c.freq_hz)),
        _ => None,
    }
}

/// Run the command.
pub fn run(a: StabilityArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    if let Some(dest) = &a.out {
        crate::staging::check_dest_as("--out", dest)?;
    }
    let an = analyse(&sc.model).map_err(|e| crate::feasible::stability_failure(&sc.model, e))?;
    if let Some(dest) = &a.out {
        let stage = crate::run::Staging::new_as("--out", dest)?;
        write_modes_csv(&stage.path("modes.csv"), &sc.model, &an)?;
        stage.commit()?;
    }
    // Levers need hundreds of analyses: only for models of the fixed-size path.
    let large = matches!(&sc.model, AnyModel::Lumped(l)
        if l.dof_count() > squeal_core::model::lumped::MAX_SIM_DOFS);
    let levers = if large { Vec::new() } else { levers(&sc.model) };
    if a.json {
        let mut doc = analysis_json(&sc.model, &an);
        doc["scenario"] = sc.to_json();
        doc["levers"] = json!(levers
            .iter()
            .map(|l| json!({ "param": l.param, "from": l.from, "to": l.to, "freq_hz": l.freq_hz }))
            .collect::<Vec<_>>());
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
        return Ok(());
    }
    let verdict = if an.stable {
        "STABLE: every mode is damped"
    } else if an.neutral {
        "NEUTRAL: no mode grows, but a mode is undamped (σ = 0 within the eigen-solver's round-off, 1e-12·|λ|); linear analysis cannot decide"
    } else {
        "UNSTABLE: it squeals"
    };
    crate::outln!(
        "{} ({}): steady sliding is {verdict} (max growth rate {:+.6e} 1/s)",
        sc.name,
        sc.model.name(),
        an.max_growth_rate
    );
    if let Some(line) = modal_line(&an) {
        crate::outln!("{line}");
    }
    crate::outln!(
        "{:>3}  {:>15}  {:>15}  {:>12}  {:>14}  dominant",
        "#",
        "σ (1/s)",
        "ω (rad/s)",
        "freq (Hz)",
        "damping ratio"
    );
    for (i, e) in an.eigen.iter().enumerate() {
        crate::outln!(
            "{:>3}  {:>+15.6e}  {:>+15.6e}  {:>12.2}  {:>+14.4e}  {}{}",
            i + 1,
            e.re,
            e.im,
            e.freq_hz,
            e.damping_ratio,
            e.dominant_name,
            if e.growing {
                "  grows"
            } else if e.neutral {
                "  neutral"
            } else {
                ""
            }
        );
    }
    let ls = an.least_stable_mode();
    crate::outln!(
        "least stable mode: {:.2} Hz, dominated by {}, σ = {:+.6e} 1/s",
        ls.freq_hz,
        ls.dominant_name,
        ls.re
    );
    if large {
        crate::outln!(
            "(levers are searched only for models of up to {} dofs)",
            squeal_core::model::lumped::MAX_SIM_DOFS
        );
    } else if levers.is_empty() {
        crate::outln!("no single parameter change within ×1000 either way changes the verdict");
    } else {
        crate::outln!(
            "{} by changing one parameter (all others as they are):",
            if !an.eigen.iter().any(|e| e.growing) {
                "it would start to squeal"
            } else {
                "what would stop it"
            }
        );
        for l in &levers {
            let verb = if l.to > l.from { "raise" } else { "lower" };
            crate::outln!(
                "  {verb} {:<6} from {:<11} to {:.6e} {} (the {:.1} Hz mode crosses there)",
                l.param,
                format!("{:.4e}", l.from),
                l.to,
                l.unit,
                l.freq_hz
            );
        }
    }
    Ok(())
}
