//! The command line's side of a run: the progress bar, and a timed call of
//! [`squeal_study::run::run`] (the error type, [`squeal_files::RunError`],
//! and the staged output, [`squeal_files::Staging`], are re-exported here).

use indicatif::{ProgressBar, ProgressStyle};
use squeal_study::{Cancel, Progress, Scenario};
use std::io::IsTerminal;
use std::time::Instant;

pub use squeal_files::{RunError, Staging};
pub use squeal_study::run::Run;

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

/// A progress bar on a terminal, nothing otherwise, as the files layer's
/// [`squeal_files::Bars`] want it.
pub fn bars(len: u64, what: &str) -> Box<dyn Progress> {
    Box::new(progress_bar(len, what))
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
