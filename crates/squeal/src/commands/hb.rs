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
    /// Follow the solution in one parameter, `NAME=LO:HI:N`
    /// (pseudo-arclength through folds, steps of at most (HI−LO)/(N−1)): a
    /// forced model's frequency-response curve with `<force>.freq_hz`, or a
    /// self-excited orbit's branch; writes branch.csv and hb_branch.png with --out.
    #[arg(long, value_name = "NAME=LO:HI:N")]
    pub param: Option<String>,
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
    let guess = squeal_study::hb::Guess::parse(&a.guess)?;
    if let Some(spec) = &a.param {
        let (name, lo, hi, steps) = squeal_study::branch::parse_range(spec)?;
        if guess != squeal_study::hb::Guess::Settle {
            return Err(squeal_study::scenario::InputError(
                "--guess: with --param the first point is settled by simulation".into(),
            )
            .into());
        }
        let stage = a.out.as_deref().map(Staging::new).transpose()?;
        let br =
            squeal_study::hb_branch::follow(&sc, &name, lo, hi, steps, a.harmonics, &opts, &NEVER)?;
        let mut doc = br.to_json();
        doc["scenario"] = sc.to_json();
        if let Some(stage) = stage {
            squeal_files::hb::write_branch(&stage, &br, &sc, &doc)?;
            stage.commit()?;
        }
        return report(a.json, &doc, a.out.as_deref(), || print_branch(&br, &sc));
    }
    let stage = a.out.as_deref().map(Staging::new).transpose()?;
    let found = of_scenario(&sc, a.harmonics, &opts, guess, a.out.is_some(), &NEVER)?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        squeal_files::hb::write(&stage, &found, &sc, &doc)?;
        stage.commit()?;
    }
    report(a.json, &doc, a.out.as_deref(), || print_human(&found, &sc))
}

/// The document on stdout (`--json`), or the terminal's lines and the
/// output folder.
pub(crate) fn report(
    json: bool,
    doc: &serde_json::Value,
    out: Option<&std::path::Path>,
    human: impl FnOnce(),
) -> Result<(), RunError> {
    if json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        human();
        if let Some(d) = out {
            crate::outln!("output: {}", d.display());
        }
    }
    Ok(())
}

fn print_human(f: &HbFound, sc: &Scenario) {
    let verdict = match (f.stable, f.stability_resolved) {
        (_, false) => "stability not resolved",
        (true, true) => "stable",
        (false, true) => "unstable",
    };
    if let Some(fh) = f.forcing_hz {
        crate::outln!(
            "{} ({}): forced response by harmonic balance, H = {}: at the forcing frequency {:.6} Hz (period {:.9e} s), {verdict} (largest |multiplier| {:.9}, by one exact forcing period from the HB orbit)",
            sc.name,
            sc.model.name(),
            f.harmonics,
            fh,
            f.period,
            f.max_multiplier
        );
    } else {
        print_autonomous(f, sc, verdict);
    }
    print_rest(f);
}

fn print_autonomous(f: &HbFound, sc: &Scenario, verdict: &str) {
    crate::outln!(
        "{} ({}): periodic orbit by harmonic balance, H = {}: {:.6} Hz (period {:.9e} s), {} (largest non-trivial |multiplier| {:.9}, by one exact period from the HB orbit)",
        sc.name,
        sc.model.name(),
        f.harmonics,
        1.0 / f.period,
        f.period,
        verdict,
        f.max_multiplier
    );
}

fn print_rest(f: &HbFound) {
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
    if f.stick_constraint {
        crate::outln!(
            "stick as a constraint (dynamic Lagrangian step): converges algebraically in the harmonics"
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
    if let Some(h) = &f.hill {
        crate::outln!(
            "Hill's method (smooth orbit, from the series alone): largest non-trivial |multiplier| {:.9}",
            h.max_multiplier
        );
    }
    for w in &f.warnings {
        crate::outln!("warning: {w}");
    }
}

fn print_branch(b: &squeal_study::hb_branch::HbBranchFound, sc: &Scenario) {
    let n = b.names.len() / 2;
    let k = (0..n)
        .max_by(|&x, &y| {
            let top = |i: usize| b.rows.iter().map(|r| r.amplitude[i]).fold(0.0, f64::max);
            top(x).total_cmp(&top(y))
        })
        .unwrap_or(0);
    crate::outln!(
        "{} ({}): {} by harmonic balance over {}, H = {}: {} points, {} fold{}; {}",
        sc.name,
        sc.model.name(),
        if b.forced {
            "frequency response"
        } else {
            "periodic orbit"
        },
        b.name,
        b.harmonics,
        b.rows.len(),
        b.folds.len(),
        if b.folds.len() == 1 { "" } else { "s" },
        b.end
    );
    crate::outln!(
        "  {:>14}  {:>14}  {:>14}  {:>12}  stability",
        b.name,
        "freq (Hz)",
        format!("amp {} (m)", b.names[k]),
        "max |mult|"
    );
    for r in &b.rows {
        crate::outln!(
            "  {:14.6e}  {:14.6}  {:14.6e}  {:12.9}  {}{}",
            r.value,
            1.0 / r.period,
            r.amplitude[k],
            r.max_multiplier,
            match (r.stable, r.resolved) {
                (_, false) => "not resolved",
                (true, true) => "stable",
                (false, true) => "unstable",
            },
            if r.kind == "fold" { "  (fold)" } else { "" }
        );
    }
    for f in &b.folds {
        crate::outln!("fold at {} = {f:.6e}", b.name);
    }
    for w in &b.warnings {
        crate::outln!("warning: {w}");
    }
}
