//! `squeal nma [SCENARIO] --mode K --modal-amplitude LO:HI:N`: a nonlinear
//! mode's frequency and damping over its amplitude (`squeal_study::nma`).

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use squeal_study::nma::{of_scenario, parse_amplitudes, NmaFound};
use squeal_study::scenario::Scenario;
use std::path::PathBuf;

/// Arguments of `squeal nma`.
#[derive(Args, Debug)]
pub struct NmaArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// The mode, numbered from 1 by frequency, of the model linearised with
    /// its contacts stuck (the low-amplitude limit of a friction-damped mode).
    #[arg(long, default_value_t = 1)]
    pub mode: usize,
    /// Mass-normalised modal amplitudes, `LO:HI:N` log-spaced (m·√kg).
    #[arg(long, value_name = "LO:HI:N")]
    pub modal_amplitude: String,
    /// Harmonics kept.
    #[arg(long, default_value_t = 20)]
    pub harmonics: usize,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write summary.json, nma.csv and nma.png/.svg into this new folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Run the command.
pub fn run(a: NmaArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let amps = parse_amplitudes(&a.modal_amplitude)?;
    squeal_study::hb::check_harmonics(a.harmonics)?;
    let stage = a.out.as_deref().map(Staging::new).transpose()?;
    let found = of_scenario(&sc, a.mode, &amps, a.harmonics, &NEVER)?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        squeal_files::nma::write(&stage, &found, &sc, &doc)?;
        stage.commit()?;
    }
    crate::commands::hb::report(a.json, &doc, a.out.as_deref(), || print_human(&found, &sc))
}

fn print_human(f: &NmaFound, sc: &Scenario) {
    crate::outln!(
        "{} ({}): nonlinear mode {} (stuck: {:.6} Hz) by harmonic balance, H = {}, extended periodic motion concept",
        sc.name,
        sc.model.name(),
        f.mode,
        f.linear_hz,
        f.harmonics
    );
    crate::outln!(
        "  {:>14}  {:>14}  {:>14}  {:>12}",
        "modal amp",
        "freq (Hz)",
        "damping ratio",
        "ξ (1/s)"
    );
    for r in &f.rows {
        crate::outln!(
            "  {:14.6e}  {:14.6}  {:14.6e}  {:12.5e}{}",
            r.modal_amplitude,
            r.freq_hz,
            r.damping_ratio,
            r.xi,
            match (r.sticks, r.stick_constraint) {
                (false, _) => "",
                (true, true) => "  (sticks: a constraint)",
                (true, false) => "  (sticks: as slip, not exact)",
            }
        );
    }
    for (a, why) in &f.failures {
        crate::outln!("no solution at modal amplitude {a:e}: {why}");
    }
    for w in &f.warnings {
        crate::outln!("warning: {w}");
    }
}
