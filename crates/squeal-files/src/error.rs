//! Why writing or reading a study's files failed, and the one stderr line
//! this layer may print (a note about a file it left alone or removed).

use squeal_study::{InputError, StudyError};
use std::io::Write;

/// Why a command failed: bad input (the CLI's exit code 2) or trouble
/// during the run or while writing (exit code 1).
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
    /// The caller cancelled the computation (Python's Ctrl-C); nothing was kept.
    #[error("interrupted")]
    Interrupted,
}

impl From<StudyError> for RunError {
    fn from(e: StudyError) -> Self {
        match e {
            StudyError::Input(e) => RunError::Input(e),
            StudyError::Numerical(s) => RunError::Numerical(s),
            StudyError::Interrupted => RunError::Interrupted,
        }
    }
}

/// One line to standard error, as a terminal may show it
/// ([`squeal_study::error::for_terminal`]); a failed write is ignored.
pub fn note(args: std::fmt::Arguments) {
    let line = squeal_study::error::for_terminal(&args.to_string());
    let mut e = std::io::stderr().lock();
    let _ = e
        .write_all(line.as_bytes())
        .and_then(|_| e.write_all(b"\n"));
}
