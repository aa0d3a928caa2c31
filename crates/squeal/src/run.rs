//! The command line's side of a run: its error type (with exit codes), the
//! progress bar, and a timed call of [`squeal_study::run::run`] (outputs are
//! staged by [`crate::staging::Staging`], re-exported here).

use indicatif::{ProgressBar, ProgressStyle};
use squeal_study::{Cancel, InputError, Progress, Scenario, StudyError};
use std::io::IsTerminal;
use std::time::Instant;

pub use crate::staging::Staging;
pub use squeal_study::run::Run;

/// Why a command failed: bad input (exit code 2) or trouble during the run (exit code 1).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Bad input, detected before anything was written.
    #[error(transparent)]
    Input(#[from] InputError),
    /// Numerical failure (step underflow, chatter, …) with its time and cause.
    #[error("simulation failed: {0}")]
    Numerical(String),
    /// Writing output failed.
    #[error("{0}")]
    Io(String),
}

impl From<StudyError> for RunError {
    fn from(e: StudyError) -> Self {
        match e {
            StudyError::Input(e) => RunError::Input(e),
            StudyError::Numerical(s) => RunError::Numerical(s),
            StudyError::Interrupted => RunError::Io("interrupted".into()),
        }
    }
}

/// The CLI never cancels a computation: SIGINT and SIGTERM end the process
/// (after removing its staging entries, see [`crate::staging`]).
pub static NEVER: Cancel = Cancel::new();

/// An indicatif bar as the library's [`Progress`].
pub struct Bar(pub ProgressBar);

impl Progress for Bar {
    fn inc(&self, n: u64) {
        self.0.inc(n);
    }
    fn finish(&self) {
        self.0.finish_and_clear();
    }
}

/// A progress bar on a terminal, nothing otherwise.
pub fn progress_bar(len: u64, what: &str) -> Bar {
    if !std::io::stderr().is_terminal() {
        return Bar(ProgressBar::hidden());
    }
    let pb = ProgressBar::new(len);
    pb.set_style(
        ProgressStyle::with_template(
            "{msg} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    Bar(pb)
}

/// Integrate a scenario, with a progress bar on a terminal, timing the
/// integration (`Run::integrate_s`).
pub fn run(sc: &Scenario) -> Result<Run, RunError> {
    let pb = progress_bar(1000, &format!("simulating {}", sc.name));
    let start = Instant::now();
    let mut r = squeal_study::run::run(sc, &pb, &NEVER)?;
    r.integrate_s = start.elapsed().as_secs_f64();
    Ok(r)
}
