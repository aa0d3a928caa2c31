//! `squeal critical [SCENARIO] --param NAME=LO:HI [--json]`: the parameter
//! value where steady sliding changes stability (a Hopf point, or the onset
//! of undamped mode coupling), by bracketing and Brent's method.

use crate::commands::simulate::resolve;
use crate::run::RunError;
use crate::ScenarioArgs;
use clap::Args;
use serde_json::json;
use squeal_core::stability::Direction;
use squeal_study::critical::locate;
use squeal_study::scenario::InputError;

/// Arguments of `squeal critical`.
#[derive(Args, Debug)]
pub struct CriticalArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The parameter and its search interval, e.g. V=0:20 or c_px=0:10.
    #[arg(long, value_name = "NAME=LO:HI", allow_hyphen_values = true)]
    param: String,
    /// Points of the initial scan of the interval.
    #[arg(long, default_value_t = 64)]
    grid: usize,
    /// Print {"param", "value", "freq_hz"} as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Parse `NAME=LO:HI`.
pub fn parse_interval(spec: &str, flag: &str) -> Result<(String, f64, f64), InputError> {
    let bad = || {
        InputError(format!(
            "{flag} {spec}: expected NAME=LO:HI with numbers LO < HI"
        ))
    };
    let (name, range) = spec.split_once('=').ok_or_else(bad)?;
    let (lo, hi) = range.split_once(':').ok_or_else(bad)?;
    let (lo, hi): (f64, f64) = (
        lo.trim().parse().map_err(|_| bad())?,
        hi.trim().parse().map_err(|_| bad())?,
    );
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(bad());
    }
    Ok((name.trim().to_string(), lo, hi))
}

/// Run the command.
pub fn run(a: CriticalArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let (name, lo, hi) = parse_interval(&a.param, "--param")?;
    if let Some(p) = squeal_study::plan::plan(&sc, "critical", a.grid) {
        crate::errln!("{p} (a grid of {}, then bisection)", a.grid);
    }
    let found = locate(&sc.model, &name, lo, hi, a.grid, &crate::run::NEVER)?;
    if a.json {
        let mut doc = match &found {
            Some(c) => json!({
                "param": name, "value": c.value, "freq_hz": c.freq_hz,
                "direction": c.direction, "from_neutral": c.from_neutral,
            }),
            None => json!({ "param": name, "value": null, "freq_hz": null }),
        };
        doc["modal"] = squeal_study::stability::modal_options_json(&sc.model);
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
        return Ok(());
    }
    match found {
        None => crate::outln!(
            "{}: no change of stability for {name} in [{lo}, {hi}]",
            sc.name
        ),
        Some(c) => {
            let side = match c.direction {
                Direction::Destabilising => "unstable above, stable below",
                Direction::Stabilising => "stable above, unstable below",
            };
            let kind = if c.from_neutral {
                "onset of mode coupling"
            } else {
                "Hopf point"
            };
            crate::outln!(
                "{}: critical {name} = {:.12e} ({kind}; {side}); the crossing mode is at {:.3} Hz",
                sc.name,
                c.value,
                c.freq_hz
            );
        }
    }
    Ok(())
}
