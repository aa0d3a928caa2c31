//! Errors, cancellation and progress for the long computations.

use std::sync::atomic::{AtomicBool, Ordering};

/// A bad scenario or override: one line naming the key and the value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

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

/// Most characters of a message printed for a terminal (2000): keys and
/// values echoed from the input are cut to fit (issue 24, class 6).
pub const MAX_MESSAGE_CHARS: usize = 2000;

/// A message as a terminal may show it: one line, control characters
/// (newline, carriage return, ESC, …) and the Unicode controls that reorder
/// or hide text (bidirectional overrides, zero-width marks, line and
/// paragraph separators) escaped as `\n`, `\u{1b}`, …, and cut to
/// [`MAX_MESSAGE_CHARS`] characters with the number left out said.
pub fn for_terminal(msg: &str) -> String {
    let hidden = |c: char| {
        c.is_control()
            || matches!(c, '\u{200b}'..='\u{200f}' | '\u{2028}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{feff}')
    };
    let mut out = String::with_capacity(msg.len().min(MAX_MESSAGE_CHARS + 64));
    for (shown, (i, c)) in msg.char_indices().enumerate() {
        if shown >= MAX_MESSAGE_CHARS {
            let rest = msg[i..].chars().count();
            out.push_str(&format!("… ({rest} more characters)"));
            break;
        }
        if hidden(c) {
            match c {
                '\n' => out.push_str("\\n"),
                '\r' => out.push_str("\\r"),
                '\t' => out.push_str("\\t"),
                c => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            }
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod terminal_tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_long_lines_cut() {
        assert_eq!(
            for_terminal("key 'a\nb\x1b[31m' μ = 0.3"),
            "key 'a\\nb\\u{1b}[31m' μ = 0.3"
        );
        assert_eq!(for_terminal("x\u{202e}y"), "x\\u{202e}y");
        let long = "v".repeat(100_000);
        let cut = for_terminal(&long);
        assert!(cut.chars().count() < MAX_MESSAGE_CHARS + 40);
        assert!(
            cut.ends_with("… (98000 more characters)"),
            "{}",
            &cut[cut.len() - 40..]
        );
    }
}
