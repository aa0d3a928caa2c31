//! `squeal-study`: everything squeal computes above the engine — scenarios
//! (built-ins, TOML, `--set` overrides), runs, feasibility checks, and the
//! studies (stability, maps, critical values, sweeps, cycles, branches, the
//! thesis reproduction) — shared by the command line and the Python package.
//!
//! No files are written, no clocks read and nothing printed here (a scenario's
//! own Matrix Market inputs are read). Long computations take a [`Cancel`]
//! token and report to a [`Progress`]; failures are [`StudyError`]s.

pub mod analysis;
pub mod answer;
pub mod audio;
pub mod branch;
pub mod cpu;
pub mod critical;
pub mod cycle;
pub mod error;
pub mod feasible;
pub mod hb;
pub mod hb_branch;
pub mod input;
pub mod inspect;
pub mod levers;
pub mod lumped_file;
pub mod map;
pub mod matrix_file;
pub mod memory;
pub mod model;
pub mod nma;
pub mod plan;
pub mod radiation;
pub mod reduce;
pub mod reproduce;
pub mod run;
pub mod scenario;
#[cfg(test)]
mod scenario_props;
pub mod sound;
pub mod stability;
pub mod study;
pub mod sweep;
pub mod validate;

pub use error::{Cancel, NoProgress, Progress, StudyError};
pub use model::AnyModel;
pub use run::Run;
pub use scenario::{InputError, Scenario, Setting};
