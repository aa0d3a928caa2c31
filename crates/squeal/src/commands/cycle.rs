//! `squeal cycle [SCENARIO] [--set K=V]… [--json] [--out DIR]`: the limit
//! cycle the scenario settles on — period, Floquet multipliers (saltation
//! matrices at every event), amplitudes, events per period — by
//! `squeal_core::cycle`.

use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use squeal_core::cycle::CycleOptions;
use squeal_core::EventKind;
use squeal_study::cycle::{checked_options, of_scenario, Found};
use squeal_study::scenario::Scenario;
use std::path::{Path, PathBuf};

/// How a settling run looks for a periodic orbit (`cycle`, `hb`).
#[derive(Args, Debug)]
pub struct SettleArgs {
    /// Most integrator steps spent settling onto the cycle.
    #[arg(long, default_value_t = 20_000_000)]
    pub settle_steps: u64,
    /// Most simulated time spent settling (s), whatever the scenario's duration.
    #[arg(long, default_value_t = 1000.0, allow_hyphen_values = true)]
    pub settle_time: f64,
    /// Settled when two returns to the section agree to this, relative to
    /// the orbit's amplitude (Newton's method does the rest).
    #[arg(long, default_value_t = CycleOptions::default().settle_tol)]
    pub settle_tol: f64,
}

/// Arguments of `squeal cycle`.
#[derive(Args, Debug)]
pub struct CycleArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Poincaré section: a state name, optionally with its level
    /// (`vx_p` or `vx_p=0.1`); default an upward zero of a velocity.
    #[arg(long, value_name = "STATE[=LEVEL]", allow_hyphen_values = true)]
    pub section: Option<String>,
    #[command(flatten)]
    pub settle: SettleArgs,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write orbit.csv, cycle.json and the pictures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Run the command.
pub fn run(a: CycleArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let opts = checked_options(
        &sc,
        a.settle.settle_steps,
        a.settle.settle_time,
        a.settle.settle_tol,
        a.section.as_deref(),
    )?;
    let stage = a.out.as_deref().map(Staging::new).transpose()?;
    let found = of_scenario(&sc, &opts, a.out.is_some(), &NEVER)?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        squeal_files::cycle::write(&stage, &found, &sc, &doc)?;
        stage.commit()?;
    }
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        print_human(&found, &sc, a.out.as_deref());
    }
    Ok(())
}

fn print_human(f: &Found, sc: &Scenario, out: Option<&Path>) {
    crate::outln!(
        "{} ({}): limit cycle of period {:.9e} s ({:.3} Hz), {} (largest non-trivial |multiplier| {:.9})",
        sc.name,
        sc.model.name(),
        f.period,
        1.0 / f.period,
        if f.stable { "stable" } else { "unstable" },
        f.max_multiplier
    );
    crate::outln!(
        "section: upward crossing of {} = {}; shooting residual {:.2e} after {} Newton iterations; settled in {:.4} s simulated",
        f.section.0, f.section.1, f.residual, f.iterations, f.settle_time
    );
    crate::outln!("multipliers (|·| descending):");
    for &(re, im, trivial) in &f.multipliers {
        crate::outln!(
            "  {re:+.12e} {im:+.12e}i  |{:.12}|{}",
            re.hypot(im),
            if trivial {
                "  trivial (along the flow)"
            } else {
                ""
            }
        );
    }
    let ev: Vec<String> = EventKind::ALL
        .iter()
        .filter(|k| f.events[k.index()] > 0)
        .map(|k| format!("{} {}", f.events[k.index()], k.as_str()))
        .collect();
    crate::outln!(
        "events per period: {}",
        if ev.is_empty() {
            "none".to_string()
        } else {
            ev.join(", ")
        }
    );
    let amp: Vec<String> = f
        .names
        .iter()
        .zip(&f.amplitude)
        .map(|(n, a)| format!("{n} {a:.4e}"))
        .collect();
    crate::outln!("amplitude (half peak-to-peak): {}", amp.join(", "));
    if let Some(d) = out {
        crate::outln!("output: {}", d.display());
    }
}
