//! One module per command.

pub mod branch;
pub mod critical;
pub mod cycle;
pub mod hb;
pub mod inspect;
pub mod listen;
pub mod map;
pub mod merge;
pub mod nma;
pub mod plot;
pub mod reduce;
pub mod reproduce;
pub mod scenario;
pub mod simulate;
pub mod slurm;
pub mod stability;
pub mod sweep;
pub mod validate;
