//! `squeal hb [SCENARIO] [--harmonics H] [--json]`: the self-excited
//! periodic orbit by harmonic balance (`squeal_study::hb`).

use crate::commands::cycle::SettleArgs;
use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use squeal_study::cycle::checked_options;
use squeal_study::hb::{of_scenario, HbFound};
use squeal_study::scenario::Scenario;
use std::path::PathBuf;

/// Arguments of `squeal hb`.
#[derive(Args, Debug)]
pub struct HbArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Harmonics kept (the table also shows H/4 and H/2).
    #[arg(long, default_value_t = 20)]
    pub harmonics: usize,
    #[command(flatten)]
    pub settle: SettleArgs,
    /// Where the first guess comes from: `settle` (a settled simulation, the
    /// orbit the scenario's motion settles on) or `hopf` (steady sliding's
    /// growing mode, no simulation; settles if that finds no stable orbit).
    #[arg(long, default_value = "settle")]
    pub guess: String,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write summary.json, hb_orbit.csv and hb.png/.svg (the series against
    /// the exact flow from it, and the harmonics) into this new folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Run the command.
pub fn run(a: HbArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    squeal_study::hb::check_harmonics(a.harmonics)?;
    let opts = checked_options(
        &sc,
        a.settle.settle_steps,
        a.settle.settle_time,
        a.settle.settle_tol,
        None,
    )?;
    let stage = a.out.as_deref().map(Staging::new).transpose()?;
    let guess = squeal_study::hb::Guess::parse(&a.guess)?;
    let found = of_scenario(&sc, a.harmonics, &opts, guess, a.out.is_some(), &NEVER)?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        squeal_files::hb::write(&stage, &found, &sc, &doc)?;
        stage.commit()?;
    }
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        print_human(&found, &sc);
        if let Some(d) = &a.out {
            crate::outln!("output: {}", d.display());
        }
    }
    Ok(())
}

fn print_human(f: &HbFound, sc: &Scenario) {
    crate::outln!(
        "{} ({}): periodic orbit by harmonic balance, H = {}: {:.6} Hz (period {:.9e} s), {} (largest non-trivial |multiplier| {:.9}, by one exact period from the HB orbit)",
        sc.name,
        sc.model.name(),
        f.harmonics,
        1.0 / f.period,
        f.period,
        match (f.stable, f.stability_resolved) {
            (_, false) => "stability not resolved",
            (true, true) => "stable",
            (false, true) => "unstable",
        },
        f.max_multiplier
    );
    crate::outln!(
        "residual {:.2e} after {} Newton iterations; {} panels, {} mode switches per period; exact period from the HB state misses it by {:.2e} (scaled)",
        f.residual, f.iterations, f.panels, f.switches, f.defect
    );
    crate::outln!("convergence in the harmonics:");
    crate::outln!("      H        frequency (Hz)   amplitude change   residual");
    for t in &f.convergence {
        crate::outln!(
            "  {:5}  {:20.10}   {:>16}   {:.1e}",
            t.harmonics,
            t.freq_hz,
            if t.amplitude_change.is_finite() {
                format!("{:.2e}", t.amplitude_change)
            } else {
                "–".into()
            },
            t.residual
        );
    }
    for (name, fr) in &f.fractions {
        crate::outln!(
            "contact {name}: slip+ {:.4}, slip− {:.4}, stick {:.4}, no contact {:.4} of the period",
            fr[0],
            fr[1],
            fr[2],
            fr[3]
        );
    }
    let n = f.spectrum.len();
    let show = f.harmonics.min(5);
    crate::outln!("amplitude per dof and harmonic (m; mean, then k = 1…{show}):");
    for (name, s) in f.names[..n].iter().zip(&f.spectrum) {
        let parts: Vec<String> = s[..=show].iter().map(|v| format!("{v:.4e}")).collect();
        crate::outln!("  {name}: {}", parts.join("  "));
    }
    let amp: Vec<String> = f
        .names
        .iter()
        .zip(&f.amplitude)
        .map(|(n, a)| format!("{n} {a:.4e}"))
        .collect();
    crate::outln!("amplitude (half peak-to-peak): {}", amp.join(", "));
    crate::outln!("multipliers (|·| descending):");
    for &(re, im, trivial) in &f.multipliers {
        crate::outln!(
            "  {re:+.9e} {im:+.9e}i  |{:.9}|{}",
            re.hypot(im),
            if trivial { "  trivial" } else { "" }
        );
    }
    for w in &f.warnings {
        crate::outln!("warning: {w}");
    }
}
