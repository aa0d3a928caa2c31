//! `squeal`: simulate, analyse and listen to friction-induced vibration.
//!
//! A thin layer over `squeal-core` (physics, integration), `squeal-signal`
//! (spectra, audio) and `squeal-plot` (pictures). Exit codes: 0 success,
//! 1 a run failed (numerical trouble, I/O), 2 bad input.

mod commands;
mod out;
mod run;

use squeal_files::{analysis, output, staging};

use clap::{Args, Parser, Subcommand};
use run::RunError;
use std::process::ExitCode;

/// squeal: disc-brake squeal and friction-induced vibration, simulated exactly.
#[derive(Parser, Debug)]
#[command(name = "squeal", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The scenario and its overrides, shared by every command that runs a model.
#[derive(Args, Debug, Clone)]
pub struct ScenarioArgs {
    /// A built-in scenario name (disc-pad, belt-coulomb, belt, hoffmann) or a TOML file.
    #[arg(default_value = "disc-pad")]
    pub scenario: String,
    /// Override a parameter or setting: --set N=2000 --set friction=coulomb (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub sets: Vec<String>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Integrate a scenario; write series, events, spectra, summary.json and pictures (and sound).
    Simulate(commands::simulate::SimulateArgs),
    /// Eigen-analysis of steady sliding: every mode's growth rate, frequency, damping.
    Stability(commands::stability::StabilityArgs),
    /// What a scenario's files hold: matrices (format, size, symmetry), dofs, natural frequencies, contacts.
    Inspect(commands::inspect::InspectArgs),
    /// Reduce a lumped (FE) model by Craig–Bampton: contact dofs kept physical, fixed-interface modes to modal.cutoff_hz; written as a scenario.
    Reduce(commands::reduce::ReduceArgs),
    /// Stability map over a grid of two parameters (linear, or --transient by simulation).
    Map(commands::map::MapArgs),
    /// Gather the shards of a map (`map … --shard K/N`) into the map the unsharded run writes.
    Merge(commands::merge::MergeArgs),
    /// Prepare (and with --submit, submit) a SLURM job array that computes a map in shards, and its merge job.
    Slurm {
        #[command(subcommand)]
        what: commands::slurm::SlurmCmd,
    },
    /// Run squeal's benchmark cases against analytic, published or independent references.
    Validate(commands::validate::ValidateArgs),
    /// Locate the parameter value where steady sliding changes stability.
    Critical(commands::critical::CriticalArgs),
    /// The limit cycle a scenario settles on: period, Floquet multipliers, amplitudes, events.
    Cycle(commands::cycle::CycleArgs),
    /// The self-excited periodic orbit by harmonic balance: frequency, harmonics, convergence, Floquet multipliers.
    Hb(commands::hb::HbArgs),
    /// A friction-damped mode's amplitude-dependent frequency and damping (extended periodic motion concept, harmonic balance).
    Nma(commands::nma::NmaArgs),
    /// Follow the limit cycle in one parameter: branch.csv, bifurcations, diagram.
    Branch(commands::branch::BranchArgs),
    /// Every eigenvalue along a one-parameter sweep, modes tracked: sweep.csv and the mode-coupling diagram.
    Sweep(commands::sweep::SweepArgs),
    /// Re-do the thesis: 40 sets, Appendix A, the seven conclusions checked, a report.
    Reproduce(commands::reproduce::ReproduceArgs),
    /// Redraw the pictures of a saved run without re-simulating.
    Plot(commands::plot::PlotArgs),
    /// Render a velocity as a WAV file (from a saved run or a scenario).
    Listen(commands::listen::ListenArgs),
    /// Built-in scenarios: list them, or print one as a documented TOML file.
    Scenario {
        #[command(subcommand)]
        what: commands::scenario::ScenarioCmd,
    },
}

fn main() -> ExitCode {
    // Before anything else runs: a build for x86-64-v3 (the default) on a
    // processor without AVX2 would otherwise die of an illegal instruction.
    if let Some(feature) = squeal_study::cpu::missing_feature() {
        // Plain bytes (nothing built for the missing feature runs here);
        // a failed write to stderr is ignored.
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "error: {}",
            squeal_study::cpu::refusal(feature)
        );
        return ExitCode::from(1);
    }
    run_cli()
}

/// The command line proper (not inlined into `main`, so that the check of the
/// processor comes before any of its code).
#[inline(never)]
fn run_cli() -> ExitCode {
    staging::install_signal_handlers();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    // A panic is a defect, never the user's fault: it ends as one line and
    // exit code 1 (not Rust's 101 and a backtrace), with where it happened.
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        crate::errln!("error: internal error{at}: {msg} (a defect of squeal: please report it with the command that caused it)");
    }));
    let run = std::panic::AssertUnwindSafe(move || dispatch(cli.command));
    let result = match std::panic::catch_unwind(run) {
        Ok(r) => r,
        Err(_) => return ExitCode::from(1),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            crate::errln!("error: {e}");
            match e {
                RunError::Input(_) => ExitCode::from(2),
                _ => ExitCode::from(1),
            }
        }
    }
}

/// Run one command.
fn dispatch(command: Command) -> Result<(), RunError> {
    match command {
        Command::Simulate(a) => commands::simulate::run(a),
        Command::Scenario { what } => commands::scenario::run(what),
        Command::Plot(a) => commands::plot::run(a),
        Command::Reproduce(a) => commands::reproduce::run(a),
        Command::Stability(a) => commands::stability::run(a),
        Command::Inspect(a) => commands::inspect::run(a),
        Command::Reduce(a) => commands::reduce::run(a),
        Command::Map(a) => commands::map::run(a),
        Command::Merge(a) => commands::merge::run(a),
        Command::Slurm { what } => commands::slurm::run(what),
        Command::Critical(a) => commands::critical::run(a),
        Command::Validate(a) => commands::validate::run(a),
        Command::Sweep(a) => commands::sweep::run(a),
        Command::Listen(a) => commands::listen::run(a),
        Command::Cycle(a) => commands::cycle::run(a),
        Command::Branch(a) => commands::branch::run(a),
        Command::Hb(a) => commands::hb::run(a),
        Command::Nma(a) => commands::nma::run(a),
    }
}

/// A command-line error in one line (clap's first line, and its tip if it
/// has one) and exit code 2; help and version print in full, exit code 0.
fn usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
            out::err_text(&e.render().to_string());
            return ExitCode::from(2);
        }
        out::text(&e.render().to_string());
        return ExitCode::SUCCESS;
    }
    let text = e.render().to_string();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let first = lines.next().unwrap_or("error: bad command line");
    let mut first = if first.starts_with("error:") {
        first.to_string()
    } else {
        format!("error: {first}")
    };
    // "the following required arguments were not provided:" lists them on
    // the next lines: keep them on the one line.
    if first.ends_with(':') {
        let listed: Vec<&str> = lines
            .clone()
            .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("tip:"))
            .collect();
        first = format!("{first} {}", listed.join(", "));
    }
    match lines.find(|l| l.starts_with("tip:")) {
        Some(tip) => crate::errln!("{first} ({tip}; see --help)"),
        None => crate::errln!("{first} (see --help)"),
    }
    ExitCode::from(2)
}
