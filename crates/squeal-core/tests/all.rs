//! The squeal-core integration tests as one binary (one link and one copy of the
//! library's generic code instead of one per file: issue 24, class 9).
//! Each file of this folder is a module; a new test file is declared here.

mod branch;
mod breakaway;
mod budget;
mod contact;
mod craig_bampton;
mod cycle;
mod engine;
mod ensemble;
mod equilibrium;
mod fe_formats;
mod hb;
mod hb_forced;
mod hb_hill;
mod hb_nma;
mod hb_stick;
mod lanczos;
mod lumped;
mod lumped_lanes;
mod modal;
mod padding;
mod projected;
mod stability;
mod steady;
mod sweep;
mod tanh;
