//! squeal's files: everything the studies of `squeal-study` (which know no
//! files) leave on disk, written the same way for the command line and for
//! Python.
//!
//! - [`staging`]: output folders written beside their destination and
//!   swapped into place in one step, a manifest of what squeal wrote, and
//!   nothing of a user's ever deleted;
//! - [`output`]: a run's folder (`series.csv`/`.npy`, `events.csv`,
//!   `summary.json`) and reading one back;
//! - [`analysis`]: a run's spectrum CSV, its figure and its sound (WAV);
//!   [`run_dir`]: a run's whole folder, and its pictures redrawn;
//! - [`modes`], [`cycle`], [`hb`], [`branch`], [`reduce`]: the files of
//!   `stability`, `cycle`, `hb`, `branch` and `reduce`;
//! - [`map`], [`sweep`], [`reproduce`]: the files of a map, a sweep and the
//!   thesis report, each a study with its writer;
//! - [`shard`]: a slice of a map, sweep or `reproduce` (`shard.json` and
//!   its part), and [`merge`]: all the slices of one study into the files of
//!   the unsharded study, byte for byte;

//!
//! Imports form a tree: `error` ← `staging`, `output` ← `analysis` ←
//! `map`, `sweep`, `reproduce` ← `shard` ← `merge`, `slurm`.

/// A note on standard error from this layer ([`error::note`]).
macro_rules! note {
    ($($t:tt)*) => {
        $crate::error::note(format_args!($($t)*))
    };
}

pub mod analysis;
pub mod branch;
pub mod cycle;
pub mod error;
pub mod hb;
pub mod map;
pub mod merge;
pub mod modes;
pub mod nma;
pub mod output;
pub mod reduce;
pub mod reproduce;
pub mod run_dir;
pub mod shard;
pub mod slurm;
pub mod staging;
pub mod sweep;

pub use error::RunError;
pub use staging::{StagedFile, Staging};

/// Progress bars for a study's stages: `bars(len, what)` gives the bar of a stage
/// of `len` units named `what` (the CLI's indicatif bar on a terminal; Python's none).
pub type Bars<'a> = &'a dyn Fn(u64, &str) -> Box<dyn squeal_study::Progress>;
