//! Errors, cancellation and progress for the long computations.

use crate::scenario::InputError;
use std::sync::atomic::{AtomicBool, Ordering};

/// Why a study failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum StudyError {
    /// Bad input, detected before any work (the CLI's exit code 2).
    #[error(transparent)]
    Input(#[from] InputError),
    /// Numerical failure (step underflow, chatter, …) with its time and
    /// cause (the CLI's exit code 1).
    #[error("simulation failed: {0}")]
    Numerical(String),
    /// The caller's [`Cancel`] token was set.
    #[error("interrupted")]
    Interrupted,
}

/// A cancellation token: set it from another thread (a Ctrl-C handler) and
/// every long computation that was given it stops soon after with
/// [`StudyError::Interrupted`] (a simulation checks it every thousand
/// samples, a grid before every point).
#[derive(Debug, Default)]
pub struct Cancel(AtomicBool);

impl Cancel {
    /// A token that is not set.
    pub const fn new() -> Self {
        Cancel(AtomicBool::new(false))
    }
    /// Ask the computations holding this token to stop.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
    /// Whether [`cancel`](Self::cancel) was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
    /// `Err(Interrupted)` once cancelled.
    pub fn check(&self) -> Result<(), StudyError> {
        if self.is_cancelled() {
            Err(StudyError::Interrupted)
        } else {
            Ok(())
        }
    }
}

/// Where a long computation reports how far it got: `inc(n)` after `n`
/// more units of work (grid points, or thousandths of a run's duration).
/// Implementations must be cheap and thread-safe (grids call it from rayon
/// workers).
pub trait Progress: Sync {
    /// `n` more units done.
    fn inc(&self, n: u64);
    /// The work is over (a bar clears itself); by default nothing.
    fn finish(&self) {}
}

/// A [`Progress`] that ignores everything.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn inc(&self, _n: u64) {}
}
