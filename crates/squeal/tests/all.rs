//! The squeal integration tests as one binary (one link and one copy of the
//! library's generic code instead of one per file: issue 24, class 9).
//! Each file of this folder is a module; a new test file is declared here.

mod answer_cli;
mod cli;
mod cli_common;
mod condense_cli;
mod cycle_cli;
mod fe_files_cli;
mod hb_cli;
mod levers_cli;
mod lumped_cli;
mod params_cli;
mod radiation_cli;
mod reduce_cli;
mod reliability;
mod reliability_inputs;
mod reliability_limits;
mod reliability_outputs;
mod reliability_slurm;
mod reproduce;
mod shard_cli;
mod signals;
mod stability_cli;
mod sweep_cli;
mod validate_cli;
mod verdict;
